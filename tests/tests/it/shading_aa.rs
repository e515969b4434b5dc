//! Shading antialiasing, end to end: a hard shadow edge across a translucent plane whose mean
//! free path is far below a pixel, at `aa = 4`, against a 16× supersampled render of the same
//! scene (4× the resolution at `aa = 1`, averaged over 4 × 4 blocks: every sub-sample of the
//! `aa = 4` grid shaded at its own position, the same grid, since both rasterise at 1/256 of
//! a sub-sample).
//!
//! - In the pixels the edge crosses, the error against that reference falls to at most ¼ of
//!   coverage-only antialiasing's (one shading point per pixel);
//! - every such pixel is shaded again at exactly two points (lit and shadowed), every other
//!   pixel once, with the same bits as without shading antialiasing;
//! - the same at a texture edge (a K_d step far sharper than a pixel);
//! - a scene without an edge shades once per pixel and gives the same bits as without it;
//! - the image is the same for 1, 2 and 8 threads.

use std::borrow::Cow;

use lucent_core::glam::Vec3;
use lucent_raster::output::png::write_png_rgb8;
use lucent_raster::render::{Render, RenderOptions, render};
use lucent_raster::scene::{Scene, SceneOrigin, parse_scene};

/// Pixels per side of the `aa = 4` image.
const SIZE: u32 = 48;

/// A 4 × 4 translucent plane at z = 0 (ℓ_u = 0.001, ℓ_d ≈ 0.002, a pixel ≈ 0.023), rendered
/// with LM07's split, whose local term E(x)·K keeps the edge as hard as the light's when the
/// samples are far sparser than ℓ_d. The camera looks straight down from z = 1.5; a directional
/// light shines straight down past a plate at z = 3 (behind the camera), rotated 20° about z,
/// so its shadow edge is the line through the origin at 20° to the image's columns.
fn edge_scene(occluder: bool, size: u32, aa: u32, threads: usize) -> Scene {
    let plate = if occluder {
        let (c, s) = (20f32.to_radians().cos(), 20f32.to_radians().sin());
        format!(
            r#"
[[object]]
name = "plate"
shape = "box"
size = [60.0, 60.0, 0.1]
rotate = [0.0, 0.0, 20.0]
translate = [{}, {}, 3.0]
material = "black"

[material.black]
type = "lambert"
albedo = 0.0
"#,
            -30.0 * c,
            -30.0 * s
        )
    } else {
        String::new()
    };
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, 1.5]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0
width = {size}
height = {size}

[[object]]
name = "slab"
shape = "plane"
size = [4.0, 4.0]
material = "wax"

[material.wax]
type = "translucent"
kd = [0.8, 0.6, 0.4]
mean_free_path = 0.001
eta = 1.3
{plate}
[[light]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = 2.0

[render]
method = "local-global"
samples = 2000
aa = {aa}
threads = {threads}
"#
    );
    parse_scene(
        &text,
        &SceneOrigin::Embedded {
            name: "edge.toml".into(),
            files: Vec::new(),
        },
    )
    .expect("test scene parses")
}

fn run(scene: &Scene, shade_once: bool) -> Render {
    render(
        scene,
        &RenderOptions {
            shade_once,
            ..RenderOptions::default()
        },
    )
    .expect("renders")
}

fn bits(r: &Render) -> Vec<u32> {
    r.pixels
        .iter()
        .flat_map(|p| {
            [p.color, p.exitance, p.local, p.global, p.irradiance]
                .into_iter()
                .flat_map(|v| v.to_array())
                .chain([p.depth])
        })
        .map(f32::to_bits)
        .collect()
}

