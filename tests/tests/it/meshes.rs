//! Mesh files through the scene loader: `mesh = …` chooses the format by extension, the
//! committed PLY bunny equals the OBJ bunny it was converted from, the committed `.gltf` and
//! `.glb` eggs load identically, and a binary PLY named by the old `obj` key loads (it used to
//! fail as "not UTF-8 text").

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use lucent_raster::scene::gltf::parse_gltf;
use lucent_raster::scene::obj::parse_obj;
use lucent_raster::scene::ply::parse_ply;
use lucent_raster::scene::{SceneOrigin, load_scene, parse_scene};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(p: &str) -> Vec<u8> {
    std::fs::read(root().join(p)).unwrap_or_else(|e| panic!("{p}: {e}"))
}

#[test]
fn ply_bunny_equals_the_obj_it_was_converted_from() {
    let obj = parse_obj(&read("assets/bunny.obj")).unwrap();
    let ply = parse_ply(&read("tests/data/meshes/bunny.ply")).unwrap();
    assert_eq!(ply.triangles.len(), obj.triangles.len());
    assert_eq!(ply.positions.len(), obj.positions.len());
    // tobj renumbers vertices in order of first use; compare triangle by triangle. The PLY holds
    // the OBJ's decimals rounded to f32 by the converter, tobj parses them to f32 itself: equal
    // up to one rounding.
    for (k, (tp, to)) in ply.triangles.iter().zip(&obj.triangles).enumerate() {
        for (&i, &j) in tp.iter().zip(to) {
            let (p, o) = (ply.positions[i as usize], obj.positions[j as usize]);
            assert!(
                (p - o).abs().max_element() <= 4e-7 * o.abs().max_element().max(1.0),
                "triangle {k}: {p} vs {o}"
            );
            assert!(
                (ply.normals[i as usize] - obj.normals[j as usize]).length() < 1e-5,
                "triangle {k}: normals"
            );
        }
    }
}

#[test]
fn gltf_and_glb_eggs_are_the_same_mesh() {
    let no_files = &mut |name: &str| Err(format!("unexpected file {name}"));
    let text = parse_gltf(&read("tests/data/meshes/egg.gltf"), no_files).unwrap();
    let binary = parse_gltf(&read("tests/data/meshes/egg.glb"), no_files).unwrap();
    assert_eq!(text.mesh.positions, binary.mesh.positions);
    assert_eq!(text.mesh.normals, binary.mesh.normals);
    assert_eq!(text.mesh.uvs, binary.mesh.uvs);
    assert_eq!(text.mesh.triangles, binary.mesh.triangles);
    assert_eq!(text.groups, binary.groups);
    assert_eq!(text.groups[0].material.as_deref(), Some("wax"));
    // The node transform: the unit sphere scaled (1, 0.6, 0.8), turned 30° about z, lifted by
    // (0.25, -0.5, 1): its lowest point is at z = 1 - 0.8, its extent along the turned x axis 1.
    let lowest = text
        .mesh
        .positions
        .iter()
        .map(|p| p.z)
        .fold(f32::INFINITY, f32::min);
    assert!((lowest - 0.2).abs() < 1e-6, "{lowest}");
    let axis =
        lucent_core::glam::Vec3::new(30f32.to_radians().cos(), 30f32.to_radians().sin(), 0.0);
    let centre = lucent_core::glam::Vec3::new(0.25, -0.5, 1.0);
    let reach = text
        .mesh
        .positions
        .iter()
        .map(|p| (*p - centre).dot(axis))
        .fold(f32::NEG_INFINITY, f32::max);
    assert!((reach - 1.0).abs() < 1e-6, "{reach}");
}

