//! OBJ files with several materials (`materials = { … }`, `kd = "mtl"`), mesh repairs and
//! their warnings, `weld` / `crease_angle`, and the coordinate bound, through the scene loader.

use std::borrow::Cow;

use super::*;
use crate::texture::tests::encode_png;

const CAMERA_AND_LIGHT: &str = r#"[camera]
position = [0, -5, 1]
target = [0, 0, 0.5]
fov = 30

[[light]]
type = "point"
position = [0, -3, 5]
intensity = 20

[material.skin]
type = "translucent"
kd = "mtl"
mean_free_path = 0.1
eta = 1.3

[material.plain]
type = "translucent"
preset = "marble"
mm_per_unit = 10

[material.dark]
type = "lambert"
albedo = 0.1
"#;

/// Two unit quads with UVs: faces before any `usemtl`, then groups `a`, `b`, `a` again.
const GROUPS: &str = "mtllib lib.mtl\n\
    v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
    f 1/1 2/2 3/3\n\
    usemtl a\nf 1/1 3/3 4/4\n\
    usemtl b\nf 5/1 6/2 7/3\n\
    usemtl a\nf 5/1 7/3 8/4\n";

const LIB: &str = "newmtl a\nmap_Kd tex/a.png\nnewmtl b\nKd 1 0 0\n";

/// A closed tetrahedron wound inside out (clockwise seen from outside).
const INSIDE_OUT: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
    f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n";

/// A unit quad as two glTF primitives, one triangle each, with materials `wax` and `jade`.
fn two_material_gltf() -> Vec<u8> {
    use base64::Engine as _;
    let mut buffer = Vec::new();
    for p in [
        [0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ] {
        for v in p {
            buffer.extend_from_slice(&v.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        buffer.extend_from_slice(&i.to_le_bytes());
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&buffer);
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [
    {{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}},
    {{"attributes": {{"POSITION": 0}}, "indices": 2, "material": 1}}]}}],
  "materials": [{{"name": "wax"}}, {{"name": "jade"}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
      "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}},
    {{"bufferView": 1, "byteOffset": 6, "componentType": 5123, "count": 3, "type": "SCALAR"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 12}}],
  "buffers": [{{"byteLength": 60, "uri": "data:application/octet-stream;base64,{data}"}}]}}"#
    )
    .into_bytes()
}

fn origin() -> SceneOrigin {
    let (rgb, eight) = (png::ColorType::Rgb, png::BitDepth::Eight);
    let png = encode_png(2, 1, rgb, eight, &[200, 100, 50, 50, 100, 200], None);
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("m/groups.obj", GROUPS.into()),
        ("m/lib.mtl", LIB.into()),
        ("m/tex/a.png", png),
        (
            "m/nolib.obj",
            GROUPS.replace("lib.mtl", "missing.mtl").into(),
        ),
        (
            "m/nomtllib.obj",
            GROUPS.replace("mtllib lib.mtl\n", "").into(),
        ),
        ("m/inside-out.obj", INSIDE_OUT.into()),
        ("m/two.gltf", two_material_gltf()),
        (
            "m/inside-out.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nelement face 4\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n"
                .into(),
        ),
        // The same with a copy of one face: the copy makes it look open until it is dropped.
        (
            "m/inside-out-copy.obj",
            format!("{INSIDE_OUT}f 2 3 1\n").into(),
        ),
        (
            "m/inside-out-copy.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nelement face 5\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n\
             3 3 2 1\n"
                .into(),
        ),
        // One triangle and a copy of it with another file normal: the copy's corners are
        // separate vertices, dropped with it.
        (
            "m/copy-normals.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0.6 0.8\nvn 0 0 1\n\
             f 1//1 2//1 3//1\nf 2//2 3//2 1//2\n"
                .into(),
        ),
        (
            "m/latin1.obj",
            b"# caf\xe9\no t\xe9te\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
        ),
        (
            "m/latin1-usemtl.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl t\xe9te\nf 1 2 3\n".to_vec(),
        ),
        (
            "m/huge.obj",
            "v -6e37 0 0\nv 6e37 0 0\nv 0 6e37 0\nf 1 2 3\n".into(),
        ),
    ];
    SceneOrigin::Embedded {
        name: "t.toml".into(),
        files: files
            .into_iter()
            .map(|(n, b)| (n.to_string(), Cow::Owned(b)))
            .collect(),
    }
}

fn scene(object: &str) -> Result<Scene, SceneError> {
    parse_scene(
        &format!("{CAMERA_AND_LIGHT}\n[[object]]\n{object}"),
        &origin(),
    )
}

fn material_name(s: &Scene, object: usize) -> &str {
    match &s.materials[s.objects[object].material] {
        Material::Translucent(t) => &t.name,
        Material::Lambert { name, .. } => name,
    }
}

