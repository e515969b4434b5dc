//! Error heat maps: per-pixel error between two images as a colour-ramp PNG.
//!
//! Per-pixel error `e` is the mean over R, G, B of `|test − reference|` ([`ErrorMetric::Absolute`])
//! or of `|test − reference| / (|reference| + 0.01)` ([`ErrorMetric::Relative`], the offset is
//! [`RELATIVE_L1_OFFSET`]).
//!
//! Scale: `e` is mapped to `t ∈ [0, 1]` and `t` to a colour by [`ramp`].
//!
//! - [`HeatmapScale::Linear`]: `t = e / white`, so 0 → black and `white` (or more) → white.
//! - [`HeatmapScale::Log`] with `decades` D: `t = 1 + log10(e / white) / D`, so
//!   `white · 10^−D` (or less, including 0) → black and `white` → white.
//!
//! `white` is [`HeatmapOptions::max`] if given (to make heat maps of several renders
//! comparable), otherwise the largest per-pixel error among the included pixels; it is returned
//! in [`Heatmap::white`] so the caller can print the legend. Pixels excluded by the mask are
//! drawn in [`MASKED_COLOUR`], a dark teal that is not on the ramp.
//!
//! # The ramp
//!
//! Piecewise linear in 8-bit sRGB between five stops: black (0, 0, 0) → violet (60, 0, 110) →
//! crimson (205, 30, 110) → light orange (255, 160, 110) → white (255, 255, 255), at
//! t = 0, ¼, ½, ¾, 1 (relative luminance 0, 0.021, 0.150, 0.475, 1). No channel ever
//! decreases along the ramp, so its luminance never decreases, even after rounding to 8 bits
//! (tested), and rises strictly from stop to stop: brighter always means larger error, also in
//! grey-scale print, while the hue change helps tell neighbouring levels apart.

use std::path::Path;

use super::compare::{RELATIVE_L1_OFFSET, check_inputs};
use super::png::write_png_rgb8;
use super::{OutputError, RgbImage};

/// The ramp's stops: (t, sRGB8 colour).
const STOPS: [(f32, [u8; 3]); 5] = [
    (0.0, [0, 0, 0]),
    (0.25, [60, 0, 110]),
    (0.5, [205, 30, 110]),
    (0.75, [255, 160, 110]),
    (1.0, [255, 255, 255]),
];

/// Colour of pixels excluded by the mask.
pub const MASKED_COLOUR: [u8; 3] = [0, 80, 80];

/// Which per-pixel error to map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ErrorMetric {
    /// Mean over channels of `|test − reference|`.
    #[default]
    Absolute,
    /// Mean over channels of `|test − reference| / (|reference| + 0.01)`.
    Relative,
}

/// How errors map to the ramp.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum HeatmapScale {
    /// `t = e / white`.
    #[default]
    Linear,
    /// `t = 1 + log10(e / white) / decades`.
    Log {
        /// How many factors of ten below `white` are still distinguished from black (> 0).
        decades: f32,
    },
}

/// Heat-map settings.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct HeatmapOptions {
    /// The per-pixel error.
    pub metric: ErrorMetric,
    /// Linear or logarithmic.
    pub scale: HeatmapScale,
    /// The error shown as white; `None` = the largest per-pixel error. Must be finite and > 0.
    pub max: Option<f32>,
}

/// An error heat map: 8-bit sRGB pixels plus its scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Heatmap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Interleaved RGB bytes, row-major, top row first.
    pub rgb: Vec<u8>,
    /// The error mapped to white.
    pub white: f32,
    /// The largest error mapped to black (0 on the linear scale).
    pub black: f32,
}

impl Heatmap {
    /// Writes the heat map as a PNG, atomically.
    pub fn write_png(&self, path: &Path) -> Result<(), OutputError> {
        write_png_rgb8(path, self.width, self.height, &self.rgb)
    }
}

