//! Numerical stress at the renderer level: whole scenes at
//! scales 1e-4 … 1e4, tiny and huge translucent objects side by side, mean free paths down
//! to the ℓ → 0 limit. Every pixel of every render must be finite and non-negative; where
//! the physics promises more (scale invariance, E·Rd_total on a lit plane), that is checked
//! too. Scenes are parsed from text and rendered through the library, in memory.
//!
//! Quick tests: `cargo test -p lucent-raster --test it stress::`. The long sweep is ignored:
//!
//! ```text
//! cargo test --release -p lucent-raster --test it stress:: -- --ignored --nocapture
//! ```

use lucent_core::glam::Vec3;
use lucent_raster::render::{self, PixelValue, Render, RenderOptions};
use lucent_raster::scene::{SceneOrigin, parse_scene};

/// A marble-like sphere half in the shadow of a plate, on a translucent floor, lit by a
/// directional light (whose irradiance does not depend on the scene's scale), with every
/// length multiplied by `s`.
fn shadow_scene(s: f32, method: &str, ell: f32, kd: f32, eta: f32, size: u32) -> String {
    let v = |x: f32, y: f32, z: f32| format!("[{:e}, {:e}, {:e}]", x * s, y * s, z * s);
    format!(
        r#"
[camera]
position = {cam}
target = {target}
fov = 30.0
width = {size}
height = {size}

[[object]]
name = "sphere"
shape = "sphere"
radius = {radius:e}
segments = 48
translate = {centre}
material = "stone"

[[object]]
name = "floor"
shape = "plane"
size = [{floor:e}, {floor:e}]
material = "floor"

[[object]]
name = "plate"
shape = "box"
size = {plate}
translate = {plate_at}
material = "grey"

[material.stone]
type = "translucent"
kd = [{kd}, {kd2}, {kd3}]
mean_free_path = {ell:e}
eta = {eta}

[material.floor]
type = "translucent"
kd = 0.5
mean_free_path = {floor_ell:e}
eta = 1.3

[material.grey]
type = "lambert"
albedo = 0.2

[[light]]
type = "directional"
direction = [0.3, 0.4, -1.0]
irradiance = 2.0

[render]
method = "{method}"
samples = 3000
aa = 1
threads = 2
"#,
        cam = v(0.0, -6.0, 2.0),
        target = v(0.0, 0.0, 0.8),
        radius = s,
        centre = v(0.0, 0.0, 1.0),
        floor = 8.0 * s,
        plate = v(3.0, 6.0, 0.05),
        plate_at = v(-1.5, 0.0, 2.7),
        kd2 = kd.powf(0.5),
        kd3 = kd.powf(0.25),
        floor_ell = 0.05 * s,
    )
}