/// The error's line within the `[[object]]` table appended by [`scene`], and its text.
fn object_error(object: &str) -> (usize, String, SceneError) {
    let e = scene(object).expect_err("an error");
    let offset = CAMERA_AND_LIGHT.lines().count() + 2;
    let line = e.position.expect("located").0 - offset;
    (line, e.to_string(), e)
}

#[test]
fn groups_map_to_materials_and_split_the_object() {
    let s = scene(
        "name = \"q\"\nobj = \"m/groups.obj\"\nmaterial = \"plain\"\n\
         materials = { a = \"dark\", b = \"plain\" }\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // Faces in file order: ungrouped → plain, a → dark, b → plain, a → dark. Two materials,
    // two objects, in order of first triangle; `b` joins the ungrouped face.
    assert_eq!(s.objects.len(), 2);
    assert_eq!(s.objects[0].name, "q/plain");
    assert_eq!(s.objects[1].name, "q/dark");
    assert_eq!(material_name(&s, 0), "plain");
    assert_eq!(material_name(&s, 1), "dark");
    assert_eq!(s.objects[0].mesh.triangles.len(), 2);
    assert_eq!(s.objects[1].mesh.triangles.len(), 2);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    // The dark part holds the faces of group a: z = 0 and z = 1, one each.
    let zs: Vec<f32> = s.objects[1]
        .mesh
        .triangles
        .iter()
        .map(|t| s.objects[1].mesh.positions[t[0] as usize].z)
        .collect();
    assert_eq!(zs, vec![0.0, 1.0]);
    // Without a mapping, one object with the default material and no warning.
    let s = scene("obj = \"m/groups.obj\"\nmaterial = \"plain\"\n").unwrap();
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.objects[0].mesh.triangles.len(), 4);
    assert!(s.warnings.is_empty());
}

#[test]
fn an_unmapped_group_takes_the_default_with_a_located_warning() {
    let s = scene("obj = \"m/groups.obj\"\nmaterial = \"plain\"\nmaterials = { a = \"dark\" }\n")
        .unwrap();
    assert_eq!(s.objects.len(), 2);
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    let w = &s.warnings[0];
    let line = CAMERA_AND_LIGHT.lines().count() + 2 + 3;
    assert!(w.starts_with(&format!("t.toml:{line}:")), "{w}");
    assert!(
        w.contains("object[0].materials") && w.contains("usemtl b"),
        "{w}"
    );
    assert!(w.contains("`plain`"), "{w}");
}

#[test]
fn unknown_names_in_the_mapping_are_errors() {
    let (line, shown, e) = object_error(
        "obj = \"m/groups.obj\"\nmaterial = \"plain\"\nmaterials = { a = \"dark\", c = \"dark\" }\n",
    );
    assert_eq!(line, 3, "{shown}");
    assert_eq!(e.kind, SceneErrorKind::UnknownName, "{shown}");
    assert_eq!(e.key.as_deref(), Some("object[0].materials.c"), "{shown}");
    assert!(
        e.message.contains("no `usemtl c`") && e.message.contains("a, b"),
        "{shown}"
    );
    let (line, shown, e) = object_error(
        "obj = \"m/groups.obj\"\nmaterial = \"plain\"\nmaterials = { a = \"glass\" }\n",
    );
    assert_eq!(line, 3, "{shown}");
    assert_eq!(e.kind, SceneErrorKind::UnknownName, "{shown}");
    assert!(e.message.contains("unknown material `glass`"), "{shown}");
    // A shape has no groups to map.
    let (_, shown, e) =
        object_error("shape = \"sphere\"\nradius = 1\nmaterial = \"plain\"\nmaterials = {}\n");
    assert_eq!(e.kind, SceneErrorKind::Conflict, "{shown}");
}

#[test]
fn kd_from_the_mtl_makes_a_textured_copy_per_texture() {
    let s = scene(
        "obj = \"m/groups.obj\"\nmaterial = \"plain\"\nmaterials = { a = \"skin\", b = \"dark\" }\n",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.objects.len(), 3);
    let skin = s
        .objects
        .iter()
        .find(|o| o.name.ends_with("/skin (map_Kd m/tex/a.png)"));
    let skin = skin.unwrap_or_else(|| {
        panic!(
            "{:?}",
            s.objects.iter().map(|o| &o.name).collect::<Vec<_>>()
        )
    });
    let Material::Translucent(t) = &s.materials[skin.material] else {
        panic!("not translucent");
    };
    let Medium::Reflectance {
        kd: ColorParam::Texture(tex),
        ..
    } = &t.medium
    else {
        panic!("kd is not the texture: {:?}", t.medium);
    };
    // The sRGB texel 200 decodes to linear 0.578.
    let texel = tex.sample(glam::Vec2::new(0.25, 0.5));
    assert!((texel.x - 0.578).abs() < 2e-3, "{texel}");
    // A second object with the same texture reuses the copy.
    let text = format!(
        "{CAMERA_AND_LIGHT}\n[[object]]\nobj = \"m/groups.obj\"\nmaterial = \"plain\"\n\
         materials = {{ a = \"skin\" }}\n[[object]]\nobj = \"m/groups.obj\"\nmaterial = \"plain\"\n\
         materials = {{ a = \"skin\" }}\ntranslate = [3, 0, 0]\n"
    );
    let s = parse_scene(&text, &origin()).unwrap();
    assert_eq!(s.materials.len(), 4, "three named and one copy");
}

