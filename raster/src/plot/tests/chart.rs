//! Tests of [`chart`](crate::plot::chart): layout, where data lands, bad data, and
//! rendering.

use crate::plot::chart::*;
use crate::plot::{Canvas, MAX_SIDE, PlotError};

fn series(label: &str, points: &[(f64, f64)]) -> Series {
    Series {
        label: label.to_string(),
        points: points.to_vec(),
    }
}

fn chart(series: Vec<Series>, log_x: bool, log_y: bool) -> Chart {
    Chart {
        title: "Error against time".into(),
        x_label: "time (s)".into(),
        y_label: "relative error".into(),
        series,
        log_x,
        log_y,
    }
}

/// The pixel under the canvas position `p`.
fn at(canvas: &Canvas, p: (f32, f32)) -> [u8; 3] {
    canvas.pixel(p.0 as u32, p.1 as u32).unwrap()
}

fn distance(a: [u8; 3], b: [u8; 3]) -> i32 {
    (0..3)
        .map(|i| (a[i] as i32 - b[i] as i32).abs())
        .max()
        .unwrap()
}

#[test]
fn output_has_the_requested_size() {
    let c = chart(vec![series("a", &[(1.0, 2.0), (2.0, 1.0)])], false, false);
    for (w, h) in [(640, 400), (1, 1), (17, 300), (1600, 1000)] {
        let canvas = render_chart(&c, w, h).unwrap();
        assert_eq!((canvas.width(), canvas.height()), (w, h));
    }
    for (w, h) in [(0, 400), (640, 0), (MAX_SIDE + 1, 10)] {
        assert!(matches!(
            render_chart(&c, w, h),
            Err(PlotError::Size { .. })
        ));
    }
}

#[test]
fn a_single_point_is_drawn_where_the_layout_says() {
    let c = chart(vec![series("one", &[(5.0, 5.0)])], false, false);
    let layout = chart_layout(&c, 400, 300).unwrap();
    let p = layout.data_to_pixel(5.0, 5.0).unwrap();
    // A single value sits in the middle of its widened range.
    assert_eq!(p.0, layout.plot_left + layout.plot_width / 2.0);
    assert_eq!(p.1, layout.plot_top + layout.plot_height / 2.0);
    let canvas = render_chart(&c, 400, 300).unwrap();
    assert_eq!(at(&canvas, p), PALETTE[0]);
    // The range is ±10 % of the value: 4.5 and 5.5 are the plot edges.
    let (left, top) = layout.data_to_pixel(4.5, 5.5).unwrap();
    assert!((left - layout.plot_left).abs() < 1e-3);
    assert!((top - layout.plot_top).abs() < 1e-3);
    // Away from the point (and the legend) the plot area is background or grid.
    let empty = at(&canvas, (p.0 - 40.0, p.1 + 40.0));
    assert!(empty == BACKGROUND || empty == GRID, "{empty:?}");
}

#[test]
fn log_axes_give_decades_equal_lengths() {
    let points = [(1.0, 1e-3), (10.0, 1e-2), (100.0, 0.1), (1000.0, 1.0)];
    let c = chart(vec![series("power law", &points)], true, true);
    let layout = chart_layout(&c, 600, 400).unwrap();
    let px: Vec<(f32, f32)> = points
        .iter()
        .map(|&(x, y)| layout.data_to_pixel(x, y).unwrap())
        .collect();
    for pair in px.windows(2) {
        let (dx, dy) = (pair[1].0 - pair[0].0, pair[1].1 - pair[0].1);
        assert!((dx - (px[1].0 - px[0].0)).abs() < 1e-3, "{px:?}");
        assert!((dy - (px[1].1 - px[0].1)).abs() < 1e-3, "{px:?}");
        assert!(dx > 0.0 && dy < 0.0);
    }
    let canvas = render_chart(&c, 600, 400).unwrap();
    for &p in &px {
        assert_eq!(at(&canvas, p), PALETTE[0]);
    }
    // The line is straight in log-log space: it passes through (10^0.5, 10^-2.5).
    let middle = layout
        .data_to_pixel(10f64.sqrt(), 10f64.powf(-2.5))
        .unwrap();
    assert!(distance(at(&canvas, middle), PALETTE[0]) < 60);
    let ticks: Vec<String> = layout.x.ticks().into_iter().map(|t| t.1).collect();
    assert_eq!(ticks, ["1", "10", "100", "1000"]);
    let ticks: Vec<String> = layout.y.ticks().into_iter().map(|t| t.1).collect();
    assert_eq!(ticks, ["1e-3", "0.01", "0.1", "1"]);
}

#[test]
fn points_are_joined_in_x_order() {
    let c = chart(
        vec![series("zigzag", &[(1.0, 1.0), (3.0, 1.0), (2.0, 3.0)])],
        false,
        false,
    );
    let layout = chart_layout(&c, 500, 400).unwrap();
    let canvas = render_chart(&c, 500, 400).unwrap();
    // (1,1)→(2,3)→(3,1), not (1,1)→(3,1).
    let on = layout.data_to_pixel(1.5, 2.0).unwrap();
    let off = layout.data_to_pixel(2.0, 1.0).unwrap();
    assert!(distance(at(&canvas, on), PALETTE[0]) < 60);
    assert!(distance(at(&canvas, off), BACKGROUND) < 40);
}

