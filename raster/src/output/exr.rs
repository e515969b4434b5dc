//! Linear float OpenEXR output (beauty plus optional layers in one file), and reading back.
//!
//! # File layout
//!
//! One single-part, scan-line OpenEXR file, every channel 32-bit float (`f32`, so the values
//! the renderer computed are stored exactly; half floats would round irradiance to 11
//! significant bits, which is visible in `lucent compare` at the accuracy we measure), ZIP
//! compression in blocks of 16 scan lines (lossless), increasing line order, data window = display
//! window = `[0, width−1] × [0, height−1]`. Channel names follow the OpenEXR layer convention
//! `layer.channel`:
//!
//! | channels | content |
//! |---|---|
//! | `R`, `G`, `B` | the beauty image (final linear RGB, premultiplied by the alpha) |
//! | `A` | alpha: the fraction of each pixel's coverage sub-samples that see a surface (if given) |
//! | `exitance.R`, `exitance.G`, `exitance.B` | translucent exitance M_o |
//! | `local.R`, `local.G`, `local.B` | local term of the split |
//! | `global.R`, `global.G`, `global.B` | global term of the split |
//! | `irradiance.R`, `irradiance.G`, `irradiance.B` | irradiance at the shading point |
//! | `depth.Z` | camera-space depth (+∞ where no surface is visible) |
//!
//! An RGB [`Layer`] named `n` becomes `n.R`, `n.G`, `n.B`; a scalar layer `n` with channel `c`
//! becomes `n.c`. As the format requires, channels are stored sorted by name (byte order, so
//! `B`, `G`, `R`, `depth.Z`, `exitance.B`, ...). The header holds only the attributes the format
//! requires plus `software = "lucent"`: no time stamp, so the same image gives the same bytes.
//! Writing goes through [`write_atomically`].
//!
//! # Reading
//!
//! [`read_exr_rgb`] finds the channels `R`, `G`, `B` (in any part, any sample type; a part
//! with a layer name `n` contributes channels `n.c`) and returns them as an [`RgbImage`] of
//! the part's data window. [`read_exr`] also returns the alpha channel `A` if there is one,
//! and every layer it recognises: a prefix `n`
//! with channels `n.R`, `n.G`, `n.B` becomes an RGB layer, a prefix with exactly one channel a
//! scalar layer; other channels are ignored. Malformed, truncated or oversized files
//! (more than [`MAX_PIXELS`] per part) give an [`OutputError`], never a panic; so do the lossy
//! B44 compressions and blocks larger than their part, refused from the header before the
//! decoder sees them (the checks the texture reader makes too).

use std::fs::File;
use std::io::{BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Blocks, Compression, Encoding, FlatSamples, Image,
    ImageAttributes, IntegerBounds, LayerAttributes, LineOrder, MetaData, ReadChannels, ReadLayers,
    SmallVec, Text, Vec2, WritableImage,
};
use glam::Vec3;

use super::atomic::write_atomically;
use super::image::{MAX_PIXELS, is_valid_name};
use super::tile::{EXPOSURE_ATTRIBUTE, Placement};
use super::{Layer, LayerData, OutputError, RgbImage};
use crate::memory;

/// The most channels a part may have for lucent to read it.
const MAX_CHANNELS: usize = 1024;

/// A decoded EXR: the beauty image and the recognised layers, in file (name) order.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Channels `R`, `G`, `B`.
    pub beauty: RgbImage,
    /// Channel `A`, if the file has one.
    pub alpha: Option<Vec<f32>>,
    /// Layers (see the module doc for what is recognised).
    pub layers: Vec<Layer>,
}

/// Writes `beauty`, its `alpha` (if any) and `layers` into one OpenEXR file at `path`,
/// atomically (layout in the module doc).
///
/// Fails on a zero-sized image, an invalid or duplicate layer name, or an alpha or a layer
/// whose pixel count differs from the beauty image's.
pub fn write_exr(
    path: &Path,
    beauty: &RgbImage,
    alpha: Option<&[f32]>,
    layers: &[Layer],
) -> Result<(), OutputError> {
    write_exr_placed(path, beauty, alpha, layers, None)
}