#[test]
fn kd_from_the_mtl_failures_are_located_and_name_the_files() {
    let cases = [
        (
            "obj = \"m/nolib.obj\"\nmaterial = \"plain\"\nmaterials = { a = \"skin\" }\n",
            SceneErrorKind::Io,
            "m/missing.mtl (mtllib at m/nolib.obj line 1)",
        ),
        (
            "obj = \"m/nomtllib.obj\"\nmaterial = \"plain\"\nmaterials = { a = \"skin\" }\n",
            SceneErrorKind::Mesh,
            "has no mtllib",
        ),
        (
            "obj = \"m/groups.obj\"\nmaterial = \"plain\"\nmaterials = { b = \"skin\" }\n",
            SceneErrorKind::Mesh,
            "`newmtl b` in m/lib.mtl has no map_Kd",
        ),
        (
            // The faces before any usemtl have no .mtl material.
            "obj = \"m/groups.obj\"\nmaterial = \"skin\"\nmaterials = { b = \"dark\" }\n",
            SceneErrorKind::Mesh,
            "before any usemtl",
        ),
    ];
    for (object, kind, words) in cases {
        let (line, shown, e) = object_error(object);
        assert_eq!(line, 1, "{shown}");
        assert_eq!(e.kind, kind, "{shown}");
        assert_eq!(e.key.as_deref(), Some("object[0].obj"), "{shown}");
        assert!(e.message.contains(words), "{words}: {shown}");
    }
    // A kd = "mtl" material on a built-in shape.
    let (line, shown, e) = object_error("shape = \"sphere\"\nradius = 1\nmaterial = \"skin\"\n");
    assert_eq!((line, e.kind), (3, SceneErrorKind::Conflict), "{shown}");
    // A texture the library names but that does not exist.
    let mut o = origin();
    if let SceneOrigin::Embedded { files, .. } = &mut o {
        files.retain(|(n, _)| n != "m/tex/a.png");
    }
    let text = format!(
        "{CAMERA_AND_LIGHT}\n[[object]]\nobj = \"m/groups.obj\"\nmaterial = \"plain\"\n\
         materials = {{ a = \"skin\" }}\n"
    );
    let e = parse_scene(&text, &o).expect_err("missing texture");
    assert!(
        e.message.contains("m/tex/a.png") && e.message.contains("in m/lib.mtl"),
        "{e}"
    );
}

#[test]
fn inside_out_meshes_are_flipped_with_a_warning() {
    let s = scene("obj = \"m/inside-out.obj\"\nmaterial = \"plain\"\n").unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    let line = CAMERA_AND_LIGHT.lines().count() + 3;
    let w = &s.warnings[0];
    assert!(w.starts_with(&format!("t.toml:{line}:")), "{w}");
    assert!(w.contains("inside out"), "{w}");
    assert!(crate::scene::sanity::signed_volume(&s.objects[0].mesh) > 0.0);
    // PLY (and glTF) meshes get the same repair; their computed normals follow the flip.
    let s = scene("mesh = \"m/inside-out.ply\"\nmaterial = \"plain\"\n").unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("inside out"), "{}", s.warnings[0]);
    let mesh = &s.objects[0].mesh;
    assert!(crate::scene::sanity::signed_volume(mesh) > 0.0);
    let centre = mesh.positions.iter().copied().sum::<glam::Vec3>() / 4.0;
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert!(n.dot(*p - centre) > 0.0, "normal {n} at {p} points in");
    }
}

#[test]
fn copies_are_dropped_before_the_winding_is_checked() {
    for file in ["m/inside-out-copy.obj", "m/inside-out-copy.ply"] {
        let s = scene(&format!("mesh = \"{file}\"\nmaterial = \"plain\"\n")).unwrap();
        assert_eq!(s.warnings.len(), 2, "{file}: {:?}", s.warnings);
        assert!(
            s.warnings[0].contains("coincident copies"),
            "{}",
            s.warnings[0]
        );
        assert!(s.warnings[1].contains("inside out"), "{}", s.warnings[1]);
        let mesh = &s.objects[0].mesh;
        assert_eq!(mesh.triangles.len(), 4, "{file}");
        assert!(crate::scene::sanity::signed_volume(mesh) > 0.0, "{file}");
    }
}

