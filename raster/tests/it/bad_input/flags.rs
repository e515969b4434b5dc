//! Command-line flags: usage errors (exit 2, printed by clap), and well-formed values that
//! are out of range, NaN or infinite (exit 1, naming the flag and the value).

use super::harness::{Sandbox, render};

/// Unknown flags, malformed values, missing values, conflicting flags: exit 2.
#[test]
fn bad_flags_are_usage_errors() {
    let sb = Sandbox::new("flags-usage");
    let cases: &[(&[&str], &[&str])] = &[
        (&["--bogus"], &["unexpected argument '--bogus'", "Usage"]),
        (&["--width", "abc"], &["invalid value 'abc'", "--width"]),
        (&["--width", "1e3"], &["invalid value '1e3'", "--width"]),
        (&["--width", "-5"], &["unexpected argument '-5'"]),
        (
            &["--width", "100000000000"],
            &["invalid value '100000000000'", "--width"],
        ),
        (&["--samples", "-1"], &["unexpected argument '-1'"]),
        (&["--epsilon", "-1"], &["unexpected argument '-1'"]),
        (
            &["--epsilon", "small"],
            &["invalid value 'small'", "--epsilon"],
        ),
        (
            &["--method", "fast"],
            &["invalid value 'fast'", "--method", "edge-aware"],
        ),
        (&["--epsilon"], &["a value is required for '--epsilon"]),
        (
            &["--samples", "5", "--spacing", "0.1"],
            &["cannot be used with"],
        ),
        (&["--seed", "x"], &["invalid value 'x'", "--seed"]),
    ];
    for (extra, needles) in cases {
        sb.fails(&render(extra), 2, needles);
    }
    // The subcommands validate their own flags the same way.
    sb.fails(&["bake", "scene.toml", "--bogus"], 2, &["'--bogus'"]);
    if cfg!(feature = "harness") {
        sb.fails(&["compare", "out.png"], 2, &["required"]);
    } else {
        // Without the experiment harness there is no `compare` command.
        sb.fails(&["compare", "out.png"], 2, &["cannot be used with"]);
    }
    sb.fails(&["presets", "extra"], 2, &["unexpected argument 'extra'"]);
}

/// `--epsilon NaN` and every other float flag given NaN or an infinity: exit 1, naming the
/// flag. (Decimals beyond f32 parse to ∞, so the message shows `inf` for `1e40`; `-inf` is
/// a usage error, read as the flags `-i -n -f`, but `--exposure -1e40` reaches the check.)
#[test]
fn nan_and_infinite_flag_values() {
    let sb = Sandbox::new("flags-nan");
    for flag in [
        "--epsilon",
        "--smoothing",
        "--spacing",
        "--exposure",
        "--interpolation-tolerance",
    ] {
        for (value, shown) in [
            ("NaN", "NaN"),
            ("nan", "NaN"),
            ("inf", "inf"),
            ("1e40", "inf"),
        ] {
            let expect = format!("{flag} {shown}: must be");
            sb.fails(&render(&[flag, value]), 1, &[expect.as_str()]);
        }
    }
    sb.fails(
        &render(&["--exposure", "-1e40"]),
        1,
        &["--exposure -inf: must be"],
    );
    sb.fails(
        &render(&["--exposure", "-inf"]),
        2,
        &["unexpected argument"],
    );
}

/// Resolutions of 0 and 100000² on the command line, and other out-of-range counts.
#[test]
fn zero_and_huge_resolution_flags() {
    let sb = Sandbox::new("flags-resolution");
    let cases: &[(&[&str], &[&str])] = &[
        (&["--width", "0"], &["--width 0", "between 1 and 16384"]),
        (&["--height", "0"], &["--height 0", "between 1 and 16384"]),
        (
            &["--width", "100000", "--height", "100000"],
            &["--width 100000", "between 1 and 16384"],
        ),
        (&["--height", "100000"], &["--height 100000"]),
        (
            &["--width", "16384", "--height", "16384"],
            &["image size 16384×16384", "at most 67108864 pixels"],
        ),
        (&["--samples", "0"], &["--samples 0", "between 1 and"]),
        (&["--samples", "4000000000"], &["--samples 4000000000"]),
        (&["--aa", "0"], &["--aa 0", "between 1 and 8"]),
        (&["--aa", "9"], &["--aa 9"]),
        (&["--threads", "0"], &["--threads 0"]),
        // The scene's own limits: `threads` in 1..=1024, `seed` a signed 64-bit integer.
        (
            &["--threads", "1025"],
            &["--threads 1025", "between 1 and 1024"],
        ),
        (
            &["--seed", "9223372036854775808"],
            &[
                "--seed 9223372036854775808",
                "between 0 and 9223372036854775807",
            ],
        ),
        (&["--spacing", "0"], &["--spacing 0", "positive"]),
        // A count that saturates is not printed as 18446744073709551615.
        (
            &["--spacing", "1e-45"],
            &["would make more than 10¹⁹ samples", "the limit of 33554432"],
        ),
        (&["--exposure", "65"], &["--exposure 65"]),
        (
            &["--interpolation", "0"],
            &["--interpolation 0", "between 1 and 16"],
        ),
        (&["--interpolation", "17"], &["--interpolation 17"]),
        (
            &["--interpolation-tolerance", "-0.5"],
            &["--interpolation-tolerance -0.5", "≥ 0"],
        ),
    ];
    for (extra, needles) in cases {
        sb.fails(&render(extra), 1, needles);
    }
}

