//! The reader against `tobj`, its oracle, on random files.

use super::*;
use crate::raster::testutil::Rng;

/// The `mtllib` name under which the oracle hands every `usemtl` name to `tobj`, which
/// otherwise reports no material for names no loaded library defines.
const NAMES_LIBRARY: &str = "\u{1}usemtl-names";

/// The reader's output as `tobj` gives it, after the two-pass index check lucent ran
/// before `tobj`.
fn oracle(text: &str) -> Result<Vec<(Option<String>, tobj::Mesh)>, ()> {
    let mut names: Vec<String> = Vec::new();
    let mut fed = format!("mtllib {NAMES_LIBRARY}\n");
    for line in text.lines() {
        let line = line.trim_start();
        fed.push_str(line);
        fed.push('\n');
        if line.split_whitespace().next() == Some("usemtl") {
            let name = line.split_once(' ').unwrap_or_default().1.trim();
            if !name.is_empty() && !names.iter().any(|n| n == name) {
                names.push(name.to_string());
            }
        }
    }
    super::super::obj::check_indices(text).map_err(|_| ())?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, materials) = tobj::load_obj_buf(&mut fed.as_bytes(), &options, |path| {
        if path == std::path::Path::new(NAMES_LIBRARY) {
            let library = names
                .iter()
                .map(|name| tobj::Material {
                    name: name.clone(),
                    ..Default::default()
                })
                .collect();
            let index = names.iter().enumerate().map(|(i, n)| (n.clone(), i));
            Ok((library, index.collect()))
        } else {
            Ok((Vec::new(), Default::default()))
        }
    })
    .map_err(|_| ())?;
    let materials = materials.unwrap_or_default();
    Ok(models
        .into_iter()
        .map(|m| {
            let name = m.mesh.material_id.map(|id| materials[id].name.clone());
            (name, m.mesh)
        })
        .collect())
}

/// A number as files write them: integers, decimals, exponents, signs, now and then
/// something that is not a number.
fn number(rng: &mut Rng, noisy: bool) -> String {
    match rng.range_i64(0, 12) {
        0 => "-0.5".into(),
        1 => format!("{}e-3", rng.range_i64(-9, 10)),
        2 if noisy && rng.range_i64(0, 20) == 0 => "x".into(),
        3 => format!("{:.7}", rng.f32_in(-2.0, 2.0)),
        _ => rng.range_i64(-3, 4).to_string(),
    }
}

/// An index for a slot with `count` entries so far: mostly valid (positive or negative),
/// sometimes 0, out of range or not a number.
fn index(rng: &mut Rng, count: usize, noisy: bool) -> String {
    let count = count as i64;
    match rng.range_i64(if noisy { 0 } else { 3 }, 40) {
        0 => "0".into(),
        // Beyond the count so far, and beyond any later one (a later vertex would make a
        // forward reference, which only the reader accepts).
        1 if rng.range_i64(0, 2) == 0 => (-count - 1).to_string(),
        1 => "99999".into(),
        2 => "q".into(),
        _ if count == 0 => "1".into(),
        k if k % 2 == 0 => rng.range_i64(1, count + 1).to_string(),
        _ => (-rng.range_i64(1, count + 1)).to_string(),
    }
}

