//! The local term's inputs bound together: the smoothing radius α and the local integral K at
//! that α (LM07 / N10, `docs/physics.md` §12–§14).
//!
//! The split methods compute M_o = E_loc·K + Σ (1 − w(r))·Rd·E·A, where w is the kernel of
//! radius α and K = 2π ∫₀^α w(r)·Rd(r)·r dr. K only makes sense for the α of the kernel that
//! weights the global sum: a K for another α double-counts or drops part of the profile near x.
//! A [`LocalTerm`] is therefore made only by whoever computes K — [`LocalTerm::exact`],
//! [`crate::LocalIntegralTable::local_term`], [`crate::LocalIntegralByKd::local_term`] —
//! and carries its α into [`crate::IrradianceCache::query`].

use glam::Vec3;

use crate::error::ParamError;
use crate::profile::Profile;
use crate::table::exact_local_integral;

/// The smoothing radius α (scene units) and the local integral K per RGB channel for it.
///
/// ```text
/// offset  0  alpha  f32
/// offset  4  k      Vec3 (x, y, z: f32)
/// size   16
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct LocalTerm {
    alpha: f32,
    k: Vec3,
}

const _: () = {
    assert!(core::mem::size_of::<LocalTerm>() == 16);
    assert!(core::mem::offset_of!(LocalTerm, k) == 4);
};

impl LocalTerm {
    /// No local term: α = 0 and K = 0, for the unsplit methods ([`crate::Method::is_split`]
    /// false), which use neither. A split method given it has no kernel and no local term.
    pub const NONE: LocalTerm = LocalTerm {
        alpha: 0.0,
        k: Vec3::ZERO,
    };

    /// Bound by the tables, which validated α (finite, > 0) and computed K for it.
    pub(crate) fn new(alpha: f32, k: Vec3) -> LocalTerm {
        LocalTerm { alpha, k }
    }

    /// K for `profile` at its own mean free path ℓ_u and smoothing radius `alpha` by a fresh
    /// quadrature per channel (no table, no interpolation error; about 1e-12 relative before
    /// rounding to f32): for a material that does not vary over the surface, computed once
    /// per object. Errors if α is not finite and positive.
    pub fn exact(profile: &Profile, alpha: f32) -> Result<LocalTerm, ParamError> {
        check_smoothing_radius(alpha)?;
        Ok(LocalTerm::new(alpha, exact_local_integral(profile, alpha)))
    }

    /// The smoothing radius α (scene units).
    pub fn alpha(self) -> f32 {
        self.alpha
    }

    /// The local integral K per RGB channel (dimensionless, in [0, Rd_total]).
    pub fn k(self) -> Vec3 {
        self.k
    }
}

/// The smoothing radius α must be finite and positive (every K is for one α > 0).
pub(crate) fn check_smoothing_radius(alpha: f32) -> Result<(), ParamError> {
    if !alpha.is_finite() {
        return Err(ParamError::NotFinite {
            name: "smoothing radius",
            value: alpha,
        });
    }
    if alpha <= 0.0 {
        return Err(ParamError::NotPositive {
            name: "smoothing radius",
            value: alpha,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::Distance;

    #[test]
    fn exact_is_the_quadrature_at_the_profiles_own_mean_free_path() {
        let profile = Profile::from_reflectance(
            Vec3::new(0.8, 0.5, 0.2),
            Distance::MeanFreePath(Vec3::new(0.3, 0.1, 0.05)),
            1.3,
        )
        .unwrap();
        let term = LocalTerm::exact(&profile, 0.2).unwrap();
        assert_eq!(term.alpha(), 0.2);
        assert_eq!(term.k(), exact_local_integral(&profile, 0.2));
        // K lies strictly between 0 and the ℓ → 0 limit Rd_total.
        let limit = profile.total_reflectance();
        assert!(term.k().min_element() > 0.0, "{}", term.k());
        assert!(term.k().cmplt(limit).all(), "{} vs {limit}", term.k());
    }

    #[test]
    fn exact_rejects_a_radius_that_is_not_finite_and_positive() {
        let profile =
            Profile::from_reflectance(Vec3::splat(0.5), Distance::MeanFreePath(Vec3::ONE), 1.3)
                .unwrap();
        for alpha in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert!(LocalTerm::exact(&profile, alpha).is_err(), "α = {alpha}");
        }
        assert_eq!(LocalTerm::NONE.alpha(), 0.0);
        assert_eq!(LocalTerm::NONE.k(), Vec3::ZERO);
    }
}