#[test]
fn file_normals_stay_with_their_vertices_when_copies_are_dropped() {
    let s = scene("mesh = \"m/copy-normals.obj\"\nmaterial = \"plain\"\n").unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    let mesh = &s.objects[0].mesh;
    assert_eq!((mesh.positions.len(), mesh.triangles.len()), (3, 1));
    // The kept triangle's own normals, not the copy's and not ones computed from the winding.
    for n in &mesh.normals {
        assert!((*n - glam::Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6, "{n}");
    }
}

#[test]
fn bytes_that_are_not_utf8_pass_in_comments_and_names_only() {
    let s = scene("obj = \"m/latin1.obj\"\nmaterial = \"plain\"\n").unwrap();
    assert_eq!(s.objects[0].mesh.triangles.len(), 1);
    let (line, shown, e) = object_error("obj = \"m/latin1-usemtl.obj\"\nmaterial = \"plain\"\n");
    assert_eq!(line, 1, "{shown}");
    assert!(shown.contains("line 4: not UTF-8"), "{shown}");
    assert_eq!(e.kind, SceneErrorKind::Mesh);
}

#[test]
fn absurd_coordinates_are_rejected() {
    let (line, shown, _) = object_error("obj = \"m/huge.obj\"\nmaterial = \"plain\"\n");
    assert_eq!(line, 1, "{shown}");
    assert!(shown.contains("farther than 1e12"), "{shown}");
    // In range in the file, out of range once scaled.
    let (line, shown, _) =
        object_error("shape = \"sphere\"\nradius = 1\nscale = 1e13\nmaterial = \"plain\"\n");
    assert_eq!(line, 1, "{shown}");
    assert!(
        shown.contains("after its transform") && shown.contains("farther than"),
        "{shown}"
    );
}

#[test]
fn weld_and_crease_angle_smooth_a_faceted_mesh() {
    // The inside-out tetrahedron, flipped, then welded: each corner's normal is the sum of its
    // three faces' normals (crease 180°), pointing away from the opposite face.
    let s = scene("obj = \"m/inside-out.obj\"\nmaterial = \"plain\"\nweld = true\n").unwrap();
    let m = &s.objects[0].mesh;
    assert_eq!(m.positions.len(), 4, "one vertex per corner, no creases");
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let centroid = glam::Vec3::splat(0.25);
        assert!(n.dot(*p - centroid) > 0.0, "{p} {n}");
    }
    // The tetrahedron's face normals are 90° or more apart: a 30° crease angle keeps every
    // face flat (12 corners, face normals).
    let s = scene("obj = \"m/inside-out.obj\"\nmaterial = \"plain\"\ncrease_angle = 30\n").unwrap();
    let m = &s.objects[0].mesh;
    assert_eq!(m.positions.len(), 12);
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let face = (b - a).cross(c - a).normalize();
        assert!(
            t.iter()
                .all(|&i| (m.normals[i as usize] - face).length() < 1e-6)
        );
    }
    for (object, kind) in [
        (
            "obj = \"m/inside-out.obj\"\nmaterial = \"plain\"\ncrease_angle = 181\n",
            SceneErrorKind::OutOfRange,
        ),
        (
            "obj = \"m/inside-out.obj\"\nmaterial = \"plain\"\nweld = false\ncrease_angle = 30\n",
            SceneErrorKind::Conflict,
        ),
        (
            "shape = \"sphere\"\nradius = 1\nmaterial = \"plain\"\nweld = true\n",
            SceneErrorKind::Conflict,
        ),
    ] {
        let (_, shown, e) = object_error(object);
        assert_eq!(e.kind, kind, "{shown}");
    }
}

/// glTF primitives' material names map like OBJ groups: one object per scene material; a
/// `kd = "mtl"` material cannot apply to a glTF mesh.
#[test]
fn gltf_material_names_map_to_scene_materials() {
    let s = scene(
        "name = \"g\"\nmesh = \"m/two.gltf\"\nmaterial = \"plain\"\n\
         materials = { jade = \"dark\" }\n",
    )
    .unwrap();
    let names: Vec<_> = s.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["g/plain", "g/dark"]);
    assert_eq!(material_name(&s, 0), "plain");
    assert_eq!(material_name(&s, 1), "dark");
    assert!(s.objects.iter().all(|o| o.mesh.triangles.len() == 1));
    // `wax` is not mapped: a warning, and the default material.
    assert!(
        s.warnings.iter().any(|w| w.contains("wax")),
        "{:?}",
        s.warnings
    );
    let err =
        scene("mesh = \"m/two.gltf\"\nmaterial = \"plain\"\nmaterials = { wax = \"skin\" }\n")
            .unwrap_err();
    assert!(err.to_string().contains("kd = \"mtl\""), "{err}");
}
