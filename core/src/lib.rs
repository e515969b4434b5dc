//! # lucent-core
//!
//! Point-based subsurface scattering for translucent materials, `#![no_std]` with `alloc`:
//!
//! - the classical dipole of Jensen et al. 2001 ([`Profile`], per channel a [`Dipole`]), from
//!   coefficients, artist parameters ([`Distance`]) or measured [`presets`], with the
//!   project's exitance → radiance convention;
//! - an irradiance cache ([`IrradianceCache`] of [`Sample`]s): a linear octree over
//!   Morton-sorted, quantised sample positions in flat structure-of-arrays, queried 8 nodes or
//!   8 samples at a time;
//! - five queries ([`Method`]) at a [`ShadingPoint`], giving an [`Exitance`]: hierarchical
//!   (Jensen & Buhler 2002), local-global (Langlands & Mertens 2007), edge-aware (Neulander
//!   2010), edge-refined (edge-aware with the local term a quadrature of the irradiance at
//!   edges, [`LocalQuadrature`]) and exhaustive;
//! - the local integral K of the split methods, bound to its smoothing radius α in a
//!   [`LocalTerm`]: from the table of Neulander 2010 ([`LocalIntegralTable`], cached at powers
//!   of two of the mean free path and interpolated, lock-free), from tables over a
//!   texture-mapped reflectance ([`LocalIntegralByKd`]), or by quadrature
//!   ([`LocalTerm::exact`]).
//!
//! Errors are typed ([`error`]); traversal counters for benchmarks are in [`stats`].
//!
//! Lengths are in scene units, coefficients in inverse scene units, irradiance and exitance in
//! any consistent radiometric unit. η is the relative index inside / outside.
//!
//! # Quick start
//!
//! ```
//! use lucent_core::glam::Vec3;
//! use lucent_core::{IrradianceCache, LocalIntegralTable, Method, Profile, QuerySettings};
//! use lucent_core::{Sample, ShadingPoint};
//!
//! // Marble, modelled in centimetres (10 mm per scene unit).
//! let marble = lucent_core::presets::find("marble").unwrap();
//! let profile = Profile::from_preset(marble, 10.0)?;
//!
//! // A 4 × 4 cm patch of irradiance samples, 0.05 cm apart, uniformly lit.
//! let mut samples = Vec::new();
//! for i in 0..80 {
//!     for j in 0..80 {
//!         let position = Vec3::new(i as f32 * 0.05 - 2.0, j as f32 * 0.05 - 2.0, 0.0);
//!         samples.push(Sample { position, area: 0.05 * 0.05, irradiance: Vec3::ONE });
//!     }
//! }
//! let cache = IrradianceCache::build(&samples)?;
//! cache.validate()?;
//!
//! // Edge-aware query (N10) with smoothing radius α = 2·√Ā; the table hands out K bound to α.
//! let alpha = cache.smoothing_radius(2.0);
//! let table = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)?;
//! let local = table.local_term(profile.mean_free_path());
//! let settings = QuerySettings { method: Method::EdgeAware, ..Default::default() };
//! let point = ShadingPoint { position: Vec3::new(0.01, 0.02, 0.0), irradiance: Vec3::ONE };
//! let m = cache.query(&profile, &point, local, &settings)?;
//!
//! // Far from the patch's edges a uniformly lit surface gives back E·Rd_total = E·K_d.
//! let rd_total = profile.total_reflectance();
//! assert!(((m.total - rd_total) / rd_total).abs().max_element() < 0.01);
//!
//! // Radiance towards a viewer at 30° from the normal.
//! let radiance = profile.radiance(m.total, 30f32.to_radians().cos());
//! # assert!(radiance.is_finite());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! `core/examples/embed.rs` runs every method on such a patch.
//!
//! # Features
//!
//! - `simd` (default): 8-wide SIMD lanes through `wide`. Off, the same code runs on a scalar
//!   `[f32; 8]` lane type.
#![no_std]
#![warn(missing_docs)]