/// The ramp colour at `t` (clamped to [0, 1]; NaN gives black).
pub fn ramp(t: f32) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let mut k = 0;
    while k + 2 < STOPS.len() && t > STOPS[k + 1].0 {
        k += 1;
    }
    let ((t0, c0), (t1, c1)) = (STOPS[k], STOPS[k + 1]);
    let u = (t - t0) / (t1 - t0);
    let mix = |a: u8, b: u8| (a as f32 + (b as f32 - a as f32) * u).round() as u8;
    [mix(c0[0], c1[0]), mix(c0[1], c1[1]), mix(c0[2], c1[2])]
}

/// The per-pixel error of one pixel pair.
fn pixel_error(metric: ErrorMetric, a: glam::Vec3, b: glam::Vec3) -> f32 {
    let mut sum = 0.0f64;
    for c in 0..3 {
        let d = (a[c] as f64 - b[c] as f64).abs();
        sum += match metric {
            ErrorMetric::Absolute => d,
            ErrorMetric::Relative => d / ((b[c] as f64).abs() + RELATIVE_L1_OFFSET),
        };
    }
    (sum / 3.0) as f32
}

fn pixel_errors(test: &RgbImage, reference: &RgbImage, metric: ErrorMetric) -> Vec<f32> {
    test.pixels()
        .iter()
        .zip(reference.pixels())
        .map(|(&a, &b)| pixel_error(metric, a, b))
        .collect()
}

fn largest_included(errors: &[f32], mask: Option<&[bool]>) -> f32 {
    errors
        .iter()
        .enumerate()
        .filter(|&(i, _)| mask.is_none_or(|m| m[i]))
        .fold(0.0f32, |m, (_, &e)| m.max(e))
}

/// The largest per-pixel error over the included pixels: the white level a heat map gets
/// without [`HeatmapOptions::max`]. The largest over several images gives their heat maps one
/// scale.
pub fn max_pixel_error(
    test: &RgbImage,
    reference: &RgbImage,
    mask: Option<&[bool]>,
    metric: ErrorMetric,
) -> Result<f32, OutputError> {
    check_inputs(test, reference, mask)?;
    Ok(largest_included(
        &pixel_errors(test, reference, metric),
        mask,
    ))
}

/// Builds the heat map of `test` against `reference` (see the module doc).
pub fn error_heatmap(
    test: &RgbImage,
    reference: &RgbImage,
    mask: Option<&[bool]>,
    options: &HeatmapOptions,
) -> Result<Heatmap, OutputError> {
    check_inputs(test, reference, mask)?;
    if let Some(max) = options.max
        && !(max.is_finite() && max > 0.0)
    {
        return Err(OutputError::invalid(
            "",
            format!("heat-map maximum {max} must be > 0"),
        ));
    }
    if let HeatmapScale::Log { decades } = options.scale
        && !(decades.is_finite() && decades > 0.0)
    {
        return Err(OutputError::invalid(
            "",
            format!("heat-map log scale needs a positive number of decades, got {decades}"),
        ));
    }

    let included = |i: usize| mask.is_none_or(|m| m[i]);
    let errors = pixel_errors(test, reference, options.metric);
    let white = options
        .max
        .unwrap_or_else(|| largest_included(&errors, mask));
    let black = match options.scale {
        HeatmapScale::Linear => 0.0,
        HeatmapScale::Log { decades } => white * 10f32.powf(-decades),
    };

    let mut rgb = Vec::with_capacity(errors.len() * 3);
    for (i, &e) in errors.iter().enumerate() {
        let colour = if !included(i) {
            MASKED_COLOUR
        } else if white <= 0.0 || e <= 0.0 {
            STOPS[0].1
        } else {
            let t = match options.scale {
                HeatmapScale::Linear => e / white,
                HeatmapScale::Log { decades } => 1.0 + (e / white).log10() / decades,
            };
            ramp(t)
        };
        rgb.extend_from_slice(&colour);
    }
    Ok(Heatmap {
        width: reference.width(),
        height: reference.height(),
        rgb,
        white,
        black,
    })
}

