//! Image textures over mesh UVs: PNG decoding to linear RGB and bilinear lookup.
//!
//! Two kinds of texture data exist in a scene, and they decode differently:
//!
//! - **colour** (the diffuse reflectance K_d): the PNG holds sRGB-encoded values, which are
//!   decoded to linear with the sRGB transfer function (IEC 61966-2-1) on load;
//! - **data** (a distance mapped through `min · (max/min)^t`): the PNG values are used as they
//!   are, `t = code / (2^bits − 1)`, so that equal steps in the image are equal steps in t.
//!
//! Every PNG colour type is accepted (grey, grey + alpha, RGB, RGBA, palette, 1 to 16 bits);
//! grey is replicated to RGB and alpha is ignored. Sizes are capped ([`MAX_TEXTURE_SIDE`],
//! [`MAX_TEXTURE_TEXELS`]) before any pixel memory is allocated, so a hostile header cannot
//! exhaust memory.

use std::fmt;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

/// Largest accepted texture width or height, in texels.
pub const MAX_TEXTURE_SIDE: u32 = 16_384;

/// Largest accepted number of texels (2^24, e.g. 4096 × 4096; 192 MiB as linear `Vec3`).
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 24;

/// A decoded RGB texture with linear values.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it was loaded from.
    pub path: PathBuf,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, top row first, linear RGB.
    pub texels: Vec<Vec3>,
}

/// How the values stored in a PNG map to the texture's linear values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureEncoding {
    /// Colour: sRGB-encoded, decoded to linear on load.
    Srgb,
    /// Data: the normalised code value itself (`code / (2^bits − 1)`).
    Linear,
}

/// Why a PNG could not be turned into a [`Texture`].
#[derive(Debug)]
pub struct TextureError {
    /// The file concerned.
    pub path: PathBuf,
    /// What went wrong (it includes the source's message, if there is a source).
    pub message: String,
    /// The error behind it, if one: returned by [`source`](std::error::Error::source).
    pub source: Option<TextureSource>,
}

/// The error behind a [`TextureError`].
#[derive(Debug)]
#[non_exhaustive]
pub enum TextureSource {
    /// Reading the file failed.
    Io(std::io::Error),
    /// The PNG decoder failed.
    Png(png::DecodingError),
}

impl fmt::Display for TextureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "texture {}: {}", self.path.display(), self.message)
    }
}

impl std::error::Error for TextureError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.source {
            Some(TextureSource::Io(e)) => Some(e),
            Some(TextureSource::Png(e)) => Some(e),
            None => None,
        }
    }
}

