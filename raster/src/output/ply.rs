//! The baked irradiance sample set: a binary PLY point cloud.
//!
//! `lucent bake` writes the irradiance samples (position, normal, the surface area each one
//! represents, and the irradiance there) so that `lucent render` can load them instead of
//! sampling and lighting again, and so that they can be inspected in any point-cloud viewer.
//!
//! # Format
//!
//! A standard PLY 1.0 file with a binary little-endian body:
//!
//! ```text
//! ply
//! format binary_little_endian 1.0
//! comment lucent sample-set v1
//! comment <provenance, one line each, e.g. "scene scenes/bunny.toml", "seed 1">
//! element vertex <N>
//! property float x
//! property float y
//! property float z
//! property float nx
//! property float ny
//! property float nz
//! property float area
//! property float irradiance_r
//! property float irradiance_g
//! property float irradiance_b
//! end_header
//! <N × 40 bytes: the ten properties of each sample as IEEE-754 f32, little-endian, in order>
//! ```
//!
//! Header lines end with `\n`. Units: positions and areas in scene units (area in units²),
//! normals unit length, irradiance in linear RGB (W/m² per unit of light intensity, the same
//! scale the renderer uses). The writer emits exactly the header above — the provenance
//! comments are whatever the caller passes — so the same samples give the same bytes.
//!
//! # What the reader accepts
//!
//! - `ascii` and `binary_big_endian` bodies are rejected with a message saying so.
//! - The ten properties above must each appear exactly once in `element vertex`, with type
//!   `float` (or its alias `float32`), in any order. Other scalar vertex properties (any PLY
//!   type, e.g. `red`/`green`/`blue` added by a viewer) are skipped; list properties in the
//!   vertex element are rejected.
//! - Other elements are accepted only with a count of 0 (some tools write `element face 0`).
//! - A comment `lucent sample-set vK` with K ≠ 1 is rejected (a future format version); files
//!   without the marker are accepted if they otherwise match.
//! - The file size must equal header length + N × vertex size exactly (truncated files and
//!   trailing data are errors naming both sizes); N above [`MAX_SAMPLES`] is rejected before
//!   anything is allocated.
//! - Every sample is validated: finite position, finite normal within 10⁻³ of unit length,
//!   finite area ≥ 0, finite irradiance ≥ 0 per channel. The error names the vertex index.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use glam::Vec3;

use super::OutputError;
use super::atomic::write_atomically;

/// The comment that marks (and versions) a lucent sample set.
pub const FORMAT_COMMENT: &str = "lucent sample-set v1";

/// The most samples the reader accepts (2²⁸ ≈ 268 million, 10.7 GB of samples): larger
/// counts are taken to be corruption.
pub const MAX_SAMPLES: u64 = 1 << 28;

/// Longest header the reader accepts.
const MAX_HEADER_BYTES: u64 = 64 * 1024;

/// How far a normal's length may be from 1.
const NORMAL_TOLERANCE: f32 = 1e-3;

/// The vertex properties, in the order they are written.
const PROPERTIES: [&str; 10] = [
    "x",
    "y",
    "z",
    "nx",
    "ny",
    "nz",
    "area",
    "irradiance_r",
    "irradiance_g",
    "irradiance_b",
];

/// Bytes per sample as written.
const RECORD_BYTES: usize = 4 * PROPERTIES.len();

/// Irradiance samples on the translucent surfaces (structure of arrays, one entry per sample
/// in each vector).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleSet {
    /// Sample positions (world space, scene units).
    pub positions: Vec<Vec3>,
    /// Unit surface normals.
    pub normals: Vec<Vec3>,
    /// Surface area each sample represents (scene units²).
    pub areas: Vec<f32>,
    /// Irradiance at each sample (linear RGB).
    pub irradiance: Vec<Vec3>,
}

