//! An OBJ file's statements: vertices, faces fanned into triangles, the groups that `o`, `g`
//! and `usemtl` start, and the `mtllib` paths.
//!
//! The conventions are those of the `tobj` crate (triangulated, single index), which lucent
//! used before and which remains the oracle of the differential test (`tests.rs`):
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
//! The lines are read in chunks of about [`CHUNK_BYTES`] in parallel (`chunk.rs`), then
//! stitched in order: the counts before each chunk resolve its negative indices, and its group
//! boundaries continue the groups of the chunks before it. The result does not depend on the
//! chunks (the differential test reads with chunks of a few bytes).
//!
//! Where `tobj` fails but the file is meaningful, the reader accepts: a positive index may name
//! a vertex defined later in the file (`tobj` reads it only when defined before the group
//! ends), and colours given for only some vertices are ignored like all colours.

mod chunk;
mod vertices;

use std::collections::HashMap;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::obj::ObjError;
use chunk::{BIAS, Boundary, Chunk, ChunkError, RELATIVE};
use vertices::{Attributes, FirstUse};

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

/// Bytes of text per chunk read by one task (whole lines: a chunk ends at the first line end
/// after this many bytes).
const CHUNK_BYTES: usize = 1 << 20;

/// A group while the chunks are stitched: its material and its triangles' corners.
struct PendingGroup {
    usemtl: Option<u32>,
    corners: std::ops::Range<usize>,
}

/// Reads every statement lucent uses from an OBJ file's text.
///
/// Indices are checked against the counts so far (negative) and the whole file's (positive);
/// a bad one is reported by [`super::obj::check_indices`] with its line. Other syntax errors
/// name their line and carry the `tobj` error of the same kind as their source. With several
/// errors, the first in the file is reported.
pub(super) fn read_statements(text: &str) -> Result<ObjStatements, ObjError> {
    read_in_chunks(text, CHUNK_BYTES)
}

/// [`read_statements`] with chunks of about `chunk_bytes`.
fn read_in_chunks(text: &str, chunk_bytes: usize) -> Result<ObjStatements, ObjError> {
    let chunks: Vec<Chunk> = split_lines(text, chunk_bytes)
        .par_iter()
        .map(|part| Chunk::read(part))
        .collect();
    let mut first_line = 0;
    for chunk in &chunks {
        if let Some((line, error)) = chunk.error {
            let malformed = match error {
                ChunkError::Malformed(kind) => Some(ObjError {
                    line: Some(first_line + line + 1),
                    message: format!("malformed OBJ: {kind}"),
                    source: Some(kind),
                }),
                ChunkError::Index => None,
            };
            return Err(first_error(text, malformed));
        }
        first_line += chunk.lines;
    }
    let mut out = ObjStatements::default();
    let mut pending: Vec<PendingGroup> = Vec::new();
    let mut usemtl: Option<u32> = None;
    let mut known = HashMap::new();
    let (mut group_start, mut faces_in_group) = (0, 0);
    let (mut first_line, mut first_corner) = (0, 0);
    for chunk in &chunks {
        let mut faces_seen = 0;
        for event in &chunk.events {
            faces_in_group += event.faces_before - faces_seen;
            faces_seen = event.faces_before;
            let material = match event.boundary {
                Boundary::Object => usemtl,
                Boundary::Usemtl(name) => Some(intern(&mut out.usemtl_names, &mut known, name)),
            };
            let ends = matches!(event.boundary, Boundary::Object) || material != usemtl;
            if ends && faces_in_group > 0 {
                let end = first_corner + event.corners_before;
                pending.push(PendingGroup {
                    usemtl,
                    corners: group_start..end,
                });
                group_start = end;
                faces_in_group = 0;
            }
            usemtl = material;
        }
        faces_in_group += chunk.faces - faces_seen;
        out.mtllibs.extend(
            chunk
                .mtllibs
                .iter()
                .map(|&(line, path)| (first_line + line + 1, path.to_string())),
        );
        first_line += chunk.lines;
        first_corner += chunk.corners.len();
    }
    pending.push(PendingGroup {
        usemtl,
        corners: group_start..first_corner,
    });
    let (attributes, corners) = concatenate(chunks).ok_or_else(|| index_error(text))?;
    if attributes.positions.len() >= MISSING as usize {
        return Err(ObjError {
            line: None,
            message: "too many vertices".to_string(),
            source: None,
        });
    }
    let mut first_use = FirstUse::new(attributes.positions.len());
    for (number, group) in pending.iter().enumerate() {
        out.groups.push(attributes.group(
            group.usemtl,
            &corners[group.corners.clone()],
            number as u32,
            &mut first_use,
        ));
    }
    Ok(out)
}

