//! Normalised diffusion (Christensen & Burley 2015, "Approximate reflectance profiles for
//! efficient subsurface scattering"; `docs/physics.md` §18), one colour channel:
//!
//! ```text
//! R(r) = A (e^(−r/d) + e^(−r/(3d))) / (8π d r),      ∫ R dA = A for every d,
//! cdf(r) = 1 − ¼ e^(−r/d) − ¾ e^(−r/(3d))             (the share of A within r)
//! d = ℓ / s(A):  s = 1.85 − A + 7|A − 0.8|³           searchlight, ℓ the mean free path
//!                s = 1.9 − A + 3.5 (A − 0.8)²         diffuse surface transmission
//! ```
//!
//! A is the surface albedo (the total diffuse reflectance, K_d), so no inversion is needed.
//! R is a sum of two exponentials over r, a "source" at depth 0 for each rate: the traversal
//! evaluates it from r² like the dipoles, and its node aggregate takes the same fourth-order
//! expansion (with θ₀ … θ₃ instead of θ₁ … θ₃; see [`crate::profile`]).
//!
//! **r → 0.** R diverges like A/(4π d r). A sample of area A_i at distance r < √(A_i/π)
//! stands for a disc that contains x, over which R is finite on average: every point
//! evaluation is therefore capped at the disc average over the mean sample's disc,
//! R̄(ρ) = A·cdf(ρ)/(πρ²) with ρ = √(Ā/π) ([`Burley::with_near_cap`], set when a query is
//! planned on a cache). The cap is also N10's weight for the shading point itself. It removes
//! about ρ/(8d) of A from JB02's plain sum (nothing from the split methods, whose global sum
//! is weighted by 1 − w ≈ 3(r/α)⁴ there).
//!
//! **Local term.** With the kernel w(u) = 1 − 3u⁴ + 2u⁶ ([`crate::kernel`]), K has a closed
//! form: 2πr R(r) = A (e^(−r/d) + e^(−r/(3d)))/(4d), so with b = α/λ for each rate 1/λ,
//!
//! ```text
//! K(α) = A α/(4d) Σ_λ∈{d, 3d} P(α/λ),   P(b) = ∫₀¹ (1 − 3x⁴ + 2x⁶) e^(−bx) dx
//! ```
//!
//! and its radius derivative the same with 12x⁴ − 12x⁶ ([`UnitBurley`]).

use crate::error::ParamError;
use crate::lanes::Lanes;
use crate::math;

/// Which published fit of s(A) maps the mean free path ℓ to Burley's d = ℓ/s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BurleyFit {
    /// The searchlight configuration (a pencil beam at normal incidence):
    /// s = 1.85 − A + 7|A − 0.8|³ (Christensen & Burley 2015, eq. 5). Their reported mean
    /// profile error against Monte Carlo: 5.3%.
    #[default]
    Searchlight,
    /// Diffuse surface transmission (light entering from every direction):
    /// s = 1.9 − A + 3.5(A − 0.8)² (eq. 6). Reported error: 3.9%.
    DiffuseTransmission,
}

impl BurleyFit {
    /// Both fits.
    pub const ALL: [BurleyFit; 2] = [BurleyFit::Searchlight, BurleyFit::DiffuseTransmission];

    /// The scale s(A) of the fit: d = ℓ/s.
    pub fn scale(self, albedo: f64) -> f64 {
        let x = albedo - 0.8;
        match self {
            BurleyFit::Searchlight => 1.85 - albedo + 7.0 * (x * x * x).abs(),
            BurleyFit::DiffuseTransmission => 1.9 - albedo + 3.5 * x * x,
        }
    }

    /// The name the scene format uses.
    pub fn name(self) -> &'static str {
        match self {
            BurleyFit::Searchlight => "searchlight",
            BurleyFit::DiffuseTransmission => "diffuse",
        }
    }
}

/// Squared distances below (this · d)² are evaluated there: R stays finite (the near-field
/// cap normally takes over long before).
const R2_FLOOR: f64 = 1e-12;

/// One channel of normalised diffusion, precomputed for evaluation from r².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Burley {
    /// The surface albedo A = ∫ R dA.
    albedo: f64,
    /// The mean free path ℓ (scene units) the profile was built from.
    mean_free_path: f32,
    /// d = ℓ/s(A).
    d: f32,
    /// The two rates 1/d and 1/(3d).
    rate_fast: f32,
    rate_slow: f32,
    /// A / (8π d).
    scale: f32,
    /// (R2_FLOOR · d²).
    r2_floor: f32,
    /// The largest value a point evaluation returns (see the module's "r → 0").
    cap: f32,
}