impl SampleSet {
    /// Number of samples (the length of `positions`).
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Checks that all four vectors have the same length and every value is valid (see the
    /// module doc).
    pub fn validate(&self) -> Result<(), OutputError> {
        self.check(Path::new(""))
    }

    fn check(&self, path: &Path) -> Result<(), OutputError> {
        let n = self.positions.len();
        if self.normals.len() != n || self.areas.len() != n || self.irradiance.len() != n {
            return Err(OutputError::invalid(
                path,
                format!(
                    "sample set vectors differ in length: {} positions, {} normals, {} areas, \
                     {} irradiance values",
                    n,
                    self.normals.len(),
                    self.areas.len(),
                    self.irradiance.len()
                ),
            ));
        }
        for i in 0..n {
            check_sample(
                self.positions[i],
                self.normals[i],
                self.areas[i],
                self.irradiance[i],
            )
            .map_err(|message| OutputError::SampleValue {
                path: path.to_path_buf(),
                vertex: i,
                message,
            })?;
        }
        Ok(())
    }
}

/// Validates one sample; the message names the bad value.
fn check_sample(p: Vec3, n: Vec3, area: f32, e: Vec3) -> Result<(), String> {
    if !p.is_finite() {
        return Err(format!("position {p} is not finite"));
    }
    if !n.is_finite() || (n.length() - 1.0).abs() > NORMAL_TOLERANCE {
        return Err(format!("normal {n} is not of unit length"));
    }
    if !area.is_finite() || area < 0.0 {
        return Err(format!("area {area} is not a finite non-negative number"));
    }
    if !e.is_finite() || e.min_element() < 0.0 {
        return Err(format!("irradiance {e} is not finite and non-negative"));
    }
    Ok(())
}

/// Writes `samples` as a binary little-endian PLY (format in the module doc), atomically.
///
/// `comments` are written as header comments after the format marker, e.g. the scene file,
/// seed and sample count; each must be a single line of printable ASCII. Invalid samples are
/// rejected (with the index) so that every written file can be read back.
pub fn write_ply(path: &Path, samples: &SampleSet, comments: &[&str]) -> Result<(), OutputError> {
    samples.check(path)?;
    for c in comments {
        if !c.bytes().all(|b| (0x20..0x7f).contains(&b)) {
            return Err(OutputError::invalid(
                path,
                format!("PLY comment {c:?} must be one line of printable ASCII"),
            ));
        }
    }

    let mut header = String::new();
    header.push_str("ply\nformat binary_little_endian 1.0\n");
    header.push_str(&format!("comment {FORMAT_COMMENT}\n"));
    for c in comments {
        header.push_str(&format!("comment {c}\n"));
    }
    header.push_str(&format!("element vertex {}\n", samples.len()));
    for p in PROPERTIES {
        header.push_str(&format!("property float {p}\n"));
    }
    header.push_str("end_header\n");

    let io_err = |e| OutputError::io(path, "writing the PLY failed", e);
    write_atomically(path, |w| {
        w.write_all(header.as_bytes()).map_err(io_err)?;
        let mut record = [0u8; RECORD_BYTES];
        for i in 0..samples.len() {
            let (p, n, e) = (
                samples.positions[i],
                samples.normals[i],
                samples.irradiance[i],
            );
            let values = [
                p.x,
                p.y,
                p.z,
                n.x,
                n.y,
                n.z,
                samples.areas[i],
                e.x,
                e.y,
                e.z,
            ];
            for (chunk, v) in record.chunks_exact_mut(4).zip(values) {
                chunk.copy_from_slice(&v.to_le_bytes());
            }
            w.write_all(&record).map_err(io_err)?;
        }
        Ok(())
    })
}

/// Reads a sample set written by [`write_ply`] (or any PLY matching the module doc).
pub fn read_ply(path: &Path) -> Result<SampleSet, OutputError> {
    read_ply_with_comments(path).map(|(samples, _)| samples)
}

/// Like [`read_ply`], also returning the header comments other than the format marker.
pub fn read_ply_with_comments(path: &Path) -> Result<(SampleSet, Vec<String>), OutputError> {
    let file = File::open(path).map_err(|e| OutputError::io(path, "opening the PLY failed", e))?;
    let file_len = file
        .metadata()
        .map_err(|e| OutputError::io(path, "reading the PLY's size failed", e))?
        .len();
    let mut reader = BufReader::new(file);
    let header = parse_header(path, &mut reader)?;

    let expected = header
        .vertex_count
        .checked_mul(header.stride)
        .and_then(|body| body.checked_add(header.length))
        .ok_or_else(|| header_err(path, 0, "vertex count times vertex size overflows"))?;
    if expected != file_len {
        return Err(OutputError::PlySize {
            path: path.to_path_buf(),
            expected,
            actual: file_len,
        });
    }

    // Bounded by MAX_SAMPLES and consistent with the file size, so the allocation is sane.
    let n = header.vertex_count as usize;
    let mut set = SampleSet {
        positions: Vec::with_capacity(n),
        normals: Vec::with_capacity(n),
        areas: Vec::with_capacity(n),
        irradiance: Vec::with_capacity(n),
    };
    let mut record = vec![0u8; header.stride as usize];
    let mut v = [0.0f32; PROPERTIES.len()];
    for i in 0..n {
        reader
            .read_exact(&mut record)
            .map_err(|e| OutputError::io(path, format!("reading vertex {i} failed"), e))?;
        for (value, &offset) in v.iter_mut().zip(&header.offsets) {
            let mut bytes = [0u8; 4];
            bytes.copy_from_slice(&record[offset..offset + 4]);
            *value = f32::from_le_bytes(bytes);
        }
        let p = Vec3::new(v[0], v[1], v[2]);
        let nrm = Vec3::new(v[3], v[4], v[5]);
        let e = Vec3::new(v[7], v[8], v[9]);
        check_sample(p, nrm, v[6], e).map_err(|message| OutputError::SampleValue {
            path: path.to_path_buf(),
            vertex: i,
            message,
        })?;
        set.positions.push(p);
        set.normals.push(nrm);
        set.areas.push(v[6]);
        set.irradiance.push(e);
    }
    Ok((set, header.comments))
}

/// What the header says about the body.
struct Header {
    /// Bytes up to and including the `end_header` line.
    length: u64,
    vertex_count: u64,
    /// Bytes per vertex.
    stride: u64,
    /// Byte offset within a vertex of each of [`PROPERTIES`].
    offsets: [usize; PROPERTIES.len()],
    comments: Vec<String>,
}

struct Element {
    name: String,
    count: u64,
    line: usize,
    /// (name, type name, size in bytes; `None` for list properties, line).
    properties: Vec<(String, String, Option<u64>, usize)>,
}

fn header_err(path: &Path, line: usize, message: impl Into<String>) -> OutputError {
    OutputError::PlyHeader {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Size of a PLY scalar type, or `None` for an unknown type name.
fn scalar_size(ty: &str) -> Option<u64> {
    Some(match ty {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => return None,
    })
}

fn parse_header(path: &Path, reader: &mut impl BufRead) -> Result<Header, OutputError> {
    let mut length = 0u64;
    let mut line_no = 0usize;
    let mut raw = Vec::new();
    let mut format_seen = false;
    let mut comments = Vec::new();
    let mut elements: Vec<Element> = Vec::new();

    loop {
        raw.clear();
        let limit = MAX_HEADER_BYTES - length;
        let n = reader
            .by_ref()
            .take(limit)
            .read_until(b'\n', &mut raw)
            .map_err(|e| OutputError::io(path, "reading the PLY header failed", e))?;
        length += n as u64;
        line_no += 1;
        if raw.last() != Some(&b'\n') {
            let message = if length >= MAX_HEADER_BYTES {
                format!("no end_header within the first {MAX_HEADER_BYTES} bytes")
            } else if line_no == 1 {
                "not a PLY file (it does not start with a 'ply' line)".to_string()
            } else {
                "the file ends before end_header".to_string()
            };
            return Err(header_err(path, line_no, message));
        }
        raw.pop();
        if raw.last() == Some(&b'\r') {
            raw.pop();
        }
        let Ok(text) = std::str::from_utf8(&raw) else {
            let message = if line_no == 1 {
                "not a PLY file (it does not start with a 'ply' line)"
            } else {
                "header line is not text"
            };
            return Err(header_err(path, line_no, message));
        };
        if line_no == 1 {
            if text != "ply" {
                return Err(header_err(
                    path,
                    1,
                    "not a PLY file (it does not start with a 'ply' line)",
                ));
            }
            continue;
        }
        let mut tokens = text.split_ascii_whitespace();
        let keyword = tokens.next().unwrap_or("");
        let args: Vec<&str> = tokens.collect();
        match keyword {
            "format" => {
                if format_seen {
                    return Err(header_err(path, line_no, "second format line"));
                }
                format_seen = true;
                match args.as_slice() {
                    ["binary_little_endian", "1.0"] => {}
                    ["ascii", _] => {
                        return Err(header_err(
                            path,
                            line_no,
                            "ASCII PLY is not supported: sample sets are binary_little_endian",
                        ));
                    }
                    ["binary_big_endian", _] => {
                        return Err(header_err(
                            path,
                            line_no,
                            "big-endian PLY is not supported: sample sets are \
                             binary_little_endian",
                        ));
                    }
                    ["binary_little_endian", v] => {
                        return Err(header_err(
                            path,
                            line_no,
                            format!("PLY version {v} is not supported (only 1.0)"),
                        ));
                    }
                    _ => {
                        return Err(header_err(
                            path,
                            line_no,
                            format!("malformed format line '{text}'"),
                        ));
                    }
                }
            }
            "comment" => {
                // Everything after "comment " is the comment, kept verbatim.
                let rest = text.trim_start().strip_prefix("comment").unwrap_or("");
                let body = rest.strip_prefix(' ').unwrap_or(rest);
                if body.trim() == FORMAT_COMMENT {
                    continue;
                }
                if let Some(version) = body.trim().strip_prefix("lucent sample-set ") {
                    return Err(header_err(
                        path,
                        line_no,
                        format!(
                            "sample-set format version '{version}' is not supported (this \
                             lucent reads v1)"
                        ),
                    ));
                }
                comments.push(body.to_string());
            }
            "obj_info" => {}
            "element" => {
                if !format_seen {
                    return Err(header_err(path, line_no, "element before the format line"));
                }
                let [name, count] = args.as_slice() else {
                    return Err(header_err(
                        path,
                        line_no,
                        format!("malformed element line '{text}'"),
                    ));
                };
                let count: u64 = count.parse().map_err(|_| {
                    header_err(
                        path,
                        line_no,
                        format!("element count '{count}' is not a number"),
                    )
                })?;
                if elements.iter().any(|e| e.name == *name) {
                    return Err(header_err(
                        path,
                        line_no,
                        format!("second element '{name}'"),
                    ));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    line: line_no,
                    properties: Vec::new(),
                });
            }
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(header_err(path, line_no, "property before any element"));
                };
                let entry = match args.as_slice() {
                    ["list", count_ty, item_ty, name] => {
                        if scalar_size(count_ty).is_none() || scalar_size(item_ty).is_none() {
                            return Err(header_err(
                                path,
                                line_no,
                                format!("unknown type in list property '{name}'"),
                            ));
                        }
                        (name.to_string(), "list".to_string(), None, line_no)
                    }
                    [ty, name] => {
                        let size = scalar_size(ty).ok_or_else(|| {
                            header_err(
                                path,
                                line_no,
                                format!("unknown type '{ty}' of property '{name}'"),
                            )
                        })?;
                        (name.to_string(), ty.to_string(), Some(size), line_no)
                    }
                    _ => {
                        return Err(header_err(
                            path,
                            line_no,
                            format!("malformed property line '{text}'"),
                        ));
                    }
                };
                element.properties.push(entry);
            }
            "end_header" => {
                if !args.is_empty() {
                    return Err(header_err(path, line_no, "text after end_header"));
                }
                break;
            }
            other => {
                return Err(header_err(
                    path,
                    line_no,
                    format!("unknown header keyword '{other}'"),
                ));
            }
        }
    }

