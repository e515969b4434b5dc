//! Deterministic golden-image tests.
//!
//! Eleven small scenes — the default scene, the sphere shadow edge, the texture-mapped ℓ_u
//! plane, an opaque-only scene, the rect light, the environment map, an OBJ with two materials
//! (K_d from its `.mtl`), a binary-PLY bunny, a glTF egg under a node hierarchy, a JPEG K_d
//! texture and an OpenEXR ℓ_u texture — are rendered and compared with files committed under
//! `tests/golden/`:
//!
//! - `<name>.coverage.png`: the supersampled visibility buffer (triangle id + 1 as 24-bit RGB,
//!   black = empty), compared **exactly**;
//! - `<name>.png`: the 8-bit sRGB image, compared **exactly**;
//! - `<name>.exr`: linear radiance, exitance and depth. Depth is compared exactly; the shaded
//!   floats exactly on the pinned build configuration (x86-64 without FMA: fused multiply-add
//!   changes rounding; every transcendental comes from libm or lucent's own polynomial, so
//!   nothing else varies) and within 1e-5 relative (+1e-7 absolute) elsewhere.
//!
//! Regenerate after an intended change with `LUCENT_BLESS=1 cargo test -p lucent-tests --test it
//! golden::`, then look at the images before committing them.
//!
//! The README's pictures (`docs/images/`) are checked the same way at full size, and the
//! bless run rewrites them too.
//!
//! The same scenes also check determinism: identical bits for 1, 2 and 8 threads and across
//! repeated runs, for the image and for the baked sample file.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use lucent_core::glam::Vec3;
use lucent_raster::output::image::LAYER_EXITANCE;
use lucent_raster::output::png::write_png_rgb8;
use lucent_raster::output::{LayerData, RgbImage, read_exr, read_png, write_exr, write_png};
use lucent_raster::render::{Prepared, RenderOptions, bake, rasterize, render, write_baked};
use lucent_raster::scene::{ExrLayers, SampleDensity, Scene, default_scene, load_scene};

/// True where shaded floats must match their goldens bit for bit.
const PINNED: bool = cfg!(all(target_arch = "x86_64", not(target_feature = "fma")));

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn golden(name: &str) -> PathBuf {
    root().join("tests/golden").join(name)
}

/// `LUCENT_BLESS=1` regenerates the goldens; unset, empty or `0` compares with them (an empty
/// value once blessed a changed golden unnoticed).
fn bless() -> bool {
    std::env::var_os("LUCENT_BLESS").is_some_and(|v| !v.is_empty() && v != "0")
}

/// The golden scenes, small: a few thousand samples, 64–96 pixels.
fn scenes() -> Vec<(&'static str, Scene)> {
    let small = |mut s: Scene, size: u32, samples: u32| {
        s.camera.width = size;
        s.camera.height = size;
        s.render.samples = SampleDensity::Count(samples).into();
        s.render.aa = 2;
        s.render.threads = Some(2);
        s
    };
    let load = |p: &str| load_scene(&root().join(p)).unwrap_or_else(|e| panic!("{e}"));
    vec![
        ("default", small(default_scene(), 96, 4000)),
        (
            "sphere-shadow",
            small(load("scenes/sphere-shadow.toml"), 64, 3000),
        ),
        (
            "textured-mfp",
            small(load("scenes/textured-mfp.toml"), 64, 3000),
        ),
        ("opaque", small(load("tests/data/opaque.toml"), 64, 1000)),
        (
            "rect-light",
            small(load("scenes/rect-light.toml"), 64, 2000),
        ),
        (
            "environment",
            small(load("scenes/environment.toml"), 64, 3000),
        ),
        (
            "obj-materials",
            small(load("scenes/obj-materials.toml"), 64, 3000),
        ),
        (
            "ply-bunny",
            small(load("tests/data/ply-bunny.toml"), 64, 2000),
        ),
        (
            "gltf-egg",
            small(load("tests/data/gltf-egg.toml"), 64, 2000),
        ),
        (
            "textured-kd-jpeg",
            small(load("scenes/textured-kd-jpeg.toml"), 64, 3000),
        ),
        (
            "textured-mfp-exr",
            small(load("scenes/textured-mfp-exr.toml"), 64, 3000),
        ),
    ]
}

