use super::*;

mod encode;
mod formats;
mod scene_textures;

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
    Texture::from_linear(PathBuf::from("test"), width, height, texels)
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

/// Two textures sampled together give each one's own lookup, bit for bit: of the same size
/// (one footprint), of different sizes, and with an empty one (black, as alone).
#[test]
fn sample_pair_is_two_samples() {
    let ramp = |w: u32, h: u32, k: f32| {
        let texels = (0..w * h)
            .map(|i| Vec3::new(i as f32 * k, 1.0 / (i as f32 + 1.5), (i % 3) as f32))
            .collect();
        texture(w, h, texels)
    };
    let (a, b, c) = (ramp(3, 2, 0.1), ramp(3, 2, 0.7), ramp(5, 4, 0.3));
    let empty = texture(0, 0, Vec::new());
    let uvs = [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.999, 0.0),
        Vec2::new(-1.3, 7.25),
        Vec2::new(f32::NAN, 0.5),
        Vec2::new(1.0 / 3.0, 0.5),
    ];
    for uv in uvs {
        for (x, y) in [(&a, &b), (&a, &c), (&c, &a), (&a, &empty), (&empty, &a)] {
            let (p, q) = Texture::sample_pair(x, y, uv);
            assert_eq!(
                (p.to_array(), q.to_array()),
                (x.sample(uv).to_array(), y.sample(uv).to_array())
            );
        }
    }
    assert_ne!(
        Texture::sample_pair(&a, &b, uvs[0]).0,
        Texture::sample_pair(&a, &b, uvs[0]).1
    );
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
    let lin =
        Texture::from_bytes(&png, Path::new("a.png"), TextureEncoding::Linear).expect("decodes");
    assert_eq!((lin.width, lin.height), (2, 1));
    assert!(close(
        lin.texel(0),
        Vec3::new(1.0, 128.0 / 255.0, 0.0),
        1e-6
    ));
    assert!(close(
        lin.texel(1),
        Vec3::new(188.0 / 255.0, 10.0 / 255.0, 64.0 / 255.0),
        1e-6
    ));
    let s = Texture::from_bytes(&png, Path::new("a.png"), TextureEncoding::Srgb).expect("decodes");
    assert!((s.texel(1).x - 0.502_886).abs() < 1e-5);
    assert!((s.texel(1).y - 10.0 / 255.0 / 12.92).abs() < 1e-6);
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
    let t =
        Texture::from_bytes(&png, Path::new("g.png"), TextureEncoding::Linear).expect("decodes");
    assert!(close(t.texel(0), Vec3::splat(32768.0 / 65535.0), 1e-7));
    assert!(close(t.texel(1), Vec3::ONE, 0.0));
    // 16-bit RGB and RGBA, big endian, each channel its own code; sRGB-decoded, exactly.
    let codes: [u16; 6] = [0x0102, 0x8000, 0xfffe, 0x0000, 0x1234, 0xffff];
    let srgb = |c: u16| srgb_to_linear(f32::from(c) / 65535.0);
    let want = [0, 3].map(|i| Vec3::new(srgb(codes[i]), srgb(codes[i + 1]), srgb(codes[i + 2])));
    let be: Vec<u8> = codes.iter().flat_map(|c| c.to_be_bytes()).collect();
    let alpha: Vec<u8> = be
        .chunks_exact(6)
        .flat_map(|p| p.iter().copied().chain([0x55, 0xaa]))
        .collect();
    for (colour, data) in [(png::ColorType::Rgb, be), (png::ColorType::Rgba, alpha)] {
        let png = encode_png(2, 1, colour, png::BitDepth::Sixteen, &data, None);
        let t =
            Texture::from_bytes(&png, Path::new("c.png"), TextureEncoding::Srgb).expect("decodes");
        assert_eq!([t.texel(0), t.texel(1)], want, "{colour:?}");
    }
    // 1-bit grey, 3 × 1: bits 1 0 1 (row padded to a byte).
    let png = encode_png(
        3,
        1,
        png::ColorType::Grayscale,
        png::BitDepth::One,
        &[0b1010_0000],
        None,
    );
    let t =
        Texture::from_bytes(&png, Path::new("b.png"), TextureEncoding::Linear).expect("decodes");
    assert_eq!(
        t.texels().collect::<Vec<_>>(),
        vec![Vec3::ONE, Vec3::ZERO, Vec3::ONE]
    );
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
    let t =
        Texture::from_bytes(&png, Path::new("p.png"), TextureEncoding::Linear).expect("decodes");
    assert!(close(t.texel(0), Vec3::new(1.0, 0.0, 0.2), 1e-6));
    assert!(close(t.texel(1), Vec3::new(10.0, 20.0, 30.0) / 255.0, 1e-6));
    // RGBA 8: alpha ignored.
    let png = encode_png(
        1,
        1,
        png::ColorType::Rgba,
        png::BitDepth::Eight,
        &[51, 102, 153, 7],
        None,
    );
    let t =
        Texture::from_bytes(&png, Path::new("r.png"), TextureEncoding::Linear).expect("decodes");
    assert!(close(t.texel(0), Vec3::new(0.2, 0.4, 0.6), 1e-6));
    // Grey + alpha, 8 bit.
    let png = encode_png(
        1,
        1,
        png::ColorType::GrayscaleAlpha,
        png::BitDepth::Eight,
        &[255, 0],
        None,
    );
    let t = Texture::from_bytes(&png, Path::new("ga.png"), TextureEncoding::Srgb).expect("decodes");
    assert!(close(t.texel(0), Vec3::ONE, 1e-6));
}

