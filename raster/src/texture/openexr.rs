//! OpenEXR textures through the `exr` crate: linear float data, read as it is stored.
//!
//! The first part (layer) of the file is used, at its largest resolution level. Its channels
//! are chosen by name: `R`, `G`, `B` if all three exist; otherwise `Y` (luminance), or the one
//! channel of a single-channel part other than `A`, used for all three. Half samples are kept
//! as their 16 bits when all three channels hold them (see `texels`); otherwise half, float and
//! unsigned-int samples are converted to `f32` by value. Sub-sampled channels are not full-size
//! images and are not used. Deep data is rejected.
//!
//! Before anything is decoded, the headers are read and every part's size checked against the
//! [`TextureLimits`], and the samples of all parts together against four channels of the
//! largest allowed texture, so that a header cannot make the decoder allocate without bound.
//! Each part's block size and compression are checked too: see [`crate::exr_header`].

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{FlatSamples, MetaData, ReadChannels, ReadLayers, f16};
use glam::Vec3;

use super::image_formats::Decoded;
use super::texels::half_value;
use super::{Texels, TextureError, TextureLimits, TextureSource};

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
        crate::exr_header::check_part(header).map_err(|m| TextureError::new(path, m))?;
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
    let texels = if let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) {
        rgb_texels([r, g, b])
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
        rgb_texels([grey; 3])
    };
    Ok((width, height, texels))
}

/// The texels of three full-size channels: 16-bit codes where all three hold half floats
/// (the usual OpenEXR map; a half's bits index the table of their exact `f32` values), else
/// 32-bit linear values.
fn rgb_texels(channels: [&FlatSamples; 3]) -> Texels {
    if let [
        FlatSamples::F16(r),
        FlatSamples::F16(g),
        FlatSamples::F16(b),
    ] = channels
    {
        let texel = |((r, g), b): ((&f16, &f16), &f16)| [r, g, b].map(|h| h.to_bits());
        let codes = r.iter().zip(g).zip(b).flat_map(texel).collect();
        return Texels::codes16(codes, half_value);
    }
    let [r, g, b] = channels.map(FlatSamples::values_as_f32);
    Texels::Linear(
        r.zip(g)
            .zip(b)
            .map(|((r, g), b)| Vec3::new(r, g, b))
            .collect(),
    )
}