#[cfg(test)]
mod tests {
    use super::super::atomic::tests::TestDir;
    use super::super::srgb::srgb8_to_linear_table;
    use super::*;
    use glam::Vec3;

    fn img(w: u32, h: u32, p: &[[f32; 3]]) -> RgbImage {
        RgbImage::from_pixels(w, h, p.iter().map(|&a| Vec3::from_array(a)).collect()).unwrap()
    }

    fn luminance(c: [u8; 3]) -> f32 {
        let t = srgb8_to_linear_table();
        0.2126 * t[c[0] as usize] + 0.7152 * t[c[1] as usize] + 0.0722 * t[c[2] as usize]
    }

    #[test]
    fn ramp_hits_its_stops_and_interpolates() {
        for (t, c) in STOPS {
            assert_eq!(ramp(t), c);
        }
        // Midway between violet and crimson: (132.5, 15, 110) → (133, 15, 110).
        assert_eq!(ramp(0.375), [133, 15, 110]);
        assert_eq!(ramp(-1.0), [0, 0, 0]);
        assert_eq!(ramp(2.0), [255, 255, 255]);
        assert_eq!(ramp(f32::NAN), [0, 0, 0]);
    }

    #[test]
    fn ramp_luminance_increases_strictly() {
        for pair in STOPS.windows(2) {
            let ((_, a), (_, b)) = (pair[0], pair[1]);
            assert!(
                (0..3).all(|c| a[c] <= b[c]),
                "a channel decreases from {a:?} to {b:?}"
            );
        }
        let mut previous = -1.0;
        for k in 0..=1000 {
            let y = luminance(ramp(k as f32 / 1000.0));
            // Rounding to 8 bits can repeat a colour between close samples; never go down.
            assert!(
                y >= previous,
                "luminance drops at t = {}",
                k as f32 / 1000.0
            );
            previous = y;
        }
        let mut previous = -1.0;
        for k in 0..=50 {
            let y = luminance(ramp(k as f32 / 50.0));
            assert!(
                y > previous,
                "luminance not rising at t = {}",
                k as f32 / 50.0
            );
            previous = y;
        }
        assert!(luminance(MASKED_COLOUR) > 0.0);
    }

    #[test]
    fn linear_scale_hand_values() {
        // Absolute per-pixel errors: 0, 0.5, 1.0, 2.0 (mean over channels).
        let reference = img(4, 1, &[[0.0; 3]; 4]);
        let test = img(
            4,
            1,
            &[[0.0; 3], [1.5, 0.0, 0.0], [1.0; 3], [6.0, 0.0, 0.0]],
        );
        let h = error_heatmap(&test, &reference, None, &HeatmapOptions::default()).unwrap();
        assert_eq!((h.white, h.black), (2.0, 0.0));
        let px = |i: usize| [h.rgb[3 * i], h.rgb[3 * i + 1], h.rgb[3 * i + 2]];
        assert_eq!(px(0), [0, 0, 0]);
        assert_eq!(px(1), [60, 0, 110]); // t = 0.25
        assert_eq!(px(2), [205, 30, 110]); // t = 0.5
        assert_eq!(px(3), [255, 255, 255]); // t = 1

        // Fixed maximum 4: t = 0.125 for e = 0.5 → halfway black..violet = (30, 0, 55).
        let opts = HeatmapOptions {
            max: Some(4.0),
            ..Default::default()
        };
        let h = error_heatmap(&test, &reference, None, &opts).unwrap();
        assert_eq!(&h.rgb[3..6], &[30, 0, 55]);
        assert_eq!(&h.rgb[9..12], &[205, 30, 110]);
    }

