//! One pass over an OBJ file's statements: vertices, faces fanned into triangles, the groups
//! that `o`, `g` and `usemtl` start, and the `mtllib` paths.
//!
//! The conventions are those of the `tobj` crate (triangulated, single index), which lucent
//! used before and which remains the oracle of the differential test below:
//!
//! - a statement is a line's first whitespace-separated word; `v` takes three numbers and then
//!   either nothing, a `w` that divides them, or three colour components (ignored); `vt` takes
//!   two numbers and `vn` three, and ignores the rest;
//! - `f` and `l` are faces alike: each corner is `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or
//!   negative (relative to the count so far); one or two corners are skipped, and three or more
//!   are fanned from the first corner;
//! - a group ends at `o` or `g`, or at a `usemtl` naming another material, once it has a face;
//!   the last group always ends with the file;
//! - within a group, each distinct (`v`, `vt`, `vn`) triple becomes one vertex, numbered in
//!   order of first use.
//!
//! Where `tobj` fails but the file is meaningful, the reader accepts: a positive index may name
//! a vertex defined later in the file (`tobj` reads it only when defined before the group
//! ends), and colours given for only some vertices are ignored like all colours.

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::obj::ObjError;

/// One group's triangles, with its own vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct ObjGroup {
    /// Index into [`ObjStatements::usemtl_names`] of the material in use, if any.
    pub usemtl: Option<u32>,
    /// One per distinct (`v`, `vt`, `vn`) triple of the group's corners.
    pub positions: Vec<Vec3>,
    /// One per vertex whose corner named a normal (all or some of them).
    pub normals: Vec<Vec3>,
    /// One per vertex whose corner named a texture coordinate (all or some of them).
    pub uvs: Vec<Vec2>,
    /// Indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// What [`read_statements`] finds in an OBJ file.
#[derive(Clone, Debug, Default)]
pub(super) struct ObjStatements {
    /// The groups in file order; the last one may have no triangles.
    pub groups: Vec<ObjGroup>,
    /// Every non-empty `usemtl` name, in order of first appearance.
    pub usemtl_names: Vec<String>,
    /// The `mtllib` statements: (1-based line, path).
    pub mtllibs: Vec<(usize, String)>,
}

/// The `vt` or `vn` slot of a corner that names none.
const MISSING: u32 = u32::MAX;

/// A corner as written: 0-based (`v`, `vt`, `vn`), [`MISSING`] where absent.
type Corner = [u32; 3];

/// A group while the file is read: its material and its triangles' corners.
struct PendingGroup {
    usemtl: Option<u32>,
    corners: std::ops::Range<usize>,
}