/// [`write_exr`], or with a `placement` a tile ([`super::tile`]): `beauty`, `alpha` and
/// `layers` are the region's pixels, written as the data window of the full image's display
/// window, with the exposure in the header.
pub(super) fn write_exr_placed(
    path: &Path,
    beauty: &RgbImage,
    alpha: Option<&[f32]>,
    layers: &[Layer],
    placement: Option<&Placement>,
) -> Result<(), OutputError> {
    let (width, height) = beauty.size();
    if let Some(placement) = placement {
        placement.check(path)?;
        let region = placement.region;
        if (region.width(), region.height()) != (width, height) {
            return Err(OutputError::invalid(
                path,
                format!(
                    "the region {region} is {}x{}, the image {width}x{height}",
                    region.width(),
                    region.height()
                ),
            ));
        }
    }
    if width == 0 || height == 0 {
        return Err(OutputError::invalid(
            path,
            format!("cannot write a {width}x{height} image (both sides must be positive)"),
        ));
    }
    let n = beauty.pixels().len();
    if let Some(alpha) = alpha
        && alpha.len() != n
    {
        return Err(OutputError::invalid(
            path,
            format!(
                "the alpha has {} pixels, the {width}x{height} image has {n}",
                alpha.len()
            ),
        ));
    }
    for (i, layer) in layers.iter().enumerate() {
        if !is_valid_name(&layer.name) {
            return Err(OutputError::invalid(
                path,
                format!(
                    "layer name '{}' is invalid (use 1 to 24 characters from A-Z a-z 0-9 _ -)",
                    layer.name
                ),
            ));
        }
        if layers[..i].iter().any(|l| l.name == layer.name) {
            return Err(OutputError::invalid(
                path,
                format!("layer '{}' given twice", layer.name),
            ));
        }
        if let LayerData::Scalar { channel, .. } = &layer.data
            && !is_valid_name(channel)
        {
            return Err(OutputError::invalid(
                path,
                format!(
                    "channel name '{channel}' of layer '{}' is invalid",
                    layer.name
                ),
            ));
        }
        if layer.len() != n {
            return Err(OutputError::invalid(
                path,
                format!(
                    "layer '{}' has {} pixels, the {width}x{height} image has {n}",
                    layer.name,
                    layer.len()
                ),
            ));
        }
    }

    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    push_rgb(path, &mut list, "", beauty.pixels())?;
    if let Some(alpha) = alpha {
        list.push(AnyChannel::new(
            text(path, "A")?,
            FlatSamples::F32(alpha.to_vec()),
        ));
    }
    for layer in layers {
        match &layer.data {
            LayerData::Rgb(pixels) => push_rgb(path, &mut list, &layer.name, pixels)?,
            LayerData::Scalar { channel, values } => {
                let name = text(path, &format!("{}.{channel}", layer.name))?;
                list.push(AnyChannel::new(name, FlatSamples::F32(values.clone())));
            }
        }
    }

    let mut attributes = LayerAttributes {
        software_name: Some(text(path, "lucent")?),
        ..Default::default()
    };
    if let Some(placement) = placement {
        let region = placement.region;
        attributes.layer_position = Vec2(region.x0 as i32, region.y0 as i32);
        attributes.other.insert(
            text(path, EXPOSURE_ATTRIBUTE)?,
            AttributeValue::F32(placement.exposure),
        );
    }
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = exr::image::Layer::new(
        Vec2(width as usize, height as usize),
        attributes,
        encoding,
        AnyChannels::sort(list),
    );
    let image = match placement {
        None => Image::from_layer(layer),
        Some(placement) => {
            let (w, h) = placement.display;
            let display = IntegerBounds::new(Vec2(0, 0), Vec2(w as usize, h as usize));
            Image::new(ImageAttributes::new(display), layer)
        }
    };
    write_atomically(path, |w| {
        // `non_parallel`: exr is built without rayon, and sequential block order keeps the
        // bytes independent of scheduling anyway.
        image
            .write()
            .non_parallel()
            .to_buffered(w)
            .map_err(|source| OutputError::Exr {
                path: path.to_path_buf(),
                source,
            })
    })
}

fn text(path: &Path, s: &str) -> Result<Text, OutputError> {
    Text::new_or_none(s).ok_or_else(|| {
        OutputError::invalid(path, format!("'{s}' cannot be stored as an OpenEXR name"))
    })
}

