//! `scene_parse_never_panics` and `obj_load_never_panics`: arbitrary bytes into the scene and
//! OBJ loaders.
//!
//! Both loaders promise "a value or an error, never a panic" on any input. On success the
//! result must also keep the invariants the renderer relies on: every mesh passes
//! `validate_mesh` (and, checked here independently, its indices are in range and its
//! positions finite), every object's material exists, the camera gives a finite view, and the
//! render settings are valid query settings (and interpolation settings).

use std::borrow::Cow;

use lucent_core::QuerySettings;
use lucent_core::glam::Vec3;
use lucent_raster::raster::MAX_AA;
use lucent_raster::scene::mesh::validate_mesh;
use lucent_raster::scene::mtl::parse_mtl;
use lucent_raster::scene::obj::load_obj;
use lucent_raster::scene::weld::weld_normals;
use lucent_raster::scene::{Light, MAX_INTERPOLATION_STEP, Mesh, SceneOrigin, parse_scene};

/// A small closed mesh (a tetrahedron with UVs and normals) served under the bunny's path, so
/// that the repository's scenes parse quickly inside the fuzzer.
pub const SMALL_MESH_OBJ: &str = "\
v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n\
vn -0.577 -0.577 -0.577\nvn 1 0 0\nvn 0 1 0\nvn 0 0 1\n\
f 1/1/1 3/3/3 2/2/2\nf 1/1/1 2/2/2 4/4/4\nf 1/1/1 4/4/4 3/3/3\nf 2/2/2 3/3/3 4/4/4\n";

/// The 8-bit grey ramp of `scenes/textured-mfp.toml`.
const RAMP_PNG: &[u8] = include_bytes!("../../../scenes/textures/mfp-ramp.png");

/// The lat-long sky of `scenes/environment.toml`.
const SKY_PNG: &[u8] = include_bytes!("../../../scenes/textures/sky-latlong.png");

/// The two-material OBJ of `scenes/obj-materials.toml`, its `.mtl` and its `map_Kd`.
const TWO_MATERIALS: [(&str, &[u8]); 3] = [
    (
        "meshes/two-materials.obj",
        include_bytes!("../../../scenes/meshes/two-materials.obj"),
    ),
    (
        "meshes/two-materials.mtl",
        include_bytes!("../../../scenes/meshes/two-materials.mtl"),
    ),
    (
        "meshes/two-materials-kd.png",
        include_bytes!("../../../scenes/meshes/two-materials-kd.png"),
    ),
];

/// Where fuzzed scenes come from: files served from memory under the names the repository's
/// scenes use (`../assets/bunny.obj`, `textures/mfp-ramp.png`, `textures/sky-latlong.png`,
/// `meshes/two-materials.*`), plus `mesh.obj`.
pub fn fuzz_origin() -> SceneOrigin {
    let mut files = TWO_MATERIALS
        .iter()
        .map(|&(name, bytes)| (name.to_string(), Cow::Borrowed(bytes)))
        .collect::<Vec<_>>();
    SceneOrigin::Embedded {
        name: "<fuzz>/scene.toml".to_string(),
        files: vec![
            (
                "../assets/bunny.obj".to_string(),
                Cow::Borrowed(SMALL_MESH_OBJ.as_bytes()),
            ),
            (
                "mesh.obj".to_string(),
                Cow::Borrowed(SMALL_MESH_OBJ.as_bytes()),
            ),
            ("textures/mfp-ramp.png".to_string(), Cow::Borrowed(RAMP_PNG)),
            (
                "textures/sky-latlong.png".to_string(),
                Cow::Borrowed(SKY_PNG),
            ),
        ]
        .into_iter()
        .chain(files.drain(..))
        .collect(),
    }
}

