//! Wavefront OBJ meshes (triangulated, single index), merged into one [`Mesh`] per file.
//!
//! The statements are read by `obj_reader/` (in chunks, in parallel); every face index is
//! checked against the number of vertices, texture coordinates and normals defined so far
//! (negative, relative indices) or in the whole file (positive indices), and a bad one is
//! reported with its OBJ line. Each triangle remembers its `usemtl` group and the `mtllib`
//! paths are kept: the scene maps groups to its materials and may take `map_Kd` from the
//! libraries (`objects.rs`, `mtl.rs`). Normals are kept when every vertex has one, else
//! computed (area-weighted); UVs are kept when every vertex has them. A closed mesh wound
//! inside out is flipped, and file normals against the winding are reported (`sanity.rs`).

use std::borrow::Cow;
use std::fmt;

use glam::Vec3;

use super::mesh::{
    drop_unused_vertices, reject_non_finite, retain_flagged, smooth_normals, unit_normal,
    validate_mesh,
};
use super::model::Mesh;
use super::obj_reader::{ObjGroup, read_statements};
use super::origin::MAX_MESH_FILE_BYTES;
use super::sanity::{
    PositionIds, drop_coincident_triangles, normals_against_winding, orient_outward,
};
use crate::memory;

/// Why an OBJ file could not be used.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjError {
    /// 1-based line in the OBJ file, when the problem has one.
    pub line: Option<usize>,
    /// What is wrong (with the parser's message, when the parser failed).
    pub message: String,
    /// The kind of syntax error, in the terms of the `tobj` crate (whose conventions the
    /// reader follows), when a statement is malformed: returned by
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

/// An OBJ file as loaded: the merged mesh plus what the scene may refine it with.
#[derive(Clone, Debug, Default)]
pub struct ObjMesh {
    /// Every face of the file, in its own (object) coordinates.
    pub mesh: Mesh,
    /// The `usemtl` names, in order of first use by a face.
    pub groups: Vec<String>,
    /// Per triangle of `mesh`: index into `groups`, or `None` for faces before any `usemtl`.
    pub triangle_groups: Vec<Option<u32>>,
    /// The `mtllib` statements: (1-based OBJ line, path relative to the OBJ file).
    pub mtllibs: Vec<(usize, String)>,
    /// Repairs made and doubts about the file (see `sanity.rs`), one sentence each.
    pub warnings: Vec<String>,
}

/// Parses an OBJ file held in memory into one mesh in its own (object) coordinates.
pub fn parse_obj(bytes: &[u8]) -> Result<Mesh, ObjError> {
    load_obj(bytes).map(|obj| obj.mesh)
}

/// Parses an OBJ file held in memory, keeping its `usemtl` groups and `mtllib` statements.
///
/// The material libraries are not read here: that is left to the scene, which knows whether it
/// needs them (`kd = "mtl"`).
///
/// Text longer than [`MAX_MESH_FILE_BYTES`] is rejected, and so is text whose reading would need more
/// memory than the allocator grants (about [`PARSE_BYTES_PER_TEXT_BYTE`] times the text, asked
/// for at once before reading).
///
/// Bytes that are not UTF-8 are accepted in comments and in `o`, `g` and `s` statements
/// (replaced by U+FFFD; lucent does not use those names) and rejected with their line anywhere
/// else, where they would change a number, an index or a name that must match.
pub fn load_obj(bytes: &[u8]) -> Result<ObjMesh, ObjError> {
    load_obj_up_to(bytes, MAX_MESH_FILE_BYTES)
}

/// Bytes asked for per byte of OBJ text before its statements are read: what the load holds
/// besides the text (the chunks' statements and their concatenation, which live together for
/// a moment, then the groups' vertices and the repairs). Measured on a 31 M-triangle sphere
/// (1.37 GB of text, 42 bytes a triangle; `BENCHMARKS.md`, "Large meshes"): 1.56.
pub const PARSE_BYTES_PER_TEXT_BYTE: u64 = 2;

