//! Every key reaching the model, the example scenes in `scenes/`, files on disk, and
//! robustness against mutated input.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use lucent_core::Method;

use super::*;

#[test]
fn every_field_reaches_the_model() {
    let text = r#"
[camera]
position = [1, -6, 2]
target = [0, 0, 1]
up = [0, 0.1, 1]
fov = 35.5
width = 320
height = 200

[[object]]
name = "slab"
shape = "box"
size = [2, 3, 0.5]
translate = [1, 2, 3]
rotate = [0, 0, 90]
scale = 2
material = "wax"

[[object]]
shape = "disk"
radius = 4
segments = 12
material = "floor"

[material.wax]
type = "translucent"
sigma_a = [0.01, 0.02, 0.03]
sigma_s_prime = 1.5
eta = 1.4
specular = { exponent = 40, strength = 0.5 }

[material.floor]
type = "lambert"
albedo = [0.2, 0.3, 0.4]

[[light]]
type = "spot"
position = [0, 0, 5]
direction = [0, 0, -2]
inner_angle = 10
outer_angle = 20
color = [1, 0.5, 0.25]
intensity = 7

[[light]]
type = "directional"
direction = [0, 1, -1]
irradiance = 0.5

[[light]]
type = "sphere"
center = [3, 3, 3]
radius = 0.5
intensity = 9
samples = 4

[render]
method = "local-global"
spacing = 0.05
epsilon = 0.1
smoothing = 2
ell_min = 0.001
cull_tolerance = 0
interpolation = 3
interpolation_tolerance = 0.5
aa = 4
exposure = -1.5
threads = 3
seed = 42

[output]
png = "out/a.png"
exr = "out/a.exr"
layers = ["local", "depth"]
"#;
    let s = load(text).expect("loads");
    let c = &s.camera;
    assert_eq!(
        (
            c.position,
            c.target,
            c.up,
            c.vfov_degrees,
            c.width,
            c.height
        ),
        (
            Vec3::new(1.0, -6.0, 2.0),
            Vec3::Z,
            Vec3::new(0.0, 0.1, 1.0),
            35.5,
            320,
            200
        )
    );
    // Materials are indexed in name order: floor, wax.
    assert_eq!(s.materials.len(), 2);
    assert!(
        matches!(&s.materials[0], Material::Lambert { name, albedo } if name == "floor" && *albedo == Vec3::new(0.2, 0.3, 0.4))
    );
    let Material::Translucent(wax) = &s.materials[1] else {
        panic!("wax")
    };
    assert_eq!(
        wax.specular,
        Some(Specular {
            exponent: 40.0,
            strength: 0.5
        })
    );
    assert!(
        matches!(wax.medium, Medium::Coefficients { sigma_a, sigma_s_prime, eta }
        if sigma_a == Vec3::new(0.01, 0.02, 0.03) && sigma_s_prime == Vec3::splat(1.5) && eta == 1.4)
    );
    let slab = &s.objects[0];
    assert_eq!((slab.name.as_str(), slab.material), ("slab", 1));
    // Box corner (1, 1.5, 0.25) → ×2 → (2, 3, 0.5) → Rz(90°) → (−3, 2, 0.5) → + (1, 2, 3).
    let expected = Vec3::new(-2.0, 4.0, 3.5);
    assert!(
        slab.mesh
            .positions
            .iter()
            .any(|p| (*p - expected).length() < 1e-5)
    );
    let disk = &s.objects[1];
    assert_eq!(
        (disk.name.as_str(), disk.material, disk.mesh.triangles.len()),
        ("disk", 0, 12)
    );
    assert_eq!(
        s.lights,
        vec![
            Light::Spot {
                position: Vec3::new(0.0, 0.0, 5.0),
                direction: -Vec3::Z,
                inner_angle_degrees: 10.0,
                outer_angle_degrees: 20.0,
                color: Vec3::new(1.0, 0.5, 0.25),
                intensity: 7.0,
            },
            Light::Directional {
                direction: Vec3::new(0.0, 1.0, -1.0).normalize(),
                color: Vec3::ONE,
                irradiance: 0.5,
            },
            Light::Sphere {
                center: Vec3::splat(3.0),
                radius: 0.5,
                color: Vec3::ONE,
                intensity: 9.0,
                samples: 4,
            },
        ]
    );
    assert_eq!(
        s.render,
        RenderSettings {
            method: Method::LocalGlobal,
            samples: SampleDensity::Spacing(0.05).into(),
            max_samples: None,
            epsilon: 0.1,
            smoothing: 2.0,
            ell_min: Some(0.001),
            cull_tolerance: 0.0,
            interpolation: 3,
            interpolation_tolerance: 0.5,
            aa: 4,
            exposure: -1.5,
            threads: Some(3),
            seed: 42,
        }
    );
    assert_eq!(
        s.output,
        OutputSettings {
            png: Some(PathBuf::from("out/a.png")),
            exr: Some(PathBuf::from("out/a.exr")),
            layers: ExrLayers {
                local: true,
                depth: true,
                ..ExrLayers::default()
            },
        }
    );
}