/// Appends the three channels `prefix.R`, `prefix.G`, `prefix.B` (or `R`, `G`, `B`).
fn push_rgb(
    path: &Path,
    list: &mut SmallVec<[AnyChannel<FlatSamples>; 4]>,
    prefix: &str,
    pixels: &[Vec3],
) -> Result<(), OutputError> {
    for (c, suffix) in ["R", "G", "B"].into_iter().enumerate() {
        let name = if prefix.is_empty() {
            suffix.to_string()
        } else {
            format!("{prefix}.{suffix}")
        };
        let values: Vec<f32> = pixels.iter().map(|p| p[c]).collect();
        list.push(AnyChannel::new(
            text(path, &name)?,
            FlatSamples::F32(values),
        ));
    }
    Ok(())
}

/// One decoded channel with its full (`layer.channel`) name.
struct Channel {
    name: String,
    /// Position of its part's data window.
    origin: (i32, i32),
    size: (u32, u32),
    values: Vec<f32>,
}

/// Where a decoded file's pixels lie (see [`read_exr_framed`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The display window's position.
    pub display_origin: (i32, i32),
    /// The display window's size.
    pub display_size: (u64, u64),
    /// The data window's position (of the part holding `R`, `G`, `B`).
    pub data_origin: (i32, i32),
    /// The float attribute [`EXPOSURE_ATTRIBUTE`], if present.
    pub exposure: Option<f32>,
}

/// Decodes every channel of every part of the file at `path`, largest resolution level only.
fn load_channels(path: &Path) -> Result<(Vec<Channel>, Frame), OutputError> {
    let file = File::open(path).map_err(|e| OutputError::io(path, "opening the EXR failed", e))?;
    load_channels_from(BufReader::new(file), path, u64::MAX)
}

/// [`load_channels`] from any reader (`path` names it in errors), refusing files of more than
/// `max_samples` samples in all parts together.
fn load_channels_from(
    mut reader: impl Read + Seek,
    path: &Path,
    max_samples: u64,
) -> Result<(Vec<Channel>, Frame), OutputError> {
    let exr_err = |source: exr::error::Error| OutputError::Exr {
        path: path.to_path_buf(),
        source,
    };

    // Check the sizes in the header before the decoder allocates anything for them.
    let meta = MetaData::read_from_buffered(&mut reader, false).map_err(exr_err)?;
    for header in meta.headers.iter() {
        crate::exr_header::check_part(header).map_err(|m| OutputError::invalid(path, m))?;
        let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
        if w.saturating_mul(h) > MAX_PIXELS {
            return Err(OutputError::invalid(
                path,
                format!("{w}x{h} pixels is more than the {MAX_PIXELS} lucent reads"),
            ));
        }
        if header.channels.list.len() > MAX_CHANNELS {
            return Err(OutputError::invalid(
                path,
                format!(
                    "{} channels in one part is more than the {MAX_CHANNELS} lucent reads",
                    header.channels.list.len()
                ),
            ));
        }
    }
    // The decoder's samples and their f32 copies live together while the channels are
    // gathered, 8 bytes per sample at most; ask for that first, as a refusal inside the
    // decoder would abort.
    let samples: u64 = meta
        .headers
        .iter()
        .map(|h| h.layer_size.0 as u64 * h.layer_size.1 as u64 * h.channels.list.len() as u64)
        .sum();
    if samples > max_samples {
        return Err(OutputError::invalid(
            path,
            format!("the file holds {samples} samples, more than the {max_samples} allowed here"),
        ));
    }
    memory::probe(samples.saturating_mul(8), memory::READ_IMAGE).map_err(|source| {
        OutputError::Memory {
            path: path.to_path_buf(),
            source,
        }
    })?;
    reader
        .seek(SeekFrom::Start(0))
        .map_err(|e| OutputError::io(path, "seeking in the EXR failed", e))?;

    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .non_parallel()
        .from_buffered(reader)
        .map_err(exr_err)?;

    let display = image.attributes.display_window;
    let exposure_name = text(path, EXPOSURE_ATTRIBUTE)?;
    let mut exposure = match image.attributes.other.get(&exposure_name) {
        Some(AttributeValue::F32(x)) => Some(*x),
        _ => None,
    };
    let mut channels = Vec::new();
    for part in image.layer_data {
        if let Some(AttributeValue::F32(x)) = part.attributes.other.get(&exposure_name) {
            exposure = exposure.or(Some(*x));
        }
        let size = (part.size.0 as u32, part.size.1 as u32);
        let origin = (
            part.attributes.layer_position.0,
            part.attributes.layer_position.1,
        );
        let prefix = part.attributes.layer_name.as_ref().map(|t| t.to_string());
        for ch in part.channel_data.list {
            let short = ch.name.to_string();
            let name = match &prefix {
                Some(p) if !p.is_empty() => format!("{p}.{short}"),
                _ => short,
            };
            let values: Vec<f32> = ch.sample_data.values_as_f32().collect();
            if values.len() as u64 != size.0 as u64 * size.1 as u64 {
                // Subsampled channels (e.g. chroma) are not images of the full size.
                continue;
            }
            channels.push(Channel {
                name,
                origin,
                size,
                values,
            });
        }
    }
    let data_origin = channels
        .iter()
        .find(|c| c.name == "R")
        .map_or((0, 0), |c| c.origin);
    let frame = Frame {
        display_origin: (display.position.0, display.position.1),
        display_size: (display.size.0 as u64, display.size.1 as u64),
        data_origin,
        exposure,
    };
    Ok((channels, frame))
}

