//! Demonstration images for a visual check (ignored by default).

use crate::plot::*;

/// Writes a demonstration chart and contact sheet to the system temp directory
/// (`plot-demo-chart.svg`, `plot-demo-chart-linear.svg`, `plot-demo-sheet.png`) for a visual check:
/// `cargo test -p lucent-raster --lib plot::tests::demo -- --ignored`.
#[test]
#[ignore = "writes demonstration images for a visual check"]
fn demo() {
    let methods = [("reference MC", 0.5), ("N10 network", 1.0), ("dipole", 0.8)];
    let mut series: Vec<Series> = methods
        .iter()
        .enumerate()
        .map(|(i, &(name, slope))| Series {
            label: name.to_string(),
            points: (0..9)
                .map(|k| {
                    let t = 1e-3 * 10f64.powf(k as f64 * 0.5);
                    (t, 0.3 * (i as f64 + 1.0) * t.powf(-slope) * 1e-2)
                })
                .collect(),
        })
        .collect();
    series.push(Series {
        label: "with NaN and -1".into(),
        points: vec![(1e-2, 0.5), (f64::NAN, 1.0), (0.1, -1.0), (1.0, 0.05)],
    });
    let chart = Chart {
        title: "Relative error against render time".into(),
        x_label: "time per frame (s)".into(),
        y_label: "relative L1 error".into(),
        series,
        log_x: true,
        log_y: true,
    };
    let dir = std::env::temp_dir();
    let write = |name: &str, svg: String| {
        crate::output::write_text_atomically(&dir.join(name), &svg).unwrap();
    };
    write(
        "plot-demo-chart.svg",
        render_chart(&chart, 800, 500).unwrap(),
    );
    let linear = Chart {
        title: "Linear axes".into(),
        x_label: "samples".into(),
        y_label: "RMSE".into(),
        series: vec![Series {
            label: "rising".into(),
            points: (0..20)
                .map(|i| (i as f64 * 1000.0, (i as f64 * 0.37).sin() * 0.004 + 0.01))
                .collect(),
        }],
        log_x: false,
        log_y: false,
    };
    write(
        "plot-demo-chart-linear.svg",
        render_chart(&linear, 480, 300).unwrap(),
    );

    let image = |seed: u32| {
        let (w, h) = (192u32, 128u32);
        let mut rgb = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let ring = ((x as f32 - 96.0).hypot(y as f32 - 64.0) / 6.0) as u32;
                let v = ((ring + seed) % 4 * 60 + 40) as u8;
                rgb.extend_from_slice(&[v, (x * 255 / w) as u8, (y * 255 / h) as u8]);
            }
        }
        (rgb, w, h)
    };
    let mut rows = Vec::new();
    for r in 0..2 {
        let mut tiles = Vec::new();
        for m in 0..3 {
            let (rgb, w, h) = image(r as u32 * 3 + m);
            let (crop, cw, ch) = crop_magnify(&rgb, w, h, 80, 50, 32, 32, 4).unwrap();
            tiles.push(Some(Tile::new(rgb, w, h).unwrap()));
            if m == 2 {
                tiles.push(Some(Tile::new(crop, cw, ch).unwrap()));
            }
        }
        if r == 1 {
            tiles[1] = None;
        }
        rows.push(tiles);
    }
    let sheet = Sheet { rows };
    render_sheet(&sheet)
        .unwrap()
        .write_png(&dir.join("plot-demo-sheet.png"))
        .unwrap();
}
