//! Smoke test of `lucent bench --quick`: the real binary runs the whole experiment at a small
//! size and writes a complete, consistent report.

use std::path::{Path, PathBuf};
use std::process::Command;

use lucent_raster::bench::{BenchScene, chart_files};
use lucent_raster::output::read_png;
use lucent_raster::plot::xml::check_well_formed;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lucent-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn column<'a>(header: &'a [&'a str], name: &str) -> usize {
    header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

fn check_png(path: &Path) {
    let image = read_png(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        image.width() >= 64 && image.height() >= 64,
        "{}",
        path.display()
    );
    let first = image.pixels()[0];
    assert!(
        image.pixels().iter().any(|&p| p != first),
        "{} is blank",
        path.display()
    );
}

/// An error-against-time chart: a well-formed SVG document with a line and a legend entry
/// for every method.
fn check_svg(path: &Path, labels: &[&str]) -> String {
    let svg = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        check_well_formed(&svg),
        Ok("svg".to_string()),
        "{}",
        path.display()
    );
    assert!(svg.contains("xmlns=\"http://www.w3.org/2000/svg\""));
    assert!(svg.contains("error against time"), "{}", path.display());
    for label in labels {
        let group = format!("<g class=\"series\" data-label=\"{label}\"");
        let start = svg
            .find(&group)
            .unwrap_or_else(|| panic!("{}: no series {label}", path.display()));
        let body = &svg[start..start + svg[start..].find("</g>").unwrap()];
        // Two sample counts: a line through two points.
        assert!(body.contains("<polyline"), "{}: {label}", path.display());
        assert_eq!(
            body.matches("<circle").count(),
            2,
            "{}: {label}",
            path.display()
        );
        assert!(svg.contains(&format!(">{label}</text>")), "legend {label}");
    }
    svg
}

