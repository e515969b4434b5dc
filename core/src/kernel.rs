//! The smoothing kernel w(r) of the local/global split (LM07, N10; `docs/physics.md` §11).
//!
//! LM07 does not publish its kernel; it only needs w(0) = 1, w(r ≥ α) = 0 and smoothness in
//! between. lucent uses the smoothstep of t = 1 − r²/α²:
//!
//! ```text
//! w(r) = t²·(3 − 2t) = 1 − 3u⁴ + 2u⁶,   u = r/α, t = 1 − u²,   for r < α;   0 otherwise
//! ```
//!
//! It is C¹ at r = α (no visible ring where the global sum takes over), a polynomial in r²
//! (no square root), and **flat to fourth order at r = 0**: 1 − w = 3u⁴ − 2u⁶. That last
//! property is what keeps the global sum quiet. Between the mean free path and α the dipole
//! falls like 1/r³, so the global integrand (1 − w)·Rd has a peak of width about ℓ_u at the
//! centre unless 1 − w vanishes fast enough there; the nearest sample, a spacing away or less,
//! then decides alone how much of that peak is counted. With the quartic (1 − u²)² that LM07's
//! description suggests (1 − w ≈ 2u²), the global integrand behaves like 1/r inside α, and on a
//! uniformly lit marble plane at the default density the exitance varied by 0.93–0.98% from
//! pixel to pixel; with 3u⁴ it behaves like r and the variation is 0.39–0.42%, with the same α.
//! (A kernel flatter still, 1 − w = 10u⁶ − 15u⁸ + 6u¹⁰, is steeper near α and gave 0.69%.)

use crate::lanes::Lanes;

/// The kernel for one smoothing radius α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kernel {
    radius: f32,
    radius2: f32,
    inv_radius2: f32,
}

impl Kernel {
    /// The kernel of radius α (α = 0 gives w ≡ 0: no smoothing). A radius whose square is not
    /// a normal float (α < 1.1e-19) is no smoothing too: 1/α² would overflow and w(0) would be
    /// 1 − 0·∞ = NaN. (Such a kernel covers nothing but samples exactly at x, and its local
    /// integral K is 0 to f32 precision, so the split is then JB02's sum either way.)
    pub fn new(radius: f32) -> Self {
        let radius = if radius.is_finite() && radius > 0.0 && radius * radius >= f32::MIN_POSITIVE {
            radius
        } else {
            0.0
        };
        let radius2 = radius * radius;
        let inv_radius2 = if radius2 > 0.0 { 1.0 / radius2 } else { 0.0 };
        Kernel {
            radius,
            radius2,
            inv_radius2,
        }
    }
    /// α.
    pub fn radius(&self) -> f32 {
        self.radius
    }
    /// α².
    pub fn radius2(&self) -> f32 {
        self.radius2
    }
    /// w from r².
    #[inline]
    pub fn weight(&self, r2: f32) -> f32 {
        if r2 >= self.radius2 {
            return 0.0;
        }
        let t = 1.0 - r2 * self.inv_radius2;
        t * t * (3.0 - 2.0 * t)
    }
    /// w on eight squared distances.
    #[inline(always)]
    pub fn weight_lanes<L: Lanes>(&self, r2: L) -> L {
        let t = (L::splat(1.0) - r2 * L::splat(self.inv_radius2)).max(L::splat(0.0));
        (t * t * (L::splat(3.0) - L::splat(2.0) * t)).keep(r2.lt(L::splat(self.radius2)))
    }
    /// w(ρ·α) in double precision for ρ = r/α (for quadrature).
    pub fn weight_unit(rho: f64) -> f64 {
        if rho >= 1.0 {
            0.0
        } else {
            let t = 1.0 - rho * rho;
            t * t * (3.0 - 2.0 * t)
        }
    }
    /// How w(ρ/a) changes with the radius a, times a, at u = ρ/a:
    /// a·∂w(ρ/a)/∂a = −u·w′(u) = 12u⁴(1 − u²) for u < 1, 0 beyond (double precision, for the
    /// derivative of the local integral in the radius). It vanishes at u = 1 like w′.
    pub fn radius_derivative_unit(u: f64) -> f64 {
        if u >= 1.0 {
            0.0
        } else {
            let u2 = u * u;
            12.0 * u2 * u2 * (1.0 - u2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::ScalarLanes;

    #[test]
    fn kernel_shape() {
        let k = Kernel::new(2.0);
        assert_eq!(k.weight(0.0), 1.0);
        assert_eq!(k.weight(4.0), 0.0);
        assert_eq!(k.weight(100.0), 0.0);
        // u² = 1/4: 1 − 3/16 + 2/64.
        assert!((k.weight(1.0) - 0.84375).abs() < 1e-7);
        // Flat at the centre to fourth order, C¹ at α.
        let w = |u: f64| Kernel::weight_unit(u);
        for u in [1e-3, 1e-2] {
            assert!(
                ((1.0 - w(u)) / (3.0 * u.powi(4)) - 1.0).abs() < 1e-3,
                "u {u}"
            );
        }
        assert!(w(1.0 - 1e-5) / 1e-5 < 1e-3);
        let lanes = k
            .weight_lanes(ScalarLanes([0.0, 1.0, 2.0, 3.0, 3.99, 4.0, 5.0, 1e30]))
            .to_array();
        for (i, r2) in [0.0, 1.0, 2.0, 3.0, 3.99, 4.0, 5.0, 1e30]
            .iter()
            .enumerate()
        {
            assert!((lanes[i] - k.weight(*r2)).abs() < 1e-7);
        }
        // The radius derivative against a central difference of w(ρ/a) in a.
        for u in [0.0, 0.1, 0.5, 0.9, 0.999, 1.0, 2.0] {
            let (rho, a, h) = (u, 1.0, 1e-6);
            let fd = a * (Kernel::weight_unit(rho / (a + h)) - Kernel::weight_unit(rho / (a - h)))
                / (2.0 * h);
            let want = Kernel::radius_derivative_unit(u);
            // (At u = 1 the one-sided half of the difference leaves 2h = 2e-6.)
            assert!((fd - want).abs() < 1e-5, "u {u}: {fd} vs {want}");
        }
        // α = 0 and nonsense radii switch smoothing off.
        for bad in [0.0, -1.0, f32::NAN, 1e-20] {
            let k = Kernel::new(bad);
            assert_eq!(k.weight(0.0), 0.0);
            assert_eq!(k.weight_lanes(ScalarLanes([0.0; 8])).to_array(), [0.0; 8]);
        }
    }
}
