//! Wavefront OBJ meshes, read with `tobj` (triangulated, single index), merged into one
//! [`Mesh`] per file.
//!
//! Before `tobj` sees a file, a cheap pass checks every face index against the number of
//! vertices, texture coordinates and normals defined so far (negative, relative indices) or in
//! the whole file (positive indices). That gives errors with OBJ line numbers, and keeps
//! absurd indices (which overflow inside `tobj`'s index arithmetic) away from it. Materials
//! (`mtllib`, `usemtl`) are ignored: the scene assigns the material. Normals are kept when every
//! vertex has one, else computed (area-weighted); UVs are kept when every vertex has them.

use std::fmt;
use std::io::BufReader;

use glam::{Vec2, Vec3};

use super::mesh::finish_loaded_mesh;
use super::model::Mesh;

/// Why an OBJ file could not be used.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjError {
    /// 1-based line in the OBJ file, when the problem has one.
    pub line: Option<usize>,
    /// What is wrong (with the parser's message, when the parser failed).
    pub message: String,
    /// The OBJ parser's error, when it failed: returned by
    /// [`source`](std::error::Error::source).
    pub source: Option<tobj::LoadError>,
}

impl fmt::Display for ObjError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "line {line}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for ObjError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source
            .as_ref()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

/// Parses an OBJ file held in memory into one mesh in its own (object) coordinates.
pub fn parse_obj(bytes: &[u8]) -> Result<Mesh, ObjError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        ObjError {
            line: Some(line),
            message: "not UTF-8 text".to_string(),
            source: None,
        }
    })?;
    check_indices(text)?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = BufReader::new(text.as_bytes());
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| ObjError {
        line: None,
        message: format!("malformed OBJ: {e}"),
        source: Some(e),
    })?;
    merge(&models)
}

/// Merges tobj's models (one per `o`/`g`/material group) into one mesh.
fn merge(models: &[tobj::Model]) -> Result<Mesh, ObjError> {
    let fail = |message: String| ObjError {
        line: None,
        message,
        source: None,
    };
    let mut mesh = Mesh::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let (mut all_normals, mut all_uvs) = (true, true);
    for model in models {
        let m = &model.mesh;
        let base = mesh.positions.len();
        let count = m.positions.len() / 3;
        if base + count > u32::MAX as usize {
            return Err(fail("too many vertices".to_string()));
        }
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if m.normals.len() == 3 * count {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        } else {
            all_normals = false;
        }
        if m.texcoords.len() == 2 * count {
            uvs.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
        } else {
            all_uvs = false;
        }
        for t in m.indices.chunks_exact(3) {
            if let Some(&bad) = t.iter().find(|&&i| i as usize >= count) {
                return Err(fail(format!(
                    "face index {bad} out of range ({count} vertices)"
                )));
            }
            mesh.triangles
                .push([t[0], t[1], t[2]].map(|i| i + base as u32));
        }
    }
    if mesh.triangles.is_empty() {
        return Err(fail(
            "the file defines no faces (a mesh needs at least one triangle)".to_string(),
        ));
    }
    mesh.uvs = all_uvs.then_some(uvs);
    finish_loaded_mesh(mesh, all_normals.then_some(normals)).map_err(fail)
}

