//! Noise: how much an image changes when only the irradiance samples' seed changes.
//!
//! Point-based subsurface scattering with too few samples shows low-frequency blotches that
//! move with the sample placement (flicker in animation). This needs no ground truth: render
//! the same scene with `n ≥ 2` seeds and take, per pixel and channel, the sample standard
//! deviation `s` (denominator `n − 1`) of the `n` values. Reported over the included pixels
//! (all, or a mask), `3 · pixels` values in all:
//!
//! - **RMS noise** = √(Σ s² / (3 · pixels)): in the image's units.
//! - **Mean relative noise** = Σ s / (|mean| + [`RELATIVE_L1_OFFSET`]) / (3 · pixels): the
//!   same normalisation as the mean relative L1 error of [`compare()`](super::compare()), so the
//!   two can be read side by side.
//!
//! Sums are in `f64` in scan order (deterministic).

use super::compare::check_inputs;
use super::{OutputError, RELATIVE_L1_OFFSET, RgbImage};

/// The result of [`seed_noise`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseStats {
    /// Renders compared.
    pub renders: usize,
    /// Pixels included.
    pub pixels: usize,
    /// Root-mean-square per-pixel standard deviation.
    pub rms: f64,
    /// Mean relative standard deviation (offset [`RELATIVE_L1_OFFSET`]).
    pub mean_relative: f64,
}

/// Per-pixel standard deviation across `renders` (same scene, different sample seeds); see
/// the module doc. Needs at least two images of one size, finite where included.
pub fn seed_noise(renders: &[&RgbImage], mask: Option<&[bool]>) -> Result<NoiseStats, OutputError> {
    let [first, rest @ ..] = renders else {
        return Err(OutputError::Mask {
            message: "noise needs at least two renders, got none".to_string(),
        });
    };
    if rest.is_empty() {
        return Err(OutputError::Mask {
            message: "noise needs at least two renders, got one".to_string(),
        });
    }
    for image in rest {
        check_inputs(image, first, mask)?;
    }
    let n = renders.len() as f64;
    let (mut pixels, mut sum_var, mut sum_rel) = (0usize, 0.0f64, 0.0f64);
    for i in 0..first.pixels().len() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        pixels += 1;
        for c in 0..3 {
            let mean = renders.iter().map(|r| r.pixels()[i][c] as f64).sum::<f64>() / n;
            let var = renders
                .iter()
                .map(|r| (r.pixels()[i][c] as f64 - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0);
            sum_var += var;
            sum_rel += var.sqrt() / (mean.abs() + RELATIVE_L1_OFFSET);
        }
    }
    let values = 3.0 * pixels as f64;
    Ok(NoiseStats {
        renders: renders.len(),
        pixels,
        rms: (sum_var / values).sqrt(),
        mean_relative: sum_rel / values,
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    fn image(values: &[f32]) -> RgbImage {
        RgbImage::from_pixels(
            values.len() as u32,
            1,
            values.iter().map(|&v| Vec3::splat(v)).collect(),
        )
        .unwrap()
    }

    #[test]
    fn matches_the_sample_standard_deviation_by_hand() {
        // Pixel 0: values 1, 3 → mean 2, s = √2. Pixel 1: 5, 5 → s = 0.
        let (a, b) = (image(&[1.0, 5.0]), image(&[3.0, 5.0]));
        let s = seed_noise(&[&a, &b], None).unwrap();
        assert_eq!((s.renders, s.pixels), (2, 2));
        // RMS over 6 values: √((3 · 2 + 3 · 0) / 6) = 1.
        assert!((s.rms - 1.0).abs() < 1e-12, "{s:?}");
        let rel = (2f64.sqrt() / 2.01) / 2.0;
        assert!((s.mean_relative - rel).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn identical_renders_have_no_noise_and_masks_select() {
        let a = image(&[1.0, 2.0, 3.0]);
        let s = seed_noise(&[&a, &a, &a], None).unwrap();
        assert_eq!((s.rms, s.mean_relative), (0.0, 0.0));
        let b = image(&[1.0, 2.0, 9.0]);
        let masked = seed_noise(&[&a, &b], Some(&[true, true, false])).unwrap();
        assert_eq!((masked.pixels, masked.rms), (2, 0.0));
    }

    #[test]
    fn rejects_too_few_or_mismatched_renders() {
        let a = image(&[1.0, 2.0]);
        assert!(seed_noise(&[], None).is_err());
        assert!(seed_noise(&[&a], None).is_err());
        assert!(seed_noise(&[&a, &image(&[1.0])], None).is_err());
        assert!(seed_noise(&[&a, &image(&[1.0, f32::NAN])], None).is_err());
    }
}
