//! Local-integral tables for a texture-mapped diffuse reflectance K_d (N10's table generalised,
//! `docs/physics.md` §14).
//!
//! A [`LocalIntegralTable`] serves every ℓ_u of one material because K depends on α/ℓ_u and the
//! model's albedo parameter only (α′ for the dipoles, A for Burley), and that is fixed by K_d.
//! Where K_d varies over the surface, the albedo parameter does too, so one table per K_d is
//! needed: [`LocalIntegralByKd`] holds tables at the
//! [`LocalIntegralByKd::LEVELS`] + 1 evenly spaced K_d,i = i / LEVELS (clamped into
//! [0.001, 0.999]) and interpolates, per channel, the fraction K / K_d of the two bracketing
//! tables, each looked up at the point's ℓ_u:
//!
//! ```text
//!   K(K_d, ℓ) = K_d · [f_i(ℓ) + (f_i+1(ℓ) − f_i(ℓ))·t],   f_i = K_i / K_d,i,
//!   i = ⌊K_d·LEVELS⌋,  t = (K_d − K_d,i) / (K_d,i+1 − K_d,i)
//!
//!   levels:   K_d = 0.001  1/64  2/64  …  63/64  0.999
//!   tables:   [0]          [1]   [2]   …  [63]   [64]     (each lock-free, filled on use)
//! ```
//!
//! K / K_d, the share of the total within α, is smooth in K_d; K itself is nearly proportional
//! to K_d near 0, where interpolating K linearly erred by 2.7% at K_d = 0.005. Against K by
//! quadrature at each point's own profile, over K_d ∈ [0.005, 0.995] and ℓ_u ∈ [α/32, 8α]:
//! within 0.12% for every model (the renderer's test
//! `textured_albedo_and_radius_interpolate_k_within_half_a_percent`).
//!
//! A material knows the range its textures reach, and [`LocalIntegralByKd::with_range`] samples
//! the tables over it into a dense grid (`kd_grid.rs`): the levels covering its K_d (and one
//! more on each side) × ℓ_u at 32 nodes per octave (and an octave more on each side), K / K_d in
//! f32. A lookup there is a bilinear interpolation, under half the cost of the tables' (no
//! logarithm, no exponential, no check for a segment still to compute); over the test above
//! the worst error becomes 0.144% (dipole). For a K_d texture over [0.2, 0.9] and ℓ_u over two
//! decades the grid holds 49 levels × 279 rows, 55 KB.

use alloc::sync::Arc;
use alloc::vec::Vec;

use glam::Vec3;

use crate::error::ParamError;
use crate::kd_grid::KdGrid;
use crate::lanes::LANES;
use crate::local_term::LocalTerm;
use crate::math;
use crate::profile::{Distance, Profile, ProfileModel};
use crate::quadrature::GaussLegendre;
use crate::table::LocalIntegralTable;

/// Local-integral tables at evenly spaced K_d for one η and smoothing radius α, for a material
/// whose diffuse reflectance K_d is texture-mapped. `Send + Sync`; lookups are lock-free (each
/// table is, and the set of tables is fixed at construction).
#[derive(Debug)]
pub struct LocalIntegralByKd {
    /// `levels[i]`: the table for K_d = i / LEVELS, clamped into [0.001, 0.999].
    levels: Vec<LocalIntegralTable>,
    /// `weights[i]`: interval i's reciprocals, so that a lookup divides by nothing.
    weights: Vec<LevelWeights>,
    alpha: f32,
    ell_min: f32,
    /// K / K_d sampled densely over the range a material reaches ([`LocalIntegralByKd::with_range`]).
    grid: Option<KdGrid>,
}

/// The interval between levels i and i + 1: K_d,i, 1/K_d,i, 1/K_d,i+1 and 1/(K_d,i+1 − K_d,i).
#[derive(Clone, Copy, Debug, Default)]
struct LevelWeights {
    kd_lo: f32,
    inv_kd_lo: f32,
    inv_kd_hi: f32,
    inv_width: f32,
}

impl LevelWeights {
    /// How far `kd` (clamped as the levels are) lies from level i to level i + 1, in [0, 1].
    /// The end levels sit at the clamp bounds, not at 0 and 1: the fraction comes from the
    /// levels' own K_d.
    #[inline]
    fn fraction(&self, kd: f32) -> f32 {
        ((kd - self.kd_lo) * self.inv_width).clamp(0.0, 1.0)
    }
}

