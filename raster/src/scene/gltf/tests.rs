//! Tests of the glTF reader: node transforms against an independent composition, GLB and
//! external buffers, material groups, and malformed files as errors.

use super::*;

/// A quad in the z = 0 plane (two triangles, normals +z, UVs = xy): positions, normals, UVs,
/// u16 indices, packed in that order.
fn quad_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    let corners = [[0.0f32, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    for [x, y] in corners {
        for v in [x, y, 0.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    for _ in corners {
        for v in [0.0f32, 0.0, 1.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    for [x, y] in corners {
        for v in [x, y] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// A document over [`quad_buffer`] with the given `nodes`, `scenes` and primitive list, the
/// buffer given by `buffer` (a JSON object).
fn document(nodes: &str, scenes: &str, primitives: &str, buffer: &str) -> String {
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scenes": {scenes},
  "nodes": {nodes},
  "meshes": [{{"name": "quad", "primitives": {primitives}}}],
  "materials": [{{"name": "wax"}}, {{"name": "jade"}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
      "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3"}},
    {{"bufferView": 0, "byteOffset": 96, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}
  ],
  "bufferViews": [
    {{"buffer": 0, "byteLength": 128}},
    {{"buffer": 0, "byteOffset": 128, "byteLength": 12}}
  ],
  "buffers": [{buffer}]
}}"#
    )
}

fn embedded() -> String {
    format!(
        r#"{{"byteLength": 140, "uri": "data:application/octet-stream;base64,{}"}}"#,
        base64::engine::general_purpose::STANDARD.encode(quad_buffer())
    )
}

const ONE_PRIMITIVE: &str = r#"[{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]"#;

/// The quad of one node and [`ONE_PRIMITIVE`] with `buffer` (JSON objects) as its buffers.
fn one_quad(buffer: &str) -> String {
    document(
        r#"[{"mesh": 0}]"#,
        r#"[{"nodes": [0]}]"#,
        ONE_PRIMITIVE,
        buffer,
    )
}

/// Parses `text`, serving [`quad_buffer`] for every external file; also returns the names
/// asked for, in order.
fn parse_serving_quads(text: &str) -> (Result<GltfMesh, GltfError>, Vec<String>) {
    let mut asked = Vec::new();
    let parsed = parse_gltf(text.as_bytes(), &mut |name| {
        asked.push(name.to_string());
        Ok(quad_buffer())
    });
    (parsed, asked)
}

fn no_files(name: &str) -> Result<Vec<u8>, String> {
    Err(format!("no file {name}"))
}

fn parse(text: &str) -> Result<GltfMesh, GltfError> {
    parse_gltf(text.as_bytes(), &mut no_files)
}

/// Rotation by `degrees` about the unit axis `a` (Rodrigues' formula), written out.
fn rotation(a: [f64; 3], degrees: f64) -> [[f64; 3]; 3] {
    let (s, c) = degrees.to_radians().sin_cos();
    let [x, y, z] = a;
    [
        [
            c + x * x * (1.0 - c),
            x * y * (1.0 - c) - z * s,
            x * z * (1.0 - c) + y * s,
        ],
        [
            y * x * (1.0 - c) + z * s,
            c + y * y * (1.0 - c),
            y * z * (1.0 - c) - x * s,
        ],
        [
            z * x * (1.0 - c) - y * s,
            z * y * (1.0 - c) + x * s,
            c + z * z * (1.0 - c),
        ],
    ]
}

fn apply(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| (0..3).map(|k| m[r][k] * v[k]).sum())
}

#[test]
fn node_hierarchy_transforms_positions_and_normals() {
    // Root: a column-major matrix = translation (1, 2, 3) · rotation 90° about z. Child: TRS
    // with translation (0, 0, 1), 60° about x, scale (2, 3, 4).
    let (s60, c60) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let nodes = format!(
        r#"[{{"matrix": [0,1,0,0, -1,0,0,0, 0,0,1,0, 1,2,3,1], "children": [1]}},
           {{"translation": [0, 0, 1], "rotation": [{s60}, 0, 0, {c60}], "scale": [2, 3, 4],
             "mesh": 0}}]"#
    );
    let g = parse(&document(
        &nodes,
        r#"[{"nodes": [0]}]"#,
        ONE_PRIMITIVE,
        &embedded(),
    ))
    .unwrap();
    let rz = rotation([0.0, 0.0, 1.0], 90.0);
    let rx = rotation([1.0, 0.0, 0.0], 60.0);
    let world = |p: [f64; 3]| {
        let scaled = [2.0 * p[0], 3.0 * p[1], 4.0 * p[2]];
        let child = apply(&rx, scaled);
        let child = [child[0], child[1], child[2] + 1.0];
        let root = apply(&rz, child);
        Vec3::new(
            (root[0] + 1.0) as f32,
            (root[1] + 2.0) as f32,
            (root[2] + 3.0) as f32,
        )
    };
    let want: Vec<Vec3> = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]
    .map(world)
    .to_vec();
    for (got, want) in g.mesh.positions.iter().zip(&want) {
        assert!(
            (*got - *want).length() <= 4e-7 * want.length(),
            "{got} vs {want}"
        );
    }
    // The normal: +z through the inverse transpose of the linear part, i.e. the rotations of
    // (0, 0, 1/4).
    let n = apply(&rz, apply(&rx, [0.0, 0.0, 0.25]));
    let n = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32).normalize();
    for got in &g.mesh.normals {
        assert!((*got - n).length() < 1e-6, "{got} vs {n}");
    }
    // UVs untouched, triangles as indexed (no mirroring), one material group.
    assert_eq!(
        g.mesh.uvs.unwrap(),
        vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]
    );
    assert_eq!(g.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(
        g.groups,
        vec![MaterialGroup {
            material: Some("wax".into()),
            triangles: 0..2
        }]
    );
}

