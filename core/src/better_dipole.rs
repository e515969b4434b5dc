//! d'Eon's better dipole (2012, "A better dipole"; `docs/physics.md` §18), one colour channel:
//! the classical dipole's two sources with Grosjean's diffusion coefficient, a boundary term
//! from the Fresnel moments, and the exitance taken from both the fluence φ and the flux E:
//!
//! ```text
//! D = (2σ_a + σ_s′)/(3σ_t′²),  σ_tr = √(σ_a/D),  A = (1 + 3C₂)/(1 − 2C₁)
//! z_r = 1/σ_t′,  z_v = −z_r − 4AD  (the virtual source above the surface)
//! R(r) = α′ [ C_φ φ(r) + C_E E(r) ],  C_φ = (1 − 2C₁)/4,  C_E = (1 − 3C₂)/2
//! φ(r) = (e^(−σ_tr d_r)/d_r − e^(−σ_tr d_v)/d_v) / (4πD)
//! E(r) = (z_r (1 + σ_tr d_r) e^(−σ_tr d_r)/d_r³ − z_v (1 + σ_tr d_v) e^(−σ_tr d_v)/d_v³) / (4π)
//! ```
//!
//! with Cₙ = ∫₀¹ F_r μⁿ dμ the internal Fresnel moments ([`crate::fresnel::moment`]). R is
//! strictly decreasing in r (each source's e^(−u)/d and z θ₁ e^(−u)/d³ fall with d, and
//! d_r < d_v), which the cache's culling needs. The total has a closed form (∫ over the plane
//! of e^(−σd)/d is 2π e^(−σ|z|)/σ, of z θ₁ e^(−σd)/d³ is 2π sign(z) e^(−σ|z|)):
//!
//! ```text
//! Rd_total = α′ [ C_φ (e^(−σ_tr z_r) − e^(−σ_tr |z_v|)) / (2Dσ_tr) + C_E (e^(−σ_tr z_r) + e^(−σ_tr |z_v|)) / 2 ]
//! ```
//!
//! which is 1 at α′ = 1 for every η (C_φ·2A + C_E = 1). The source strength is α′ once, as in
//! the classical dipole, which the Monte Carlo comparison bears out (`BENCHMARKS.md`,
//! "Profiles against a Monte Carlo random walk").

use crate::dipole::{self, MAX_R2, NodeMoments, check_eta};
use crate::error::ParamError;
use crate::fresnel;
use crate::lanes::Lanes;
use crate::math;

/// The η-only constants: the boundary term and the exitance weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// A = (1 + 3C₂)/(1 − 2C₁).
    pub a: f64,
    /// C_φ = (1 − 2C₁)/4.
    pub c_phi: f64,
    /// C_E = (1 − 3C₂)/2.
    pub c_e: f64,
}

impl Boundary {
    /// For relative index η ≥ 1 (the moments of internal reflection, index 1/η outside).
    pub fn new(eta: f64) -> Self {
        let c1 = fresnel::moment(1.0 / eta, 1);
        let c2 = fresnel::moment(1.0 / eta, 2);
        Boundary {
            a: (1.0 + 3.0 * c2) / (1.0 - 2.0 * c1),
            c_phi: 0.25 * (1.0 - 2.0 * c1),
            c_e: 0.5 * (1.0 - 3.0 * c2),
        }
    }
}

/// The better dipole with σ_t′ = 1 in double precision: the unitless shape (lengths in ℓ_u),
/// for the total reflectance, its inversion and the local-integral quadrature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitBetterDipole {
    albedo: f64,
    sigma_tr: f64,
    /// D.
    diffusion: f64,
    /// |z_v|.
    z_v: f64,
    phi_scale: f64,
    e_scale: f64,
}

impl UnitBetterDipole {
    /// For reduced albedo α′ ∈ [0, 1] and the boundary of η.
    pub fn new(albedo: f64, boundary: &Boundary) -> Self {
        let diffusion = (2.0 - albedo) / 3.0;
        UnitBetterDipole {
            albedo,
            sigma_tr: math::sqrt64((1.0 - albedo).max(0.0) / diffusion),
            diffusion,
            z_v: 1.0 + 4.0 * boundary.a * diffusion,
            phi_scale: albedo * boundary.c_phi / (4.0 * core::f64::consts::PI * diffusion),
            e_scale: albedo * boundary.c_e / (4.0 * core::f64::consts::PI),
        }
    }

    /// R₁(ρ), ρ in units of ℓ_u.
    pub fn rd(&self, rho: f64) -> f64 {
        let s = self.sigma_tr;
        let source = |z: f64| {
            let d2 = rho * rho + z * z;
            let d = math::sqrt64(d2);
            let e = math::exp64(-s * d);
            (e / d, z * (1.0 + s * d) * e / (d * d2))
        };
        let (phi_r, e_r) = source(1.0);
        let (phi_v, e_v) = source(self.z_v);
        self.phi_scale * (phi_r - phi_v) + self.e_scale * (e_r + e_v)
    }