    #[test]
    fn max_pixel_error_is_the_default_white() {
        // Absolute per-pixel errors 0, 0.5, 1.0, 2.0; the mask drops the last.
        let reference = img(4, 1, &[[0.0; 3]; 4]);
        let test = img(
            4,
            1,
            &[[0.0; 3], [1.5, 0.0, 0.0], [1.0; 3], [6.0, 0.0, 0.0]],
        );
        let mask = [true, true, true, false];
        for m in [None, Some(&mask[..])] {
            let white = error_heatmap(&test, &reference, m, &HeatmapOptions::default())
                .unwrap()
                .white;
            let max = max_pixel_error(&test, &reference, m, ErrorMetric::Absolute).unwrap();
            assert_eq!(max, white);
            assert_eq!(max, if m.is_some() { 1.0 } else { 2.0 });
        }
        assert!(
            max_pixel_error(
                &test,
                &img(3, 1, &[[0.0; 3]; 3]),
                None,
                ErrorMetric::Absolute
            )
            .is_err()
        );
    }

    #[test]
    fn log_scale_and_relative_metric_and_mask() {
        let reference = img(4, 1, &[[1.0; 3]; 4]);
        // Relative errors |d| / 1.01 per channel: set d so that e = 1, 0.1, 0.01, 0.001 · 1.01.
        let d = |e: f32| 1.0 + e * 1.01;
        let test = img(
            4,
            1,
            &[[d(1.0); 3], [d(0.1); 3], [d(0.01); 3], [d(0.001); 3]],
        );
        let opts = HeatmapOptions {
            metric: ErrorMetric::Relative,
            scale: HeatmapScale::Log { decades: 2.0 },
            max: None,
        };
        let h = error_heatmap(&test, &reference, None, &opts).unwrap();
        assert!(
            (h.white - 1.0).abs() < 1e-6 && (h.black - 0.01).abs() < 1e-8,
            "{h:?}"
        );
        // t = 1, 0.5, 0 (=black at 10^−2), clamped 0.
        assert_eq!(&h.rgb[0..3], &[255, 255, 255]);
        assert_eq!(&h.rgb[3..6], &[205, 30, 110]);
        assert_eq!(&h.rgb[9..12], &[0, 0, 0]);
        assert!(h.rgb[6..9].iter().all(|&c| c <= 1), "{:?}", &h.rgb[6..9]);

        // Masking the largest error changes the automatic maximum; excluded pixel is teal.
        let mask = [false, true, true, true];
        let h = error_heatmap(&test, &reference, Some(&mask), &opts).unwrap();
        assert!((h.white - 0.1).abs() < 1e-6);
        assert_eq!(&h.rgb[0..3], &MASKED_COLOUR);
        assert_eq!(&h.rgb[3..6], &[255, 255, 255]);
    }

    #[test]
    fn identical_images_are_black_and_bad_options_fail() {
        let a = img(2, 1, &[[0.3; 3]; 2]);
        let h = error_heatmap(&a, &a, None, &HeatmapOptions::default()).unwrap();
        assert!(h.rgb.iter().all(|&c| c == 0));
        assert_eq!(h.white, 0.0);
        for opts in [
            HeatmapOptions {
                max: Some(0.0),
                ..Default::default()
            },
            HeatmapOptions {
                max: Some(f32::NAN),
                ..Default::default()
            },
            HeatmapOptions {
                scale: HeatmapScale::Log { decades: 0.0 },
                ..Default::default()
            },
        ] {
            assert!(error_heatmap(&a, &a, None, &opts).is_err(), "{opts:?}");
        }
        let b = img(1, 1, &[[0.0; 3]]);
        assert!(error_heatmap(&a, &b, None, &HeatmapOptions::default()).is_err());
    }

    #[test]
    fn writes_a_png_that_reads_back() {
        let dir = TestDir::new("heatmap-png");
        let path = dir.path("h.png");
        let reference = img(3, 1, &[[0.0; 3]; 3]);
        let test = img(3, 1, &[[0.0; 3], [1.0; 3], [2.0; 3]]);
        let h = error_heatmap(&test, &reference, None, &HeatmapOptions::default()).unwrap();
        h.write_png(&path).unwrap();
        let back = super::super::png::read_png(&path).unwrap();
        let t = srgb8_to_linear_table();
        assert_eq!(back.pixels()[1], Vec3::new(t[205], t[30], t[110]));
        assert_eq!(back.pixels()[2], Vec3::ONE);
    }
}
