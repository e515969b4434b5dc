//! Loader tests: every error class (each asserting the file, the line and the key of the
//! message), every key reaching the model, the example scenes in `scenes/`, and file access
//! through both origins.
//!
//! Most cases edit one line of [`BASE`], a minimal valid scene, and name the line the error
//! must point at by a piece of its text (`needle`).

mod examples;
mod obj_materials;
mod ranges;
mod references;
mod robustness;
mod structure;

use std::borrow::Cow;

use super::*;
use crate::texture::tests::{encode_png, patch_ihdr_size};

/// A minimal valid scene; cases edit it with [`edit`] or append to it.
const BASE: &str = r#"[camera]
position = [0, -5, 1]
target = [0, 0, 0.5]
fov = 30

[[object]]
shape = "sphere"
radius = 1
material = "m"

[material.m]
type = "translucent"
preset = "marble"
mm_per_unit = 10

[[light]]
type = "point"
position = [0, -3, 5]
intensity = 20
"#;

/// The preset lines of [`BASE`], which cases swap for other ways of giving the medium.
const PRESET: &str = "preset = \"marble\"\nmm_per_unit = 10";

const QUAD_UV: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                       f 1/1 2/2 3/3 4/4\n";
const QUAD_NO_UV: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

/// An 8 × 1 grey ramp, codes 0, 32, …, 224.
fn png_ramp() -> Vec<u8> {
    let data: Vec<u8> = (0..8u8).map(|i| i * 32).collect();
    let (grey, eight) = (png::ColorType::Grayscale, png::BitDepth::Eight);
    encode_png(8, 1, grey, eight, &data, None)
}

/// The in-memory files every case can refer to.
fn origin() -> SceneOrigin {
    let ramp = png_ramp();
    let truncated = ramp[..ramp.len() - 20].to_vec();
    let (rgb, eight) = (png::ColorType::Rgb, png::BitDepth::Eight);
    let mut huge = encode_png(1, 1, rgb, eight, &[0; 3], None);
    patch_ihdr_size(&mut huge, 100_000, 1);
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("quad.obj", QUAD_UV.into()),
        ("nouv.obj", QUAD_NO_UV.into()),
        (
            "syntax.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 oops 0\nf 1 2 3\n".into(),
        ),
        ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n".into()),
        ("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".into()),
        ("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n".into()),
        ("empty.obj", "# nothing\nv 0 0 0\n".into()),
        ("ramp.png", ramp),
        ("bad.png", b"\x89PNG\r\n\x1a\nnot really".to_vec()),
        ("trunc.png", truncated),
        ("huge.png", huge),
    ];
    SceneOrigin::Embedded {
        name: "t.toml".into(),
        files: files
            .into_iter()
            .map(|(n, b)| (n.to_string(), Cow::Owned(b)))
            .collect(),
    }
}

/// Parses scene text with the in-memory files of [`origin`].
fn load(text: &str) -> Result<Scene, SceneError> {
    parse_scene(text, &origin())
}

/// [`BASE`] with `old` replaced by `new` (`old` must occur in it).
fn edit(old: &str, new: &str) -> String {
    assert!(BASE.contains(old), "BASE has no {old:?}");
    BASE.replacen(old, new, 1)
}

/// [`BASE`] with `extra` appended.
fn append(extra: &str) -> String {
    format!("{BASE}{extra}")
}

/// Loads `text`, expects an error of `kind` on the line holding `needle`, for `key`, with
/// `words` in the message; checks that the displayed message carries all of it.
#[track_caller]
fn expect(text: &str, kind: SceneErrorKind, needle: &str, key: &str, words: &str) {
    let err = match load(text) {
        Ok(_) => panic!("loaded, expected {kind:?} at {key}:\n{text}"),
        Err(e) => e,
    };
    let shown = err.to_string();
    assert_eq!(err.kind, kind, "{shown}");
    assert_eq!(err.file, "t.toml", "{shown}");
    let line = text
        .lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no line with {needle:?}"))
        + 1;
    assert_eq!(err.position.map(|p| p.0), Some(line), "{shown}");
    assert!(shown.starts_with(&format!("t.toml:{line}:")), "{shown}");
    assert_eq!(err.key.as_deref(), Some(key), "{shown}");
    assert!(shown.contains(key), "{shown}");
    assert!(
        err.message.contains(words),
        "message lacks {words:?}: {shown}"
    );
}

/// A table of [`expect`] cases for one error kind, one per line:
/// `scene text => needle, key, words in the message;`.
macro_rules! expect_all {
    ($kind:expr; $($text:expr => $needle:expr, $key:expr, $words:expr;)+) => {
        $( expect(&$text, $kind, $needle, $key, $words); )+
    };
}
use expect_all;

#[test]
fn base_scene_loads_with_defaults() {
    let s = load(BASE).expect("BASE is valid");
    assert_eq!(s.objects.len(), 1);
    assert_eq!((s.camera.width, s.camera.height), (512, 512));
    assert_eq!(s.camera.up, glam::Vec3::Z);
    assert_eq!(s.render, RenderSettings::default());
    assert_eq!(s.output.png.as_deref(), Some(std::path::Path::new("t.png")));
    assert_eq!(s.output.exr, None);
    assert_eq!(s.objects[0].name, "sphere");
}
