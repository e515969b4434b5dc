//! OpenEXR textures through the `exr` crate: linear float data, read as it is stored.
//!
//! The first part (layer) of the file is used, at its largest resolution level. Its channels
//! are chosen by name: `R`, `G`, `B` if all three exist; otherwise `Y` (luminance), or the one
//! channel of a single-channel part other than `A`, used for all three. Half, float and
//! unsigned-int samples are converted to `f32` by value. Sub-sampled channels are not full-size
//! images and are not used. Deep data is rejected.
//!
//! Before anything is decoded, the headers are read and every part's size checked against the
//! [`TextureLimits`], and the samples of all parts together against four channels of the
//! largest allowed texture, so that a header cannot make the decoder allocate without bound.
//! Each part's block (a tile, or a run of scan lines) is checked too: see [`check_block_size`].

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{FlatSamples, MetaData, ReadChannels, ReadLayers};
use glam::Vec3;

use super::image_formats::Decoded;
use super::{TextureError, TextureLimits, TextureSource};

/// Bytes a block may always hold, whatever the part's size: a tile overhanging a small image,
/// or 256 scan lines of four float channels at the widest texture (16384 × 256 × 16 bytes).
const BLOCK_BYTES_FLOOR: u64 = 64 << 20;

/// Refuses B44 and B44A parts: `exr`'s B44 decoder does OpenEXR's unsigned 16-bit arithmetic
/// with subtractions that wrap, which a build with overflow checks (tests, fuzzing, debug)
/// turns into a panic on ordinary data. These lossy formats are meant for images to look at,
/// not for textures read as data.
fn check_compression(header: &exr::meta::header::Header, path: &Path) -> Result<(), TextureError> {
    use exr::compression::Compression;
    let name = match header.compression {
        Compression::B44 => "B44",
        Compression::B44A => "B44A",
        _ => return Ok(()),
    };
    Err(TextureError::new(
        path,
        format!(
            "OpenEXR {name} compression is not read (save the texture with ZIP, PIZ or no \
             compression)"
        ),
    ))
}

/// Refuses a part whose blocks (tiles, or runs of scan lines) hold more bytes than the whole
/// part, or than [`BLOCK_BYTES_FLOOR`] if that is more.
///
/// The decoder reads each block into a buffer of the size the header implies for a block
/// before it finds out whether the file holds that many bytes, and the header's tile size is
/// not tied to the image's: a 2.5 KB file declaring 64 × 16 449 600-pixel tiles on a 64 × 64
/// image made it zero-fill a gigabyte. A real block is a piece of its image, so only a part
/// smaller than one block (a tiny image in large tiles) comes near the bound.
fn check_block_size(header: &exr::meta::header::Header, path: &Path) -> Result<(), TextureError> {
    let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
    let bytes_per_pixel = header.channels.bytes_per_pixel as u64;
    let (block_pixels, what) = match header.blocks {
        exr::meta::BlockDescription::Tiles(tiles) => {
            let (tw, th) = (tiles.tile_size.0 as u64, tiles.tile_size.1 as u64);
            (
                tw.saturating_mul(th),
                format!("tiles of {tw} × {th} pixels"),
            )
        }
        exr::meta::BlockDescription::ScanLines => {
            let lines = header.compression.scan_lines_per_block() as u64;
            (
                lines.saturating_mul(w),
                format!("blocks of {lines} scan lines"),
            )
        }
    };
    let block_bytes = block_pixels.saturating_mul(bytes_per_pixel);
    let allowed = w
        .saturating_mul(h)
        .saturating_mul(bytes_per_pixel)
        .max(BLOCK_BYTES_FLOOR);
    if block_bytes > allowed {
        return Err(TextureError::new(
            path,
            format!(
                "OpenEXR part of {w} × {h} pixels declares {what} ({block_bytes} bytes each, \
                 more than the {allowed} bytes lucent allows a block of this part)"
            ),
        ));
    }
    Ok(())
}

/// Decodes an OpenEXR file held in memory.
pub(super) fn decode_exr(
    bytes: &[u8],
    path: &Path,
    limits: &TextureLimits,
) -> Result<Decoded, TextureError> {
    let failed = |e: exr::error::Error| TextureError {
        path: path.to_path_buf(),
        message: format!("OpenEXR decoding failed: {e}"),
        source: Some(TextureSource::Exr(e)),
    };
    let meta = MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(failed)?;
    let Some(first) = meta.headers.first() else {
        return Err(TextureError::new(path, "OpenEXR file without parts"));
    };
    let size = |h: &exr::meta::header::Header| (h.layer_size.0, h.layer_size.1);
    let (width, height) = size(first);
    let (width, height) = (
        u32::try_from(width).unwrap_or(u32::MAX),
        u32::try_from(height).unwrap_or(u32::MAX),
    );
    limits
        .check(width, height)
        .map_err(|m| TextureError::new(path, m))?;
    let mut samples = 0u64;
    for header in meta.headers.iter() {
        let (w, h) = size(header);
        let channels = header.channels.list.len() as u64;
        samples =
            samples.saturating_add((w as u64).saturating_mul(h as u64).saturating_mul(channels));
        check_block_size(header, path)?;
        check_compression(header, path)?;
    }
    let max_samples = limits.max_texels.saturating_mul(4);
    if samples > max_samples {
        return Err(TextureError::new(
            path,
            format!(
                "OpenEXR file holds {samples} samples in all, more than the {max_samples} \
                 (four channels of the largest texture) lucent reads"
            ),
        ));
    }

    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(failed)?;
    let layer = image.layer_data;
    if (layer.size.0, layer.size.1) != (width as usize, height as usize) {
        return Err(TextureError::new(
            path,
            format!(
                "decoded {} × {} pixels, the header says {width} × {height}",
                layer.size.0, layer.size.1
            ),
        ));
    }
    let texels = width as usize * height as usize;
    // Full-size channels by name.
    let channels: Vec<(String, &FlatSamples)> = layer
        .channel_data
        .list
        .iter()
        .filter(|c| c.sample_data.len() == texels)
        .map(|c| (c.name.to_string(), &c.sample_data))
        .collect();
    let find = |name: &str| channels.iter().find(|(n, _)| n == name).map(|(_, s)| *s);
    let values = |s: &FlatSamples| s.values_as_f32().collect::<Vec<f32>>();
    let texels = if let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) {
        let (r, g, b) = (values(r), values(g), values(b));
        (0..texels).map(|i| Vec3::new(r[i], g[i], b[i])).collect()
    } else {
        let non_alpha: Vec<&(String, &FlatSamples)> =
            channels.iter().filter(|(n, _)| n != "A").collect();
        let grey = find("Y").or(match non_alpha.as_slice() {
            [(_, only)] => Some(*only),
            _ => None,
        });
        let Some(grey) = grey else {
            let names: Vec<String> = layer
                .channel_data
                .list
                .iter()
                .take(16)
                .map(|c| c.name.to_string())
                .collect();
            return Err(TextureError::new(
                path,
                format!(
                    "OpenEXR part has no R, G, B channels, no Y channel and not exactly one \
                     other full-size channel (channels: {})",
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ),
            ));
        };
        values(grey).into_iter().map(Vec3::splat).collect()
    };
    Ok((width, height, texels))
}