/// [`load_obj`] with a size limit of its own.
fn load_obj_up_to(bytes: &[u8], limit: u64) -> Result<ObjMesh, ObjError> {
    let refused = |message: String| ObjError {
        line: None,
        message,
        source: None,
    };
    let len = bytes.len() as u64;
    if len > limit {
        return Err(refused(format!(
            "OBJ text is {len} bytes, larger than the {limit}-byte limit"
        )));
    }
    memory::probe(
        len.saturating_mul(PARSE_BYTES_PER_TEXT_BYTE),
        memory::OBJ_STATEMENTS,
    )
    .map_err(|e| refused(e.to_string()))?;
    let text = utf8_lines(bytes, &["o", "g", "s"])?;
    let statements = read_statements(&text)?;
    let mut obj = merge(&statements.groups, &statements.usemtl_names)?;
    obj.mtllibs = statements.mtllibs;
    Ok(obj)
}

/// The text of a file whose lines must be UTF-8, except comments and the statements in
/// `lossy` (whose bytes that are not UTF-8 become U+FFFD).
pub(crate) fn utf8_lines<'b>(bytes: &'b [u8], lossy: &[&str]) -> Result<Cow<'b, str>, ObjError> {
    if let Ok(text) = std::str::from_utf8(bytes) {
        return Ok(Cow::Borrowed(text));
    }
    let mut text = String::with_capacity(bytes.len() + 16);
    for (number, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if number > 0 {
            text.push('\n');
        }
        match std::str::from_utf8(line) {
            Ok(line) => text.push_str(line),
            Err(_) => {
                let keyword = line
                    .split(u8::is_ascii_whitespace)
                    .find(|w| !w.is_empty())
                    .unwrap_or_default();
                let comment = keyword.first() == Some(&b'#');
                if !comment && !lossy.iter().any(|k| k.as_bytes() == keyword) {
                    return Err(ObjError {
                        line: Some(number + 1),
                        message: format!(
                            "not UTF-8 text (accepted only in comments{})",
                            if lossy.is_empty() {
                                String::new()
                            } else {
                                format!(" and `{}` statements", lossy.join("`, `"))
                            }
                        ),
                        source: None,
                    });
                }
                text.push_str(&String::from_utf8_lossy(line));
            }
        }
    }
    Ok(Cow::Owned(text))
}

/// Merges the file's groups into one mesh, remembering each triangle's `usemtl` group.
fn merge(parts: &[ObjGroup], usemtl_names: &[String]) -> Result<ObjMesh, ObjError> {
    let fail = |message: String| ObjError {
        line: None,
        message,
        source: None,
    };
    let mut mesh = Mesh::default();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut groups: Vec<String> = Vec::new();
    // Per `usemtl` name, its index in `groups` once a group has used it.
    let mut group_of: Vec<Option<u32>> = vec![None; usemtl_names.len()];
    let mut triangle_groups = Vec::new();
    let (mut all_normals, mut all_uvs) = (true, true);
    for part in parts {
        let base = mesh.positions.len();
        let count = part.positions.len();
        if base + count > u32::MAX as usize {
            return Err(fail("too many vertices".to_string()));
        }
        // Numbered in order of first use by a group (a last, empty group included).
        let group = part.usemtl.map(|id| {
            *group_of[id as usize].get_or_insert_with(|| {
                groups.push(usemtl_names[id as usize].clone());
                (groups.len() - 1) as u32
            })
        });
        mesh.positions.extend_from_slice(&part.positions);
        if part.normals.len() == count {
            normals.extend_from_slice(&part.normals);
        } else {
            all_normals = false;
        }
        if part.uvs.len() == count {
            uvs.extend_from_slice(&part.uvs);
        } else {
            all_uvs = false;
        }
        mesh.triangles
            .extend(part.triangles.iter().map(|t| t.map(|i| i + base as u32)));
        triangle_groups.extend(std::iter::repeat_n(group, part.triangles.len()));
    }
    if mesh.triangles.is_empty() {
        return Err(fail(
            "the file defines no faces (a mesh needs at least one triangle)".to_string(),
        ));
    }
    mesh.uvs = all_uvs.then_some(uvs);
    if all_normals && normals.len() == mesh.positions.len() {
        // Held in the mesh while copies and unused vertices are dropped, so that they stay
        // aligned with the vertices kept.
        mesh.normals = normals;
    }
    reject_non_finite(&mesh).map_err(fail)?;
    // Before the winding is checked: copies make a closed surface look open.
    let mut ids = PositionIds::default();
    let mut warnings: Vec<String> = drop_coincident_triangles(&mut mesh, &mut ids, |keep| {
        retain_flagged(&mut triangle_groups, keep)
    })
    .into_iter()
    .collect();
    drop_unused_vertices(&mut mesh);
    // File normals are only trusted when every vertex has a usable one.
    let units: Option<Vec<Vec3>> = (!mesh.normals.is_empty())
        .then(|| {
            std::mem::take(&mut mesh.normals)
                .into_iter()
                .map(unit_normal)
                .collect()
        })
        .flatten();
    let file_normals = units.is_some();
    if let Some(units) = units {
        mesh.normals = units;
    }
    warnings.extend(orient_outward(&mut mesh, file_normals, &mut ids));
    // Freed before the normals are made: held through them, the peak resident size of a
    // 2 M-triangle file was 8% higher with glibc's default malloc (the live memory was not).
    drop(ids);
    if file_normals {
        warnings.extend(normals_against_winding(&mesh));
    } else {
        mesh.normals = smooth_normals(&mesh.positions, &mesh.triangles);
    }
    validate_mesh(&mesh).map_err(fail)?;
    Ok(ObjMesh {
        mesh,
        groups,
        triangle_groups,
        mtllibs: Vec::new(),
        warnings,
    })
}