    /// ∫ R dA in closed form (the module's formula).
    pub fn total_reflectance(&self) -> f64 {
        let s = self.sigma_tr;
        let er = math::exp64(-s);
        let ev = math::exp64(-s * self.z_v);
        // (e^(−σ z_r) − e^(−σ z_v))/σ without cancellation: e^(−σ z_r)(1 − e^(−σ Δz))/σ, and
        // the limit Δz as σ → 0.
        let dz = self.z_v - 1.0;
        let phi_integral = if s * dz > 1e-300 {
            er * -math::expm1_64(-s * dz) / s
        } else {
            dz
        };
        let phi = self.phi_scale * 2.0 * core::f64::consts::PI * phi_integral;
        let e = self.e_scale * 2.0 * core::f64::consts::PI * (er + ev);
        phi + e
    }

    /// σ_tr per ℓ_u: R falls like e^(−σ_tr r).
    pub fn decay_rate(&self) -> f64 {
        self.sigma_tr
    }
    /// α′.
    pub fn albedo(&self) -> f64 {
        self.albedo
    }
}

/// Rd_total of the better dipole for α′ and η.
pub fn total_reflectance(albedo: f64, eta: f64) -> f64 {
    UnitBetterDipole::new(albedo, &Boundary::new(eta)).total_reflectance()
}

/// The α′ whose better-dipole Rd_total is `kd` ∈ (0, 1), by bisection in s = √(3(1 − α′))
/// (64 halvings; Rd_total is monotone, as for the classical dipole).
pub fn albedo_from_total_reflectance(kd: f64, eta: f64) -> f64 {
    albedo_from_total_reflectance_with(kd, &Boundary::new(eta))
}

/// [`albedo_from_total_reflectance`] with the η-only constants computed once (for tables).
pub fn albedo_from_total_reflectance_with(kd: f64, boundary: &Boundary) -> f64 {
    let total = |s: f64| UnitBetterDipole::new(1.0 - s * s / 3.0, boundary).total_reflectance();
    let (mut lo, mut hi) = (0.0, math::sqrt64(3.0));
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if total(mid) > kd {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = 0.5 * (lo + hi);
    1.0 - s * s / 3.0
}

/// One channel of the better dipole, precomputed for evaluation from r².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BetterDipole {
    sigma_tr: f32,
    z_r: f32,
    z_r2: f32,
    /// |z_v|.
    z_v: f32,
    z_v2: f32,
    /// α′ C_φ / (4πD).
    phi_scale: f32,
    /// α′ C_E / (4π).
    e_scale: f32,
    albedo: f64,
    sigma_t: f32,
    rd_zero: f32,
    rd_total: f32,
}

impl BetterDipole {
    /// From α′ ∈ (0, 1], σ_t′ = 1/ℓ_u (per scene unit) and η.
    pub fn new(albedo: f64, sigma_t: f64, eta: f32) -> Result<Self, ParamError> {
        check_eta(eta)?;
        Self::with_boundary(albedo, sigma_t, &Boundary::new(eta as f64))
    }

    /// [`BetterDipole::new`] with the η-only constants computed once.
    pub fn with_boundary(
        albedo: f64,
        sigma_t: f64,
        boundary: &Boundary,
    ) -> Result<Self, ParamError> {
        dipole::check_albedo(albedo)?;
        dipole::check_positive_length("sigma_t", sigma_t)?;
        let unit = UnitBetterDipole::new(albedo, boundary);
        let ell = 1.0 / sigma_t;
        // Every length scales with ℓ_u; R with 1/ℓ_u².
        let z_v = unit.z_v * ell;
        let rd_zero = unit.rd(0.0) / (ell * ell);
        let d = BetterDipole {
            sigma_tr: (unit.sigma_tr * sigma_t) as f32,
            z_r: ell as f32,
            z_r2: (ell * ell) as f32,
            z_v: z_v as f32,
            z_v2: (z_v * z_v) as f32,
            phi_scale: (unit.phi_scale * sigma_t) as f32,
            e_scale: unit.e_scale as f32,
            albedo,
            sigma_t: sigma_t as f32,
            rd_zero: rd_zero as f32,
            rd_total: unit.total_reflectance() as f32,
        };
        // As for the classical dipole: both depths' cubes normal, R(0) finite.
        let ok = |v: f32| v.is_finite() && v >= f32::MIN_POSITIVE;
        if !(ok(d.z_r2)
            && ok(d.z_v2)
            && ok(d.z_r * d.z_r2)
            && ok(d.z_v * d.z_v2)
            && d.z_v2 < 1e30
            && ok(d.phi_scale)
            && d.rd_zero.is_finite()
            && d.rd_zero > 0.0
            && d.rd(0.0).is_finite())
        {
            return Err(ParamError::OutOfRange {
                name: "mean free path",
                value: ell as f32,
            });
        }
        Ok(d)
    }