/// Triangle id + 1 per sub-sample as 8-bit RGB (0 = empty).
fn coverage_rgb(scene: &Scene) -> (u32, u32, Vec<u8>) {
    let prep = Prepared::new(scene).unwrap();
    let (vb, _) = rasterize(&prep).unwrap();
    let (w, h) = vb.grid_size();
    let rgb = vb
        .triangles()
        .iter()
        .flat_map(|&t| t.wrapping_add(1).to_le_bytes()[..3].to_vec())
        .collect();
    (w, h, rgb)
}

fn close(a: f32, b: f32) -> bool {
    if PINNED {
        a.to_bits() == b.to_bits()
    } else {
        (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) + 1e-7
    }
}

fn compare_rgb(what: &str, got: &[Vec3], want: &[Vec3], exact: bool) {
    assert_eq!(got.len(), want.len(), "{what}: size");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        for c in 0..3 {
            let ok = if exact {
                g[c].to_bits() == w[c].to_bits()
            } else {
                close(g[c], w[c])
            };
            assert!(
                ok,
                "{what}: pixel {i} channel {c}: {} vs golden {}",
                g[c], w[c]
            );
        }
    }
}

/// `image` encoded as the renderer writes it (8-bit sRGB at `exposure` stops) equals the PNG at
/// `want`: byte for byte on the pinned build, within one code per channel elsewhere. Regenerate
/// with `LUCENT_BLESS=1 cargo test -p lucent-tests --test it golden::`.
fn assert_png_matches(what: &str, image: &RgbImage, exposure: f32, want: &Path) {
    // A name of its own for each call: the goldens and the README's pictures share scene
    // names and file names, and their tests run at once in this process (one file for both
    // let the README's check read the other's 64-pixel image).
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let actual = std::env::temp_dir().join(format!(
        "lucent-{what}-{}-{}-{}",
        std::process::id(),
        CALLS.fetch_add(1, Ordering::Relaxed),
        want.file_name().unwrap().to_string_lossy()
    ));
    write_png(&actual, image, exposure).unwrap();
    if PINNED {
        let (got, expected) = (
            std::fs::read(&actual).unwrap(),
            std::fs::read(want).unwrap(),
        );
        assert!(
            got == expected,
            "{what}: PNG bytes differ from {} (actual: {}); regenerate with LUCENT_BLESS=1 cargo \
             test -p lucent-tests --test it golden::",
            want.display(),
            actual.display()
        );
    } else {
        let expected = read_png(want).unwrap();
        let enc = |v: f32| lucent_raster::output::srgb::Srgb8Encoder::new(0.0).encode(v) as i32;
        for (g, w) in image.pixels().iter().zip(expected.pixels()) {
            let g = *g * 2f32.powf(exposure);
            assert!(
                (0..3).all(|c| (enc(g[c]) - enc(w[c])).abs() <= 1),
                "{what}: 8-bit pixel of {} off by more than one code",
                want.display()
            );
        }
    }
    let _ = std::fs::remove_file(&actual);
}

