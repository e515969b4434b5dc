//! What a sample set needs from a PLY header (parsed by [`super::header`]): the checks the
//! parent module doc lists, and where each required property sits in a vertex record.

use std::path::Path;

use super::header::{Element, Format, Header, HeaderError, Kind, Property, Scalar};
use super::{FORMAT_COMMENT, MAX_SAMPLES, PROPERTIES};
use crate::output::OutputError;

/// Where the samples are in the body.
pub(super) struct Layout {
    /// The `element vertex` count.
    pub(super) vertex_count: u64,
    /// Bytes per vertex.
    pub(super) stride: u64,
    /// Byte offset within a vertex of each of [`PROPERTIES`].
    pub(super) offsets: [usize; PROPERTIES.len()],
    /// Header comments other than [`FORMAT_COMMENT`], verbatim.
    pub(super) comments: Vec<String>,
}

pub(super) fn header_err(path: &Path, line: usize, message: impl Into<String>) -> OutputError {
    OutputError::PlyHeader {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

impl From<(&Path, HeaderError)> for OutputError {
    fn from((path, e): (&Path, HeaderError)) -> Self {
        header_err(path, e.line, e.message)
    }
}

/// The header the writer emits for `count` samples and these provenance comments.
pub(super) fn sample_header(count: usize, comments: &[&str]) -> Header {
    let mut all = vec![(0, FORMAT_COMMENT.to_string())];
    all.extend(comments.iter().map(|c| (0, c.to_string())));
    Header {
        format: Format::BinaryLittleEndian,
        format_line: 0,
        comments: all,
        elements: vec![Element {
            name: "vertex".to_string(),
            count: count as u64,
            line: 0,
            properties: PROPERTIES
                .iter()
                .map(|p| Property {
                    name: p.to_string(),
                    kind: Kind::Scalar(Scalar::F32),
                    line: 0,
                })
                .collect(),
        }],
        length: 0,
    }
}

/// Checks a parsed header against the sample-set format and locates the properties.
pub(super) fn sample_layout(path: &Path, header: Header) -> Result<Layout, OutputError> {
    match header.format {
        Format::BinaryLittleEndian => {}
        Format::Ascii => {
            return Err(header_err(
                path,
                header.format_line,
                "ASCII PLY is not supported: sample sets are binary_little_endian",
            ));
        }
        Format::BinaryBigEndian => {
            return Err(header_err(
                path,
                header.format_line,
                "big-endian PLY is not supported: sample sets are binary_little_endian",
            ));
        }
    }
    let mut comments = Vec::new();
    for (line, body) in header.comments {
        if body.trim() == FORMAT_COMMENT {
            continue;
        }
        if let Some(version) = body.trim().strip_prefix("lucent sample-set ") {
            return Err(header_err(
                path,
                line,
                format!(
                    "sample-set format version '{version}' is not supported (this lucent reads \
                     v1)"
                ),
            ));
        }
        comments.push(body);
    }
    let mut vertex = None;
    for e in &header.elements {
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
    for p in &vertex.properties {
        let Kind::Scalar(ty) = p.kind else {
            return Err(header_err(
                path,
                p.line,
                format!(
                    "list property '{}' in element vertex is not supported",
                    p.name
                ),
            ));
        };
        if let Some(k) = PROPERTIES.iter().position(|&q| q == p.name) {
            if ty != Scalar::F32 {
                return Err(header_err(
                    path,
                    p.line,
                    format!("property '{}' must be float, found {}", p.name, ty.name()),
                ));
            }
            offsets[k] = Some(stride as usize);
        }
        stride += ty.size() as u64;
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
    Ok(Layout {
        vertex_count: vertex.count,
        stride,
        offsets: resolved,
        comments,
    })
}
