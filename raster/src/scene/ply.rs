//! PLY meshes as range scanners and mesh tools write them (the Stanford 3D Scanning Repository
//! models, Meshlab, Blender): ASCII, binary little-endian and binary big-endian bodies.
//!
//! The header goes through the same parser as lucent's sample sets
//! (`crate::output::ply::header`). From it this reader uses:
//!
//! - `element vertex`: `x`, `y`, `z` (any scalar type), the normal `nx`, `ny`, `nz` when all
//!   three are present, texture coordinates from the first pair present among `u`/`v`,
//!   `s`/`t`, `texture_u`/`texture_v`, `texture_s`/`texture_t`;
//! - `element face`: the list `vertex_indices` (or `vertex_index`) of any integer types;
//!   polygons are fan-triangulated `(0, k, k+1)`;
//!
//! and skips every other property and element (lists included), in any order. Normals are
//! kept and UVs checked as for OBJ files (see [`finish_loaded_mesh`]).
//!
//! Malformed input is an error, never a panic: before anything is allocated, every element's
//! count times its smallest entry size is checked against the bytes the body has; errors name
//! the header line, the body line (ASCII) or the byte offset (binary) where reading stopped.
//! A binary body must end exactly after the last element; an ASCII body may end in whitespace.

use std::fmt;

use glam::{Vec2, Vec3};

use super::mesh::finish_loaded_mesh;
use super::model::Mesh;
use crate::memory;
use crate::output::ply::header::{Element, Format, Header, Kind, Scalar};

/// Texture-coordinate property pairs, in order of preference.
const UV_NAMES: [(&str, &str); 4] = [
    ("u", "v"),
    ("s", "t"),
    ("texture_u", "texture_v"),
    ("texture_s", "texture_t"),
];

/// Where in a PLY file a problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlyLocation {
    /// 1-based line (the header, or an ASCII body).
    Line(usize),
    /// Byte offset from the start of the file (a binary body).
    Byte(u64),
}