/// The profile at `uv` of the first material of scene `text` (a translucent one).
fn profile_at(text: &str, uv: Vec2) -> lucent_core::Profile {
    profiles_at(text, &[uv])[0]
}

/// The profiles at several points of one material (its shader built once: a textured K_d's
/// tables take a while).
fn profiles_at(text: &str, uvs: &[Vec2]) -> Vec<lucent_core::Profile> {
    let s = load(text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    match crate::material::Shader::new(&s.materials[0]).unwrap() {
        crate::material::Shader::Translucent(t) => {
            uvs.iter().map(|&uv| t.at(uv).unwrap().profile).collect()
        }
        crate::material::Shader::Lambert { .. } => panic!("not translucent:\n{text}"),
    }
}

/// `profile` reaches the profile of every way of giving a medium, textured ones included; the
/// classical dipole without it.
#[test]
fn profile_key_reaches_every_profile() {
    let forms = [
        PRESET,
        "sigma_a = 0.1\nsigma_s_prime = 2\neta = 1.3",
        "kd = [0.8, 0.5, 0.3]\nmean_free_path = 0.2\neta = 1.3",
        "kd = { texture = 'ramp.png' }\ndiffuse_mean_free_path = 0.2\neta = 1.3",
        "kd = 0.5\nradius = { texture = 'ramp.png', min = 0.01, max = 1 }\nradius_scale = 0.5\neta = 1.3",
    ];
    let uv = Vec2::new(0.3, 0.5);
    for form in forms {
        let plain = profile_at(&edit(PRESET, form), uv);
        assert_eq!(plain.model(), lucent_core::ProfileModel::Dipole, "{form}");
        for model in lucent_core::ProfileModel::ALL {
            let text = edit(PRESET, &format!("{form}\nprofile = \"{}\"", model.name()));
            let s = load(&text).unwrap_or_else(|e| panic!("{e}"));
            let Material::Translucent(m) = &s.materials[0] else {
                panic!("not translucent")
            };
            assert_eq!(m.model, model);
            assert_eq!(profile_at(&text, uv).model(), model, "{form}");
        }
    }
}

/// `radius` × `radius_scale` is `mean_free_path`, to the bit, under every model: constants (a
/// scale of a power of two, and one that rounds) and distance textures (`min` and `max` scaled)
/// with a textured K_d.
#[test]
fn radius_times_scale_is_the_mean_free_path() {
    let (radius, s) = ([1.0f32, 0.4, 0.2], 0.3f32);
    let product = radius.map(|r| r * s);
    let cases = [
        (
            "radius = [1.0, 0.4, 0.2]".to_string(),
            "mean_free_path = [1.0, 0.4, 0.2]".to_string(),
        ),
        (
            "radius = [1.0, 0.4, 0.2]\nradius_scale = 0.25".to_string(),
            "mean_free_path = [0.25, 0.1, 0.05]".to_string(),
        ),
        (
            "radius = [1.0, 0.4, 0.2]\nradius_scale = 0.3".to_string(),
            format!(
                "mean_free_path = [{:?}, {:?}, {:?}]",
                product[0], product[1], product[2]
            ),
        ),
        (
            "radius = { texture = 'ramp.png', min = 0.02, max = 2 }\nradius_scale = 0.5"
                .to_string(),
            "mean_free_path = { texture = 'ramp.png', min = 0.01, max = 1 }".to_string(),
        ),
    ];
    for model in lucent_core::ProfileModel::ALL {
        for kd in ["[0.8, 0.5, 0.3]", "{ texture = 'ramp.png' }"] {
            for (given, want) in &cases {
                let material = |distance: &str| {
                    edit(
                        PRESET,
                        &format!(
                            "kd = {kd}\n{distance}\neta = 1.3\nprofile = '{}'",
                            model.name()
                        ),
                    )
                };
                let uvs = [0.05, 0.3, 0.55, 0.9].map(|u| Vec2::new(u, 0.5));
                let (a, b) = (
                    profiles_at(&material(given), &uvs),
                    profiles_at(&material(want), &uvs),
                );
                assert_eq!(a, b, "{} {kd}: {given} vs {want}", model.name());
            }
        }
    }
}

/// The scenes shipped in `scenes/`, loaded from disk.
fn example_scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    scenes
}

