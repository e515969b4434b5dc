//! Output paths that cannot be written, and `compare` on bad images: nothing is written or
//! replaced, and no temporary file is left behind.

use super::harness::{CONSTANT, PREVIOUS, Sandbox, render, rgb_exr, scene};

/// PNG and EXR paths in a missing directory, naming a directory, or the same file twice:
/// rejected before rendering, both outputs untouched.
#[test]
fn unwritable_output_paths() {
    let sb = Sandbox::new("out-paths");
    std::fs::create_dir(sb.path("adir")).unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["-o", "nodir/x.png"],
            &["nodir/x.png", "the directory 'nodir' does not exist"],
        ),
        (
            &["--exr", "nodir/x.exr"],
            &["nodir/x.exr", "the directory 'nodir' does not exist"],
        ),
        (
            &["-o", "adir"],
            &["adir: cannot write there: it is a directory"],
        ),
        (
            &["--exr", "adir"],
            &["adir: cannot write there: it is a directory"],
        ),
        (&["-o", "same", "--exr", "same"], &["given as both"]),
        (&["-o", "/"], &["does not name a file"]),
    ];
    for (extra, needles) in cases {
        sb.fails(&render(extra), 1, needles);
    }
}

/// The bug this suite found: with a good PNG path and an EXR path in a missing directory,
/// the PNG used to be replaced before the EXR failed. Both outputs now stay as they were.
#[test]
fn failing_exr_does_not_replace_the_png() {
    let sb = Sandbox::new("out-partial");
    sb.fails(
        &render(&["-o", "out.png", "--exr", "missing/out.exr"]),
        1,
        &["missing/out.exr"],
    );
    assert_eq!(sb.read("out.png"), PREVIOUS);
}

/// An existing output whose permissions say read-only is refused by name, not replaced (a
/// rename would replace it whatever its permissions; as root nothing else stops it): render
/// checks before rendering, so the other output keeps its bytes too; bake refuses at the
/// write.
#[test]
fn read_only_outputs_are_refused() {
    let sb = Sandbox::new("out-readonly");
    let protect = |name: &str| {
        let path = sb.path(name);
        let mut permissions = std::fs::metadata(&path).unwrap().permissions();
        permissions.set_readonly(true);
        std::fs::set_permissions(&path, permissions).unwrap();
    };
    protect("out.exr");
    sb.fails(
        &render(&["-o", "out.png", "--exr", "out.exr"]),
        1,
        &[
            "out.exr: the file is read-only",
            "lucent does not replace it",
        ],
    );
    assert_eq!(sb.read("out.png"), PREVIOUS);
    assert_eq!(sb.read("out.exr"), PREVIOUS);
    std::fs::write(sb.path("s.ply"), PREVIOUS).unwrap();
    protect("s.ply");
    sb.fails(
        &["bake", "scene.toml", "-q", "-o", "s.ply"],
        1,
        &["s.ply: the file is read-only"],
    );
    assert_eq!(sb.read("s.ply"), PREVIOUS);
    assert!(
        std::fs::metadata(sb.path("s.ply"))
            .unwrap()
            .permissions()
            .readonly()
    );
}

/// Bake: an output in a missing directory or naming a directory.
#[test]
fn unwritable_bake_output() {
    let sb = Sandbox::new("out-bake");
    std::fs::create_dir(sb.path("adir")).unwrap();
    sb.fails(
        &["bake", "scene.toml", "-q", "-o", "nodir/s.ply"],
        1,
        &["nodir/s.ply"],
    );
    sb.fails(&["bake", "scene.toml", "-q", "-o", "adir"], 1, &["adir"]);
    // A bad scene never reaches the writer.
    sb.fails(
        &["bake", "nosuch.toml", "-q", "-o", "s.ply"],
        1,
        &["nosuch.toml: cannot read scene"],
    );
}