impl Burley {
    /// From the surface albedo A ∈ (0, 1], the mean free path ℓ (scene units) and the fit.
    pub fn new(albedo: f64, mean_free_path: f64, fit: BurleyFit) -> Result<Self, ParamError> {
        crate::dipole::check_albedo(albedo)?;
        crate::dipole::check_positive_length("mean free path", mean_free_path)?;
        let d = mean_free_path / fit.scale(albedo);
        let scale = albedo / (8.0 * core::f64::consts::PI * d);
        let r2_floor = R2_FLOOR * d * d;
        let b = Burley {
            albedo,
            mean_free_path: mean_free_path as f32,
            d: d as f32,
            rate_fast: (1.0 / d) as f32,
            rate_slow: (1.0 / (3.0 * d)) as f32,
            scale: scale as f32,
            r2_floor: r2_floor as f32,
            cap: f32::INFINITY,
        };
        // Every length and the floor's value must be normal, finite floats.
        let ok = |v: f32| v.is_finite() && v >= f32::MIN_POSITIVE;
        let peak = b.rd_uncapped(b.r2_floor);
        if !(ok(b.d) && ok(b.rate_fast) && ok(b.r2_floor) && ok(b.scale) && peak.is_finite()) {
            return Err(ParamError::OutOfRange {
                name: "mean free path",
                value: mean_free_path as f32,
            });
        }
        Ok(Burley { cap: peak, ..b })
    }

    /// The same profile with point evaluations capped at the disc average over a disc of
    /// area `area` (a cache's mean sample area Ā; 0 or not finite: only the r² floor).
    pub fn with_near_cap(&self, area: f32) -> Self {
        let floor = self.rd_uncapped(self.r2_floor);
        let cap = if area.is_finite() && area > 0.0 {
            let rho = math::sqrt64(area as f64 / core::f64::consts::PI);
            let mean = disc_average(self.albedo, self.d as f64, rho) as f32;
            if mean.is_finite() && mean > 0.0 {
                mean.min(floor)
            } else {
                floor
            }
        } else {
            floor
        };
        Burley { cap, ..*self }
    }

    #[inline]
    fn rd_uncapped(&self, r2: f32) -> f32 {
        let r = math::sqrt(r2.max(self.r2_floor));
        let e = math::exp(-self.rate_fast * r) + math::exp(-self.rate_slow * r);
        self.scale * e / r
    }

    /// R(r) from r² (units 1/length²), capped near 0.
    #[inline]
    pub fn rd(&self, r2: f32) -> f32 {
        self.rd_uncapped(r2).min(self.cap)
    }

    /// R on eight squared distances; the same formula as [`Burley::rd`].
    #[inline(always)]
    pub(crate) fn rd_lanes<L: Lanes>(&self, r2: L) -> L {
        let r = r2.max(L::splat(self.r2_floor)).sqrt();
        let zero = L::splat(0.0);
        let e = (zero - L::splat(self.rate_fast) * r).exp_nonpositive()
            + (zero - L::splat(self.rate_slow) * r).exp_nonpositive();
        (L::splat(self.scale) * e / r).min(L::splat(self.cap))
    }

    /// The fourth-order node aggregate (see [`crate::Dipole::rd_lanes_corrected`] for the
    /// expansion): each exponential is a source at depth 0 (d = r, ρ = 1, t = 1/r²) whose term
    /// e^(−u)/r has derivatives in s = ½r² of (−1)ⁿ θₙ(u) e^(−u)/r^(2n+1), u = r/λ.
    #[inline(always)]
    pub(crate) fn rd_lanes_corrected<L: Lanes>(
        &self,
        r2: L,
        m: &crate::dipole::NodeMoments<L>,
    ) -> L {
        let r2 = r2.max(L::splat(self.r2_floor));
        let r = r2.sqrt();
        let t = L::splat(1.0) / r2;
        let terms = crate::moments::MomentTerms::new(t, m);
        let mut plain = L::splat(0.0);
        let mut correction = L::splat(0.0);
        for rate in [self.rate_fast, self.rate_slow] {
            let sigma = L::splat(rate);
            let u = sigma * r;
            let e = (L::splat(0.0) - u).exp_nonpositive();
            let value = e / r;
            plain = plain + value;
            correction = correction + terms.fluence_correction(value * t, u, sigma, L::splat(1.0));
        }
        let corrected = (plain + correction).max(L::splat(0.0)).min(plain + plain);
        (L::splat(self.scale) * corrected).min(L::splat(self.cap))
    }

