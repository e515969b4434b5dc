//! The environment estimators against exact values: π L for a constant sky, a quadrature of
//! the piecewise-constant map for a map, and the sampling density against its own integral.

use std::path::PathBuf;
use std::sync::Arc;

use glam::{DVec3, Vec2, Vec3};

use crate::geometry::Bvh;
use crate::lights::{EnvironmentMap, Lighting};
use crate::sampling::stratified_square;
use crate::scene::Light;
use crate::texture::Texture;

fn map(width: u32, height: u32, texel: impl Fn(u32, u32) -> Vec3) -> Arc<EnvironmentMap> {
    let texels = (0..height)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .map(|(i, j)| texel(i, j))
        .collect();
    let texture = Texture::from_linear(PathBuf::from("test.png"), width, height, texels);
    Arc::new(EnvironmentMap::new(Arc::new(texture)).unwrap())
}

fn env(map: Option<Arc<EnvironmentMap>>, rotation: f32, samples: u32) -> Light {
    Light::Environment {
        color: Vec3::new(1.0, 0.5, 0.25),
        intensity: 2.0,
        map,
        rotation_degrees: rotation,
        samples,
    }
}

fn normals() -> [Vec3; 5] {
    [
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        Vec3::new(0.3, -0.4, 0.8).normalize(),
        Vec3::new(-0.7, 0.1, -0.2).normalize(),
    ]
}

#[test]
fn a_constant_sky_gives_pi_l_exactly() {
    let want = Vec3::new(1.0, 0.5, 0.25) * 2.0 * std::f32::consts::PI;
    for samples in [1, 7, 64] {
        let lights = [env(None, 0.0, samples)];
        let l = Lighting::new(&lights, None, 1.0);
        for n in normals() {
            for seed in 0..20 {
                let e = l.irradiance(Vec3::new(1.0, 2.0, 3.0), n, seed);
                assert!(
                    (e - want).abs().max_element() <= 1e-6 * want.x,
                    "{e} vs {want}"
                );
            }
        }
    }
}

/// A uniform map is a constant sky: the mixture of map and cosine directions is unbiased
/// (its mean over point rotations is π L) and each point's value is close to it.
#[test]
fn a_uniform_map_gives_pi_l() {
    let m = map(16, 8, |_, _| Vec3::splat(0.5));
    let want = 0.5 * 2.0 * std::f64::consts::PI; // texel × intensity × red
    for n in normals() {
        let lights = [env(Some(m.clone()), 10.0, 64)];
        let l = Lighting::new(&lights, None, 1.0);
        let values: Vec<f64> = (0..256)
            .map(|s| l.irradiance(Vec3::ZERO, n, s).x as f64)
            .collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let worst = values
            .iter()
            .map(|e| (e - want).abs() / want)
            .fold(0.0, f64::max);
        eprintln!("uniform map, n {n}: mean/πL {}, worst {worst}", mean / want);
        // 256 points of about 4 % spread each: a standard error near 0.25 %.
        assert!(
            (mean - want).abs() / want < 1e-2,
            "{n}: mean {mean} vs {want}"
        );
        assert!(worst < 0.15, "{n}: worst {worst}");
    }
}

/// A vertical receiver under a sky whose lower half a large plate hides receives π L / 2; the
/// stratified estimate converges to it.
#[test]
fn a_half_hidden_constant_sky_converges_to_half() {
    let plate = [
        [
            Vec3::new(-1e4, -1e4, -0.5),
            Vec3::new(1e4, -1e4, -0.5),
            Vec3::new(1e4, 1e4, -0.5),
        ],
        [
            Vec3::new(-1e4, -1e4, -0.5),
            Vec3::new(1e4, 1e4, -0.5),
            Vec3::new(-1e4, 1e4, -0.5),
        ],
    ];
    let bvh = Bvh::build(&plate);
    let want = std::f64::consts::PI; // × L = 2 (red channel) / 2
    let mut errors = Vec::new();
    for samples in [16, 256, 4096] {
        let lights = [env(None, 0.0, samples)];
        let l = Lighting::new(&lights, Some(&bvh), 1.0);
        let seeds = 16;
        let err: f64 = (0..seeds)
            .map(|s| (l.irradiance(Vec3::ZERO, Vec3::X, s).x as f64 - want).abs() / want)
            .sum();
        errors.push(err / seeds as f64);
    }
    eprintln!("half-hidden sky: mean relative error at N = 16, 256, 4096: {errors:?}");
    assert!(errors[2] < 4e-3, "{errors:?}");
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
}

