//! Where the split methods' error comes from (claim 2): the global sum, which local-global and
//! edge-aware compute alike, or the local term, where they differ.
//!
//! The truth is split at the test runs' own smoothing radius. The ground truth's scene is
//! rendered again with the smoothing factor scaled by √(truth samples / test samples), so that
//! α = k·√Ā — and with it the kernel w that divides the two terms — is the test runs' α. That
//! render's `global` layer is the exact global term Σ(1 − w)·Rd·E·A at that α, to the truth's
//! own accuracy, and the truth's exitance minus it is the exact local term. Each test run's
//! `global` and `local` layers are compared with those.
//!
//! Errors here are Σ|test − exact| / Σ|truth| over the region's pixels and the three
//! channels, in exitance: a share of the truth, so that the two parts and the total can be
//! read against each other (the other tables use the offset-relative radiance error).

use glam::Vec3;

use crate::render::PixelValue;

/// The total, global-term and local-term errors of one run over one region.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TermErrors {
    /// Σ|M − M_truth| / Σ|M_truth|.
    pub total: f64,
    /// Σ|global − global_exact| / Σ|M_truth|.
    pub global: f64,
    /// Σ|local − (M_truth − global_exact)| / Σ|M_truth|.
    pub local: f64,
}

/// The error split of one run: `truth` is the ground truth's exitance per pixel,
/// `exact_global` the global layer of the truth re-rendered at the run's α, `run` the run's
/// pixels, `mask` the region. Zero everywhere if the region holds no light.
pub fn term_errors(
    truth: &[Vec3],
    exact_global: &[Vec3],
    run: &[PixelValue],
    mask: &[bool],
) -> TermErrors {
    let (mut scale, mut total, mut global, mut local) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let sum = |v: Vec3| v.abs().to_array().iter().map(|&x| x as f64).sum::<f64>();
    for i in 0..truth
        .len()
        .min(exact_global.len())
        .min(run.len())
        .min(mask.len())
    {
        if !mask[i] {
            continue;
        }
        let (t, g, p) = (truth[i], exact_global[i], &run[i]);
        scale += sum(t);
        total += sum(p.exitance - t);
        global += sum(p.global - g);
        local += sum(p.local - (t - g));
    }
    if !(scale > 0.0) {
        return TermErrors::default();
    }
    TermErrors {
        total: total / scale,
        global: global / scale,
        local: local / scale,
    }
}

/// The smoothing factor at which `truth_samples` samples have the α of `test_samples` samples
/// with factor `k` (α = k·√Ā and Ā ∝ 1 / samples on the same surfaces).
pub fn matched_smoothing(k: f32, truth_samples: usize, test_samples: usize) -> f32 {
    k * (truth_samples as f64 / test_samples.max(1) as f64).sqrt() as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(exitance: f32, local: f32, global: f32) -> PixelValue {
        PixelValue {
            exitance: Vec3::splat(exitance),
            local: Vec3::splat(local),
            global: Vec3::splat(global),
            ..PixelValue::default()
        }
    }

    #[test]
    fn errors_split_into_the_two_terms_by_hand() {
        // Truth 4 and 2, exact global 3 and 1 (so exact local 1 and 1). The run: local 1.5,
        // global 3 → total off by 0.5; local 1, global 0.5 → total off by 0.5.
        let truth = [Vec3::splat(4.0), Vec3::splat(2.0), Vec3::splat(100.0)];
        let exact = [Vec3::splat(3.0), Vec3::splat(1.0), Vec3::splat(50.0)];
        let run = [
            pixel(4.5, 1.5, 3.0),
            pixel(1.5, 1.0, 0.5),
            pixel(0.0, 0.0, 0.0),
        ];
        let e = term_errors(&truth, &exact, &run, &[true, true, false]);
        // Σ|truth| = 3·(4 + 2) = 18; totals 3·0.5 + 3·0.5 = 3; global 3·0.5; local 3·0.5.
        assert!((e.total - 3.0 / 18.0).abs() < 1e-12, "{e:?}");
        assert!((e.global - 1.5 / 18.0).abs() < 1e-12, "{e:?}");
        assert!((e.local - 1.5 / 18.0).abs() < 1e-12, "{e:?}");
        // A dark region gives zeros, not NaN.
        let dark = term_errors(
            &[Vec3::ZERO],
            &[Vec3::ZERO],
            &[pixel(1.0, 1.0, 0.0)],
            &[true],
        );
        assert_eq!(dark, TermErrors::default());
    }

    #[test]
    fn matched_smoothing_keeps_alpha() {
        // α ∝ k / √samples.
        let k = matched_smoothing(1.5, 1_600_000, 25_000);
        assert!((k - 12.0).abs() < 1e-5, "{k}");
        let alpha = |k: f32, n: f64| k as f64 / n.sqrt();
        assert!((alpha(k, 1.6e6) - alpha(1.5, 2.5e4)).abs() < 1e-9);
    }
}