    /// The largest value R takes: the cap (N10's weight for the shading point itself).
    pub fn rd_zero(&self) -> f32 {
        self.cap
    }
    /// ∫ R dA = A.
    pub fn total_reflectance(&self) -> f32 {
        self.albedo as f32
    }
    /// The surface albedo A.
    pub fn albedo(&self) -> f64 {
        self.albedo
    }
    /// The mean free path ℓ the profile was built from.
    pub fn mean_free_path(&self) -> f32 {
        self.mean_free_path
    }
    /// Burley's d = ℓ/s(A).
    pub fn d(&self) -> f32 {
        self.d
    }
    /// The slowest decay rate, 1/(3d): R falls like e^(−r/(3d)) far away.
    pub fn decay_rate(&self) -> f32 {
        self.rate_slow
    }
}

/// The share of ∫ R dA within distance r: 1 − ¼e^(−r/d) − ¾e^(−r/(3d)).
pub fn cdf(r: f64, d: f64) -> f64 {
    1.0 - 0.25 * math::exp64(-r / d) - 0.75 * math::exp64(-r / (3.0 * d))
}

/// The mean of R over a disc of radius ρ about its peak: A·cdf(ρ)/(πρ²).
pub fn disc_average(albedo: f64, d: f64, rho: f64) -> f64 {
    albedo * cdf(rho, d) / (core::f64::consts::PI * rho * rho)
}

/// ∫₀¹ p(x) e^(−bx) dx for p(x) = Σ cₙ xⁿ given as (n, cₙ) pairs, b ≥ 0: by the power series
/// Σₖ (−b)ᵏ/k! Σₙ cₙ/(n + k + 1) for b ≤ 3 (the largest term is below 3³/3! = 4.5, so the
/// alternation costs under one digit), else by the upward recurrence
/// Mₙ = (n Mₙ₋₁ − e^(−b))/b from M₀ = (1 − e^(−b))/b, which amplifies an error by
/// Πₖ≤ₙ k/b ≤ 1 for n ≤ 6 < b^n/n! (at b = 12 the series lost 9 digits).
pub fn polynomial_exp_integral(terms: &[(u32, f64)], b: f64) -> f64 {
    if !(b > 0.0) {
        return terms.iter().map(|&(n, c)| c / (n as f64 + 1.0)).sum();
    }
    if b <= 3.0 {
        let mut sum = 0.0;
        let mut power = 1.0; // (−b)^k / k!
        for k in 0..200u32 {
            let inner: f64 = terms
                .iter()
                .map(|&(n, c)| c / (n as f64 + k as f64 + 1.0))
                .sum();
            let term = power * inner;
            sum += term;
            if k > 2 * b as u32 + 4 && term.abs() < 1e-18 * sum.abs() {
                break;
            }
            power *= -b / (k as f64 + 1.0);
        }
        sum
    } else {
        let e = math::exp64(-b);
        let top = terms.iter().map(|&(n, _)| n).max().unwrap_or(0);
        let mut m = (1.0 - e) / b;
        let mut sum = 0.0;
        for n in 0..=top {
            if n > 0 {
                m = (n as f64 * m - e) / b;
            }
            sum += terms
                .iter()
                .filter(|&&(k, _)| k == n)
                .map(|&(_, c)| c * m)
                .sum::<f64>();
        }
        sum
    }
}

/// The kernel w(x) = 1 − 3x⁴ + 2x⁶ as (power, coefficient) pairs.
const KERNEL: [(u32, f64); 3] = [(0, 1.0), (4, -3.0), (6, 2.0)];
/// −x w′(x) = 12x⁴ − 12x⁶, the kernel's radius derivative (see `table.rs`).
const KERNEL_RADIUS_DERIVATIVE: [(u32, f64); 2] = [(4, 12.0), (6, -12.0)];

/// Normalised diffusion with ℓ = 1 in double precision: the shape the local-integral table
/// stretches, with its local integral in closed form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitBurley {
    albedo: f64,
    /// d in units of ℓ: 1/s(A).
    d: f64,
}

