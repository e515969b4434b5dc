//! Every format: exact texels where the format is lossless (JPEG within a tolerance), colour
//! vs data decoding, format detection, and corrupt, truncated and oversized files.

use std::path::Path;

use exr::prelude::{FlatSamples, f16};
use glam::Vec3;

use super::super::{
    MAX_TEXTURE_SIDE, Texture, TextureEncoding, TextureError, TextureFormat, TextureLimits,
    srgb_to_linear,
};
use super::encode::{
    bmp_rgb, exr_b44, exr_channels, exr_rgb_f32, exr_tiled_rgb_f32, hdr_rgbe, jpeg_grey, jpeg_rgb,
    tga_grey, tga_header, tga_rgb,
};
use super::{encode_png, patch_ihdr_size};

fn load(bytes: &[u8], name: &str, encoding: TextureEncoding) -> Result<Texture, TextureError> {
    Texture::from_bytes(bytes, Path::new(name), encoding)
}

fn ok(bytes: &[u8], name: &str, encoding: TextureEncoding) -> Texture {
    load(bytes, name, encoding).unwrap_or_else(|e| panic!("{e}"))
}

fn err(bytes: &[u8], name: &str) -> String {
    load(bytes, name, TextureEncoding::Srgb)
        .expect_err("must fail")
        .to_string()
}

/// 8-bit codes as data: `code / 255`.
fn data8(p: [u8; 3]) -> Vec3 {
    Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0
}

/// 8-bit codes as colour: the sRGB decode of `code / 255`.
fn colour8(p: [u8; 3]) -> Vec3 {
    data8(p).to_array().map(srgb_to_linear).into()
}

/// A 3 × 2 pattern with distinct channels, rows top first.
const PATTERN: [[u8; 3]; 6] = [
    [255, 0, 0],
    [0, 128, 0],
    [0, 0, 64],
    [10, 20, 30],
    [188, 188, 188],
    [1, 254, 127],
];

#[test]
fn detects_formats_by_content_and_tga_by_extension() {
    let png = encode_png(
        1,
        1,
        png::ColorType::Rgb,
        png::BitDepth::Eight,
        &[0; 3],
        None,
    );
    let cases: [(&[u8], &str, Option<TextureFormat>); 9] = [
        (&png, "a.jpg", Some(TextureFormat::Png)),
        (b"\xff\xd8\xff\xe0", "a.png", Some(TextureFormat::Jpeg)),
        (b"BM....", "a", Some(TextureFormat::Bmp)),
        (b"#?RADIANCE\n", "a.exr", Some(TextureFormat::Hdr)),
        (b"#?RGBE\n", "a.hdr", Some(TextureFormat::Hdr)),
        (b"\x76\x2f\x31\x01\x02", "a.png", Some(TextureFormat::Exr)),
        (b"\0\0\x02", "a.TGA", Some(TextureFormat::Tga)),
        (b"\0\0\x02", "a.png", None),
        (b"", "a.tga", Some(TextureFormat::Tga)),
    ];
    for (bytes, name, want) in cases {
        assert_eq!(
            TextureFormat::detect(bytes, Path::new(name)),
            want,
            "{name}"
        );
    }
}

#[test]
fn tga_true_colour_bottom_up_and_grey_top_down_are_exact() {
    for top_first in [false, true] {
        let file = tga_rgb(3, 2, &PATTERN, top_first);
        let data = ok(&file, "t.tga", TextureEncoding::Linear);
        assert_eq!((data.width, data.height), (3, 2));
        let want: Vec<Vec3> = PATTERN.iter().map(|&p| data8(p)).collect();
        assert_eq!(
            data.texels().collect::<Vec<_>>(),
            want,
            "top_first {top_first}"
        );
        let colour = ok(&file, "t.tga", TextureEncoding::Srgb);
        let want: Vec<Vec3> = PATTERN.iter().map(|&p| colour8(p)).collect();
        assert_eq!(colour.texels().collect::<Vec<_>>(), want);
    }
    let t = ok(&tga_grey(2, 1, &[0, 51]), "g.TGA", TextureEncoding::Linear);
    assert_eq!(
        t.texels().collect::<Vec<_>>(),
        vec![Vec3::ZERO, Vec3::splat(0.2)]
    );
}