/// The 16× reference, averaged per pixel (radiance), and per pixel whether its 16 sub-pixels
/// are both lit (E > 0) and shadowed: the pixels the edge crosses.
fn reference() -> (Vec<Vec3>, Vec<bool>) {
    let hi = run(&edge_scene(true, SIZE * 4, 1, 2), false);
    assert_eq!(hi.stats.refined_pixels, 0, "aa = 1 has nothing to refine");
    let n = SIZE as usize;
    let mut mean = vec![Vec3::ZERO; n * n];
    let mut edge = vec![false; n * n];
    for y in 0..n {
        for x in 0..n {
            let (mut lit, mut dark) = (false, false);
            for j in 0..4 {
                for i in 0..4 {
                    let p = &hi.pixels[(4 * y + j) * 4 * n + 4 * x + i];
                    mean[y * n + x] += p.color / 16.0;
                    if p.irradiance.x > 0.0 {
                        lit = true;
                    } else {
                        dark = true;
                    }
                }
            }
            edge[y * n + x] = lit && dark;
        }
    }
    (mean, edge)
}

/// RMSE of the radiance over the `edge` pixels, relative to the lit radiance.
fn edge_error(r: &Render, reference: &[Vec3], edge: &[bool], lit: f32) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for ((p, want), _) in r
        .pixels
        .iter()
        .zip(reference)
        .zip(edge)
        .filter(|(_, e)| **e)
    {
        let d = (p.color - *want) / lit;
        sum += f64::from(d.length_squared()) / 3.0;
        n += 1;
    }
    (sum / n as f64).sqrt()
}

#[test]
fn a_hard_shadow_edge_converges_to_the_supersampled_reference() {
    let (reference, edge) = reference();
    let crossed = edge.iter().filter(|&&e| e).count();
    // A line across a 48-pixel square at 20° to its columns passes through about
    // 48 (1 + tan 20°) = 65 pixels, fewer of which have sub-sample centres on both sides.
    assert!((40..=70).contains(&crossed), "{crossed} pixels on the edge");

    let scene = edge_scene(true, SIZE, 4, 2);
    let once = run(&scene, true);
    let adaptive = run(&scene, false);
    let lit = once.pixels.iter().map(|p| p.color.x).fold(0.0f32, f32::max);
    assert!(lit > 0.1, "the lit side is lit: {lit}");
    let before = edge_error(&once, &reference, &edge, lit);
    let after = edge_error(&adaptive, &reference, &edge, lit);
    eprintln!(
        "edge pixels {crossed}: relative RMSE against the 16x reference, one point per pixel \
         {before:.5}, adaptive {after:.5} (ratio {:.4})",
        after / before
    );
    // Coverage-only shading puts each edge pixel wholly on one side: an error of about √(1/12)
    // of the step on average. The adaptive pass weights each side by its exact sub-sample
    // coverage.
    assert!(before > 0.15, "the stair-steps are visible: {before}");
    assert!(after <= 0.25 * before, "{after} vs {before}");

    // Exactly the edge's pixels are shaded again, at two points each (the pass re-shades the
    // representative's side too), and every other pixel keeps its first-pass bits.
    let pixels = u64::from(SIZE * SIZE);
    assert_eq!(adaptive.stats.refined_pixels, crossed as u64);
    assert_eq!(adaptive.stats.shading_points, pixels + 2 * crossed as u64);
    assert_eq!(adaptive.stats.queries, pixels + 2 * crossed as u64);
    assert_eq!(once.stats.queries, pixels);
    assert_eq!(once.stats.probes, 0);
    assert!(adaptive.stats.probes >= 16 * crossed as u64);
    let (a, o) = (bits(&adaptive), bits(&once));
    let per_pixel = a.len() / edge.len();
    for (k, e) in edge.iter().enumerate() {
        let range = k * per_pixel..(k + 1) * per_pixel;
        if *e {
            assert_ne!(a[range.clone()], o[range], "edge pixel {k} unchanged");
        } else {
            assert_eq!(a[range.clone()], o[range], "pixel {k} off the edge changed");
        }
    }
    // Every layer is resolved the same way: radiance stays the `docs/physics.md` §17 conversion of exitance
    // (normal incidence here to within 0.1%), local + global = exitance.
    for p in &adaptive.pixels {
        assert!((p.local + p.global - p.exitance).abs().max_element() <= 1e-5 * lit.max(1.0));
    }
}