/// `compare` on missing, truncated and non-image files, of different sizes, and on tiles of
/// different places: an error naming the file, and no heat map written.
#[cfg(feature = "harness")]
#[test]
fn compare_bad_images() {
    let sb = Sandbox::new("out-compare");
    sb.succeeds(&render(&[]));
    let png = sb.read("out.png");
    sb.write("a.png", &png);
    sb.write("cut.png", &png[..png.len() / 2]);
    sb.write("junk.exr", b"not an exr at all");
    let small = Sandbox::with_scene(
        "out-compare-small",
        &String::from_utf8(sb.read("scene.toml"))
            .unwrap()
            .replace("width = 32", "width = 16"),
    );
    small.succeeds(&render(&[]));
    sb.write("small.png", &small.read("out.png"));
    // Two tiles of one size from different places of the image.
    for (crop, name) in [("0,0,32,16", "top.exr"), ("0,16,32,32", "bottom.exr")] {
        sb.succeeds(&render(&["--aa", "1", "--crop", crop, "--exr", name]));
    }
    let heat = ["--heatmap", "heat.png"];
    let cases: &[(&[&str], &[&str])] = &[
        (&["compare", "a.png", "nosuch.png"], &["nosuch.png"]),
        (&["compare", "cut.png", "a.png"], &["cut.png"]),
        (&["compare", "a.png", "junk.exr"], &["junk.exr"]),
        (
            &["compare", "a.png", "scene.toml"],
            &["scene.toml", "unknown image type"],
        ),
        (&["compare", "a.png", "small.png"], &["32", "16"]),
        (
            &["compare", "top.exr", "bottom.exr"],
            &[
                "top.exr holds pixels from (0, 0) of a 32×32 image",
                "bottom.exr holds pixels from (0, 16)",
                "compare images of the same region",
            ],
        ),
    ];
    for (args, needles) in cases {
        let mut all = args.to_vec();
        all.extend_from_slice(&heat);
        sb.fails(&all, 1, needles);
    }
}

/// A B44-compressed EXR (lossy, and a decoder whose 16-bit arithmetic wraps: a panic in a
/// build with overflow checks) is refused from its header by `compare` and `merge`.
#[test]
fn lossy_b44_exrs_are_refused() {
    use exr::prelude::{Compression, Encoding, FlatSamples, f16};
    let encoding = Encoding {
        compression: Compression::B44,
        ..Encoding::FAST_LOSSLESS
    };
    let b44 = rgb_exr(8, FlatSamples::F16(vec![f16::ONE; 8 * 8]), encoding);
    let sb = Sandbox::new("out-b44");
    sb.write("b.exr", &b44);
    let message = "b.exr: OpenEXR B44 compression is not read (save the file with ZIP, PIZ or \
                   no compression)";
    sb.fails(&["compare", "b.exr", "b.exr"], 1, &[message]);
    sb.fails(&["merge", "b.exr", "-o", "m.png"], 1, &[message]);
    assert!(!sb.path("m.png").exists());
}

