//! The benchmark's tables: `report.md` (per-scene tables, the ground truth's convergence, and
//! the four published claims, each with its verdict), `results.csv` (one row per
//! configuration, for plotting elsewhere) and `overhead.csv` (claim 1's interleaved rounds).

use std::fmt::Write as _;
use std::path::Path;

use super::runner::{MethodSetting, RunResult};
use super::{BenchError, BenchReport, BenchScene, SmoothingRow};
use crate::output::write_text_atomically;
use lucent_core::Method;

/// The well-known C++ implementation's CPU per lookup on the sphere (µs) and its error
/// against its own exhaustive sum (relative): the figures claim 4 compares with.
pub const REFERENCE_US_PER_LOOKUP: f64 = 26.0;
/// See [`REFERENCE_US_PER_LOOKUP`].
pub const REFERENCE_ERROR: f64 = 0.006;

fn write_file(path: &Path, text: &str) -> Result<(), BenchError> {
    Ok(write_text_atomically(path, text)?)
}

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.3}%", x * 100.0)
    } else {
        "–".to_string()
    }
}

/// The run of a scene, setting and count.
pub fn find(
    report: &BenchReport,
    scene: BenchScene,
    setting: MethodSetting,
    samples: u32,
) -> Option<&RunResult> {
    report
        .runs
        .iter()
        .find(|r| r.scene == scene && r.setting == setting && r.samples == samples)
}

fn split(report: &BenchReport, method: Method) -> MethodSetting {
    MethodSetting {
        method,
        epsilon: report.config.split_epsilon,
    }
}

/// Claim 2 at every smoothing factor k of the sweep: the band errors, their ratios, the overall
/// errors and the seed noise, then each method at the k that suits it best.
fn smoothing_sweep(report: &BenchReport, s: &mut String) {
    if report.smoothing.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "\nThe same at {} samples for several smoothing radii α = k·√Ā (`docs/physics.md` §12: k ≈ 1–3; every other run uses the scene's k, 1.5). A larger α hands more of the sum to the noise-free local term: local-global's edge hardens, edge-aware's does not; edge-refined's local term follows the light, but its 12 nodes resolve a larger disc more coarsely. Ratios are to local-global at the same k.\n\n| scene | k | edge band: local-global | edge-aware | edge-refined | ratio: edge-aware | edge-refined | overall: local-global | edge-aware | edge-refined | noise: local-global | edge-aware | edge-refined |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        report.config.sheet_count
    );
    let band = |r: &RunResult| r.edge_error.map_or(f64::NAN, |e| e.mean_relative_l1);
    let noise = |r: &RunResult| r.noise.map_or(f64::NAN, |n| n.mean_relative);
    for row in &report.smoothing {
        let (l, e, r) = (&row.local_global, &row.edge_aware, &row.edge_refined);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} | {} | {} | {} |",
            row.scene.name(),
            row.smoothing,
            pct(band(l)),
            pct(band(e)),
            pct(band(r)),
            band(e) / band(l),
            band(r) / band(l),
            pct(l.error.mean_relative_l1),
            pct(e.error.mean_relative_l1),
            pct(r.error.mean_relative_l1),
            pct(noise(l)),
            pct(noise(e)),
            pct(noise(r)),
        );
    }
    let _ = writeln!(s);
    for &scene in &report.config.scenes {
        let rows: Vec<&SmoothingRow> = report
            .smoothing
            .iter()
            .filter(|r| r.scene == scene)
            .collect();
        let best = |f: fn(&SmoothingRow) -> &RunResult| {
            rows.iter()
                .map(|r| (r.smoothing, band(f(r))))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        let met = |f: fn(&SmoothingRow) -> &RunResult| {
            let ks: Vec<String> = rows
                .iter()
                .filter(|r| band(f(r)) <= 0.5 * band(&r.local_global))
                .map(|r| r.smoothing.to_string())
                .collect();
            if ks.is_empty() {
                "at none".to_string()
            } else {
                format!("met at k = {}", ks.join(", "))
            }
        };
        if let (Some((kl, bl)), Some((ke, be)), Some((kr, br))) = (
            best(|r| &r.local_global),
            best(|r| &r.edge_aware),
            best(|r| &r.edge_refined),
        ) {
            let _ = writeln!(
                s,
                "- {}: band ratio ≤ 0.5 at the same k: edge-aware {}, edge-refined {}. Each at its best k: local-global {} (k = {kl}), edge-aware {} (k = {ke}, ratio {:.2}), edge-refined {} (k = {kr}, ratio {:.2}).",
                scene.name(),
                met(|r| &r.edge_aware),
                met(|r| &r.edge_refined),
                pct(bl),
                pct(be),
                be / bl,
                pct(br),
                br / bl
            );
        }
    }
}

