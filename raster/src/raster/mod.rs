//! Fixed-point scanline rasterisation into a supersampled visibility buffer.
//!
//! The renderer does not shade while rasterising. It first records, for each of the `aa × aa`
//! sub-samples of every pixel, which triangle is nearest there ([`VisibilityBuffer`]); then it
//! [resolves](VisibilityBuffer::resolve) each pixel into one [`Fragment`] per visible surface,
//! shades that fragment once at a representative sub-sample, using
//! [`perspective_barycentrics`] to interpolate vertex attributes, and weights it by
//! `coverage / aa²`. Antialiasing thus costs sub-sample *coverage*, not sub-sample *shading*,
//! except where a fragment's sub-samples see different light, normals or material: the
//! renderer's second pass (`render::adaptive`) splits those fragments into a few groups of
//! sub-samples, each shaded once.
//!
//! Pipeline of [`VisibilityBuffer::rasterize_triangle`], one module per stage:
//!
//! 1. `clip`: reject NaN / infinity, then clip against the six frustum planes (near plane
//!    `z >= 0` for glam's [0, 1] depth) in 2D homogeneous coordinates (Olano & Greer 1997): the
//!    viewport square is cut by the triangle's three edge lines and its near and far lines, all
//!    exact to one rounding for any finite `f32` input, so even corners at 10^30 or behind the eye
//!    clip correctly and nothing large ever reaches the fixed-point conversion. The same lines
//!    give the triangle's depth plane.
//! 2. `fixed`: snap to signed 24.8 fixed point (1/256 sub-sample, i.e. 1/(256·aa) pixel). All
//!    coverage decisions from here on are exact integer arithmetic.
//! 3. `scan`: walk the edges row by row with an exact integer DDA and emit spans under the
//!    top-left fill rule (watertight: every sub-sample centre on a shared edge belongs to
//!    exactly one triangle).
//! 4. `visibility`: interpolate NDC depth along each span and keep the nearest (`<`, so ties
//!    keep the earlier triangle).
//!
//! Written in the spirit of tiny-skia's fixed-point edge walkers, without its code.

mod barycentric;
mod clip;
mod error;
mod fixed;
mod resolve;
mod scan;
mod visibility;

#[cfg(test)]
mod tests;
#[cfg(test)]
pub(crate) mod testutil;

pub use barycentric::perspective_barycentrics;
pub use error::RasterError;
pub use resolve::Fragment;
pub use visibility::{EMPTY, MAX_AA, MAX_SUBSAMPLES, VisibilityBuffer};
