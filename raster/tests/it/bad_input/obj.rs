//! OBJ meshes: missing, malformed, truncated.

use super::harness::{CONSTANT, Sandbox, render, scene};

/// A small valid OBJ: an octahedron with texture coordinates and normals (so that a cut can
/// land inside any kind of statement).
const OCTAHEDRON: &str = "# octahedron
o shape
v 0.5 0 0
v -0.5 0 0
v 0 0.5 0
v 0 -0.5 0
v 0 0 0.5
v 0 0 -0.5
vt 0 0
vt 1 0
vt 0.5 1
vn 0.5773503 0.5773503 0.5773503
vn -0.5773503 0.5773503 0.5773503
vn -0.5773503 -0.5773503 0.5773503
vn 0.5773503 -0.5773503 0.5773503
vn 0.5773503 0.5773503 -0.5773503
vn -0.5773503 0.5773503 -0.5773503
vn -0.5773503 -0.5773503 -0.5773503
vn 0.5773503 -0.5773503 -0.5773503
f 1/1/1 3/2/1 5/3/1
f 3/1/2 2/2/2 5/3/2
f 2/1/3 4/2/3 5/3/3
f 4/1/4 1/2/4 5/3/4
f 3/1/5 1/2/5 6/3/5
f 2/1/6 3/2/6 6/3/6
f 4/1/7 2/2/7 6/3/7
f 1/1/8 4/2/8 6/3/8
";

fn mesh_sandbox(tag: &str) -> Sandbox {
    let sb = Sandbox::with_scene(tag, &scene("obj = \"mesh.obj\"", CONSTANT));
    sb.write("mesh.obj", OCTAHEDRON.as_bytes());
    sb
}

#[test]
fn valid_obj_renders() {
    let sb = mesh_sandbox("obj-valid");
    sb.succeeds(&render(&[]));
}

/// Writes the octahedron as `mesh.obj`, its last line a comment of NUL bytes that makes the file
/// `len` bytes long. The file is sparse: no disk space and no time to write it.
pub(super) fn write_padded_octahedron(sb: &Sandbox, len: u64) {
    let mut text = OCTAHEDRON.to_string();
    text.push('#');
    sb.write_sparse("mesh.obj", text.as_bytes(), len);
}

/// An OBJ of more than 1 GiB (the limit of other files a scene reads) is read: a scanned mesh
/// of 25 M triangles already takes that much text.
#[test]
#[cfg(target_pointer_width = "64")]
fn obj_text_beyond_one_gib_is_read() {
    let sb = mesh_sandbox("obj-beyond-1gib");
    let len = (1u64 << 30) + (1 << 20);
    write_padded_octahedron(&sb, len);
    let out = sb.succeeds(&render(&["--samples", "50"]));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("limit"), "{stderr}");
    assert_eq!(std::fs::metadata(sb.path("mesh.obj")).unwrap().len(), len);
}

/// The octahedron with 500 coincident copies of its faces, half of them wound the other way:
/// the copies are dropped with one warning, and the render is the octahedron's (before, the
/// sampler placed and thinned samples on 500 layers of the same surface).
#[test]
fn coincident_copies_of_faces_are_dropped_with_a_warning() {
    let sb = mesh_sandbox("obj-copies");
    sb.succeeds(&render(&[]));
    let single = sb.read("out.png");
    let mut obj = OCTAHEDRON.to_string();
    for k in 0..500 {
        let face = OCTAHEDRON
            .lines()
            .filter(|l| l.starts_with("f "))
            .nth(k % 8);
        let face = face.expect("eight faces");
        if k % 2 == 0 {
            obj.push_str(face);
        } else {
            let corners: Vec<&str> = face.split_whitespace().skip(1).collect();
            obj.push_str(&format!("f {} {} {}", corners[2], corners[1], corners[0]));
        }
        obj.push('\n');
    }
    sb.write("mesh.obj", obj.as_bytes());
    let out = sb.succeeds(&render(&[]));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("warning: scene.toml:12:")
            && stderr.contains(
                "`mesh.obj`: 500 of its 508 triangles repeat the corners of another \
                 (coincident copies); they were dropped"
            )
            && stderr.lines().count() == 1,
        "{stderr}"
    );
    assert_eq!(sb.read("out.png"), single, "the octahedron's image");
}