/// A random OBJ file within what `tobj` and the reader agree on: positive indices only
/// name vertices already defined, and `vt`/`vn` appear before the first face or never.
fn random_file(rng: &mut Rng) -> String {
    let mut out = String::new();
    // Half the files have a chance of errors; the others are well formed.
    let noisy = rng.range_i64(0, 2) == 0;
    let colours = rng.range_i64(0, 4) == 0;
    let mut counts = [0usize; 3];
    let vertex = |out: &mut String, rng: &mut Rng, counts: &mut [usize; 3]| {
        let [x, y, z] = [number(rng, noisy), number(rng, noisy), number(rng, noisy)];
        let extra = match rng.range_i64(0, 12) {
            _ if colours => " 0.5 0.25 1".to_string(),
            0 if noisy => format!(" {}", number(rng, noisy)),
            0 => " 2".to_string(),
            1 if noisy => " 1 2".to_string(),
            _ => String::new(),
        };
        let short = noisy && rng.range_i64(0, 60) == 0;
        if short {
            out.push_str(&format!("v {x} {y}\n"));
        } else {
            out.push_str(&format!("v {x} {y} {z}{extra}\n"));
        }
        counts[0] += 1;
    };
    for _ in 0..rng.range_i64(1, 7) {
        vertex(&mut out, rng, &mut counts);
    }
    let with = [rng.range_i64(0, 2) == 0, rng.range_i64(0, 2) == 0];
    for (slot, keyword, n) in [(1, "vt", 2), (2, "vn", 3)] {
        if with[slot - 1] {
            for _ in 0..rng.range_i64(1, 5) {
                let words: Vec<String> = (0..n).map(|_| number(rng, noisy)).collect();
                out.push_str(&format!("{keyword} {}\n", words.join(" ")));
                counts[slot] += 1;
            }
        }
    }
    let materials = ["a", "b c", "a", ""];
    for _ in 0..rng.range_i64(0, 30) {
        match rng.range_i64(0, 20) {
            0 => vertex(&mut out, rng, &mut counts),
            1 if with[0] => {
                out.push_str(&format!(
                    "vt {} {} 0\n",
                    number(rng, noisy),
                    number(rng, noisy)
                ));
                counts[1] += 1;
            }
            2 if with[1] => {
                let words = [number(rng, noisy), number(rng, noisy), number(rng, noisy)];
                out.push_str(&format!("vn {}\n", words.join(" ")));
                counts[2] += 1;
            }
            3 => out.push_str(["o thing\n", "g\n", "g part two\n"][rng.range_i64(0, 3) as usize]),
            4 => {
                let name = materials[rng.range_i64(0, if noisy { 4 } else { 3 }) as usize];
                let indent = ["", "  ", "\t"][rng.range_i64(0, 3) as usize];
                out.push_str(&format!("{indent}usemtl {name}\n"));
            }
            5 => out.push_str(
                [
                    "mtllib x.mtl\n",
                    "# f 1 2 3\n",
                    "\n",
                    "s off\n",
                    "#f 1 2 3\n",
                    "  #v 1 2 3\n",
                    "\t#usemtl a\n",
                    "#\n",
                ][rng.range_i64(0, 8) as usize],
            ),
            _ => {
                let keyword = if rng.range_i64(0, 8) == 0 { "l" } else { "f" };
                let corners = match rng.range_i64(0, 10) {
                    0 => rng.range_i64(if noisy { 0 } else { 1 }, 3),
                    1 => rng.range_i64(5, 9),
                    2 | 3 => 4,
                    _ => 3,
                };
                // One form per face, as exporters write them, now and then mixed.
                let mut form = rng.range_i64(0, 4);
                out.push_str(keyword);
                for _ in 0..corners {
                    if rng.range_i64(0, 25) == 0 {
                        form = rng.range_i64(0, if noisy { 6 } else { 4 });
                    }
                    let v = index(rng, counts[0], noisy);
                    // Well-formed files only name the kinds they define.
                    let form = match form {
                        1 | 3 if !noisy && !with[0] => 0,
                        2 | 3 if !noisy && !with[1] => 0,
                        f => f,
                    };
                    let corner = match form {
                        0 => v,
                        1 => format!("{v}/{}", index(rng, counts[1], noisy)),
                        2 => format!("{v}//{}", index(rng, counts[2], noisy)),
                        3 => format!(
                            "{v}/{}/{}",
                            index(rng, counts[1], noisy),
                            index(rng, counts[2], noisy)
                        ),
                        4 => format!("/{}", index(rng, counts[1], noisy)),
                        _ => format!("{v}/1/1/1"),
                    };
                    out.push(' ');
                    out.push_str(&corner);
                }
                out.push('\n');
            }
        }
    }
    // Other whitespace: Windows line ends, tabs and runs of spaces.
    match rng.range_i64(0, 8) {
        0 => out.replace('\n', "\r\n"),
        1 => out.replace(' ', " \t "),
        _ => out,
    }
}

fn flat3(v: &[Vec3]) -> Vec<u32> {
    v.iter()
        .flat_map(|p| p.to_array())
        .map(f32::to_bits)
        .collect()
}

#[test]
fn statements_read_as_tobj_reads_them() {
    let mut rng = Rng::new(0x0b1_2eade2);
    let (mut loaded, mut refused) = (0, 0);
    for case in 0..6000 {
        let text = random_file(&mut rng);
        let ours = read_statements(&text);
        // Read again in chunks of a few bytes (about a line each): the same statements, or
        // the same error.
        let chunk = rng.range_i64(1, 40) as usize;
        match (&ours, read_in_chunks(&text, chunk)) {
            (Ok(whole), Ok(chunked)) => {
                assert_eq!(
                    whole.groups, chunked.groups,
                    "case {case}, chunks of {chunk}\n{text}"
                );
                assert_eq!(whole.usemtl_names, chunked.usemtl_names, "case {case}");
                assert_eq!(whole.mtllibs, chunked.mtllibs, "case {case}");
            }
            (Err(whole), Err(chunked)) => {
                assert_eq!(*whole, chunked, "case {case}, chunks of {chunk}\n{text}")
            }
            (whole, chunked) => {
                panic!("case {case}, chunks of {chunk}: {whole:?} but {chunked:?}\n{text}")
            }
        }
        let theirs = oracle(&text);
        let (ours, theirs) = match (ours, theirs) {
            (Ok(ours), Ok(theirs)) => (ours, theirs),
            (Err(_), Err(())) => {
                refused += 1;
                continue;
            }
            (ours, theirs) => {
                panic!("case {case}: reader {ours:?}, tobj {theirs:?}\n{text}")
            }
        };
        loaded += 1;
        assert_eq!(ours.groups.len(), theirs.len(), "case {case}\n{text}");
        for (group, (name, mesh)) in ours.groups.iter().zip(&theirs) {
            let ours_name = group.usemtl.map(|i| ours.usemtl_names[i as usize].clone());
            assert_eq!(ours_name, *name, "case {case}\n{text}");
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                flat3(&group.positions),
                bits(&mesh.positions),
                "case {case}\n{text}"
            );
            assert_eq!(
                flat3(&group.normals),
                bits(&mesh.normals),
                "case {case}\n{text}"
            );
            let uvs: Vec<u32> = group
                .uvs
                .iter()
                .flat_map(|t| t.to_array())
                .map(f32::to_bits)
                .collect();
            assert_eq!(uvs, bits(&mesh.texcoords), "case {case}\n{text}");
            let indices: Vec<u32> = group.triangles.iter().flatten().copied().collect();
            assert_eq!(indices, mesh.indices, "case {case}\n{text}");
        }
    }
    // Both outcomes are exercised in earnest.
    assert!(
        loaded > 1500 && refused > 1500,
        "{loaded} loaded, {refused} refused"
    );
}

