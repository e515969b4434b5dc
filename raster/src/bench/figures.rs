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
//! The charts are drawn by [`charts`](super::charts).

use std::path::Path;

use super::charts::{ChartPoint, write_charts};
use super::runner::{MethodSetting, Reference};
use super::{BenchConfig, BenchError, BenchReport, BenchScene};
use crate::output::heatmap::max_pixel_error;
use crate::output::png::encode_srgb8;
use crate::output::{ErrorMetric, HeatmapOptions, HeatmapScale, RgbImage, error_heatmap};
use crate::plot::{Sheet, Tile, crop_magnify, render_sheet};
use lucent_core::Method;

/// Magnification of the shadow-edge insets.
const INSET_ZOOM: u32 = 3;

/// Inset marker colour.
const MARKER: [u8; 3] = [255, 220, 0];

/// Writes a scene's charts ([`super::write_charts`]) and, when the sheet's images are all there,
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

    let pick = |method: Method| {
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
        pick(Method::Hierarchical),
        pick(Method::LocalGlobal),
        pick(Method::EdgeAware),
        pick(Method::EdgeRefined),
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
