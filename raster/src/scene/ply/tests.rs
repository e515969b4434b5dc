//! Tests of the PLY mesh reader: the three encodings of one mesh agree, skipped elements and
//! properties, fan triangulation, normals and UVs, and every malformed case as an error.

use super::*;
use crate::output::ply::header::Property;
use crate::scene::mesh::smooth_normals;

/// Values of one entry: one `Vec` per property (a scalar has one value, a list its items).
type Entry = Vec<Vec<f64>>;

/// Encodes a PLY file: `header` as text, then each element's entries in its format.
fn encode(header: &Header, entries: &[Vec<Entry>]) -> Vec<u8> {
    let mut out = header.to_text().into_bytes();
    for (element, rows) in header.elements.iter().zip(entries) {
        for row in rows {
            let mut words = Vec::new();
            for (p, values) in element.properties.iter().zip(row) {
                match p.kind {
                    Kind::Scalar(t) => put(&mut out, &mut words, header.format, t, values[0]),
                    Kind::List { count, item } => {
                        put(
                            &mut out,
                            &mut words,
                            header.format,
                            count,
                            values.len() as f64,
                        );
                        for &v in values {
                            put(&mut out, &mut words, header.format, item, v);
                        }
                    }
                }
            }
            if header.format == Format::Ascii {
                out.extend_from_slice(words.join(" ").as_bytes());
                out.push(b'\n');
            }
        }
    }
    out
}

fn put(out: &mut Vec<u8>, words: &mut Vec<String>, format: Format, t: Scalar, v: f64) {
    let le: Vec<u8> = match t {
        Scalar::I8 => (v as i8).to_le_bytes().to_vec(),
        Scalar::U8 => (v as u8).to_le_bytes().to_vec(),
        Scalar::I16 => (v as i16).to_le_bytes().to_vec(),
        Scalar::U16 => (v as u16).to_le_bytes().to_vec(),
        Scalar::I32 => (v as i32).to_le_bytes().to_vec(),
        Scalar::U32 => (v as u32).to_le_bytes().to_vec(),
        Scalar::F32 => (v as f32).to_le_bytes().to_vec(),
        Scalar::F64 => v.to_le_bytes().to_vec(),
    };
    match format {
        Format::Ascii => words.push(format!("{v}")),
        Format::BinaryLittleEndian => out.extend(le),
        Format::BinaryBigEndian => out.extend(le.into_iter().rev()),
    }
}

fn scalar(name: &str, t: Scalar) -> Property {
    Property {
        name: name.into(),
        kind: Kind::Scalar(t),
        line: 0,
    }
}

fn list(name: &str, count: Scalar, item: Scalar) -> Property {
    Property {
        name: name.into(),
        kind: Kind::List { count, item },
        line: 0,
    }
}

fn element(name: &str, count: usize, properties: Vec<Property>) -> Element {
    Element {
        name: name.into(),
        count: count as u64,
        line: 0,
        properties,
    }
}

/// A unit cube's corners.
fn corners() -> Vec<[f64; 3]> {
    (0..8)
        .map(|i| [f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2)])
        .collect()
}

/// The cube's six quads, counter-clockwise seen from outside.
const QUADS: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

/// The cube as Stanford-style files write it, with things to skip: a leading `material`
/// element, a `double z` between an `uchar` colour and texture coordinates `s`, `t`, a face
/// `flags` scalar and a `texcoord` list before the `uint` index list, a trailing `edge` element.
fn cube(format: Format) -> Vec<u8> {
    let header = Header {
        format,
        format_line: 0,
        comments: vec![(0, "made by hand".into())],
        elements: vec![
            element(
                "material",
                1,
                vec![
                    scalar("shine", Scalar::F32),
                    list("rgb", Scalar::U8, Scalar::U8),
                ],
            ),
            element(
                "vertex",
                8,
                vec![
                    scalar("x", Scalar::F32),
                    scalar("y", Scalar::F32),
                    scalar("red", Scalar::U8),
                    scalar("z", Scalar::F64),
                    scalar("s", Scalar::F32),
                    scalar("t", Scalar::F32),
                ],
            ),
            element(
                "face",
                6,
                vec![
                    scalar("flags", Scalar::I16),
                    list("texcoord", Scalar::U8, Scalar::F32),
                    list("vertex_indices", Scalar::U8, Scalar::U32),
                ],
            ),
            element(
                "edge",
                2,
                vec![
                    scalar("vertex1", Scalar::I32),
                    scalar("vertex2", Scalar::I32),
                ],
            ),
        ],
        length: 0,
    };
    let vertices = corners()
        .iter()
        .map(|c| {
            vec![
                vec![c[0]],
                vec![c[1]],
                vec![200.0],
                vec![c[2]],
                vec![0.25 * c[0]],
                vec![0.5 * c[1] - 0.125],
            ]
        })
        .collect();
    let faces = QUADS
        .iter()
        .map(|q| {
            vec![
                vec![-7.0],
                vec![0.5, 1.5],
                q.iter().map(|&i| f64::from(i)).collect(),
            ]
        })
        .collect();
    let edges = vec![vec![vec![0.0], vec![1.0]], vec![vec![-1.0], vec![7.0]]];
    encode(
        &header,
        &[
            vec![vec![vec![0.5], vec![1.0, 2.0, 3.0]]],
            vertices,
            faces,
            edges,
        ],
    )
}