#[test]
fn where_tobj_fails_a_meaningful_file_still_reads() {
    // A face before its vertices, in a group that ends before they are defined.
    let text = "f 1 2 3\ng next\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert!(oracle(text).is_err());
    let read = read_statements(text).expect("reads");
    assert_eq!(read.groups.len(), 2);
    assert_eq!(read.groups[0].positions, read.groups[1].positions);
    // Colours on only some vertices are ignored.
    let text = "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    assert!(oracle(text).is_err());
    assert_eq!(
        read_statements(text).expect("reads").groups[0].triangles,
        vec![[0, 1, 2]]
    );
}

#[test]
fn malformed_statements_name_their_line_and_kind() {
    for (text, line, kind) in [
        ("v 0 0\n", 1, tobj::LoadError::PositionParseError),
        (
            "v 0 0 0\nv 1 0 0 0\n",
            2,
            tobj::LoadError::ScalingByZeroError,
        ),
        ("v 0 0 0 1 1\n", 1, tobj::LoadError::ColorParseError),
        ("\nvt 0\n", 2, tobj::LoadError::TexcoordParseError),
        ("vn 0 0 z\n", 1, tobj::LoadError::NormalParseError),
        (
            "v 0 0 0\nf 1/1/1/1 1 1\n",
            2,
            tobj::LoadError::FaceParseError,
        ),
        ("v 0 0 0\n\nf\n", 3, tobj::LoadError::InvalidPolygon),
        ("usemtl\n", 1, tobj::LoadError::MaterialParseError),
        (
            "vt 0 0\nf /1 /1 /1\n",
            2,
            tobj::LoadError::FaceVertexOutOfBounds,
        ),
    ] {
        let e = read_statements(text).expect_err(text);
        assert_eq!(
            (e.line, e.source),
            (Some(line), Some(kind)),
            "{text:?}: {e}"
        );
    }
    // Index errors come from the two-pass check, with its message and line.
    // Points and lines are skipped, but their indices are checked all the same, whether the
    // index reaches into an earlier chunk or before the file.
    for chunk in [1, 4, 12, 1000] {
        let e = read_in_chunks("v 0 0 0\nv 1 0 0\nl -3 1\n", chunk).unwrap_err();
        assert_eq!(e.line, Some(3), "chunks of {chunk}: {e}");
        let e = read_in_chunks("v 0 0 0\nv 1 0 0\nf 1 2 1\nf 2\nl 1 4\n", chunk).unwrap_err();
        assert_eq!(e.line, Some(5), "chunks of {chunk}: {e}");
    }
    let e = read_statements("v 0 0 0\nf 1 1 2\n").unwrap_err();
    assert_eq!(e.line, Some(2));
    assert!(e.message.contains("index 2 out of range"), "{e}");
}

/// An index the file defines but the reader cannot hold is reported as the reader's limit,
/// not as a corner naming no vertex (the reader's bound lowered to 2 to make such a file).
#[test]
fn a_file_beyond_the_readers_counts_names_the_limit() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let beyond = index_error_beyond(text, 2);
    assert_eq!(beyond.line, None);
    assert_eq!(
        beyond.message,
        "more than 2 vertices, texture coordinates or normals: beyond what the reader holds"
    );
    assert_eq!(
        index_error_beyond(text, 3).message,
        "a face corner names no vertex"
    );
    // A real index error keeps its line, whatever the bound.
    let bad = index_error_beyond("v 0 0 0\nf 1 2 3\n", 0);
    assert_eq!(bad.line, Some(2));
    // Comments are skipped whole, however long: a first word starting with `#` is never a
    // statement, so a comment that looks like one changes nothing.
    let commented = read_statements("v 0 0 0\n#v 1 1 1\n# f 1 1 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        .expect("valid");
    assert_eq!(commented.groups[0].positions.len(), 3);
    assert_eq!(commented.groups[0].triangles, vec![[0, 1, 2]]);
}