/// Claim 2's errors divided into the global and the local term.
fn error_split(report: &BenchReport, s: &mut String) {
    if report.splits.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "\nWhere the error comes from, at the scene's k: each split run's error against the truth divided into its global and its local term, the truth split at the runs' own α (re-rendered at the matched k; `raster/src/bench/split.rs`). Shares of the truth's exitance, Σ|error| / Σ|truth| (not the offset-relative error above).\n\n| scene | samples | region | global term: local-global | edge-aware | edge-refined | local term: local-global | edge-aware | edge-refined | local ratio: edge-aware | edge-refined | total: local-global | edge-aware | edge-refined |\n|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for split in &report.splits {
        for (region, [l, e, r]) in [
            ("edge band", split.band),
            ("translucent", split.translucent),
        ] {
            let _ = writeln!(
                s,
                "| {} | {} | {region} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} | {} | {} | {} |",
                split.scene.name(),
                split.samples,
                pct(l.global),
                pct(e.global),
                pct(r.global),
                pct(l.local),
                pct(e.local),
                pct(r.local),
                e.local / l.local,
                r.local / l.local,
                pct(l.total),
                pct(e.total),
                pct(r.total),
            );
        }
    }
}

/// The claims, as Markdown lines with verdicts.
fn claims(report: &BenchReport) -> String {
    let c = &report.config;
    let mut s = String::new();
    let hier = split(report, Method::Hierarchical);
    let lm = split(report, Method::LocalGlobal);
    let n10 = split(report, Method::EdgeAware);

    let _ = writeln!(
        s,
        "### 1. Edge-aware overhead (same samples, ε = {})\n",
        c.split_epsilon
    );
    let _ = writeln!(
        s,
        "Shading-phase time (median of {} seeds), edge-aware against hierarchical and against local-global (which shares edge-aware's shadow rays for E(x)); target ≤ 3 % against hierarchical. The last column is the stricter measure: CPU per translucent shading point, which leaves out the opaque pixels both methods shade alike.\n",
        c.seeds.len()
    );
    let _ = writeln!(
        s,
        "| scene | samples | hierarchical | local-global | edge-aware | vs hierarchical | vs local-global | per lookup vs hierarchical |\n|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for &scene in &c.scenes {
        for &n in &c.counts {
            if let (Some(h), Some(l), Some(e)) = (
                find(report, scene, hier, n),
                find(report, scene, lm, n),
                find(report, scene, n10, n),
            ) {
                let (th, tl, te) = (
                    h.timings.shading.as_secs_f64(),
                    l.timings.shading.as_secs_f64(),
                    e.timings.shading.as_secs_f64(),
                );
                let _ = writeln!(
                    s,
                    "| {} | {n} | {:.1} ms | {:.1} ms | {:.1} ms | {:+.1}% | {:+.1}% | {:+.1}% |",
                    scene.name(),
                    th * 1e3,
                    tl * 1e3,
                    te * 1e3,
                    (te / th - 1.0) * 100.0,
                    (te / tl - 1.0) * 100.0,
                    (e.cpu_us_per_lookup() / h.cpu_us_per_lookup().max(1e-12) - 1.0) * 100.0
                );
            }
        }
    }

    overhead_table(report, &mut s);

    let n = c.sheet_count;
    let four = c.counts.iter().copied().filter(|&k| k >= 4 * n).min();
    let _ = writeln!(
        s,
        "\n### 2. Shadow edges at {n} samples\n\nTarget: edge-aware's mean relative error in the shadow-edge band at most half of local-global's; its overall error no worse than hierarchical's at ≥ 4× the samples ({}).\n",
        four.map_or("not run".to_string(), |k| format!("{k}"))
    );
    let _ = writeln!(
        s,
        "| scene | edge band: local-global | edge-aware | ratio | overall: edge-aware @ {n} | hierarchical @ 4× | verdict |\n|---|---:|---:|---:|---:|---:|---|"
    );
    for &scene in &c.scenes {
        let (Some(l), Some(e)) = (find(report, scene, lm, n), find(report, scene, n10, n)) else {
            continue;
        };
        let (le, ee) = (
            l.edge_error.map_or(f64::NAN, |x| x.mean_relative_l1),
            e.edge_error.map_or(f64::NAN, |x| x.mean_relative_l1),
        );
        let h4 = four
            .and_then(|k| find(report, scene, hier, k))
            .map_or(f64::NAN, |h| h.error.mean_relative_l1);
        let ok_edge = ee <= 0.5 * le;
        let ok_all = e.error.mean_relative_l1 <= h4;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {} | {} | {} |",
            scene.name(),
            pct(le),
            pct(ee),
            ee / le,
            pct(e.error.mean_relative_l1),
            pct(h4),
            match (ok_edge, ok_all) {
                (true, true) => "met",
                (true, false) => "edge met; overall not met",
                (false, true) => "edge not met; overall met",
                (false, false) => "not met",
            }
        );
    }

    refined_table(report, &mut s);
    smoothing_sweep(report, &mut s);
    error_split(report, &mut s);

    let _ = writeln!(s, "\n### 3. Texture-mapped ℓ_u: the power-of-two K table\n");
    match &report.table {
        Some(t) => {
            let _ = writeln!(
                s,
                "Edge-aware, {} samples. Table against K by quadrature at every shading point: mean relative {}, RMSE {:.3e}, max {:.3e} (for scale, the exact-K render against the ground truth: mean relative {}). Shading time: table {:.1} ms, quadrature {:.1} ms ({:.1}× slower).",
                t.samples,
                pct(t.error.mean_relative_l1),
                t.error.rmse,
                t.error.max_abs,
                pct(t.exact_error.mean_relative_l1),
                t.table_shading.as_secs_f64() * 1e3,
                t.exact_shading.as_secs_f64() * 1e3,
                t.exact_shading.as_secs_f64() / t.table_shading.as_secs_f64().max(1e-9)
            );
        }
        None => {
            let _ = writeln!(s, "Not run (the textured scene was not selected).");
        }
    }
    if let Some(c) = &report.texture_cost {
        let _ = writeln!(
            s,
            "\nTexture-mapped K_d and radius on the same slab, {} samples, edge-refined, one thread, {} interleaved rounds from one baked sample set: the slab's K_d and ℓ_u as constants, as uniform textures of the same values (the textured path: texture lookups, K_d inverted per point, K from the tables over K_d), and as varying textures (K_d from `kd-checker.jpg`, ℓ_u from the ramp).\n\n| material | CPU µs / lookup | against constant (median, min … max over rounds) | evaluations / lookup |\n|---|---:|---:|---:|",
            c.samples, c.rounds
        );
        let spreads = [
            None,
            Some(c.uniform_vs_constant),
            Some(c.varying_vs_constant),
        ];
        for (i, name) in super::TEXTURE_COST_VERSIONS.iter().enumerate() {
            let against = spreads[i].map_or("—".to_string(), |r| {
                format!(
                    "{:+.1}% ({:+.1} … {:+.1}%)",
                    r.median * 100.0,
                    r.min * 100.0,
                    r.max * 100.0
                )
            });
            let _ = writeln!(
                s,
                "| {name} | {:.2} | {against} | {:.1} |",
                c.lookup_us[i], c.evaluations[i]
            );
        }
        let _ = writeln!(
            s,
            "\nThe varying slab with K from the tables against K by quadrature at every shading point (exitance, translucent pixels, per channel): mean relative {:.3}%, max {:.3}%.",
            c.table_mean_relative * 100.0,
            c.table_max_relative * 100.0
        );
    }

    let _ = writeln!(
        s,
        "\n### 4. Speed\n\nHierarchical against the exhaustive sum on the same samples (sphere, one thread). The reference C++ implementation: {REFERENCE_US_PER_LOOKUP} µs of CPU per lookup at {} error; target ≥ 20× less CPU at equal or lower error. *CPU / lookup* is the time of the translucent shading points (attributes, material, query, radiance, and two clock readings); *whole shading / lookup* also charges the floor and the plate, shaded in the same phase, to the lookups.\n",
        pct(REFERENCE_ERROR)
    );
    if report.exhaustive.is_empty() {
        let _ = writeln!(s, "Not run (the sphere scene was not selected).");
    } else {
        let _ = writeln!(
            s,
            "| method | samples | error vs exhaustive | CPU µs / lookup | whole shading µs / lookup | evaluations / lookup | speed-up vs 26 µs |\n|---|---:|---:|---:|---:|---:|---:|"
        );
        for r in &report.exhaustive {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.2} | {:.2} | {:.1} | {:.1}× |",
                r.setting.label(),
                r.samples,
                pct(r.error.mean_relative_l1),
                r.cpu_us_per_lookup,
                r.shading_us_per_lookup,
                r.evaluations_per_lookup,
                REFERENCE_US_PER_LOOKUP / r.cpu_us_per_lookup.max(1e-9)
            );
        }
        let best = report
            .exhaustive
            .iter()
            .filter(|r| r.error.mean_relative_l1 <= REFERENCE_ERROR)
            .min_by(|a, b| a.cpu_us_per_lookup.total_cmp(&b.cpu_us_per_lookup));
        match best {
            Some(b) => {
                let x = REFERENCE_US_PER_LOOKUP / b.cpu_us_per_lookup.max(1e-9);
                let _ = writeln!(
                    s,
                    "\nFastest at ≤ {}: {} at {:.2} µs per lookup, **{x:.1}×** less CPU ({}).",
                    pct(REFERENCE_ERROR),
                    b.setting.label(),
                    b.cpu_us_per_lookup,
                    if x >= 20.0 { "met" } else { "not met" }
                );
            }
            None => {
                let _ = writeln!(s, "\nNo ε reached the reference error: not met.");
            }
        }
    }
    match report.end_to_end {
        Some(t) => {
            let _ = writeln!(
                s,
                "\nDefault scene at 512², everything included (load, sample, light, cache, rasterise, shade, write PNG + EXR), {} threads: **{:.3} s** ({}).",
                report.threads,
                t.as_secs_f64(),
                if t.as_secs_f64() < 1.0 {
                    "met"
                } else {
                    "not met"
                }
            );
        }
        None => {
            let _ = writeln!(s, "\nDefault scene end to end: not run (`--quick`).");
        }
    }
    s
}