#[test]
fn renders_match_their_goldens() {
    for (name, scene) in scenes() {
        let r = render(&scene, &RenderOptions::default()).unwrap();
        let (cw, ch, coverage) = coverage_rgb(&scene);
        let layers = r.layers(&ExrLayers {
            exitance: true,
            depth: true,
            ..ExrLayers::default()
        });
        let (png, exr, cov) = (
            golden(&format!("{name}.png")),
            golden(&format!("{name}.exr")),
            golden(&format!("{name}.coverage.png")),
        );
        if bless() {
            std::fs::create_dir_all(golden("")).unwrap();
            write_png(&png, &r.image, scene.render.exposure).unwrap();
            write_exr(&exr, &r.image, None, &layers).unwrap();
            write_png_rgb8(&cov, cw, ch, &coverage).unwrap();
            eprintln!("blessed {name}");
            continue;
        }
        let missing = |p: &Path| {
            format!(
                "{} is missing: run LUCENT_BLESS=1 cargo test -p lucent-tests --test it golden::",
                p.display()
            )
        };

        // Coverage: exact (the PNG writer is deterministic, so compare the encoded bytes).
        let want_cov = std::fs::read(&cov).unwrap_or_else(|_| panic!("{}", missing(&cov)));
        let actual =
            std::env::temp_dir().join(format!("lucent-{name}-{}.coverage.png", std::process::id()));
        write_png_rgb8(&actual, cw, ch, &coverage).unwrap();
        let got_cov = std::fs::read(&actual).unwrap();
        assert!(
            got_cov == want_cov,
            "{name}: coverage differs from its golden (actual: {})",
            actual.display()
        );
        let _ = std::fs::remove_file(&actual);

        // The 8-bit image: exact when pinned; elsewhere within one code per channel.
        if !png.exists() {
            panic!("{}", missing(&png));
        }
        assert_png_matches(name, &r.image, scene.render.exposure, &png);

        // Floats: depth exactly, shading exactly when pinned.
        let want_exr = read_exr(&exr).unwrap_or_else(|_| panic!("{}", missing(&exr)));
        compare_rgb(
            &format!("{name} radiance"),
            r.image.pixels(),
            want_exr.beauty.pixels(),
            false,
        );
        for layer in &want_exr.layers {
            match (
                &layer.data,
                layers
                    .iter()
                    .find(|l| l.name == layer.name)
                    .map(|l| &l.data),
            ) {
                (LayerData::Rgb(want), Some(LayerData::Rgb(got))) => {
                    assert_eq!(layer.name, LAYER_EXITANCE);
                    compare_rgb(&format!("{name} exitance"), got, want, false);
                }
                (
                    LayerData::Scalar { values: want, .. },
                    Some(LayerData::Scalar { values: got, .. }),
                ) => {
                    assert_eq!(got.len(), want.len());
                    for (i, (g, w)) in got.iter().zip(want).enumerate() {
                        assert!(
                            g.to_bits() == w.to_bits(),
                            "{name} depth pixel {i}: {g} vs golden {w}"
                        );
                    }
                }
                _ => panic!("{name}: layer {} missing from the render", layer.name),
            }
        }
    }
}

