//! The PLY header (format, elements, property types), parsed and written in one place: the
//! sample-set files of this module and the PLY meshes of `crate::scene::ply` both go through it.
//!
//! ```text
//! ply                                   line 1, exactly
//! format <ascii|binary_little_endian|binary_big_endian> 1.0
//! comment <text>                        any number, anywhere; `obj_info <text>` is skipped
//! element <name> <count>                then its properties, in record order:
//! property <type> <name>                  a scalar
//! property list <count type> <item type> <name>   a count, then that many items
//! end_header                            the body starts after this line's `\n`
//! ```
//!
//! Types (with their sized aliases): `char`/`int8`, `uchar`/`uint8`, `short`/`int16`,
//! `ushort`/`uint16`, `int`/`int32`, `uint`/`uint32`, `float`/`float32`, `double`/`float64`.
//! Lines may end in `\r\n`. The parser rejects everything else with the 1-based line number:
//! unknown keywords or types, a non-integer list count type, a version other than 1.0, a second
//! element or property of the same name, and headers over [`MAX_HEADER_BYTES`].

use std::io::{BufRead, Read};

/// Longest header accepted.
pub(crate) const MAX_HEADER_BYTES: u64 = 64 * 1024;

/// How the body is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Format {
    /// Whitespace-separated decimal numbers.
    Ascii,
    /// Packed binary values, little-endian.
    BinaryLittleEndian,
    /// Packed binary values, big-endian.
    BinaryBigEndian,
}

impl Format {
    /// The keyword on the `format` line.
    pub(crate) fn keyword(self) -> &'static str {
        match self {
            Format::Ascii => "ascii",
            Format::BinaryLittleEndian => "binary_little_endian",
            Format::BinaryBigEndian => "binary_big_endian",
        }
    }
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    /// The type named `name` (classic or sized spelling).
    pub(crate) fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// The classic name, as written.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Bytes in a binary body.
    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Whether the type holds integers.
    pub(crate) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// What a property holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// One value.
    Scalar(Scalar),
    /// A count (of an integer type), then that many items.
    List {
        /// Type of the count.
        count: Scalar,
        /// Type of each item.
        item: Scalar,
    },
}

/// One `property` line.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Property {
    pub(crate) name: String,
    pub(crate) kind: Kind,
    /// 1-based header line (0 for a property built in memory).
    pub(crate) line: usize,
}

/// One `element` line and its properties.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Element {
    pub(crate) name: String,
    pub(crate) count: u64,
    /// 1-based header line (0 for an element built in memory).
    pub(crate) line: usize,
    pub(crate) properties: Vec<Property>,
}

impl Element {
    /// The property called `name`, with its index.
    pub(crate) fn property(&self, name: &str) -> Option<(usize, &Property)> {
        self.properties
            .iter()
            .enumerate()
            .find(|(_, p)| p.name == name)
    }
}

/// A whole header.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Header {
    pub(crate) format: Format,
    /// 1-based line of the `format` line.
    pub(crate) format_line: usize,
    /// `comment` lines: (1-based line, text after `comment ` verbatim).
    pub(crate) comments: Vec<(usize, String)>,
    pub(crate) elements: Vec<Element>,
    /// Bytes up to and including the `end_header` line (where the body starts).
    pub(crate) length: u64,
}

/// A header problem: 1-based line (0 when it is not on one line) and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct HeaderError {
    pub(crate) line: usize,
    pub(crate) message: String,
}

fn err(line: usize, message: impl Into<String>) -> HeaderError {
    HeaderError {
        line,
        message: message.into(),
    }
}

const NOT_PLY: &str = "not a PLY file (it does not start with a 'ply' line)";

impl Header {
    /// The element called `name`.
    pub(crate) fn element(&self, name: &str) -> Option<&Element> {
        self.elements.iter().find(|e| e.name == name)
    }

