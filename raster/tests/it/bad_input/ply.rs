//! Baked sample sets (`lucent render --samples-from FILE.ply`): missing, truncated,
//! malformed headers, bad values, and sets baked for another scene.

use super::harness::{Sandbox, render};

/// A sandbox with `samples.ply` baked from its own scene (500 samples). Returns the bytes
/// and the length of the header.
fn baked(tag: &str) -> (Sandbox, Vec<u8>, usize) {
    let sb = Sandbox::new(tag);
    sb.succeeds(&[
        "bake",
        "scene.toml",
        "-q",
        "-o",
        "samples.ply",
        "--samples",
        "500",
    ]);
    let ply = sb.read("samples.ply");
    let header = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    assert_eq!((ply.len() - header) % 40, 0, "ten f32 per sample");
    (sb, ply, header)
}

fn from_samples() -> Vec<&'static str> {
    render(&["--samples-from", "samples.ply"])
}

/// The baked set renders (the harness's baseline for this module).
#[test]
fn baked_samples_render() {
    let (sb, _, _) = baked("ply-valid");
    sb.succeeds(&from_samples());
    assert!(sb.read("out.png").starts_with(b"\x89PNG"));
}

/// A render from a bake whose objects or lights have changed since warns, once, naming the
/// file, and still renders; one whose camera, material coefficients or shading settings
/// changed does not, since the samples do not depend on them.
#[test]
fn samples_baked_for_other_lights_or_meshes_warn() {
    let (sb, _, _) = baked("ply-stale");
    let original = String::from_utf8(sb.read("scene.toml")).expect("utf-8");
    let stderr_with = |text: &str| {
        sb.write("scene.toml", text.as_bytes());
        let out = sb.succeeds(&from_samples());
        String::from_utf8(out.stderr).expect("utf-8")
    };
    let unchanged = [
        original.clone(),
        original.replace("fov = 35.0", "fov = 30.0"),
        original.replace("eta = 1.3", "eta = 1.4"),
        original.replace("width = 32", "width = 24"),
    ];
    for text in &unchanged {
        let stderr = stderr_with(text);
        assert!(!stderr.contains("warning"), "{stderr}");
    }
    let stale = [
        original.replace("position = [0.0, -3.0, 5.0]", "position = [0.0, -3.0, 4.0]"),
        original.replace("segments = 24", "segments = 25"),
        original.replace("translate = [0.0, 0.0, 0.5]", "translate = [0.0, 0.0, 0.6]"),
        original
            .replace(
                "albedo = [0.2, 0.2, 0.2]",
                "kd = [0.2, 0.2, 0.2]\nmean_free_path = 0.1\neta = 1.3",
            )
            .replace("type = \"lambert\"", "type = \"translucent\""),
    ];
    // The scene's method, edge-aware, lights samples at their positions, as hierarchical
    // does; edge-refined as means over their cells.
    sb.write("scene.toml", original.as_bytes());
    for (method, warns) in [
        ("edge-refined", true),
        ("hierarchical", false),
        ("edge-aware", false),
    ] {
        let mut args = from_samples();
        args.extend(["--method", method]);
        let stderr = String::from_utf8(sb.succeeds(&args).stderr).expect("utf-8");
        let expected = "warning: samples.ply: baked for edge-aware, whose samples are lit at \
                        their positions; edge-refined lights its own as means over their cells \
                        (bake with --method edge-refined)";
        assert_eq!(stderr.contains(expected), warns, "{method}: {stderr}");
        assert_eq!(
            stderr.matches("warning").count(),
            usize::from(warns),
            "{stderr}"
        );
    }
    for text in &stale {
        assert_ne!(text, &original, "the edit applies");
        let stderr = stderr_with(text);
        assert!(
            stderr.starts_with(
                "warning: samples.ply: baked for other objects or lights than this scene has"
            ) && stderr.matches("warning").count() == 1,
            "{stderr}"
        );
    }
}

#[test]
fn missing_samples_file() {
    let sb = Sandbox::new("ply-missing");
    sb.fails(
        &render(&["--samples-from", "nosuch.ply"]),
        1,
        &["baked samples: nosuch.ply", "No such file"],
    );
    std::fs::create_dir(sb.path("dir.ply")).unwrap();
    sb.fails(
        &render(&["--samples-from", "dir.ply"]),
        1,
        &["baked samples: dir.ply"],
    );
}