/// Writes `report.md`.
pub fn write_markdown(report: &BenchReport, path: &Path) -> Result<(), BenchError> {
    let c = &report.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# lucent bench\n\n{}², sample counts {:?}, seeds {:?}, {} threads, {:.0} s in all. Errors are mean relative L1 (offset 0.01) over translucent pixels against the ground truth; *edge* is the same in the shadow-edge band; *noise* is the mean relative per-pixel standard deviation across the seeds. Times are medians over the seeds. CPU per lookup = the time of the translucent shading points, summed over threads, per lookup.\n",
        c.resolution,
        c.counts,
        c.seeds,
        report.threads,
        report.wall.as_secs_f64()
    );
    let _ = writeln!(
        s,
        "## Ground truth\n\n{}, ε = {}, cull tolerance 1e-6, {}× the largest count (why not the exhaustive sum: `raster/src/bench/mod.rs`); convergence = the half-density truth against it, to be read against the smallest error below.\n\n| scene | samples | render | translucent px | edge-band px | convergence (mean rel.) | RMSE |\n|---|---:|---:|---:|---:|---:|---:|",
        c.truth_method.name(),
        c.truth_epsilon,
        c.truth_factor
    );
    for t in &report.truths {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} s | {} | {} | {} | {:.3e} |",
            t.scene.name(),
            t.samples,
            t.time.as_secs_f64(),
            t.pixels.0,
            t.pixels.1,
            pct(t.convergence.mean_relative_l1),
            t.convergence.rmse
        );
    }
    let _ = writeln!(s, "\n## Claims\n\n{}", claims(report));
    for &scene in &c.scenes {
        let [chart, edge_chart] = super::chart_files(scene.name());
        let caption = report
            .figure_captions
            .iter()
            .find(|(s, _)| *s == scene)
            .map_or(String::new(), |(_, c)| format!("\n\n{c}"));
        let _ = writeln!(
            s,
            "\n## {0}\n\n![error against time]({chart})\n\n![error against time, shadow-edge band]({edge_chart})\n\n![figure 1]({0}-figure1.png){caption}\n\n| method | samples | total | sampling | irradiance | cache | shading | CPU µs/lookup | nodes/lookup | evals/lookup | B/sample | error | RMSE | edge | noise |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
            scene.name()
        );
        for setting in c.settings() {
            for r in report
                .runs
                .iter()
                .filter(|r| r.scene == scene && r.setting == setting)
            {
                let t = &r.timings;
                let ms = |d: std::time::Duration| format!("{:.1}", d.as_secs_f64() * 1e3);
                let _ = writeln!(
                    s,
                    "| {} | {} | {} ms | {} | {} | {} | {} | {:.2} | {:.1} | {:.1} | {:.1} | {} | {:.3e} | {} | {} |",
                    setting.label(),
                    r.placed,
                    ms(t.total),
                    ms(t.sampling),
                    ms(t.irradiance),
                    ms(t.cache),
                    ms(t.shading),
                    r.cpu_us_per_lookup(),
                    r.nodes_per_lookup(),
                    r.evaluations_per_lookup(),
                    r.cache_bytes as f64 / r.placed.max(1) as f64,
                    pct(r.error.mean_relative_l1),
                    r.error.rmse,
                    pct(r.edge_error.map_or(f64::NAN, |e| e.mean_relative_l1)),
                    pct(r.noise.map_or(f64::NAN, |n| n.mean_relative)),
                );
            }
        }
    }
    if let Some(peer) = &report.peer {
        let _ = writeln!(s, "\n{}", super::peer::markdown(peer));
    }
    write_file(path, &s)
}