impl Texture {
    /// Bilinear lookup with repeat wrapping. `uv = (0, 0)` is the bottom-left corner of the
    /// image (the OBJ convention), `(1, 1)` the top-right.
    ///
    /// Texel centres sit at half-integer positions: texel column `i`, row `j` (from the top) is
    /// returned exactly at `uv = ((i + ½)/width, 1 − (j + ½)/height)`. Non-finite coordinates
    /// are treated as 0. An empty (or inconsistent) texture samples as black.
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as usize, self.height as usize);
        if w == 0 || h == 0 || self.texels.len() < w * h {
            return Vec3::ZERO;
        }
        let (x0, x1, fx) = wrap_axis(uv.x, w);
        // Rows are stored top first, v grows upwards: flip before wrapping.
        let (y0, y1, fy) = wrap_axis(1.0 - uv.y, h);
        let t = |x: usize, y: usize| self.texels[y * w + x];
        let top = t(x0, y0).lerp(t(x1, y0), fx);
        let bottom = t(x0, y1).lerp(t(x1, y1), fx);
        top.lerp(bottom, fy)
    }

    /// Decodes a PNG held in memory. `path` is only recorded (and used in messages).
    pub fn from_png_bytes(
        bytes: &[u8],
        path: &Path,
        encoding: TextureEncoding,
    ) -> Result<Texture, TextureError> {
        let fail = |message: String| TextureError {
            path: path.to_path_buf(),
            message,
            source: None,
        };
        let decoding = |what: &str, e: png::DecodingError| TextureError {
            path: path.to_path_buf(),
            message: format!("{what}: {e}"),
            source: Some(TextureSource::Png(e)),
        };
        let mut decoder = png::Decoder::new(Cursor::new(bytes));
        decoder.set_transformations(png::Transformations::EXPAND);
        decoder.set_ignore_text_chunk(true);
        let (width, height) = {
            let info = decoder
                .read_header_info()
                .map_err(|e| decoding("not a readable PNG", e))?;
            (info.width, info.height)
        };
        check_size(width, height).map_err(fail)?;
        // Buffers for a 16-bit RGBA image of the capped size stay under 128 MiB.
        decoder.set_limits(png::Limits {
            bytes: (MAX_TEXTURE_TEXELS as usize) * 8 + (1 << 20),
        });
        let mut reader = decoder
            .read_info()
            .map_err(|e| decoding("malformed PNG", e))?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| fail("image too large for memory".to_string()))?;
        let mut buf = vec![0u8; size];
        let frame = reader
            .next_frame(&mut buf)
            .map_err(|e| decoding("malformed or truncated PNG data", e))?;
        let channels = match frame.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => {
                return Err(fail("palette was not expanded by the decoder".to_string()));
            }
        };
        let wide = frame.bit_depth == png::BitDepth::Sixteen;
        let texels = convert_samples(&buf, &frame, channels, wide, encoding);
        if texels.len() != width as usize * height as usize {
            return Err(fail(format!(
                "decoded {} texels, expected {} × {}",
                texels.len(),
                width,
                height
            )));
        }
        Ok(Texture {
            path: path.to_path_buf(),
            width,
            height,
            texels,
        })
    }

    /// Reads and decodes a PNG file from disk.
    pub fn load_png(path: &Path, encoding: TextureEncoding) -> Result<Texture, TextureError> {
        let bytes = std::fs::read(path).map_err(|e| TextureError {
            path: path.to_path_buf(),
            message: format!("cannot read: {e}"),
            source: Some(TextureSource::Io(e)),
        })?;
        Texture::from_png_bytes(&bytes, path, encoding)
    }
}

/// Rejects empty and absurd image sizes before anything is allocated.
fn check_size(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("empty image ({width} × {height})"));
    }
    if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(format!(
            "image is {width} × {height}, larger than {MAX_TEXTURE_SIDE} texels per side"
        ));
    }
    if u64::from(width) * u64::from(height) > MAX_TEXTURE_TEXELS {
        return Err(format!(
            "image is {width} × {height}, more than {MAX_TEXTURE_TEXELS} texels"
        ));
    }
    Ok(())
}

/// Converts a decoded frame (8 or 16 bits, 1 to 4 channels, rows possibly padded) to linear RGB.
fn convert_samples(
    buf: &[u8],
    frame: &png::OutputInfo,
    channels: usize,
    wide: bool,
    encoding: TextureEncoding,
) -> Vec<Vec3> {
    let bytes_per_sample = if wide { 2 } else { 1 };
    let (width, height) = (frame.width as usize, frame.height as usize);
    let lut8: Vec<f32> = (0..256u32)
        .map(|c| decode(c as f32 / 255.0, encoding))
        .collect();
    let max16 = f32::from(u16::MAX);
    let value = |px: &[u8], channel: usize| -> f32 {
        if wide {
            let code = u16::from_be_bytes([px[2 * channel], px[2 * channel + 1]]);
            decode(f32::from(code) / max16, encoding)
        } else {
            lut8[px[channel] as usize]
        }
    };
    let pixel_bytes = channels * bytes_per_sample;
    let mut texels = Vec::with_capacity(width * height);
    for row in buf.chunks(frame.line_size.max(1)).take(height) {
        for px in row.chunks_exact(pixel_bytes).take(width) {
            texels.push(if channels < 3 {
                Vec3::splat(value(px, 0))
            } else {
                Vec3::new(value(px, 0), value(px, 1), value(px, 2))
            });
        }
    }
    texels
}

