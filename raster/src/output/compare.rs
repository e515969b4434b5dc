//! Error statistics between a test image and a reference image.
//!
//! All statistics are over the three channels of every included pixel (so `3 · pixels`
//! values), with `d = test − reference` per channel:
//!
//! - **RMSE** = √(Σ d² / (3 · pixels)).
//! - **Mean absolute error** = Σ |d| / (3 · pixels).
//! - **Mean relative L1** = Σ |d| / (|reference| + [`RELATIVE_L1_OFFSET`]) / (3 · pixels).
//!   The offset 0.01 keeps dark reference pixels from dominating (the same role as the 0.01 in
//!   the relative MSE of Rousselle et al. 2011, "Adaptive sampling and reconstruction using
//!   greedy error minimization").
//! - **Maximum absolute error** max |d|, with the pixel and channel where it occurs (the
//!   first in scan order, R before G before B, on ties).
//!
//! An optional mask (one `bool` per pixel, row-major, `true` = include) restricts every
//! statistic to some pixels, e.g. those covered by a translucent object. Sums are accumulated in
//! `f64` in scan order, so the result does not depend on anything but the inputs. Excluded
//! pixels may hold anything; included ones must be finite (an error names the first that is
//! not).

use super::{OutputError, RgbImage};

/// The offset added to the reference magnitude in the relative L1 error.
pub const RELATIVE_L1_OFFSET: f64 = 0.01;

/// The result of [`compare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// Number of pixels compared (all, or those selected by the mask).
    pub pixels: usize,
    /// Root-mean-square error.
    pub rmse: f64,
    /// Mean absolute error.
    pub mean_abs: f64,
    /// Mean relative L1 error (offset [`RELATIVE_L1_OFFSET`]).
    pub mean_relative_l1: f64,
    /// Maximum absolute error.
    pub max_abs: f64,
    /// Pixel `(x, y)` of the maximum absolute error.
    pub max_abs_at: (u32, u32),
    /// Channel (0 = R, 1 = G, 2 = B) of the maximum absolute error.
    pub max_abs_channel: usize,
}

/// Checks sizes and the mask, and that included pixels are finite. Shared with the heat map.
pub(crate) fn check_inputs(
    test: &RgbImage,
    reference: &RgbImage,
    mask: Option<&[bool]>,
) -> Result<(), OutputError> {
    if test.size() != reference.size() {
        return Err(OutputError::SizeMismatch {
            what: "test image vs. reference image",
            expected: reference.size(),
            actual: test.size(),
        });
    }
    let n = reference.pixels().len();
    if let Some(m) = mask {
        if m.len() != n {
            return Err(OutputError::Mask {
                message: format!("{} entries for {n} pixels", m.len()),
            });
        }
        if !m.iter().any(|&b| b) {
            return Err(OutputError::Mask {
                message: "it selects no pixel".to_string(),
            });
        }
    } else if n == 0 {
        return Err(OutputError::Mask {
            message: "the images have no pixels".to_string(),
        });
    }
    let width = reference.width().max(1) as usize;
    for (name, image) in [("test", test), ("reference", reference)] {
        for (i, p) in image.pixels().iter().enumerate() {
            if mask.is_some_and(|m| !m[i]) {
                continue;
            }
            if let Some(channel) = (0..3).find(|&c| !p[c].is_finite()) {
                return Err(OutputError::NonFinite {
                    image: name,
                    x: (i % width) as u32,
                    y: (i / width) as u32,
                    channel,
                    value: p[channel],
                });
            }
        }
    }
    Ok(())
}