    if !format_seen {
        return Err(header_err(path, 0, "no format line"));
    }
    let mut vertex = None;
    for e in &elements {
        if e.name == "vertex" {
            vertex = Some(e);
        } else if e.count != 0 {
            return Err(header_err(
                path,
                e.line,
                format!(
                    "element '{}' with {} entries is not supported (a sample set has only \
                     vertices)",
                    e.name, e.count
                ),
            ));
        }
    }
    let Some(vertex) = vertex else {
        return Err(header_err(path, 0, "no 'element vertex'"));
    };
    if vertex.count > MAX_SAMPLES {
        return Err(header_err(
            path,
            vertex.line,
            format!(
                "vertex count {} is absurd (at most {MAX_SAMPLES} samples)",
                vertex.count
            ),
        ));
    }

    let mut stride = 0u64;
    let mut offsets = [None::<usize>; PROPERTIES.len()];
    for (i, (name, ty, size, line)) in vertex.properties.iter().enumerate() {
        let Some(size) = size else {
            return Err(header_err(
                path,
                *line,
                format!("list property '{name}' in element vertex is not supported"),
            ));
        };
        if vertex.properties[..i].iter().any(|(n, ..)| n == name) {
            return Err(header_err(
                path,
                *line,
                format!("property '{name}' given twice"),
            ));
        }
        if let Some(k) = PROPERTIES.iter().position(|p| p == name) {
            if ty != "float" && ty != "float32" {
                return Err(header_err(
                    path,
                    *line,
                    format!("property '{name}' must be float, found {ty}"),
                ));
            }
            offsets[k] = Some(stride as usize);
        }
        stride += size;
    }
    let mut resolved = [0usize; PROPERTIES.len()];
    for (k, offset) in offsets.iter().enumerate() {
        resolved[k] = offset.ok_or_else(|| {
            header_err(
                path,
                vertex.line,
                format!("element vertex has no property '{}'", PROPERTIES[k]),
            )
        })?;
    }
    Ok(Header {
        length,
        vertex_count: vertex.count,
        stride,
        offsets: resolved,
        comments,
    })
}