#[test]
fn every_example_scene_loads() {
    let scenes = example_scenes();
    let names: Vec<_> = scenes
        .iter()
        .filter_map(|p| p.file_name()?.to_str().map(str::to_string))
        .collect();
    for wanted in ["default.toml", "sphere-shadow.toml", "textured-mfp.toml"] {
        assert!(
            names.iter().any(|n| n == wanted),
            "{wanted} missing from scenes/"
        );
    }
    for path in &scenes {
        let s = load_scene(path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.source.as_deref(), Some(path.as_path()));
        assert!(!s.objects.is_empty() && !s.lights.is_empty());
    }
}

#[test]
fn default_scene_from_disk_equals_the_built_in_one() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let disk = load_scene(&dir.join("default.toml")).unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(dir.join("default.toml")).expect("readable");
    assert_eq!(text, DEFAULT_SCENE_TOML, "the embedded copy is stale");
    let built_in = default_scene();
    assert_eq!(disk.camera, built_in.camera);
    assert_eq!(disk.render, built_in.render);
    assert_eq!(disk.output, built_in.output);
    assert_eq!(disk.lights, built_in.lights);
    for (a, b) in disk.objects.iter().zip(&built_in.objects) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.mesh.positions, b.mesh.positions);
        assert_eq!(a.mesh.triangles, b.mesh.triangles);
    }
}

#[test]
fn sphere_shadow_scene_matches_its_specification() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let s = load_scene(&dir.join("sphere-shadow.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.camera.position, Vec3::new(0.0, -7.0, 1.3));
    assert_eq!(s.camera.target, Vec3::new(0.0, 0.0, 0.9));
    assert_eq!(
        (s.camera.vfov_degrees, s.camera.width, s.camera.height),
        (30.0, 512, 512)
    );
    assert!(
        matches!(s.lights[..], [Light::Point { position, .. }] if position == Vec3::new(0.0, -3.0, 5.0))
    );
    let sphere = s
        .objects
        .iter()
        .find(|o| o.name == "sphere")
        .expect("sphere");
    for p in &sphere.mesh.positions {
        assert!(((*p - Vec3::Z).length() - 1.0).abs() < 1e-5);
    }
    let Material::Translucent(m) = &s.materials[sphere.material] else {
        panic!("sphere is not translucent")
    };
    assert!(
        matches!(&m.medium, Medium::Preset { name, mm_per_unit } if name == "marble" && *mm_per_unit == 10.0)
    );
    // The plate: its lower face at about z = 2.6, its edge on x = 0, covering x < 0.
    let plate = s.objects.iter().find(|o| o.name == "plate").expect("plate");
    let (lo, hi) = plate
        .mesh
        .positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| {
            (l.min(*p), h.max(*p))
        });
    assert!(
        (lo.z - 2.6).abs() < 0.05 && (hi.z - 2.6).abs() < 0.05,
        "{lo} {hi}"
    );
    assert!(hi.x.abs() < 1e-6 && lo.x < -1.0, "{lo} {hi}");
}

#[test]
fn textured_mfp_scene_spans_two_decades() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let s = load_scene(&dir.join("textured-mfp.toml")).unwrap_or_else(|e| panic!("{e}"));
    let textured =
        s.materials
            .iter()
            .find_map(|m| match m {
                Material::Translucent(TranslucentMaterial {
                    medium:
                        Medium::Reflectance {
                            distance:
                                Distance::MeanFreePath(ScalarParam::Texture { texture, min, max }),
                            ..
                        },
                    ..
                }) => Some((texture.clone(), *min, *max)),
                _ => None,
            })
            .expect("a material with a texture-mapped mean free path");
    let (texture, min, max) = textured;
    assert!(max / min >= 100.0, "{min}..{max} is less than two decades");
    // The texture is a left-to-right ramp: t = 0 at the left edge, 1 at the right.
    let t_left = texture.sample(Vec2::new(0.5 / texture.width as f32, 0.5));
    let t_right = texture.sample(Vec2::new(1.0 - 0.5 / texture.width as f32, 0.5));
    assert_eq!((t_left.x, t_right.x), (0.0, 1.0));
    let mid = texture.sample(Vec2::new(0.5, 0.5)).x;
    assert!((mid - 0.5).abs() < 0.01, "{mid}");
    // The textured object has UVs.
    let index = s
        .materials
        .iter()
        .position(|m| matches!(m, Material::Translucent(_)))
        .expect("translucent");
    assert!(
        s.objects
            .iter()
            .filter(|o| o.material == index)
            .all(|o| o.mesh.uvs.is_some())
    );
}

