//! Values out of range, NaN and infinities, per table.

use super::*;

use SceneErrorKind::OutOfRange as R;
use glam::Vec3;

#[test]
fn camera_values() {
    let cam = |extra: &str| edit("fov = 30", &format!("fov = 30\n{extra}"));
    expect_all! { R;
        edit("fov = 30", "fov = 0") => "fov = 0", "camera.fov", "(0, 180)";
        edit("fov = 30", "fov = 180") => "fov = 180", "camera.fov", "(0, 180)";
        edit("fov = 30", "fov = nan") => "fov = nan", "camera.fov", "finite";
        edit("fov = 30", "fov = -inf") => "fov = -inf", "camera.fov", "finite";
        edit("fov = 30", "fov = 1e300") => "fov = 1e300", "camera.fov", "too large";
        cam("width = 0") => "width = 0", "camera.width", "1..=16384";
        cam("height = 16385") => "height", "camera.height", "1..=16384";
        cam("width = 10000\nheight = 10000") => "height = 10000", "camera.height", "pixels";
        edit("target = [0, 0, 0.5]", "target = [0, -5, 1]") => "target", "camera.target", "differ";
        cam("up = [0, 10, -1]") => "up = ", "camera.up", "parallel";
        cam("up = [0, 0, 0]") => "up = ", "camera.up", "zero";
        edit("position = [0, -5, 1]", "position = [0, -inf, 1]") => "position", "camera.position", "finite";
    }
}

#[test]
fn object_values() {
    let sphere = |extra: &str| edit("radius = 1", &format!("radius = 1\n{extra}"));
    expect_all! { R;
        edit("radius = 1", "radius = -1") => "radius = -1", "object[0].radius", "greater than 0";
        sphere("segments = 2") => "segments", "object[0].segments", "3..=4096";
        sphere("segments = 5000") => "segments", "object[0].segments", "3..=4096";
        sphere("scale = 0") => "scale", "object[0].scale", "greater than 0";
        // Underflows to 0 as an f32.
        sphere("scale = 1e-46") => "scale", "object[0].scale", "greater than 0";
        sphere("rotate = [0, nan, 0]") => "rotate", "object[0].rotate", "finite";
        sphere("translate = [1e39, 0, 0]") => "translate", "object[0].translate", "finite";
        sphere("name = ' '") => "name", "object[0].name", "empty";
        edit("shape = \"sphere\"\nradius = 1", "shape = 'box'\nsize = [1, 0, 1]") => "size", "object[0].size", "greater than 0";
    }
}

