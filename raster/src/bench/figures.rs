//! The benchmark's pictures: per scene an error-against-time chart (overall and in the
//! shadow-edge band, SVG) and a contact sheet laid out like Figure 1 of Neulander 2010 (PNG;
//! its caption, the row and column names below, goes into `report.md`).
//!
//! ```text
//!               no smoothing   LM07   edge-aware   edge-refined   ground truth
//! image            ▢            ▢         ▢            ▢             ▢     (inset in yellow)
//! shadow edge ×3   ▢            ▢         ▢            ▢             ▢
//! error            ▢            ▢         ▢            ▢                   (relative, log
//! error ×3         ▢            ▢         ▢            ▢                    scale, one white)
//! ```
//!
//! The charts can be drawn again from a report's `results.csv` ([`replot`]) without running
//! anything.

use std::path::Path;

use super::runner::{MethodSetting, Reference};
use super::{BenchConfig, BenchError, BenchReport, BenchScene};
use crate::output::heatmap::max_pixel_error;
use crate::output::png::encode_srgb8;
use crate::output::{
    ErrorMetric, HeatmapOptions, HeatmapScale, RgbImage, error_heatmap, write_text_atomically,
};
use crate::plot::{Chart, Series, Sheet, Tile, crop_magnify, render_chart, render_sheet};
use crate::scene::SssMethod;

/// Magnification of the shadow-edge insets.
const INSET_ZOOM: u32 = 3;

/// Inset marker colour.
const MARKER: [u8; 3] = [255, 220, 0];

/// One run as a chart point: its series label, render time, and errors.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartPoint {
    /// The series (a method setting's label).
    pub label: String,
    /// Render time in seconds.
    pub time: f64,
    /// Mean relative error over the translucent pixels.
    pub error: f64,
    /// Mean relative error in the shadow-edge band, if the scene has one.
    pub edge_error: Option<f64>,
}

/// The chart files of a scene, without the directory: `<scene>-error-vs-time.svg` and
/// `<scene>-edge-error-vs-time.svg`.
pub fn chart_files(scene: &str) -> [String; 2] {
    [
        format!("{scene}-error-vs-time.svg"),
        format!("{scene}-edge-error-vs-time.svg"),
    ]
}

/// Width and height of the charts.
const CHART_SIZE: (u32, u32) = (800, 560);

/// Writes a scene's two error-against-time charts ([`chart_files`]) into `out`: one series
/// per label, in the order the labels first appear in `points`.
pub fn write_charts(scene: &str, points: &[ChartPoint], out: &Path) -> Result<(), BenchError> {
    let mut labels: Vec<&str> = Vec::new();
    for p in points {
        if !labels.contains(&p.label.as_str()) {
            labels.push(&p.label);
        }
    }
    for (edge, file, what) in [
        (false, &chart_files(scene)[0], "translucent pixels"),
        (true, &chart_files(scene)[1], "shadow-edge band"),
    ] {
        let series = labels
            .iter()
            .map(|&label| Series {
                label: label.to_string(),
                points: points
                    .iter()
                    .filter(|p| p.label == label)
                    .filter_map(|p| Some((p.time, if edge { p.edge_error? } else { p.error })))
                    .collect(),
            })
            .collect();
        let chart = Chart {
            title: format!("{scene}: error against time ({what})"),
            x_label: "render time (s)".to_string(),
            y_label: "mean relative error".to_string(),
            series,
            log_x: true,
            log_y: true,
        };
        let svg = render_chart(&chart, CHART_SIZE.0, CHART_SIZE.1)?;
        write_text_atomically(&out.join(file), &svg)?;
    }
    Ok(())
}