#[test]
fn bad_points_are_skipped_without_panicking() {
    let bad = [
        (f64::NAN, 1.0),
        (1.0, f64::INFINITY),
        (-1.0, 5.0),
        (2.0, 0.0),
        (3.0, -2.0),
        (4.0, 10.0),
        (5.0, 100.0),
        (f64::NEG_INFINITY, f64::NAN),
    ];
    for (log_x, log_y) in [(false, false), (true, false), (false, true), (true, true)] {
        let c = chart(vec![series("bad", &bad), series("", &[])], log_x, log_y);
        let layout = chart_layout(&c, 300, 200).unwrap();
        assert!(layout.has_data);
        assert!(layout.x.min.is_finite() && layout.x.max > layout.x.min);
        assert!(layout.y.min.is_finite() && layout.y.max > layout.y.min);
        assert_eq!(layout.data_to_pixel(f64::NAN, 1.0), None);
        assert_eq!(layout.data_to_pixel(3.0, -2.0).is_none(), log_y);
        let canvas = render_chart(&c, 300, 200).unwrap();
        assert_eq!(
            at(&canvas, layout.data_to_pixel(5.0, 100.0).unwrap()),
            PALETTE[0]
        );
    }
    // On log-log only (4, 10) and (5, 100) remain: y spans exactly one decade + 5 %.
    let c = chart(vec![series("bad", &bad)], true, true);
    let y = chart_layout(&c, 300, 200).unwrap().y;
    assert!(
        (y.min - 0.95).abs() < 1e-12 && (y.max - 2.05).abs() < 1e-12,
        "{y:?}"
    );
}

#[test]
fn no_drawable_point_says_no_data() {
    let c = chart(
        vec![series("nothing", &[(f64::NAN, 1.0), (-1.0, -1.0)])],
        true,
        true,
    );
    let layout = chart_layout(&c, 400, 300).unwrap();
    assert!(!layout.has_data);
    assert_eq!(layout.data_to_pixel(1.0, 1.0), None);
    let canvas = render_chart(&c, 400, 300).unwrap();
    let rgb = canvas.to_rgb8();
    let pixels: Vec<[u8; 3]> = rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    assert!(!pixels.contains(&PALETTE[0]), "no series is drawn");
    // "no data" is written around the centre of the plot area.
    let (cx, cy) = (
        (layout.plot_left + layout.plot_width / 2.0) as u32,
        (layout.plot_top + layout.plot_height / 2.0) as u32,
    );
    let text = (cx - 30..cx + 30)
        .flat_map(|x| (cy - 10..cy + 10).map(move |y| (x, y)))
        .filter(|&(x, y)| canvas.pixel(x, y) == Some(TICK_INK))
        .count();
    assert!(text > 50, "{text} text pixels");
    // The frame is there.
    let frame = (layout.plot_left - 1.0, layout.plot_top + 10.0);
    assert_eq!(at(&canvas, frame), FRAME);
    // An empty chart is no different.
    assert!(render_chart(&Chart::default(), 50, 40).is_ok());
}

#[test]
fn ranges_are_valid_for_degenerate_data() {
    let cases: [(&[(f64, f64)], bool); 7] = [
        (&[(0.0, 0.0)], false),
        (&[(3.0, -7.0), (3.0, -7.0)], false),
        (&[(1e-300, 1e300)], false),
        (&[(-f64::MAX, f64::MAX), (f64::MAX, -f64::MAX)], false),
        (&[(1.0, 1.0 + 1e-15), (2.0, 1.0)], false),
        (&[(5e-324, 1.0)], true),
        (&[(1e-300, 1e300), (1e300, f64::MAX)], true),
    ];
    for (points, log) in cases {
        let c = chart(vec![series("s", points)], log, log);
        let layout = chart_layout(&c, 400, 300).unwrap();
        for axis in [layout.x, layout.y] {
            assert!(axis.min.is_finite() && axis.max.is_finite(), "{points:?}");
            assert!(axis.max > axis.min, "{points:?}");
            let ticks = axis.ticks();
            assert!(
                !ticks.is_empty() && ticks.len() <= 12,
                "{points:?}: {ticks:?}"
            );
            assert!(ticks.iter().all(|(a, _)| *a >= axis.min && *a <= axis.max));
        }
        for &(x, y) in points {
            let (px, py) = layout.data_to_pixel(x, y).unwrap();
            assert!(px >= layout.plot_left && px <= layout.plot_left + layout.plot_width);
            assert!(py >= layout.plot_top && py <= layout.plot_top + layout.plot_height);
        }
        render_chart(&c, 400, 300).unwrap();
    }
}

#[test]
fn colours_cycle_and_rendering_is_deterministic() {
    let many: Vec<Series> = (0..12)
        .map(|i| series(&format!("method {i}"), &[(i as f64, i as f64)]))
        .collect();
    let c = chart(many, false, false);
    let layout = chart_layout(&c, 800, 500).unwrap();
    let canvas = render_chart(&c, 800, 500).unwrap();
    // The legend goes to the free bottom-right corner; every series shows its own colour,
    // cycling after 10.
    for i in 0..12 {
        let p = layout.data_to_pixel(i as f64, i as f64).unwrap();
        assert_eq!(at(&canvas, p), PALETTE[i % PALETTE.len()], "series {i}");
    }
    assert_eq!(
        canvas.to_rgb8(),
        render_chart(&c, 800, 500).unwrap().to_rgb8()
    );
}