#[test]
fn rejects_garbage_truncation_and_absurd_sizes() {
    // No known signature: rejected before any decoder runs, with the first bytes shown.
    let err = Texture::from_bytes(b"not a png", Path::new("x.png"), TextureEncoding::Srgb)
        .expect_err("garbage");
    assert_eq!(
        err.to_string(),
        "texture x.png: not a PNG, JPEG, BMP, Radiance HDR or OpenEXR file (it starts with \
         6e 6f 74 20 61 20 70 6e), nor named .tga"
    );
    assert!(std::error::Error::source(&err).is_none());
    let err =
        Texture::from_bytes(b"", Path::new("e.png"), TextureEncoding::Srgb).expect_err("empty");
    assert_eq!(err.to_string(), "texture e.png: empty file");
    // A PNG signature and then garbage: the decoder's reason, and the decoder's error.
    let err = Texture::from_bytes(
        b"\x89PNG\r\n\x1a\ngarbage",
        Path::new("x.png"),
        TextureEncoding::Srgb,
    )
    .expect_err("garbage");
    assert!(
        err.to_string()
            .starts_with("texture x.png: PNG decoding failed: "),
        "{err}"
    );
    let source = std::error::Error::source(&err).expect("the decoder's error");
    assert!(source.downcast_ref::<image::ImageError>().is_some());
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
        let err = Texture::from_bytes(&png[..cut], Path::new("t.png"), TextureEncoding::Srgb)
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
    let err = Texture::from_bytes(&huge, Path::new("h.png"), TextureEncoding::Srgb)
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
    let err = Texture::from_bytes(&huge, Path::new("h.png"), TextureEncoding::Srgb)
        .expect_err("too many texels");
    assert!(err.message.contains("texels"), "{err}");
    assert!(
        std::error::Error::source(&err).is_none(),
        "a check, not a decoder error"
    );
}

#[test]
fn load_reports_missing_files() {
    let err = Texture::load(Path::new("/nonexistent/kd.png"), TextureEncoding::Srgb)
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

/// The lookup's floor is the standard library's on every kind of finite value.
#[test]
fn floor_matches_the_standard_library() {
    let mut values = vec![
        0.0,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        0.999_999_94,
        -0.999_999_94,
        8_388_607.5,
        -8_388_607.5,
        8_388_608.0,
        -8_388_609.0,
        1e30,
        -1e30,
        f32::MAX,
        f32::MIN,
        f32::MIN_POSITIVE,
        -f32::MIN_POSITIVE,
    ];
    let mut state = 0x2545_f491_u32;
    for _ in 0..100_000 {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        // Every sign and exponent up to 2^40.
        let bits = (state & 0x803f_ffff) | ((100 + state % 67) << 23);
        values.push(f32::from_bits(bits));
    }
    for x in values {
        assert_eq!(floor(x), x.floor(), "{x}");
    }
}

/// A UDIM set holds its tiles' texels one tile after the other, in tile order, and samples
/// alone or in a pair with another texture of either kind.
#[test]
fn a_udim_set_holds_its_tiles_and_samples_in_pairs() {
    let a = texture(1, 1, vec![Vec3::X]);
    let b = texture(2, 1, vec![Vec3::Y, Vec3::Z]);
    let set = Texture::udim("s.<UDIM>.png", vec![(1002, b.clone()), (1001, a.clone())])
        .expect("valid tiles");
    assert!(set.is_udim() && !a.is_udim());
    assert_eq!(set.texel_count(), 3);
    assert_eq!(
        set.texels().collect::<Vec<_>>(),
        [Vec3::X, Vec3::Y, Vec3::Z]
    );
    assert_eq!(set.texel(2), Vec3::Z);
    assert_eq!(set.texel_bytes(), 3 * 12);
    let uv = Vec2::new(1.3, 0.5);
    let in_tile = uv - Vec2::X; // what the set samples its tile 1002 at
    assert_ne!(b.sample(uv), b.sample(Vec2::new(0.7, 0.5)));
    assert_eq!(set.sample(uv), b.sample(in_tile));
    assert_eq!(set.sample(Vec2::new(0.3, 0.5)), Vec3::X);
    assert_eq!(
        Texture::sample_pair(&set, &b, uv),
        (b.sample(in_tile), b.sample(uv))
    );
    assert_eq!(
        Texture::sample_pair(&b, &set, uv),
        (b.sample(uv), b.sample(in_tile))
    );
    assert!(Texture::udim("s", vec![(1001, a.clone()), (1001, a)]).is_none());
}