/// Draws the error-against-time charts again from `dir/results.csv` (as [`write_csv`]
/// wrote it) into `dir`, for every scene in it; returns the files written. Only the runs at
/// each scene's own smoothing factor (its first row's) are drawn, like the charts of the run
/// itself; the smoothing sweep's other rows are left out.
///
/// [`write_csv`]: super::write_csv
pub fn replot(dir: &Path) -> Result<Vec<std::path::PathBuf>, BenchError> {
    let path = dir.join("results.csv");
    let text = std::fs::read_to_string(&path).map_err(|e| BenchError::Read {
        path: path.clone(),
        source: e,
    })?;
    let bad = |line: usize, message: String| BenchError::Csv {
        path: path.clone(),
        line,
        message,
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| bad(1, format!("no column '{name}'")))
    };
    let [scene, method, epsilon, smoothing, total, error, edge] = [
        "scene",
        "method",
        "epsilon",
        "smoothing",
        "total_s",
        "error_mean_rel",
        "edge_mean_rel",
    ]
    .map(column);
    let (scene, method, epsilon, smoothing, total, error, edge) =
        (scene?, method?, epsilon?, smoothing?, total?, error?, edge?);
    // Per scene, in the order of the file: its own smoothing factor and its points.
    let mut scenes: Vec<(String, String, Vec<ChartPoint>)> = Vec::new();
    for (index, line) in lines.enumerate().filter(|(_, l)| !l.is_empty()) {
        let number = index + 2;
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            return Err(bad(
                number,
                format!("{} cells, the header has {}", cells.len(), header.len()),
            ));
        }
        let number_at = |c: usize| -> Result<f64, BenchError> {
            cells[c]
                .parse::<f64>()
                .map_err(|_| bad(number, format!("'{}' is not a number", cells[c])))
        };
        let label = if cells[method] == "hierarchical" {
            format!("hierarchical eps={}", cells[epsilon])
        } else {
            cells[method].to_string()
        };
        let point = ChartPoint {
            label,
            time: number_at(total)?,
            error: number_at(error)?,
            edge_error: if cells[edge].is_empty() {
                None
            } else {
                Some(number_at(edge)?)
            },
        };
        let name = cells[scene];
        if !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
            || name.is_empty()
        {
            return Err(bad(number, format!("'{name}' is not a scene name")));
        }
        match scenes.iter_mut().find(|(s, _, _)| s == name) {
            Some((_, k, points)) => {
                if *k == cells[smoothing] {
                    points.push(point);
                }
            }
            None => scenes.push((name.to_string(), cells[smoothing].to_string(), vec![point])),
        }
    }
    let mut written = Vec::new();
    for (name, _, points) in &scenes {
        write_charts(name, points, dir)?;
        written.extend(chart_files(name).iter().map(|f| dir.join(f)));
    }
    Ok(written)
}

/// Writes a scene's charts ([`write_charts`]) and, when the sheet's images are all there,
/// `<scene>-figure1.png`; returns the contact sheet's caption (Markdown) for the report.
pub fn write_scene_figures(
    config: &BenchConfig,
    scene: BenchScene,
    report: &BenchReport,
    reference: &Reference,
    sheet_images: &[(MethodSetting, RgbImage)],
    exposure: f32,
    out: &Path,
) -> Result<Option<String>, BenchError> {
    let points: Vec<ChartPoint> = config
        .settings()
        .into_iter()
        .flat_map(|setting| {
            report
                .runs
                .iter()
                .filter(move |r| r.scene == scene && r.setting == setting)
                .map(move |r| ChartPoint {
                    label: setting.label(),
                    time: r.timings.total.as_secs_f64(),
                    error: r.error.mean_relative_l1,
                    edge_error: r.edge_error.map(|e| e.mean_relative_l1),
                })
        })
        .collect();
    write_charts(scene.name(), &points, out)?;

    let pick = |method: SssMethod| {
        sheet_images
            .iter()
            .filter(|(s, _)| s.method == method)
            .min_by(|a, b| {
                let d = |s: &MethodSetting| (s.epsilon - config.split_epsilon).abs();
                d(&a.0).total_cmp(&d(&b.0))
            })
            .map(|(_, image)| image)
    };
    let (Some(hier), Some(lm), Some(n10), Some(refined)) = (
        pick(SssMethod::Hierarchical),
        pick(SssMethod::LocalGlobal),
        pick(SssMethod::EdgeAware),
        pick(SssMethod::EdgeRefined),
    ) else {
        return Ok(None);
    };
    let (sheet, caption) = figure1(config, reference, [hier, lm, n10, refined], exposure)?;
    render_sheet(&sheet)?.write_png(&out.join(format!("{}-figure1.png", scene.name())))?;
    Ok(Some(caption))
}

/// The inset square: centred on the shadow-edge pixel nearest the band's centroid.
fn inset_rect(reference: &Reference) -> (u32, u32, u32) {
    let (w, h) = reference.image.size();
    let side = (w.min(h) / 6).max(4);
    let mask = if reference.band.contains(&true) {
        &reference.band
    } else {
        &reference.translucent
    };
    let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0.0f64);
    for (i, _) in mask.iter().enumerate().filter(|(_, b)| **b) {
        sx += (i % w as usize) as f64;
        sy += (i / w as usize) as f64;
        n += 1.0;
    }
    let (cx, cy) = if n > 0.0 {
        let (mx, my) = (sx / n, sy / n);
        let nearest = mask
            .iter()
            .enumerate()
            .filter(|(_, b)| **b)
            .map(|(i, _)| ((i % w as usize) as f64, (i / w as usize) as f64))
            .min_by(|a, b| {
                let d = |p: &(f64, f64)| (p.0 - mx).powi(2) + (p.1 - my).powi(2);
                d(a).total_cmp(&d(b))
            })
            .unwrap_or((mx, my));
        (nearest.0 as u32, nearest.1 as u32)
    } else {
        (w / 2, h / 2)
    };
    let x0 = cx.saturating_sub(side / 2).min(w.saturating_sub(side));
    let y0 = cy.saturating_sub(side / 2).min(h.saturating_sub(side));
    (x0, y0, side)
}