/// Finds `prefix.R/G/B` and interleaves them; `None` if one is missing.
fn take_rgb(channels: &[Channel], prefix: &str) -> Option<((u32, u32), Vec<Vec3>)> {
    let find = |s: &str| {
        let full = if prefix.is_empty() {
            s.to_string()
        } else {
            format!("{prefix}.{s}")
        };
        channels.iter().find(|c| c.name == full)
    };
    let (r, g, b) = (find("R")?, find("G")?, find("B")?);
    if r.size != g.size || r.size != b.size || r.origin != g.origin || r.origin != b.origin {
        return None;
    }
    let pixels = r
        .values
        .iter()
        .zip(&g.values)
        .zip(&b.values)
        .map(|((&r, &g), &b)| Vec3::new(r, g, b))
        .collect();
    Some((r.size, pixels))
}

fn beauty(path: &Path, channels: &[Channel]) -> Result<RgbImage, OutputError> {
    match take_rgb(channels, "") {
        Some(((w, h), pixels)) => RgbImage::from_pixels(w, h, pixels)
            .map_err(|e| OutputError::invalid(path, e.to_string())),
        None => {
            let missing = ["R", "G", "B"]
                .into_iter()
                .find(|s| !channels.iter().any(|c| c.name == *s))
                .unwrap_or("R");
            let mut available: Vec<&str> =
                channels.iter().take(20).map(|c| c.name.as_str()).collect();
            if channels.len() > 20 {
                available.push("...");
            }
            let available = if available.is_empty() {
                "none".to_string()
            } else {
                available.join(", ")
            };
            Err(OutputError::MissingChannel {
                path: path.to_path_buf(),
                channel: missing.to_string(),
                available,
            })
        }
    }
}

/// Reads the beauty channels `R`, `G`, `B` of an OpenEXR file as linear RGB.
pub fn read_exr_rgb(path: &Path) -> Result<RgbImage, OutputError> {
    let (channels, _) = load_channels(path)?;
    beauty(path, &channels)
}

/// Reads the beauty image and every recognised layer (see the module doc). Layers whose size
/// differs from the beauty image's are an error.
pub fn read_exr(path: &Path) -> Result<ExrImage, OutputError> {
    read_exr_framed(path).map(|(image, _)| image)
}

/// [`read_exr`], also returning the display and data windows and the exposure attribute.
/// Layers and alpha whose data window differs from the beauty image's are an error.
pub fn read_exr_framed(path: &Path) -> Result<(ExrImage, Frame), OutputError> {
    let (channels, frame) = load_channels(path)?;
    framed_image(path, channels, frame)
}

/// [`read_exr_framed`] of a file held in memory (`path` names it in errors), refusing files of
/// more than `max_samples` samples (pixels times channels, all parts together) before decoding.
pub fn decode_exr_framed(
    bytes: &[u8],
    path: &Path,
    max_samples: u64,
) -> Result<(ExrImage, Frame), OutputError> {
    let (channels, frame) = load_channels_from(Cursor::new(bytes), path, max_samples)?;
    framed_image(path, channels, frame)
}

