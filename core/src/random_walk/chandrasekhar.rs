//! Chandrasekhar's H-function for isotropic scattering, and from it the exact reflectance of
//! an index-matched (η = 1) semi-infinite medium: the independent reference the random walk is
//! checked against.
//!
//! For single-scattering albedo ϖ (here the reduced albedo α′), H solves (Chandrasekhar 1950,
//! *Radiative Transfer*, §34, eq. 22, the form that converges for every ϖ ≤ 1)
//!
//! ```text
//! 1/H(μ) = √(1 − ϖ) + (ϖ/2) ∫₀¹ μ′ H(μ′) / (μ + μ′) dμ′
//! ```
//!
//! and the medium's plane albedo — the fraction of a collimated beam at incidence cosine μ₀
//! that comes back out — is r(μ₀) = 1 − H(μ₀) √(1 − ϖ); under uniform (cosine-weighted)
//! illumination the spherical albedo is 1 − 2 √(1 − ϖ) ∫₀¹ H(μ) μ dμ (§ 47).
//!
//! The integral equation is solved by damped fixed-point iteration on the nodes of a composite
//! Gauss–Legendre rule graded towards μ = 0, where H′ has a logarithmic singularity at ϖ = 1.

use alloc::vec::Vec;

use crate::math;
use crate::quadrature::GaussLegendre;

/// The ends of the composite rule's panels: finer towards 0, where the kernel 1/(μ + μ′) is
/// sharp for small μ and H has a μ ln μ term.
const PANELS: [f64; 8] = [0.0, 1e-4, 1e-3, 0.01, 0.05, 0.2, 0.5, 1.0];

/// Iterations stop when no node's value changes by more than this (relative).
const TOLERANCE: f64 = 1e-14;

/// At most this many iterations (ϖ = 1 converges slowest; it needs a few hundred).
const MAX_ITERATIONS: usize = 20_000;

/// H(μ) for one albedo, kept at the quadrature nodes and evaluated anywhere through the
/// integral equation itself (Nyström interpolation, as accurate as the nodes).
#[derive(Clone, Debug)]
pub struct HFunction {
    albedo: f64,
    /// (μ_j, w_j) of the composite rule on [0, 1].
    points: Vec<(f64, f64)>,
    /// H(μ_j).
    values: Vec<f64>,
}

impl HFunction {
    /// Solves for single-scattering albedo `albedo` ∈ [0, 1] (clamped).
    pub fn new(albedo: f64) -> Self {
        let albedo = albedo.clamp(0.0, 1.0);
        let rule = GaussLegendre::<16>::new();
        let points: Vec<(f64, f64)> = PANELS
            .windows(2)
            .flat_map(|p| rule.points(p[0], p[1]).collect::<Vec<_>>())
            .collect();
        let mut h = HFunction {
            albedo,
            values: alloc::vec![1.0; points.len()],
            points,
        };
        for _ in 0..MAX_ITERATIONS {
            // At ϖ = 1 the plain iteration H ← T(H) only flips a scale error λ to 1/λ (T is
            // homogeneous of degree −1 there), so it never settles; the geometric mean of H and
            // T(H) cancels that mode exactly and leaves the fixed point unchanged.
            let next: Vec<f64> = h
                .points
                .iter()
                .zip(&h.values)
                .map(|(&(mu, _), &old)| math::sqrt64(old * h.eval(mu)))
                .collect();
            let change = next
                .iter()
                .zip(&h.values)
                .map(|(a, b)| ((a - b) / a).abs())
                .fold(0.0, f64::max);
            h.values = next;
            if change < TOLERANCE {
                break;
            }
        }
        h
    }

    /// H(μ) for μ ∈ [0, 1].
    pub fn eval(&self, mu: f64) -> f64 {
        let integral: f64 = self
            .points
            .iter()
            .zip(&self.values)
            .map(|(&(m, w), &h)| w * m * h / (mu + m))
            .sum();
        1.0 / (math::sqrt64(1.0 - self.albedo) + 0.5 * self.albedo * integral)
    }

    /// The n-th moment ∫₀¹ H(μ) μⁿ dμ.
    pub fn moment(&self, n: i32) -> f64 {
        self.points
            .iter()
            .zip(&self.values)
            .map(|(&(m, w), &h)| {
                let mut p = 1.0;
                for _ in 0..n {
                    p *= m;
                }
                w * h * p
            })
            .sum()
    }

    /// The plane albedo r(μ₀) = 1 − H(μ₀) √(1 − ϖ): reflectance of a collimated beam at
    /// incidence cosine μ₀ on an index-matched half-space.
    pub fn plane_albedo(&self, mu0: f64) -> f64 {
        1.0 - self.eval(mu0) * math::sqrt64(1.0 - self.albedo)
    }

    /// The spherical albedo 1 − 2 √(1 − ϖ) ∫₀¹ H(μ) μ dμ: reflectance under uniform
    /// illumination of an index-matched half-space.
    pub fn spherical_albedo(&self) -> f64 {
        1.0 - 2.0 * math::sqrt64(1.0 - self.albedo) * self.moment(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conservative_values_match_the_tables() {
        // ϖ = 1: H(1) = 2.90781 (Chandrasekhar 1950, Table XII); the moments are exact,
        // α₀ = 2 and α₁ = 2/√3 (§ 39).
        let h = HFunction::new(1.0);
        assert!((h.eval(1.0) - 2.90781).abs() < 1e-5, "{}", h.eval(1.0));
        assert!((h.eval(0.0) - 1.0).abs() < 1e-12);
        assert!((h.moment(0) - 2.0).abs() < 1e-9, "{}", h.moment(0));
        let alpha1 = 2.0 / math::sqrt64(3.0);
        assert!((h.moment(1) - alpha1).abs() < 1e-9, "{}", h.moment(1));
        // Nothing is absorbed: every photon comes back.
        assert_eq!(h.plane_albedo(0.4), 1.0);
    }

    #[test]
    fn zeroth_moment_obeys_its_closed_form() {
        // Integrating the equation gives α₀ = (2/ϖ)(1 − √(1 − ϖ)) for every ϖ (§ 39).
        for albedo in [0.1, 0.3, 0.8, 0.99] {
            let h = HFunction::new(albedo);
            let want = 2.0 / albedo * (1.0 - math::sqrt64(1.0 - albedo));
            assert!(
                (h.moment(0) - want).abs() < 1e-9,
                "{albedo}: {}",
                h.moment(0)
            );
        }
    }

    #[test]
    fn weak_scattering_is_single_scattering() {
        // To first order in ϖ, H(μ) = 1 + (ϖ/2) μ ln(1 + 1/μ), and the plane albedo is what
        // single scattering gives: depth τ with density e^(−τ/μ₀)/μ₀, escape along μ with
        // e^(−τ/μ) over half the sphere, so r = (ϖ/2) ∫₀¹ μ/(μ + μ₀) dμ
        // = (ϖ/2)(1 − μ₀ ln(1 + 1/μ₀)).
        let albedo = 1e-4;
        let h = HFunction::new(albedo);
        let ln2 = math::ln64(2.0);
        assert!((h.eval(1.0) - 1.0 - 0.5 * albedo * ln2).abs() < 1e-8);
        let single = 0.5 * albedo * (1.0 - ln2);
        let r = h.plane_albedo(1.0);
        assert!((r - single).abs() / single < 1e-3, "{r} vs {single}");
    }
}
