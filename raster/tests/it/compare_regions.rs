//! `lucent compare` on real renders: statistics over the translucent pixels and the
//! shadow-edge band (from the reference's EXR layers) and seed noise.

use std::path::PathBuf;
use std::process::{Command, Output};

fn lucent(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .output()
        .expect("run lucent")
}

fn row<'a>(stdout: &'a str, region: &str) -> Vec<&'a str> {
    stdout
        .lines()
        .find(|l| l.starts_with(region))
        .unwrap_or_else(|| panic!("no '{region}' row in\n{stdout}"))
        .split_whitespace()
        .collect()
}

#[test]
fn compare_reports_regions_and_noise_of_sphere_renders() {
    let dir = std::env::temp_dir().join(format!("lucent-compare-regions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let exr = |seed: u32| -> PathBuf {
        let path = dir.join(format!("s{seed}.exr"));
        let o = lucent(&[
            "../scenes/sphere-shadow.toml",
            "--width",
            "96",
            "--height",
            "96",
            "--samples",
            "3000",
            "--seed",
            &seed.to_string(),
            "--quiet",
            "-o",
            dir.join(format!("s{seed}.png")).to_str().unwrap(),
            "--exr",
            path.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        path
    };
    let (a, b, c) = (exr(1), exr(2), exr(3));
    let o = lucent(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--noise-with",
        c.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();

    // The sphere covers part of the image; the band part of the sphere.
    let all: usize = row(&out, "all pixels")[2].parse().unwrap();
    let translucent: usize = row(&out, "translucent")[1].parse().unwrap();
    let band = row(&out, "shadow edge");
    let band_pixels: usize = band[3].parse().unwrap();
    assert_eq!(all, 96 * 96);
    assert!(translucent > 500 && translucent < all, "{out}");
    assert!(band_pixels > 20 && band_pixels < translucent / 2, "{out}");
    // Another seed differs only on the sphere: the error per translucent pixel is larger
    // than per pixel of the whole image.
    let rmse_all: f64 = row(&out, "all pixels")[3].parse().unwrap();
    let rmse_translucent: f64 = row(&out, "translucent")[2].parse().unwrap();
    assert!(rmse_translucent > rmse_all && rmse_all > 0.0, "{out}");
    let noise = out
        .lines()
        .find(|l| l.starts_with("seed noise over 2 renders"))
        .unwrap_or_else(|| panic!("no noise line in\n{out}"));
    assert!(
        noise.contains(&format!("{translucent} translucent pixels")),
        "{noise}"
    );

    // A PNG reference has no layers: whole-image statistics only, and it says so.
    let png = dir.join("s2.png");
    let o = lucent(&[
        "compare",
        dir.join("s1.png").to_str().unwrap(),
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("whole-image statistics only"), "{out}");

    // A noise render of another size is named in the error, and nothing is printed as noise.
    let small = dir.join("small.png");
    let o = lucent(&[
        "../scenes/sphere-shadow.toml",
        "--width",
        "48",
        "--height",
        "48",
        "--samples",
        "1000",
        "--quiet",
        "-o",
        small.to_str().unwrap(),
        "--exr",
        dir.join("small.exr").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = lucent(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--noise-with",
        small.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("small.png") && err.contains("48×48") && err.contains("96×96"),
        "{err}"
    );
    assert!(!String::from_utf8_lossy(&o.stdout).contains("seed noise"));
    let _ = std::fs::remove_dir_all(&dir);
}