/// Panics unless `mesh` passes `validate_mesh`, with indices in range and finite positions.
pub(super) fn check_mesh(what: &str, mesh: &Mesh) {
    if let Err(e) = validate_mesh(mesh) {
        panic!("{what}: the loader returned an invalid mesh: {e}");
    }
    let n = mesh.positions.len();
    assert!(
        mesh.triangles.iter().flatten().all(|&i| (i as usize) < n),
        "{what}: index out of range"
    );
    assert!(
        mesh.positions.iter().all(|p| p.is_finite()),
        "{what}: non-finite position"
    );
}

/// The property of the fuzz target `scene_parse_never_panics`: `parse_scene` on the bytes
/// (lossily converted to UTF-8) returns a value or an error, and a value is sound (see the
/// module docs). Panics when that fails.
pub fn scene_parse_never_panics(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(scene) = parse_scene(&text, &fuzz_origin()) else {
        return;
    };
    for object in &scene.objects {
        check_mesh(&object.name, &object.mesh);
        assert!(
            object.material < scene.materials.len(),
            "object {} has material {} of {}",
            object.name,
            object.material,
            scene.materials.len()
        );
    }
    let cam = &scene.camera;
    assert!(cam.width > 0 && cam.height > 0, "camera {cam:?}");
    assert!(
        cam.vfov_degrees > 0.0 && cam.vfov_degrees < 180.0,
        "camera {cam:?}"
    );
    assert!(cam.view_matrix().is_finite(), "camera {cam:?}: view matrix");
    let (origin, direction) = cam.ray(cam.width as f32 * 0.5, cam.height as f32 * 0.5);
    assert!(
        origin.is_finite() && direction.is_finite() && direction.length() > 0.5,
        "camera {cam:?}: central ray {origin} {direction}"
    );
    let r = &scene.render;
    let settings = QuerySettings {
        epsilon: r.epsilon,
        cull_tolerance: r.cull_tolerance,
        ..Default::default()
    };
    assert!(settings.validate().is_ok(), "render settings {r:?}");
    assert!(
        r.smoothing.is_finite() && r.smoothing >= 0.0,
        "render settings {r:?}"
    );
    assert!((1..=MAX_AA).contains(&r.aa), "render settings {r:?}");
    assert!(
        (1..=MAX_INTERPOLATION_STEP).contains(&r.interpolation)
            && r.interpolation_tolerance.is_finite()
            && r.interpolation_tolerance >= 0.0,
        "render settings {r:?}"
    );
    for light in &scene.lights {
        match light {
            Light::Rect {
                normal,
                right,
                up_axis,
                size,
                ..
            } => {
                let unit = |v: &Vec3| (v.length() - 1.0).abs() < 1e-4;
                assert!(
                    unit(normal) && unit(right) && unit(up_axis),
                    "rect frame {light:?}"
                );
                assert!(size.x > 0.0 && size.y > 0.0, "rect size {light:?}");
            }
            Light::Environment {
                map: Some(map),
                intensity,
                ..
            } => {
                assert_eq!(map.validate(), Ok(()), "environment map");
                assert!(intensity.is_finite() && *intensity >= 0.0);
            }
            _ => {}
        }
    }
}

/// The property of the fuzz target `obj_load_never_panics`: `load_obj` returns a value or an
/// error, and a value is a valid mesh whose every triangle has a group in range; welding it
/// (at a 60° crease) keeps it valid with the same triangles. The same bytes read as a `.mtl`
/// give materials or an error. Panics when that fails.
pub fn obj_load_never_panics(data: &[u8]) {
    if let Ok(obj) = load_obj(data) {
        check_mesh("load_obj", &obj.mesh);
        assert_eq!(obj.triangle_groups.len(), obj.mesh.triangles.len());
        assert!(
            obj.triangle_groups
                .iter()
                .flatten()
                .all(|&g| (g as usize) < obj.groups.len()),
            "group out of range"
        );
        let mut welded = obj.mesh.clone();
        weld_normals(&mut welded, 60.0);
        check_mesh("weld_normals", &welded);
        assert_eq!(welded.triangles.len(), obj.mesh.triangles.len());
    }
    let _ = parse_mtl(data);
}