#[test]
fn a_scene_without_edges_shades_once_per_pixel_with_the_same_bits() {
    let scene = edge_scene(false, SIZE, 4, 2);
    let adaptive = run(&scene, false);
    let once = run(&scene, true);
    let pixels = u64::from(SIZE * SIZE);
    assert_eq!(adaptive.stats.queries, pixels);
    assert_eq!(adaptive.stats.shading_points, pixels);
    assert_eq!(adaptive.stats.refined_pixels, 0);
    assert_eq!(bits(&adaptive), bits(&once));
}

#[test]
fn the_refined_image_is_the_same_for_any_thread_count() {
    let one = run(&edge_scene(true, SIZE, 4, 1), false);
    assert!(
        one.stats.refined_pixels > 40,
        "{}",
        one.stats.refined_pixels
    );
    for threads in [2, 8] {
        let other = run(&edge_scene(true, SIZE, 4, threads), false);
        assert!(
            bits(&one) == bits(&other),
            "{threads} threads differ from 1"
        );
        assert_eq!(one.stats.probes, other.stats.probes);
    }
}

/// A K_d texture 1024 texels wide: dark (sRGB 60) on the left half, bright (230) on the right,
/// on the plane of [`edge_scene`] rotated 20° about z and lit without shadows: the step is
/// a straight line at 20° to the columns, a fifth of a pixel wide after bilinear filtering.
fn texture_scene(size: u32, aa: u32) -> Scene {
    let dir = std::env::temp_dir().join(format!("lucent-shading-aa-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("kd-{size}-{aa}.png"));
    let rgb: Vec<u8> = (0..1024)
        .flat_map(|i| [if i < 512 { 60u8 } else { 230 }; 3])
        .collect();
    write_png_rgb8(&path, 1024, 1, &rgb).unwrap();
    let png = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let text = format!(
        r#"
[camera]
position = [0.0, 0.0, 1.5]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 40.0
width = {size}
height = {size}

[[object]]
name = "slab"
shape = "plane"
size = [4.0, 4.0]
rotate = [0.0, 0.0, 20.0]
material = "wax"

[material.wax]
type = "translucent"
kd = {{ texture = "kd.png" }}
mean_free_path = 0.001
eta = 1.3

[[light]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = 2.0

[render]
method = "local-global"
samples = 2000
aa = {aa}
threads = 2
"#
    );
    parse_scene(
        &text,
        &SceneOrigin::Embedded {
            name: "texture.toml".into(),
            files: vec![("kd.png".into(), Cow::Owned(png))],
        },
    )
    .expect("test scene parses")
}

#[test]
fn a_sharp_texture_edge_converges_to_the_supersampled_reference() {
    let hi = run(&texture_scene(SIZE * 4, 1), false);
    let n = SIZE as usize;
    let mut reference = vec![Vec3::ZERO; n * n];
    let mut edge = vec![false; n * n];
    let lit = hi.pixels.iter().map(|p| p.color.x).fold(0.0f32, f32::max);
    for y in 0..n {
        for x in 0..n {
            let (mut lo, mut up) = (f32::INFINITY, 0.0f32);
            for j in 0..4 {
                for i in 0..4 {
                    let c = hi.pixels[(4 * y + j) * 4 * n + 4 * x + i].color;
                    reference[y * n + x] += c / 16.0;
                    lo = lo.min(c.x);
                    up = up.max(c.x);
                }
            }
            edge[y * n + x] = up - lo > 0.25 * lit;
        }
    }
    let crossed = edge.iter().filter(|&&e| e).count();
    assert!((40..=70).contains(&crossed), "{crossed} pixels on the edge");
    let scene = texture_scene(SIZE, 4);
    let once = run(&scene, true);
    let adaptive = run(&scene, false);
    let before = edge_error(&once, &reference, &edge, lit);
    let after = edge_error(&adaptive, &reference, &edge, lit);
    eprintln!(
        "texture edge pixels {crossed}: relative RMSE one point per pixel {before:.5}, \
         adaptive {after:.5} (ratio {:.4})",
        after / before
    );
    assert!(before > 0.1, "the stair-steps are visible: {before}");
    assert!(after <= 0.25 * before, "{after} vs {before}");
    assert!(adaptive.stats.refined_pixels >= crossed as u64);
}