/// A mesh's floats as bits: positions, normals, UVs, then its triangles.
type MeshBits = (Vec<u32>, Vec<u32>, Option<Vec<u32>>, Vec<[u32; 3]>);

fn bits(m: &Mesh) -> MeshBits {
    let v3 = |v: &[Vec3]| {
        v.iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    (
        v3(&m.positions),
        v3(&m.normals),
        m.uvs.as_ref().map(|u| {
            u.iter()
                .flat_map(|t| t.to_array().map(f32::to_bits))
                .collect()
        }),
        m.triangles.clone(),
    )
}

#[test]
fn ascii_little_and_big_endian_give_the_same_mesh() {
    let ascii = parse_ply(&cube(Format::Ascii)).unwrap();
    let le = parse_ply(&cube(Format::BinaryLittleEndian)).unwrap();
    let be = parse_ply(&cube(Format::BinaryBigEndian)).unwrap();
    assert_eq!(bits(&ascii), bits(&le));
    assert_eq!(bits(&ascii), bits(&be));
    // And it is the cube: corners in order, quads fanned (0, k, k+1), UVs from s/t.
    let want: Vec<Vec3> = corners()
        .iter()
        .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
        .collect();
    assert_eq!(le.positions, want);
    let fans: Vec<[u32; 3]> = QUADS
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    assert_eq!(le.triangles, fans);
    let uvs = le.uvs.as_ref().unwrap();
    for (p, t) in le.positions.iter().zip(uvs) {
        assert_eq!(*t, Vec2::new(0.25 * p.x, 0.5 * p.y - 0.125));
    }
    // No normals in the file: the area-weighted ones, pointing out of the cube.
    assert_eq!(le.normals, smooth_normals(&le.positions, &le.triangles));
    for (p, n) in le.positions.iter().zip(&le.normals) {
        assert!(n.dot(*p - Vec3::splat(0.5)) > 0.5, "{p} {n}");
    }
}

/// A single triangle with normals `nx ny nz` (typed `t`) and `vertex_index` as the list name.
fn triangle_with_normals(format: Format, normal: [f64; 3]) -> Vec<u8> {
    let header = Header {
        format,
        format_line: 0,
        comments: vec![],
        elements: vec![
            element(
                "vertex",
                3,
                ["x", "y", "z", "nx", "ny", "nz"]
                    .iter()
                    .map(|n| scalar(n, Scalar::F32))
                    .collect(),
            ),
            element(
                "face",
                1,
                vec![list("vertex_index", Scalar::I32, Scalar::I16)],
            ),
        ],
        length: 0,
    };
    let vertex = |p: [f64; 3]| -> Entry { p.iter().chain(&normal).map(|&v| vec![v]).collect() };
    let vertices = vec![
        vertex([0.0, 0.0, 0.0]),
        vertex([1.0, 0.0, 0.0]),
        vertex([0.0, 1.0, 0.0]),
    ];
    encode(&header, &[vertices, vec![vec![vec![0.0, 1.0, 2.0]]]])
}

#[test]
fn file_normals_are_kept_normalised_and_unusable_ones_replaced() {
    for format in [Format::Ascii, Format::BinaryBigEndian] {
        let m = parse_ply(&triangle_with_normals(format, [0.0, 2.0, 0.0])).unwrap();
        assert_eq!(m.normals, vec![Vec3::Y; 3], "{format:?}");
        assert!(m.uvs.is_none());
        let m = parse_ply(&triangle_with_normals(format, [0.0, 0.0, 0.0])).unwrap();
        assert_eq!(m.normals, vec![Vec3::Z; 3], "{format:?}: computed");
    }
}

fn expect_err(bytes: &[u8], at: Option<PlyLocation>, needle: &str) {
    let err = parse_ply(bytes).expect_err(needle);
    assert!(err.message.contains(needle), "'{err}' lacks '{needle}'");
    assert_eq!(err.at, at, "{err}");
}

#[test]
fn every_truncation_is_an_error() {
    for format in [
        Format::Ascii,
        Format::BinaryLittleEndian,
        Format::BinaryBigEndian,
    ] {
        let full = cube(format);
        for len in 0..full.len() {
            // ASCII may lose its final newline (and only that) and still be whole.
            if format == Format::Ascii && len == full.len() - 1 {
                continue;
            }
            assert!(parse_ply(&full[..len]).is_err(), "{format:?} cut at {len}");
        }
        let mut more = full.clone();
        more.extend_from_slice(b"7");
        assert!(
            parse_ply(&more)
                .unwrap_err()
                .message
                .contains("after the last element")
        );
    }
}

const TRI_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
    property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n\
    end_header\n";

#[test]
fn malformed_bodies_name_their_place() {
    let tri = |body: &str| format!("{TRI_HEAD}{body}").into_bytes();
    assert!(parse_ply(&tri("0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).is_ok());
    let line = |n| Some(PlyLocation::Line(n));
    expect_err(&tri("0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), line(13), "vertex 3");
    expect_err(
        &tri("0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
        line(13),
        "vertex -1",
    );
    expect_err(&tri("0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), line(13), "2 vertices");
    expect_err(
        &tri("0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
        line(11),
        "'zero'",
    );
    expect_err(&tri("0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n"), line(13), "'300'");
    expect_err(&tri("0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n"), line(13), "'2.5'");
    expect_err(&tri("0 0 0\n1 0 0\n0 1 0\n3 0 1\n"), line(14), "truncated");
    expect_err(&tri("0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"), None, "area");
    expect_err(&tri("0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n"), None, "not finite");
    expect_err(
        &tri("0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n"),
        None,
        "not finite",
    );

    // Binary: byte offsets.
    let head = TRI_HEAD.replace("ascii", "binary_little_endian");
    let mut bin = head.clone().into_bytes();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    bin.push(3);
    for i in [0i32, 1, 9] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let end = bin.len() as u64;
    expect_err(&bin, Some(PlyLocation::Byte(end)), "vertex 9");
    let mut huge = bin[..end as usize - 13].to_vec();
    huge.extend_from_slice(&[255]);
    expect_err(
        &huge,
        Some(PlyLocation::Byte(head.len() as u64 + 37)),
        "does not fit",
    );
}

#[test]
fn malformed_headers_name_their_line() {
    let with = |from: &str, to: &str| {
        let text = TRI_HEAD.replace(from, to);
        format!("{text}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").into_bytes()
    };
    let line = |n| Some(PlyLocation::Line(n));
    expect_err(
        &with("vertex 3", "vertex 4000000"),
        line(3),
        "more than the",
    );
    expect_err(
        &with("face 1", "face 18446744073709551615"),
        line(7),
        "more than the",
    );
    expect_err(&with("property float x\n", ""), line(3), "no property 'x'");
    expect_err(
        &with("uchar int", "uchar float"),
        line(8),
        "list of integers",
    );
    expect_err(
        &with("vertex_indices", "corners"),
        line(7),
        "vertex_indices",
    );
    expect_err(
        &with("float y", "list uchar float y"),
        line(5),
        "not a list",
    );
    expect_err(&with("element face", "element facet"), None, "point cloud");
    expect_err(
        &with("element vertex", "element point"),
        None,
        "element vertex",
    );
    expect_err(&with("ascii", "utf8"), line(2), "malformed format");
    expect_err(b"\x89PNG\r\n", line(1), "not a PLY file");
    expect_err(b"", line(1), "not a PLY file");
    let swapped = "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n\
        element vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n\
        3 0 1 2\n0 0 0\n1 0 0\n0 1 0\n";
    expect_err(swapped.as_bytes(), line(3), "before element vertex");
}
