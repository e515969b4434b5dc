//! The smoothing kernel w(r) of the local/global split (LM07, N10).
//!
//! LM07 does not publish its kernel; it only needs w(0) = 1, w(r ≥ α) = 0 and smoothness in
//! between. lucent uses the quartic ("biweight")
//!
//! ```text
//! w(r) = (1 − r²/α²)²   for r < α,   0 otherwise
//! ```
//!
//! It is C¹ at r = α (no visible ring where the global sum takes over), and a polynomial in
//! r², so it is evaluated from the squared distance with no square root.

use crate::lanes::Lanes;

/// The quartic kernel for one smoothing radius α.
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
        t * t
    }
    /// w on eight squared distances.
    #[inline(always)]
    pub fn weight_lanes<L: Lanes>(&self, r2: L) -> L {
        let t = (L::splat(1.0) - r2 * L::splat(self.inv_radius2)).max(L::splat(0.0));
        (t * t).keep(r2.lt(L::splat(self.radius2)))
    }
    /// w(ρ·α) in double precision for ρ = r/α (for quadrature).
    pub fn weight_unit(rho: f64) -> f64 {
        if rho >= 1.0 {
            0.0
        } else {
            let t = 1.0 - rho * rho;
            t * t
        }
    }
    /// How w(ρ/a) changes with the radius a, times a, at u = ρ/a:
    /// a·∂w(ρ/a)/∂a = −u·w′(u) = 4u²(1 − u²) for u < 1, 0 beyond (double precision, for the
    /// derivative of the local integral in the radius). It vanishes at u = 1 like w itself.
    pub fn radius_derivative_unit(u: f64) -> f64 {
        if u >= 1.0 {
            0.0
        } else {
            4.0 * u * u * (1.0 - u * u)
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
        assert!((k.weight(1.0) - 0.5625).abs() < 1e-7); // (1 − 1/4)²
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
