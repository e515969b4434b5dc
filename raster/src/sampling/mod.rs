//! Blue-noise irradiance sample placement over triangle meshes.
//!
//! The subsurface integral is a sum over irradiance samples spread evenly over every
//! translucent surface, each standing for an equal share of the area
//! (`total_area(triangles) / N`). [`poisson_samples`] places them: area-uniform in distribution
//! and Poisson-disk (blue-noise) in arrangement, so no two crowd together and no gap opens, at
//! exactly the requested count, by weighted sample elimination (Yuksel 2015).
//! [`stratified_square`] gives the per-pixel sample patterns for area-light soft shadows.
//!
//! | file | what |
//! |---|---|
//! | `rng.rs` | PCG32 and SplitMix64 (deterministic randomness) |
//! | `surface.rs` | surface points, sample counts, area-uniform candidates |
//! | `grid.rs` | tiles of cells over the candidates: neighbourhoods for parallel elimination |
//! | `maxtree.rs` | blocked tournament tree: the heaviest candidate |
//! | `poisson.rs` | weighted sample elimination |
//! | `stratified.rs` | stratified points in the unit square |
//! | `error.rs` | errors |

mod error;
mod grid;
mod maxtree;
mod poisson;
pub mod rng;
mod strata;
mod stratified;
mod surface;

pub use error::{MAX_SAMPLES, SamplingError};
pub use poisson::{poisson_samples, poisson_samples_with_progress};
pub use stratified::{StratifiedSquare, stratified_square};
pub use surface::{SampleTarget, SurfacePoint, hex_spacing, total_area, triangle_area};

#[cfg(test)]
mod tests;