impl UnitBurley {
    /// For surface albedo A and a fit.
    pub fn new(albedo: f64, fit: BurleyFit) -> Self {
        UnitBurley {
            albedo,
            d: 1.0 / fit.scale(albedo),
        }
    }
    /// R₁(ρ) for ρ in units of ℓ (infinite at 0).
    pub fn rd(&self, rho: f64) -> f64 {
        let d = self.d;
        self.albedo * (math::exp64(-rho / d) + math::exp64(-rho / (3.0 * d)))
            / (8.0 * core::f64::consts::PI * d * rho)
    }
    /// 2πρ R₁(ρ), finite at 0: the integrand of every radial integral.
    pub fn ring_density(&self, rho: f64) -> f64 {
        let d = self.d;
        self.albedo * (math::exp64(-rho / d) + math::exp64(-rho / (3.0 * d))) / (4.0 * d)
    }
    /// The slowest decay rate 1/(3d), per ℓ.
    pub fn decay_rate(&self) -> f64 {
        1.0 / (3.0 * self.d)
    }
    /// d in units of ℓ.
    pub fn d(&self) -> f64 {
        self.d
    }
    /// (K, a·dK/da) at a = α/ℓ in closed form (the module's formula).
    pub fn local_integral_and_slope(&self, a: f64) -> (f64, f64) {
        if !(a > 0.0) {
            return (0.0, 0.0);
        }
        let factor = self.albedo * a / (4.0 * self.d);
        let mut k = 0.0;
        let mut slope = 0.0;
        for lambda in [self.d, 3.0 * self.d] {
            let b = a / lambda;
            k += polynomial_exp_integral(&KERNEL, b);
            slope += polynomial_exp_integral(&KERNEL_RADIUS_DERIVATIVE, b);
        }
        (factor * k, factor * slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Kernel;
    use crate::quadrature::GaussLegendre;

    /// ∫ R dA = A for every albedo, fit and ℓ, by quadrature of the f32 evaluation.
    #[test]
    fn integrates_to_the_albedo() {
        let rule = GaussLegendre::<32>::new();
        for fit in BurleyFit::ALL {
            for albedo in [0.05, 0.3, 0.8, 0.99] {
                for ell in [0.01, 1.0, 30.0] {
                    let b = Burley::new(albedo, ell, fit).unwrap();
                    let d = b.d() as f64;
                    // ∫ 2πr R dr over geometric intervals out to 60·3d.
                    let mut total = 0.0;
                    let (mut lo, mut hi) = (0.0, 1e-3 * d);
                    while lo < 180.0 * d {
                        total += rule.integrate(lo, hi, |r| {
                            2.0 * core::f64::consts::PI * r * b.rd((r * r) as f32) as f64
                        });
                        lo = hi;
                        hi *= 2.0;
                    }
                    assert!(
                        (total - albedo).abs() < 2e-4 * albedo,
                        "{fit:?} A {albedo} ℓ {ell}: {total}"
                    );
                }
            }
        }
    }

    #[test]
    fn fits_match_the_published_values() {
        // s(0.8) is 1.05 and 1.1; at A = 1, 0.85 + 7·0.008 and 0.9 + 3.5·0.04.
        assert!((BurleyFit::Searchlight.scale(0.8) - 1.05).abs() < 1e-12);
        assert!((BurleyFit::DiffuseTransmission.scale(0.8) - 1.1).abs() < 1e-12);
        assert!((BurleyFit::Searchlight.scale(1.0) - 0.906).abs() < 1e-12);
        assert!((BurleyFit::DiffuseTransmission.scale(1.0) - 1.04).abs() < 1e-12);
    }

    /// The CDF is the integral of R: its derivative is 2πr R(r), it is 0 at 0 and 1 at ∞.
    #[test]
    fn cdf_is_the_profiles_integral() {
        let u = UnitBurley::new(0.6, BurleyFit::Searchlight);
        let d = u.d();
        assert_eq!(cdf(0.0, d), 0.0);
        assert!((cdf(1e3, d) - 1.0).abs() < 1e-12);
        for r in [0.01, 0.3, 2.0] {
            let h = 1e-6;
            let slope = (cdf(r + h, d) - cdf(r - h, d)) / (2.0 * h);
            let want = u.ring_density(r) / u.albedo;
            assert!((slope - want).abs() < 1e-7 * want, "{r}: {slope} vs {want}");
        }
    }

    /// The closed-form integrals against Gauss–Legendre quadrature, across the switch
    /// between the series and the recurrence.
    #[test]
    fn polynomial_exp_integral_matches_quadrature() {
        let rule = GaussLegendre::<48>::new();
        for b in [0.0_f64, 1e-3, 0.5, 2.99, 3.01, 11.9, 40.0, 400.0] {
            for terms in [&KERNEL[..], &KERNEL_RADIUS_DERIVATIVE[..], &[(2, 1.0)][..]] {
                let pow = |x: f64, n: u32| (0..n).fold(1.0, |acc, _| acc * x);
                let p = |x: f64| terms.iter().map(|&(n, c)| c * pow(x, n)).sum::<f64>();
                // Split so that the quadrature resolves e^(−bx) at large b.
                let mut want = 0.0;
                let mut lo = 0.0;
                while lo < 1.0 {
                    let hi = (lo + 4.0 / b.max(4.0)).min(1.0);
                    want += rule.integrate(lo, hi, |x| p(x) * math::exp64(-b * x));
                    lo = hi;
                }
                let got = polynomial_exp_integral(terms, b);
                assert!(
                    (got - want).abs() <= 1e-11 * want.abs().max(1e-300),
                    "b {b}: {got} vs {want}"
                );
            }
        }
    }

    /// K and a·dK/da in closed form against quadrature of the kernel times the profile.
    #[test]
    fn local_integral_closed_form_matches_quadrature() {
        let rule = GaussLegendre::<48>::new();
        for fit in BurleyFit::ALL {
            for albedo in [0.1, 0.5, 0.9, 0.999] {
                let u = UnitBurley::new(albedo, fit);
                for a in [1e-3_f64, 0.1, 1.0, 7.0, 100.0] {
                    let (mut k, mut slope) = (0.0, 0.0);
                    let (mut lo, mut hi) = (0.0, a.min(0.01));
                    loop {
                        let (dk, ds) = rule.integrate_pair(lo, hi, |rho| {
                            let v = u.ring_density(rho);
                            let x = rho / a;
                            (
                                v * Kernel::weight_unit(x),
                                v * Kernel::radius_derivative_unit(x),
                            )
                        });
                        k += dk;
                        slope += ds;
                        if hi >= a {
                            break;
                        }
                        lo = hi;
                        hi = (hi * 2.0).min(a);
                    }
                    let (ck, cs) = u.local_integral_and_slope(a);
                    assert!(
                        (ck - k).abs() < 1e-10 * k,
                        "{fit:?} {albedo} a {a}: {ck} vs {k}"
                    );
                    assert!(
                        (cs - slope).abs() < 1e-10 * slope,
                        "{fit:?} {albedo} a {a}: {cs} vs {slope}"
                    );
                }
                // a → ∞: the whole albedo (the Lambertian limit).
                let (k, _) = u.local_integral_and_slope(1e6);
                assert!((k - albedo).abs() < 1e-5 * albedo);
            }
        }
    }

    /// The cap is the disc average, below the floor's value, and R never exceeds it.
    #[test]
    fn near_field_cap_is_the_disc_average() {
        let b = Burley::new(0.7, 0.5, BurleyFit::Searchlight).unwrap();
        let area = 1e-3_f32;
        let c = b.with_near_cap(area);
        let rho = math::sqrt64(area as f64 / core::f64::consts::PI);
        let want = disc_average(0.7, b.d() as f64, rho);
        assert!(((c.rd_zero() as f64 - want) / want).abs() < 1e-6);
        assert_eq!(c.rd(0.0), c.rd_zero());
        // Far from 0 the cap does not matter.
        assert_eq!(c.rd(0.25), b.rd(0.25));
        assert!(c.rd(1e-8) <= c.rd_zero());
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(Burley::new(0.0, 1.0, BurleyFit::Searchlight).is_err());
        assert!(Burley::new(1.2, 1.0, BurleyFit::Searchlight).is_err());
        assert!(Burley::new(f64::NAN, 1.0, BurleyFit::Searchlight).is_err());
        assert!(Burley::new(0.5, -1.0, BurleyFit::Searchlight).is_err());
        assert!(Burley::new(0.5, f64::INFINITY, BurleyFit::Searchlight).is_err());
        assert!(Burley::new(0.5, 1e-30, BurleyFit::Searchlight).is_err());
    }
}
