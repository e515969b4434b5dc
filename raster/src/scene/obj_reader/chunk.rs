//! One chunk of an OBJ file's lines, read on its own: what it defines, its faces' corners, and
//! the group boundaries in it, to be stitched to the chunks before it (`mod.rs`).
//!
//! A negative index may reach into earlier chunks, whose counts are not known yet, so a
//! corner slot is stored in one of three forms:
//!
//! ```text
//!   bit 31 = 0        a 0-based index into the whole file's list (written positive)
//!   bit 31 = 1        RELATIVE: (count before this chunk) + low bits − BIAS (written negative)
//!   u32::MAX          MISSING: the corner names none
//! ```

use glam::{Vec2, Vec3};

use super::{Corner, MISSING};

/// Marks a corner slot counted from the chunk's start (see the module's table).
pub(super) const RELATIVE: u32 = 1 << 31;
/// Added to a relative slot's offset, which may be negative, to store it unsigned.
pub(super) const BIAS: i64 = 1 << 29;
/// The most `v`, `vt` or `vn` statements a face may reach: an index beyond it is refused
/// whatever the counts (see `index_error` in `mod.rs` for the message), and an offset within
/// it fits the relative form. 2²⁸ positions are at least 2 GiB of text (`v 0 0 0` and a line
/// end each) and would make a mesh of half a billion triangles, beyond what a render's memory
/// (about 250 bytes a triangle) holds on any machine lucent runs on.
pub(super) const BEYOND_ANY_COUNT: u64 = 1 << 28;
const _: () = assert!(BEYOND_ANY_COUNT < BIAS as u64);

/// The first error in a chunk, which ends its reading.
#[derive(Clone, Copy, Debug)]
pub(super) enum ChunkError {
    /// A malformed statement, of `tobj`'s kind.
    Malformed(tobj::LoadError),
    /// A face index that is not an integer, is 0 or is out of range.
    Index,
}

/// A statement that may end the current group.
pub(super) enum Boundary<'a> {
    /// `o` or `g`.
    Object,
    /// `usemtl` with its (non-empty) name.
    Usemtl(&'a str),
}

/// A [`Boundary`] and where it falls among the chunk's faces and corners.
pub(super) struct Event<'a> {
    /// `f` and `l` statements in the chunk before it (points and lines included).
    pub faces_before: usize,
    /// Corners in the chunk before it.
    pub corners_before: usize,
    pub boundary: Boundary<'a>,
}

/// What one chunk of whole lines holds.
#[derive(Default)]
pub(super) struct Chunk<'a> {
    /// Lines in the chunk.
    pub lines: usize,
    pub positions: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub normals: Vec<Vec3>,
    /// Three per triangle, in the forms of the module's table.
    pub corners: Vec<Corner>,
    /// `f` and `l` statements (points and lines included).
    pub faces: usize,
    pub events: Vec<Event<'a>>,
    /// `mtllib` statements: (0-based line in the chunk, path).
    pub mtllibs: Vec<(usize, &'a str)>,
    /// The largest positive index per slot, to check against the file's totals.
    pub largest: [u64; 3],
    /// The lowest offset of a negative index from the chunk's start per slot (0 if none
    /// reaches before it), to check against the counts before the chunk. Faces that are
    /// skipped (points, lines) count too: their indices must be in range all the same.
    pub lowest: [i64; 3],
    /// The first error and its 0-based line in the chunk.
    pub error: Option<(usize, ChunkError)>,
}