/// ∫ over texel (i, j) of max(0, n·ω) dω by a 48 × 48 midpoint rule in (φ, cos θ), where dω
/// = dφ d(cos θ), in f64.
fn texel_cosine_integral(i: u32, j: u32, w: u32, h: u32, n: DVec3, rotation: f64) -> f64 {
    let k = 48;
    let (phi0, phi1) = (
        std::f64::consts::TAU * i as f64 / w as f64,
        std::f64::consts::TAU * (i + 1) as f64 / w as f64,
    );
    let (c0, c1) = (
        (std::f64::consts::PI * j as f64 / h as f64).cos(),
        (std::f64::consts::PI * (j + 1) as f64 / h as f64).cos(),
    );
    let cell = (phi1 - phi0) / k as f64 * (c0 - c1) / k as f64;
    let mut sum = 0.0;
    for a in 0..k {
        let phi = phi0 + (phi1 - phi0) * (a as f64 + 0.5) / k as f64 + rotation;
        for b in 0..k {
            let c = c0 + (c1 - c0) * (b as f64 + 0.5) / k as f64;
            let s = (1.0 - c * c).max(0.0).sqrt();
            let d = DVec3::new(s * phi.cos(), s * phi.sin(), c);
            sum += n.dot(d).max(0.0);
        }
    }
    sum * cell
}

/// A map with one bright block (and one with a dim background too), rotated or not, against
/// the quadrature of its piecewise-constant radiance; the error shrinks with the rays.
#[test]
fn a_bright_region_matches_its_quadrature_and_converges() {
    let (w, h) = (16, 8);
    let block = |i: u32, j: u32| (3..6).contains(&i) && (2..4).contains(&j);
    let bright = Vec3::new(4.0, 2.0, 1.0);
    for background in [0.0f32, 0.05] {
        let m = map(w, h, |i, j| {
            if block(i, j) {
                bright
            } else {
                Vec3::splat(background)
            }
        });
        for rotation in [0.0f32, 30.0] {
            for n in normals() {
                let reference: f64 = (0..h)
                    .flat_map(|j| (0..w).map(move |i| (i, j)))
                    .map(|(i, j)| {
                        let l = if block(i, j) {
                            bright.x as f64
                        } else {
                            background as f64
                        };
                        l * texel_cosine_integral(
                            i,
                            j,
                            w,
                            h,
                            n.as_dvec3(),
                            (rotation as f64).to_radians(),
                        )
                    })
                    .sum::<f64>()
                    * 2.0; // intensity × red of color
                if reference < 1e-3 {
                    // The block is below the horizon (and there is no background).
                    let lights = [env(Some(m.clone()), rotation, 64)];
                    let e = Lighting::new(&lights, None, 1.0).irradiance(Vec3::ZERO, n, 1);
                    assert_eq!(e, Vec3::ZERO);
                    continue;
                }
                let mut errors = Vec::new();
                for samples in [16, 256, 4096] {
                    let lights = [env(Some(m.clone()), rotation, samples)];
                    let l = Lighting::new(&lights, None, 1.0);
                    let seeds = 16;
                    let err: f64 = (0..seeds)
                        .map(|s| {
                            let e = l.irradiance(Vec3::ZERO, n, s).x as f64;
                            (e - reference).abs() / reference
                        })
                        .sum();
                    errors.push(err / seeds as f64);
                }
                let what = format!("background {background}, rotation {rotation}, n {n}");
                eprintln!("{what}: mean relative error at N = 16, 256, 4096: {errors:?}");
                // Directions drawn towards the block are wasted for a receiver that faces away from
                // it: the background-only cases converge more slowly.
                assert!(errors[2] < 2e-2, "{what}: {errors:?}");
                assert!(
                    errors[0] > errors[1] && errors[1] > errors[2],
                    "{what}: no convergence {errors:?}"
                );
            }
        }
    }
}

