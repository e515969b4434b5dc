//! Scene files: missing, unreadable, truncated, malformed TOML, NaN and infinities in any
//! number, resolutions of 0 and 100000².

use super::harness::{CONSTANT, SPHERE, Sandbox, render, scene};

/// The harness is able to see a run: the template renders, and replaces both outputs.
#[test]
fn template_scene_renders_and_replaces_the_outputs() {
    let sb = Sandbox::new("template");
    sb.succeeds(&render(&[]));
    assert!(sb.read("out.png").starts_with(b"\x89PNG"));
    assert!(sb.read("out.exr").starts_with(&[0x76, 0x2f, 0x31, 0x01]));
}

#[test]
fn missing_scene_file() {
    let sb = Sandbox::new("missing-scene");
    sb.fails(
        &["nosuch.toml", "-q"],
        1,
        &["nosuch.toml: cannot read scene", "No such file"],
    );
    sb.fails(
        &["no/such/dir/scene.toml", "-q"],
        1,
        &["no/such/dir/scene.toml: cannot read scene"],
    );
}

#[test]
fn scene_is_a_directory() {
    let sb = Sandbox::new("scene-dir");
    std::fs::create_dir(sb.path("d.toml")).unwrap();
    sb.fails(&["d.toml", "-q"], 1, &["d.toml: cannot read scene"]);
}

#[test]
fn scene_not_utf8() {
    let sb = Sandbox::new("scene-utf8");
    let mut text = scene(SPHERE, CONSTANT).into_bytes();
    text.splice(40..40, [0xff, 0xfe, 0x00]);
    sb.write("scene.toml", &text);
    sb.fails(&render(&[]), 1, &["scene.toml:", "not UTF-8"]);
}

/// The scene cut at every 5th byte up to its last line: each prefix is an error naming the
/// file (most are TOML syntax errors with a line; the others miss a required table or key),
/// never a render. (The last line is the `layers` of `[output]`: cutting the file anywhere
/// before it leaves out at least one required thing — the lights come before it, but so does a
/// `[camera]` or an object cut in half.)
#[test]
fn truncated_scene() {
    let sb = Sandbox::new("scene-truncated");
    let text = scene(SPHERE, CONSTANT);
    let full = text.clone();
    // Cutting inside the last tables can leave a valid scene (e.g. without `layers`); stop
    // before the first light's intensity is complete.
    let stop = full.find("intensity = 25.0").unwrap();
    let mut failures = 0;
    for cut in (0..stop).step_by(5) {
        sb.write("scene.toml", &full.as_bytes()[..cut]);
        sb.fails(&render(&[]), 1, &["error: scene.toml"]);
        failures += 1;
    }
    assert!(failures > 50);
}