/// Why a PLY file could not be used.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyError {
    /// Where the problem is, when it is at one place.
    pub at: Option<PlyLocation>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for PlyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.at {
            Some(PlyLocation::Line(line)) => write!(f, "line {line}: {}", self.message),
            Some(PlyLocation::Byte(byte)) => write!(f, "byte {byte}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for PlyError {}

fn at_line(line: usize, message: impl Into<String>) -> PlyError {
    PlyError {
        at: (line > 0).then_some(PlyLocation::Line(line)),
        message: message.into(),
    }
}

/// Parses a PLY file held in memory into one mesh in its own (object) coordinates.
pub fn parse_ply(bytes: &[u8]) -> Result<Mesh, PlyError> {
    let mut rest = bytes;
    let header = Header::parse(&mut rest).map_err(|e| at_line(e.line, e.message))?;
    let layout = MeshLayout::new(&header)?;
    let start = header.length as usize;
    let body_len = (bytes.len() - start) as u64;
    check_counts(&header, body_len)?;
    probe_lists(&header, &layout)?;
    let mut body = match header.format {
        Format::Ascii => Body::Ascii {
            bytes,
            pos: start,
            line: 1 + bytes[..start].iter().filter(|&&b| b == b'\n').count(),
        },
        Format::BinaryLittleEndian => Body::Binary {
            bytes,
            pos: start,
            big_endian: false,
        },
        Format::BinaryBigEndian => Body::Binary {
            bytes,
            pos: start,
            big_endian: true,
        },
    };
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut triangles = Vec::new();
    for element in &header.elements {
        if element.properties.is_empty() {
            continue;
        }
        if element.name == "vertex" {
            // Bounded by `check_counts`.
            let n = element.count as usize;
            let refused = |_| out_of_memory(&header, &layout);
            positions.try_reserve_exact(n).map_err(refused)?;
            if layout.normal.is_some() {
                normals.try_reserve_exact(n).map_err(refused)?;
            }
            if layout.uv.is_some() {
                uvs.try_reserve_exact(n).map_err(refused)?;
            }
            read_vertices(
                &mut body,
                element,
                &layout,
                &mut positions,
                &mut normals,
                &mut uvs,
            )?;
        } else if element.name == "face" {
            triangles
                .try_reserve(element.count as usize)
                .map_err(|_| out_of_memory(&header, &layout))?;
            read_faces(
                &mut body,
                element,
                layout.indices,
                positions.len(),
                &mut triangles,
            )?;
        } else if !body.skip_fixed(element) {
            for _ in 0..element.count {
                for p in &element.properties {
                    body.skip(p.kind)?;
                }
            }
        }
    }
    body.finish()?;
    if triangles.is_empty() {
        return Err(at_line(
            0,
            "the file defines no faces (a mesh needs at least one triangle)",
        ));
    }
    let mesh = Mesh {
        positions,
        normals: Vec::new(),
        uvs: layout.uv.map(|_| uvs),
        triangles,
    };
    finish_loaded_mesh(mesh, layout.normal.map(|_| normals)).map_err(|m| at_line(0, m))
}

/// Which properties of `vertex` and `face` this reader uses (indices into their property
/// lists).
struct MeshLayout {
    position: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
    /// The face's vertex-index list.
    indices: usize,
}

impl MeshLayout {
    fn new(header: &Header) -> Result<MeshLayout, PlyError> {
        let Some(vertex) = header.element("vertex") else {
            return Err(at_line(0, "no 'element vertex'"));
        };
        let Some(face) = header.element("face") else {
            return Err(at_line(
                0,
                "no 'element face' (a point cloud is not a mesh)",
            ));
        };
        if header
            .elements
            .iter()
            .position(|e| e.name == "face")
            .zip(header.elements.iter().position(|e| e.name == "vertex"))
            .is_some_and(|(f, v)| f < v)
        {
            return Err(at_line(
                face.line,
                "element face comes before element vertex (faces must follow their vertices)",
            ));
        }
        let scalar = |name: &str| -> Result<Option<usize>, PlyError> {
            match vertex.property(name) {
                None => Ok(None),
                Some((i, p)) => match p.kind {
                    Kind::Scalar(_) => Ok(Some(i)),
                    Kind::List { .. } => Err(at_line(
                        p.line,
                        format!("vertex property '{name}' must be a scalar, not a list"),
                    )),
                },
            }
        };
        let mut position = [0; 3];
        for (slot, name) in position.iter_mut().zip(["x", "y", "z"]) {
            *slot = scalar(name)?.ok_or_else(|| {
                at_line(
                    vertex.line,
                    format!("element vertex has no property '{name}'"),
                )
            })?;
        }
        let normal = match (scalar("nx")?, scalar("ny")?, scalar("nz")?) {
            (Some(x), Some(y), Some(z)) => Some([x, y, z]),
            _ => None,
        };
        let mut uv = None;
        for (u, v) in UV_NAMES {
            if let (Some(u), Some(v)) = (scalar(u)?, scalar(v)?) {
                uv = Some([u, v]);
                break;
            }
        }
        let Some((indices, list)) = face
            .property("vertex_indices")
            .or_else(|| face.property("vertex_index"))
        else {
            return Err(at_line(
                face.line,
                "element face has no list property 'vertex_indices' (or 'vertex_index')",
            ));
        };
        match list.kind {
            Kind::List { item, .. } if item.is_integer() => {}
            _ => {
                return Err(at_line(
                    list.line,
                    format!("'{}' must be a list of integers", list.name),
                ));
            }
        }
        Ok(MeshLayout {
            position,
            normal,
            uv,
            indices,
        })
    }
}

/// Rejects element counts the body cannot hold, before anything is allocated: each entry takes
/// at least its scalars' and list counts' bytes (binary) or one character per property
/// (ASCII).
fn check_counts(header: &Header, body_len: u64) -> Result<(), PlyError> {
    let mut needed = 0u64;
    for e in &header.elements {
        let per_entry: u64 = match header.format {
            Format::Ascii => e.properties.len() as u64,
            _ => e
                .properties
                .iter()
                .map(|p| match p.kind {
                    Kind::Scalar(t) | Kind::List { count: t, .. } => t.size() as u64,
                })
                .sum(),
        };
        needed = e
            .count
            .checked_mul(per_entry)
            .and_then(|n| n.checked_add(needed))
            .filter(|&n| n <= body_len)
            .ok_or_else(|| {
                at_line(
                    e.line,
                    format!(
                        "element '{}' declares {} entries, more than the {body_len} bytes of the \
                         body can hold",
                        e.name, e.count
                    ),
                )
            })?;
    }
    if let Some(v) = header.element("vertex")
        && v.count > u64::from(u32::MAX)
    {
        return Err(at_line(v.line, format!("too many vertices ({})", v.count)));
    }
    Ok(())
}

/// Bytes the vertex and face lists will hold: 12 a position, 12 a normal, 8 a texture
/// coordinate and 12 a triangle (at least one per face).
fn list_bytes(header: &Header, layout: &MeshLayout) -> u64 {
    let count = |name| header.element(name).map_or(0, |e| e.count);
    let per_vertex =
        12 + 12 * u64::from(layout.normal.is_some()) + 8 * u64::from(layout.uv.is_some());
    count("vertex")
        .saturating_mul(per_vertex)
        .saturating_add(count("face").saturating_mul(12))
}

/// The error for lists the allocator refused to reserve after [`probe_lists`] granted them.
fn out_of_memory(header: &Header, layout: &MeshLayout) -> PlyError {
    let refused = memory::OutOfMemory {
        bytes: list_bytes(header, layout),
        buffer: memory::PLY_LISTS,
    };
    at_line(0, refused.to_string())
}

/// Asks for the vertex and face lists' memory at once, before reading them: their counts are
/// bounded by the body's length (`check_counts`), but an ASCII vertex of three one-character
/// numbers becomes 12 bytes or more.
fn probe_lists(header: &Header, layout: &MeshLayout) -> Result<(), PlyError> {
    memory::probe(list_bytes(header, layout), memory::PLY_LISTS)
        .map_err(|refused| at_line(0, refused.to_string()))
}

fn read_vertices(
    body: &mut Body,
    element: &Element,
    layout: &MeshLayout,
    positions: &mut Vec<Vec3>,
    normals: &mut Vec<Vec3>,
    uvs: &mut Vec<Vec2>,
) -> Result<(), PlyError> {
    let mut values = vec![0.0f64; element.properties.len()];
    for _ in 0..element.count {
        for (value, p) in values.iter_mut().zip(&element.properties) {
            match p.kind {
                Kind::Scalar(t) => *value = body.value(t)?,
                Kind::List { .. } => body.skip(p.kind)?,
            }
        }
        let v3 =
            |[x, y, z]: [usize; 3]| Vec3::new(values[x] as f32, values[y] as f32, values[z] as f32);
        positions.push(v3(layout.position));
        if let Some(n) = layout.normal {
            normals.push(v3(n));
        }
        if let Some([u, v]) = layout.uv {
            uvs.push(Vec2::new(values[u] as f32, values[v] as f32));
        }
    }
    Ok(())
}

fn read_faces(
    body: &mut Body,
    element: &Element,
    index_property: usize,
    vertex_count: usize,
    triangles: &mut Vec<[u32; 3]>,
) -> Result<(), PlyError> {
    let mut polygon = Vec::new();
    for face in 0..element.count {
        for (k, p) in element.properties.iter().enumerate() {
            let Kind::List { count, item } = p.kind else {
                body.skip(p.kind)?;
                continue;
            };
            if k != index_property {
                body.skip(p.kind)?;
                continue;
            }
            let n = body.count(count, item)?;
            if n < 3 {
                return Err(body.error(format!(
                    "face {face} has {n} vertices (a face needs at least 3)"
                )));
            }
            polygon.clear();
            for _ in 0..n {
                let i = body.value(item)?;
                if !(0.0..vertex_count as f64).contains(&i) {
                    return Err(body.error(format!(
                        "face {face} uses vertex {i}, but there are only {vertex_count} vertices"
                    )));
                }
                polygon.push(i as u32);
            }
            for k in 1..polygon.len() - 1 {
                triangles.push([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
    }
    Ok(())
}

/// The body being read: a cursor over the whole file.
enum Body<'a> {
    Ascii {
        bytes: &'a [u8],
        pos: usize,
        /// 1-based line of `pos`.
        line: usize,
    },
    Binary {
        bytes: &'a [u8],
        pos: usize,
        big_endian: bool,
    },
}

impl<'a> Body<'a> {
    /// An error at the current position.
    fn error(&self, message: impl Into<String>) -> PlyError {
        PlyError {
            at: Some(match self {
                Body::Ascii { line, .. } => PlyLocation::Line(*line),
                Body::Binary { pos, .. } => PlyLocation::Byte(*pos as u64),
            }),
            message: message.into(),
        }
    }

    /// The next value of type `t` (exact for every integer type).
    fn value(&mut self, t: Scalar) -> Result<f64, PlyError> {
        match self {
            Body::Binary {
                bytes,
                pos,
                big_endian,
            } => {
                let size = t.size();
                let Some(raw) = bytes.get(*pos..*pos + size) else {
                    return Err(self.error(format!(
                        "the file ends inside a {} value (truncated)",
                        t.name()
                    )));
                };
                let mut b = [0u8; 8];
                b[..size].copy_from_slice(raw);
                if *big_endian {
                    b[..size].reverse();
                }
                *pos += size;
                let [b0, b1, b2, b3, ..] = b;
                Ok(match t {
                    Scalar::I8 => f64::from(b0 as i8),
                    Scalar::U8 => f64::from(b0),
                    Scalar::I16 => f64::from(i16::from_le_bytes([b0, b1])),
                    Scalar::U16 => f64::from(u16::from_le_bytes([b0, b1])),
                    Scalar::I32 => f64::from(i32::from_le_bytes([b0, b1, b2, b3])),
                    Scalar::U32 => f64::from(u32::from_le_bytes([b0, b1, b2, b3])),
                    Scalar::F32 => f64::from(f32::from_le_bytes([b0, b1, b2, b3])),
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
            Body::Ascii { bytes, pos, line } => {
                let Some(token) = next_token(bytes, pos, line) else {
                    return Err(self.error("the file ends before the last element (truncated)"));
                };
                let fail = |this: &Self| {
                    this.error(format!(
                        "'{}' is not a {} value",
                        String::from_utf8_lossy(token),
                        t.name()
                    ))
                };
                let Ok(text) = std::str::from_utf8(token) else {
                    return Err(fail(self));
                };
                if !t.is_integer() {
                    return text.parse::<f64>().map_err(|_| fail(self));
                }
                let (low, high) = match t {
                    Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
                    Scalar::U8 => (0, u8::MAX.into()),
                    Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
                    Scalar::U16 => (0, u16::MAX.into()),
                    Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
                    _ => (0, u32::MAX.into()),
                };
                match text.parse::<i64>() {
                    Ok(v) if (low..=high).contains(&v) => Ok(v as f64),
                    _ => Err(fail(self)),
                }
            }
        }
    }

    /// A list's item count, checked against the bytes left for its items.
    fn count(&mut self, count: Scalar, item: Scalar) -> Result<u64, PlyError> {
        let n = self.value(count)?;
        if n < 0.0 {
            return Err(self.error(format!("negative list count {n}")));
        }
        let n = n as u64;
        // ASCII items take at least two bytes each (a digit and a separator), except the last.
        let (left, item_bytes) = match self {
            Body::Binary { bytes, pos, .. } => (bytes.len() - *pos, item.size() as u64),
            Body::Ascii { bytes, pos, .. } => (bytes.len() - *pos + 1, 2),
        };
        if n.saturating_mul(item_bytes) > left as u64 {
            return Err(self.error(format!(
                "a list of {n} items does not fit in the {left} bytes left (truncated)"
            )));
        }
        Ok(n)
    }

    /// Reads past a whole binary element of scalar properties at once, if it fits in what is
    /// left; false (nothing read) otherwise, where reading entry by entry finds the error.
    fn skip_fixed(&mut self, element: &Element) -> bool {
        let Body::Binary { bytes, pos, .. } = self else {
            return false;
        };
        let mut size = 0u64;
        for p in &element.properties {
            match p.kind {
                Kind::Scalar(t) => size += t.size() as u64,
                Kind::List { .. } => return false,
            }
        }
        match element.count.checked_mul(size) {
            Some(total) if total <= (bytes.len() - *pos) as u64 => {
                *pos += total as usize;
                true
            }
            _ => false,
        }
    }

    /// Reads past one property.
    fn skip(&mut self, kind: Kind) -> Result<(), PlyError> {
        match kind {
            Kind::Scalar(t) => self.value(t).map(drop),
            Kind::List { count, item } => {
                let n = self.count(count, item)?;
                if let Body::Binary { pos, .. } = self {
                    // `count` checked that the items fit.
                    *pos += n as usize * item.size();
                    return Ok(());
                }
                for _ in 0..n {
                    self.value(item)?;
                }
                Ok(())
            }
        }
    }

    /// Checks that nothing but (ASCII) whitespace follows the last element.
    fn finish(&self) -> Result<(), PlyError> {
        match self {
            Body::Binary { bytes, pos, .. } if *pos < bytes.len() => Err(self.error(format!(
                "{} bytes of unexpected data after the last element",
                bytes.len() - pos
            ))),
            Body::Ascii { bytes, pos, .. }
                if !bytes[*pos..].iter().all(u8::is_ascii_whitespace) =>
            {
                Err(self.error("unexpected data after the last element"))
            }
            _ => Ok(()),
        }
    }
}

/// The next whitespace-separated token of an ASCII body, advancing `pos` (and `line` over
/// newlines); `None` at the end.
fn next_token<'a>(bytes: &'a [u8], pos: &mut usize, line: &mut usize) -> Option<&'a [u8]> {
    while let Some(&b) = bytes.get(*pos)
        && b.is_ascii_whitespace()
    {
        if b == b'\n' {
            *line += 1;
        }
        *pos += 1;
    }
    let start = *pos;
    while bytes.get(*pos).is_some_and(|b| !b.is_ascii_whitespace()) {
        *pos += 1;
    }
    (start < *pos).then(|| &bytes[start..*pos])
}

#[cfg(test)]
mod tests;