/// Reads every statement lucent uses from an OBJ file's text.
///
/// Indices are checked against the counts so far (negative) and the whole file's (positive);
/// a bad one is reported by [`super::obj::check_indices`] with its line. Other syntax errors
/// name their line and carry the `tobj` error of the same kind as their source.
pub(super) fn read_statements(text: &str) -> Result<ObjStatements, ObjError> {
    let mut out = ObjStatements::default();
    let mut positions: Vec<Vec3> = Vec::new();
    let mut uvs: Vec<Vec2> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut corners: Vec<Corner> = Vec::new();
    let mut pending: Vec<PendingGroup> = Vec::new();
    let mut usemtl: Option<u32> = None;
    let mut group_start = 0;
    // `f` and `l` statements in the current group, including skipped points and lines.
    let mut faces_in_group = 0usize;
    // The largest positive index per slot, checked against the totals at the end.
    let mut largest = [0u64; 3];
    let mut fan: Vec<Corner> = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.trim_start();
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let malformed = |kind: tobj::LoadError| ObjError {
            line: Some(number + 1),
            message: format!("malformed OBJ: {kind}"),
            source: Some(kind),
        };
        // The statement's argument as `tobj` takes it: the rest after the first space, trimmed.
        let argument = || line.split_once(' ').unwrap_or_default().1.trim();
        match keyword {
            "v" => {
                let [x, y, z] = numbers::<3>(&mut words)
                    .ok_or_else(|| malformed(tobj::LoadError::PositionParseError))?;
                let mut p = Vec3::new(x, y, z);
                match (words.next(), words.next(), words.next(), words.next()) {
                    (None, ..) | (Some(_), Some(_), Some(_), None) => {}
                    (Some(w), None, ..) => {
                        let w: f32 = w
                            .parse()
                            .map_err(|_| malformed(tobj::LoadError::PositionParseError))?;
                        if w == 0.0 {
                            return Err(malformed(tobj::LoadError::ScalingByZeroError));
                        }
                        p = Vec3::new(p.x / w, p.y / w, p.z / w);
                    }
                    _ => return Err(malformed(tobj::LoadError::ColorParseError)),
                }
                positions.push(p);
            }
            "vt" => {
                let [u, v] = numbers::<2>(&mut words)
                    .ok_or_else(|| malformed(tobj::LoadError::TexcoordParseError))?;
                uvs.push(Vec2::new(u, v));
            }
            "vn" => {
                let [x, y, z] = numbers::<3>(&mut words)
                    .ok_or_else(|| malformed(tobj::LoadError::NormalParseError))?;
                normals.push(Vec3::new(x, y, z));
            }
            "f" | "l" => {
                faces_in_group += 1;
                fan.clear();
                let so_far = [positions.len(), uvs.len(), normals.len()];
                for word in words {
                    let corner =
                        parse_corner(word, so_far, &mut largest).map_err(|bad| match bad {
                            BadCorner::Syntax => malformed(tobj::LoadError::FaceParseError),
                            BadCorner::Index => index_error(text),
                        })?;
                    fan.push(corner);
                }
                match fan.len() {
                    0 => return Err(malformed(tobj::LoadError::InvalidPolygon)),
                    1 | 2 => {}
                    // A corner like `/2` names no vertex (points and lines are skipped unread).
                    _ if fan.iter().any(|c| c[0] == MISSING) => {
                        return Err(malformed(tobj::LoadError::FaceVertexOutOfBounds));
                    }
                    _ => {
                        for pair in fan[1..].windows(2) {
                            corners.extend([fan[0], pair[0], pair[1]]);
                        }
                    }
                }
            }
            "o" | "g" if faces_in_group > 0 => {
                pending.push(PendingGroup {
                    usemtl,
                    corners: group_start..corners.len(),
                });
                group_start = corners.len();
                faces_in_group = 0;
            }
            "usemtl" => {
                let name = argument();
                if name.is_empty() {
                    return Err(malformed(tobj::LoadError::MaterialParseError));
                }
                let index = match out.usemtl_names.iter().position(|n| n == name) {
                    Some(i) => i,
                    None => {
                        out.usemtl_names.push(name.to_string());
                        out.usemtl_names.len() - 1
                    }
                };
                let material = Some(index as u32);
                if material != usemtl && faces_in_group > 0 {
                    pending.push(PendingGroup {
                        usemtl,
                        corners: group_start..corners.len(),
                    });
                    group_start = corners.len();
                    faces_in_group = 0;
                }
                usemtl = material;
            }
            "mtllib" => {
                let path = argument();
                if !path.is_empty() {
                    out.mtllibs.push((number + 1, path.to_string()));
                }
            }
            _ => {}
        }
    }
    pending.push(PendingGroup {
        usemtl,
        corners: group_start..corners.len(),
    });
    let totals = [positions.len(), uvs.len(), normals.len()];
    if largest.iter().zip(totals).any(|(&l, t)| l > t as u64) {
        return Err(index_error(text));
    }
    if totals[0] > MISSING as usize {
        return Err(ObjError {
            line: None,
            message: "too many vertices".to_string(),
            source: None,
        });
    }
    let mut first_use = FirstUse::new(positions.len());
    for (number, group) in pending.iter().enumerate() {
        let attributes = Attributes {
            positions: &positions,
            uvs: &uvs,
            normals: &normals,
        };
        out.groups.push(attributes.group(
            group.usemtl,
            &corners[group.corners.clone()],
            number as u32,
            &mut first_use,
        ));
    }
    Ok(out)
}

/// The first `N` words as `f32` (`str::parse`, as `tobj` reads them), or `None`.
fn numbers<const N: usize>(words: &mut std::str::SplitWhitespace) -> Option<[f32; N]> {
    let mut out = [0.0; N];
    for slot in &mut out {
        *slot = words.next()?.parse().ok()?;
    }
    Some(out)
}

