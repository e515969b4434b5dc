//! Syntax, unknown keys, wrong types and missing keys.

use super::*;

#[test]
fn toml_syntax_errors() {
    use SceneErrorKind::Syntax;
    let e = load("[camera\nfov = 3").expect_err("syntax");
    assert_eq!((e.kind, e.position), (Syntax, Some((1, 8))), "{e}");
    assert!(
        e.to_string().starts_with("t.toml:1:8: TOML syntax error"),
        "{e}"
    );
    let e = load(&edit("fov = 30", "fov = 3 0")).expect_err("syntax");
    assert_eq!((e.kind, e.position.map(|p| p.0)), (Syntax, Some(4)), "{e}");
    // A second [camera] table (line 21 of the text).
    let e = load(&append("\n[camera]\nfov = 3\n")).expect_err("duplicate table");
    assert_eq!((e.kind, e.position.map(|p| p.0)), (Syntax, Some(21)), "{e}");
}

#[test]
fn unknown_keys() {
    let texture_kd = "kd = { texture = 'ramp.png', mn = 1 }\nmean_free_path = 1\neta = 1.3";
    let second = "[[object]]\nshape = 'sphere'\nradius = 1\nmaterial = 'm'\nfoo = 1\n";
    expect_all! { SceneErrorKind::UnknownKey;
        append("colour = 1\n") => "colour", "light[0].colour", "unknown key";
        edit("fov = 30", "fov = 30\nfocal = 2") => "focal", "camera.focal", "expected one of";
        edit("radius = 1", "radius = 1\nradious = 2") => "radious", "object[0].radious", "unknown key";
        edit("mm_per_unit = 10", "mm_per_unit = 10\nsigma = 1") => "sigma", "material.m.sigma", "unknown key";
        append("[render]\nsample = 3\n") => "sample", "render.sample", "unknown key";
        append("[output]\njpg = 'a.jpg'\n") => "jpg", "output.jpg", "unknown key";
        format!("scale = 2\n{BASE}") => "scale", "scale", "unknown key";
        edit(PRESET, "preset = 'marble'\nmm_per_unit = 10\nspecular = { exponent = 2, power = 1 }")
            => "power", "material.m.specular.power", "unknown key";
        edit(PRESET, texture_kd) => "mn = 1", "material.m.kd.mn", "unknown key";
        append(second) => "foo", "object[1].foo", "unknown key";
    }
}

#[test]
fn wrong_types() {
    let artist = |kd: &str| edit(PRESET, &format!("kd = {kd}\nmean_free_path = 1\neta = 1.3"));
    expect_all! { SceneErrorKind::WrongType;
        edit("fov = 30", "fov = \"wide\"") => "wide", "camera.fov", "invalid type";
        edit("fov = 30", "fov = 30\nwidth = 512.5") => "width", "camera.width", "invalid type";
        edit("position = [0, -5, 1]", "position = [0, -5]") => "[0, -5]", "camera.position", "array of 3";
        edit("position = [0, -5, 1]", "position = [0, -5, 1, 1]") => "[0, -5, 1, 1]", "camera.position", "array of 3";
        edit("position = [0, -5, 1]", "position = 3") => "position = 3", "camera.position", "array [x, y, z]";
        edit("material = \"m\"", "material = 3") => "material = 3", "object[0].material", "invalid type";
        append("[output]\nexr = 'a.exr'\nlayers = 'depth'\n") => "layers", "output.layers", "invalid type";
        edit("mm_per_unit = 10", "mm_per_unit = [10]") => "[10]", "material.m.mm_per_unit", "invalid type";
        artist("'white'") => "white", "material.m.kd", "a number, an array";
        artist("[0.5, 0.5]") => "kd = [0.5, 0.5]", "material.m.kd", "array of 3";
        edit("mm_per_unit = 10", "mm_per_unit = 10\nprofile = 2") => "profile", "material.m.profile", "invalid type";
        edit(PRESET, "kd = 0.5\nradius = 'wide'\neta = 1.3") => "wide", "material.m.radius", "a number, an array";
        edit(PRESET, "kd = 0.5\nradius = [1, 2]\neta = 1.3") => "[1, 2]", "material.m.radius", "array of 3";
        edit(PRESET, "kd = 0.5\nradius = 0.7\nradius_scale = [1, 2, 3]\neta = 1.3")
            => "radius_scale", "material.m.radius_scale", "invalid type";
    }
}

#[test]
fn missing_keys() {
    let coefficients = "sigma_a = 0.1\nsigma_s_prime = 1";
    let ramp_no_min = "kd = 0.5\nmean_free_path = { texture = 'ramp.png', max = 2 }\neta = 1.3";
    let sphere_light = edit("type = \"point\"\nposition", "type = \"sphere\"\ncenter");
    expect_all! { SceneErrorKind::MissingKey;
        edit("fov = 30\n", "") => "[camera]", "camera.fov", "missing required key";
        edit("material = \"m\"\n", "") => "[[object]]", "object[0].material", "missing required key";
        edit("type = \"translucent\"\n", "") => "[material.m]", "material.m.type", "missing required key";
        edit("type = \"point\"\n", "") => "[[light]]", "light[0].type", "missing required key";
        edit("shape = \"sphere\"\nradius = 1\n", "") => "[[object]]", "object[0].mesh", "shape";
        edit("radius = 1\n", "") => "[[object]]", "object[0].radius", "shape `sphere`";
        edit("mm_per_unit = 10\n", "") => "[material.m]", "material.m.mm_per_unit", "preset";
        edit(PRESET, "") => "[material.m]", "material.m", "exactly one of";
        edit(PRESET, coefficients) => "[material.m]", "material.m.eta", "missing required key";
        edit(PRESET, "kd = 0.5\neta = 1.3") => "[material.m]", "material.m.mean_free_path", "diffuse_mean_free_path";
        edit(PRESET, ramp_no_min) => "mean_free_path =", "material.m.mean_free_path.min", "min";
        edit(PRESET, "kd = 0.5\nradius_scale = 2\neta = 1.3") => "radius_scale", "material.m.radius", "`radius_scale` scales `radius`";
        edit(PRESET, "kd = 0.5\nradius = { texture = 'ramp.png', min = 1 }\neta = 1.3")
            => "radius = {", "material.m.radius.max", "max";
        edit(PRESET, "radius = 0.7\neta = 1.3") => "[material.m]", "material.m.kd", "missing required key";
        edit("intensity = 20\n", "") => "[[light]]", "light[0].intensity", "point light";
        sphere_light => "[[light]]", "light[0].radius", "sphere light";
    }
}

#[test]
fn missing_tables_name_the_file_and_key() {
    let object_at = BASE.find("[[object]]").unwrap_or(0);
    let material_at = BASE.find("[material.m]").unwrap_or(0);
    let light_at = BASE.find("[[light]]").unwrap_or(0);
    let cases = [
        (BASE[object_at..].to_string(), "camera"),
        (
            format!("{}{}", &BASE[..object_at], &BASE[material_at..]),
            "object",
        ),
        (BASE[..light_at].to_string(), "light"),
    ];
    for (text, key) in cases {
        let e = load(&text).expect_err(key);
        assert_eq!(
            (e.kind, e.key.as_deref()),
            (SceneErrorKind::MissingKey, Some(key)),
            "{e}"
        );
        assert!(
            e.to_string().starts_with(&format!("t.toml: {key}: ")),
            "{e}"
        );
    }
}