/// Edge-refined (a departure from N10) against local-global and edge-aware at every count:
/// the shadow-edge band's error and the shading phase.
fn refined_table(report: &BenchReport, s: &mut String) {
    let lm = split(report, Method::LocalGlobal);
    let n10 = split(report, Method::EdgeAware);
    let refined = split(report, Method::EdgeRefined);
    let _ = writeln!(
        s,
        "\nEdge-refined (the local term integrated from shadow rays where the irradiance within α is not uniform; `core/src/refine.rs`): mean relative error in the shadow-edge band and overall, and its shading phase against edge-aware's (medians of the seeds).\n"
    );
    let _ = writeln!(
        s,
        "| scene | samples | edge band: local-global | edge-aware | edge-refined | ratio to local-global | overall: edge-aware | edge-refined | shading vs edge-aware |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for &scene in &report.config.scenes {
        for &n in &report.config.counts {
            let (Some(l), Some(e), Some(r)) = (
                find(report, scene, lm, n),
                find(report, scene, n10, n),
                find(report, scene, refined, n),
            ) else {
                continue;
            };
            let band = |x: &super::RunResult| x.edge_error.map_or(f64::NAN, |x| x.mean_relative_l1);
            let _ = writeln!(
                s,
                "| {} | {n} | {} | {} | {} | {:.2} | {} | {} | {:+.1}% |",
                scene.name(),
                pct(band(l)),
                pct(band(e)),
                pct(band(r)),
                band(r) / band(l),
                pct(e.error.mean_relative_l1),
                pct(r.error.mean_relative_l1),
                (r.timings.shading.as_secs_f64() / e.timings.shading.as_secs_f64() - 1.0) * 100.0
            );
        }
    }
}