/// Why a face corner could not be read.
enum BadCorner {
    /// More than three parts.
    Syntax,
    /// A part is not an integer, or is out of range.
    Index,
}

/// One face corner `v[/vt[/vn]]`, resolved to 0-based indices ([`MISSING`] for an empty part).
/// Negative indices are checked against `so_far`; positive ones only raise `largest`, checked
/// once the totals are known.
fn parse_corner(
    word: &str,
    so_far: [usize; 3],
    largest: &mut [u64; 3],
) -> Result<Corner, BadCorner> {
    let mut corner = [MISSING; 3];
    for (slot, part) in word.split('/').enumerate() {
        if part.is_empty() {
            continue;
        }
        if slot >= 3 {
            return Err(BadCorner::Syntax);
        }
        let index: i64 = part.parse().map_err(|_| BadCorner::Index)?;
        corner[slot] = match index {
            0 => return Err(BadCorner::Index),
            i if i > 0 => {
                largest[slot] = largest[slot].max(i as u64);
                // Files are at most 1 GiB, so a valid index fits; a larger one fails the check.
                u32::try_from(i - 1).map_err(|_| BadCorner::Index)?
            }
            i => {
                let back = i.unsigned_abs();
                if back > so_far[slot] as u64 {
                    return Err(BadCorner::Index);
                }
                (so_far[slot] as u64 - back) as u32
            }
        };
    }
    Ok(corner)
}

/// The error for a bad face index, found again with its line by the two-pass check.
fn index_error(text: &str) -> ObjError {
    let mut totals = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    super::obj::check_indices(text, totals)
        .err()
        .unwrap_or_else(|| ObjError {
            line: None,
            message: "a face corner names no vertex".to_string(),
            source: None,
        })
}

/// The file's vertex attributes, which every group's corners index.
struct Attributes<'a> {
    positions: &'a [Vec3],
    uvs: &'a [Vec2],
    normals: &'a [Vec3],
}

/// Which vertex each (`v`, `vt`, `vn`) triple became in the current group.
///
/// Most positions appear with one (`vt`, `vn`) pair, so each has one slot, stamped with the
/// group that filled it (no clearing between groups); other pairs go to a map.
struct FirstUse {
    slots: Vec<Slot>,
    others: HashMap<Corner, u32>,
}

/// The first (`vt`, `vn`) pair seen with a position in group `group`, and its vertex.
#[derive(Clone, Copy)]
struct Slot {
    group: u32,
    vt: u32,
    vn: u32,
    vertex: u32,
}

impl FirstUse {
    fn new(positions: usize) -> FirstUse {
        let empty = Slot {
            group: u32::MAX,
            vt: 0,
            vn: 0,
            vertex: 0,
        };
        FirstUse {
            slots: vec![empty; positions],
            others: HashMap::new(),
        }
    }

    /// The vertex of `corner` in `group`, or `None` after recording `next` as its vertex.
    fn find_or_insert(&mut self, group: u32, corner: Corner, next: u32) -> Option<u32> {
        let [v, vt, vn] = corner;
        let slot = &mut self.slots[v as usize];
        if slot.group != group {
            *slot = Slot {
                group,
                vt,
                vn,
                vertex: next,
            };
            return None;
        }
        if slot.vt == vt && slot.vn == vn {
            return Some(slot.vertex);
        }
        match self.others.entry(corner) {
            std::collections::hash_map::Entry::Occupied(e) => Some(*e.get()),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(next);
                None
            }
        }
    }
}