#[test]
fn quick_bench_writes_a_complete_report() {
    let out = scratch("bench-quick");
    let status = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["bench", "--quick", "--quiet", "-o"])
        .arg(&out)
        .status()
        .expect("run lucent");
    assert!(status.success(), "lucent bench --quick failed: {status}");

    // One CSV row per scene × count × method (quick: 2 counts; hierarchical, LM07, N10,
    // edge-refined), and per scene the three split methods at the sweep's other smoothing
    // factor (k = 3).
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3 * 2 * 4 + 3 * 3, "{csv}");
    let value = |row: &[&str], name: &str| -> f64 {
        row[column(&header, name)]
            .parse()
            .unwrap_or_else(|e| panic!("{name} = '{}': {e}", row[column(&header, name)]))
    };
    for row in &rows {
        assert_eq!(row.len(), header.len());
        for name in [
            "total_s",
            "shading_s",
            "cpu_us_per_lookup",
            "shading_us_per_lookup",
            "evaluations_per_lookup",
        ] {
            assert!(value(row, name) > 0.0, "{name} in {row:?}");
        }
        // A lookup's CPU is part of the shading phase, which also shades the opaque pixels.
        assert!(
            value(row, "cpu_us_per_lookup") < value(row, "shading_us_per_lookup"),
            "{row:?}"
        );
        for name in ["error_mean_rel", "error_rmse", "noise_mean_rel"] {
            let v = value(row, name);
            assert!(v.is_finite() && v >= 0.0, "{name} = {v} in {row:?}");
        }
        // Errors against a 4× denser truth stay small at these counts.
        assert!(value(row, "error_mean_rel") < 0.5, "{row:?}");
    }
    // More samples, less error: hierarchical on the sphere at 4000 beats 1000.
    let smoothing = column(&header, "smoothing");
    let requested = column(&header, "samples_requested");
    assert_eq!(
        rows.iter().filter(|r| r[smoothing] == "3").count(),
        3 * 3,
        "{csv}"
    );
    let error_at = |scene: &str, method: &str, n: &str| {
        rows.iter()
            .find(|r| r[0] == scene && r[1] == method && r[requested] == n && r[smoothing] == "1.5")
            .map(|r| value(r, "error_mean_rel"))
            .unwrap_or_else(|| panic!("no row {scene} {method} {n}"))
    };
    for method in ["hierarchical", "edge-aware"] {
        assert!(
            error_at("sphere", method, "4000") < error_at("sphere", method, "1000"),
            "{method}: error does not fall with samples"
        );
    }

    // Claim 1's interleaved rounds: a row per scene and count, ratios inside their range.
    let overhead = std::fs::read_to_string(out.join("overhead.csv")).unwrap();
    let mut lines = overhead.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3 * 2, "{overhead}");
    for row in &rows {
        assert_eq!(row.len(), header.len());
        let value = |name: &str| -> f64 { row[column(&header, name)].parse().unwrap() };
        assert_eq!(value("rounds"), 2.0);
        for name in [
            "hierarchical_shading_s",
            "local_global_shading_s",
            "edge_aware_shading_s",
            "edge_refined_shading_s",
        ] {
            assert!(value(name) > 0.0, "{name} in {row:?}");
        }
        for ratio in [
            "vs_hierarchical",
            "vs_local_global",
            "per_lookup_vs_hierarchical",
            "refined_vs_edge_aware",
        ] {
            let (lo, mid, hi) = (
                value(&format!("{ratio}_min")),
                value(&format!("{ratio}_median")),
                value(&format!("{ratio}_max")),
            );
            assert!(lo <= mid && mid <= hi && lo > -1.0, "{ratio} in {row:?}");
        }
    }

    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    for needle in [
        "## Ground truth",
        "### 1. Edge-aware overhead",
        "interleaved rounds",
        "### 2. Shadow edges",
        "for several smoothing radii",
        "Where the error comes from",
        "### 3. Texture-mapped",
        "| uniform texture |",
        "K by quadrature at every shading point (exitance",
        "### 4. Speed",
        "## Peer comparison",
        "pbrt-v2 dipolesubsurface",
        "One against two threads",
    ] {
        assert!(report.contains(needle), "report.md lacks '{needle}'");
    }
    // The peer curves: one row per ε of the quick sweep, then the interpolated curve's one;
    // step, share queried, ε, errors, evaluations and times positive.
    let peer = std::fs::read_to_string(out.join("peer.csv")).unwrap();
    let peer_rows: Vec<&str> = peer.lines().skip(1).collect();
    assert_eq!(peer_rows.len(), 4, "{peer}");
    for (i, row) in peer_rows.iter().enumerate() {
        let cells: Vec<f64> = row.split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(cells[0], if i < 3 { 1.0 } else { 2.0 }, "{row}");
        assert!(cells[2] > 0.0 && cells[2] <= 1.0, "{row}");
        assert!(cells[3..10].iter().all(|&v| v > 0.0), "{row}");
    }
    let labels = [
        "hierarchical eps=0.5",
        "local-global",
        "edge-aware",
        "edge-refined",
    ];
    let mut charts = Vec::new();
    // `--quick` leaves the Burley sphere out (the sphere's code path with another profile).
    for scene in BenchScene::ALL
        .into_iter()
        .filter(|&s| s != BenchScene::SphereBurley)
    {
        check_png(&out.join(format!("{}-figure1.png", scene.name())));
        for file in chart_files(scene.name()) {
            assert!(
                report.contains(&format!("]({file})")),
                "report.md links {file}"
            );
            charts.push((out.join(&file), check_svg(&out.join(&file), &labels)));
        }
        assert!(
            report.contains("Columns: no smoothing"),
            "the sheet's caption"
        );
    }

    // The charts drawn again from results.csv are the same bytes.
    for (path, _) in &charts {
        std::fs::remove_file(path).unwrap();
    }
    let status = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["bench", "--replot", "--quiet", "-o"])
        .arg(&out)
        .status()
        .expect("run lucent");
    assert!(status.success(), "lucent bench --replot failed: {status}");
    for (path, svg) in &charts {
        let again = std::fs::read_to_string(path).unwrap();
        assert_eq!(&again, svg, "{}", path.display());
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bench_rejects_bad_options_with_a_message() {
    let out = scratch("bench-bad");
    for args in [
        &["bench", "--quick", "--scenes", "teapot"][..],
        &["bench", "--quick", "--counts", "5"][..],
        &["bench", "--quick", "--seeds", "0"][..],
        &["bench", "--quick", "--resolution", "3"][..],
        &["bench", "--quick", "--rounds", "0"][..],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
            .args(args)
            .arg("-o")
            .arg(&out)
            .output()
            .expect("run lucent");
        assert_eq!(o.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
    }
    assert!(!out.join("report.md").exists());
    // Nothing to draw from: the missing results.csv is named.
    let o = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["bench", "--replot", "-o"])
        .arg(&out)
        .output()
        .expect("run lucent");
    assert_eq!(o.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("results.csv"), "{stderr}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn the_peer_comparison_runs_alone() {
    let out = scratch("bench-peer");
    let status = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["bench", "--peer", "--quick", "--quiet", "-o"])
        .arg(&out)
        .status()
        .expect("run lucent");
    assert!(
        status.success(),
        "lucent bench --peer --quick failed: {status}"
    );
    let md = std::fs::read_to_string(out.join("peer.md")).unwrap();
    assert!(
        md.contains("| relRMSE | lucent µs | pbrt-v2 µs | ratio |"),
        "{md}"
    );
    assert!(out.join("peer.csv").exists());
    assert!(
        !out.join("report.md").exists(),
        "--peer writes only its own files"
    );
}

#[test]
fn the_profiles_comparison_runs_alone() {
    let out = scratch("bench-profiles");
    let status = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["bench", "--profiles", "--quick", "--quiet", "-o"])
        .arg(&out)
        .status()
        .expect("run lucent");
    assert!(
        status.success(),
        "lucent bench --profiles --quick failed: {status}"
    );
    let md = std::fs::read_to_string(out.join("profiles.md")).unwrap();
    assert!(md.contains("## classical dipole"), "{md}");
    // α′ = 0.99 in each η's totals table and every model's, η = 1.3 and 1.
    let rows = md.lines().filter(|l| l.starts_with("| 0.99 |")).count();
    assert_eq!(rows, 2 * (1 + lucent_raster::bench::MODELS.len()));
    assert!(
        md.contains("## The walk at η = 1 against Chandrasekhar"),
        "{md}"
    );
    for file in [
        "profiles.csv",
        "profile-bins.csv",
        "profile-eta1.3-pencil-0.95.svg",
    ] {
        assert!(out.join(file).exists(), "{file}");
    }
    assert!(
        !out.join("report.md").exists(),
        "--profiles writes only its own files"
    );
    let _ = std::fs::remove_dir_all(&out);
}