#[cfg(test)]
mod tests {
    use super::super::atomic::tests::TestDir;
    use super::*;

    fn samples(n: usize) -> SampleSet {
        let mut s = SampleSet::default();
        for i in 0..n {
            let t = i as f32;
            s.positions.push(Vec3::new(t * 0.1, -t, 1e-30 * t));
            let a = t * 0.7;
            s.normals.push(Vec3::new(a.cos(), a.sin(), 0.0));
            s.areas.push(if i == 1 { 0.0 } else { 1.0 / (t + 1.0) });
            s.irradiance.push(Vec3::new(t, 0.5 * t, f32::MIN_POSITIVE));
        }
        s
    }

    /// Builds a PLY file by hand: header lines plus little-endian f32 values.
    fn raw_ply(header: &[&str], values: &[f32]) -> Vec<u8> {
        let mut bytes = Vec::new();
        for line in header {
            bytes.extend_from_slice(line.as_bytes());
            bytes.push(b'\n');
        }
        for v in values {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes
    }

    const STANDARD: [&str; 10] = [
        "property float x",
        "property float y",
        "property float z",
        "property float nx",
        "property float ny",
        "property float nz",
        "property float area",
        "property float irradiance_r",
        "property float irradiance_g",
        "property float irradiance_b",
    ];

    fn header_with(count: usize, props: &[&str]) -> Vec<String> {
        let mut h = vec![
            "ply".to_string(),
            "format binary_little_endian 1.0".to_string(),
            format!("element vertex {count}"),
        ];
        h.extend(props.iter().map(|s| s.to_string()));
        h.push("end_header".to_string());
        h
    }

    fn read_bytes(dir: &TestDir, bytes: &[u8]) -> Result<SampleSet, OutputError> {
        let path = dir.path("t.ply");
        std::fs::write(&path, bytes).unwrap();
        read_ply(&path)
    }

    fn expect_err(dir: &TestDir, bytes: &[u8], needle: &str) {
        let err = read_bytes(dir, bytes).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains(needle), "'{msg}' does not contain '{needle}'");
        assert!(msg.contains("t.ply"), "'{msg}' does not name the file");
    }