impl LocalIntegralByKd {
    /// Intervals between the K_d levels (the tables are one more).
    pub const LEVELS: usize = 64;

    /// The classical dipole's tables for relative index `eta`, smoothing radius `alpha` and
    /// threshold `ell_min` (scene units; as [`LocalIntegralTable::new`]). Only the tables'
    /// headers are built here; their values are computed by the lookups that need them.
    pub fn new(eta: f32, alpha: f32, ell_min: f32) -> Result<Self, ParamError> {
        Self::for_model(ProfileModel::Dipole, eta, alpha, ell_min)
    }

    /// [`LocalIntegralByKd::new`] for the profiles of `model`: level i holds the table of the
    /// profile whose total reflectance is that level's K_d under `model`.
    pub fn for_model(
        model: ProfileModel,
        eta: f32,
        alpha: f32,
        ell_min: f32,
    ) -> Result<Self, ParamError> {
        let rule = Arc::new(GaussLegendre::new());
        let levels = (0..=Self::LEVELS)
            .map(|i| {
                let kd = level_kd(i);
                // ℓ_u is what each table varies; 1 is as good as any.
                let profile = Profile::from_reflectance_with(
                    model,
                    Vec3::splat(kd),
                    Distance::MeanFreePath(Vec3::ONE),
                    eta,
                )?;
                LocalIntegralTable::with_rule(&profile, alpha, ell_min, rule.clone())
            })
            .collect::<Result<Vec<_>, _>>()?;
        let weights = (0..Self::LEVELS)
            .map(|i| {
                let (kd_lo, kd_hi) = (level_kd(i), level_kd(i + 1));
                LevelWeights {
                    kd_lo,
                    inv_kd_lo: 1.0 / kd_lo,
                    inv_kd_hi: 1.0 / kd_hi,
                    inv_width: 1.0 / (kd_hi - kd_lo),
                }
            })
            .collect();
        Ok(LocalIntegralByKd {
            levels,
            weights,
            alpha,
            ell_min,
            grid: None,
        })
    }

    /// These tables with a dense grid of K / K_d (`kd_grid.rs`) over the range a material
    /// reaches: K_d from `kd.0` to `kd.1` and ℓ_u from `ell_u.0` to `ell_u.1`, each widened
    /// by a margin (a level of K_d and an octave of ℓ_u). Lookups inside it interpolate the
    /// grid bilinearly; lookups outside use the tables as before. The grid's values are
    /// computed here (with the segments of the tables they come from), so that lookups in the
    /// range never compute. A range that is empty, not finite, or wider than 48 octaves builds
    /// no grid.
    pub fn with_range(mut self, kd: (f32, f32), ell_u: (f32, f32)) -> Self {
        if !(kd.0 <= kd.1 && ell_u.0 <= ell_u.1) {
            // Empty, or NaN.
            self.grid = None;
            return self;
        }
        let level = |v: f32| level_of(v.clamp(LEVEL_KD_MIN, LEVEL_KD_MAX));
        let levels = (
            level(kd.0).saturating_sub(1),
            (level(kd.1) + 2).min(Self::LEVELS),
        );
        self.grid = KdGrid::new(
            &self.levels,
            level_kd,
            levels,
            (ell_u.0 * 0.5, ell_u.1 * 2.0),
            self.alpha,
            self.levels[0].first_node(),
        );
        self
    }

    /// True when a lookup at `kd`, `ell_u` reads the dense grid of
    /// [`LocalIntegralByKd::with_range`] rather than the tables.
    pub fn in_grid(&self, kd: Vec3, ell_u: Vec3) -> bool {
        self.grid
            .as_ref()
            .is_some_and(|g| self.lookup_in_grid(g, kd, ell_u).is_some())
    }

    /// Bytes held by the dense grid of [`LocalIntegralByKd::with_range`] (0 without one).
    pub fn grid_bytes(&self) -> usize {
        self.grid.as_ref().map_or(0, KdGrid::bytes)
    }

