//! Tests of [`chart`](crate::plot::chart): layout, where data lands, bad data, and the SVG
//! document.

use crate::plot::chart::*;
use crate::plot::xml::check_well_formed;
use crate::plot::{MAX_SIDE, PlotError};

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

/// The value of attribute `name` in the tag `tag`.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&tag[start..start + tag[start..].find('"')?])
}

/// A series as drawn: its label, colour, polyline points and marker centres.
struct Drawn {
    label: String,
    colour: String,
    line: Vec<(f32, f32)>,
    markers: Vec<(f32, f32)>,
}

/// Every `<g class="series">` of an SVG chart, in document order.
fn drawn(svg: &str) -> Vec<Drawn> {
    let number = |s: &str| s.parse::<f32>().unwrap();
    svg.split("<g class=\"series\"")
        .skip(1)
        .map(|part| {
            let group = &part[..part.find("</g>").unwrap()];
            let open = &group[..group.find('>').unwrap()];
            let line = group
                .find("<polyline")
                .map(|i| {
                    attribute(&group[i..], "points")
                        .unwrap()
                        .split(' ')
                        .map(|p| {
                            let (x, y) = p.split_once(',').unwrap();
                            (number(x), number(y))
                        })
                        .collect()
                })
                .unwrap_or_default();
            let markers = group
                .split("<circle")
                .skip(1)
                .map(|c| {
                    (
                        number(attribute(c, "cx").unwrap()),
                        number(attribute(c, "cy").unwrap()),
                    )
                })
                .collect();
            Drawn {
                label: attribute(open, "data-label").unwrap().to_string(),
                colour: attribute(open, "stroke").unwrap().to_string(),
                line,
                markers,
            }
        })
        .collect()
}

fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

fn near(a: (f32, f32), b: (f32, f32)) -> bool {
    (a.0 - b.0).abs() <= 0.01 && (a.1 - b.1).abs() <= 0.01
}

#[test]
fn output_is_a_well_formed_svg_of_the_requested_size() {
    let c = chart(vec![series("a", &[(1.0, 2.0), (2.0, 1.0)])], false, false);
    for (w, h) in [(640, 400), (1, 1), (17, 300), (1600, 1000)] {
        let svg = render_chart(&c, w, h).unwrap();
        assert_eq!(check_well_formed(&svg), Ok("svg".to_string()), "{svg}");
        let root = &svg[svg.find("<svg").unwrap()..];
        let root = &root[..root.find('>').unwrap()];
        assert_eq!(attribute(root, "width"), Some(w.to_string().as_str()));
        assert_eq!(attribute(root, "height"), Some(h.to_string().as_str()));
        assert_eq!(
            attribute(root, "viewBox"),
            Some(format!("0 0 {w} {h}").as_str())
        );
        assert!(svg.contains(">Error against time</text>"), "{svg}");
        assert!(svg.contains(">time (s)</text>"));
        assert!(svg.contains(">relative error</text>"));
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
    let svg = render_chart(&c, 400, 300).unwrap();
    let d = drawn(&svg);
    assert_eq!(d.len(), 1);
    assert_eq!(d[0].label, "one");
    assert_eq!(d[0].colour, hex(PALETTE[0]));
    assert!(d[0].line.is_empty(), "one point makes no line");
    assert_eq!(d[0].markers.len(), 1);
    assert!(near(d[0].markers[0], p), "{:?} {p:?}", d[0].markers);
    // The range is ±10 % of the value: 4.5 and 5.5 are the plot edges.
    let (left, top) = layout.data_to_pixel(4.5, 5.5).unwrap();
    assert!((left - layout.plot_left).abs() < 1e-3);
    assert!((top - layout.plot_top).abs() < 1e-3);
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
    let d = drawn(&render_chart(&c, 600, 400).unwrap());
    assert_eq!(d[0].line.len(), 4);
    for (drawn, want) in d[0].line.iter().zip(&px) {
        assert!(near(*drawn, *want), "{drawn:?} {want:?}");
    }
    let ticks: Vec<String> = layout.x.ticks().into_iter().map(|t| t.1).collect();
    assert_eq!(ticks, ["1", "10", "100", "1000"]);
    let ticks: Vec<String> = layout.y.ticks().into_iter().map(|t| t.1).collect();
    assert_eq!(ticks, ["1e-3", "0.01", "0.1", "1"]);
    let svg = render_chart(&c, 600, 400).unwrap();
    for label in ["1000", "1e-3", "0.01"] {
        assert!(svg.contains(&format!(">{label}</text>")), "tick {label}");
    }
}

#[test]
fn points_are_joined_in_x_order() {
    let c = chart(
        vec![series("zigzag", &[(1.0, 1.0), (3.0, 1.0), (2.0, 3.0)])],
        false,
        false,
    );
    let layout = chart_layout(&c, 500, 400).unwrap();
    let d = drawn(&render_chart(&c, 500, 400).unwrap());
    // (1,1)→(2,3)→(3,1), not (1,1)→(3,1).
    let want: Vec<(f32, f32)> = [(1.0, 1.0), (2.0, 3.0), (3.0, 1.0)]
        .iter()
        .map(|&(x, y)| layout.data_to_pixel(x, y).unwrap())
        .collect();
    assert_eq!(d[0].line.len(), 3);
    for (a, b) in d[0].line.iter().zip(&want) {
        assert!(near(*a, *b), "{:?} {want:?}", d[0].line);
    }
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
        let svg = render_chart(&c, 300, 200).unwrap();
        check_well_formed(&svg).unwrap();
        assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
        let d = drawn(&svg);
        let expected = [
            (-1.0, 5.0),
            (2.0, 0.0),
            (3.0, -2.0),
            (4.0, 10.0),
            (5.0, 100.0),
        ]
        .iter()
        .filter(|&&(x, y)| (!log_x || x > 0.0) && (!log_y || y > 0.0))
        .count();
        assert_eq!(d[0].markers.len(), expected, "{log_x} {log_y}");
        let p = layout.data_to_pixel(5.0, 100.0).unwrap();
        assert!(d[0].markers.iter().any(|&m| near(m, p)));
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
    let svg = render_chart(&c, 400, 300).unwrap();
    check_well_formed(&svg).unwrap();
    assert!(drawn(&svg).is_empty(), "no series is drawn");
    assert!(svg.contains(">no data</text>"));
    assert!(!svg.contains("class=\"legend\""));
    // An empty chart is no different.
    let empty = render_chart(&Chart::default(), 50, 40).unwrap();
    check_well_formed(&empty).unwrap();
}

#[test]
fn text_is_escaped() {
    let c = Chart {
        title: "a < b & \"c\" > 'd'".into(),
        series: vec![series("<script>&", &[(1.0, 1.0), (2.0, 2.0)])],
        ..Chart::default()
    };
    let svg = render_chart(&c, 300, 200).unwrap();
    check_well_formed(&svg).unwrap();
    assert!(svg.contains(">a &lt; b &amp; &quot;c&quot; &gt; &apos;d&apos;</text>"));
    assert!(svg.contains("data-label=\"&lt;script&gt;&amp;\""));
    assert!(!svg.contains("<script"));
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
        check_well_formed(&render_chart(&c, 400, 300).unwrap()).unwrap();
    }
}

