//! The baked irradiance sample set: a binary PLY point cloud.
//!
//! `lucent bake` writes the irradiance samples (position, normal, the surface area each one
//! represents — its cell of the restricted Voronoi diagram of its object's samples, so an
//! object's areas sum to its surface area — and the irradiance there) so that `lucent render` can load them instead of
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
use std::io::{BufRead, BufReader};
use std::path::Path;

use glam::Vec3;

use super::OutputError;
use super::atomic::write_atomically;
use header::Header;
use layout::{header_err, sample_header, sample_layout};

pub(crate) mod header;
mod layout;

/// The comment that marks (and versions) a lucent sample set.
pub const FORMAT_COMMENT: &str = "lucent sample-set v1";

/// The most samples the reader accepts (2²⁸ ≈ 268 million, 10.7 GB of samples): larger
/// counts are taken to be corruption.
pub const MAX_SAMPLES: u64 = 1 << 28;

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
    /// Surface area each sample represents (scene units²): its restricted Voronoi cell when
    /// placed by lucent; any non-negative weights when read from a file.
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

    let header = sample_header(samples.len(), comments).to_text();

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
    read_samples(BufReader::new(file), file_len, path)
}

/// [`read_ply_with_comments`] of a file held in memory (`path` names it in errors).
pub fn decode_ply_with_comments(
    bytes: &[u8],
    path: &Path,
) -> Result<(SampleSet, Vec<String>), OutputError> {
    read_samples(bytes, bytes.len() as u64, path)
}

/// Reads a sample set from `reader`, a file of `file_len` bytes that `path` names in errors.
fn read_samples(
    mut reader: impl BufRead,
    file_len: u64,
    path: &Path,
) -> Result<(SampleSet, Vec<String>), OutputError> {
    let header = Header::parse(&mut reader).map_err(|e| OutputError::from((path, e)))?;
    let length = header.length;
    let header = sample_layout(path, header)?;

    let expected = header
        .vertex_count
        .checked_mul(header.stride)
        .and_then(|body| body.checked_add(length))
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

#[cfg(test)]
mod tests;