#[test]
fn mirroring_reverses_the_winding_and_instances_merge() {
    // The mesh twice: once as is, once mirrored in x; the default scene is scene 1.
    let nodes = r#"[{"mesh": 0}, {"mesh": 0, "scale": [-1, 1, 1]}, {"mesh": 0}]"#;
    let g = parse(&document(
        nodes,
        r#"[{"nodes": [2]}, {"nodes": [0, 1]}]"#,
        ONE_PRIMITIVE,
        &embedded(),
    ))
    .map(|g| g.mesh);
    // Scene 0 is the first but "scene" is not given: scene 0 is used.
    let g = g.unwrap();
    assert_eq!(g.triangles.len(), 2, "the first scene, one instance");
    let text = document(
        nodes,
        r#"[{"nodes": [2]}, {"nodes": [0, 1]}]"#,
        ONE_PRIMITIVE,
        &embedded(),
    )
    .replacen('{', r#"{"scene": 1,"#, 1);
    let m = parse(&text).unwrap().mesh;
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]]
    );
    assert_eq!(m.positions[5], Vec3::new(-1.0, 0.0, 0.0));
    // Mirrored normals stay +z (x flips, z does not), and the winding seen from +z is again
    // counter-clockwise.
    assert!(m.normals.iter().all(|n| *n == Vec3::Z));
    let [a, b, c] = m.triangles[2].map(|i| m.positions[i as usize]);
    assert!((b - a).cross(c - a).z > 0.0);
}