/// How many `v`, `vt` and `vn` statements the text holds.
pub(super) fn attribute_counts(text: &str) -> [usize; 3] {
    let mut totals = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    totals
}

/// Checks face-index ranges the way `tobj` resolves them, reporting the first bad one with its
/// line. Counts of `v`, `vt`, `vn` so far resolve negative indices; the file's totals bound
/// positive ones. Two passes over the text: the reader calls it only to find an error's line.
pub(super) fn check_indices(text: &str) -> Result<(), ObjError> {
    const NAMES: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    let totals = attribute_counts(text);
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
    use glam::Vec2;

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
    fn text_beyond_the_limit_is_refused_unread() {
        let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert!(load_obj_up_to(text, text.len() as u64).is_ok());
        let e = load_obj_up_to(text, text.len() as u64 - 1).unwrap_err();
        assert_eq!(e.line, None);
        assert_eq!(
            e.message,
            "OBJ text is 32 bytes, larger than the 31-byte limit"
        );
        assert_eq!(MAX_MESH_FILE_BYTES, 1 << 36);
    }

    #[test]
    fn file_normals_are_kept_and_normalised() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nf 1//1 2//1 3//1\n";
        let m = parse_obj(text.as_bytes()).expect("loads");
        assert_eq!(m.normals, vec![Vec3::Z; 3]);
        assert!(m.uvs.is_none());
        // A length beyond f32 keeps its direction (it was normalised to zero and refused);
        // below 10⁻¹² a normal has none, and the triangle's own (+z) is computed instead.
        let lengths = [
            ("vn 3e38 0 3e38", Vec3::new(1.0, 0.0, 1.0).normalize()),
            ("vn 1e-30 0 1e-30", Vec3::Z),
        ];
        for (vn, want) in lengths {
            let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{vn}\nf 1//1 2//1 3//1\n");
            let m = parse_obj(text.as_bytes()).expect("loads");
            assert!(
                m.normals.iter().all(|n| (*n - want).length() < 1e-6),
                "{vn}: {:?}",
                m.normals
            );
        }
    }

    #[test]
    fn negative_indices_resolve_relative() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n";
        let m = parse_obj(text.as_bytes()).expect("loads");
        assert_eq!(m.triangles.len(), 1);
        // Positive indices are bounded by the whole file's count: a face may come first.
        let text = "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
        assert_eq!(
            parse_obj(text.as_bytes()).expect("loads").triangles.len(),
            1
        );
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

    #[test]
    fn usemtl_groups_and_mtllibs_are_kept_per_triangle() {
        let text = "mtllib a b.mtl\n  usemtl x\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                    f 1 2 3\nusemtl y z\nf 1 2 4\nusemtl x\nf 1 3 4\nmtllib c.mtl\n";
        let obj = load_obj(text.as_bytes()).expect("loads");
        // tobj keeps names with spaces whole; an indented usemtl is found as well.
        assert_eq!(obj.groups, vec!["x".to_string(), "y z".to_string()]);
        assert_eq!(obj.triangle_groups, vec![Some(0), Some(1), Some(0)]);
        assert_eq!(
            obj.mtllibs,
            vec![(1, "a b.mtl".to_string()), (12, "c.mtl".to_string())]
        );
        // Faces before any usemtl have no group.
        let obj = load_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert!(obj.groups.is_empty());
        assert_eq!(obj.triangle_groups, vec![None]);
    }

    #[test]
    fn thousands_of_materials_keep_their_order_of_first_use() {
        let names = 3000;
        let mut text = String::from("v 0 0 0\nv 1 0 0\n");
        for row in 1..=2 {
            for k in 0..names {
                text.push_str(&format!("v {k} {row} 0\n"));
            }
        }
        // A triangle per name, then one more per name in reverse order: the indices of the
        // names stay those of their first use.
        for k in 0..names {
            text.push_str(&format!("usemtl m{k}\nf 1 2 {}\n", 3 + k));
        }
        for k in (0..names).rev() {
            text.push_str(&format!("usemtl m{k}\nf 1 2 {}\n", 3 + names + k));
        }
        let obj = load_obj(text.as_bytes()).expect("loads");
        assert_eq!(obj.groups.len(), names);
        assert!(
            obj.groups
                .iter()
                .enumerate()
                .all(|(i, g)| *g == format!("m{i}"))
        );
        let want: Vec<Option<u32>> = (0..names as u32)
            .chain((0..names as u32).rev())
            .map(Some)
            .collect();
        assert_eq!(obj.triangle_groups, want);
    }

    #[test]
    fn bytes_that_are_not_utf8_are_accepted_only_where_unused() {
        let ok = b"# caf\xe9\no t\xeate\ng \xff\ns \xff\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_eq!(parse_obj(ok).expect("loads").triangles.len(), 1);
        for (bytes, line) in [
            (&b"v 0 0 0\nv 1 0 0\nv 0 1 \xb0\nf 1 2 3\n"[..], 3),
            (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \xe9\nf 1 2 3\n", 4),
            (
                b"mtllib caf\xe9.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                1,
            ),
        ] {
            let e = parse_obj(bytes).expect_err("rejected");
            assert_eq!(e.line, Some(line), "{e}");
            assert!(e.message.contains("not UTF-8"), "{e}");
        }
    }

    #[test]
    fn coordinates_beyond_the_bound_are_rejected_quickly() {
        let e = parse_obj(b"v -6e37 -6e37 0\nv 6e37 -6e37 0\nv 0 6e37 0\nf 1 2 3\n").unwrap_err();
        assert!(e.message.contains("farther than 1e12"), "{e}");
        // At the bound itself a mesh is fine.
        let m = parse_obj(b"v -1e12 -1e12 0\nv 1e12 -1e12 0\nv 0 1e12 0\nf 1 2 3\n");
        assert!(m.is_ok(), "{m:?}");
    }

    #[test]
    fn file_normals_against_the_winding_give_a_warning() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 -1\nf 1//1 2//1 3//1\n";
        let obj = load_obj(text.as_bytes()).unwrap();
        assert_eq!(obj.warnings.len(), 1, "{:?}", obj.warnings);
        assert!(
            obj.warnings[0].contains("3 of 3 vertex normals"),
            "{:?}",
            obj.warnings
        );
        let agreeing = text.replace("vn 0 0 -1", "vn 0 0 1");
        assert!(load_obj(agreeing.as_bytes()).unwrap().warnings.is_empty());
    }
}