impl Attributes<'_> {
    /// One group's vertices and triangles from its corners (three per triangle).
    fn group(
        &self,
        usemtl: Option<u32>,
        corners: &[Corner],
        number: u32,
        first_use: &mut FirstUse,
    ) -> ObjGroup {
        first_use.others.clear();
        let mut out = ObjGroup {
            usemtl,
            triangles: Vec::with_capacity(corners.len() / 3),
            ..ObjGroup::default()
        };
        for triangle in corners.chunks_exact(3) {
            let mut indices = [0u32; 3];
            for (index, &corner) in indices.iter_mut().zip(triangle) {
                let next = out.positions.len() as u32;
                *index = first_use
                    .find_or_insert(number, corner, next)
                    .unwrap_or_else(|| {
                        let [v, vt, vn] = corner;
                        out.positions.push(self.positions[v as usize]);
                        if vt != MISSING && !self.uvs.is_empty() {
                            out.uvs.push(self.uvs[vt as usize]);
                        }
                        if vn != MISSING && !self.normals.is_empty() {
                            out.normals.push(self.normals[vn as usize]);
                        }
                        next
                    });
            }
            out.triangles.push(indices);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::testutil::Rng;

    /// The `mtllib` name under which the oracle hands every `usemtl` name to `tobj`, which
    /// otherwise reports no material for names no loaded library defines.
    const NAMES_LIBRARY: &str = "\u{1}usemtl-names";

    /// The reader's output as `tobj` gives it, after the two-pass index check lucent ran
    /// before `tobj`.
    fn oracle(text: &str) -> Result<Vec<(Option<String>, tobj::Mesh)>, ()> {
        let mut totals = [0usize; 3];
        let mut names: Vec<String> = Vec::new();
        let mut fed = format!("mtllib {NAMES_LIBRARY}\n");
        for line in text.lines() {
            let line = line.trim_start();
            fed.push_str(line);
            fed.push('\n');
            match line.split_whitespace().next() {
                Some("v") => totals[0] += 1,
                Some("vt") => totals[1] += 1,
                Some("vn") => totals[2] += 1,
                Some("usemtl") => {
                    let name = line.split_once(' ').unwrap_or_default().1.trim();
                    if !name.is_empty() && !names.iter().any(|n| n == name) {
                        names.push(name.to_string());
                    }
                }
                _ => {}
            }
        }
        super::super::obj::check_indices(text, totals).map_err(|_| ())?;
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, materials) = tobj::load_obj_buf(&mut fed.as_bytes(), &options, |path| {
            if path == std::path::Path::new(NAMES_LIBRARY) {
                let library = names
                    .iter()
                    .map(|name| tobj::Material {
                        name: name.clone(),
                        ..Default::default()
                    })
                    .collect();
                let index = names.iter().enumerate().map(|(i, n)| (n.clone(), i));
                Ok((library, index.collect()))
            } else {
                Ok((Vec::new(), Default::default()))
            }
        })
        .map_err(|_| ())?;
        let materials = materials.unwrap_or_default();
        Ok(models
            .into_iter()
            .map(|m| {
                let name = m.mesh.material_id.map(|id| materials[id].name.clone());
                (name, m.mesh)
            })
            .collect())
    }

    /// A number as files write them: integers, decimals, exponents, signs, now and then
    /// something that is not a number.
    fn number(rng: &mut Rng, noisy: bool) -> String {
        match rng.range_i64(0, 12) {
            0 => "-0.5".into(),
            1 => format!("{}e-3", rng.range_i64(-9, 10)),
            2 if noisy && rng.range_i64(0, 20) == 0 => "x".into(),
            3 => format!("{:.7}", rng.f32_in(-2.0, 2.0)),
            _ => rng.range_i64(-3, 4).to_string(),
        }
    }

    /// An index for a slot with `count` entries so far: mostly valid (positive or negative),
    /// sometimes 0, out of range or not a number.
    fn index(rng: &mut Rng, count: usize, noisy: bool) -> String {
        let count = count as i64;
        match rng.range_i64(if noisy { 0 } else { 3 }, 40) {
            0 => "0".into(),
            // Beyond the count so far, and beyond any later one (a later vertex would make a
            // forward reference, which only the reader accepts).
            1 if rng.range_i64(0, 2) == 0 => (-count - 1).to_string(),
            1 => "99999".into(),
            2 => "q".into(),
            _ if count == 0 => "1".into(),
            k if k % 2 == 0 => rng.range_i64(1, count + 1).to_string(),
            _ => (-rng.range_i64(1, count + 1)).to_string(),
        }
    }

    /// A random OBJ file within what `tobj` and the reader agree on: positive indices only
    /// name vertices already defined, and `vt`/`vn` appear before the first face or never.
    fn random_file(rng: &mut Rng) -> String {
        let mut out = String::new();
        // Half the files have a chance of errors; the others are well formed.
        let noisy = rng.range_i64(0, 2) == 0;
        let colours = rng.range_i64(0, 4) == 0;
        let mut counts = [0usize; 3];
        let vertex = |out: &mut String, rng: &mut Rng, counts: &mut [usize; 3]| {
            let [x, y, z] = [number(rng, noisy), number(rng, noisy), number(rng, noisy)];
            let extra = match rng.range_i64(0, 12) {
                _ if colours => " 0.5 0.25 1".to_string(),
                0 if noisy => format!(" {}", number(rng, noisy)),
                0 => " 2".to_string(),
                1 if noisy => " 1 2".to_string(),
                _ => String::new(),
            };
            let short = noisy && rng.range_i64(0, 60) == 0;
            if short {
                out.push_str(&format!("v {x} {y}\n"));
            } else {
                out.push_str(&format!("v {x} {y} {z}{extra}\n"));
            }
            counts[0] += 1;
        };
        for _ in 0..rng.range_i64(1, 7) {
            vertex(&mut out, rng, &mut counts);
        }
        let with = [rng.range_i64(0, 2) == 0, rng.range_i64(0, 2) == 0];
        for (slot, keyword, n) in [(1, "vt", 2), (2, "vn", 3)] {
            if with[slot - 1] {
                for _ in 0..rng.range_i64(1, 5) {
                    let words: Vec<String> = (0..n).map(|_| number(rng, noisy)).collect();
                    out.push_str(&format!("{keyword} {}\n", words.join(" ")));
                    counts[slot] += 1;
                }
            }
        }
        let materials = ["a", "b c", "a", ""];
        for _ in 0..rng.range_i64(0, 30) {
            match rng.range_i64(0, 20) {
                0 => vertex(&mut out, rng, &mut counts),
                1 if with[0] => {
                    out.push_str(&format!(
                        "vt {} {} 0\n",
                        number(rng, noisy),
                        number(rng, noisy)
                    ));
                    counts[1] += 1;
                }
                2 if with[1] => {
                    let words = [number(rng, noisy), number(rng, noisy), number(rng, noisy)];
                    out.push_str(&format!("vn {}\n", words.join(" ")));
                    counts[2] += 1;
                }
                3 => {
                    out.push_str(["o thing\n", "g\n", "g part two\n"][rng.range_i64(0, 3) as usize])
                }
                4 => {
                    let name = materials[rng.range_i64(0, if noisy { 4 } else { 3 }) as usize];
                    let indent = ["", "  ", "\t"][rng.range_i64(0, 3) as usize];
                    out.push_str(&format!("{indent}usemtl {name}\n"));
                }
                5 => out.push_str(
                    ["mtllib x.mtl\n", "# f 1 2 3\n", "\n", "s off\n"]
                        [rng.range_i64(0, 4) as usize],
                ),
                _ => {
                    let keyword = if rng.range_i64(0, 8) == 0 { "l" } else { "f" };
                    let corners = match rng.range_i64(0, 10) {
                        0 => rng.range_i64(if noisy { 0 } else { 1 }, 3),
                        1 => rng.range_i64(5, 9),
                        2 | 3 => 4,
                        _ => 3,
                    };
                    // One form per face, as exporters write them, now and then mixed.
                    let mut form = rng.range_i64(0, 4);
                    out.push_str(keyword);
                    for _ in 0..corners {
                        if rng.range_i64(0, 25) == 0 {
                            form = rng.range_i64(0, if noisy { 6 } else { 4 });
                        }
                        let v = index(rng, counts[0], noisy);
                        // Well-formed files only name the kinds they define.
                        let form = match form {
                            1 | 3 if !noisy && !with[0] => 0,
                            2 | 3 if !noisy && !with[1] => 0,
                            f => f,
                        };
                        let corner = match form {
                            0 => v,
                            1 => format!("{v}/{}", index(rng, counts[1], noisy)),
                            2 => format!("{v}//{}", index(rng, counts[2], noisy)),
                            3 => format!(
                                "{v}/{}/{}",
                                index(rng, counts[1], noisy),
                                index(rng, counts[2], noisy)
                            ),
                            4 => format!("/{}", index(rng, counts[1], noisy)),
                            _ => format!("{v}/1/1/1"),
                        };
                        out.push(' ');
                        out.push_str(&corner);
                    }
                    out.push('\n');
                }
            }
        }
        // Other whitespace: Windows line ends, tabs and runs of spaces.
        match rng.range_i64(0, 8) {
            0 => out.replace('\n', "\r\n"),
            1 => out.replace(' ', " \t "),
            _ => out,
        }
    }

    fn flat3(v: &[Vec3]) -> Vec<u32> {
        v.iter()
            .flat_map(|p| p.to_array())
            .map(f32::to_bits)
            .collect()
    }

    #[test]
    fn statements_read_as_tobj_reads_them() {
        let mut rng = Rng::new(0x0b1_2eade2);
        let (mut loaded, mut refused) = (0, 0);
        for case in 0..6000 {
            let text = random_file(&mut rng);
            let ours = read_statements(&text);
            let theirs = oracle(&text);
            let (ours, theirs) = match (ours, theirs) {
                (Ok(ours), Ok(theirs)) => (ours, theirs),
                (Err(_), Err(())) => {
                    refused += 1;
                    continue;
                }
                (ours, theirs) => {
                    panic!("case {case}: reader {ours:?}, tobj {theirs:?}\n{text}")
                }
            };
            loaded += 1;
            assert_eq!(ours.groups.len(), theirs.len(), "case {case}\n{text}");
            for (group, (name, mesh)) in ours.groups.iter().zip(&theirs) {
                let ours_name = group.usemtl.map(|i| ours.usemtl_names[i as usize].clone());
                assert_eq!(ours_name, *name, "case {case}\n{text}");
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    flat3(&group.positions),
                    bits(&mesh.positions),
                    "case {case}\n{text}"
                );
                assert_eq!(
                    flat3(&group.normals),
                    bits(&mesh.normals),
                    "case {case}\n{text}"
                );
                let uvs: Vec<u32> = group
                    .uvs
                    .iter()
                    .flat_map(|t| t.to_array())
                    .map(f32::to_bits)
                    .collect();
                assert_eq!(uvs, bits(&mesh.texcoords), "case {case}\n{text}");
                let indices: Vec<u32> = group.triangles.iter().flatten().copied().collect();
                assert_eq!(indices, mesh.indices, "case {case}\n{text}");
            }
        }
        // Both outcomes are exercised in earnest.
        assert!(
            loaded > 1500 && refused > 1500,
            "{loaded} loaded, {refused} refused"
        );
    }

    #[test]
    fn where_tobj_fails_a_meaningful_file_still_reads() {
        // A face before its vertices, in a group that ends before they are defined.
        let text = "f 1 2 3\ng next\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert!(oracle(text).is_err());
        let read = read_statements(text).expect("reads");
        assert_eq!(read.groups.len(), 2);
        assert_eq!(read.groups[0].positions, read.groups[1].positions);
        // Colours on only some vertices are ignored.
        let text = "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert!(oracle(text).is_err());
        assert_eq!(
            read_statements(text).expect("reads").groups[0].triangles,
            vec![[0, 1, 2]]
        );
    }

    #[test]
    fn malformed_statements_name_their_line_and_kind() {
        for (text, line, kind) in [
            ("v 0 0\n", 1, tobj::LoadError::PositionParseError),
            (
                "v 0 0 0\nv 1 0 0 0\n",
                2,
                tobj::LoadError::ScalingByZeroError,
            ),
            ("v 0 0 0 1 1\n", 1, tobj::LoadError::ColorParseError),
            ("\nvt 0\n", 2, tobj::LoadError::TexcoordParseError),
            ("vn 0 0 z\n", 1, tobj::LoadError::NormalParseError),
            (
                "v 0 0 0\nf 1/1/1/1 1 1\n",
                2,
                tobj::LoadError::FaceParseError,
            ),
            ("v 0 0 0\n\nf\n", 3, tobj::LoadError::InvalidPolygon),
            ("usemtl\n", 1, tobj::LoadError::MaterialParseError),
            (
                "vt 0 0\nf /1 /1 /1\n",
                2,
                tobj::LoadError::FaceVertexOutOfBounds,
            ),
        ] {
            let e = read_statements(text).expect_err(text);
            assert_eq!(
                (e.line, e.source),
                (Some(line), Some(kind)),
                "{text:?}: {e}"
            );
        }
        // Index errors come from the two-pass check, with its message and line.
        let e = read_statements("v 0 0 0\nf 1 1 2\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("index 2 out of range"), "{e}");
    }
}
