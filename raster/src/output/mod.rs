//! Output files: PNG, OpenEXR, baked sample sets (PLY), and image comparison.
//!
//! | file | what |
//! |---|---|
//! | [`image`] | [`RgbImage`] (linear float RGB) and EXR [`Layer`]s |
//! | [`atomic`] | [`write_atomically`]: temporary file, fsync, rename |
//! | [`srgb`] | the sRGB transfer function and the exact 8-bit encoder |
//! | [`png`] | 8-bit sRGB PNG with exposure; PNG back to linear |
//! | [`exr`] | float OpenEXR with layers; reading the beauty back |
//! | [`tile`] | a [`Region`] of an image as an OpenEXR tile (data window in the display window) |
//! | [`merge`] | assembling tiles into the whole image |
//! | [`ply`] | the baked irradiance sample set (binary PLY) |
//! | `compare` | RMSE, relative L1, maximum error between two images |
//! | `heatmap` | per-pixel error as a colour-ramp PNG |
//! | `regions` | translucent pixels and the shadow-edge band, from a reference's layers |
//! | `noise` | per-pixel standard deviation across renders with different seeds |
//!
//! The last four, the image comparison of `lucent compare` and `lucent bench`, are part of the
//! experiment harness (feature `harness`, on by default).
//!
//! Every writer is deterministic (same input, same bytes) and atomic (a file is either the
//! complete new one or the untouched old one). Every reader validates its input and returns an
//! [`OutputError`] naming the file and the problem; none panics on malformed input.

pub mod atomic;
#[cfg(feature = "harness")]
pub mod compare;
mod error;
pub mod exr;
#[cfg(feature = "harness")]
pub mod heatmap;
pub mod image;
pub mod merge;
#[cfg(feature = "harness")]
pub mod noise;
pub mod ply;
pub mod png;
#[cfg(feature = "harness")]
pub mod regions;
pub mod srgb;
pub mod tile;

pub use atomic::{
    WriteSeek, output_target, refuse_read_only, write_atomically, write_text_atomically,
};
#[cfg(feature = "harness")]
pub use compare::{ErrorStats, RELATIVE_L1_OFFSET, compare};
pub use error::OutputError;
pub use exr::{
    ExrImage, Frame, decode_exr_framed, read_exr, read_exr_framed, read_exr_rgb, write_exr,
};
#[cfg(feature = "harness")]
pub use heatmap::{ErrorMetric, Heatmap, HeatmapOptions, HeatmapScale, error_heatmap};
pub use image::{Layer, LayerData, RgbImage};
pub use merge::{Merged, merge_tiles};
#[cfg(feature = "harness")]
pub use noise::{NoiseStats, seed_noise};
pub use ply::{SampleSet, decode_ply_with_comments, read_ply, read_ply_with_comments, write_ply};
pub use png::{read_png, write_png};
#[cfg(feature = "harness")]
pub use regions::{default_band_radius, shadow_edge_band, translucent_mask};
pub use tile::{ExrTile, Placement, Region, decode_exr_tile, read_exr_tile, write_exr_tile};