/// Claim 1 from the interleaved rounds (`overhead.rs`), with the medians over scenes.
fn overhead_table(report: &BenchReport, s: &mut String) {
    if report.overhead.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "\nThe same claim measured on its own, robust to the machine's load: per scene and count the four methods render one baked sample set in {} interleaved rounds (the order rotating), and each round gives its own ratios; the table lists their median and range (`raster/src/bench/overhead.rs`).\n",
        report.config.overhead_rounds
    );
    let _ = writeln!(
        s,
        "| scene | samples | hierarchical | local-global | edge-aware | edge-refined | vs hierarchical | vs local-global | per lookup vs hierarchical | edge-refined vs edge-aware |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    let spread = |x: super::Spread| {
        format!(
            "{:+.1}% ({:+.1} … {:+.1})",
            x.median * 100.0,
            x.min * 100.0,
            x.max * 100.0
        )
    };
    for row in &report.overhead {
        let ms = row.shading.map(|t| t.as_secs_f64() * 1e3);
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} ms | {:.1} ms | {:.1} ms | {:.1} ms | {} | {} | {} | {} |",
            row.scene.name(),
            row.samples,
            ms[0],
            ms[1],
            ms[2],
            ms[3],
            spread(row.vs_hierarchical),
            spread(row.vs_local_global),
            spread(row.per_lookup_vs_hierarchical),
            spread(row.refined_vs_edge_aware)
        );
    }
    let _ = writeln!(
        s,
        "\n| scene | median over counts: vs hierarchical | per lookup vs hierarchical | vs local-global | edge-refined vs edge-aware |\n|---|---:|---:|---:|---:|"
    );
    for &scene in &report.config.scenes {
        let rows: Vec<_> = report
            .overhead
            .iter()
            .filter(|r| r.scene == scene)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let med = |f: fn(&super::OverheadRow) -> f64| {
            super::Spread::of(rows.iter().map(|r| f(r)).collect()).median * 100.0
        };
        let _ = writeln!(
            s,
            "| {} | {:+.1}% | {:+.1}% | {:+.1}% | {:+.1}% |",
            scene.name(),
            med(|r| r.vs_hierarchical.median),
            med(|r| r.per_lookup_vs_hierarchical.median),
            med(|r| r.vs_local_global.median),
            med(|r| r.refined_vs_edge_aware.median)
        );
    }
}