    /// R(r) from r² (units 1/length²).
    #[inline]
    pub fn rd(&self, r2: f32) -> f32 {
        let r2 = r2.min(MAX_R2);
        let s = self.sigma_tr;
        let source = |z: f32, z2: f32| {
            let d2 = r2 + z2;
            let d = math::sqrt(d2);
            let e = math::exp(-s * d);
            (e / d, z * (s * d + 1.0) * e / (d * d2))
        };
        let (phi_r, e_r) = source(self.z_r, self.z_r2);
        let (phi_v, e_v) = source(self.z_v, self.z_v2);
        (self.phi_scale * (phi_r - phi_v) + self.e_scale * (e_r + e_v)).max(0.0)
    }

    /// R on eight squared distances; the same formula as [`BetterDipole::rd`].
    #[inline(always)]
    pub(crate) fn rd_lanes<L: Lanes>(&self, r2: L) -> L {
        let r2 = r2.min(L::splat(MAX_R2));
        let sigma = L::splat(self.sigma_tr);
        let one = L::splat(1.0);
        let mut phi = [L::splat(0.0); 2];
        let mut flux = [L::splat(0.0); 2];
        let sources = [(self.z_r, self.z_r2), (self.z_v, self.z_v2)];
        for k in 0..2 {
            let (z, z2) = sources[k];
            let d2 = r2 + L::splat(z2);
            let d = d2.sqrt();
            let e = (L::splat(0.0) - sigma * d).exp_nonpositive();
            phi[k] = e / d;
            flux[k] = L::splat(z) * (sigma * d + one) * e / (d * d2);
        }
        (L::splat(self.phi_scale) * (phi[0] - phi[1])
            + L::splat(self.e_scale) * (flux[0] + flux[1]))
            .max(L::splat(0.0))
    }

    /// The fourth-order node aggregate (see [`crate::Dipole::rd_lanes_corrected`]): per
    /// source, the fluence term e^(−u)/d with derivatives (−1)ⁿ θₙ e^(−u)/d^(2n+1) and the
    /// flux term z θ₁ e^(−u)/d³ with (−1)ⁿ z θₙ₊₁ e^(−u)/d^(2n+3), under the same moment
    /// closure; clamped to [0, 2·plain].
    #[inline(always)]
    pub(crate) fn rd_lanes_corrected<L: Lanes>(&self, r2: L, m: &NodeMoments<L>) -> L {
        let r2 = r2.min(L::splat(MAX_R2));
        let sigma = L::splat(self.sigma_tr);
        let one = L::splat(1.0);
        let inv_r2 = (one / r2).min(L::splat(f32::MAX));
        let terms = crate::moments::MomentTerms::new(inv_r2, m);
        let sources = [
            (self.z_r, self.z_r2, L::splat(self.phi_scale)),
            (self.z_v, self.z_v2, L::splat(-self.phi_scale)),
        ];
        let e_scale = L::splat(self.e_scale);
        let mut plain = L::splat(0.0);
        let mut correction = L::splat(0.0);
        for (z, z2, phi_scale) in sources {
            let d2 = r2 + L::splat(z2);
            let d = d2.sqrt();
            let u = sigma * d;
            let e = (L::splat(0.0) - u).exp_nonpositive();
            let t = one / d2;
            let rho = r2 * t;
            let fluence = e / d;
            let w = L::splat(z) * (e / (d * d2));
            plain = plain + phi_scale * fluence + e_scale * w * (u + one);
            correction = correction
                + phi_scale * terms.fluence_correction(fluence * t, u, sigma, rho)
                + e_scale * terms.flux_correction(w * t, u, sigma, rho);
        }
        (plain + correction).max(L::splat(0.0)).min(plain + plain)
    }