#[test]
fn material_values() {
    let coeffs = |sa: &str, ss: &str, eta: &str| {
        edit(
            PRESET,
            &format!("sigma_a = {sa}\nsigma_s_prime = {ss}\neta = {eta}"),
        )
    };
    let artist = |kd: &str, d: &str| edit(PRESET, &format!("kd = {kd}\n{d}\neta = 1.3"));
    let dtex = "diffuse_mean_free_path = { texture = 'ramp.png', min = -1, max = 2 }";
    let lambert = |albedo: &str| {
        edit(
            "type = \"translucent\"\npreset = \"marble\"\nmm_per_unit = 10",
            &format!("type = 'lambert'\nalbedo = {albedo}"),
        )
    };
    expect_all! { R;
        edit("mm_per_unit = 10", "mm_per_unit = 0") => "mm_per_unit", "material.m.mm_per_unit", "greater than 0";
        coeffs("[0.1, 0, 0.1]", "1", "1.3") => "sigma_a", "material.m.sigma_a", "greater than 0";
        coeffs("0.1", "-2", "1.3") => "sigma_s_prime", "material.m.sigma_s_prime", "greater than 0";
        coeffs("0.1", "2", "0.9") => "eta", "material.m.eta", "between 1 and 3";
        coeffs("0.1", "2", "3.5") => "eta", "material.m.eta", "between 1 and 3";
        coeffs("0.1", "inf", "1.3") => "sigma_s_prime", "material.m.sigma_s_prime", "finite";
        coeffs("0.1", "2", "nan") => "eta", "material.m.eta", "finite";
        artist("[0.5, 1.0, 0.5]", "mean_free_path = 1") => "kd", "material.m.kd", "strictly between 0 and 1";
        artist("0", "mean_free_path = 1") => "kd", "material.m.kd", "strictly between";
        artist("0.5", "mean_free_path = [1, 0, 1]") => "mean_free_path", "material.m.mean_free_path", "greater than 0";
        artist("0.5", dtex) => "diffuse_mean_free_path", "material.m.diffuse_mean_free_path.min", "greater than 0";
        edit("mm_per_unit = 10", "mm_per_unit = 10\nspecular = { exponent = 0 }")
            => "specular", "material.m.specular.exponent", "greater than 0";
        edit("mm_per_unit = 10", "mm_per_unit = 10\nspecular = { exponent = 9, strength = -1 }")
            => "specular", "material.m.specular.strength", "at least 0";
        lambert("1.5") => "albedo", "material.m.albedo", "[0, 1]";
        // Valid numbers that put the dipole outside f32: the key and the value as written.
        edit("mm_per_unit = 10", "mm_per_unit = 1e20")
            => "mm_per_unit = 1e20", "material.m.mm_per_unit", "1e20 is out of range for preset `marble`";
        coeffs("1e30", "1e30", "1.3") => "sigma_a", "material.m.sigma_a", "1e30 (with sigma_s_prime = 1e30) is out of range";
        artist("0.5", "mean_free_path = 1e-30")
            => "mean_free_path", "material.m.mean_free_path", "1e-30 is out of range with kd = 0.5";
        artist("0.5", "radius = [1, 0, 1]") => "radius = [", "material.m.radius", "greater than 0";
        artist("0.5", "radius = 0.7\nradius_scale = 0") => "radius_scale", "material.m.radius_scale", "greater than 0";
        artist("0.5", "radius = 0.7\nradius_scale = nan") => "radius_scale", "material.m.radius_scale", "finite";
        artist("0.5", "radius = 1e30\nradius_scale = 1e30")
            => "radius_scale", "material.m.radius_scale", "not a positive single-precision distance";
        artist("0.5", "radius = { texture = 'ramp.png', min = 1e-30, max = 1 }\nradius_scale = 1e-20")
            => "radius_scale", "material.m.radius_scale", "not a positive single-precision distance";
        artist("0.5", "radius = { texture = 'ramp.png', min = 0, max = 1 }")
            => "radius = {", "material.m.radius.min", "greater than 0";
        artist("0.5", "radius = 1e-30\nprofile = 'burley'")
            => "radius = 1e-30", "material.m.radius", "1e-30 is out of range with kd = 0.5";
    }
}

#[test]
fn light_values() {
    let point = |extra: &str| edit("intensity = 20", &format!("intensity = 20\n{extra}"));
    let spot = |inner: &str, outer: &str, dir: &str| {
        edit(
            "type = \"point\"",
            &format!(
                "type = \"spot\"\ndirection = {dir}\ninner_angle = {inner}\nouter_angle = {outer}"
            ),
        )
    };
    let sphere = |extra: &str| {
        edit(
            "type = \"point\"\nposition = [0, -3, 5]",
            &format!("type = 'sphere'\ncenter = [0, -3, 5]\n{extra}"),
        )
    };
    let directional = edit(
        "type = \"point\"\nposition = [0, -3, 5]\nintensity = 20",
        "type = 'directional'\ndirection = [0, 0, -1]\nirradiance = -2",
    );
    expect_all! { R;
        edit("intensity = 20", "intensity = -1") => "intensity", "light[0].intensity", "at least 0";
        edit("intensity = 20", "intensity = inf") => "intensity", "light[0].intensity", "finite";
        point("color = [1, nan, 1]") => "color", "light[0].color", "finite";
        point("color = -1") => "color", "light[0].color", "at least 0";
        spot("30", "20", "[0, 0, -1]") => "inner_angle", "light[0].inner_angle", "outer_angle";
        spot("10", "180", "[0, 0, -1]") => "outer_angle", "light[0].outer_angle", "(0, 180)";
        spot("10", "20", "[0, 0, 0]") => "direction", "light[0].direction", "zero";
        sphere("radius = 0") => "radius = 0", "light[0].radius", "greater than 0";
        sphere("radius = 1\nsamples = 0") => "samples", "light[0].samples", "1..=4096";
        directional => "irradiance", "light[0].irradiance", "at least 0";
    }
}

/// The rect light `extra` lines (a complete one unless they say otherwise), in place of the
/// point light.
fn rect(extra: &str) -> String {
    edit(
        "type = \"point\"",
        &format!("type = 'rect'\ndirection = [0, 0, -1]\n{extra}"),
    )
}

/// An environment light with `extra` lines, in place of the point light.
fn environment(extra: &str) -> String {
    edit(
        "type = \"point\"\nposition = [0, -3, 5]\nintensity = 20",
        &format!("type = 'environment'\n{extra}"),
    )
}