    /// One valid sample: position, unit normal, area, irradiance.
    const ONE: [f32; 10] = [1.0, 2.0, 3.0, 0.0, 0.0, 1.0, 0.5, 0.1, 0.2, 0.3];

    #[test]
    fn round_trip_is_bit_exact_with_comments() {
        let dir = TestDir::new("ply-rt");
        let path = dir.path("s.ply");
        let set = samples(257);
        // The last comment checks that spaces inside a comment survive verbatim.
        let written = ["scene scenes/bunny.toml", "seed 1", " padded  "];
        write_ply(&path, &set, &written).unwrap();
        let (back, comments) = read_ply_with_comments(&path).unwrap();
        assert_eq!(comments, written);
        assert_eq!(back.len(), 257);
        let bits = |v: &[Vec3]| {
            v.iter()
                .flat_map(|p| p.to_array().map(f32::to_bits))
                .collect()
        };
        let bits_a: Vec<u32> = bits(&set.positions);
        assert_eq!(bits_a, bits(&back.positions));
        let bits_n: Vec<u32> = bits(&set.normals);
        assert_eq!(bits_n, bits(&back.normals));
        let bits_e: Vec<u32> = bits(&set.irradiance);
        assert_eq!(bits_e, bits(&back.irradiance));
        let areas = |v: &[f32]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
        assert_eq!(areas(&set.areas), areas(&back.areas));

        // Exact byte layout: the documented header, then 40 bytes per sample.
        let bytes = std::fs::read(&path).unwrap();
        let header = "ply\nformat binary_little_endian 1.0\ncomment lucent sample-set v1\n\
            comment scene scenes/bunny.toml\ncomment seed 1\ncomment  padded  \n\
            element vertex 257\n\
            property float x\nproperty float y\nproperty float z\nproperty float nx\n\
            property float ny\nproperty float nz\nproperty float area\n\
            property float irradiance_r\nproperty float irradiance_g\n\
            property float irradiance_b\nend_header\n";
        assert_eq!(&bytes[..header.len()], header.as_bytes());
        assert_eq!(bytes.len(), header.len() + 257 * 40);
        let second_y = &bytes[header.len() + 40 + 4..header.len() + 40 + 8];
        assert_eq!(second_y, (-1.0f32).to_le_bytes());

        // Deterministic.
        write_ply(&dir.path("again.ply"), &set, &written).unwrap();
        assert_eq!(bytes, std::fs::read(dir.path("again.ply")).unwrap());
    }

