//! The textures of `scenes/textured-kd-jpeg.toml` and `scenes/textured-mfp-exr.toml`: made here
//! from closed-form patterns, so that they can be checked and remade.
//!
//! `LUCENT_BLESS=1 cargo test -p lucent-raster --lib texture::tests::scene_textures` rewrites
//! them; without it the committed files must decode to what the patterns give (the JPEG
//! within its compression error, the OpenEXR exactly).

use std::io::Cursor;
use std::path::{Path, PathBuf};

use exr::prelude::{
    AnyChannel, AnyChannels, Compression, Encoding, FlatSamples, Image, LayerAttributes, LineOrder,
    SmallVec, Vec2, WritableImage, f16,
};
use glam::Vec3;

use super::super::{Texture, TextureEncoding};
use super::encode::jpeg_rgb;

/// Side of both textures, in texels.
const SIDE: usize = 64;

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/textures")
}

fn bless() -> bool {
    std::env::var_os("LUCENT_BLESS").is_some_and(|v| !v.is_empty() && v != "0")
}

/// K_d as 8-bit sRGB codes at texel (x, y), y from the top: a 4 × 4 checker of a warm
/// skin-like and a cool blue-green reflectance, each darkening by 15% towards the bottom.
fn kd_codes(x: usize, y: usize) -> [u8; 3] {
    let warm = [224.0, 160.0, 128.0];
    let cool = [96.0, 160.0, 200.0];
    let base = if (x / 16 + y / 16).is_multiple_of(2) {
        warm
    } else {
        cool
    };
    let shade = 1.0 - 0.15 * y as f32 / (SIDE - 1) as f32;
    base.map(|c: f32| (c * shade).round() as u8)
}

/// The mean-free-path parameter t at texel (x, y): the distance from the centre in units of
/// the half side, clamped to 1, for red; 0.8 and 0.6 of it for green and blue (a smooth disc
/// where scattering is short in the middle and long outside, longest in red).
fn mfp_t(x: usize, y: usize) -> [f32; 3] {
    let centre = (SIDE as f32 - 1.0) / 2.0;
    let (dx, dy) = (x as f32 - centre, y as f32 - centre);
    let r = ((dx * dx + dy * dy).sqrt() / (SIDE as f32 / 2.0)).min(1.0);
    [r, 0.8 * r, 0.6 * r]
}

fn kd_jpeg() -> Vec<u8> {
    let rgb: Vec<u8> = (0..SIDE * SIDE)
        .flat_map(|i| kd_codes(i % SIDE, i / SIDE))
        .collect();
    jpeg_rgb(SIDE as u32, SIDE as u32, &rgb, 90)
}

/// Half floats (the data needs no more), ZIP compressed in blocks of 16 lines.
fn mfp_exr() -> Vec<u8> {
    let channel = |name: &str, c: usize| {
        let values = (0..SIDE * SIDE)
            .map(|i| f16::from_f32(mfp_t(i % SIDE, i / SIDE)[c]))
            .collect();
        AnyChannel::new(name, FlatSamples::F16(values))
    };
    let layer = exr::image::Layer::new(
        Vec2(SIDE, SIDE),
        LayerAttributes::default(),
        Encoding {
            compression: Compression::ZIP16,
            line_order: LineOrder::Increasing,
            ..Encoding::default()
        },
        AnyChannels::sort(SmallVec::from_vec(vec![
            channel("R", 0),
            channel("G", 1),
            channel("B", 2),
        ])),
    );
    let mut out = Vec::new();
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(Cursor::new(&mut out))
        .expect("EXR writes");
    out
}

#[test]
fn scene_textures_match_their_patterns() {
    let (jpeg_path, exr_path) = (
        scenes_dir().join("kd-checker.jpg"),
        scenes_dir().join("mfp-disc.exr"),
    );
    if bless() {
        std::fs::write(&jpeg_path, kd_jpeg()).unwrap();
        std::fs::write(&exr_path, mfp_exr()).unwrap();
    }
    for path in [&jpeg_path, &exr_path] {
        let size = std::fs::metadata(path).unwrap().len();
        assert!(size < 50_000, "{}: {size} bytes", path.display());
    }
    let kd = Texture::load(&jpeg_path, TextureEncoding::Linear).unwrap();
    assert_eq!((kd.width, kd.height), (SIDE as u32, SIDE as u32));
    // Away from the checker's edges (where the JPEG rings and chroma is shared) within a few
    // codes; everywhere within a bound that still tells the two colours apart.
    for (i, t) in kd.texels().enumerate() {
        let (x, y) = (i % SIDE, i / SIDE);
        let want = Vec3::from_array(kd_codes(x, y).map(|c| c as f32 / 255.0));
        let inner = (2..14).contains(&(x % 16)) && (2..14).contains(&(y % 16));
        let tolerance = if inner { 4.0 } else { 40.0 } / 255.0;
        assert!(
            (t - want).abs().max_element() <= tolerance,
            "kd texel ({x}, {y}): {t} vs {want}"
        );
    }
    let mfp = Texture::load(&exr_path, TextureEncoding::Linear).unwrap();
    assert_eq!((mfp.width, mfp.height), (SIDE as u32, SIDE as u32));
    for (i, t) in mfp.texels().enumerate() {
        let want = mfp_t(i % SIDE, i / SIDE).map(|v| f16::from_f32(v).to_f32());
        assert_eq!(t.to_array(), want, "mfp texel {i}");
    }
}
