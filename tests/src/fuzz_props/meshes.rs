//! `ply_load_never_panics` and `gltf_load_never_panics`: arbitrary bytes into the PLY and glTF
//! mesh loaders.
//!
//! Both promise "a mesh or an error, never a panic", with allocations bounded by the input (a
//! count is checked against the bytes present before anything is reserved). A returned mesh
//! must pass `validate_mesh`, with indices in range and finite positions checked here
//! independently; a glTF mesh's material groups must cover its triangles in order, without gaps.
//! The glTF loader is given one external file, `buffer.bin` (a 140-byte quad: positions,
//! normals, UVs, six u16 indices); every other name fails to read.

use lucent_raster::scene::gltf::parse_gltf;
use lucent_raster::scene::ply::parse_ply;

use super::parse::check_mesh;

/// The one external buffer the fuzzed glTF files can name.
fn buffer_bin() -> Vec<u8> {
    let corners = [[0.0f32, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let mut b = Vec::new();
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

/// The property of the fuzz target `ply_load_never_panics`: `parse_ply` returns a valid mesh
/// or an error. Panics when that fails.
pub fn ply_load_never_panics(data: &[u8]) {
    if let Ok(mesh) = parse_ply(data) {
        check_mesh("parse_ply", &mesh);
    }
}

/// The property of the fuzz target `gltf_load_never_panics`: `parse_gltf` returns a valid mesh
/// whose material groups tile its triangles, or an error. Panics when that fails.
pub fn gltf_load_never_panics(data: &[u8]) {
    let mut read_file = |name: &str| {
        if name == "buffer.bin" {
            Ok(buffer_bin())
        } else {
            Err(format!("no file {name}"))
        }
    };
    if let Ok(g) = parse_gltf(data, &mut read_file) {
        check_mesh("parse_gltf", &g.mesh);
        let mut next = 0;
        for group in &g.groups {
            assert_eq!(group.triangles.start, next, "groups {:?}", g.groups);
            assert!(
                group.triangles.end > group.triangles.start,
                "groups {:?}",
                g.groups
            );
            next = group.triangles.end;
        }
        assert_eq!(next, g.mesh.triangles.len(), "groups {:?}", g.groups);
    }
}
