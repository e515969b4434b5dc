//! PNG, JPEG, TGA, BMP and Radiance HDR, through the `image` crate (built with exactly these
//! five codecs).
//!
//! The header is read first and its size checked against the [`TextureLimits`] before any pixel
//! memory exists; the decoder's own allocation cap (`image::Limits::max_alloc`) is a second
//! line behind it. Decoded pixels of every layout the codecs produce (grey, grey + alpha, RGB,
//! RGBA; 8 bits, 16 bits, 32-bit float) become RGB: grey is replicated, alpha dropped. Integer
//! codes are kept, beside the table of their values (`code / (2^bits − 1)` decoded by the
//! [`TextureEncoding`]); float samples are taken as they are.

use std::io::Cursor;
use std::path::Path;

use glam::Vec3;
use image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader};

use super::{
    Texels, TextureEncoding, TextureError, TextureFormat, TextureLimits, TextureSource, decode,
};

/// The decoded size and texels (row-major, top row first).
pub(super) type Decoded = (u32, u32, Texels);

/// Decodes `bytes` as `format` (not [`TextureFormat::Exr`]).
pub(super) fn decode_with_image(
    bytes: &[u8],
    path: &Path,
    format: TextureFormat,
    encoding: TextureEncoding,
    limits: &TextureLimits,
) -> Result<Decoded, TextureError> {
    let image_format = match format {
        TextureFormat::Png => ImageFormat::Png,
        TextureFormat::Jpeg => ImageFormat::Jpeg,
        TextureFormat::Tga => ImageFormat::Tga,
        TextureFormat::Bmp => ImageFormat::Bmp,
        TextureFormat::Hdr => ImageFormat::Hdr,
        TextureFormat::Exr => {
            return Err(TextureError::new(path, "OpenEXR is not an `image` format"));
        }
    };
    let failed = |e: image::ImageError| TextureError {
        path: path.to_path_buf(),
        message: format!("{} decoding failed: {e}", format.name()),
        source: Some(TextureSource::Image(e)),
    };
    // PNG's size sits at a fixed place in the first chunk, which the decoder only reports
    // after reading on to the image data: check it first, so that a header claiming an absurd
    // size is named as such even when the rest of the file is missing.
    if format == TextureFormat::Png
        && let Some((width, height)) = png_header_size(bytes)
    {
        limits
            .check(width, height)
            .map_err(|m| TextureError::new(path, m))?;
    }
    let mut reader = ImageReader::with_format(Cursor::new(bytes), image_format);
    let mut image_limits = image::Limits::default();
    // The largest buffer a capped image needs: RGBA at 32-bit float, plus headroom for tables.
    image_limits.max_alloc = Some(limits.max_texels.saturating_mul(16) + (1 << 20));
    reader.limits(image_limits);
    let decoder = reader.into_decoder().map_err(failed)?;
    let (width, height) = decoder.dimensions();
    limits
        .check(width, height)
        .map_err(|m| TextureError::new(path, m))?;
    let image = DynamicImage::from_decoder(decoder).map_err(failed)?;
    if (image.width(), image.height()) != (width, height) {
        return Err(TextureError::new(
            path,
            format!(
                "decoded {} × {} pixels, the header says {width} × {height}",
                image.width(),
                image.height()
            ),
        ));
    }
    let texels = texels_of(image, encoding).ok_or_else(|| {
        TextureError::new(
            path,
            format!("{} decoder returned an unknown pixel layout", format.name()),
        )
    })?;
    Ok((width, height, texels))
}

/// The width and height in a PNG's IHDR chunk (the first chunk, right after the 8-byte
/// signature: length, `IHDR`, then width and height as big-endian u32), if present.
fn png_header_size(bytes: &[u8]) -> Option<(u32, u32)> {
    if bytes.get(12..16)? != b"IHDR" {
        return None;
    }
    let be = |at: usize| -> Option<u32> {
        Some(u32::from_be_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
    };
    Some((be(16)?, be(20)?))
}

/// Converts every pixel layout the five codecs produce; `None` for any other.
fn texels_of(image: DynamicImage, encoding: TextureEncoding) -> Option<Texels> {
    let value8 = |c: u8| decode(f32::from(c) / 255.0, encoding);
    let value16 = |c: u16| decode(f32::from(c) / f32::from(u16::MAX), encoding);
    let linear = |texels: Vec<Vec3>| Some(Texels::Linear(texels));
    Some(match image {
        // RGB is kept as decoded, without a copy.
        DynamicImage::ImageRgb8(b) => Texels::codes8(b.into_raw(), value8),
        DynamicImage::ImageLuma8(b) => Texels::codes8(rgb_codes(&b, 1), value8),
        DynamicImage::ImageLumaA8(b) => Texels::codes8(rgb_codes(&b, 2), value8),
        DynamicImage::ImageRgba8(b) => Texels::codes8(rgb_codes(&b, 4), value8),
        DynamicImage::ImageRgb16(b) => Texels::codes16(b.into_raw(), value16),
        DynamicImage::ImageLuma16(b) => Texels::codes16(rgb_codes(&b, 1), value16),
        DynamicImage::ImageLumaA16(b) => Texels::codes16(rgb_codes(&b, 2), value16),
        DynamicImage::ImageRgba16(b) => Texels::codes16(rgb_codes(&b, 4), value16),
        // Floating-point samples (Radiance HDR) are linear values: no encoding applies.
        DynamicImage::ImageRgb32F(b) => {
            return linear(b.pixels().map(|p| Vec3::from_array(p.0)).collect());
        }
        DynamicImage::ImageRgba32F(b) => {
            return linear(
                b.pixels()
                    .map(|p| Vec3::new(p.0[0], p.0[1], p.0[2]))
                    .collect(),
            );
        }
        _ => return None,
    })
}

/// Three codes per pixel from pixels of `channels` codes each: grey (one or two channels, the
/// second alpha) replicated, RGBA's alpha dropped.
fn rgb_codes<C: Copy>(pixels: &[C], channels: usize) -> Vec<C> {
    let rgb = |p: &[C]| {
        if channels < 3 {
            [p[0]; 3]
        } else {
            [p[0], p[1], p[2]]
        }
    };
    pixels.chunks_exact(channels).flat_map(rgb).collect()
}
