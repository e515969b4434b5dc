//! Tests of the sample-set reader and writer (round trips, every malformed case).

use super::*;
use crate::output::atomic::tests::TestDir;

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