    /// The header text, `ply` to `end_header\n` (`length` and line numbers are ignored).
    pub(crate) fn to_text(&self) -> String {
        let mut text = format!("ply\nformat {} 1.0\n", self.format.keyword());
        for (_, c) in &self.comments {
            text.push_str(&format!("comment {c}\n"));
        }
        for e in &self.elements {
            text.push_str(&format!("element {} {}\n", e.name, e.count));
            for p in &e.properties {
                match p.kind {
                    Kind::Scalar(t) => {
                        text.push_str(&format!("property {} {}\n", t.name(), p.name))
                    }
                    Kind::List { count, item } => text.push_str(&format!(
                        "property list {} {} {}\n",
                        count.name(),
                        item.name(),
                        p.name
                    )),
                }
            }
        }
        text.push_str("end_header\n");
        text
    }

    /// Reads a header, leaving `reader` at the first byte of the body.
    pub(crate) fn parse(reader: &mut impl BufRead) -> Result<Header, HeaderError> {
        let mut length = 0u64;
        let mut line_no = 0usize;
        let mut raw = Vec::new();
        let mut format = None;
        let mut comments = Vec::new();
        let mut elements: Vec<Element> = Vec::new();
        loop {
            raw.clear();
            let n = reader
                .by_ref()
                .take(MAX_HEADER_BYTES - length)
                .read_until(b'\n', &mut raw)
                .map_err(|e| err(line_no + 1, format!("reading the header failed: {e}")))?;
            length += n as u64;
            line_no += 1;
            if raw.last() != Some(&b'\n') {
                return Err(err(
                    line_no,
                    if length >= MAX_HEADER_BYTES {
                        format!("no end_header within the first {MAX_HEADER_BYTES} bytes")
                    } else if line_no == 1 {
                        NOT_PLY.to_string()
                    } else {
                        "the file ends before end_header".to_string()
                    },
                ));
            }
            raw.pop();
            if raw.last() == Some(&b'\r') {
                raw.pop();
            }
            let Ok(text) = std::str::from_utf8(&raw) else {
                let message = if line_no == 1 {
                    NOT_PLY
                } else {
                    "header line is not text"
                };
                return Err(err(line_no, message));
            };
            if line_no == 1 {
                if text != "ply" {
                    return Err(err(1, NOT_PLY));
                }
                continue;
            }
            let mut tokens = text.split_ascii_whitespace();
            let keyword = tokens.next().unwrap_or("");
            let args: Vec<&str> = tokens.collect();
            match keyword {
                "format" => {
                    if format.is_some() {
                        return Err(err(line_no, "second format line"));
                    }
                    let [name, version] = args.as_slice() else {
                        return Err(err(line_no, format!("malformed format line '{text}'")));
                    };
                    let f = match *name {
                        "ascii" => Format::Ascii,
                        "binary_little_endian" => Format::BinaryLittleEndian,
                        "binary_big_endian" => Format::BinaryBigEndian,
                        _ => return Err(err(line_no, format!("malformed format line '{text}'"))),
                    };
                    if *version != "1.0" {
                        return Err(err(
                            line_no,
                            format!("PLY version {version} is not supported (only 1.0)"),
                        ));
                    }
                    format = Some((f, line_no));
                }
                "comment" => {
                    // Everything after "comment " is the comment, kept verbatim.
                    let rest = text.trim_start().strip_prefix("comment").unwrap_or("");
                    let body = rest.strip_prefix(' ').unwrap_or(rest);
                    comments.push((line_no, body.to_string()));
                }
                "obj_info" => {}
                "element" => {
                    if format.is_none() {
                        return Err(err(line_no, "element before the format line"));
                    }
                    let [name, count] = args.as_slice() else {
                        return Err(err(line_no, format!("malformed element line '{text}'")));
                    };
                    let count: u64 = count.parse().map_err(|_| {
                        err(line_no, format!("element count '{count}' is not a number"))
                    })?;
                    if elements.iter().any(|e| e.name == *name) {
                        return Err(err(line_no, format!("second element '{name}'")));
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
                        return Err(err(line_no, "property before any element"));
                    };
                    let (name, kind) = match args.as_slice() {
                        ["list", count, item, name] => {
                            let (Some(count), Some(item)) =
                                (Scalar::parse(count), Scalar::parse(item))
                            else {
                                return Err(err(
                                    line_no,
                                    format!("unknown type in list property '{name}'"),
                                ));
                            };
                            if !count.is_integer() {
                                return Err(err(
                                    line_no,
                                    format!(
                                        "the count of list property '{name}' must be an integer \
                                         type, found {}",
                                        count.name()
                                    ),
                                ));
                            }
                            (name, Kind::List { count, item })
                        }
                        [ty, name] => {
                            let t = Scalar::parse(ty).ok_or_else(|| {
                                err(line_no, format!("unknown type '{ty}' of property '{name}'"))
                            })?;
                            (name, Kind::Scalar(t))
                        }
                        _ => return Err(err(line_no, format!("malformed property line '{text}'"))),
                    };
                    if element.property(name).is_some() {
                        return Err(err(line_no, format!("property '{name}' given twice")));
                    }
                    element.properties.push(Property {
                        name: name.to_string(),
                        kind,
                        line: line_no,
                    });
                }
                "end_header" => {
                    if !args.is_empty() {
                        return Err(err(line_no, "text after end_header"));
                    }
                    break;
                }
                other => return Err(err(line_no, format!("unknown header keyword '{other}'"))),
            }
        }
        let Some((format, format_line)) = format else {
            return Err(err(0, "no format line"));
        };
        Ok(Header {
            format,
            format_line,
            comments,
            elements,
            length,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_round_trips_through_the_parser() {
        let header = Header {
            format: Format::BinaryBigEndian,
            format_line: 2,
            comments: vec![(3, " two  spaces".to_string())],
            elements: vec![
                Element {
                    name: "vertex".into(),
                    count: 3,
                    line: 4,
                    properties: vec![
                        Property {
                            name: "x".into(),
                            kind: Kind::Scalar(Scalar::F64),
                            line: 5,
                        },
                        Property {
                            name: "red".into(),
                            kind: Kind::Scalar(Scalar::U8),
                            line: 6,
                        },
                    ],
                },
                Element {
                    name: "face".into(),
                    count: 1,
                    line: 7,
                    properties: vec![Property {
                        name: "vertex_indices".into(),
                        kind: Kind::List {
                            count: Scalar::U8,
                            item: Scalar::I32,
                        },
                        line: 8,
                    }],
                },
            ],
            length: 0,
        };
        let text = header.to_text();
        let mut bytes = text.as_bytes();
        let back = Header::parse(&mut bytes).unwrap();
        assert!(bytes.is_empty());
        assert_eq!(back.length, text.len() as u64);
        assert_eq!(Header { length: 0, ..back }, header);
    }

    #[test]
    fn sized_type_names_and_errors_carry_lines() {
        let text = "ply\nformat ascii 1.0\nelement v 1\nproperty float32 a\n\
                    property list uint8 int32 b\nend_header\n";
        let h = Header::parse(&mut text.as_bytes()).unwrap();
        assert_eq!(h.elements[0].properties[0].kind, Kind::Scalar(Scalar::F32));
        assert_eq!(
            h.elements[0].properties[1].kind,
            Kind::List {
                count: Scalar::U8,
                item: Scalar::I32
            }
        );
        for (text, line, needle) in [
            (
                "ply\nformat ascii 1.0\nelement v 1\nproperty list float int a\n",
                4,
                "integer",
            ),
            ("ply\nformat ascii 1.1\n", 2, "version 1.1"),
            ("ply\nformat utf8 1.0\n", 2, "malformed format"),
            (
                "ply\nformat ascii 1.0\nelement v 1\nelement v 2\n",
                4,
                "second element",
            ),
            (
                "ply\nformat ascii 1.0\nproperty int a\n",
                3,
                "before any element",
            ),
            ("ply\ncomment x\nend_header\n", 0, "no format"),
            (
                "ply\nformat ascii 1.0\nend_header x\n",
                3,
                "after end_header",
            ),
        ] {
            let e = Header::parse(&mut text.as_bytes()).unwrap_err();
            assert_eq!(e.line, line, "{text:?}: {e:?}");
            assert!(e.message.contains(needle), "{text:?}: {e:?}");
        }
        let e = Header::parse(&mut &b"ply\nformat ascii 1.0\n\xff\n"[..]).unwrap_err();
        assert_eq!((e.line, e.message.as_str()), (3, "header line is not text"));
    }
}