#[test]
fn files_on_disk_resolve_next_to_the_scene_and_errors_name_them() {
    let dir = std::env::temp_dir().join(format!("lucent-scene-test-{}", std::process::id()));
    let sub = dir.join("meshes");
    std::fs::create_dir_all(&sub).expect("temp dir");
    std::fs::write(sub.join("quad.obj"), QUAD_UV).expect("write");
    let scene = edit(
        "shape = \"sphere\"\nradius = 1",
        "obj = \"meshes/quad.obj\"",
    );
    std::fs::write(dir.join("ok.toml"), &scene).expect("write");
    let s = load_scene(&dir.join("ok.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.objects[0].name, "quad");
    assert_eq!(s.output.png.as_deref(), Some(Path::new("ok.png")));

    let missing = scene.replace("meshes/quad.obj", "meshes/gone.obj");
    std::fs::write(dir.join("missing.toml"), &missing).expect("write");
    let e = load_scene(&dir.join("missing.toml")).expect_err("missing mesh");
    assert_eq!(e.kind, SceneErrorKind::Io);
    assert!(e.file.ends_with("missing.toml"), "{e}");
    assert!(
        e.message
            .contains(&sub.join("gone.obj").display().to_string()),
        "{e}"
    );

    let e = load_scene(&dir.join("absent.toml")).expect_err("no scene");
    assert_eq!((e.kind, e.position), (SceneErrorKind::Io, None), "{e}");
    assert!(e.to_string().contains("absent.toml"), "{e}");

    let mut bytes = b"[camera]\nfov = 3\n# caf".to_vec();
    bytes.extend_from_slice(&[0xe9, b'\n']);
    std::fs::write(dir.join("latin1.toml"), bytes).expect("write");
    let e = load_scene(&dir.join("latin1.toml")).expect_err("not UTF-8");
    assert_eq!(
        (e.kind, e.position),
        (SceneErrorKind::Syntax, Some((3, 6))),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every key the parser accepts is documented in `docs/scene-format.md`: the lists come from
/// the parser's own "unknown key, expected one of …" messages, one per table.
#[test]
fn every_key_is_documented() {
    let doc_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scene-format.md");
    let doc = std::fs::read_to_string(&doc_path).expect("docs/scene-format.md");
    let probes = [
        format!("zzz = 1\n{BASE}"),
        edit("fov = 30", "fov = 30\nzzz = 1"),
        edit("radius = 1", "radius = 1\nzzz = 1"),
        edit("mm_per_unit = 10", "mm_per_unit = 10\nzzz = 1"),
        edit(
            "mm_per_unit = 10",
            "mm_per_unit = 10\nspecular = { zzz = 1 }",
        ),
        edit(PRESET, "kd = { zzz = 1 }\nmean_free_path = 1\neta = 1.3"),
        append("zzz = 1\n"),
        append("[render]\nzzz = 1\n"),
        append("[output]\nzzz = 1\n"),
    ];
    let mut seen = 0;
    for text in probes {
        let e = load(&text).expect_err("unknown key");
        assert_eq!(e.kind, SceneErrorKind::UnknownKey, "{e}");
        // "expected one of `a`, `b`, `c`" or "expected `a` or `b`".
        let list = e
            .message
            .split("expected ")
            .nth(1)
            .unwrap_or_else(|| panic!("no key list in {e}"))
            .trim_start_matches("one of ")
            .replace(" or ", ", ");
        for key in list.split(',').map(|k| k.trim().trim_matches('`')) {
            let forms = [
                format!("`{key}`"),
                format!("`[{key}"),
                format!("`[[{key}]]`"),
            ];
            let documented = forms.iter().any(|form| doc.contains(form.as_str()));
            assert!(documented, "key `{key}` is not documented");
            seen += 1;
        }
    }
    assert!(seen > 50, "only {seen} keys probed");
}