/// Malformed TOML and malformed values: located errors naming the key.
#[test]
fn malformed_scene() {
    let base = scene(SPHERE, CONSTANT);
    let cases: &[(&str, &str, &str, &[&str])] = &[
        // (what, replace, with, expected in the message)
        (
            "unclosed array",
            "fov = 35.0",
            "fov = [35.0",
            &["scene.toml:", "TOML syntax error"],
        ),
        (
            "double equals",
            "fov = 35.0",
            "fov = = 35.0",
            &["scene.toml:6:", "TOML syntax error"],
        ),
        (
            "duplicate key",
            "fov = 35.0",
            "fov = 35.0\nfov = 36.0",
            &["scene.toml:7:", "duplicate key"],
        ),
        (
            "unknown key",
            "fov = 35.0",
            "fov = 35.0\nfocal = 2.0",
            &["scene.toml:", "unknown key", "focal"],
        ),
        (
            "string for a number",
            "fov = 35.0",
            "fov = \"wide\"",
            &["scene.toml:6:", "camera.fov", "invalid type"],
        ),
        (
            "missing required key",
            "fov = 35.0\n",
            "",
            &["scene.toml:", "camera", "fov"],
        ),
        (
            "missing camera",
            "[camera]",
            "[kamera]",
            &["scene.toml", "kamera"],
        ),
        (
            "out of range",
            "fov = 35.0",
            "fov = 180.0",
            &["scene.toml:6:", "camera.fov", "(0, 180)", "180"],
        ),
        (
            "unknown material",
            "material = \"m\"",
            "material = \"jade\"",
            &["scene.toml:", "object[0].material", "jade"],
        ),
        (
            "unknown method",
            "method = \"edge-aware\"",
            "method = \"fast\"",
            &["scene.toml:", "render.method", "fast"],
        ),
        (
            "vector of two",
            "target = [0.0, 0.0, 0.5]",
            "target = [0.0, 0.5]",
            &["scene.toml:4:", "camera.target", "3 numbers"],
        ),
        (
            "negative samples",
            "samples = 500",
            "samples = -500",
            &["scene.toml:", "render.samples", "-500"],
        ),
        (
            "samples not a count",
            "samples = 500",
            "samples = \"lots\"",
            &[
                "scene.toml:",
                "render.samples",
                "`lots` is not a sample count",
                "\"auto\"",
            ],
        ),
        (
            "samples beyond the cap",
            "samples = 500",
            "samples = 40000000",
            &["scene.toml:", "render.samples", "1..=33554432", "40000000"],
        ),
        (
            "max_samples with a count",
            "samples = 500",
            "samples = 500\nmax_samples = 100",
            &["scene.toml:", "render.max_samples", "automatic count only"],
        ),
        (
            "max_samples of 0",
            "samples = 500",
            "samples = \"auto\"\nmax_samples = 0",
            &["scene.toml:", "render.max_samples", "1..=33554432 (got 0)"],
        ),
        (
            "K_d of 1",
            "kd = [0.8, 0.6, 0.4]",
            "kd = [0.8, 1.0, 0.4]",
            &["scene.toml:", "material.m.kd"],
        ),
        (
            "η below 1",
            "eta = 1.3",
            "eta = 0.7",
            &["scene.toml:", "material.m.eta", "0.7"],
        ),
        (
            "a table as an array",
            "[camera]\nposition = [0.0, -5.0, 1.2]\ntarget = [0.0, 0.0, 0.5]\nup = [0.0, 0.0, 1.0]\n\
             fov = 35.0\nwidth = 32\nheight = 32",
            "camera = [[0.0, -5.0, 1.2], [0.0, 0.0, 0.5], [0.0, 0.0, 1.0], 35.0, 32, 32]",
            &["scene.toml:2:10: camera: expected a table ([camera] or { … }), got an array"],
        ),
        (
            "an inline table as an array",
            "specular = { exponent = 60.0, strength = 0.4 }",
            "specular = [60.0, 0.4]",
            &[
                "scene.toml:",
                "material.m.specular: expected a table",
                "got an array",
            ],
        ),
    ];
    for (what, from, to, needles) in cases {
        assert!(base.contains(from), "{what}: template lacks {from}");
        let sb = Sandbox::with_scene("scene-malformed", &base.replacen(from, to, 1));
        let message = sb.fails(&render(&[]), 1, needles);
        assert!(!message.contains("internal"), "{what}: {message}");
    }
}

/// One numeric literal of the template: its line (1-based), byte range and key.
struct Number {
    line: usize,
    start: usize,
    end: usize,
    key: String,
}