#[test]
fn scenes_choose_the_loader_by_extension() {
    let scene = |key: &str, file: &str| {
        format!(
            "[camera]\nposition = [0.0, -5.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 30.0\n\
             [[object]]\n{key} = \"{file}\"\nmaterial = \"m\"\n\
             [material.m]\ntype = \"lambert\"\nalbedo = 0.5\n\
             [[light]]\ntype = \"point\"\nposition = [0.0, 0.0, 5.0]\nintensity = 1.0\n"
        )
    };
    let origin = SceneOrigin::Embedded {
        name: "s/scene.toml".to_string(),
        files: vec![
            (
                "m/bunny.ply".into(),
                Cow::Owned(read("tests/data/meshes/bunny.ply")),
            ),
            (
                "m/bunny.PLY".into(),
                Cow::Owned(read("tests/data/meshes/bunny.ply")),
            ),
            (
                "m/egg.glb".into(),
                Cow::Owned(read("tests/data/meshes/egg.glb")),
            ),
            (
                "m/bunny.stl".into(),
                Cow::Owned(read("tests/data/meshes/bunny.ply")),
            ),
        ],
    };
    let load = |key: &str, file: &str| parse_scene(&scene(key, file), &origin);
    let bunny = load("mesh", "m/bunny.ply").unwrap();
    assert_eq!(bunny.objects[0].name, "bunny");
    assert_eq!(bunny.objects[0].mesh.triangles.len(), 3674);
    // The old key reads any format; the extension's case does not matter.
    assert_eq!(
        load("obj", "m/bunny.PLY").unwrap().objects[0]
            .mesh
            .positions,
        bunny.objects[0].mesh.positions
    );
    assert_eq!(load("mesh", "m/egg.glb").unwrap().objects[0].name, "egg");
    let e = load("mesh", "m/bunny.stl").unwrap_err().to_string();
    assert!(
        e.contains("object[0].mesh") && e.contains(".obj, .ply, .gltf, .glb"),
        "{e}"
    );
    let both = scene("mesh", "m/bunny.ply").replace(
        "material = \"m\"\n[m",
        "obj = \"x.obj\"\nmaterial = \"m\"\n[m",
    );
    let e = parse_scene(&both, &origin).unwrap_err().to_string();
    assert!(
        e.contains("object[0].obj") && e.contains("cannot be combined with `mesh`"),
        "{e}"
    );
    // A broken PLY is reported with the key, the file and the place in it.
    let mut cut = read("tests/data/meshes/bunny.ply");
    cut.truncate(cut.len() - 5);
    let origin = SceneOrigin::Embedded {
        name: "scene.toml".to_string(),
        files: vec![("cut.ply".into(), Cow::Owned(cut))],
    };
    let e = parse_scene(&scene("mesh", "cut.ply"), &origin)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("object[0].mesh") && e.contains("cut.ply") && e.contains("byte "),
        "{e}"
    );
}

#[test]
fn gltf_with_an_external_buffer_loads_from_disk() {
    // The committed .gltf with its buffer moved to a file next to it (name with a space,
    // %-escaped in the URI), in a scratch directory.
    let dir = std::env::temp_dir().join(format!("lucent-gltf-ext-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("m")).unwrap();
    let text = String::from_utf8(read("tests/data/meshes/egg.gltf")).unwrap();
    let start = text.find("data:application/octet-stream;base64,").unwrap();
    let end = start + text[start..].find('"').unwrap();
    let data = &text[start + "data:application/octet-stream;base64,".len()..end];
    let glb = read("tests/data/meshes/egg.glb");
    // The GLB's binary chunk is the same buffer: take it from there.
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let bin = &glb[12 + 8 + json_len + 8..];
    assert!(!data.is_empty());
    std::fs::write(dir.join("m/egg data.bin"), bin).unwrap();
    let external = format!("{}egg%20data.bin{}", &text[..start], &text[end..]);
    std::fs::write(dir.join("m/egg.gltf"), external).unwrap();
    let scene = read("tests/data/gltf-egg.toml");
    let scene = String::from_utf8(scene)
        .unwrap()
        .replace("meshes/egg.gltf", "m/egg.gltf");
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let from_disk = load_scene(&dir.join("scene.toml"));
    let reference = load_scene(&root().join("tests/data/gltf-egg.toml")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let from_disk = from_disk.unwrap();
    assert_eq!(
        from_disk.objects[0].mesh.positions,
        reference.objects[0].mesh.positions
    );
}
