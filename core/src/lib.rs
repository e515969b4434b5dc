//! # lucent-core
//!
//! Point-based subsurface scattering for translucent materials, `#![no_std]` with `alloc`:
//!
//! - the classical dipole of Jensen et al. 2001 ([`Dipole`], [`Profile`]), from coefficients,
//!   artist parameters or measured presets, with the project's exitance → radiance convention;
//! - an irradiance cache ([`IrradianceCache`]): a linear octree over Morton-sorted, quantised
//!   sample positions in flat structure-of-arrays, queried 8 nodes or 8 samples at a time;
//! - five queries ([`Method`]): hierarchical (Jensen & Buhler 2002), local-global (Langlands &
//!   Mertens 2007), edge-aware (Neulander 2010), exhaustive, and edge-refined (edge-aware with
//!   the local term a quadrature of the irradiance at edges, [`refine`]);
//! - the local-integral table of Neulander 2010 ([`LocalIntegralTable`]), cached at powers of
//!   two of the mean free path and interpolated, lock-free.
//!
//! Lengths are in scene units, coefficients in inverse scene units, irradiance and exitance in
//! any consistent radiometric unit. η is the relative index inside / outside.
//!
//! # Quick start
//!
//! ```
//! use lucent_core::{IrradianceCache, LocalIntegralTable, Method, Profile, QuerySettings, Sample, ShadingPoint};
//! use lucent_core::glam::Vec3;
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
//! // Edge-aware query (N10) with smoothing radius α = 2·√Ā.
//! let alpha = cache.smoothing_radius(2.0);
//! let table = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)?;
//! let settings = QuerySettings { method: Method::EdgeAware, smoothing_radius: alpha, ..Default::default() };
//! let point = ShadingPoint { position: Vec3::new(0.01, 0.02, 0.0), irradiance: Vec3::ONE };
//! let k = table.lookup(profile.mean_free_path());
//! let m = cache.query(&profile, &point, k, &settings)?;
//! assert!(m.total.min_element() > 0.0 && m.total.max_element() < 1.0);
//!
//! // Radiance towards a viewer at 30° from the normal.
//! let radiance = profile.radiance(m.total, 30f32.to_radians().cos());
//! # assert!(radiance.is_finite());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Features
//!
//! - `simd` (default): 8-wide SIMD lanes through `wide`. Off, the same code runs on a scalar
//!   `[f32; 8]` lane type.
#![no_std]
#![warn(missing_docs)]

extern crate alloc;

pub mod cache;
pub mod dipole;
pub mod error;
pub mod fresnel;
pub mod kernel;
pub mod lanes;
pub mod math;
pub mod morton;
pub mod presets;
pub mod profile;
pub mod quadrature;
pub mod query;
pub mod refine;
pub mod stats;
pub mod table;

pub use glam;

pub use cache::{IrradianceCache, Sample};
pub use dipole::Dipole;
pub use error::{BuildError, ParamError};
pub use kernel::Kernel;
pub use profile::{Distance, Profile};
pub use query::{Exitance, Method, QueryError, QuerySettings, ShadingPoint};
pub use refine::LocalQuadrature;
pub use stats::{NoStats, QueryStats, StatsSink};
pub use table::LocalIntegralTable;