/// The density integrates to 1 over the sphere (a midpoint rule on a grid unrelated to the
/// texels), agrees with the density reported with each sample, and the samples fall in the
/// texels as often as it says.
#[test]
fn the_sampling_density_is_a_density() {
    let (w, h) = (12, 7);
    let m = map(w, h, |i, j| {
        Vec3::new(
            (i * 7 + j * 3) as f32 % 5.0,
            (i + 2 * j) as f32 % 3.0,
            if i == 4 { 9.0 } else { 0.0 },
        )
    });
    assert_eq!(m.validate(), Ok(()));
    let (na, nb) = (1009, 773);
    let mut integral = 0.0f64;
    for a in 0..na {
        let phi = std::f32::consts::TAU * (a as f32 + 0.5) / na as f32;
        for b in 0..nb {
            let c = 1.0 - 2.0 * (b as f32 + 0.5) / nb as f32;
            let s = (1.0 - c * c).max(0.0).sqrt();
            let d = Vec3::new(s * phi.cos(), s * phi.sin(), c);
            integral += m.pdf(d) as f64;
        }
    }
    integral *= std::f64::consts::TAU / na as f64 * 2.0 / nb as f64;
    eprintln!("∫ p dω = {integral}");
    assert!((integral - 1.0).abs() < 2e-3, "∫ p dω = {integral}");

    let n = 1 << 16;
    let mut counts = vec![0u32; (w * h) as usize];
    for u in stratified_square(n, Vec2::ZERO) {
        let s = m.sample(u).unwrap();
        assert!((s.direction.length() - 1.0).abs() < 1e-5);
        let p = m.pdf(s.direction);
        assert!((s.pdf - p).abs() <= 1e-4 * p, "{} vs {p}", s.pdf);
        assert_eq!(s.radiance, m.radiance(s.direction));
        let phi = s
            .direction
            .y
            .atan2(s.direction.x)
            .rem_euclid(std::f32::consts::TAU);
        let i = ((phi / std::f32::consts::TAU * w as f32) as u32).min(w - 1);
        let j = ((s.direction.z.acos() / std::f32::consts::PI * h as f32) as u32).min(h - 1);
        counts[(j * w + i) as usize] += 1;
    }
    let (mut chi2, mut cells) = (0.0f32, 0);
    for j in 0..h {
        let (c0, c1) = (
            (std::f32::consts::PI * j as f32 / h as f32).cos(),
            (std::f32::consts::PI * (j + 1) as f32 / h as f32).cos(),
        );
        let texel_solid_angle = std::f32::consts::TAU / w as f32 * (c0 - c1);
        for i in 0..w {
            let phi = std::f32::consts::TAU * (i as f32 + 0.5) / w as f32;
            let c = 0.5 * (c0 + c1);
            let s = (1.0 - c * c).sqrt();
            let centre = Vec3::new(s * phi.cos(), s * phi.sin(), c);
            let expected = m.pdf(centre) * texel_solid_angle * n as f32;
            let got = counts[(j * w + i) as usize] as f32;
            assert!(
                (got - expected).abs() <= 3.0 * expected.sqrt() + 1.0,
                "texel ({i}, {j}): {got} vs {expected}"
            );
            if expected > 0.0 {
                chi2 += (got - expected).powi(2) / expected;
                cells += 1;
            } else {
                assert_eq!(got, 0.0, "texel ({i}, {j}) has no light");
            }
        }
    }
    // Independent samples would give χ² ≈ the number of cells; stratified ones far less.
    eprintln!("χ² = {chi2} over {cells} cells");
    assert!(chi2 < 0.2 * cells as f32, "χ² = {chi2} over {cells} cells");
}