/// Checks face-index ranges the way `tobj` resolves them, reporting the first bad one with its
/// line. Counts of `v`, `vt`, `vn` so far resolve negative indices; totals bound positive ones.
fn check_indices(text: &str) -> Result<(), ObjError> {
    let mut totals = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    const NAMES: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    let mut so_far = [0usize; 3];
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => so_far[0] += 1,
            Some("vt") => so_far[1] += 1,
            Some("vn") => so_far[2] += 1,
            Some("f") | Some("l") => {
                for corner in words {
                    for (slot, part) in corner.split('/').enumerate().take(3) {
                        if part.is_empty() {
                            continue;
                        }
                        let fail = |what: String| ObjError {
                            line: Some(number + 1),
                            message: what,
                            source: None,
                        };
                        let Ok(index) = part.parse::<i64>() else {
                            return Err(fail(format!("bad face index `{part}`")));
                        };
                        let ok = match index {
                            0 => false,
                            i if i > 0 => (i as u64) <= totals[slot] as u64,
                            i => i.unsigned_abs() <= so_far[slot] as u64,
                        };
                        if !ok {
                            return Err(fail(format!(
                                "face {} index {index} out of range ({} defined{})",
                                NAMES[slot],
                                if index < 0 {
                                    so_far[slot]
                                } else {
                                    totals[slot]
                                },
                                if index < 0 { " so far" } else { "" },
                            )));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD: &str = "\
# a unit square in the xy plane, counter-clockwise seen from +z
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3 4/4
";

    #[test]
    fn quad_is_triangulated_with_uvs_and_computed_normals() {
        let m = parse_obj(QUAD.as_bytes()).expect("loads");
        assert_eq!(m.triangles.len(), 2);
        assert_eq!(m.positions.len(), 4);
        assert!(m.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
        let uvs = m.uvs.as_ref().expect("uvs kept");
        for (p, t) in m.positions.iter().zip(uvs) {
            assert_eq!(Vec2::new(p.x, p.y), *t);
        }
    }

    #[test]
    fn file_normals_are_kept_and_normalised() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nf 1//1 2//1 3//1\n";
        let m = parse_obj(text.as_bytes()).expect("loads");
        assert_eq!(m.normals, vec![Vec3::Z; 3]);
        assert!(m.uvs.is_none());
    }

    #[test]
    fn negative_indices_resolve_relative() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n";
        let m = parse_obj(text.as_bytes()).expect("loads");
        assert_eq!(m.triangles.len(), 1);
    }

    #[test]
    fn bad_indices_name_their_line() {
        for (text, line, what) in [
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, "index 4"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "index 0"),
            ("v 0 0 0\nv 1 0 0\nf -3 -2 -1\nv 0 1 0\n", 3, "index -3"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/-99 2 3\n",
                4,
                "texture coordinate",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//99999999999999999 2 3\n",
                4,
                "normal",
            ),
            ("v 0 0 0\nf 1 x 1\n", 2, "bad face index"),
        ] {
            let err = parse_obj(text.as_bytes()).expect_err(text);
            assert_eq!(err.line, Some(line), "{text}: {err}");
            assert!(err.message.contains(what), "{text}: {err}");
        }
    }

    #[test]
    fn malformed_and_degenerate_files_are_errors() {
        let cases: [(&[u8], &str); 6] = [
            (b"v 0 0 zero\nf 1 1 1\n", "malformed OBJ"),
            (b"v 0 0 0\nv 1 0 0\n", "no faces"),
            (b"", "no faces"),
            (b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "area"),
            (b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
            (b"v 0 0 0\n\xff\xfe\n", "UTF-8"),
        ];
        for (bytes, what) in cases {
            let err = parse_obj(bytes).expect_err(what);
            assert!(err.to_string().contains(what), "{what}: {err}");
            // Only the parser's own failure has a source: its error.
            let source = std::error::Error::source(&err);
            assert_eq!(source.is_some(), what == "malformed OBJ", "{what}: {err}");
            if let Some(source) = source {
                assert!(source.downcast_ref::<tobj::LoadError>().is_some());
            }
        }
    }

    #[test]
    fn groups_merge_and_partial_uvs_are_dropped() {
        let text = "\
v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1
o a
f 1/1 2/2 3/3
o b
f 1 3 4
";
        let m = parse_obj(text.as_bytes()).expect("loads");
        assert_eq!(m.triangles.len(), 2);
        assert!(m.uvs.is_none(), "only some faces have UVs");
        // Every index refers into the merged vertex list.
        assert!(
            m.triangles
                .iter()
                .flatten()
                .all(|&i| (i as usize) < m.positions.len())
        );
    }
}
