//! PLY meshes at the sizes of scans: files beyond 1 GiB read, lists beyond memory refused.

use std::os::unix::fs::FileExt;

use super::harness::{CONSTANT, Sandbox, render, scene};

/// Writes `mesh.ply`: a binary PLY of one triangle whose `vertex` element holds `vertices`
/// entries (the first three the triangle's corners, the rest zeros), followed by an element
/// `padding` of `padding` doubles that the reader skips. The zeros are sparse: no disk space
/// and no time to write them.
fn write_ply(sb: &Sandbox, vertices: u64, padding: u64) {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\n\
         property float y\nproperty float z\nelement face 1\n\
         property list uchar int vertex_indices\nelement padding {padding}\n\
         property double p\nend_header\n"
    );
    let mut bytes = header.into_bytes();
    for corner in [[0.5f32, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]] {
        for c in corner {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    let face_at = bytes.len() as u64 + (vertices - 3) * 12;
    let mut face = vec![3u8];
    for i in [0i32, 1, 2] {
        face.extend_from_slice(&i.to_le_bytes());
    }
    let path = sb.path("mesh.ply");
    std::fs::write(&path, &bytes).unwrap();
    let file = std::fs::File::options().write(true).open(&path).unwrap();
    file.set_len(face_at + face.len() as u64 + padding * 8)
        .unwrap();
    file.write_all_at(&face, face_at).unwrap();
}

/// A PLY of more than 1 GiB (the limit of the files a scene names other than meshes) is
/// read.
#[test]
#[cfg(target_pointer_width = "64")]
fn ply_beyond_one_gib_is_read() {
    let sb = Sandbox::with_scene("ply-beyond-1gib", &scene("mesh = \"mesh.ply\"", CONSTANT));
    write_ply(&sb, 3, (1 << 27) + (1 << 17));
    assert!(std::fs::metadata(sb.path("mesh.ply")).unwrap().len() > 1 << 30);
    sb.succeeds(&render(&["--samples", "50"]));
}

/// A PLY whose vertex list does not fit in memory is refused before it is read (under 0.75
/// GiB of address space, 40 M vertices: 480 MB of file, and as much again for the list),
/// instead of aborting when the list is allocated.
#[test]
#[cfg(target_os = "linux")]
fn ply_lists_larger_than_memory_are_refused() {
    let sb = Sandbox::with_scene("ply-lists", &scene("mesh = \"mesh.ply\"", CONSTANT))
        .with_address_space(3 << 18);
    write_ply(&sb, 40_000_000, 0);
    sb.fails(
        &["scene.toml"],
        1,
        &[
            "object[0].mesh",
            "mesh.ply: out of memory: could not allocate 457.8 MiB for the PLY file's vertices \
             and faces (use a coarser mesh, or free memory)",
        ],
    );
}