/// The header of `overhead.csv` (one row per scene and count follows).
pub const OVERHEAD_CSV_HEADER: &str = "scene,samples_requested,rounds,hierarchical_shading_s,local_global_shading_s,edge_aware_shading_s,edge_refined_shading_s,vs_hierarchical_median,vs_hierarchical_min,vs_hierarchical_max,vs_local_global_median,vs_local_global_min,vs_local_global_max,per_lookup_vs_hierarchical_median,per_lookup_vs_hierarchical_min,per_lookup_vs_hierarchical_max,refined_vs_edge_aware_median,refined_vs_edge_aware_min,refined_vs_edge_aware_max";

/// Writes `overhead.csv`: claim 1's interleaved measurement (ratios minus one).
pub fn write_overhead_csv(report: &BenchReport, path: &Path) -> Result<(), BenchError> {
    let mut s = String::new();
    let _ = writeln!(s, "{OVERHEAD_CSV_HEADER}");
    for r in &report.overhead {
        let [h, l, e, f] = r.shading.map(|t| t.as_secs_f64());
        let _ = write!(
            s,
            "{},{},{},{h},{l},{e},{f}",
            r.scene.name(),
            r.samples,
            r.rounds
        );
        for x in [
            r.vs_hierarchical,
            r.vs_local_global,
            r.per_lookup_vs_hierarchical,
            r.refined_vs_edge_aware,
        ] {
            let _ = write!(s, ",{},{},{}", x.median, x.min, x.max);
        }
        let _ = writeln!(s);
    }
    write_file(path, &s)
}

/// The CSV header (one row per configuration follows).
pub const CSV_HEADER: &str = "scene,method,epsilon,smoothing,samples_requested,samples,renders,threads,total_s,prepare_s,sampling_s,irradiance_s,cache_s,raster_s,shading_s,lookups,cpu_us_per_lookup,shading_us_per_lookup,nodes_per_lookup,evaluations_per_lookup,cache_bytes,error_mean_rel,error_rmse,error_max,edge_mean_rel,edge_rmse,noise_mean_rel,noise_rms";

/// Writes `results.csv`.
pub fn write_csv(report: &BenchReport, path: &Path) -> Result<(), BenchError> {
    let mut s = String::new();
    let _ = writeln!(s, "{CSV_HEADER}");
    let opt = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    // The sweep's rows at the scene's own k are main runs already.
    let sweep = report.smoothing.iter().flat_map(|row| {
        [&row.local_global, &row.edge_aware, &row.edge_refined]
            .into_iter()
            .filter(|r| {
                !report
                    .runs
                    .iter()
                    .any(|m| m.scene == r.scene && m.smoothing == r.smoothing)
            })
    });
    for r in report.runs.iter().chain(sweep) {
        let t = &r.timings;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:e},{:e},{:e},{},{},{},{}",
            r.scene.name(),
            r.setting.method.name(),
            r.setting.epsilon,
            r.smoothing,
            r.samples,
            r.placed,
            r.renders,
            r.threads,
            t.total.as_secs_f64(),
            t.prepare.as_secs_f64(),
            t.sampling.as_secs_f64(),
            t.irradiance.as_secs_f64(),
            t.cache.as_secs_f64(),
            t.raster.as_secs_f64(),
            t.shading.as_secs_f64(),
            r.queries,
            r.cpu_us_per_lookup(),
            r.shading_us_per_lookup(),
            r.nodes_per_lookup(),
            r.evaluations_per_lookup(),
            r.cache_bytes,
            r.error.mean_relative_l1,
            r.error.rmse,
            r.error.max_abs,
            opt(r.edge_error.map(|e| e.mean_relative_l1)),
            opt(r.edge_error.map(|e| e.rmse)),
            opt(r.noise.map(|n| n.mean_relative)),
            opt(r.noise.map(|n| n.rms)),
        );
    }
    write_file(path, &s)
}
