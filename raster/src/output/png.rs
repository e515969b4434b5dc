//! 8-bit sRGB PNG output, and PNG input back to linear float.
//!
//! Writing: each linear channel is multiplied by `2^exposure` (exposure in stops), encoded with
//! the exact sRGB transfer function, clamped to [0, 1] and rounded to the nearest 8-bit code
//! (see [`super::srgb`]; NaN and −∞ become 0, +∞ becomes 255). The file is 8-bit RGB (no
//! alpha) with an `sRGB` chunk (perceptual intent), deflated with the `png` crate's `Balanced`
//! setting and adaptive filtering. It contains no time stamp or text, so the same image gives
//! the same bytes.
//!
//! Reading (for tests and `lucent compare`): 8- and 16-bit greyscale, RGB and palette files,
//! with or without alpha, interlaced or not. Samples are assumed to be sRGB-encoded whatever
//! `gAMA`/`iCCP` chunks say; alpha is dropped; greyscale is replicated to R = G = B.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use glam::Vec3;

use super::atomic::write_atomically;
use super::image::MAX_PIXELS;
use super::srgb::{Srgb8Encoder, srgb_to_linear, srgb8_to_linear_table};
use super::{OutputError, RgbImage};

/// Memory the PNG decoder may allocate (its default, 64 MiB, is too little for large 16-bit
/// images).
const DECODER_MEMORY_LIMIT: usize = 1 << 30;

/// Encodes `image` to interleaved 8-bit sRGB (`R G B R G B ...`, row-major, top row first)
/// with an exposure of `exposure` stops.
pub fn encode_srgb8(image: &RgbImage, exposure: f32) -> Vec<u8> {
    let encoder = Srgb8Encoder::new(exposure);
    let mut bytes = Vec::with_capacity(image.pixels().len() * 3);
    for p in image.pixels() {
        bytes.extend_from_slice(&[
            encoder.encode(p.x),
            encoder.encode(p.y),
            encoder.encode(p.z),
        ]);
    }
    bytes
}

/// Writes `image` as an 8-bit sRGB PNG, exposure in stops, atomically.
///
/// Fails on a zero-sized image or a non-finite exposure.
pub fn write_png(path: &Path, image: &RgbImage, exposure: f32) -> Result<(), OutputError> {
    if !exposure.is_finite() {
        return Err(OutputError::invalid(
            path,
            format!("exposure must be finite, got {exposure}"),
        ));
    }
    check_size(path, image.width(), image.height())?;
    let bytes = encode_srgb8(image, exposure);
    write_png_rgb8(path, image.width(), image.height(), &bytes)
}