/// Maps a normalised code value in [0, 1] to a linear texture value.
fn decode(c: f32, encoding: TextureEncoding) -> f32 {
    match encoding {
        TextureEncoding::Srgb => srgb_to_linear(c),
        TextureEncoding::Linear => c,
    }
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1): encoded value → linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Repeat-wraps one texture coordinate: the two texel indices to blend and the weight of the
/// second. `coord` is in texture units (0 = first edge, 1 = last edge of the image).
fn wrap_axis(coord: f32, n: usize) -> (usize, usize, f32) {
    let coord = if coord.is_finite() { coord } else { 0.0 };
    let wrapped = coord - coord.floor(); // [0, 1] (1 only by rounding)
    let x = wrapped * n as f32 - 0.5; // [−0.5, n − 0.5]
    let x0 = x.floor();
    let frac = x - x0;
    let i0 = (x0 as i64).rem_euclid(n as i64) as usize;
    let i1 = (i0 + 1) % n;
    (i0, i1, frac)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Encodes a PNG in memory for the tests.
    pub(crate) fn encode_png(
        width: u32,
        height: u32,
        color: png::ColorType,
        depth: png::BitDepth,
        data: &[u8],
        palette: Option<Vec<u8>>,
    ) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, width, height);
            enc.set_color(color);
            enc.set_depth(depth);
            if let Some(p) = palette {
                enc.set_palette(p);
            }
            let mut writer = enc.write_header().expect("header");
            writer.write_image_data(data).expect("data");
        }
        out
    }

    fn texture(width: u32, height: u32, texels: Vec<Vec3>) -> Texture {
        Texture {
            path: PathBuf::from("test"),
            width,
            height,
            texels,
        }
    }

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[test]
    fn sample_hits_texel_centres_exactly() {
        // 2 × 2: top row (a, b), bottom row (c, d).
        let (a, b, c, d) = (Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE);
        let t = texture(2, 2, vec![a, b, c, d]);
        assert_eq!(t.sample(Vec2::new(0.25, 0.75)), a);
        assert_eq!(t.sample(Vec2::new(0.75, 0.75)), b);
        assert_eq!(t.sample(Vec2::new(0.25, 0.25)), c);
        assert_eq!(t.sample(Vec2::new(0.75, 0.25)), d);
    }

    #[test]
    fn sample_is_bilinear_against_hand_computed_values() {
        // 3 × 2 scalar texture, values in the red channel:
        //   top:    1 2 3
        //   bottom: 4 5 6
        let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let t = texture(3, 2, v.iter().map(|&x| Vec3::new(x, 0.0, 0.0)).collect());
        // u = 1/3 → x = 0.5 between columns 0 and 1; v = 0.5 → y = 0.5 between rows.
        // (1 + 2 + 4 + 5)/4 = 3.
        assert!(close(
            t.sample(Vec2::new(1.0 / 3.0, 0.5)),
            Vec3::X * 3.0,
            1e-5
        ));
        // u = 0.5 → x = 1.0 exactly column 1; v = 0.625 → y_top = 0.375·2 − 0.5 = 0.25.
        // 2·0.75 + 5·0.25 = 2.75.
        assert!(close(t.sample(Vec2::new(0.5, 0.625)), Vec3::X * 2.75, 1e-5));
        // Wrapping in u: u = 0 → x = −0.5 → halfway between column 2 and column 0.
        // At v = 0.75 (top row centre): (3 + 1)/2 = 2.
        assert!(close(t.sample(Vec2::new(0.0, 0.75)), Vec3::X * 2.0, 1e-5));
        // Wrapping in v: v = 1 → y_top = −0.5 → halfway between bottom row and top row.
        // At u = 1/6 (column 0 centre): (4 + 1)/2 = 2.5.
        assert!(close(
            t.sample(Vec2::new(1.0 / 6.0, 1.0)),
            Vec3::X * 2.5,
            1e-5
        ));
        // Repeat: shifting by whole periods changes nothing.
        let p = Vec2::new(0.41, 0.13);
        assert!(close(t.sample(p), t.sample(p + Vec2::new(3.0, -2.0)), 1e-4));
        // Non-finite coordinates do not panic.
        let _ = t.sample(Vec2::new(f32::NAN, f32::INFINITY));
        assert_eq!(texture(0, 0, vec![]).sample(p), Vec3::ZERO);
    }

    #[test]
    fn srgb_decode_matches_the_standard() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // Linear segment: 0.04 / 12.92.
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-7);
        // Mid grey 0.5 → 0.214041 (standard value).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        // 8-bit 188 → ((188/255 + 0.055)/1.055)^2.4 = 0.502886.
        assert!((srgb_to_linear(188.0 / 255.0) - 0.502_886).abs() < 1e-5);
    }

    #[test]
    fn decodes_rgb8_as_srgb_and_as_data() {
        // 2 × 1: (255, 128, 0), (188, 10, 64).
        let data = [255, 128, 0, 188, 10, 64];
        let png = encode_png(2, 1, png::ColorType::Rgb, png::BitDepth::Eight, &data, None);
        let lin = Texture::from_png_bytes(&png, Path::new("a.png"), TextureEncoding::Linear)
            .expect("decodes");
        assert_eq!((lin.width, lin.height), (2, 1));
        assert!(close(
            lin.texels[0],
            Vec3::new(1.0, 128.0 / 255.0, 0.0),
            1e-6
        ));
        assert!(close(
            lin.texels[1],
            Vec3::new(188.0 / 255.0, 10.0 / 255.0, 64.0 / 255.0),
            1e-6
        ));
        let s = Texture::from_png_bytes(&png, Path::new("a.png"), TextureEncoding::Srgb)
            .expect("decodes");
        assert!((s.texels[1].x - 0.502_886).abs() < 1e-5);
        assert!((s.texels[1].y - 10.0 / 255.0 / 12.92).abs() < 1e-6);
    }

    #[test]
    fn decodes_grey16_palette_and_rgba() {
        // 16-bit grey, big endian: 0x8000 → 32768/65535.
        let png = encode_png(
            1,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Sixteen,
            &[0x80, 0x00, 0xff, 0xff],
            None,
        );
        let t = Texture::from_png_bytes(&png, Path::new("g.png"), TextureEncoding::Linear)
            .expect("decodes");
        assert!(close(t.texels[0], Vec3::splat(32768.0 / 65535.0), 1e-7));
        assert!(close(t.texels[1], Vec3::ONE, 0.0));
        // 1-bit grey, 3 × 1: bits 1 0 1 (row padded to a byte).
        let png = encode_png(
            3,
            1,
            png::ColorType::Grayscale,
            png::BitDepth::One,
            &[0b1010_0000],
            None,
        );
        let t = Texture::from_png_bytes(&png, Path::new("b.png"), TextureEncoding::Linear)
            .expect("decodes");
        assert_eq!(t.texels, vec![Vec3::ONE, Vec3::ZERO, Vec3::ONE]);
        // 4-bit palette, 2 × 1, indices 1 and 0.
        let palette = vec![10, 20, 30, 255, 0, 51];
        let png = encode_png(
            2,
            1,
            png::ColorType::Indexed,
            png::BitDepth::Four,
            &[0x10],
            Some(palette),
        );
        let t = Texture::from_png_bytes(&png, Path::new("p.png"), TextureEncoding::Linear)
            .expect("decodes");
        assert!(close(t.texels[0], Vec3::new(1.0, 0.0, 0.2), 1e-6));
        assert!(close(
            t.texels[1],
            Vec3::new(10.0, 20.0, 30.0) / 255.0,
            1e-6
        ));
        // RGBA 8: alpha ignored.
        let png = encode_png(
            1,
            1,
            png::ColorType::Rgba,
            png::BitDepth::Eight,
            &[51, 102, 153, 7],
            None,
        );
        let t = Texture::from_png_bytes(&png, Path::new("r.png"), TextureEncoding::Linear)
            .expect("decodes");
        assert!(close(t.texels[0], Vec3::new(0.2, 0.4, 0.6), 1e-6));
        // Grey + alpha, 8 bit.
        let png = encode_png(
            1,
            1,
            png::ColorType::GrayscaleAlpha,
            png::BitDepth::Eight,
            &[255, 0],
            None,
        );
        let t = Texture::from_png_bytes(&png, Path::new("ga.png"), TextureEncoding::Srgb)
            .expect("decodes");
        assert!(close(t.texels[0], Vec3::ONE, 1e-6));
    }

    #[test]
    fn rejects_garbage_truncation_and_absurd_sizes() {
        let err = Texture::from_png_bytes(b"not a png", Path::new("x.png"), TextureEncoding::Srgb)
            .expect_err("garbage");
        assert!(err.to_string().contains("x.png"), "{err}");
        let source = std::error::Error::source(&err).expect("the decoder's error");
        assert!(source.downcast_ref::<png::DecodingError>().is_some());
        let data: Vec<u8> = (0..64 * 64 * 3).map(|i| (i * 7 % 251) as u8).collect();
        let png = encode_png(
            64,
            64,
            png::ColorType::Rgb,
            png::BitDepth::Eight,
            &data,
            None,
        );
        for cut in [10, 40, png.len() / 2, png.len() - 13] {
            let err =
                Texture::from_png_bytes(&png[..cut], Path::new("t.png"), TextureEncoding::Srgb)
                    .expect_err("truncated");
            assert!(err.to_string().contains("t.png"), "{err}");
        }
        // A header claiming 20000 × 1: rejected before decoding.
        let mut huge = encode_png(
            1,
            1,
            png::ColorType::Rgb,
            png::BitDepth::Eight,
            &[0; 3],
            None,
        );
        patch_ihdr_size(&mut huge, 20_000, 1);
        let err = Texture::from_png_bytes(&huge, Path::new("h.png"), TextureEncoding::Srgb)
            .expect_err("too wide");
        assert!(err.message.contains("16384"), "{err}");
        let mut huge = encode_png(
            1,
            1,
            png::ColorType::Rgb,
            png::BitDepth::Eight,
            &[0; 3],
            None,
        );
        patch_ihdr_size(&mut huge, 16_000, 16_000);
        let err = Texture::from_png_bytes(&huge, Path::new("h.png"), TextureEncoding::Srgb)
            .expect_err("too many texels");
        assert!(err.message.contains("texels"), "{err}");
        assert!(
            std::error::Error::source(&err).is_none(),
            "a check, not a decoder error"
        );
    }

    #[test]
    fn load_png_reports_missing_files() {
        let err = Texture::load_png(Path::new("/nonexistent/kd.png"), TextureEncoding::Srgb)
            .expect_err("missing");
        assert!(err.to_string().contains("/nonexistent/kd.png"), "{err}");
        assert!(err.message.contains("cannot read"), "{err}");
        let source = std::error::Error::source(&err).expect("the I/O error");
        let io = source
            .downcast_ref::<std::io::Error>()
            .expect("an io::Error");
        assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
    }

    /// Rewrites the IHDR width/height of a PNG and fixes its CRC.
    pub(crate) fn patch_ihdr_size(png: &mut [u8], width: u32, height: u32) {
        // Signature (8) + length (4) + "IHDR" (4), then width, height.
        png[16..20].copy_from_slice(&width.to_be_bytes());
        png[20..24].copy_from_slice(&height.to_be_bytes());
        let crc = crc32(&png[12..29]);
        png[29..33].copy_from_slice(&crc.to_be_bytes());
    }

    /// Plain CRC-32 (PNG chunk checksum), bitwise.
    fn crc32(data: &[u8]) -> u32 {
        let mut crc = 0xffff_ffffu32;
        for &byte in data {
            crc ^= u32::from(byte);
            for _ in 0..8 {
                let mask = (crc & 1).wrapping_neg();
                crc = (crc >> 1) ^ (0xedb8_8320 & mask);
            }
        }
        !crc
    }
}