fn render_text(text: &str, options: &RenderOptions) -> Render {
    let origin = SceneOrigin::Embedded {
        name: "stress.toml".into(),
        files: Vec::new(),
    };
    let scene = parse_scene(text, &origin).unwrap_or_else(|e| panic!("{e}\n{text}"));
    render::render(&scene, options).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Every value of every pixel is finite and non-negative (depth may be +∞: no surface).
fn assert_finite(what: &str, r: &Render) {
    for (i, p) in r.pixels.iter().enumerate() {
        for v in [p.color, p.exitance, p.local, p.global, p.irradiance] {
            assert!(
                v.is_finite() && v.min_element() >= 0.0,
                "{what}: pixel {i}: {p:?}"
            );
        }
        assert!(
            !p.depth.is_nan() && p.depth > 0.0,
            "{what}: pixel {i}: {p:?}"
        );
    }
}

/// Per-pixel relative differences of the exitance from `reference` (relative to the larger
/// of the pixel's value and 1 % of the image's peak), sorted.
fn differences(a: &[PixelValue], reference: &[PixelValue]) -> Vec<f32> {
    let peak = reference
        .iter()
        .map(|p| p.exitance.max_element())
        .fold(0.0_f32, f32::max);
    let floor = Vec3::splat(0.01 * peak + 1e-30);
    let mut d: Vec<f32> = a
        .iter()
        .zip(reference)
        .map(|(p, q)| ((p.exitance - q.exitance).abs() / q.exitance.abs().max(floor)).max_element())
        .collect();
    d.sort_by(f32::total_cmp);
    d
}

/// The same scene at other scales (every length × s, irradiance fixed) renders the same
/// exitance, for every method:
///
/// - at power-of-two scales (2^±13 ≈ 1.2e-4 and 8192) every pixel to 1e-6: the pipeline has no
///   hidden absolute length (scaling by 2^k is exact in floating point);
/// - at decimal scales (1e-4, 1e-2, 1e2, 1e4) to 1 % on 99 % of the pixels and 2 % on all (5 %
///   for the unsmoothed sums). The residue is not in the physics but in the sample placement:
///   weighted sample elimination breaks near-ties differently once positions are rounded at
///   another scale, so a few samples of the blue-noise set move (measured: the same 482 + 2518
///   samples, a handful elsewhere). A moved sample also changes its neighbours' Voronoi areas,
///   and the unsmoothed sums (hierarchical, exhaustive) weigh the sample nearest a pixel
///   heavily: measured at 1e4, 99th percentile 1.1e-3, worst 3.8e-2 for them and 1.2e-2 for
///   the split methods; at the other decimal scales at most 2.3e-3. Without
///   `exact_local_integral` the same bounds hold: the scene's materials are uniform, so K is
///   one quadrature per object either way (and the table's nodes sit at ℓ/α = 2^k, scale
///   invariant too).
#[test]
fn rendered_exitance_is_scale_invariant() {
    let size = 32;
    // (method, K by quadrature, allowed 99th percentile and worst at decimal scales)
    let cases = [
        ("exhaustive", false, 0.01, 0.05),
        ("hierarchical", false, 0.01, 0.05),
        ("edge-aware", true, 0.01, 0.02),
        ("local-global", true, 0.01, 0.02),
        ("edge-aware", false, 0.01, 0.02),
    ];
    for (method, exact, p99_allowed, worst_allowed) in cases {
        let options = RenderOptions {
            exact_local_integral: exact,
            ..RenderOptions::default()
        };
        let reference = render_text(&shadow_scene(1.0, method, 0.3, 0.6, 1.4, size), &options);
        assert_finite("scale 1", &reference);
        for s in [1.0 / 8192.0, 8192.0, 1e-4, 1e-2, 1e2, 1e4] {
            let what = format!("{method} (K by quadrature: {exact}) at scale {s:e}");
            let r = render_text(&shadow_scene(s, method, 0.3 * s, 0.6, 1.4, size), &options);
            assert_finite(&what, &r);
            let d = differences(&r.pixels, &reference.pixels);
            let (p99, worst) = (d[d.len() * 99 / 100], d[d.len() - 1]);
            println!("{what}: 99th percentile {p99:.1e}, worst {worst:.1e}");
            if s.log2().fract() == 0.0 {
                assert!(worst <= 1e-6, "{what}: worst pixel differs by {worst}");
            } else {
                assert!(
                    p99 <= p99_allowed && worst <= worst_allowed,
                    "{what}: 99th percentile {p99}, worst {worst}"
                );
            }
        }
    }
}

/// A 1e-4-sized translucent sphere in front of a 1e4-sized translucent wall, one shared set
/// of samples: the sphere (1e-16 of the translucent area) receives no sample at all. Every
/// method renders both, finite; the split methods shade the sphere with their local term,
/// which is the Lambertian E·Rd_total there (α, from the wall's spacing, is 1e7 ℓ_u), and the
/// wall, lit head-on, at E·Rd_total too.
#[test]
fn tiny_and_huge_translucent_objects() {
    let text = |method: &str| {
        format!(
            r#"
[camera]
position = [0.0, -0.001, 0.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
width = 33
height = 33

[[object]]
name = "tiny"
shape = "sphere"
radius = 1e-4
segments = 32
material = "a"

[[object]]
name = "huge"
shape = "plane"
size = [1e4, 1e4]
rotate = [90.0, 0.0, 0.0]
translate = [0.0, 1.0, 0.0]
material = "b"

[material.a]
type = "translucent"
kd = [0.2, 0.5, 0.8]
mean_free_path = 1e-5
eta = 1.3

[material.b]
type = "translucent"
kd = 0.6
mean_free_path = 10.0
eta = 1.3

[[light]]
type = "directional"
direction = [0.0, 1.0, 0.0]
irradiance = 1.5

[render]
method = "{method}"
samples = 500
aa = 1
"#
        )
    };
    for method in ["edge-aware", "local-global", "hierarchical", "exhaustive"] {
        let r = render_text(&text(method), &RenderOptions::default());
        assert_finite(method, &r);
        assert_eq!(r.stats.samples, 500);
        // The centre pixel sees the sphere head-on (normal towards the light), a corner pixel
        // the wall.
        let centre = r.pixels[16 * 33 + 16];
        let corner = r.pixels[0];
        assert!(
            centre.depth < 1e-3 && corner.depth > 0.5,
            "{centre:?} {corner:?}"
        );
        if method == "edge-aware" || method == "local-global" {
            // (Only the split methods evaluate E at the shading point.)
            assert!(
                (centre.irradiance - Vec3::splat(1.5)).abs().max_element() < 0.01,
                "{method}: {centre:?}"
            );
            let want = Vec3::new(0.2, 0.5, 0.8) * 1.5;
            assert!(
                ((centre.exitance - want) / want).abs().max_element() < 0.01,
                "{method}: tiny sphere exitance {} vs E·K_d {want}",
                centre.exitance
            );
            let want = Vec3::splat(0.6 * 1.5);
            assert!(
                ((corner.exitance - want) / want).abs().max_element() < 0.05,
                "{method}: wall exitance {} vs E·K_d {want}",
                corner.exitance
            );
        } else {
            // No samples, no subsurface light: the unsplit methods cannot shade the sphere.
            assert_eq!(centre.exitance, Vec3::ZERO, "{method}");
        }
    }
}

/// A uniformly lit translucent square seen from above: as ℓ_u falls from the sample spacing
/// h to 1e-9 (and the lower limit of the f32 dipole, 2.3e-13), the split methods' exitance in
/// the middle of the square approaches E·Rd_total = E·K_d: within 0.1 % once α/ℓ_u ≥ 1000,
/// smoothly (less than 5 % between ℓ a quarter of a decade apart). The unsplit methods stay
/// finite.
#[test]
fn rendered_plane_reaches_the_lambertian_limit() {
    let text = |method: &str, ell: f32| {
        format!(
            r#"
[camera]
position = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 20.0
width = 24
height = 24

[[object]]
name = "square"
shape = "plane"
size = [4.0, 4.0]
material = "m"

[material.m]
type = "translucent"
kd = [0.3, 0.6, 0.9]
mean_free_path = {ell:e}
eta = 1.4

[[light]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = 2.0

[render]
method = "{method}"
samples = 2000
aa = 1
"#
        )
    };
    let e = 2.0;
    let kd = Vec3::new(0.3, 0.6, 0.9);
    // Mean area per sample Ā = 16/2000; α = 1.5·√Ā ≈ 0.13.
    let alpha = 1.5 * (16.0_f32 / 2000.0).sqrt();
    let interior = |r: &Render| -> Vec3 {
        let mut sum = Vec3::ZERO;
        for y in 8..16 {
            for x in 8..16 {
                sum += r.pixels[y * 24 + x].exitance;
            }
        }
        sum / 64.0
    };
    let mut ells: Vec<f32> = (0..=28)
        .map(|i| 0.01 * 10f32.powf(-i as f32 / 4.0))
        .collect();
    ells.push(2.3e-13);
    for method in ["edge-aware", "local-global"] {
        let mut prev: Option<(f32, Vec3)> = None;
        let mut peak = 0.0_f32;
        for &ell in &ells {
            let r = render_text(&text(method, ell), &RenderOptions::default());
            assert_finite(method, &r);
            let m = interior(&r);
            let err = ((m - kd * e) / (kd * e)).abs().max_element();
            peak = peak.max(err);
            let what = format!("{method} ℓ {ell:e} (α/ℓ = {:.0})", alpha / ell);
            assert!(err < 0.1, "{what}: {m} vs E·K_d {}", kd * e);
            if alpha / ell >= 1000.0 {
                assert!(err < 1e-3, "{what}: {m} vs E·K_d {}", kd * e);
            }
            if let Some((l0, m0)) = prev {
                assert!(
                    ((m - m0) / m0).abs().max_element() < 0.05,
                    "{what}: exitance jumps from {m0} (ℓ {l0:e}) to {m}"
                );
            }
            prev = Some((ell, m));
        }
        println!("{method}: worst interior error {peak:.4} on the way to the ℓ → 0 limit");
    }
    for method in ["hierarchical", "exhaustive"] {
        for ell in [1e-2, 1e-6, 2.3e-13] {
            let r = render_text(&text(method, ell), &RenderOptions::default());
            assert_finite(method, &r);
        }
    }
}

/// The grid at the renderer level: scale 1e-4 … 1e4 × ℓ_u/scale 1e-6 … 1e6 × K_d 0.001 …
/// 0.999 × η 1.0 … 2.5 × every method, on the shadow scene: every pixel finite and
/// non-negative, no error.
#[test]
#[ignore = "long sweep (about a minute in release): cargo test --release -p lucent-raster --test it stress:: -- --ignored"]
fn renderer_parameter_sweep() {
    let start = std::time::Instant::now();
    let mut renders = 0;
    for s in [1e-4_f32, 1e-2, 1.0, 1e2, 1e4] {
        for ell in [1e-6_f32, 1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6] {
            for kd in [0.001, 0.5, 0.999] {
                for eta in [1.0, 2.5] {
                    for method in ["hierarchical", "local-global", "edge-aware", "exhaustive"] {
                        let what = format!("scale {s:e} ℓ {ell:e}·s K_d {kd} η {eta} {method}");
                        let r = render_text(
                            &shadow_scene(s, method, ell * s, kd, eta, 24),
                            &RenderOptions::default(),
                        );
                        assert_finite(&what, &r);
                        renders += 1;
                    }
                }
            }
        }
    }
    println!(
        "{renders} renders in {:.1} s, all finite",
        start.elapsed().as_secs_f64()
    );
}