#[test]
fn rect_and_environment_values() {
    expect_all! { R;
        rect("size = [1, 0]") => "size", "light[0].size", "greater than 0";
        rect("size = [-1, 2]") => "size", "light[0].size", "greater than 0";
        rect("size = 0") => "size", "light[0].size", "greater than 0";
        // Each side is a float, the area underflows: a zero-area rectangle.
        rect("size = [1e-30, 1e-30]") => "size", "light[0].size", "area";
        rect("size = [1, nan]") => "size", "light[0].size", "finite";
        rect("size = [1, 1]\nup = [0, 0, 2]") => "up", "light[0].up", "parallel to `direction`";
        rect("size = [1, 1]\nup = [0, 0, 0]") => "up", "light[0].up", "zero";
        rect("size = [1, 1]\nsamples = 5000") => "samples", "light[0].samples", "1..=4096";
        edit("intensity = 20", "intensity = -3").replace("type = \"point\"", "type = 'rect'\ndirection = [0, 0, -1]\nsize = 1")
            => "intensity", "light[0].intensity", "at least 0";
        edit("intensity = 20", "intensity = nan").replace("type = \"point\"", "type = 'rect'\ndirection = [0, 0, -1]\nsize = 1")
            => "intensity", "light[0].intensity", "finite";
        environment("intensity = -1") => "intensity", "light[0].intensity", "at least 0";
        environment("intensity = nan") => "intensity", "light[0].intensity", "finite";
        environment("intensity = 1\ncolor = [1, -0.5, 1]") => "color", "light[0].color", "at least 0";
        environment("intensity = 1\nrotation = inf") => "rotation", "light[0].rotation", "finite";
        environment("intensity = 1\nrotation = 400") => "rotation", "light[0].rotation", "[-360, 360]";
        environment("intensity = 1\nsamples = 0") => "samples", "light[0].samples", "1..=4096";
    }
    expect_all! { SceneErrorKind::WrongType;
        rect("size = [1, 2, 3]") => "size", "light[0].size", "array of 2 numbers";
    }
    expect_all! { SceneErrorKind::MissingKey;
        rect("") => "[[light]]", "light[0].size", "a rect light";
        environment("map = 'ramp.png'") => "[[light]]", "light[0].intensity", "an environment light";
    }
    expect_all! { SceneErrorKind::Conflict;
        rect("size = 1\nradius = 2") => "radius = 2", "light[0].radius", "a rect light";
        environment("intensity = 1\nposition = [0, 0, 1]") => "position = [0, 0, 1]", "light[0].position", "an environment light";
        environment("intensity = 1\nsize = [1, 1]") => "size = [1, 1]", "light[0].size", "an environment light";
        edit("intensity = 20", "intensity = 20\nmap = 'ramp.png'") => "map", "light[0].map", "a point light";
    }
    expect_all! { SceneErrorKind::Io;
        environment("intensity = 1\nmap = 'nothere.png'") => "nothere.png", "light[0].map", "cannot read texture";
    }
    expect_all! { SceneErrorKind::Texture;
        environment("intensity = 1\nmap = 'bad.png'") => "bad.png", "light[0].map", "bad.png";
    }
}