    #[test]
    fn empty_set_round_trips() {
        let dir = TestDir::new("ply-empty");
        let path = dir.path("e.ply");
        write_ply(&path, &SampleSet::default(), &[]).unwrap();
        assert_eq!(read_ply(&path).unwrap(), SampleSet::default());
    }

    #[test]
    fn extra_properties_reordering_and_zero_count_elements_are_accepted() {
        let dir = TestDir::new("ply-extra");
        // Reordered required properties, a double and a uchar in between, a CRLF header, an
        // empty face element.
        let header = [
            "ply\r",
            "format binary_little_endian 1.0\r",
            "obj_info from some viewer\r",
            "element vertex 1\r",
            "property float irradiance_b\r",
            "property double weight\r",
            "property float32 x\r",
            "property float y\r",
            "property uchar red\r",
            "property float z\r",
            "property float nx\r",
            "property float ny\r",
            "property float nz\r",
            "property float area\r",
            "property float irradiance_r\r",
            "property float irradiance_g\r",
            "element face 0\r",
            "property list uchar int vertex_indices\r",
            "end_header\r",
        ];
        let mut bytes = raw_ply(&header, &[0.3]);
        bytes.extend_from_slice(&7.5f64.to_le_bytes());
        bytes.extend_from_slice(&1.0f32.to_le_bytes());
        bytes.extend_from_slice(&2.0f32.to_le_bytes());
        bytes.push(200);
        for v in [3.0f32, 0.0, 0.0, 1.0, 0.5, 0.1, 0.2] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let set = read_bytes(&dir, &bytes).unwrap();
        assert_eq!(set.positions, vec![Vec3::new(1.0, 2.0, 3.0)]);
        assert_eq!(set.normals, vec![Vec3::Z]);
        assert_eq!(set.areas, vec![0.5]);
        assert_eq!(set.irradiance, vec![Vec3::new(0.1, 0.2, 0.3)]);
    }