extern crate alloc;

mod better_dipole;
mod burley;
mod cache;
mod cell_average;
mod dipole;
pub mod error;
mod fresnel;
mod kd_grid;
mod kd_tables;
mod kernel;
mod lanes;
mod local_term;
mod math;
mod moments;
mod morton;
pub mod presets;
mod profile;
mod quadrature;
mod query;
mod random_walk;
mod refine;
mod seed;
pub mod stats;
mod table;
mod unit_profile;

/// The vector types of the API (`Vec3` for positions and RGB values), re-exported so that an
/// embedder uses the same glam version.
pub use glam;

pub use better_dipole::BetterDipole;
pub use burley::{Burley, BurleyFit};
pub use cache::{IrradianceCache, Sample};
pub use cell_average::CellAverage;
pub use dipole::Dipole;
pub use kd_tables::LocalIntegralByKd;
pub use local_term::LocalTerm;
pub use profile::{Distance, Profile, ProfileModel};
pub use query::{Exitance, Method, QueryPlan, QuerySettings, ShadingPoint};
pub use refine::{LocalQuadrature, QuadratureLayout};
pub use table::LocalIntegralTable;

/// Implementation details that the renderer, the test suites, the benchmarks and the fuzz
/// targets of this repository need: the lane types, the exhaustive oracles, the dipole and
/// kernel in closed form, the quadratures. **Unstable**: not part of the API, changed without
/// notice; an embedder should not use it.
#[doc(hidden)]
pub mod internals {
    pub use crate::better_dipole::{Boundary, UnitBetterDipole};
    pub use crate::burley::{UnitBurley, disc_average, polynomial_exp_integral};
    pub use crate::cache::{
        LEAF_CAPACITY, MAX_DEPTH, MAX_SAMPLES, NODE_BYTES, SAMPLE_BYTES, exhaustive_edge_aware,
        exhaustive_local_global, exhaustive_sum, exhaustive_sum_lanes,
    };
    pub use crate::dipole::{
        AlbedoInverter, MAX_ETA, NodeMoments, UnitDipole, albedo_from_total_reflectance,
        boundary_term, total_reflectance,
    };
    pub use crate::kernel::Kernel;
    #[cfg(feature = "simd")]
    pub use crate::lanes::SimdLanes;
    pub use crate::lanes::{DefaultLanes, LANES, Lanes, Mask, ScalarLanes};
    pub use crate::morton::Grid;
    pub use crate::profile::{KD_MAX, KD_MIN};
    pub use crate::quadrature::GaussLegendre;
    pub use crate::refine::{
        DEFAULT_PER_RING, DEFAULT_RINGS, EDGE_THRESHOLD, MAX_NODES, MAX_PER_RING, MAX_RINGS,
    };
    pub use crate::seed::splitmix64;
    pub use crate::table::{
        exact_local_integral, local_integral_and_slope_unit, local_integral_slope_unit,
        local_integral_unit,
    };
    pub use crate::unit_profile::{UnitProfile, UnitShape};

    /// A local term with any α and K, not computed together: for testing the queries against
    /// the exhaustive oracles at chosen K (the API hands out only K computed for its α).
    pub fn local_term(alpha: f32, k: glam::Vec3) -> crate::LocalTerm {
        crate::LocalTerm::new(alpha, k)
    }

    /// Fresnel reflectance and transmittance (`docs/physics.md` §2).
    pub mod fresnel {
        pub use crate::fresnel::*;
    }
    /// The libm-backed transcendentals every computation of the core goes through.
    pub mod math {
        pub use crate::math::*;
    }
    /// Morton codes of quantised positions.
    pub mod morton {
        pub use crate::morton::*;
    }
    /// The Monte Carlo reference for diffusion profiles: a random walk in a semi-infinite
    /// medium scored as a radial profile, Chandrasekhar's H-function, and the comparison of a
    /// model's profile with the walk's.
    pub mod random_walk {
        pub use crate::random_walk::*;
    }
}
