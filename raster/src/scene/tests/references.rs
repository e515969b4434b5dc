//! Names that refer to nothing, keys that conflict, and the files a scene names (meshes and
//! textures).

use std::path::PathBuf;

use super::*;

#[test]
fn unknown_names_list_the_valid_ones() {
    let layers = "[output]\nexr = 'a.exr'\nlayers = ['depth', 'normals']\n";
    expect_all! { SceneErrorKind::UnknownName;
        edit("preset = \"marble\"", "preset = \"granite\"") => "granite", "material.m.preset", "skin1, skin2, wholemilk";
        edit("material = \"m\"", "material = \"wax\"") => "wax", "object[0].material", "defined: m";
        edit("shape = \"sphere\"", "shape = \"cube\"") => "cube", "object[0].shape", "plane, sphere, box, disk";
        edit("type = \"point\"", "type = \"area\"") => "area", "light[0].type", "point, spot, directional, sphere";
        edit("type = \"translucent\"", "type = \"glass\"") => "glass", "material.m.type", "translucent, lambert";
        append("[render]\nmethod = 'fast'\n") => "fast", "render.method", "local-global, edge-aware";
        append(layers) => "layers", "output.layers", "exitance, local, global, irradiance, depth";
        edit(PRESET, "preset = 'marble'\nmm_per_unit = 10\nprofile = 'jensen'")
            => "jensen", "material.m.profile", "expected one of: dipole, better-dipole, burley, burley-diffuse";
        edit(PRESET, "kd = 0.5\nradius = 0.7\neta = 1.3\nprofile = 'Burley'")
            => "Burley", "material.m.profile", "unknown profile `Burley`";
    }
}