#[test]
fn bmp_bottom_up_padded_rows_are_exact() {
    // 3 pixels × 3 bytes = 9, padded to 12 per row: the padding must not shift pixels.
    let file = bmp_rgb(3, 2, &PATTERN);
    let data = ok(&file, "b.bmp", TextureEncoding::Linear);
    assert_eq!((data.width, data.height), (3, 2));
    let want: Vec<Vec3> = PATTERN.iter().map(|&p| data8(p)).collect();
    assert_eq!(data.texels().collect::<Vec<_>>(), want);
    let colour = ok(&file, "b.bmp", TextureEncoding::Srgb);
    let want: Vec<Vec3> = PATTERN.iter().map(|&p| colour8(p)).collect();
    assert_eq!(colour.texels().collect::<Vec<_>>(), want);
}

#[test]
fn hdr_is_linear_float_for_colour_and_data() {
    // m · 2^(e − 136): (128, 64, 32) at e = 129 is (1, 0.5, 0.25); e = 0 is black; e = 140
    // scales 200 by 16 (values above 1 are kept).
    let file = hdr_rgbe(
        2,
        2,
        &[
            [128, 64, 32, 129],
            [0, 0, 0, 0],
            [200, 1, 255, 140],
            [128, 128, 128, 128],
        ],
    );
    let want = vec![
        Vec3::new(1.0, 0.5, 0.25),
        Vec3::ZERO,
        Vec3::new(3200.0, 16.0, 4080.0),
        Vec3::splat(0.5),
    ];
    for encoding in [TextureEncoding::Srgb, TextureEncoding::Linear] {
        let t = ok(&file, "h.hdr", encoding);
        assert_eq!((t.width, t.height), (2, 2));
        assert_eq!(t.texels().collect::<Vec<_>>(), want, "{encoding:?}");
    }
}

#[test]
fn exr_rgb_half_and_single_channel_are_exact_and_linear() {
    let rgb = [
        [0.0, 0.5, 1.0],
        [0.125, 2.5, 1e-3],
        [0.75, 0.25, 0.0625],
        [3.0, 0.0, 1.0 / 3.0],
    ];
    let file = exr_rgb_f32(2, 2, &rgb);
    let want: Vec<Vec3> = rgb.iter().map(|&p| Vec3::from_array(p)).collect();
    for encoding in [TextureEncoding::Srgb, TextureEncoding::Linear] {
        let t = ok(&file, "e.exr", encoding);
        assert_eq!((t.width, t.height), (2, 2));
        assert_eq!(t.texels().collect::<Vec<_>>(), want);
    }
    // Half floats, luminance only (with alpha, ignored): replicated to RGB.
    let h = |v: &[f32]| FlatSamples::F16(v.iter().map(|&x| f16::from_f32(x)).collect());
    let file = exr_channels(
        3,
        1,
        vec![("Y", h(&[0.25, 0.5, 0.875])), ("A", h(&[1.0, 0.0, 0.5]))],
    );
    let t = ok(&file, "y.exr", TextureEncoding::Linear);
    assert_eq!(
        t.texels().collect::<Vec<_>>(),
        vec![Vec3::splat(0.25), Vec3::splat(0.5), Vec3::splat(0.875)]
    );
    // One channel of any name.
    let file = exr_channels(2, 1, vec![("Z", FlatSamples::F32(vec![0.1, 0.9]))]);
    let t = ok(&file, "z.exr", TextureEncoding::Linear);
    assert_eq!(
        t.texels().collect::<Vec<_>>(),
        vec![Vec3::splat(0.1), Vec3::splat(0.9)]
    );
    // Two channels that are neither RGB nor Y: which one is meant is unclear.
    let file = exr_channels(
        1,
        1,
        vec![
            ("U", FlatSamples::F32(vec![0.0])),
            ("V", FlatSamples::F32(vec![0.0])),
        ],
    );
    let message = err(&file, "uv.exr");
    assert!(
        message.contains("no R, G, B channels") && message.contains("(channels: U, V)"),
        "{message}"
    );
}