    /// Checks the dense grid's invariants ([`LocalIntegralByKd::with_range`]), if there is one.
    pub fn validate(&self) -> Result<(), &'static str> {
        self.grid.as_ref().map_or(Ok(()), KdGrid::validate)
    }

    /// The smoothing radius α.
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// The threshold ℓ_min.
    pub fn ell_min(&self) -> f32 {
        self.ell_min
    }

    /// The table of level i (K_d = i / [`LocalIntegralByKd::LEVELS`], clamped into
    /// [0.001, 0.999]), `None` beyond the last.
    pub fn level(&self, i: usize) -> Option<&LocalIntegralTable> {
        self.levels.get(i)
    }

    /// K per channel at diffuse reflectance `kd` (each channel clamped into [0, 1]) and mean
    /// free path `ell_u`: each channel's two bracketing levels looked up at that channel's ℓ
    /// and interpolated linearly in K_d.
    pub fn lookup(&self, kd: Vec3, ell_u: Vec3) -> Vec3 {
        if let Some(k) = self
            .grid
            .as_ref()
            .and_then(|g| self.lookup_in_grid(g, kd, ell_u))
        {
            return k;
        }
        self.lookup_in_tables(kd, ell_u)
    }

    /// [`LocalIntegralByKd::lookup`] by the dense grid, `None` where a channel falls outside.
    #[inline]
    fn lookup_in_grid(&self, grid: &KdGrid, kd: Vec3, ell_u: Vec3) -> Option<Vec3> {
        let shared = grid.row(ell_u.x)?;
        let grey = ell_u.x == ell_u.y && ell_u.y == ell_u.z;
        let mut k = [0.0f32; 3];
        for c in 0..3 {
            let row = if grey || c == 0 {
                shared
            } else {
                grid.row(ell_u[c])?
            };
            let kd_c = kd[c].clamp(LEVEL_KD_MIN, LEVEL_KD_MAX);
            let i = level_of(kd_c);
            let place = grid.place(i, row)?;
            k[c] = grid.share(place, self.weights[i].fraction(kd_c)) * kd_c;
        }
        Some(Vec3::from_array(k))
    }

    /// [`LocalIntegralByKd::lookup`] by the tables: each channel's two levels at its ℓ.
    fn lookup_in_tables(&self, kd: Vec3, ell_u: Vec3) -> Vec3 {
        // ℓ's place is the same in every table (one α and ℓ_min), and usually in every channel.
        let first = &self.levels[0];
        let shared = first.place(ell_u.x);
        let grey = ell_u.x == ell_u.y && ell_u.y == ell_u.z;
        // Per channel, the two levels' K = k·e^x: the six exponentials in one 8-lane
        // evaluation.
        let mut factors = [0.0f32; 6];
        let mut exponents = [0.0f32; LANES];
        let mut interval = [(0.0f32, LevelWeights::default()); 3];
        for c in 0..3 {
            let place = if grey || c == 0 {
                shared
            } else {
                first.place(ell_u[c])
            };
            // NaN stays NaN through the clamps: level 0, and a NaN K.
            let kd_c = kd[c].clamp(LEVEL_KD_MIN, LEVEL_KD_MAX);
            let i = level_of(kd_c);
            // Every level's profile is grey: channel 0 of its table serves all three (and
            // only one channel's segments are ever computed).
            (factors[2 * c], exponents[2 * c]) = self.levels[i].value_parts(0, place);
            (factors[2 * c + 1], exponents[2 * c + 1]) = self.levels[i + 1].value_parts(0, place);
            interval[c] = (kd_c, self.weights[i]);
        }
        let e = math::exp_nonpositive_poly_8(exponents);
        Vec3::from_array(core::array::from_fn(|c| {
            let (kd_c, w) = interval[c];
            let t = w.fraction(kd_c);
            // The fraction K / K_d is what varies slowly: at low K_d, K is nearly proportional
            // to K_d and linear interpolation of K itself erred by 2.7% at K_d = 0.005.
            let lo = factors[2 * c] * e[2 * c] * w.inv_kd_lo;
            let hi = factors[2 * c + 1] * e[2 * c + 1] * w.inv_kd_hi;
            (lo + (hi - lo) * t) * kd_c
        }))
    }

    /// [`LocalIntegralByKd::lookup`] bound to this α: the local term of a query
    /// ([`crate::IrradianceCache::query`]).
    #[inline]
    pub fn local_term(&self, kd: Vec3, ell_u: Vec3) -> LocalTerm {
        LocalTerm::new(self.alpha, self.lookup(kd, ell_u))
    }
}

/// The K_d of the first and last level.
const LEVEL_KD_MIN: f32 = 0.001;
const LEVEL_KD_MAX: f32 = 0.999;

/// The level at or below `kd` (already clamped into [`LEVEL_KD_MIN`], [`LEVEL_KD_MAX`]; a NaN
/// gives level 0): the first of the two levels a lookup interpolates between.
#[inline]
fn level_of(kd: f32) -> usize {
    // In [0.064, 63.94]: the i32 conversion is exact and cheaper than usize's.
    ((kd * LocalIntegralByKd::LEVELS as f32) as i32 as usize).min(LocalIntegralByKd::LEVELS - 1)
}