#[test]
fn rect_and_environment_lights_load() {
    let s = load(&rect("size = [2, 0.5]\nsamples = 9")).unwrap();
    match &s.lights[..] {
        [
            Light::Rect {
                center,
                normal,
                right,
                up_axis,
                size,
                intensity,
                samples,
                ..
            },
        ] => {
            assert_eq!(*center, Vec3::new(0.0, -3.0, 5.0));
            assert_eq!(*normal, -Vec3::Z);
            // Facing straight down: height along +y, width along y × (−z) = −x.
            assert_eq!((*up_axis, *right), (Vec3::Y, -Vec3::X));
            assert_eq!(*size, glam::Vec2::new(2.0, 0.5));
            assert_eq!((*intensity, *samples), (20.0, 9));
        }
        other => panic!("{other:?}"),
    }
    let s = load(&environment("intensity = 0.5\ncolor = [1, 0.5, 0.25]")).unwrap();
    assert!(matches!(
        &s.lights[..],
        [Light::Environment { map: None, samples: 64, rotation_degrees: 0.0, intensity: 0.5, color, .. }]
            if *color == Vec3::new(1.0, 0.5, 0.25)
    ));
    let s = load(&environment(
        "intensity = 2\nmap = 'ramp.png'\nrotation = -90",
    ))
    .unwrap();
    match &s.lights[..] {
        [
            Light::Environment {
                map: Some(map),
                rotation_degrees,
                ..
            },
        ] => {
            assert_eq!(*rotation_degrees, -90.0);
            assert_eq!((map.texture().width, map.texture().height), (8, 1));
            assert_eq!(map.validate(), Ok(()));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn render_and_output_values() {
    let render = |line: &str| append(&format!("[render]\n{line}\n"));
    expect_all! { R;
        render("aa = 0") => "aa", "render.aa", "1..=8";
        render("aa = 9") => "aa", "render.aa", "1..=8";
        render("samples = 0") => "samples", "render.samples", "1..=33554432 or \"auto\" (got 0)";
        render("samples = -7") => "samples", "render.samples", "(got -7)";
        render("samples = 100000000") => "samples", "render.samples", "1..=";
        render("samples = 33554433") => "samples", "render.samples", "(got 33554433)";
        render("samples = 'lots'") => "samples", "render.samples", "`lots` is not a sample count";
        render("samples = 'Auto'") => "samples", "render.samples", "or \"auto\"";
        render("max_samples = 0") => "max_samples", "render.max_samples", "1..=33554432";
        render("max_samples = 40000000") => "max_samples", "render.max_samples", "1..=33554432";
        render("epsilon = -0.1") => "epsilon", "render.epsilon", "at least 0";
        render("cull_tolerance = 1") => "cull_tolerance", "render.cull_tolerance", "[0, 1)";
        render("interpolation = 0") => "interpolation", "render.interpolation", "1..=16";
        render("interpolation = 17") => "interpolation", "render.interpolation", "(got 17)";
        render("interpolation_tolerance = -0.5") => "interpolation_tolerance", "render.interpolation_tolerance", "at least 0";
        render("interpolation_tolerance = inf") => "interpolation_tolerance", "render.interpolation_tolerance", "finite";
        render("ell_min = 0") => "ell_min", "render.ell_min", "greater than 0";
        render("exposure = 100") => "exposure", "render.exposure", "stops";
        render("threads = 0") => "threads", "render.threads", "1..=";
        render("seed = -1") => "seed", "render.seed", "0..=";
        render("smoothing = nan") => "smoothing", "render.smoothing", "finite";
        // A sphere of area 4π with samples 1e-4 apart: up to 1.45e9 samples.
        render("spacing = 1e-4") => "spacing", "render.spacing", "units";
        append("[output]\npng = ''\n") => "png", "output.png", "empty";
    }
}

#[test]
fn sample_counts_parse() {
    let render = |line: &str| {
        load(&append(&format!("[render]\n{line}\n")))
            .unwrap()
            .render
    };
    // The default, absent or spelled out.
    assert_eq!(load(BASE).unwrap().render.samples, SampleRequest::Auto);
    assert_eq!(render("samples = 'auto'").samples, SampleRequest::Auto);
    assert_eq!(render("samples = 'auto'").max_samples, None);
    assert_eq!(
        render("samples = 'auto'\nmax_samples = 5000").max_samples,
        Some(5000)
    );
    assert_eq!(render("max_samples = 33554432").max_samples, Some(1 << 25));
    assert_eq!(
        render("samples = 1").samples,
        SampleRequest::Density(SampleDensity::Count(1))
    );
    assert_eq!(
        render("samples = 33554432").samples,
        SampleRequest::Density(SampleDensity::Count(1 << 25))
    );
    assert_eq!(
        render("spacing = 0.5").samples,
        SampleRequest::Density(SampleDensity::Spacing(0.5))
    );
}

#[test]
fn sample_count_conflicts_and_types() {
    let render = |line: &str| append(&format!("[render]\n{line}\n"));
    expect_all! { SceneErrorKind::Conflict;
        render("samples = 100\nmax_samples = 5000") => "max_samples", "render.max_samples", "gives `samples`";
        render("spacing = 0.5\nmax_samples = 5000") => "max_samples", "render.max_samples", "gives `spacing`";
        render("samples = 'auto'\nspacing = 0.5") => "spacing", "render.spacing", "cannot be combined";
    }
    expect_all! { SceneErrorKind::WrongType;
        render("samples = 1.5") => "samples", "render.samples", "an integer) or \"auto\"";
        render("samples = true") => "samples", "render.samples", "an integer) or \"auto\"";
        render("max_samples = 'auto'") => "max_samples", "render.max_samples", "invalid type";
    }
}