#[test]
fn exr_b44_is_refused_before_it_is_decoded() {
    let half = |v: f32| f16::from_f32(v);
    let file = exr_b44(
        8,
        8,
        vec![(
            "Y",
            FlatSamples::F16((0..64).map(|i| half(i as f32)).collect()),
        )],
    );
    let message = err(&file, "b.exr");
    assert!(
        message.starts_with("texture b.exr: OpenEXR B44 compression is not read"),
        "{message}"
    );
}

#[test]
fn exr_non_finite_texels_are_errors_naming_the_texel() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let file = exr_rgb_f32(2, 2, &[[0.5; 3], [0.5; 3], [0.5, bad, 0.5], [0.5; 3]]);
        let message = err(&file, "n.exr");
        assert!(
            message.starts_with("texture n.exr: texel (0, 1) (column, row from the top) is "),
            "{message}"
        );
        assert!(
            message.contains("OpenEXR values must be finite"),
            "{message}"
        );
    }
}

#[test]
fn jpeg_decodes_within_a_few_codes_as_colour_and_data() {
    // Grey: four flat 8 × 8 blocks, one per quadrant (each block's DCT is a single DC term).
    let codes = [16u8, 96, 160, 240];
    let grey: Vec<u8> = (0..16 * 16)
        .map(|i| codes[(i / 16 / 8) * 2 + (i % 16) / 8])
        .collect();
    let file = jpeg_grey(16, 16, &grey, 95);
    let data = ok(&file, "g.jpg", TextureEncoding::Linear);
    assert_eq!((data.width, data.height), (16, 16));
    for (i, (t, &code)) in data.texels().zip(&grey).enumerate() {
        let want = code as f32 / 255.0;
        assert!(
            (t.x - want).abs() <= 1.0 / 255.0 && t.x == t.y && t.y == t.z,
            "texel {i}: {t} vs {want}"
        );
    }
    // Colour: a flat RGB field (chroma subsampling and YCbCr rounding cost a few codes).
    let rgb = [200u8, 120, 40];
    let pixels: Vec<u8> = rgb.iter().copied().cycle().take(16 * 16 * 3).collect();
    let file = jpeg_rgb(16, 16, &pixels, 95);
    let data = ok(&file, "c.jpeg", TextureEncoding::Linear);
    let colour = ok(&file, "c.jpeg", TextureEncoding::Srgb);
    for (d, c) in data.texels().zip(colour.texels()) {
        assert!(
            (d - data8(rgb)).abs().max_element() <= 3.0 / 255.0,
            "{d} vs {}",
            data8(rgb)
        );
        // Colour is the sRGB decode of the very same codes.
        let decoded = Vec3::from_array(d.to_array().map(srgb_to_linear));
        assert!(
            (c - decoded).abs().max_element() <= 1e-6,
            "{c} vs {decoded}"
        );
    }
    // The content decides: the same JPEG named .png still decodes as a JPEG.
    assert_eq!(
        ok(&file, "c.png", TextureEncoding::Linear),
        Texture {
            path: "c.png".into(),
            ..data
        }
    );
}