    /// R(0), the peak.
    pub fn rd_zero(&self) -> f32 {
        self.rd_zero
    }
    /// Rd_total (closed form).
    pub fn total_reflectance(&self) -> f32 {
        self.rd_total
    }
    /// α′.
    pub fn albedo(&self) -> f64 {
        self.albedo
    }
    /// ℓ_u = 1/σ_t′.
    pub fn mean_free_path(&self) -> f32 {
        self.z_r
    }
    /// σ_tr: R falls like e^(−σ_tr r).
    pub fn decay_rate(&self) -> f32 {
        self.sigma_tr
    }
    /// σ_t′.
    pub fn sigma_t(&self) -> f32 {
        self.sigma_t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::GaussLegendre;

    /// ∫ 2πr R dr by quadrature over geometric intervals, from the f64 shape.
    fn integral(u: &UnitBetterDipole) -> f64 {
        let rule = GaussLegendre::<32>::new();
        let mut total = 0.0;
        let (mut lo, mut hi) = (0.0, 0.01);
        let end = 80.0 / u.decay_rate().max(1e-3) + 200.0;
        while lo < end {
            total += rule.integrate(lo, hi, |r| 2.0 * core::f64::consts::PI * r * u.rd(r));
            lo = hi;
            hi *= 2.0;
        }
        total
    }

    #[test]
    fn closed_form_total_matches_quadrature() {
        for eta in [1.0, 1.3, 1.5, 2.5] {
            let b = Boundary::new(eta);
            // (At α′ = 1 the profile falls like 1/r³ only, beyond a quadrature's reach; the
            // closed form is checked there by energy conservation below.)
            for albedo in [0.01, 0.3, 0.8, 0.99, 0.9999] {
                let u = UnitBetterDipole::new(albedo, &b);
                let closed = u.total_reflectance();
                let numeric = integral(&u);
                assert!(
                    (closed - numeric).abs() < 1e-4 * closed.max(1e-3),
                    "η {eta} α′ {albedo}: {closed} vs {numeric}"
                );
            }
            // Energy conservation at α′ = 1: everything comes back out.
            let one = UnitBetterDipole::new(1.0, &b).total_reflectance();
            assert!((one - 1.0).abs() < 1e-12, "η {eta}: {one}");
        }
    }

    /// Index matched, the moments vanish: A = 1, C_φ = ¼, C_E = ½.
    #[test]
    fn index_matched_boundary() {
        let b = Boundary::new(1.0);
        assert!((b.a - 1.0).abs() < 1e-12);
        assert!((b.c_phi - 0.25).abs() < 1e-12 && (b.c_e - 0.5).abs() < 1e-12);
        // More internal reflection with η: a larger A.
        assert!(Boundary::new(1.5).a > Boundary::new(1.3).a);
    }

    #[test]
    fn total_is_monotone_and_inverts() {
        for eta in [1.0, 1.3, 1.5] {
            let mut last = 0.0;
            for i in 1..=100 {
                let albedo = i as f64 / 100.0;
                let t = total_reflectance(albedo, eta);
                assert!(t > last, "η {eta} α′ {albedo}");
                last = t;
            }
            for kd in [0.01, 0.2, 0.5, 0.9, 0.999] {
                let albedo = albedo_from_total_reflectance(kd, eta);
                let back = total_reflectance(albedo, eta);
                assert!((back - kd).abs() < 1e-10, "{kd}: {back}");
            }
        }
    }

    /// The f32 evaluation against the f64 shape and the scaling law R_ℓ(r) = R₁(r/ℓ)/ℓ².
    #[test]
    fn evaluation_matches_the_shape_at_any_scale() {
        let b = Boundary::new(1.3);
        for albedo in [0.2, 0.9, 0.999] {
            let u = UnitBetterDipole::new(albedo, &b);
            for ell in [0.01_f64, 1.0, 25.0] {
                let d = BetterDipole::with_boundary(albedo, 1.0 / ell, &b).unwrap();
                for rho in [0.0, 0.3, 1.0, 4.0, 20.0] {
                    let r = rho * ell;
                    let want = u.rd(rho) / (ell * ell);
                    let got = d.rd((r * r) as f32) as f64;
                    assert!((got - want).abs() < 2e-5 * want, "{albedo} {ell} {rho}");
                    let lanes = d.rd_lanes(crate::lanes::DefaultLanes::splat((r * r) as f32));
                    let lane = lanes.to_array()[0] as f64;
                    assert!(
                        (lane - want).abs() < 2e-5 * want,
                        "lanes {albedo} {ell} {rho}"
                    );
                }
            }
        }
    }

    #[test]
    fn strictly_decreasing() {
        let d = BetterDipole::new(0.8, 2.0, 1.4).unwrap();
        let mut last = f32::INFINITY;
        for i in 0..400 {
            let r = i as f32 * 0.02;
            let v = d.rd(r * r);
            assert!(v < last || v == 0.0, "r {r}");
            last = v;
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(BetterDipole::new(0.0, 1.0, 1.3).is_err());
        assert!(BetterDipole::new(0.5, -1.0, 1.3).is_err());
        assert!(BetterDipole::new(0.5, 1.0, 0.9).is_err());
        assert!(BetterDipole::new(0.5, 1e30, 1.3).is_err());
        assert!(BetterDipole::new(f64::NAN, 1.0, 1.3).is_err());
    }
}
