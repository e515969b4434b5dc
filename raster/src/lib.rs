//! lucent-raster: turns a scene into an image, shading every translucent pixel through
//! `lucent-core`.
//!
//! The pipeline, one module per stage:
//!
//! | stage | module |
//! |---|---|
//! | scene file, OBJ meshes, textures | [`scene`], [`texture`] |
//! | blue-noise irradiance samples | [`sampling`] |
//! | shadow rays | [`geometry`] |
//! | fixed-point rasterisation, visibility | [`raster`], [`camera`] |
//! | lights and irradiance | [`lights`] |
//! | shading through the core | [`material`], [`render`] |
//! | PNG / EXR / PLY output, image comparison | [`output`] |
//! | 2-D report drawing: charts, contact sheets | `plot` (feature `harness`) |
//! | run time against error: `lucent bench` | `bench` (feature `harness`) |
//! | the `lucent` command | [`cli`] |
//!
//! The feature `harness` (on by default) adds the experiment harness: `bench`, `plot`, the
//! image comparison in [`output`] and the `bench` and `compare` commands. Without it
//! (`--no-default-features`) the crate is the renderer alone, without `tiny-skia`.

#[cfg(feature = "harness")]
pub mod bench;
pub mod camera;
pub mod cli;
mod exr_header;
pub mod geometry;
pub mod lights;
pub mod material;
pub mod memory;
pub mod output;
mod parallel;
#[cfg(feature = "harness")]
pub mod plot;
pub mod raster;
pub mod render;
pub mod sampling;
pub mod scene;

pub mod texture;