/// Each format's small valid file, named with its usual extension.
fn valid_files() -> Vec<(&'static str, Vec<u8>)> {
    let grey: Vec<u8> = (0..64).map(|i| (i * 4) as u8).collect();
    vec![
        (
            "v.png",
            encode_png(
                8,
                8,
                png::ColorType::Grayscale,
                png::BitDepth::Eight,
                &grey,
                None,
            ),
        ),
        ("v.jpg", jpeg_grey(8, 8, &grey, 90)),
        ("v.tga", tga_rgb(3, 2, &PATTERN, false)),
        ("v.bmp", bmp_rgb(3, 2, &PATTERN)),
        (
            "v.hdr",
            hdr_rgbe(2, 1, &[[128, 64, 32, 129], [1, 2, 3, 130]]),
        ),
        ("v.exr", exr_rgb_f32(2, 2, &[[0.5; 3]; 4])),
    ]
}

/// Every prefix of a valid file of each format: an error that names the file and the format,
/// or (where the cut only loses trailing bytes the decoder does not need) the full-size
/// texture; never a panic.
#[test]
fn truncated_files_are_errors_naming_the_file() {
    for (name, file) in valid_files() {
        let mut errors = 0;
        for cut in 0..file.len() {
            match load(&file[..cut], name, TextureEncoding::Srgb) {
                Err(e) => {
                    let message = e.to_string();
                    assert!(
                        message.starts_with(&format!("texture {name}: ")),
                        "{message}"
                    );
                    errors += 1;
                }
                Ok(t) => {
                    assert_eq!(t.texel_count(), (t.width * t.height) as usize);
                    assert!(cut > file.len() / 2, "{name} decoded from {cut} bytes");
                }
            }
        }
        assert!(errors > file.len() / 2, "{name}: only {errors} errors");
    }
}

/// Single-byte corruptions anywhere: an error naming the file, or a texture; never a panic.
#[test]
fn corrupt_files_never_panic() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for (name, file) in valid_files() {
        for _ in 0..300 {
            let mut bad = file.clone();
            let at = (next() % bad.len() as u64) as usize;
            bad[at] ^= (next() % 255 + 1) as u8;
            match load(&bad, name, TextureEncoding::Linear) {
                Err(e) => assert!(e.to_string().contains(name), "{e}"),
                Ok(t) => {
                    assert_eq!(t.texel_count(), (t.width * t.height) as usize);
                    assert!(t.texels().all(|v| v.is_finite()));
                }
            }
        }
    }
}

/// Error messages name the format and carry the decoder's reason.
#[test]
fn decoder_errors_name_the_format() {
    let cases: [(&[u8], &str, &str); 5] = [
        (
            b"\xff\xd8\xff\xe0\0\x10JFIF\0",
            "kd.jpg",
            "JPEG decoding failed: ",
        ),
        (b"BM\0\0", "kd.bmp", "BMP decoding failed: "),
        (
            b"#?RADIANCE\nbad",
            "kd.hdr",
            "Radiance HDR decoding failed: ",
        ),
        (
            b"\x76\x2f\x31\x01\x02\0\0\0",
            "kd.exr",
            "OpenEXR decoding failed: ",
        ),
        (b"\0\0\x02\0", "kd.tga", "TGA decoding failed: "),
    ];
    for (bytes, name, prefix) in cases {
        let e = load(bytes, name, TextureEncoding::Srgb).expect_err(name);
        let message = e.to_string();
        assert!(
            message.starts_with(&format!("texture {name}: {prefix}")) && message.len() > 30,
            "{message}"
        );
        assert!(std::error::Error::source(&e).is_some(), "{message}");
    }
}