#[test]
fn images_and_baked_samples_are_identical_for_any_thread_count() {
    let dir = std::env::temp_dir().join(format!("lucent-golden-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, mut scene) in scenes() {
        let mut images: Vec<Vec<u32>> = Vec::new();
        let mut baked: Vec<Vec<u8>> = Vec::new();
        for threads in [1, 2, 8, 2] {
            scene.render.threads = Some(threads);
            // Each thread count bakes its own samples and renders from them (a render without
            // `baked` would place and light the same samples a second time).
            let sets = bake(&scene, false).unwrap();
            let options = RenderOptions {
                baked: Some(&sets),
                ..RenderOptions::default()
            };
            let r = render(&scene, &options).unwrap();
            images.push(
                r.pixels
                    .iter()
                    .flat_map(|p| p.color.to_array().into_iter().chain(p.exitance.to_array()))
                    .map(f32::to_bits)
                    .collect(),
            );
            let path = dir.join(format!("{name}-{threads}.ply"));
            let names: Vec<String> = scene.objects.iter().map(|o| o.name.clone()).collect();
            write_baked(&path, &sets, &names, &["golden test".to_string()]).unwrap();
            baked.push(std::fs::read(&path).unwrap());
        }
        for (i, threads) in [2, 8, 2].iter().enumerate() {
            assert!(
                images[i + 1] == images[0],
                "{name}: image with {threads} threads differs from 1 thread"
            );
            assert!(
                baked[i + 1] == baked[0],
                "{name}: baked samples with {threads} threads differ from 1 thread"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Translucent pixels (positive exitance) whose radiance per unit exitance is below what F_t at
/// a grazing 89.9° allows (1.05–1.35% of its value at normal incidence for η from 1.3 to 2.5),
/// relative to the image's median; and how many translucent pixels there are. A pixel on a
/// triangle seen nearly edge-on is legitimately dark (the default scene at 512² has one at
/// 3.3%, about 89.7°); a shading normal facing away once made such pixels 10⁻²⁰ of it.
fn dark_translucent_pixels(exitance: &[Vec3], radiance: &[Vec3]) -> (Vec<usize>, usize) {
    let ratios: Vec<(usize, f32)> = exitance
        .iter()
        .zip(radiance)
        .enumerate()
        .filter(|(_, (m, _))| m.element_sum() > 0.0)
        .map(|(i, (m, l))| (i, l.element_sum() / m.element_sum()))
        .collect();
    let mut sorted: Vec<f32> = ratios.iter().map(|r| r.1).collect();
    sorted.sort_by(f32::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else {
        return (Vec::new(), 0);
    };
    let dark = ratios
        .iter()
        .filter(|r| !(r.1 >= 0.01 * median))
        .map(|r| r.0)
        .collect();
    (dark, ratios.len())
}

/// No translucent pixel of any golden is black or darkened while light leaves the surface
/// there ([`dark_translucent_pixels`]). Shading normals that face away from the camera at
/// silhouettes once made F_t = 0 there.
#[test]
fn goldens_have_no_dark_translucent_pixels() {
    let mut checked = 0;
    for (name, _) in scenes() {
        let path = golden(&format!("{name}.exr"));
        let exr = read_exr(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let Some(exitance) = exr.layers.iter().find_map(|l| match &l.data {
            LayerData::Rgb(v) if l.name == LAYER_EXITANCE => Some(v),
            _ => None,
        }) else {
            panic!("{name}: no exitance layer");
        };
        let (dark, translucent) = dark_translucent_pixels(exitance, exr.beauty.pixels());
        assert!(
            dark.is_empty(),
            "{name}: {} translucent pixels darker than Fresnel allows (first: pixel {})",
            dark.len(),
            dark[0]
        );
        checked += translucent;
    }
    assert!(checked > 1000, "only {checked} translucent pixels checked");
}

/// The README's pictures, `docs/images/<name>.png`: each scene exactly as shipped.
fn readme_scenes() -> Vec<(&'static str, Scene)> {
    let load = |p: &str| load_scene(&root().join(p)).unwrap_or_else(|e| panic!("{e}"));
    vec![
        ("default", default_scene()),
        ("sphere-shadow", load("scenes/sphere-shadow.toml")),
        ("textured-mfp", load("scenes/textured-mfp.toml")),
    ]
}

/// The README's pictures are what the program renders today: `lucent -o
/// docs/images/default.png`, `lucent scenes/sphere-shadow.toml -o docs/images/sphere-shadow.png`
/// and `lucent scenes/textured-mfp.toml -o docs/images/textured-mfp.png` give the same bytes
/// (on the pinned build; within one code per channel elsewhere). `LUCENT_BLESS=1` rewrites them
/// with the goldens.
#[test]
fn readme_images_match_the_renderer() {
    for (name, scene) in readme_scenes() {
        let path = root().join("docs/images").join(format!("{name}.png"));
        let r = render(&scene, &RenderOptions::default()).unwrap();
        let exitance: Vec<Vec3> = r.pixels.iter().map(|p| p.exitance).collect();
        let (dark, translucent) = dark_translucent_pixels(&exitance, r.image.pixels());
        assert!(
            translucent > 10_000,
            "{name}: {translucent} translucent pixels"
        );
        assert!(
            dark.is_empty(),
            "{name}: {} dark translucent pixels at (x, y) {:?}",
            dark.len(),
            dark.iter()
                .map(|&i| (i as u32 % scene.camera.width, i as u32 / scene.camera.width))
                .collect::<Vec<_>>()
        );
        if bless() {
            write_png(&path, &r.image, scene.render.exposure).unwrap();
            eprintln!("rendered {}", path.display());
            continue;
        }
        assert_png_matches(name, &r.image, scene.render.exposure, &path);
    }
}