    #[test]
    fn malformed_headers_are_rejected_with_clear_messages() {
        let dir = TestDir::new("ply-header");
        let ok = header_with(1, &STANDARD);
        let with = |f: &dyn Fn(&mut Vec<String>)| {
            let mut h = ok.clone();
            f(&mut h);
            let h: Vec<&str> = h.iter().map(String::as_str).collect();
            raw_ply(&h, &ONE)
        };
        // Sanity: the unmodified header reads.
        assert!(read_bytes(&dir, &with(&|_| {})).is_ok());

        expect_err(&dir, b"", "not a PLY file");
        expect_err(&dir, b"\x89PNG\r\n\x1a\n", "not a PLY file");
        expect_err(&dir, &with(&|h| h[0] = "plyx".into()), "not a PLY file");
        expect_err(
            &dir,
            &with(&|h| h[1] = "format ascii 1.0".into()),
            "line 2: ASCII PLY is not supported",
        );
        expect_err(
            &dir,
            &with(&|h| h[1] = "format binary_big_endian 1.0".into()),
            "big-endian PLY is not supported",
        );
        expect_err(
            &dir,
            &with(&|h| h[1] = "format binary_little_endian 2.0".into()),
            "2.0",
        );
        expect_err(
            &dir,
            &with(&|h| {
                h.remove(1);
            }),
            "element before the format line",
        );
        expect_err(
            &dir,
            &with(&|h| h[4] = "property double y".into()),
            "'y' must be float",
        );
        expect_err(
            &dir,
            &with(&|h| h[4] = "property half y".into()),
            "unknown type 'half'",
        );
        expect_err(
            &dir,
            &with(&|h| h[4] = "property float x".into()),
            "'x' given twice",
        );
        expect_err(
            &dir,
            &with(&|h| h[4] = "property float why".into()),
            "no property 'y'",
        );
        expect_err(
            &dir,
            &with(&|h| h.insert(3, "property list uchar int idx".into())),
            "list property 'idx'",
        );
        expect_err(
            &dir,
            &with(&|h| h[2] = "element vertex many".into()),
            "'many' is not",
        );
        expect_err(
            &dir,
            &with(&|h| {
                h.insert(13, "element face 2".into());
            }),
            "element 'face' with 2 entries",
        );
        expect_err(
            &dir,
            &with(&|h| h[2] = "element point 0".into()),
            "no 'element vertex'",
        );
        expect_err(
            &dir,
            &with(&|h| h.insert(2, "color red".into())),
            "unknown header keyword",
        );
        expect_err(
            &dir,
            &with(&|h| h.insert(2, "comment lucent sample-set v2".into())),
            "version 'v2' is not supported",
        );
        // Header never ends.
        let endless = raw_ply(&["ply", "format binary_little_endian 1.0"], &[]);
        expect_err(&dir, &endless, "ends before end_header");
        let mut huge = b"ply\ncomment ".to_vec();
        huge.extend(std::iter::repeat_n(b'a', 70_000));
        expect_err(&dir, &huge, "no end_header within");
    }

    #[test]
    fn size_mismatches_name_expected_and_actual() {
        let dir = TestDir::new("ply-size");
        let path = dir.path("s.ply");
        write_ply(&path, &samples(10), &[]).unwrap();
        let full = std::fs::read(&path).unwrap();
        let len = full.len() as u64;

        let err = read_bytes(&dir, &full[..full.len() - 3]).unwrap_err();
        assert!(
            matches!(err, OutputError::PlySize { expected, actual, .. }
                if expected == len && actual == len - 3),
            "{err:?}"
        );
        assert!(
            err.to_string().contains(&format!("{} bytes", len - 3)),
            "{err}"
        );
        assert!(err.to_string().contains("truncated"), "{err}");

        let mut long = full.clone();
        long.push(0);
        let err = read_bytes(&dir, &long).unwrap_err();
        assert!(err.to_string().contains("trailing data"), "{err}");

        // Every truncation inside the body or header is an error.
        for cut in (0..full.len()).step_by(7) {
            assert!(read_bytes(&dir, &full[..cut]).is_err(), "cut at {cut}");
        }
    }