/// Headers claiming absurd sizes: rejected by lucent's check (no decoder error behind it)
/// before pixel memory exists.
#[test]
fn oversized_headers_are_rejected_before_decoding() {
    let side = format!("larger than {MAX_TEXTURE_SIDE} texels per side");
    // PNG: IHDR patched.
    let mut png = encode_png(
        1,
        1,
        png::ColorType::Rgb,
        png::BitDepth::Eight,
        &[0; 3],
        None,
    );
    patch_ihdr_size(&mut png, 20_000, 1);
    // JPEG: the SOF0 segment's height and width patched to 16000 × 16000.
    let mut jpeg = jpeg_grey(8, 8, &[0; 64], 90);
    let sof = jpeg
        .windows(2)
        .position(|w| w == [0xff, 0xc0])
        .expect("SOF0");
    jpeg[sof + 5..sof + 9].copy_from_slice(&[0x3e, 0x80, 0x3e, 0x80]);
    // TGA: 65535 × 1, header only.
    let tga = tga_header(2, 65_535, 1, 24, false);
    // BMP: 16384 × 16384 claimed, 1 × 1 given.
    let bmp = bmp_rgb(16_384, 16_384, &[[0; 3]]);
    // HDR: 100000 × 100000.
    let hdr = hdr_rgbe(100_000, 100_000, &[]);
    // EXR: the data window's x_max patched from 1 to 19999 (a 20000 × 2 image).
    let mut exr = exr_rgb_f32(2, 2, &[[0.0; 3]; 4]);
    let at = exr
        .windows(11)
        .position(|w| w == b"dataWindow\0")
        .expect("dataWindow");
    let values = at + 11 + b"box2i\0".len() + 4;
    exr[values + 8..values + 12].copy_from_slice(&19_999i32.to_le_bytes());
    let cases: [(&[u8], &str, &str); 6] = [
        (&png, "h.png", "image is 20000 × 1, "),
        (
            &jpeg,
            "h.jpg",
            "image is 16000 × 16000, more than 67108864 texels",
        ),
        (&tga, "h.tga", "image is 65535 × 1, "),
        (
            &bmp,
            "h.bmp",
            "image is 16384 × 16384, more than 67108864 texels",
        ),
        (&hdr, "h.hdr", "image is 100000 × 100000, "),
        (&exr, "h.exr", "image is 20000 × 2, "),
    ];
    for (bytes, name, needle) in cases {
        let e = load(bytes, name, TextureEncoding::Srgb).expect_err(name);
        assert!(e.message.starts_with(needle), "{name}: {e}");
        if !needle.ends_with("texels") {
            assert!(e.message.ends_with(&side), "{name}: {e}");
        }
        assert!(std::error::Error::source(&e).is_none(), "{name}: {e}");
    }
    // Lower caps apply the same way (what the fuzz target uses).
    let small = TextureLimits {
        max_side: 4,
        max_texels: 6,
    };
    let tga = tga_rgb(3, 2, &PATTERN, false);
    let t = Texture::decode(
        &tga,
        Path::new("s.tga"),
        TextureFormat::Tga,
        TextureEncoding::Linear,
        &small,
    );
    assert!(t.is_ok());
    let small = TextureLimits {
        max_texels: 5,
        ..small
    };
    let e = Texture::decode(
        &tga,
        Path::new("s.tga"),
        TextureFormat::Tga,
        TextureEncoding::Linear,
        &small,
    )
    .expect_err("6 texels > 5");
    assert_eq!(e.message, "image is 3 × 2, more than 5 texels");
}

