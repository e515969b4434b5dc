//! Blue-noise irradiance sample placement over triangle meshes.
//!
//! The subsurface integral is a sum over irradiance samples spread evenly over every
//! translucent surface, each weighted by the area it stands for. [`poisson_samples`] places
//! them: area-uniform in distribution and Poisson-disk (blue-noise) in arrangement, so no two
//! crowd together and no gap opens, at exactly the requested count, by weighted sample
//! elimination (Yuksel 2015). [`voronoi_areas`] gives each its own share of its object's
//! surface, its cell of the restricted Voronoi diagram (3-D Euclidean Voronoi cells intersected
//! with the triangles, computed exactly by clipping with a security radius; see `voronoi/`).
//!
//! Why not equal areas (`total / N`, unbiased on average): blue noise still has local density
//! fluctuations, and a finite surface holds more samples near its borders than inside; with
//! equal areas both became exitance error. On a uniformly lit plane of marble at the default
//! scene's density (64² pixels over its middle, 3 seeds), the exhaustive sum sat 0.44% below
//! E·Rd_total with equal areas and is within 0.02% with Voronoi areas; the split methods'
//! per-pixel noise fell from 2.6% to 1.1% (skin: 4.4% → 2.7%). Cost: about 1.7 µs of CPU per
//! sample (1M samples on the bunny: 1.7 s CPU) and at most 33 bytes per sample of transient
//! memory; the areas sum to each object's area to 1e-10 relative.
//! [`stratified_square`] gives the per-pixel sample patterns for area-light soft shadows.
//!
//! | file | what |
//! |---|---|
//! | `rng.rs` | PCG32 and SplitMix64 (deterministic randomness) |
//! | `surface.rs` | surface points, sample counts, area-uniform candidates |
//! | `grid.rs` | tiles of cells over the candidates: neighbourhoods for parallel elimination |
//! | `maxtree.rs` | blocked tournament tree: the heaviest candidate |
//! | `poisson.rs` | weighted sample elimination |
//! | `voronoi/` | per-sample areas: restricted Voronoi cells (grid, whole triangles, clipping, completion) |
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
mod voronoi;

pub use error::{MAX_SAMPLES, SamplingError};
pub use poisson::{poisson_samples, poisson_samples_with_progress};
pub use stratified::{StratifiedSquare, stratified_square};
pub use surface::{SampleTarget, SurfacePoint, hex_spacing, total_area, triangle_area};
pub use voronoi::{VoronoiAreas, VoronoiStats, voronoi_areas, voronoi_areas_with_progress};

#[cfg(test)]
mod tests;
