//! Output files: PNG, OpenEXR, baked sample sets (PLY), and image comparison.
//!
//! | file | what |
//! |---|---|
//! | [`image`] | [`RgbImage`] (linear float RGB) and EXR [`Layer`]s |
//! | [`atomic`] | [`write_atomically`]: temporary file, fsync, rename |
//! | [`srgb`] | the sRGB transfer function and the exact 8-bit encoder |
//! | [`png`] | 8-bit sRGB PNG with exposure; PNG back to linear |
//! | [`exr`] | float OpenEXR with layers; reading the beauty back |
//! | [`ply`] | the baked irradiance sample set (binary PLY) |
//! | [`compare`](mod@compare) | RMSE, relative L1, maximum error between two images |
//! | [`heatmap`] | per-pixel error as a colour-ramp PNG |
//! | [`regions`] | translucent pixels and the shadow-edge band, from a reference's layers |
//! | [`noise`] | per-pixel standard deviation across renders with different seeds |
//!
//! Every writer is deterministic (same input, same bytes) and atomic (a file is either the
//! complete new one or the untouched old one). Every reader validates its input and returns an
//! [`OutputError`] naming the file and the problem; none panics on malformed input.

pub mod atomic;
pub mod compare;
mod error;
pub mod exr;
pub mod heatmap;
pub mod image;
pub mod noise;
pub mod ply;
pub mod png;
pub mod regions;
pub mod srgb;

pub use atomic::{WriteSeek, write_atomically};
pub use compare::{ErrorStats, RELATIVE_L1_OFFSET, compare};
pub use error::OutputError;
pub use exr::{ExrImage, read_exr, read_exr_rgb, write_exr};
pub use heatmap::{ErrorMetric, Heatmap, HeatmapOptions, HeatmapScale, error_heatmap};
pub use image::{Layer, LayerData, RgbImage};
pub use noise::{NoiseStats, seed_noise};
pub use ply::{SampleSet, read_ply, read_ply_with_comments, write_ply};
pub use png::{read_png, write_png};
pub use regions::{default_band_radius, shadow_edge_band, translucent_mask};