/// The beauty image and layers of decoded `channels`, checked against the beauty's window.
fn framed_image(
    path: &Path,
    channels: Vec<Channel>,
    frame: Frame,
) -> Result<(ExrImage, Frame), OutputError> {
    let beauty = beauty(path, &channels)?;
    let misplaced = |name: &str, origin: (i32, i32)| {
        OutputError::invalid(
            path,
            format!(
                "'{name}' starts at ({}, {}), the beauty image at ({}, {})",
                origin.0, origin.1, frame.data_origin.0, frame.data_origin.1
            ),
        )
    };

    let mut prefixes: Vec<&str> = Vec::new();
    for c in &channels {
        if let Some((prefix, _)) = c.name.rsplit_once('.')
            && !prefixes.contains(&prefix)
        {
            prefixes.push(prefix);
        }
    }
    let mut layers = Vec::new();
    for prefix in prefixes {
        let members: Vec<&Channel> = channels
            .iter()
            .filter(|c| c.name.rsplit_once('.').is_some_and(|(p, _)| p == prefix))
            .collect();
        let (size, layer) = if let Some((size, pixels)) = take_rgb(&channels, prefix) {
            (size, Layer::rgb(prefix, pixels))
        } else if let [only] = members.as_slice() {
            let channel = only.name.rsplit_once('.').map_or("", |(_, s)| s);
            (
                only.size,
                Layer::scalar(prefix, channel, only.values.clone()),
            )
        } else {
            continue;
        };
        if let Some(c) = members.iter().find(|c| c.origin != frame.data_origin) {
            return Err(misplaced(&c.name, c.origin));
        }
        if size != beauty.size() {
            return Err(OutputError::SizeMismatch {
                what: "EXR layer size vs. beauty size",
                expected: beauty.size(),
                actual: size,
            });
        }
        layers.push(layer);
    }
    let alpha = match channels.iter().find(|c| c.name == "A") {
        Some(a) if a.origin != frame.data_origin => return Err(misplaced("A", a.origin)),
        Some(a) if a.size == beauty.size() => Some(a.values.clone()),
        Some(a) => {
            return Err(OutputError::SizeMismatch {
                what: "EXR alpha size vs. beauty size",
                expected: beauty.size(),
                actual: a.size,
            });
        }
        None => None,
    };
    let image = ExrImage {
        beauty,
        alpha,
        layers,
    };
    Ok((image, frame))
}

#[cfg(test)]
mod tests {
    use super::super::atomic::tests::TestDir;
    use super::*;

    /// A tiny deterministic xorshift generator for test data.
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    fn test_image(w: u32, h: u32, seed: u64) -> RgbImage {
        let mut s = seed;
        let pixels = (0..w * h)
            .map(|_| {
                let mut f = || (xorshift(&mut s) >> 40) as f32 / (1u64 << 24) as f32 * 3.0;
                Vec3::new(f(), f(), f())
            })
            .collect();
        RgbImage::from_pixels(w, h, pixels).unwrap()
    }

    fn all_layers(n: usize) -> Vec<Layer> {
        let ramp = |k: f32| {
            (0..n)
                .map(|i| Vec3::new(i as f32, k, -(i as f32) * k))
                .collect()
        };
        let mut depth: Vec<f32> = (0..n).map(|i| 0.5 + i as f32 * 0.25).collect();
        depth[0] = f32::INFINITY;
        vec![
            Layer::rgb("exitance", ramp(1.0)),
            Layer::rgb("local", ramp(2.0)),
            Layer::rgb("global", ramp(3.0)),
            Layer::rgb("irradiance", ramp(4.0)),
            Layer::depth(depth),
        ]
    }

    #[test]
    fn round_trip_is_bit_exact_with_layers() {
        let dir = TestDir::new("exr-rt");
        let path = dir.path("a.exr");
        let img = test_image(13, 7, 1);
        let layers = all_layers(13 * 7);
        write_exr(&path, &img, None, &layers).unwrap();

        let back = read_exr(&path).unwrap();
        assert_eq!(back.beauty, img);
        assert_eq!(read_exr_rgb(&path).unwrap(), img);
        // Layers come back in channel (name) order.
        let mut expected = layers.clone();
        expected.sort_by(|a, b| a.name.cmp(&b.name));
        assert_eq!(back.layers, expected);
        assert_eq!(back.alpha, None);
    }