#[test]
fn colours_cycle_and_rendering_is_deterministic() {
    let many: Vec<Series> = (0..12)
        .map(|i| series(&format!("method {i}"), &[(i as f64, i as f64)]))
        .collect();
    let c = chart(many, false, false);
    let svg = render_chart(&c, 800, 500).unwrap();
    let d = drawn(&svg);
    assert_eq!(d.len(), 12);
    for (i, series) in d.iter().enumerate() {
        assert_eq!(series.label, format!("method {i}"));
        assert_eq!(series.colour, hex(PALETTE[i % PALETTE.len()]), "series {i}");
        assert!(svg.contains(&format!(">method {i}</text>")), "legend {i}");
    }
    assert_eq!(svg, render_chart(&c, 800, 500).unwrap());
}

#[test]
fn the_legend_avoids_the_data() {
    // Falling curves leave the top-right corner free; rising ones cross it and leave the
    // top-left (preferred over the bottom-right) free.
    for (rising, want_right) in [(false, true), (true, false)] {
        let points: Vec<(f64, f64)> = (1..=8)
            .map(|i| (i as f64, if rising { i as f64 } else { 9.0 - i as f64 }))
            .collect();
        let c = chart(vec![series("s", &points)], false, false);
        let layout = chart_layout(&c, 600, 400).unwrap();
        let svg = render_chart(&c, 600, 400).unwrap();
        let legend = &svg[svg.find("<g class=\"legend\"").unwrap()..];
        let rect = &legend[legend.find("<rect").unwrap()..];
        let y: f32 = attribute(rect, "y").unwrap().parse().unwrap();
        let x: f32 = attribute(rect, "x").unwrap().parse().unwrap();
        let middle = layout.plot_top + layout.plot_height / 2.0;
        assert!(y < middle, "rising {rising}: y {y}");
        let centre = layout.plot_left + layout.plot_width / 2.0;
        assert_eq!(x > centre, want_right, "rising {rising}: x {x}");
    }
}