/// The convention: the top row is +z; a quarter of the way across is +y; `rotation` turns the
/// map counter-clockwise about +z; turning the map is turning the receiver the other way.
#[test]
fn the_lat_long_convention_and_rotation() {
    let (w, h) = (8, 4);
    let top = map(w, h, |_, j| if j == 0 { Vec3::ONE } else { Vec3::ZERO });
    let quarter = map(w, h, |i, j| {
        if i == 2 && (1..3).contains(&j) {
            Vec3::ONE
        } else {
            Vec3::ZERO
        }
    });
    let e = |m: &Arc<EnvironmentMap>, rotation: f32, n: Vec3| {
        let lights = [env(Some(m.clone()), rotation, 256)];
        Lighting::new(&lights, None, 1.0)
            .irradiance(Vec3::ZERO, n, 3)
            .x
    };
    assert!(e(&top, 0.0, Vec3::Z) > 0.1);
    assert_eq!(e(&top, 0.0, -Vec3::Z), 0.0);
    // Column 2 of 8 spans φ ∈ [90°, 135°): light from +y (and a little −x).
    assert!(e(&quarter, 0.0, Vec3::Y) > 0.1);
    assert_eq!(e(&quarter, 0.0, -Vec3::Y), 0.0);
    assert_eq!(e(&quarter, 0.0, Vec3::new(1.0, -0.1, 0.0).normalize()), 0.0);
    // Turned by 90°: from −x.
    assert!(e(&quarter, 90.0, -Vec3::X) > 0.1);
    assert_eq!(e(&quarter, 90.0, Vec3::new(0.1, 1.0, 0.0).normalize()), 0.0);
    // The map's half of the rays turns with it, the cosine half does not: equal up to noise.
    for n in normals() {
        let turned = Vec3::new(-n.y, n.x, n.z); // n turned by +90° about z
        let fine = |rotation: f32, n: Vec3| {
            let lights = [env(Some(quarter.clone()), rotation, 4096)];
            Lighting::new(&lights, None, 1.0)
                .irradiance(Vec3::ZERO, n, 3)
                .x
        };
        let (a, b) = (fine(90.0, turned), fine(0.0, n));
        assert!((a - b).abs() <= 5e-3 * b.max(1e-3), "{n}: {a} vs {b}");
    }
}

#[test]
fn bad_maps_are_refused_and_black_maps_are_dark() {
    let texture =
        |texels: Vec<Vec3>| Arc::new(Texture::from_linear(PathBuf::from("x.png"), 2, 1, texels));
    let err =
        EnvironmentMap::new(texture(vec![Vec3::ONE, Vec3::new(1.0, f32::NAN, 0.0)])).unwrap_err();
    assert!(
        err.contains("column 1, row 0") && err.contains("finite"),
        "{err}"
    );
    let err = EnvironmentMap::new(texture(vec![Vec3::new(0.0, -1.0, 0.0), Vec3::ONE])).unwrap_err();
    assert!(err.contains("column 0, row 0"), "{err}");
    assert!(EnvironmentMap::new(texture(vec![Vec3::ONE])).is_err());
    let black = Arc::new(EnvironmentMap::new(texture(vec![Vec3::ZERO; 2])).unwrap());
    assert!(black.is_black() && black.validate().is_ok());
    let lights = [env(Some(black), 0.0, 16)];
    assert_eq!(
        Lighting::new(&lights, None, 1.0).irradiance(Vec3::ZERO, Vec3::Z, 0),
        Vec3::ZERO
    );
}