    #[test]
    fn alpha_round_trips_as_channel_a() {
        let dir = TestDir::new("exr-alpha");
        let path = dir.path("a.exr");
        let img = test_image(5, 3, 7);
        let alpha: Vec<f32> = (0..15).map(|i| i as f32 / 16.0).collect();
        write_exr(&path, &img, Some(&alpha), &all_layers(15)).unwrap();
        let back = read_exr(&path).unwrap();
        assert_eq!(back.beauty, img);
        assert_eq!(back.alpha.as_deref(), Some(alpha.as_slice()));
        assert_eq!(back.layers.len(), 5, "A is not a layer");
        let short = write_exr(&dir.path("b.exr"), &img, Some(&alpha[..14]), &[]).unwrap_err();
        assert!(short.to_string().contains("alpha has 14 pixels"), "{short}");
    }

    #[test]
    fn channel_names_in_file_follow_the_documented_convention() {
        let dir = TestDir::new("exr-names");
        let path = dir.path("n.exr");
        write_exr(&path, &test_image(2, 2, 3), None, &all_layers(4)).unwrap();
        let meta = MetaData::read_from_file(&path, true).unwrap();
        assert_eq!(meta.headers.len(), 1);
        let names: Vec<String> = meta.headers[0]
            .channels
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert_eq!(
            names,
            [
                "B",
                "G",
                "R",
                "depth.Z",
                "exitance.B",
                "exitance.G",
                "exitance.R",
                "global.B",
                "global.G",
                "global.R",
                "irradiance.B",
                "irradiance.G",
                "irradiance.R",
                "local.B",
                "local.G",
                "local.R",
            ]
        );
        for c in &meta.headers[0].channels.list {
            assert_eq!(c.sample_type, exr::prelude::SampleType::F32, "{}", c.name);
        }
        assert_eq!(meta.headers[0].compression, Compression::ZIP16);
    }

    #[test]
    fn output_is_deterministic() {
        let dir = TestDir::new("exr-det");
        let img = test_image(40, 33, 9);
        let layers = all_layers(40 * 33);
        write_exr(&dir.path("a.exr"), &img, None, &layers).unwrap();
        write_exr(&dir.path("b.exr"), &img, None, &layers).unwrap();
        let a = std::fs::read(dir.path("a.exr")).unwrap();
        assert_eq!(a, std::fs::read(dir.path("b.exr")).unwrap());
        assert_eq!(&a[..4], &[0x76, 0x2f, 0x31, 0x01], "OpenEXR magic");
    }

    #[test]
    fn invalid_layers_are_rejected_without_writing() {
        let dir = TestDir::new("exr-bad-layers");
        let path = dir.path("x.exr");
        let img = test_image(2, 2, 5);
        let cases: Vec<(Vec<Layer>, &str)> = vec![
            (
                vec![Layer::rgb("a.b", vec![Vec3::ZERO; 4])],
                "layer name 'a.b' is invalid",
            ),
            (
                vec![Layer::rgb("", vec![Vec3::ZERO; 4])],
                "layer name '' is invalid",
            ),
            (
                vec![
                    Layer::rgb("x", vec![Vec3::ZERO; 4]),
                    Layer::depth(vec![0.0; 4]).renamed("x"),
                ],
                "layer 'x' given twice",
            ),
            (
                vec![Layer::scalar("d", "Z.1", vec![0.0; 4])],
                "channel name 'Z.1'",
            ),
            (
                vec![Layer::depth(vec![0.0; 3])],
                "layer 'depth' has 3 pixels",
            ),
        ];
        for (layers, msg) in cases {
            let err = write_exr(&path, &img, None, &layers).unwrap_err();
            assert!(
                err.to_string().contains(msg),
                "{err} does not contain {msg}"
            );
        }
        let err = write_exr(&path, &RgbImage::new(3, 0), None, &[]).unwrap_err();
        assert!(err.to_string().contains("3x0"), "{err}");
        assert!(dir.entries().is_empty());
    }

    impl Layer {
        fn renamed(mut self, name: &str) -> Self {
            self.name = name.to_string();
            self
        }
    }