/// A reader that closes the pipe before the report comes (`lucent presets | head -0`): the
/// output ends quietly with status 0, not a panic on the broken pipe.
#[test]
fn a_closed_standard_output_is_not_a_crash() {
    let (reader, writer) = std::io::pipe().unwrap();
    // Closed before the child starts: its every write fails with a broken pipe.
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lucent"))
        .arg("presets")
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// Output paths on the command line replace the scene's `[output]` paths entirely: `-o` alone
/// writes only that PNG, `--exr` alone only that EXR (with its alpha: the coverage, 0 off the
/// object, 1 inside it, fractions on its silhouette at `aa = 2`).
#[test]
fn command_line_outputs_replace_the_scenes() {
    let sb = Sandbox::new("out-replace");
    let out = sb.run(&render(&["-o", "cli.png"]));
    assert!(out.status.success(), "{out:?}");
    assert!(sb.read("cli.png").starts_with(b"\x89PNG"));
    assert_eq!(sb.read("out.png"), PREVIOUS);
    assert_eq!(sb.read("out.exr"), PREVIOUS, "the scene's EXR was written");

    let out = sb.run(&render(&["--exr", "cli.exr"]));
    assert!(out.status.success(), "{out:?}");
    assert_eq!(sb.read("out.png"), PREVIOUS, "the scene's PNG was written");
    assert_eq!(sb.read("out.exr"), PREVIOUS);
    let exr = lucent_raster::output::read_exr(&sb.path("cli.exr")).unwrap();
    let alpha = exr.alpha.expect("an alpha channel");
    assert_eq!(alpha.len(), exr.beauty.pixels().len());
    assert!(alpha.iter().all(|a| (0.0..=1.0).contains(a)));
    for wanted in [0.0, 1.0] {
        assert!(alpha.contains(&wanted), "no pixel with alpha {wanted}");
    }
    assert!(
        alpha.iter().any(|&a| a > 0.0 && a < 1.0),
        "no partial coverage"
    );
    // The beauty is premultiplied: nothing where nothing is covered.
    for (a, p) in alpha.iter().zip(exr.beauty.pixels()) {
        if *a == 0.0 {
            assert_eq!(p.to_array(), [0.0; 3]);
        }
    }
}

/// An output that is one of the command's own inputs is refused before anything is read or
/// rendered, whichever option names it: `-o` the scene, the scene's `[output]` its mesh,
/// `--exr` the `--samples-from` file, bake's `-o` the scene, merge's `--exr` a tile, compare's
/// heat map the test image.
#[test]
fn outputs_never_replace_inputs() {
    let needle = "cannot write there: it is one of this command's inputs";
    let sb = Sandbox::new("out-inputs");
    sb.fails(&render(&["-o", "scene.toml"]), 1, &["scene.toml", needle]);
    sb.fails(
        &["bake", "scene.toml", "-q", "-o", "./scene.toml"],
        1,
        &["./scene.toml", needle],
    );
    sb.write("samples.ply", PREVIOUS);
    sb.fails(
        &render(&["--samples-from", "samples.ply", "--exr", "samples.ply"]),
        1,
        &["samples.ply", needle],
    );
    sb.fails(
        &["merge", "out.exr", "--exr", "out.exr"],
        1,
        &["out.exr", needle],
    );
    sb.fails(
        &["compare", "out.png", "out.exr", "--heatmap", "out.png"],
        1,
        &["out.png", needle],
    );

    let text =
        scene("mesh = \"tri.obj\"", CONSTANT).replace("png = \"out.png\"", "png = \"tri.obj\"");
    let sb = Sandbox::with_scene("out-input-mesh", &text);
    sb.write("tri.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    sb.fails(&["scene.toml", "-q"], 1, &["tri.obj", needle]);
}

/// A symbolic link as the output writes the file it names and stays a link; a pipe is
/// refused (the rename would replace it with a plain file, as it would `/dev/null`), and so is
/// a path ending in a separator, before rendering.
#[cfg(unix)]
#[test]
fn links_are_followed_and_pipes_refused() {
    let sb = Sandbox::new("out-special");
    std::os::unix::fs::symlink("out.png", sb.path("link.png")).unwrap();
    sb.succeeds(&render(&["-o", "link.png"]));
    assert!(sb.read("out.png").starts_with(b"\x89PNG"));
    let link = std::fs::symlink_metadata(sb.path("link.png")).unwrap();
    assert!(link.file_type().is_symlink());
    std::fs::remove_file(sb.path("link.png")).unwrap();
    sb.reset_outputs();

    sb.fails(&render(&["-o", "out.png/"]), 1, &["ends with a separator"]);

    // Not through `fails`: its snapshot of the directory would block reading the pipe.
    let made = std::process::Command::new("mkfifo")
        .arg(sb.path("pipe.png"))
        .status()
        .unwrap();
    assert!(made.success());
    let out = sb.run(&render(&["-o", "pipe.png"]));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("pipe.png: cannot write there: it is not a regular file"),
        "{stderr}"
    );
    let kind = std::fs::symlink_metadata(sb.path("pipe.png"))
        .unwrap()
        .file_type();
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(&kind));
    assert_eq!(sb.read("out.png"), PREVIOUS);
}

/// A closed standard error: an error still exits 1 (not a panic, 101), and a render that has a
/// warning to print still writes its image.
#[test]
fn a_closed_standard_error_is_not_a_crash() {
    let sb = Sandbox::new("out-stderr");
    let run = |args: &[&str]| {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        std::process::Command::new(env!("CARGO_BIN_EXE_lucent"))
            .args(args)
            .current_dir(sb.path(""))
            .stderr(writer)
            .stdout(std::process::Stdio::null())
            .status()
            .unwrap()
    };
    assert_eq!(run(&["missing.toml"]).code(), Some(1));
    // 10 samples on the sphere: far too few, which the renderer warns about.
    let text = scene(super::harness::SPHERE, CONSTANT).replace("samples = 500", "samples = 10");
    std::fs::write(sb.path("warn.toml"), text).unwrap();
    assert_eq!(
        run(&["warn.toml", "-q", "-o", "warned.png"]).code(),
        Some(0)
    );
    assert!(sb.read("warned.png").starts_with(b"\x89PNG"));
}

/// A light so bright and near that a Lambert surface's irradiance overflows f32 (3·10³⁸ W/sr
/// at 0.4 units) is an error naming the cause, and nothing is written. (On a translucent
/// object the irradiance samples refuse it first.)
#[test]
fn infinite_pixels_are_an_error() {
    let text = scene(super::harness::SPHERE, CONSTANT)
        .replace("intensity = 25.0", "intensity = 3e38")
        .replace("position = [0.0, -3.0, 5.0]", "position = [0.0, -0.9, 0.5]")
        .replace("material = \"m\"", "material = \"grey\"");
    let sb = Sandbox::with_scene("out-infinite", &text);
    sb.fails(
        &["scene.toml", "-q"],
        1,
        &["infinite or NaN", "nothing was written"],
    );
}