/// Writes already-encoded 8-bit RGB bytes (`3 · width · height` of them) as a PNG, atomically.
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), OutputError> {
    check_size(path, width, height)?;
    let expected = 3 * width as u64 * height as u64;
    if rgb.len() as u64 != expected {
        return Err(OutputError::invalid(
            path,
            format!(
                "a {width}x{height} RGB image needs {expected} bytes, got {}",
                rgb.len()
            ),
        ));
    }
    let png_err = |source: png::EncodingError| OutputError::PngEncode {
        path: path.to_path_buf(),
        source,
    };
    write_atomically(path, |w| {
        let mut encoder = png::Encoder::new(w, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        encoder.set_compression(png::Compression::Balanced);
        encoder.set_filter(png::Filter::Adaptive);
        let mut writer = encoder.write_header().map_err(png_err)?;
        writer.write_image_data(rgb).map_err(png_err)?;
        writer.finish().map_err(png_err)
    })
}

fn check_size(path: &Path, width: u32, height: u32) -> Result<(), OutputError> {
    if width == 0 || height == 0 {
        return Err(OutputError::invalid(
            path,
            format!("cannot write a {width}x{height} image (both sides must be positive)"),
        ));
    }
    Ok(())
}

/// Reads a PNG and converts it to linear RGB (see the module doc for what is accepted).
pub fn read_png(path: &Path) -> Result<RgbImage, OutputError> {
    let file = File::open(path).map_err(|e| OutputError::io(path, "opening the PNG failed", e))?;
    let png_err = |source: png::DecodingError| OutputError::Png {
        path: path.to_path_buf(),
        source,
    };

    let mut decoder = png::Decoder::new_with_limits(
        BufReader::new(file),
        png::Limits {
            bytes: DECODER_MEMORY_LIMIT,
        },
    );
    decoder.set_transformations(png::Transformations::EXPAND);
    let header = decoder.read_header_info().map_err(png_err)?;
    let (width, height) = (header.width, header.height);
    if width as u64 * height as u64 > MAX_PIXELS {
        return Err(OutputError::invalid(
            path,
            format!("{width}x{height} pixels is more than the {MAX_PIXELS} lucent reads"),
        ));
    }
    let mut reader = decoder.read_info().map_err(png_err)?;
    let size = reader.output_buffer_size().ok_or_else(|| {
        OutputError::invalid(
            path,
            format!("{width}x{height} image is too large to decode"),
        )
    })?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(png_err)?;

    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => {
            return Err(OutputError::invalid(path, "palette image was not expanded"));
        }
    };
    let bytes_per_sample = match info.bit_depth {
        png::BitDepth::Eight => 1,
        png::BitDepth::Sixteen => 2,
        other => {
            return Err(OutputError::invalid(
                path,
                format!("unsupported bit depth {other:?} after expansion"),
            ));
        }
    };

    let row_samples = info.width as usize * channels;
    let row_bytes = row_samples * bytes_per_sample;
    let table8 = srgb8_to_linear_table();
    let sample = |row: &[u8], i: usize| -> f32 {
        if bytes_per_sample == 1 {
            row.get(i).map_or(0.0, |&b| table8[b as usize])
        } else {
            let hi = row.get(2 * i).copied().unwrap_or(0);
            let lo = row.get(2 * i + 1).copied().unwrap_or(0);
            let v = u16::from_be_bytes([hi, lo]);
            srgb_to_linear(v as f64 / 65535.0) as f32
        }
    };

    let mut pixels = Vec::with_capacity(info.width as usize * info.height as usize);
    for y in 0..info.height as usize {
        let start = y * info.line_size;
        let row = buf.get(start..start + row_bytes).ok_or_else(|| {
            OutputError::invalid(path, format!("decoded row {y} is shorter than expected"))
        })?;
        for x in 0..info.width as usize {
            let base = x * channels;
            let p = if channels < 3 {
                let g = sample(row, base);
                Vec3::splat(g)
            } else {
                Vec3::new(
                    sample(row, base),
                    sample(row, base + 1),
                    sample(row, base + 2),
                )
            };
            pixels.push(p);
        }
    }
    RgbImage::from_pixels(info.width, info.height, pixels)
        .map_err(|e| OutputError::invalid(path, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::super::atomic::tests::TestDir;
    use super::*;

    fn gradient(w: u32, h: u32) -> RgbImage {
        let mut pixels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                pixels.push(Vec3::new(
                    x as f32 / (w - 1) as f32,
                    y as f32 / (h - 1) as f32,
                    ((x * 7 + y * 3) % 11) as f32 / 10.0,
                ));
            }
        }
        RgbImage::from_pixels(w, h, pixels).unwrap()
    }

    /// Writes a raw PNG with the `png` crate directly (independent of `write_png`).
    fn write_raw(path: &Path, w: u32, h: u32, ct: png::ColorType, bd: png::BitDepth, d: &[u8]) {
        let file = std::fs::File::create(path).unwrap();
        let mut enc = png::Encoder::new(file, w, h);
        enc.set_color(ct);
        enc.set_depth(bd);
        let mut wr = enc.write_header().unwrap();
        wr.write_image_data(d).unwrap();
        wr.finish().unwrap();
    }

    #[test]
    fn encode_matches_hand_values_with_exposure() {
        let img = RgbImage::from_pixels(
            2,
            1,
            vec![Vec3::new(0.5, 0.18, 0.001), Vec3::new(0.25, 1.0, -1.0)],
        )
        .unwrap();
        assert_eq!(encode_srgb8(&img, 0.0), vec![188, 118, 3, 137, 255, 0]);
        // +1 stop: 1.0, 0.36, 0.002 | 0.5, 2.0, −2.0.
        // 0.36^(1/2.4) = 0.65311 → 0.63403 · 255 = 161.68 → 162; 0.002 → 7 (see srgb tests).
        assert_eq!(encode_srgb8(&img, 1.0), vec![255, 162, 7, 188, 255, 0]);
    }

    #[test]
    fn round_trip_through_file_is_within_half_a_code() {
        let dir = TestDir::new("png-rt");
        let path = dir.path("g.png");
        let img = gradient(17, 9);
        write_png(&path, &img, 0.0).unwrap();
        let back = read_png(&path).unwrap();
        assert_eq!(back.size(), (17, 9));
        // Decoding gives exactly the linear value of each written code.
        let codes = encode_srgb8(&img, 0.0);
        let table = srgb8_to_linear_table();
        for (i, p) in back.pixels().iter().enumerate() {
            for c in 0..3 {
                assert_eq!(
                    p[c],
                    table[codes[3 * i + c] as usize],
                    "pixel {i} channel {c}"
                );
            }
        }
        // And re-encoding the decoded image gives the same codes (idempotent quantisation).
        assert_eq!(encode_srgb8(&back, 0.0), codes);
    }

    #[test]
    fn output_is_deterministic_and_has_srgb_chunk() {
        let dir = TestDir::new("png-det");
        let (a, b) = (dir.path("a.png"), dir.path("b.png"));
        let img = gradient(33, 20);
        write_png(&a, &img, 0.3).unwrap();
        write_png(&b, &img, 0.3).unwrap();
        let (ba, bb) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        assert_eq!(ba, bb);
        assert!(ba.windows(4).any(|w| w == b"sRGB"));
        assert!(!ba.windows(4).any(|w| w == b"tIME" || w == b"tEXt"));
    }

    #[test]
    fn reads_16_bit_grey_alpha_and_palette() {
        let dir = TestDir::new("png-kinds");
        // 16-bit RGB: 0x8000 = 32768/65535 = 0.500008 → linear 0.214045.
        let p16 = dir.path("16.png");
        write_raw(
            &p16,
            1,
            1,
            png::ColorType::Rgb,
            png::BitDepth::Sixteen,
            &[0x80, 0x00, 0xFF, 0xFF, 0x00, 0x00],
        );
        let img = read_png(&p16).unwrap();
        let p = img.pixels()[0];
        let expected = ((32768.0f64 / 65535.0 + 0.055) / 1.055).powf(2.4) as f32;
        assert_eq!(p, Vec3::new(expected, 1.0, 0.0));
        assert!((expected - 0.214045).abs() < 1e-5);

        // Grey + alpha: grey replicated, alpha dropped.
        let pga = dir.path("ga.png");
        write_raw(
            &pga,
            2,
            1,
            png::ColorType::GrayscaleAlpha,
            png::BitDepth::Eight,
            &[188, 0, 255, 77],
        );
        let img = read_png(&pga).unwrap();
        let t = srgb8_to_linear_table();
        assert_eq!(img.pixels(), &[Vec3::splat(t[188]), Vec3::ONE]);

        // Palette (expanded by the decoder).
        let ppal = dir.path("pal.png");
        let file = std::fs::File::create(&ppal).unwrap();
        let mut enc = png::Encoder::new(file, 2, 1);
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_palette(vec![255, 0, 0, 0, 0, 188]);
        let mut wr = enc.write_header().unwrap();
        wr.write_image_data(&[1, 0]).unwrap();
        wr.finish().unwrap();
        let img = read_png(&ppal).unwrap();
        assert_eq!(
            img.pixels(),
            &[Vec3::new(0.0, 0.0, t[188]), Vec3::new(1.0, 0.0, 0.0)]
        );
    }

    #[test]
    fn bad_inputs_are_errors() {
        let dir = TestDir::new("png-bad");
        let path = dir.path("x.png");
        let err = write_png(&path, &RgbImage::new(0, 4), 0.0).unwrap_err();
        assert!(err.to_string().contains("0x4"), "{err}");
        let err = write_png(&path, &RgbImage::new(1, 1), f32::NAN).unwrap_err();
        assert!(err.to_string().contains("exposure"), "{err}");
        let err = write_png_rgb8(&path, 2, 2, &[0; 11]).unwrap_err();
        assert!(err.to_string().contains("needs 12 bytes"), "{err}");
        assert!(dir.entries().is_empty());

        // Missing file, garbage, truncated file.
        let err = read_png(&dir.path("missing.png")).unwrap_err();
        assert!(err.to_string().contains("missing.png"), "{err}");
        std::fs::write(&path, b"definitely not a png").unwrap();
        let err = read_png(&path).unwrap_err();
        assert!(matches!(err, OutputError::Png { .. }), "{err:?}");
        let source = std::error::Error::source(&err).expect("the decoder's error");
        assert!(source.downcast_ref::<png::DecodingError>().is_some());
        write_png(&path, &gradient(20, 20), 0.0).unwrap();
        let full = std::fs::read(&path).unwrap();
        for cut in [8, 20, 40, full.len() / 2, full.len() - 13] {
            std::fs::write(&path, &full[..cut]).unwrap();
            assert!(read_png(&path).is_err(), "cut at {cut}");
        }
    }
}