/// The file cut at every 3rd byte of the header and at every 997th of the body: errors naming
/// the file, and for body cuts the size it should have.
#[test]
fn truncated_ply() {
    let (sb, ply, header) = baked("ply-truncated");
    let cuts = (0..header)
        .step_by(3)
        .chain((header..ply.len()).step_by(997))
        .chain([ply.len() - 1]);
    for cut in cuts {
        sb.write("samples.ply", &ply[..cut]);
        let needle = if cut >= header {
            "(truncated)"
        } else {
            "samples.ply"
        };
        sb.fails(&from_samples(), 1, &["baked samples: samples.ply", needle]);
    }
}

/// Malformed headers: each error names the file, the header line where there is one, and
/// the problem.
#[test]
fn malformed_ply_header() {
    let (sb, ply, header) = baked("ply-header");
    let text = String::from_utf8(ply[..header].to_vec()).unwrap();
    let body = &ply[header..];
    let count = (body.len() / 40).to_string();
    let vertex_line = format!("element vertex {count}\n");
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        (
            "not a PLY",
            text.replacen("ply\n", "obj\n", 1),
            vec!["line 1", "not a PLY file"],
        ),
        (
            "ASCII body",
            text.replace("binary_little_endian", "ascii"),
            vec!["line 2", "ASCII PLY is not supported"],
        ),
        (
            "big-endian body",
            text.replace("binary_little_endian", "binary_big_endian"),
            vec!["line 2", "big"],
        ),
        (
            "PLY 2.0",
            text.replace("binary_little_endian 1.0", "binary_little_endian 2.0"),
            vec!["line 2", "version 2.0"],
        ),
        (
            "future sample-set version",
            text.replace("sample-set v1", "sample-set v2"),
            vec!["v2"],
        ),
        (
            "absurd vertex count",
            text.replace(&vertex_line, "element vertex 4000000000\n"),
            vec!["vertex count 4000000000 is absurd"],
        ),
        (
            "negative vertex count",
            text.replace(&vertex_line, "element vertex -5\n"),
            vec!["element count '-5' is not a number"],
        ),
        (
            "count larger than the body",
            text.replace(
                &vertex_line,
                &format!("element vertex {}\n", body.len() / 40 + 1),
            ),
            vec!["(truncated)"],
        ),
        (
            "count smaller than the body",
            text.replace(
                &vertex_line,
                &format!("element vertex {}\n", body.len() / 40 - 1),
            ),
            vec!["(trailing data)"],
        ),
        (
            "missing property",
            text.replace("property float area\n", ""),
            vec!["area"],
        ),
        (
            "property twice",
            text.replace(
                "property float area\n",
                "property float area\nproperty float area\n",
            ),
            vec!["area"],
        ),
        (
            "property of the wrong type",
            text.replace("property float area\n", "property double area\n"),
            vec!["area"],
        ),
        (
            "list property",
            text.replace(
                "end_header\n",
                "property list uchar int vertex_indices\nend_header\n",
            ),
            vec!["list property 'vertex_indices'"],
        ),
        (
            "unknown keyword",
            text.replace("end_header\n", "frobnicate 3\nend_header\n"),
            vec!["unknown header keyword 'frobnicate'"],
        ),
        (
            "no end_header",
            text.replace("end_header\n", ""),
            vec!["samples.ply"],
        ),
        (
            "malformed object comment",
            text.replace("comment lucent object 0 ", "comment lucent object zero "),
            vec!["malformed comment"],
        ),
        (
            "group larger than the file",
            text.replace(
                &format!("comment lucent object 0 {count} "),
                &format!("comment lucent object 0 {} ", body.len() / 40 + 5),
            ),
            vec!["claim more than the file's"],
        ),
        (
            "samples of no object",
            text.replace(&format!("comment lucent object 0 {count} ball\n"), ""),
            vec!["belong to no object"],
        ),
        (
            "binary junk in the header",
            text.replacen("comment", "\u{0}\u{1}\u{2}", 1),
            vec!["samples.ply"],
        ),
    ];
    for (what, header_text, needles) in cases {
        assert_ne!(header_text, text, "{what}: the replacement did nothing");
        sb.write("samples.ply", &[header_text.as_bytes(), body].concat());
        let mut all = vec!["baked samples:"];
        all.extend(needles);
        let message = sb.fails(&from_samples(), 1, &all);
        assert!(!message.contains("internal"), "{what}: {message}");
    }
}