/// A texture past 4096² (4608 × 4608 grey, 21 M texels, more than 2²⁴) loads with the default
/// caps and reads exactly, its 8-bit codes held at three bytes a texel; 16-bit codes and
/// half-float OpenEXR maps take six, 32-bit floats twelve.
#[test]
fn eight_bit_textures_beyond_4096_squared_load_as_codes() {
    let (w, h) = (4608u32, 4608u32);
    let code = |x: u32, y: u32| ((x * 7 + y * 13) % 256) as u8;
    let data: Vec<u8> = (0..h)
        .flat_map(|y| (0..w).map(move |x| code(x, y)))
        .collect();
    let png = encode_png(
        w,
        h,
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        &data,
        None,
    );
    let t = ok(&png, "big.png", TextureEncoding::Srgb);
    assert_eq!((t.width, t.height), (w, h));
    let n = (w * h) as usize;
    assert_eq!(t.texel_count(), n);
    assert_eq!(t.texel_bytes(), 3 * n + 256 * 4);
    for (x, y) in [(0, 0), (w - 1, 0), (1234, 3456), (w - 1, h - 1)] {
        let want = srgb_to_linear(f32::from(code(x, y)) / 255.0);
        assert_eq!(
            t.texel((y * w + x) as usize),
            Vec3::splat(want),
            "({x}, {y})"
        );
    }
    let rgb = encode_png(
        2,
        1,
        png::ColorType::Rgb,
        png::BitDepth::Eight,
        &[1, 2, 3, 4, 5, 6],
        None,
    );
    assert_eq!(
        ok(&rgb, "rgb.png", TextureEncoding::Linear).texel_bytes(),
        6 + 256 * 4
    );
    let grey16 = encode_png(
        1,
        2,
        png::ColorType::Grayscale,
        png::BitDepth::Sixteen,
        &[0; 4],
        None,
    );
    assert_eq!(
        ok(&grey16, "g16.png", TextureEncoding::Linear).texel_bytes(),
        2 * 6 + 65_536 * 4
    );
    // OpenEXR: halves stay 16 bits when all three channels hold them.
    let halves = |v: [f32; 2]| FlatSamples::F16(v.map(f16::from_f32).to_vec());
    let rgb = |r, g, b| exr_channels(2, 1, vec![("R", r), ("G", g), ("B", b)]);
    let exr_bytes = |file: Vec<u8>| ok(&file, "m.exr", TextureEncoding::Linear).texel_bytes();
    let (one, two) = ([0.5, 1.0], [2.0, 4.0]);
    assert_eq!(
        exr_bytes(rgb(halves(one), halves(two), halves(one))),
        2 * 6 + 65_536 * 4
    );
    let floats = FlatSamples::F32(two.to_vec());
    assert_eq!(exr_bytes(rgb(halves(one), floats, halves(one))), 2 * 12);
    let grey = exr_channels(2, 1, vec![("Y", halves(two))]);
    assert_eq!(exr_bytes(grey), 2 * 6 + 65_536 * 4);
}

/// A tile size far beyond the image is refused from the header: the decoder would allocate a
/// block of that size before finding that the file does not hold it (a 2.5 KB file made it
/// zero-fill a gigabyte). Tiles that overhang a small image are real files and still load.
#[test]
fn exr_tiles_larger_than_the_image_are_refused_before_decoding() {
    for (size, tile) in [(2, 64), (5, 2), (40, 300)] {
        let t = ok(
            &exr_tiled_rgb_f32(size, size, tile),
            "t.exr",
            TextureEncoding::Linear,
        );
        assert_eq!((t.width, t.height), (size as u32, size as u32));
        let want: Vec<Vec3> = (0..size * size)
            .map(|i| Vec3::new(i as f32, (i + 1) as f32, (i + 2) as f32))
            .collect();
        assert_eq!(
            t.texels().collect::<Vec<_>>(),
            want,
            "{size}² in {tile}² tiles"
        );
    }
    let mut exr = exr_tiled_rgb_f32(64, 64, 16);
    let at = exr
        .windows(6)
        .position(|w| w == b"tiles\0")
        .expect("tiles attribute");
    // Name, type "tiledesc", size (4 bytes), then x size and y size (u32 each).
    let y_size = at + 6 + b"tiledesc\0".len() + 4 + 4;
    exr[y_size..y_size + 4].copy_from_slice(&16_449_600u32.to_le_bytes());
    let message = err(&exr, "tiles.exr");
    assert_eq!(
        message,
        "texture tiles.exr: OpenEXR part of 64 × 64 pixels declares tiles of 16 × 16449600 \
         pixels (3158323200 bytes each, more than the 67108864 bytes lucent allows a block of \
         this part)",
    );
}