#[test]
fn preset_names_ignore_case() {
    let s = load(&edit("preset = \"marble\"", "preset = \"Skin1\"")).expect("Skin1 is skin1");
    match &s.materials[0] {
        Material::Translucent(TranslucentMaterial {
            medium: Medium::Preset { name, .. },
            ..
        }) => assert_eq!(name, "skin1"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn conflicting_keys() {
    let both = "kd = 0.5\nmean_free_path = 1\ndiffuse_mean_free_path = 1\neta = 1.3";
    let ranged_kd = "kd = { texture = 'ramp.png', min = 0.1 }\nmean_free_path = 1\neta = 1.3";
    let lambert_eta = edit(
        "type = \"translucent\"\npreset = \"marble\"\nmm_per_unit = 10",
        "type = \"lambert\"\nalbedo = 0.5\neta = 1",
    );
    let plus = |extra: &str| edit("mm_per_unit = 10", &format!("mm_per_unit = 10\n{extra}"));
    let artist = |lines: &str| edit(PRESET, &format!("kd = 0.5\n{lines}\neta = 1.3"));
    let lambert_profile = edit(
        "type = \"translucent\"\npreset = \"marble\"\nmm_per_unit = 10",
        "type = \"lambert\"\nalbedo = 0.5\nprofile = 'burley'",
    );
    expect_all! { SceneErrorKind::Conflict;
        plus("sigma_a = 1") => "sigma_a", "material.m.sigma_a", "preset";
        plus("kd = 0.5") => "kd", "material.m.kd", "preset";
        plus("eta = 1.3") => "eta", "material.m.eta", "preset";
        plus("albedo = 0.5") => "albedo", "material.m.albedo", "translucent";
        edit(PRESET, "sigma_a = 1\nsigma_s_prime = 1\neta = 1.3\nmm_per_unit = 10")
            => "mm_per_unit", "material.m.mm_per_unit", "explicit coefficients";
        edit("radius = 1", "radius = 1\nobj = 'quad.obj'") => "shape", "object[0].shape", "obj";
        edit("radius = 1", "radius = 1\nsize = 2") => "size", "object[0].size", "shape `sphere`";
        edit("intensity = 20", "intensity = 20\nradius = 1.5") => "radius = 1.5", "light[0].radius", "point light";
        append("[render]\nsamples = 10\nspacing = 0.1\n") => "spacing", "render.spacing", "samples";
        append("[output]\nlayers = ['depth']\n") => "layers", "output.layers", "exr";
        edit(PRESET, both) => "diffuse_mean_free_path", "material.m.diffuse_mean_free_path", "mean_free_path";
        edit(PRESET, ranged_kd) => "kd = ", "material.m.kd.min", "colour texture";
        lambert_eta => "eta", "material.m.eta", "lambert";
        lambert_profile => "profile", "material.m.profile", "lambert";
        plus("radius = 0.7") => "radius = 0.7", "material.m.radius", "cannot be combined with `preset`";
        plus("radius_scale = 2") => "radius_scale", "material.m.radius_scale", "preset";
        edit(PRESET, "sigma_a = 1\nsigma_s_prime = 1\neta = 1.3\nradius = 0.7")
            => "radius = 0.7", "material.m.radius", "sigma_a";
        artist("mean_free_path = 1\nradius = 0.7") => "radius = 0.7", "material.m.radius", "cannot be combined with `mean_free_path`";
        artist("radius = 0.7\ndiffuse_mean_free_path = 1")
            => "radius = 0.7", "material.m.radius", "cannot be combined with `diffuse_mean_free_path`";
        artist("mean_free_path = 1\nradius_scale = 2")
            => "radius_scale", "material.m.radius_scale", "it scales `radius`";
        artist("diffuse_mean_free_path = 1\nradius_scale = 2")
            => "radius_scale", "material.m.radius_scale", "`diffuse_mean_free_path`";
    }
}

#[test]
fn mesh_files_are_checked() {
    let obj = |file: &str| {
        edit(
            "shape = \"sphere\"\nradius = 1",
            &format!("obj = \"{file}\""),
        )
    };
    let textured = "kd = { texture = 'ramp.png' }\nmean_free_path = 1\neta = 1.3";
    let no_uvs = obj("nouv.obj").replacen(PRESET, textured, 1);
    let radius = "kd = 0.5\nradius = { texture = 'ramp.png', min = 0.1, max = 1 }\neta = 1.3";
    let no_uvs_radius = obj("nouv.obj").replacen(PRESET, radius, 1);
    expect_all! { SceneErrorKind::Io;
        obj("missing.obj") => "missing.obj", "object[0].obj", "cannot read mesh";
    }
    expect_all! { SceneErrorKind::Mesh;
        obj("syntax.obj") => "syntax.obj", "object[0].obj", "malformed OBJ";
        obj("range.obj") => "range.obj", "object[0].obj", "line 5: face vertex index 7 out of range";
        obj("flat.obj") => "flat.obj", "object[0].obj", "area";
        obj("nan.obj") => "nan.obj", "object[0].obj", "not finite";
        obj("empty.obj") => "empty.obj", "object[0].obj", "no faces";
        no_uvs => "nouv.obj", "object[0].obj", "no texture coordinates";
        no_uvs_radius => "nouv.obj", "object[0].obj", "`radius`";
    }
    // The same with UVs loads, and so do the shapes (which always have UVs).
    let s = load(&obj("quad.obj").replacen(PRESET, textured, 1)).expect("UVs present");
    assert_eq!(s.objects[0].name, "quad");
    assert!(load(&BASE.replacen(PRESET, textured, 1)).is_ok());
    // A mesh without UVs is fine with an untextured material.
    assert!(load(&obj("nouv.obj")).is_ok());
}

#[test]
fn texture_files_are_checked() {
    let with = |file: &str| {
        edit(
            PRESET,
            &format!(
                "kd = 0.5\nmean_free_path = {{ texture = '{file}', min = 0.1, max = 10 }}\neta = 1.3"
            ),
        )
    };
    let key = "material.m.mean_free_path.texture";
    expect_all! { SceneErrorKind::Io;
        with("nothere.png") => "nothere.png", key, "cannot read texture";
    }
    expect_all! { SceneErrorKind::Texture;
        with("bad.png") => "bad.png", key, "bad.png";
        with("trunc.png") => "trunc.png", key, "PNG";
        with("huge.png") => "huge.png", key, "100000";
    }
}

#[test]
fn textures_decode_colour_as_srgb_and_distances_as_data() {
    let text = edit(
        PRESET,
        "kd = { texture = 'ramp.png' }\n\
         mean_free_path = { texture = 'ramp.png', min = 0.01, max = 1 }\neta = 1.3",
    );
    let s = load(&text).expect("loads");
    let Material::Translucent(m) = &s.materials[0] else {
        panic!("not translucent")
    };
    let Medium::Reflectance { kd, distance, eta } = &m.medium else {
        panic!("not a reflectance medium")
    };
    assert_eq!(*eta, 1.3);
    let (
        ColorParam::Texture(kd),
        Distance::MeanFreePath(ScalarParam::Texture { texture, min, max }),
    ) = (kd, distance)
    else {
        panic!("textures expected")
    };
    assert_eq!((*min, *max), (0.01, 1.0));
    // Texel 4 holds code 128.
    assert!((texture.texel(4).x - 128.0 / 255.0).abs() < 1e-6);
    let srgb = crate::texture::srgb_to_linear(128.0 / 255.0);
    assert!((kd.texel(4).x - srgb).abs() < 1e-6);
    assert_eq!(texture.path, PathBuf::from("ramp.png"));
}