/// `--samples` and `--max-samples`: `auto` or a count; malformed values are usage errors
/// (exit 2), out-of-range ones and a cap on an explicit count runtime errors (exit 1).
#[test]
fn sample_count_flags() {
    let sb = Sandbox::new("flags-samples");
    let usage: &[(&[&str], &[&str])] = &[
        (
            &["--samples", "lots"],
            &["invalid value 'lots' for '--samples <N|auto>'", "or `auto`"],
        ),
        (&["--samples", "1.5"], &["invalid value '1.5'", "--samples"]),
        (
            &["--max-samples", "auto"],
            &["invalid value 'auto'", "--max-samples"],
        ),
        (&["--max-samples", "-3"], &["unexpected argument '-3'"]),
    ];
    for (extra, needles) in usage {
        sb.fails(&render(extra), 2, needles);
    }
    sb.fails(&["bake", "scene.toml", "--samples", "lots"], 2, &["'lots'"]);
    let runtime: &[(&[&str], &[&str])] = &[
        (
            &["--samples", "33554433"],
            &["--samples 33554433", "or auto"],
        ),
        (
            &["--max-samples", "0"],
            &["--max-samples 0", "between 1 and 33554432"],
        ),
        (
            &["--max-samples", "40000000", "--samples", "auto"],
            &["--max-samples 40000000"],
        ),
        // The template scene gives `samples = 500`.
        (
            &["--max-samples", "1000"],
            &[
                "--max-samples 1000",
                "automatic count only",
                "samples = 500",
            ],
        ),
        (
            &["--max-samples", "1000", "--spacing", "0.1"],
            &["spacing = 0.1", "--samples auto"],
        ),
    ];
    for (extra, needles) in runtime {
        sb.fails(&render(extra), 1, needles);
    }
}

/// The summary line says how the count was chosen; a count far too low for the material gets
/// one warning, even with `-q`.
#[test]
fn sample_count_summary_and_warning() {
    let sb = Sandbox::new("flags-samples-summary");
    let out = sb.succeeds(&["scene.toml", "--samples", "auto", "--max-samples", "6000"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains(" samples (auto"), "{stdout}");
    assert!(stdout.contains("ℓ_d)"), "{stdout}");
    // Every phase is timed, in the order it runs.
    let phases = [
        ": load ",
        ", prepare ",
        ", sampling ",
        ", irradiance ",
        ", cache ",
        ", raster ",
        ", shading ",
        ", total ",
    ];
    let at: Vec<usize> = phases
        .iter()
        .map(|p| {
            stdout
                .find(p)
                .unwrap_or_else(|| panic!("`{p}` in {stdout}"))
        })
        .collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{stdout}");
    // The ball's ℓ_d is 0.126 (blue): 20 samples are 3.3 ℓ_d apart, 2 are 11 ℓ_d apart
    // (a black image needs 100 ℓ_d: the unit tests of `render::density` check that text).
    let cases = [
        ("20", "hierarchical", "hierarchical will show blotches"),
        ("2", "exhaustive", "exhaustive will show blotches"),
        (
            "20",
            "local-global",
            "local-global will render hard, stair-stepped shadow edges",
        ),
    ];
    for (quiet, (count, method, effect)) in [false, true].into_iter().zip(cases.iter().cycle()) {
        let mut args = vec!["scene.toml", "--samples", count, "--method", method];
        if quiet {
            args.push("-q");
        }
        let out = sb.succeeds(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(stderr.matches("warning: ").count(), 1, "{stderr}");
        assert!(
            stderr.starts_with("warning: object 'ball': irradiance samples"),
            "{stderr}"
        );
        assert!(stderr.contains(effect), "{stderr}");
        assert!(
            stderr.contains("(blue channel of material 'm')"),
            "{stderr}"
        );
        let summary = format!("{count} samples (given: spacing");
        assert_eq!(stdout.contains(&summary), !quiet, "{stdout}");
    }
    for (count, method, effect) in cases {
        let out = sb.succeeds(&["scene.toml", "-q", "--samples", count, "--method", method]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(effect), "{stderr}");
    }
    let out = sb.succeeds(&["bake", "scene.toml", "--samples", "20", "-o", "s.ply"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        stderr.matches("warning: object 'ball'").count(),
        1,
        "{stderr}"
    );
}

/// `LUCENT_SIMD` naming no traversal path, or AVX2 on a CPU without it: exit 1, naming the
/// variable, before anything is written. Each path prints its name on the summary line, and
/// the two write the same bytes.
#[test]
fn simd_environment_variable() {
    let sb = Sandbox::new("simd-bad").with_env("LUCENT_SIMD", "sse9");
    sb.fails(
        &render(&[]),
        1,
        &["LUCENT_SIMD=\"sse9\"", "baseline, avx2 or auto"],
    );

    let run = |simd: &'static str| {
        let sb = Sandbox::new("simd-path").with_env("LUCENT_SIMD", simd);
        let out = sb.succeeds(&["scene.toml"]);
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(stdout.contains(&format!(", simd {simd} →")), "{stdout}");
        (sb.read("out.png"), sb.read("out.exr"))
    };
    let baseline = run("baseline");
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    if std::is_x86_feature_detected!("avx2") {
        assert!(baseline == run("avx2"), "the AVX2 path wrote other bytes");
    } else {
        let sb = Sandbox::new("simd-avx2").with_env("LUCENT_SIMD", "avx2");
        sb.fails(
            &render(&[]),
            1,
            &["LUCENT_SIMD=avx2", "does not support AVX2"],
        );
    }
}