/// Every numeric literal of a TOML text (outside strings, comments and table headers), with
/// the key it belongs to (the last `name =` before it on its line).
fn numbers(text: &str) -> Vec<Number> {
    let mut out = Vec::new();
    let mut offset = 0;
    for (index, line) in text.split_inclusive('\n').enumerate() {
        let bytes = line.as_bytes();
        let (mut i, mut key, mut ident) = (0, String::new(), String::new());
        if line.trim_start().starts_with('[') && !line.contains('=') {
            offset += line.len();
            continue;
        }
        while i < bytes.len() {
            let c = bytes[i] as char;
            if c == '#' {
                break;
            } else if c == '"' {
                i += 1 + line[i + 1..].find('"').unwrap_or(0) + 1;
                continue;
            } else if c.is_ascii_alphabetic() || c == '_' {
                let end = line[i..]
                    .find(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_'))
                    .map_or(line.len(), |n| i + n);
                ident = line[i..end].to_string();
                i = end;
                continue;
            } else if c == '=' {
                key = ident.clone();
            } else if c.is_ascii_digit()
                || ((c == '-' || c == '+') && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
            {
                let end = line[i + 1..]
                    .find(|ch: char| !(ch.is_ascii_digit() || "._eE+-".contains(ch)))
                    .map_or(line.len(), |n| i + 1 + n);
                out.push(Number {
                    line: index + 1,
                    start: offset + i,
                    end: offset + end,
                    key: key.clone(),
                });
                i = end;
                continue;
            }
            i += 1;
        }
        offset += line.len();
    }
    out
}

/// Every number of the scene replaced in turn by `nan`, `inf`, `-inf` and `1e39` (beyond
/// f32): each gives exit 1 and a message at the number's line naming its key and the value.
/// The template has every kind of number: vectors, colours, angles, integers, a specular
/// table, all four light types, every render setting.
#[test]
fn nan_and_infinity_in_any_scene_number() {
    let text = scene(SPHERE, CONSTANT);
    let found = numbers(&text);
    assert!(found.len() > 70, "only {} numbers found", found.len());
    let sb = Sandbox::with_scene("scene-nan", &text);
    for n in &found {
        for (value, shown) in [
            ("nan", "nan"),
            ("inf", "inf"),
            ("-inf", "inf"),
            ("1e39", ""),
        ] {
            let mut bad = text.clone();
            bad.replace_range(n.start..n.end, value);
            sb.write("scene.toml", bad.as_bytes());
            let at = format!("scene.toml:{}:", n.line);
            let message = sb.fails(&render(&[]), 1, &[at.as_str(), n.key.as_str()]);
            let lower = message.to_lowercase();
            assert!(
                lower.contains(shown)
                    || lower.contains("too large")
                    || lower.contains("invalid type: floating point"),
                "{value} for {}: {message}",
                n.key
            );
        }
    }
}

/// Resolutions of 0 and 100000² in the scene file.
#[test]
fn zero_and_huge_resolution_in_scene() {
    let base = scene(SPHERE, CONSTANT);
    for (width, height, needles) in [
        (
            "0",
            "32",
            &["scene.toml:7:", "camera.width", "1..=16384", "got 0"][..],
        ),
        ("32", "0", &["scene.toml:8:", "camera.height", "got 0"][..]),
        (
            "100000",
            "100000",
            &["scene.toml:7:", "camera.width", "got 100000"][..],
        ),
        (
            "16384",
            "16384",
            &[
                "scene.toml:8:",
                "camera.height",
                "more than 67108864 pixels",
            ][..],
        ),
        ("-1", "32", &["camera.width", "got -1"][..]),
        ("4294967296", "32", &["camera.width", "got 4294967296"][..]),
    ] {
        let text = base
            .replace("width = 32", &format!("width = {width}"))
            .replace("height = 32", &format!("height = {height}"));
        let sb = Sandbox::with_scene("scene-resolution", &text);
        sb.fails(&render(&[]), 1, needles);
    }
}

/// A scene far too large for single precision (a translucent triangle 1e20 units across):
/// rejected at load, at the key naming the mesh, not an internal error.
#[test]
fn scene_beyond_single_precision() {
    let sb = Sandbox::with_scene("scene-huge", &scene("obj = \"big.obj\"", CONSTANT));
    sb.write(
        "big.obj",
        b"v -1e20 -1e20 0\nv 1e20 -1e20 0\nv 0 1e20 0\nf 1 2 3\n",
    );
    let message = sb.fails(
        &render(&[]),
        1,
        &[
            "scene.toml:",
            "object[0].obj",
            "big.obj",
            "farther than 1e12 units",
        ],
    );
    assert!(!message.contains("internal"), "{message}");
}

/// Mean free paths the scene format accepts (> 0) but the f32 dipole cannot represent
/// (below 2.3e-13, above about 1e12; see docs/valid-ranges.md): an error at the key, with the
/// value as written.
#[test]
fn mean_free_path_beyond_single_precision() {
    for ell in ["1e-14", "1e13"] {
        let material = CONSTANT.replace("0.05", ell);
        let sb = Sandbox::with_scene("scene-mfp", &scene(SPHERE, &material));
        sb.fails(
            &render(&[]),
            1,
            &[
                "scene.toml:",
                &format!("material.m.mean_free_path: {ell} is out of range"),
                "single precision",
            ],
        );
    }
}