/// Draws the outline of the inset square into an RGB buffer.
fn mark(rgb: &mut [u8], width: u32, (x0, y0, side): (u32, u32, u32)) {
    let height = rgb.len() as u32 / 3 / width.max(1);
    let mut put = |x: u32, y: u32| {
        if x < width && y < height {
            let i = (y * width + x) as usize * 3;
            rgb[i..i + 3].copy_from_slice(&MARKER);
        }
    };
    for t in 0..side {
        put(x0 + t, y0);
        put(x0 + t, y0 + side - 1);
        put(x0, y0 + t);
        put(x0 + side - 1, y0 + t);
    }
}

fn tile(rgb: Vec<u8>, width: u32, height: u32) -> Tile {
    Tile { rgb, width, height }
}

fn inset(rgb: &[u8], width: u32, height: u32, rect: (u32, u32, u32)) -> Result<Tile, BenchError> {
    let (bytes, w, h) = crop_magnify(
        rgb, width, height, rect.0, rect.1, rect.2, rect.2, INSET_ZOOM,
    )?;
    Ok(tile(bytes, w, h))
}

fn figure1(
    config: &BenchConfig,
    reference: &Reference,
    tests: [&RgbImage; 4],
    exposure: f32,
) -> Result<(Sheet, String), BenchError> {
    let (w, h) = reference.image.size();
    let rect = inset_rect(reference);
    // One white level for all four error maps: the largest per-pixel relative error.
    let mask = Some(reference.translucent.as_slice());
    let mut white = 0.0f32;
    for image in tests {
        white = white.max(max_pixel_error(
            image,
            &reference.image,
            mask,
            ErrorMetric::Relative,
        )?);
    }
    let options = HeatmapOptions {
        metric: ErrorMetric::Relative,
        scale: HeatmapScale::Log { decades: 3.0 },
        max: (white > 0.0).then_some(white),
    };
    let maps = tests
        .iter()
        .map(|image| error_heatmap(image, &reference.image, mask, &options))
        .collect::<Result<Vec<_>, _>>()?;

    let mut images = Vec::new();
    let mut insets = Vec::new();
    for image in tests.into_iter().chain([&reference.image]) {
        let rgb = encode_srgb8(image, exposure);
        insets.push(Some(inset(&rgb, w, h, rect)?));
        let mut marked = rgb;
        mark(&mut marked, w, rect);
        images.push(Some(tile(marked, w, h)));
    }
    let mut error_maps = Vec::new();
    let mut error_insets = Vec::new();
    for m in &maps {
        error_insets.push(Some(inset(&m.rgb, m.width, m.height, rect)?));
        error_maps.push(Some(tile(m.rgb.clone(), m.width, m.height)));
    }
    error_maps.push(None);
    error_insets.push(None);

    let caption = format!(
        "Columns: no smoothing (JB02, ε {}) · LM07 (local-global) · edge-aware (N10) · \
         edge-refined · ground truth. Rows: image (the inset square in yellow) · shadow edge \
         ×{INSET_ZOOM} · relative error · relative error ×{INSET_ZOOM}. {} samples, {}×{}; \
         error on a log scale over 3 decades, white = {:.1}%.",
        config.split_epsilon,
        config.sheet_count,
        w,
        h,
        white * 100.0
    );
    let sheet = Sheet {
        rows: vec![images, insets, error_maps, error_insets],
    };
    Ok((sheet, caption))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_marker_outlines_the_inset_square() {
        let (w, h) = (10u32, 8u32);
        let mut rgb = vec![0u8; (w * h * 3) as usize];
        mark(&mut rgb, w, (2, 1, 4));
        let at = |x: u32, y: u32| &rgb[((y * w + x) * 3) as usize..][..3];
        assert_eq!(at(2, 1), MARKER);
        assert_eq!(at(5, 4), MARKER);
        assert_eq!(at(3, 2), [0, 0, 0], "inside stays");
        assert_eq!(at(6, 1), [0, 0, 0], "outside stays");
    }
}