/// The chunks' attributes and corners joined in order, each corner resolved to indices into
/// the whole file's lists; `None` if an index is out of range.
fn concatenate(chunks: Vec<Chunk>) -> Option<(Attributes, Vec<Corner>)> {
    let total = |count: fn(&Chunk) -> usize| chunks.iter().map(count).sum::<usize>();
    let mut positions = Vec::with_capacity(total(|c| c.positions.len()));
    let mut uvs = Vec::with_capacity(total(|c| c.uvs.len()));
    let mut normals = Vec::with_capacity(total(|c| c.normals.len()));
    let mut corners = Vec::with_capacity(total(|c| c.corners.len()));
    let mut largest = [0u64; 3];
    for chunk in chunks {
        let before = [positions.len(), uvs.len(), normals.len()];
        for slot in 0..3 {
            largest[slot] = largest[slot].max(chunk.largest[slot]);
            if (before[slot] as i64) + chunk.lowest[slot] < 0 {
                return None;
            }
        }
        corners.extend(chunk.corners.iter().map(|corner| {
            let mut resolved = *corner;
            for (slot, index) in resolved.iter_mut().enumerate() {
                if *index != MISSING && *index & RELATIVE != 0 {
                    // In range: checked against `lowest` above.
                    *index = (before[slot] as i64 + i64::from(*index & !RELATIVE) - BIAS) as u32;
                }
            }
            resolved
        }));
        positions.extend_from_slice(&chunk.positions);
        uvs.extend_from_slice(&chunk.uvs);
        normals.extend_from_slice(&chunk.normals);
    }
    let totals = [positions.len(), uvs.len(), normals.len()];
    let within = largest.iter().zip(totals).all(|(&l, t)| l <= t as u64);
    let attributes = Attributes {
        positions,
        uvs,
        normals,
    };
    within.then_some((attributes, corners))
}

/// `text` cut into runs of whole lines of about `bytes` each (the last may be shorter).
fn split_lines(text: &str, bytes: usize) -> Vec<&str> {
    let mut parts = Vec::with_capacity(text.len() / bytes.max(1) + 1);
    let mut rest = text;
    while !rest.is_empty() {
        // The first line end at or after `bytes` (`str::find` searches with `memchr`: a line
        // may be as long as the file).
        let mut from = bytes.max(1).min(rest.len());
        while !rest.is_char_boundary(from) {
            from += 1;
        }
        let end = match rest[from..].find('\n') {
            Some(k) => from + k + 1,
            None => rest.len(),
        };
        let (part, after) = rest.split_at(end);
        parts.push(part);
        rest = after;
    }
    parts
}

/// The index of `name` in `names` (whose indices `known` holds), appended if new. A map, not
/// a search: a file may switch among thousands of materials millions of times.
fn intern<'a>(names: &mut Vec<String>, known: &mut HashMap<&'a str, u32>, name: &'a str) -> u32 {
    *known.entry(name).or_insert_with(|| {
        names.push(name.to_string());
        (names.len() - 1) as u32
    })
}

/// The first error in the file: `malformed` (the first malformed statement, if that is what
/// stopped the reading) or the first bad face index, whichever comes first (on one line, the
/// malformed statement).
fn first_error(text: &str, malformed: Option<ObjError>) -> ObjError {
    let index = index_error(text);
    match malformed {
        Some(m) if index.line.is_none_or(|line| m.line <= Some(line)) => m,
        _ => index,
    }
}

/// The error for a bad face index, found again with its line by the two-pass check. Where
/// that check finds none, the index was within the file's counts but beyond what the reader
/// holds ([`chunk::BEYOND_ANY_COUNT`]): the file has more vertices than that.
fn index_error(text: &str) -> ObjError {
    index_error_beyond(text, chunk::BEYOND_ANY_COUNT)
}

/// [`index_error`] for a reader that holds at most `beyond` of each kind.
fn index_error_beyond(text: &str, beyond: u64) -> ObjError {
    super::obj::check_indices(text).err().unwrap_or_else(|| {
        let counts = super::obj::attribute_counts(text);
        let message = if counts.iter().any(|&n| n as u64 > beyond) {
            format!(
                "more than {beyond} vertices, texture coordinates or normals: beyond what the \
                 reader holds"
            )
        } else {
            "a face corner names no vertex".to_string()
        };
        ObjError {
            line: None,
            message,
            source: None,
        }
    })
}

#[cfg(test)]
mod tests;