#[test]
fn missing_obj() {
    let sb = Sandbox::with_scene("obj-missing", &scene("obj = \"nosuch.obj\"", CONSTANT));
    sb.fails(
        &render(&[]),
        1,
        &[
            "scene.toml:12:",
            "object[0].obj",
            "cannot read mesh nosuch.obj",
        ],
    );
}

/// Malformed OBJ files: each error names the scene key, the OBJ file and, where there is
/// one, the OBJ line.
#[test]
fn malformed_obj() {
    let cases: &[(&str, &[u8], &[&str])] = &[
        (
            "index out of range",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n",
            &["line 4", "face vertex index 7 out of range (3 defined)"],
        ),
        (
            "index 0",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
            &["line 4", "index 0 out of range"],
        ),
        (
            "relative index before the first vertex",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9\n",
            &["line 4", "index -9 out of range"],
        ),
        (
            "garbage index",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n",
            &["line 4", "bad face index `3x`"],
        ),
        (
            "texture coordinate index out of range",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/5 3/1\n",
            &["line 5", "texture coordinate index 5"],
        ),
        (
            "normal index out of range",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//4 3//1\n",
            &["line 5", "normal index 4"],
        ),
        (
            "NaN vertex",
            b"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n",
            &["vertex 2 is not finite"],
        ),
        (
            "vertex beyond f32",
            b"v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n",
            &["vertex 2 is not finite"],
        ),
        (
            "malformed number",
            b"v 0 0 0\nv 1 0 0\nv 0 1",
            &["line 3: malformed OBJ: position parse error"],
        ),
        ("no faces", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", &["no faces"]),
        ("empty file", b"", &["no faces"]),
        (
            "zero area",
            b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
            &["no usable surface area"],
        ),
        (
            "not UTF-8",
            b"v 0 0 0\n\xff\xfe\x00garbage\n",
            &["not UTF-8"],
        ),
        (
            "binary junk",
            &[0x7f, b'E', b'L', b'F', 2, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0],
            &["mesh.obj"],
        ),
    ];
    let sb = mesh_sandbox("obj-malformed");
    for (what, bytes, needles) in cases {
        sb.write("mesh.obj", bytes);
        let mut all = vec!["scene.toml:12:", "object[0].obj", "mesh.obj"];
        all.extend_from_slice(needles);
        let message = sb.fails(&render(&[]), 1, &all);
        assert!(!message.contains("internal"), "{what}: {message}");
    }
    // A directory where the OBJ should be.
    std::fs::remove_file(sb.path("mesh.obj")).unwrap();
    std::fs::create_dir(sb.path("mesh.obj")).unwrap();
    sb.fails(
        &render(&[]),
        1,
        &["object[0].obj", "cannot read mesh mesh.obj"],
    );
}

/// The OBJ cut at every 3rd byte: each prefix either renders (a cut between statements leaves
/// a smaller valid mesh) or fails with a message naming the mesh file, leaving the outputs
/// alone; never a panic. Every cut before the first face fails.
#[test]
fn truncated_obj() {
    let sb = mesh_sandbox("obj-truncated");
    let bytes = OCTAHEDRON.as_bytes();
    let first_face = OCTAHEDRON.find("\nf ").unwrap() + 1;
    let mut rendered = 0;
    for cut in (0..bytes.len()).step_by(3) {
        sb.write("mesh.obj", &bytes[..cut]);
        let failed = sb.succeeds_or_fails(&render(&["--samples", "50"]), "mesh.obj");
        assert!(failed || cut > first_face, "cut at {cut} rendered");
        rendered += usize::from(!failed);
    }
    assert!(rendered > 0, "no cut after the first face rendered");
}
