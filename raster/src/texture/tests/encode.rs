//! Small texture files built in memory for the tests: TGA, BMP and Radiance HDR byte by byte
//! (independent of the decoders), JPEG through the `image` crate's encoder, OpenEXR through the
//! `exr` crate's writer.

use std::io::Cursor;

use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Encoding, FlatSamples, Image, LayerAttributes, SmallVec, Vec2,
    WritableImage,
};

/// An uncompressed true-colour TGA (type 2, 24 bits): `rgb` holds rows top first; the file
/// stores them bottom first (origin bit clear) unless `top_first`, and each pixel as B, G, R.
pub(crate) fn tga_rgb(width: u16, height: u16, rgb: &[[u8; 3]], top_first: bool) -> Vec<u8> {
    let mut out = tga_header(2, width, height, 24, top_first);
    let rows: Vec<&[[u8; 3]]> = rgb.chunks(width as usize).collect();
    let ordered: Vec<&[[u8; 3]]> = if top_first {
        rows
    } else {
        rows.into_iter().rev().collect()
    };
    for row in ordered {
        for p in row {
            out.extend_from_slice(&[p[2], p[1], p[0]]);
        }
    }
    out
}

/// An uncompressed 8-bit grey TGA (type 3), rows stored top first.
pub(crate) fn tga_grey(width: u16, height: u16, grey: &[u8]) -> Vec<u8> {
    let mut out = tga_header(3, width, height, 8, true);
    out.extend_from_slice(grey);
    out
}

/// The 18-byte TGA header: no image id, no colour map.
pub(crate) fn tga_header(kind: u8, width: u16, height: u16, bits: u8, top_first: bool) -> Vec<u8> {
    let mut h = vec![0u8, 0, kind, 0, 0, 0, 0, 0, 0, 0, 0, 0];
    h.extend_from_slice(&width.to_le_bytes());
    h.extend_from_slice(&height.to_le_bytes());
    h.push(bits);
    h.push(if top_first { 0x20 } else { 0 });
    h
}

/// A 24-bit uncompressed BMP (BITMAPINFOHEADER, bottom-up rows padded to 4 bytes, B, G, R);
/// `rgb` holds rows top first. `height` may be given larger than the data for header tests.
pub(crate) fn bmp_rgb(width: i32, height: i32, rgb: &[[u8; 3]]) -> Vec<u8> {
    let row_bytes = (width as usize * 3).div_ceil(4) * 4;
    let mut pixels = Vec::new();
    for row in rgb.chunks(width.max(1) as usize).rev() {
        let start = pixels.len();
        for p in row {
            pixels.extend_from_slice(&[p[2], p[1], p[0]]);
        }
        pixels.resize(start + row_bytes, 0);
    }
    let mut out = b"BM".to_vec();
    out.extend_from_slice(&(54 + pixels.len() as u32).to_le_bytes());
    out.extend_from_slice(&[0; 4]);
    out.extend_from_slice(&54u32.to_le_bytes());
    out.extend_from_slice(&40u32.to_le_bytes());
    out.extend_from_slice(&width.to_le_bytes());
    out.extend_from_slice(&height.to_le_bytes());
    out.extend_from_slice(&1u16.to_le_bytes()); // planes
    out.extend_from_slice(&24u16.to_le_bytes()); // bits per pixel
    out.extend_from_slice(&0u32.to_le_bytes()); // BI_RGB
    out.extend_from_slice(&(pixels.len() as u32).to_le_bytes());
    out.extend_from_slice(&2835u32.to_le_bytes());
    out.extend_from_slice(&2835u32.to_le_bytes());
    out.extend_from_slice(&[0; 8]); // palette sizes
    out.extend_from_slice(&pixels);
    out
}

/// A flat (not run-length encoded) Radiance HDR file; each pixel is (R, G, B, E) meaning
/// `m · 2^(E − 136)` per channel. Rows top first (`-Y`).
pub(crate) fn hdr_rgbe(width: u32, height: u32, rgbe: &[[u8; 4]]) -> Vec<u8> {
    let mut out =
        format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n").into_bytes();
    for p in rgbe {
        out.extend_from_slice(p);
    }
    out
}

/// A JPEG of 8-bit RGB pixels (rows top first) at `quality`, through the `image` encoder.
pub(crate) fn jpeg_rgb(width: u32, height: u32, rgb: &[u8], quality: u8) -> Vec<u8> {
    jpeg(width, height, rgb, image::ExtendedColorType::Rgb8, quality)
}

/// A grey JPEG.
pub(crate) fn jpeg_grey(width: u32, height: u32, grey: &[u8], quality: u8) -> Vec<u8> {
    jpeg(width, height, grey, image::ExtendedColorType::L8, quality)
}

fn jpeg(width: u32, height: u32, data: &[u8], kind: image::ExtendedColorType, q: u8) -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, q)
        .encode(data, width, height, kind)
        .expect("JPEG encodes");
    out
}

/// A single-part scan-line OpenEXR file with the named channels (rows top first), ZIP
/// compressed.
pub(crate) fn exr_channels(
    width: usize,
    height: usize,
    channels: Vec<(&str, FlatSamples)>,
) -> Vec<u8> {
    exr_encoded(width, height, channels, Encoding::FAST_LOSSLESS)
}

/// A single-part scan-line OpenEXR file with the named channels, B44 compressed.
pub(crate) fn exr_b44(width: usize, height: usize, channels: Vec<(&str, FlatSamples)>) -> Vec<u8> {
    let encoding = Encoding {
        compression: exr::compression::Compression::B44,
        ..Encoding::FAST_LOSSLESS
    };
    exr_encoded(width, height, channels, encoding)
}

/// An RGB OpenEXR file of 32-bit floats in `tile × tile` tiles, ZIP compressed.
pub(crate) fn exr_tiled_rgb_f32(width: usize, height: usize, tile: usize) -> Vec<u8> {
    let channel =
        |c: usize| FlatSamples::F32((0..width * height).map(|i| (i + c) as f32).collect());
    let encoding = Encoding {
        blocks: Blocks::Tiles(Vec2(tile, tile)),
        ..Encoding::FAST_LOSSLESS
    };
    exr_encoded(
        width,
        height,
        vec![("R", channel(0)), ("G", channel(1)), ("B", channel(2))],
        encoding,
    )
}

fn exr_encoded(
    width: usize,
    height: usize,
    channels: Vec<(&str, FlatSamples)>,
    encoding: Encoding,
) -> Vec<u8> {
    let list: Vec<AnyChannel<FlatSamples>> = channels
        .into_iter()
        .map(|(name, samples)| AnyChannel::new(name, samples))
        .collect();
    let layer = exr::image::Layer::new(
        Vec2(width, height),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(SmallVec::from_vec(list)),
    );
    let mut out = Vec::new();
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(Cursor::new(&mut out))
        .expect("EXR writes");
    out
}

/// An RGB OpenEXR file of 32-bit floats.
pub(crate) fn exr_rgb_f32(width: usize, height: usize, rgb: &[[f32; 3]]) -> Vec<u8> {
    let channel = |c: usize| FlatSamples::F32(rgb.iter().map(|p| p[c]).collect());
    exr_channels(
        width,
        height,
        vec![("R", channel(0)), ("G", channel(1)), ("B", channel(2))],
    )
}
