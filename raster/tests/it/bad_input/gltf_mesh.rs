//! Binary glTF meshes at the sizes of scans: files beyond 1 GiB read, accessors beyond memory
//! refused.

use std::os::unix::fs::FileExt;

use super::harness::{CONSTANT, Sandbox, render, scene};

/// Writes `mesh.glb`: one triangle's positions at the start of a binary chunk of `bin_len`
/// bytes, and, with `indices`, an accessor of that many unsigned-byte indices right after them
/// (the first triangle 0 1 2, the rest zeros). Everything past the written bytes is sparse: no
/// disk space and no time to write it.
fn write_glb(sb: &Sandbox, bin_len: u64, indices: Option<u64>) {
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
    let mut json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{primitive}]}}],"buffers":[{{"byteLength":{bin_len}}}],"bufferViews":[{}],"accessors":[{}]}}"#,
        views.join(","),
        accessors.join(",")
    )
    .into_bytes();
    while json.len() % 4 != 0 {
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
    let bin_at = bytes.len() as u64;
    for corner in [[0.5f32, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]] {
        for c in corner {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    if indices.is_some() {
        bytes.extend_from_slice(&[0, 1, 2]);
    }
    let path = sb.path("mesh.glb");
    std::fs::write(&path, &bytes).unwrap();
    let file = std::fs::File::options().write(true).open(&path).unwrap();
    file.set_len(bin_at + bin_len).unwrap();
    assert_eq!(file.metadata().unwrap().len(), total);
    // The last byte written for real, so that the file's length does not rest on `set_len`.
    file.write_all_at(&[0], total - 1).unwrap();
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