/// Compares `test` against `reference` (see the module doc), optionally over a mask.
pub fn compare(
    test: &RgbImage,
    reference: &RgbImage,
    mask: Option<&[bool]>,
) -> Result<ErrorStats, OutputError> {
    check_inputs(test, reference, mask)?;
    let width = reference.width() as usize;
    let mut pixels = 0usize;
    let (mut sum_sq, mut sum_abs, mut sum_rel) = (0.0f64, 0.0f64, 0.0f64);
    let mut max_abs = -1.0f64;
    let (mut max_at, mut max_channel) = ((0u32, 0u32), 0usize);
    for (i, (a, b)) in test.pixels().iter().zip(reference.pixels()).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        pixels += 1;
        for c in 0..3 {
            let d = (a[c] as f64 - b[c] as f64).abs();
            sum_sq += d * d;
            sum_abs += d;
            sum_rel += d / ((b[c] as f64).abs() + RELATIVE_L1_OFFSET);
            if d > max_abs {
                max_abs = d;
                max_at = ((i % width) as u32, (i / width) as u32);
                max_channel = c;
            }
        }
    }
    let values = 3.0 * pixels as f64;
    Ok(ErrorStats {
        pixels,
        rmse: (sum_sq / values).sqrt(),
        mean_abs: sum_abs / values,
        mean_relative_l1: sum_rel / values,
        max_abs,
        max_abs_at: max_at,
        max_abs_channel: max_channel,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn img(w: u32, h: u32, p: &[[f32; 3]]) -> RgbImage {
        RgbImage::from_pixels(w, h, p.iter().map(|&a| Vec3::from_array(a)).collect()).unwrap()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    #[test]
    fn hand_computed_statistics() {
        let test = img(2, 1, &[[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]]);
        let reference = img(2, 1, &[[1.0, 1.0, 1.0], [0.5, 0.0, 0.0]]);
        let s = compare(&test, &reference, None).unwrap();
        // d = (0, 1, 2 | −0.5, 0, 0): Σd² = 5.25, Σ|d| = 3.5 over 6 values.
        assert_eq!(s.pixels, 2);
        assert!(close(s.rmse, (5.25f64 / 6.0).sqrt()), "{}", s.rmse);
        assert!(close(s.mean_abs, 3.5 / 6.0));
        // Relative: 1/1.01 + 2/1.01 + 0.5/0.51 = 3.950689...; / 6.
        let rel = (1.0 / 1.01 + 2.0 / 1.01 + 0.5 / 0.51) / 6.0;
        assert!(
            close(s.mean_relative_l1, rel),
            "{} vs {rel}",
            s.mean_relative_l1
        );
        assert!((s.mean_relative_l1 - 0.658448).abs() < 1e-6);
        assert_eq!(s.max_abs, 2.0);
        assert_eq!((s.max_abs_at, s.max_abs_channel), ((0, 0), 2));
    }

    #[test]
    fn mask_restricts_every_statistic() {
        let test = img(
            2,
            2,
            &[[1.0, 2.0, 3.0], [0.0; 3], [9.0; 3], [0.25, 0.0, 0.0]],
        );
        let reference = img(2, 2, &[[1.0; 3], [0.5, 0.0, 0.0], [0.0; 3], [0.0; 3]]);
        let mask = [false, true, false, true];
        let s = compare(&test, &reference, Some(&mask)).unwrap();
        // Included: pixel (1,0) d = (−0.5, 0, 0), pixel (1,1) d = (0.25, 0, 0).
        assert_eq!(s.pixels, 2);
        assert!(close(s.rmse, ((0.25f64 + 0.0625) / 6.0).sqrt()));
        assert!(close(s.mean_abs, 0.75 / 6.0));
        assert!(close(s.mean_relative_l1, (0.5 / 0.51 + 0.25 / 0.01) / 6.0));
        assert_eq!(s.max_abs, 0.5);
        assert_eq!((s.max_abs_at, s.max_abs_channel), ((1, 0), 0));
    }

    #[test]
    fn identical_images_have_zero_error_and_ties_pick_the_first() {
        let a = img(3, 1, &[[0.2; 3], [5.0; 3], [1.0; 3]]);
        let s = compare(&a, &a, None).unwrap();
        assert_eq!(
            (s.rmse, s.mean_abs, s.mean_relative_l1, s.max_abs),
            (0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!((s.max_abs_at, s.max_abs_channel), ((0, 0), 0));
        let b = img(3, 1, &[[0.2; 3], [5.0, 5.0, 4.0], [1.0, 0.0, 1.0]]);
        let s = compare(&b, &a, None).unwrap();
        assert_eq!(s.max_abs, 1.0);
        assert_eq!((s.max_abs_at, s.max_abs_channel), ((1, 0), 2));
    }

    #[test]
    fn errors() {
        let a = img(2, 1, &[[0.0; 3]; 2]);
        let b = img(1, 2, &[[0.0; 3]; 2]);
        let err = compare(&a, &b, None).unwrap_err();
        assert!(
            err.to_string().contains("expected 1x2 pixels, got 2x1"),
            "{err}"
        );
        let err = compare(&a, &a, Some(&[true])).unwrap_err();
        assert!(err.to_string().contains("1 entries for 2 pixels"), "{err}");
        let err = compare(&a, &a, Some(&[false, false])).unwrap_err();
        assert!(err.to_string().contains("selects no pixel"), "{err}");
        let nan = img(2, 1, &[[0.0; 3], [0.0, f32::NAN, 0.0]]);
        let err = compare(&a, &nan, None).unwrap_err();
        assert_eq!(
            err.to_string(),
            "reference image: pixel (1, 0) channel G is NaN"
        );
        // A non-finite pixel outside the mask is fine.
        assert!(compare(&a, &nan, Some(&[true, false])).is_ok());
        let empty = RgbImage::new(0, 0);
        assert!(compare(&empty, &empty, None).is_err());
    }
}