    #[test]
    fn absurd_counts_are_rejected_before_allocating() {
        let dir = TestDir::new("ply-absurd");
        let h = header_with(usize::MAX, &STANDARD);
        let h: Vec<&str> = h.iter().map(String::as_str).collect();
        expect_err(&dir, &raw_ply(&h, &ONE), "is absurd");
        let h = header_with(1 << 28, &STANDARD);
        let h: Vec<&str> = h.iter().map(String::as_str).collect();
        expect_err(&dir, &raw_ply(&h, &ONE), "truncated");
        let mut h: Vec<String> = header_with(1, &STANDARD);
        h[2] = "element vertex 99999999999999999999999".into();
        let h: Vec<&str> = h.iter().map(String::as_str).collect();
        expect_err(&dir, &raw_ply(&h, &ONE), "is not a number");
    }

    #[test]
    fn bad_values_name_the_vertex() {
        let dir = TestDir::new("ply-values");
        let h = header_with(3, &STANDARD);
        let h: Vec<&str> = h.iter().map(String::as_str).collect();
        let cases: [(usize, f32, &str); 7] = [
            (0, f32::NAN, "position"),
            (2, f32::INFINITY, "position"),
            (3, 0.5, "normal"),
            (5, f32::NAN, "normal"),
            (6, -0.25, "area -0.25"),
            (8, -1.0, "irradiance"),
            (9, f32::INFINITY, "irradiance"),
        ];
        for (field, value, needle) in cases {
            let mut values: Vec<f32> = ONE.repeat(3);
            values[20 + field] = value;
            let err = read_bytes(&dir, &raw_ply(&h, &values)).unwrap_err();
            assert!(
                matches!(&err, OutputError::SampleValue { vertex: 2, .. }),
                "field {field}: {err:?}"
            );
            let msg = err.to_string();
            assert!(msg.contains("sample 2") && msg.contains(needle), "{msg}");
        }
    }

    #[test]
    fn writer_rejects_what_the_reader_would() {
        let dir = TestDir::new("ply-write-bad");
        let path = dir.path("w.ply");
        let mut set = samples(4);
        set.areas.pop();
        let err = write_ply(&path, &set, &[]).unwrap_err();
        assert!(err.to_string().contains("differ in length"), "{err}");
        let mut set = samples(4);
        set.irradiance[3].y = -0.1;
        let err = write_ply(&path, &set, &[]).unwrap_err();
        assert!(
            matches!(err, OutputError::SampleValue { vertex: 3, .. }),
            "{err:?}"
        );
        let err = write_ply(&path, &samples(2), &["two\nlines"]).unwrap_err();
        assert!(
            err.to_string().contains("one line of printable ASCII"),
            "{err}"
        );
        assert!(dir.entries().is_empty());
        assert!(samples(3).validate().is_ok());
    }

    #[test]
    fn random_bytes_never_panic() {
        let dir = TestDir::new("ply-random");
        let mut s = 0x2545F4914F6CDD1Du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let valid = {
            let h = header_with(2, &STANDARD);
            let h: Vec<&str> = h.iter().map(String::as_str).collect();
            raw_ply(&h, &ONE.repeat(2))
        };
        for round in 0..300 {
            let mut bytes = if round % 2 == 0 {
                (0..(next() % 400))
                    .map(|_| next() as u8)
                    .collect::<Vec<u8>>()
            } else {
                valid.clone()
            };
            if round % 2 == 1 {
                let i = (next() as usize) % bytes.len();
                bytes[i] = next() as u8;
            }
            let _ = read_bytes(&dir, &bytes);
        }
    }
}