#[test]
fn a_file_named_by_two_buffers_is_read_once() {
    let reference = parse(&one_quad(&embedded())).unwrap();
    // The attributes from buffer 0, the indices from buffer 1: the same file, declared with
    // different lengths (each buffer is checked against its own).
    let text = one_quad(
        r#"{"byteLength": 128, "uri": "quad.bin"}, {"byteLength": 140, "uri": "quad.bin"}"#,
    )
    .replace(
        r#"{"buffer": 0, "byteOffset": 128"#,
        r#"{"buffer": 1, "byteOffset": 128"#,
    );
    assert!(text.contains(r#"{"buffer": 1, "byteOffset": 128"#));
    let (external, asked) = parse_serving_quads(&text);
    let external = external.unwrap();
    assert_eq!(asked, ["quad.bin"]);
    assert_eq!(external.mesh.positions, reference.mesh.positions);
    assert_eq!(external.mesh.triangles, reference.mesh.triangles);
    // Two names, two reads; and a view beyond its own buffer's declared length is still an
    // error when the file behind it is longer.
    let two_files = text.replacen(r#""uri": "quad.bin"}"#, r#""uri": "other.bin"}"#, 1);
    let (parsed, asked) = parse_serving_quads(&two_files);
    parsed.unwrap();
    assert_eq!(asked, ["other.bin", "quad.bin"]);
    let short_view = text.replace(r#""byteLength": 128, "uri""#, r#""byteLength": 100, "uri""#);
    let err = parse_serving_quads(&short_view).0.unwrap_err();
    assert!(
        err.to_string().contains("outside its buffer of 100 bytes"),
        "{err}"
    );
}

#[test]
fn glb_and_external_buffers_read_the_same_bytes() {
    let reference = parse(&one_quad(&embedded())).unwrap();
    // External file with a %-escaped name.
    let (external, asked) = parse_serving_quads(&one_quad(
        r#"{"byteLength": 140, "uri": "quad%20data.bin"}"#,
    ));
    let external = external.unwrap();
    assert_eq!(asked, ["quad data.bin"]);
    assert_eq!(external.mesh.positions, reference.mesh.positions);
    assert_eq!(external.mesh.triangles, reference.mesh.triangles);
    // GLB: the same JSON without a URI, the buffer in the BIN chunk.
    let mut json = one_quad(r#"{"byteLength": 140}"#).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin = quad_buffer();
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend_from_slice(&(json.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&json);
    glb.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&bin);
    let binary = parse_gltf(&glb, &mut no_files).unwrap();
    assert_eq!(binary.mesh.positions, reference.mesh.positions);
    assert_eq!(binary.mesh.normals, reference.mesh.normals);
    assert_eq!(binary.mesh.uvs, reference.mesh.uvs);
    assert_eq!(binary.mesh.triangles, reference.mesh.triangles);
    // Every truncation of the GLB is an error, not a panic.
    for len in 0..glb.len() {
        assert!(
            parse_gltf(&glb[..len], &mut no_files).is_err(),
            "cut at {len}"
        );
    }
}

#[test]
fn primitives_form_material_groups_and_partial_normals_are_recomputed() {
    let primitives = r#"[
        {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "material": 0},
        {"attributes": {"POSITION": 0}, "indices": 4, "material": 1},
        {"attributes": {"POSITION": 0}, "indices": 4}]"#;
    let g = parse(&document(
        r#"[{"mesh": 0}]"#,
        r#"[{"nodes": [0]}]"#,
        primitives,
        &embedded(),
    ))
    .unwrap();
    let names: Vec<_> = g
        .groups
        .iter()
        .map(|g| (g.material.as_deref(), g.triangles.clone()))
        .collect();
    assert_eq!(
        names,
        [(Some("wax"), 0..2), (Some("jade"), 2..3), (None, 3..4)]
    );
    assert!(g.mesh.uvs.is_none());
    // Only some primitives have normals: all are computed. Unused vertices of the last two
    // primitives (vertex 3 of each) are dropped.
    assert_eq!(g.mesh.positions.len(), 4 + 3 + 3);
    assert!(g.mesh.normals.iter().all(|n| *n == Vec3::Z));
}

#[test]
fn malformed_files_are_errors_naming_the_problem() {
    let with = |nodes: &str, primitives: &str, buffer: &str| {
        document(nodes, r#"[{"nodes": [0]}]"#, primitives, buffer)
    };
    let node = r#"[{"mesh": 0}]"#;
    let cases = [
        (
            with(
                node,
                &ONE_PRIMITIVE.replace("\"material\": 0", "\"mode\": 1"),
                &embedded(),
            ),
            "only triangles",
        ),
        (
            with(
                node,
                &ONE_PRIMITIVE.replace("\"indices\": 3", "\"indices\": 4"),
                &embedded(),
            )
            .replace(
                r#""count": 3, "type": "SCALAR""#,
                r#""count": 2, "type": "SCALAR""#,
            ),
            "whole triangles",
        ),
        (
            with(node, ONE_PRIMITIVE, &embedded()).replace("\"count\": 6", "\"count\": 7"),
            "overruns",
        ),
        (
            with(node, ONE_PRIMITIVE, &embedded()).replace(
                r#""byteLength": 128}"#,
                r#""byteLength": 128, "byteStride": 4}"#,
            ),
            "stride",
        ),
        (
            with(node, ONE_PRIMITIVE, &embedded())
                .replace("\"byteLength\": 140", "\"byteLength\": 400"),
            "declares 400 bytes",
        ),
        (
            // The views reach byte 140; the data has them, but the buffer is 136 bytes long.
            with(node, ONE_PRIMITIVE, &embedded())
                .replace("\"byteLength\": 140", "\"byteLength\": 136"),
            "buffer view 1 (bytes 128..+12) lies outside its buffer of 136 bytes",
        ),
        (
            with(
                node,
                ONE_PRIMITIVE,
                r#"{"byteLength": 140, "uri": "data:x;base64,@@@@"}"#,
            ),
            "base64",
        ),
        (
            with(
                node,
                ONE_PRIMITIVE,
                r#"{"byteLength": 140, "uri": "https://x/q.bin"}"#,
            ),
            "relative",
        ),
        (
            with(
                node,
                ONE_PRIMITIVE,
                r#"{"byteLength": 140, "uri": "q.bin"}"#,
            ),
            "no file q.bin",
        ),
        (
            with(node, ONE_PRIMITIVE, r#"{"byteLength": 140}"#),
            "binary chunk",
        ),
        (
            with(
                r#"[{"mesh": 0, "children": [0]}]"#,
                ONE_PRIMITIVE,
                &embedded(),
            ),
            "tree",
        ),
        (document(node, "[]", ONE_PRIMITIVE, &embedded()), "no scene"),
        (with("[{}]", ONE_PRIMITIVE, &embedded()), "no triangles"),
        (
            with(node, ONE_PRIMITIVE, &embedded()).replace("\"mesh\": 0", "\"mesh\": 5"),
            "malformed glTF",
        ),
        (
            with(
                node,
                &ONE_PRIMITIVE.replace("\"NORMAL\": 1", "\"NORMAL\": 2"),
                &embedded(),
            ),
            "NORMAL",
        ),
        ("{".to_string(), "malformed glTF"),
    ];
    for (text, needle) in cases {
        let e = parse(&text).expect_err(needle);
        assert!(e.message.contains(needle), "'{e}' lacks '{needle}'");
    }
    // An index beyond the vertices.
    let mut bad = quad_buffer();
    let last = bad.len() - 2;
    bad[last..].copy_from_slice(&9u16.to_le_bytes());
    let buffer = format!(
        r#"{{"byteLength": 140, "uri": "data:;base64,{}"}}"#,
        base64::engine::general_purpose::STANDARD.encode(&bad)
    );
    let e = parse(&with(node, ONE_PRIMITIVE, &buffer)).unwrap_err();
    assert!(e.message.contains("index 9 out of range"), "{e}");
    assert!(
        e.message.contains("mesh 0 'quad' primitive 0 (node 0)"),
        "{e}"
    );
}
