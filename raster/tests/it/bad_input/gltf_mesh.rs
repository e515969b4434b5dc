//! Binary glTF meshes at the sizes of scans: files beyond 1 GiB read, accessors beyond memory
//! refused.

use super::harness::{CONSTANT, Sandbox, render, scene};

/// The glTF document of [`write_glb`]'s mesh, its one buffer `bin_len` bytes long (`uri`:
/// where it lies, or the GLB's binary chunk for `None`).
fn document(bin_len: u64, indices: Option<u64>, uri: Option<&str>) -> String {
    let mut views = vec![r#"{"buffer":0,"byteOffset":0,"byteLength":36}"#.to_string()];
    let mut accessors = vec![
        r#"{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[0.5,0.5,0.5]}"#
            .to_string(),
    ];
    let mut primitive = r#"{"attributes":{"POSITION":0}"#.to_string();
    if let Some(count) = indices {
        views.push(format!(
            r#"{{"buffer":0,"byteOffset":36,"byteLength":{count}}}"#
        ));
        accessors.push(format!(
            r#"{{"bufferView":1,"componentType":5121,"count":{count},"type":"SCALAR"}}"#
        ));
        primitive.push_str(r#","indices":1"#);
    }
    primitive.push('}');
    let uri = uri.map_or(String::new(), |u| format!(r#","uri":"{u}""#));
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{primitive}]}}],"buffers":[{{"byteLength":{bin_len}{uri}}}],"bufferViews":[{}],"accessors":[{}]}}"#,
        views.join(","),
        accessors.join(",")
    )
}

/// The start of the buffer: one triangle's positions and, with indices, its indices 0 1 2.
fn triangle(indices: Option<u64>) -> Vec<u8> {
    let mut bytes = Vec::new();
    for corner in [[0.5f32, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]] {
        for c in corner {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    if indices.is_some() {
        bytes.extend_from_slice(&[0, 1, 2]);
    }
    bytes
}

/// Writes `mesh.glb`: one triangle's positions at the start of a binary chunk of `bin_len`
/// bytes, and, with `indices`, an accessor of that many unsigned-byte indices right after them
/// (the first triangle 0 1 2, the rest zeros).
fn write_glb(sb: &Sandbox, bin_len: u64, indices: Option<u64>) {
    let mut json = document(bin_len, indices, None).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let bin_len = bin_len.next_multiple_of(4);
    let total = 12 + 8 + json.len() as u64 + 8 + bin_len;
    let mut bytes = b"glTF".to_vec();
    bytes.extend_from_slice(&2u32.to_le_bytes());
    bytes.extend_from_slice(&u32::try_from(total).unwrap().to_le_bytes());
    bytes.extend_from_slice(&(json.len() as u32).to_le_bytes());
    bytes.extend_from_slice(b"JSON");
    bytes.extend_from_slice(&json);
    bytes.extend_from_slice(&u32::try_from(bin_len).unwrap().to_le_bytes());
    bytes.extend_from_slice(b"BIN\0");
    bytes.extend_from_slice(&triangle(indices));
    sb.write_sparse("mesh.glb", &bytes, total);
}

/// A binary glTF of more than 1 GiB (the limit of the files a scene names other than meshes)
/// is read, its binary chunk borrowed from the file's bytes rather than copied.
#[test]
#[cfg(target_pointer_width = "64")]
fn glb_beyond_one_gib_is_read() {
    let sb = Sandbox::with_scene("glb-beyond-1gib", &scene("mesh = \"mesh.glb\"", CONSTANT));
    write_glb(&sb, (1 << 30) + (1 << 20), None);
    assert!(std::fs::metadata(sb.path("mesh.glb")).unwrap().len() > 1 << 30);
    sb.succeeds(&render(&["--samples", "50"]));
}

/// A binary glTF whose index accessor does not fit in memory once read is refused with the
/// size it needs (under 0.75 GiB of address space, 300 M one-byte indices become 1.1 GiB of
/// 32-bit ones), instead of aborting when the list is allocated.
#[test]
#[cfg(target_os = "linux")]
fn glb_accessors_larger_than_memory_are_refused() {
    let sb = Sandbox::with_scene("glb-accessors", &scene("mesh = \"mesh.glb\"", CONSTANT))
        .with_address_space(3 << 18);
    let count = 300_000_000;
    write_glb(&sb, 36 + count, Some(count));
    sb.fails(
        &["scene.toml"],
        1,
        &[
            "object[0].mesh",
            "mesh.glb: mesh 0 primitive 0 (node 0): out of memory: could not allocate 1.1 GiB \
             for the glTF file's vertices and triangles (use a coarser mesh, or free memory)",
        ],
    );
}

/// A `.gltf` whose buffer file is more than 1 GiB is read: the buffers a glTF names are as
/// large as the mesh.
#[test]
#[cfg(target_pointer_width = "64")]
fn gltf_buffer_beyond_one_gib_is_read() {
    let sb = Sandbox::with_scene(
        "gltf-bin-beyond-1gib",
        &scene("mesh = \"mesh.gltf\"", CONSTANT),
    );
    let len = (1 << 30) + (1 << 20);
    sb.write(
        "mesh.gltf",
        document(len, None, Some("mesh.bin")).as_bytes(),
    );
    sb.write_sparse("mesh.bin", &triangle(None), len);
    sb.succeeds(&render(&["--samples", "50"]));
}

/// A `.gltf` whose buffer is embedded as a data URI of 300 MB is refused under 0.75 GiB of
/// address space before its JSON is parsed (the parser's copy of the string and the decoded
/// bytes would need about twice the text), instead of aborting inside the parser.
#[test]
#[cfg(target_os = "linux")]
fn gltf_json_larger_than_memory_is_refused_before_it_is_parsed() {
    let sb = Sandbox::with_scene("gltf-json", &scene("mesh = \"mesh.gltf\"", CONSTANT))
        .with_address_space(3 << 18);
    let encoded = 300_000_000;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        "A".repeat(encoded)
    );
    sb.write(
        "mesh.gltf",
        document(encoded as u64 / 4 * 3, None, Some(&uri)).as_bytes(),
    );
    sb.fails(
        &["scene.toml"],
        1,
        &[
            "object[0].mesh",
            "mesh.gltf: out of memory: could not allocate 572.2 MiB for the glTF file's JSON and \
             the buffers embedded in it (keep large buffers in a .bin file or use a .glb, or \
             free memory)",
        ],
    );
}