/// K_d of level i: i / [`LocalIntegralByKd::LEVELS`], clamped into [`LEVEL_KD_MIN`], [`LEVEL_KD_MAX`].
fn level_kd(i: usize) -> f32 {
    (i as f32 / LocalIntegralByKd::LEVELS as f32).clamp(LEVEL_KD_MIN, LEVEL_KD_MAX)
}

const _: () = {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<LocalIntegralByKd>();
};

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    /// Between levels: within 0.2% of a table built for exactly that K_d and looked up at the
    /// same ℓ (the ℓ interpolation is common to both, so this isolates the K_d interpolation).
    #[test]
    fn between_levels_matches_a_table_for_that_reflectance() {
        let (eta, alpha) = (1.4, 0.07);
        let tables = LocalIntegralByKd::new(eta, alpha, alpha / 1024.0).unwrap();
        let mut worst = 0.0f32;
        for kd in [
            Vec3::new(0.3, 0.55, 0.9),
            Vec3::new(0.05, 0.12, 0.71),
            Vec3::new(0.97, 0.4, 0.26),
        ] {
            for ell in [0.005, 0.05, 0.5] {
                let ell = Vec3::splat(ell);
                let got = tables.lookup(kd, ell);
                let profile =
                    Profile::from_reflectance(kd, Distance::MeanFreePath(ell), eta).unwrap();
                let own = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)
                    .unwrap()
                    .lookup(ell);
                worst = worst.max(((got - own) / own).abs().max_element());
            }
        }
        assert!(worst < 0.002, "worst relative error {worst}");
        // And not trivially: the levels differ from each other by far more than that.
        let ell = Vec3::splat(0.05);
        let (a, b) = (
            tables.lookup(Vec3::splat(0.3), ell),
            tables.lookup(Vec3::splat(0.6), ell),
        );
        assert!(((a - b) / b).abs().min_element() > 0.1, "{a} vs {b}");
    }

    /// At a level, K is that level's table exactly (t = 0), and the local term carries α.
    #[test]
    fn at_a_level_it_is_that_tables_lookup() {
        let alpha = 0.2;
        let tables = LocalIntegralByKd::new(1.3, alpha, alpha / 1024.0).unwrap();
        let ell = Vec3::new(0.01, 0.1, 1.0);
        let kd = Vec3::splat(16.0 / 64.0);
        assert_eq!(
            tables.lookup(kd, ell),
            tables.level(16).unwrap().lookup(ell)
        );
        let term = tables.local_term(kd, ell);
        assert_eq!((term.alpha(), term.k()), (alpha, tables.lookup(kd, ell)));
        assert!(tables.level(LocalIntegralByKd::LEVELS + 1).is_none());
        // K_d = 1 is level 64 (0.999), reached at t = 1 of the last interval.
        let top = tables.lookup(Vec3::ONE, ell);
        let last = tables.level(LocalIntegralByKd::LEVELS).unwrap().lookup(ell);
        assert!(
            ((top - last) / last).abs().max_element() < 1e-6,
            "{top} vs {last}"
        );
    }

    /// Every model: between levels within 0.2% of a table built for that model at exactly that
    /// K_d, and each level is that model's table (the Burley levels differ from the dipole's).
    #[test]
    fn every_model_takes_its_own_tables() {
        let (eta, alpha) = (1.4, 0.07);
        let ell = Vec3::new(0.005, 0.05, 0.5);
        let dipole = LocalIntegralByKd::new(eta, alpha, alpha / 1024.0).unwrap();
        for model in ProfileModel::ALL {
            let tables = LocalIntegralByKd::for_model(model, eta, alpha, alpha / 1024.0).unwrap();
            let mut worst = 0.0f32;
            for kd in [Vec3::new(0.3, 0.55, 0.9), Vec3::new(0.05, 0.12, 0.71)] {
                let got = tables.lookup(kd, ell);
                let profile =
                    Profile::from_reflectance_with(model, kd, Distance::MeanFreePath(ell), eta)
                        .unwrap();
                let own = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)
                    .unwrap()
                    .lookup(ell);
                worst = worst.max(((got - own) / own).abs().max_element());
            }
            assert!(
                worst < 0.002,
                "{}: worst relative error {worst}",
                model.name()
            );
            let at_level = Vec3::splat(16.0 / 64.0);
            let level = Profile::from_reflectance_with(
                model,
                at_level,
                Distance::MeanFreePath(Vec3::ONE),
                eta,
            )
            .unwrap();
            let own = LocalIntegralTable::new(&level, alpha, alpha / 1024.0).unwrap();
            assert_eq!(tables.lookup(at_level, ell), own.lookup(ell), "{model:?}");
            if let ProfileModel::Burley(_) = model {
                let (k, d) = (tables.lookup(at_level, ell), dipole.lookup(at_level, ell));
                assert!(((k - d) / d).abs().max_element() > 0.01, "{k} vs {d}");
            }
        }
    }

    /// With the dense grid over a range: within 0.1% of the tables' own lookups inside it (the
    /// grid's linear steps of 1/32 octave, on the tables' interpolation), the tables' bits
    /// outside it, and no grid for a range that cannot make one.
    #[test]
    fn the_grid_follows_the_tables_inside_its_range_and_defers_outside() {
        let (eta, alpha) = (1.3, 0.05);
        for model in ProfileModel::ALL {
            let plain = LocalIntegralByKd::for_model(model, eta, alpha, alpha / 1024.0).unwrap();
            let ranged = LocalIntegralByKd::for_model(model, eta, alpha, alpha / 1024.0)
                .unwrap()
                .with_range((0.2, 0.7), (0.01, 0.4));
            assert_eq!(ranged.validate(), Ok(()));
            assert!(ranged.grid_bytes() > 0);
            let mut worst = 0.0f32;
            for i in 0..=40 {
                for j in 0..=60 {
                    let kd = Vec3::new(0.2, 0.45, 0.7) + 0.5 * (i as f32 / 40.0 - 0.5);
                    let kd = kd.clamp(Vec3::splat(0.2), Vec3::splat(0.7));
                    let ell = 0.01 * 40f32.powf(j as f32 / 60.0);
                    let ell = Vec3::new(ell, ell, ell * 0.9f32.max(0.01 / ell));
                    assert!(ranged.in_grid(kd, ell) && !plain.in_grid(kd, ell));
                    let (got, want) = (ranged.lookup(kd, ell), plain.lookup(kd, ell));
                    worst = worst.max(((got - want) / want).abs().max_element());
                }
            }
            assert!(worst < 1e-3, "{}: {worst}", model.name());
            assert!(worst > 0.0, "the grid was not used");
            // Outside in K_d (by more than the level of margin) or ℓ_u (by more than an
            // octave), or not finite: the tables' bits.
            for (kd, ell) in [
                (Vec3::splat(0.05), Vec3::splat(0.1)),
                (Vec3::new(0.5, 0.5, 0.95), Vec3::splat(0.1)),
                (Vec3::splat(0.5), Vec3::splat(0.001)),
                (Vec3::splat(0.5), Vec3::new(0.1, 0.1, 3.0)),
                (Vec3::splat(0.5), Vec3::splat(f32::INFINITY)),
                (Vec3::splat(0.5), Vec3::splat(alpha / 2048.0)),
            ] {
                assert!(!ranged.in_grid(kd, ell), "{kd} {ell}");
                assert_eq!(
                    ranged.lookup(kd, ell).to_array().map(f32::to_bits),
                    plain.lookup(kd, ell).to_array().map(f32::to_bits),
                    "{kd} {ell}"
                );
            }
        }
        let tables = || LocalIntegralByKd::new(eta, alpha, alpha / 1024.0).unwrap();
        for (kd, ell) in [
            ((0.7, 0.2), (0.01, 0.4)),
            ((0.2, 0.7), (0.4, 0.01)),
            ((0.2, 0.7), (f32::NAN, 0.4)),
            ((0.2, 0.7), (0.01, f32::INFINITY)),
            ((0.2, 0.7), (1e-30, 1e30)),
            ((f32::NAN, 0.7), (0.01, 0.4)),
        ] {
            let t = tables().with_range(kd, ell);
            assert_eq!(t.grid_bytes(), 0, "{kd:?} {ell:?}");
            assert_eq!(t.validate(), Ok(()));
        }
    }

    #[test]
    fn invalid_inputs_are_errors() {
        assert!(LocalIntegralByKd::new(0.5, 0.1, 0.0).is_err());
        assert!(LocalIntegralByKd::new(1.3, 0.0, 0.0).is_err());
        assert!(LocalIntegralByKd::new(1.3, 0.1, f32::NAN).is_err());
    }
}
