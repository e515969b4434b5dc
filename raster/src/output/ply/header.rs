//! The PLY header parser: checks everything the parent module doc lists about the header and
//! works out where each required property sits in a vertex record.

use std::io::{BufRead, Read};
use std::path::Path;

use super::{FORMAT_COMMENT, MAX_HEADER_BYTES, MAX_SAMPLES, PROPERTIES};
use crate::output::OutputError;

/// What the header says about the body.
pub(super) struct Header {
    /// Bytes up to and including the `end_header` line.
    pub(super) length: u64,
    /// The `element vertex` count.
    pub(super) vertex_count: u64,
    /// Bytes per vertex.
    pub(super) stride: u64,
    /// Byte offset within a vertex of each of [`PROPERTIES`].
    pub(super) offsets: [usize; PROPERTIES.len()],
    /// Header comments other than [`FORMAT_COMMENT`], verbatim.
    pub(super) comments: Vec<String>,
}

/// One `element` line and its properties.
struct Element {
    name: String,
    count: u64,
    line: usize,
    /// (name, type name, size in bytes; `None` for list properties, line).
    properties: Vec<(String, String, Option<u64>, usize)>,
}

pub(super) fn header_err(path: &Path, line: usize, message: impl Into<String>) -> OutputError {
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

pub(super) fn parse_header(path: &Path, reader: &mut impl BufRead) -> Result<Header, OutputError> {
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