impl<'a> Chunk<'a> {
    /// Reads `text` (whole lines) up to its first error.
    pub fn read(text: &'a str) -> Chunk<'a> {
        let mut chunk = Chunk::default();
        let mut fan: Vec<Corner> = Vec::new();
        for (number, line) in text.lines().enumerate() {
            chunk.lines = number + 1;
            if let Err(error) = chunk.statement(number, line.trim_start(), &mut fan) {
                chunk.error = Some((number, error));
                break;
            }
        }
        chunk
    }

    /// Reads one line (its leading whitespace trimmed), the `number`th of the chunk.
    fn statement(
        &mut self,
        number: usize,
        line: &'a str,
        fan: &mut Vec<Corner>,
    ) -> Result<(), ChunkError> {
        use tobj::LoadError::*;
        let malformed = ChunkError::Malformed;
        if line.starts_with('#') {
            // A first word starting with `#` is no statement: skipped without splitting the
            // line into words, which a long comment would make as slow as its length.
            return Ok(());
        }
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            return Ok(());
        };
        // The statement's argument as `tobj` takes it: the rest after the first space, trimmed.
        let argument = || line.split_once(' ').unwrap_or_default().1.trim();
        match keyword {
            "v" => {
                let [x, y, z] = numbers::<3>(&mut words).ok_or(malformed(PositionParseError))?;
                let mut p = Vec3::new(x, y, z);
                match (words.next(), words.next(), words.next(), words.next()) {
                    (None, ..) | (Some(_), Some(_), Some(_), None) => {}
                    (Some(w), None, ..) => {
                        let w: f32 = w.parse().map_err(|_| malformed(PositionParseError))?;
                        if w == 0.0 {
                            return Err(malformed(ScalingByZeroError));
                        }
                        p = Vec3::new(p.x / w, p.y / w, p.z / w);
                    }
                    _ => return Err(malformed(ColorParseError)),
                }
                self.positions.push(p);
            }
            "vt" => {
                let [u, v] = numbers::<2>(&mut words).ok_or(malformed(TexcoordParseError))?;
                self.uvs.push(Vec2::new(u, v));
            }
            "vn" => {
                let [x, y, z] = numbers::<3>(&mut words).ok_or(malformed(NormalParseError))?;
                self.normals.push(Vec3::new(x, y, z));
            }
            "f" | "l" => {
                self.faces += 1;
                fan.clear();
                let so_far = [self.positions.len(), self.uvs.len(), self.normals.len()];
                for word in words {
                    fan.push(parse_corner(
                        word,
                        so_far,
                        &mut self.largest,
                        &mut self.lowest,
                    )?);
                }
                match fan.len() {
                    0 => return Err(malformed(InvalidPolygon)),
                    1 | 2 => {}
                    // A corner like `/2` names no vertex (points and lines are skipped unread).
                    _ if fan.iter().any(|c| c[0] == MISSING) => {
                        return Err(malformed(FaceVertexOutOfBounds));
                    }
                    _ => {
                        for pair in fan[1..].windows(2) {
                            self.corners.extend([fan[0], pair[0], pair[1]]);
                        }
                    }
                }
            }
            "o" | "g" => self.boundary(Boundary::Object),
            "usemtl" => {
                let name = argument();
                if name.is_empty() {
                    return Err(malformed(MaterialParseError));
                }
                self.boundary(Boundary::Usemtl(name));
            }
            "mtllib" => {
                let path = argument();
                if !path.is_empty() {
                    self.mtllibs.push((number, path));
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn boundary(&mut self, boundary: Boundary<'a>) {
        self.events.push(Event {
            faces_before: self.faces,
            corners_before: self.corners.len(),
            boundary,
        });
    }
}

/// The first `N` words as `f32` (`str::parse`, as `tobj` reads them), or `None`.
fn numbers<const N: usize>(words: &mut std::str::SplitWhitespace) -> Option<[f32; N]> {
    let mut out = [0.0; N];
    for slot in &mut out {
        *slot = words.next()?.parse().ok()?;
    }
    Some(out)
}

/// One face corner `v[/vt[/vn]]` in the forms of the module's table ([`MISSING`] for an empty
/// part), `so_far` being the chunk's counts. Positive indices raise `largest`, checked once the
/// file's totals are known; negative ones lower `lowest`, checked when the counts before the
/// chunk are.
fn parse_corner(
    word: &str,
    so_far: [usize; 3],
    largest: &mut [u64; 3],
    lowest: &mut [i64; 3],
) -> Result<Corner, ChunkError> {
    let mut corner = [MISSING; 3];
    for (slot, part) in word.split('/').enumerate() {
        if part.is_empty() {
            continue;
        }
        if slot >= 3 {
            return Err(ChunkError::Malformed(tobj::LoadError::FaceParseError));
        }
        let index: i64 = part.parse().map_err(|_| ChunkError::Index)?;
        corner[slot] = match index {
            0 => return Err(ChunkError::Index),
            i if i > 0 => {
                if i as u64 > BEYOND_ANY_COUNT {
                    return Err(ChunkError::Index);
                }
                largest[slot] = largest[slot].max(i as u64);
                (i - 1) as u32
            }
            i => {
                let back = i.unsigned_abs();
                if back > BEYOND_ANY_COUNT {
                    return Err(ChunkError::Index);
                }
                let offset = so_far[slot] as i64 - back as i64;
                lowest[slot] = lowest[slot].min(offset);
                RELATIVE | (offset + BIAS) as u32
            }
        };
    }
    Ok(corner)
}
