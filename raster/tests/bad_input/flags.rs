//! Command-line flags: usage errors (exit 2, printed by clap), and well-formed values that
//! are out of range, NaN or infinite (exit 1, naming the flag and the value).

use crate::harness::{Sandbox, render};

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
    sb.fails(&["compare", "out.png"], 2, &["required"]);
    sb.fails(&["presets", "extra"], 2, &["unexpected argument 'extra'"]);
}

/// `--epsilon NaN` and every other float flag given NaN or an infinity: exit 1, naming the
/// flag. (Decimals beyond f32 parse to ∞, so the message shows `inf` for `1e40`; `-inf` is
/// a usage error, read as the flags `-i -n -f`, but `--exposure -1e40` reaches the check.)
#[test]
fn nan_and_infinite_flag_values() {
    let sb = Sandbox::new("flags-nan");
    for flag in ["--epsilon", "--smoothing", "--spacing", "--exposure"] {
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
        (&["--spacing", "0"], &["--spacing 0", "positive"]),
        (&["--exposure", "65"], &["--exposure 65"]),
    ];
    for (extra, needles) in cases {
        sb.fails(&render(extra), 1, needles);
    }
}
