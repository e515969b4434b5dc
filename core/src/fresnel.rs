//! Fresnel terms at a smooth dielectric boundary (`docs/physics.md` §3; §17 for
//! their use in the exitance → radiance conversion).
//!
//! η is always the relative index inside / outside (1.3 skin, 1.5 marble).

use crate::math;
use crate::quadrature::GaussLegendre;

/// Unpolarised Fresnel reflectance for light arriving from outside (index 1) into a medium of
/// relative index `eta`, at incidence cosine `cos_i` ∈ [0, 1]. Also valid for `eta < 1`
/// (light leaving a denser medium), where it returns 1 beyond the critical angle.
pub fn reflectance(eta: f64, cos_i: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0; // total internal reflection
    }
    let cos_t = math::sqrt64(1.0 - sin2_t);
    let r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// Fresnel transmittance F_t(η, μ) = 1 − F_r(η, μ) into the medium (single precision, for
/// shading).
pub fn transmittance(eta: f32, cos_i: f32) -> f32 {
    (1.0 - reflectance(eta as f64, cos_i as f64)) as f32
}

/// Internal diffuse Fresnel reflectance F_dr(η), the J01 fit
/// −1.440/η² + 0.710/η + 0.668 + 0.0636 η (Jensen et al. 2001, eq. after (5); good for η ≥ 1).
/// This is the value the dipole's boundary term A uses.
pub fn diffuse_reflectance_internal_fit(eta: f64) -> f64 {
    -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
}

/// Exact diffuse Fresnel reflectance 2∫₀¹ F_r(η, μ) μ dμ: the fraction of a uniform (cosine-
/// weighted) radiance field that the boundary reflects. With `eta` > 1 this is the external
/// value (light arriving from outside); with 1/η the internal one.
pub fn diffuse_reflectance_exact(eta: f64) -> f64 {
    let rule = GaussLegendre::<32>::new();
    let f = |mu: f64| reflectance(eta, mu) * mu;
    // Split at the critical angle, where F_r has a kink (only exists for η < 1).
    let mu_c = if eta < 1.0 {
        math::sqrt64(1.0 - eta * eta)
    } else {
        0.0
    };
    let mut total = mu_c * mu_c * 0.5; // ∫₀^μc 1·μ dμ (total internal reflection)
    // F_r varies fastest near grazing incidence: split the smooth part in two.
    let split = mu_c + (1.0 - mu_c) * 0.25;
    total += rule.integrate(mu_c, split, f);
    total += rule.integrate(split, 1.0, f);
    2.0 * total
}

/// The Fresnel moment Cₙ = ∫₀¹ F_r(η, μ) μⁿ dμ of d'Eon's better dipole (2012), for light
/// meeting the boundary from the side of relative index 1/`eta` (pass 1/η for the internal
/// moments of a medium of index η). 2C₁ is [`diffuse_reflectance_exact`].
pub fn moment(eta: f64, n: u32) -> f64 {
    let rule = GaussLegendre::<32>::new();
    let power = |mu: f64| (0..n).fold(1.0, |acc, _| acc * mu);
    let f = |mu: f64| reflectance(eta, mu) * power(mu);
    let mu_c = if eta < 1.0 {
        math::sqrt64(1.0 - eta * eta)
    } else {
        0.0
    };
    // ∫₀^μc μⁿ dμ under total internal reflection.
    let mut total = power(mu_c) * mu_c / (n as f64 + 1.0);
    let split = mu_c + (1.0 - mu_c) * 0.25;
    total += rule.integrate(mu_c, split, f);
    total += rule.integrate(split, 1.0, f);
    total
}

/// pbrt-v2's polynomial fit of the external diffuse reflectance, evaluated at x = 1/η
/// (`docs/physics.md` §3). Kept to cross-check [`diffuse_reflectance_exact`].
pub fn diffuse_reflectance_external_fit(eta: f64) -> f64 {
    let x = 1.0 / eta;
    -0.4399 + 0.7099 / x - 0.3319 / (x * x) + 0.0636 / (x * x * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values from `docs/physics.md` §3 (exact hemispherical integrals).
    const EXTERNAL: [(f64, f64); 5] = [
        (1.2, 0.0443),
        (1.3, 0.0611),
        (1.4, 0.0768),
        (1.5, 0.0918),
        (2.0, 0.1606),
    ];
    const INTERNAL: [(f64, f64); 5] = [
        (1.2, 0.3363),
        (1.3, 0.4445),
        (1.4, 0.5290),
        (1.5, 0.5963),
        (2.0, 0.7901),
    ];

    #[test]
    fn exact_external_matches_reference_values() {
        for (eta, want) in EXTERNAL {
            let got = diffuse_reflectance_exact(eta);
            assert!((got - want).abs() < 6e-5, "eta {eta}: {got} vs {want}");
        }
    }

    #[test]
    fn exact_internal_matches_reference_values_and_the_fit() {
        for (eta, want) in INTERNAL {
            let got = diffuse_reflectance_exact(1.0 / eta);
            assert!((got - want).abs() < 6e-5, "eta {eta}: {got} vs {want}");
            // The J01 fit is good to about 1% over this range.
            let fit = diffuse_reflectance_internal_fit(eta);
            assert!((fit - want).abs() < 0.01, "eta {eta}: fit {fit} vs {want}");
        }
        assert!((diffuse_reflectance_internal_fit(1.3) - 0.4448).abs() < 1e-4);
    }

    #[test]
    fn pbrt_fit_agrees_with_exact_external() {
        assert!((diffuse_reflectance_external_fit(1.3) - 0.0618).abs() < 1e-4);
        for (eta, want) in EXTERNAL {
            assert!((diffuse_reflectance_external_fit(eta) - want).abs() < 0.003);
        }
    }

    /// 2C₁ is the diffuse reflectance; every moment of a perfect mirror (η → 0 side) is
    /// 1/(n + 1); index-matched boundaries reflect nothing.
    #[test]
    fn moments() {
        for eta in [1.1, 1.3, 1.5, 2.0] {
            let c1 = moment(1.0 / eta, 1);
            assert!((2.0 * c1 - diffuse_reflectance_exact(1.0 / eta)).abs() < 1e-12);
            assert!(moment(1.0 / eta, 2) < c1 && moment(1.0 / eta, 2) > 0.0);
        }
        assert!(moment(1.0, 1).abs() < 1e-15 && moment(1.0, 2).abs() < 1e-15);
        for n in 0..4 {
            let m = moment(1e-9, n);
            assert!((m - 1.0 / (n as f64 + 1.0)).abs() < 1e-6, "{n}: {m}");
        }
    }

    #[test]
    fn reflectance_limits() {
        // Normal incidence: ((η − 1)/(η + 1))².
        let r0 = reflectance(1.5, 1.0);
        assert!((r0 - 0.04).abs() < 1e-12);
        assert_eq!(reflectance(1.5, 0.0), 1.0);
        assert!(reflectance(1.0, 0.3).abs() < 1e-15);
        assert_eq!(reflectance(1.0 / 1.5, 0.1), 1.0); // beyond the critical angle
        assert!((transmittance(1.5, 1.0) - 0.96).abs() < 1e-6);
    }
}