    #[test]
    fn missing_beauty_channel_is_named() {
        let dir = TestDir::new("exr-missing");
        let path = dir.path("m.exr");
        // A file with only R and G (written with the exr crate directly).
        let r = AnyChannel::new("R", FlatSamples::F32(vec![1.0; 4]));
        let g = AnyChannel::new("G", FlatSamples::F32(vec![2.0; 4]));
        let layer = exr::image::Layer::new(
            Vec2(2, 2),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(SmallVec::from_vec(vec![r, g])),
        );
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_file(&path)
            .unwrap();
        let err = read_exr_rgb(&path).unwrap_err();
        match &err {
            OutputError::MissingChannel {
                channel, available, ..
            } => {
                assert_eq!(channel, "B");
                assert_eq!(available, "G, R");
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(err.to_string().contains("m.exr"), "{err}");
    }

    #[test]
    fn reads_half_float_files_from_other_writers() {
        let dir = TestDir::new("exr-half");
        let path = dir.path("h.exr");
        let h = |v: f32| exr::prelude::f16::from_f32(v);
        let chans = ["B", "G", "R"]
            .into_iter()
            .enumerate()
            .map(|(i, n)| AnyChannel::new(n, FlatSamples::F16(vec![h(i as f32 + 0.5); 6])))
            .collect::<Vec<_>>();
        let layer = exr::image::Layer::new(
            Vec2(3, 2),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(chans)),
        );
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_file(&path)
            .unwrap();
        let img = read_exr_rgb(&path).unwrap();
        assert_eq!(img.size(), (3, 2));
        assert!(img.pixels().iter().all(|&p| p == Vec3::new(2.5, 1.5, 0.5)));
    }

    #[test]
    fn truncated_and_random_files_are_errors_not_panics() {
        let dir = TestDir::new("exr-fuzz");
        let good = dir.path("good.exr");
        write_exr(&good, &test_image(9, 20, 2), None, &all_layers(180)).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let bad = dir.path("bad.exr");

        // Every truncation length in the header, then a stride through the blocks.
        let mut cuts: Vec<usize> = (0..bytes.len().min(600)).collect();
        cuts.extend((600..bytes.len()).step_by(37));
        for cut in cuts {
            std::fs::write(&bad, &bytes[..cut]).unwrap();
            assert!(
                read_exr_rgb(&bad).is_err(),
                "truncated at {cut} of {}",
                bytes.len()
            );
        }

        // Random bytes, with and without a valid magic number and version.
        let mut s = 0x9E3779B97F4A7C15u64;
        for round in 0..200 {
            let len = 4 + (xorshift(&mut s) % 700) as usize;
            let mut junk: Vec<u8> = (0..len).map(|_| xorshift(&mut s) as u8).collect();
            if round % 2 == 0 {
                junk[..4].copy_from_slice(&[0x76, 0x2f, 0x31, 0x01]);
                if junk.len() >= 8 {
                    junk[4..8].copy_from_slice(&[2, 0, 0, 0]);
                }
            }
            std::fs::write(&bad, &junk).unwrap();
            assert!(read_exr_rgb(&bad).is_err(), "random round {round}");
        }

        // Single-byte corruptions of a valid file: may decode (into different values) or fail,
        // but must not panic.
        for i in (0..bytes.len()).step_by(11) {
            let mut corrupt = bytes.clone();
            corrupt[i] ^= 0x5A;
            std::fs::write(&bad, &corrupt).unwrap();
            let _ = read_exr(&bad);
        }
    }

    /// Long fuzz run: `cargo test -p lucent-raster --lib output::exr -- --ignored`.
    #[test]
    #[ignore]
    fn mutated_files_never_panic_long() {
        let dir = TestDir::new("exr-fuzz-long");
        let good = dir.path("good.exr");
        write_exr(&good, &test_image(5, 18, 4), None, &all_layers(90)).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let bad = dir.path("bad.exr");
        let mut s = 0x0123456789ABCDEFu64;
        for _ in 0..20_000 {
            let mut m = bytes.clone();
            for _ in 0..1 + xorshift(&mut s) % 4 {
                // Mostly the header (first 600 bytes), sometimes anywhere.
                let span = if xorshift(&mut s).is_multiple_of(4) {
                    m.len()
                } else {
                    600.min(m.len())
                };
                let i = (xorshift(&mut s) as usize) % span;
                m[i] = xorshift(&mut s) as u8;
            }
            if xorshift(&mut s).is_multiple_of(3) {
                m.truncate((xorshift(&mut s) as usize) % m.len());
            }
            std::fs::write(&bad, &m).unwrap();
            let _ = read_exr(&bad);
        }
    }

    #[test]
    fn missing_file_names_the_path() {
        let err = read_exr_rgb(Path::new("/nonexistent/lucent/x.exr")).unwrap_err();
        assert!(
            err.to_string().contains("/nonexistent/lucent/x.exr"),
            "{err}"
        );
    }
}