/// NaN, infinities, negative areas and irradiance, and non-unit normals in the body: the
/// error names the sample (vertex) and the value.
#[test]
fn bad_values_in_ply_body() {
    let (sb, ply, header) = baked("ply-values");
    // Field index within the record (x y z nx ny nz area r g b) and the value to put there.
    let cases: &[(usize, f32, &str)] = &[
        (0, f32::NAN, "position"),
        (2, f32::INFINITY, "position"),
        (3, f32::NAN, "normal"),
        (4, 2.0, "normal"),
        (6, f32::NAN, "area NaN"),
        (6, -1.0, "area -1"),
        (6, f32::INFINITY, "area inf"),
        (7, f32::NAN, "irradiance"),
        (9, -0.5, "irradiance"),
        (8, f32::NEG_INFINITY, "irradiance"),
    ];
    for &(field, value, needle) in cases {
        for sample in [0, 123, (ply.len() - header) / 40 - 1] {
            let mut bad = ply.clone();
            let at = header + sample * 40 + field * 4;
            bad[at..at + 4].copy_from_slice(&value.to_le_bytes());
            sb.write("samples.ply", &bad);
            let vertex = format!("{sample}");
            sb.fails(
                &from_samples(),
                1,
                &["baked samples: samples.ply", vertex.as_str(), needle],
            );
        }
    }
    // Each sample valid, but the set's flux beyond f32: a scene limit, not an internal error.
    let mut bad = ply.clone();
    for sample in 0..(ply.len() - header) / 40 {
        let at = header + sample * 40;
        bad[at + 24..at + 28].copy_from_slice(&1e30_f32.to_le_bytes());
        for c in 0..3 {
            bad[at + 28 + 4 * c..at + 32 + 4 * c].copy_from_slice(&1e20_f32.to_le_bytes());
        }
    }
    sb.write("samples.ply", &bad);
    let message = sb.fails(&from_samples(), 1, &["exceed single precision"]);
    assert!(!message.contains("internal"), "{message}");
}

/// A set baked for another scene: the object names, indices and kinds must match.
#[test]
fn samples_baked_for_another_scene() {
    let (sb, ply, header) = baked("ply-other-scene");
    let text = String::from_utf8(ply[..header].to_vec()).unwrap();
    let body = &ply[header..];
    let count = (body.len() / 40).to_string();
    let group = format!("comment lucent object 0 {count} ball\n");
    let cases = [
        (
            format!("comment lucent object 0 {count} bunny\n"),
            "baked for 'bunny', but that object is 'ball'",
        ),
        (
            format!("comment lucent object 7 {count} ball\n"),
            "samples for object 7 but the scene has 2",
        ),
        (
            format!("comment lucent object 1 {count} plate\n"),
            "not translucent",
        ),
        (
            format!(
                "comment lucent object 0 {} ball\ncomment lucent object 0 {} ball\n",
                body.len() / 80,
                body.len() / 40 - body.len() / 80
            ),
            "two sample groups for object 0",
        ),
    ];
    for (replacement, needle) in cases {
        let bad = text.replace(&group, &replacement);
        assert_ne!(bad, text);
        sb.write("samples.ply", &[bad.as_bytes(), body].concat());
        sb.fails(&from_samples(), 1, &["baked samples:", needle]);
    }
}

/// `bake --method` chooses how the samples are lit: both sets have the same positions and
/// areas and name their method; edge-refined's differ from edge-aware's only where the plate's
/// shadow edge crosses a sample's cell (the mean over the cell instead of the value at it).
#[test]
fn bake_method_chooses_how_the_samples_are_lit() {
    let sb = Sandbox::new("bake-method");
    let bake = |method: &str| {
        let out = format!("{method}.ply");
        sb.succeeds(&[
            "bake",
            "scene.toml",
            "-q",
            "-o",
            &out,
            "--samples",
            "2000",
            "--method",
            method,
        ]);
        let ply = sb.read(&out);
        let header = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let text = String::from_utf8_lossy(&ply[..header]).into_owned();
        assert!(
            text.contains(&format!("comment method {method}\n")),
            "{text}"
        );
        let floats: Vec<f32> = ply[header..]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        floats
    };
    let (own, cells) = (bake("edge-aware"), bake("edge-refined"));
    assert_eq!(own.len(), cells.len());
    let samples: Vec<(&[f32], &[f32])> = own.chunks_exact(10).zip(cells.chunks_exact(10)).collect();
    assert!(
        samples.iter().all(|(a, b)| a[..7] == b[..7]),
        "positions, normals, areas"
    );
    let averaged = samples.iter().filter(|(a, b)| a[7..] != b[7..]).count();
    assert!(
        averaged > 0 && averaged < samples.len() / 10,
        "{averaged} of {} samples averaged",
        samples.len()
    );
}
