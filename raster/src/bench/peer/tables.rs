//! The peer comparison's tables: `peer.md` (and the section of the full bench's report) and
//! `peer.csv`.

use std::fmt::Write as _;

use super::{CLOCK_PAIRS, CLOCK_ROUNDS, PBRT_V2, PeerInterpolation, PeerReport, ratios};

/// ε as the tables show it (∞ for the huge value that stands for it).
fn shown_epsilon(epsilon: f32) -> String {
    if epsilon >= 1e6 {
        "∞".to_string()
    } else {
        epsilon.to_string()
    }
}

/// The Markdown section (`## Peer comparison` and its tables).
pub fn markdown(report: &PeerReport) -> String {
    let c = &report.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Peer comparison\n\nSphere, {}², one lookup per pixel (aa 1), {} samples, one thread; {} lookups per render, {} pixels in the 3 × 3-eroded mask. Error of the exitance over the mask against the exhaustive sum on the same samples: relRMSE = RMSE / mean, and the mean relative error. CPU per lookup: the clock time of the translucent points, median over {} interleaved rounds; *process CPU* is the whole render's user + system time per lookup (floor pixels and set-up included, 10 ms ticks), a bound that time spent waiting for a core does not inflate.\n\n| ε | relRMSE | mean rel. | evaluations / lookup | of which aggregates | nodes / lookup | CPU µs / lookup | process CPU µs / lookup |\n|---:|---:|---:|---:|---:|---:|---:|---:|",
        c.resolution, report.samples, report.lookups, report.pixels, c.rounds,
    );
    for r in report.rows.iter().filter(|r| r.interpolation.is_none()) {
        let _ = writeln!(
            s,
            "| {} | {:.3}% | {:.3}% | {:.1} | {:.1} | {:.1} | {:.3} | {:.3} |",
            shown_epsilon(r.epsilon),
            r.rel_rmse * 100.0,
            r.mean_relative * 100.0,
            r.evaluations,
            r.aggregates,
            r.nodes,
            r.cpu_us,
            r.process_cpu_us
        );
    }
    let _ = writeln!(
        s,
        "\npbrt-v2 dipolesubsurface, measured externally on this machine kind (one thread, the same points):\n\n| ε | relRMSE | mean rel. | Rd evaluations / lookup | CPU µs / lookup |\n|---:|---:|---:|---:|---:|"
    );
    for p in &PBRT_V2 {
        let _ = writeln!(
            s,
            "| {} | {:.3}% | {:.3}% | {:.0} | {:.1} |",
            p.epsilon,
            p.rel_rmse * 100.0,
            p.mean_relative * 100.0,
            p.evaluations,
            p.cpu_us
        );
    }
    let _ = writeln!(
        s,
        "\nCPU per lookup at equal relRMSE (log–log interpolation of each curve; *extrapolated* where the level lies outside a curve's range). lucent's time includes the two clock readings around each point, {:.1} ns per lookup on this host (measured in a loop, median of {CLOCK_ROUNDS} × {CLOCK_PAIRS} pairs); the last column leaves them out.\n",
        report.clock_us * 1e3
    );
    ratio_table(&mut s, report, None);
    interpolated(&mut s, report);
    if let [one, two] = &report.scaling[..] {
        let _ = writeln!(
            s,
            "\nOne against two threads, hierarchical ε {}, {} interleaved rounds (medians). *In-point* is the clock time around each lookup summed over threads (the CPU per lookup above); *process CPU* is the user + system time of the whole render (10 ms ticks), which a thread waiting for a core does not accrue.\n\n| threads | in-point µs / lookup | process CPU s / render | shading wall s |\n|---:|---:|---:|---:|\n| 1 | {:.3} | {:.3} | {:.3} |\n| 2 | {:.3} | {:.3} | {:.3} |\n| 2 / 1 | {:.2}× | {:.2}× | {:.2}× |",
            c.scaling_epsilon,
            c.scaling_rounds,
            one.cpu_us,
            one.process_cpu_s,
            one.shading_wall_s,
            two.cpu_us,
            two.process_cpu_s,
            two.shading_wall_s,
            two.cpu_us / one.cpu_us,
            two.process_cpu_s / one.process_cpu_s,
            two.shading_wall_s / one.shading_wall_s,
        );
    }
    s
}

/// `peer.csv`: one row per ε of each of lucent's curves (step 1: every point queried).
pub fn csv(report: &PeerReport) -> String {
    let mut s = String::from(
        "interpolation_step,interpolation_tolerance,queried_share,epsilon,rel_rmse,mean_relative,evaluations_per_lookup,aggregates_per_lookup,nodes_per_lookup,cpu_us_per_lookup,process_cpu_us_per_lookup\n",
    );
    for r in &report.rows {
        let (step, tolerance) = r.interpolation.map_or((1, 0.0), |i| (i.step, i.tolerance));
        s.push_str(&format!(
            "{step},{tolerance},{:.4},{},{:.6e},{:.6e},{:.2},{:.2},{:.2},{:.4},{:.4}\n",
            r.queried,
            r.epsilon,
            r.rel_rmse,
            r.mean_relative,
            r.evaluations,
            r.aggregates,
            r.nodes,
            r.cpu_us,
            r.process_cpu_us
        ));
    }
    s
}

/// The ratio table of one of lucent's curves against the peer's.
fn ratio_table(s: &mut String, report: &PeerReport, interpolation: Option<PeerInterpolation>) {
    let _ = writeln!(
        s,
        "| relRMSE | lucent µs | pbrt-v2 µs | ratio | ratio without the clock readings |\n|---:|---:|---:|---:|---:|"
    );
    let cell = |v: Option<(f64, bool)>, digits: usize| match v {
        Some((t, false)) => format!("{t:.digits$}"),
        Some((t, true)) => format!("{t:.digits$} (extrapolated)"),
        None => "–".to_string(),
    };
    // An interpolated curve levels off where blending's own error dominates; below that its
    // extrapolation means nothing.
    let floor = report
        .rows
        .iter()
        .filter(|r| r.interpolation == interpolation)
        .map(|r| r.rel_rmse)
        .fold(f64::INFINITY, f64::min);
    for (level, ours, theirs) in ratios(report, interpolation) {
        if level < floor {
            let _ = writeln!(
                s,
                "| {}% | not reached (lowest: {:.3}%) | {} | – | – |",
                level * 100.0,
                floor * 100.0,
                cell(theirs, 1)
            );
            continue;
        }
        let (ratio, without_clock) = match (ours, theirs) {
            (Some((a, _)), Some((b, _))) => (
                format!("**{:.1}×**", b / a),
                if a > report.clock_us {
                    format!("{:.1}×", b / (a - report.clock_us))
                } else {
                    "–".to_string()
                },
            ),
            _ => ("–".to_string(), "–".to_string()),
        };
        let _ = writeln!(
            s,
            "| {}% | {} | {} | {ratio} | {without_clock} |",
            level * 100.0,
            cell(ours, 3),
            cell(theirs, 1)
        );
    }
}

/// The curves with exitance interpolation, each with its ratio table.
fn interpolated(s: &mut String, report: &PeerReport) {
    for &i in &report.config.interpolations {
        let _ = writeln!(
            s,
            "\nWith exitance interpolation (`interpolation = {}`, `interpolation_tolerance = {}`): the cache queried at every {} pixels in x and y, the pixels between blended where their block allows it. A lookup is a pixel, queried or blended; its CPU time charges the grid's queries and the blends to the pixels. The error is still against the exhaustive sum over the same samples, so the blend's averaging of the samples' pixel-to-pixel scatter counts as error.\n\n| ε | relRMSE | mean rel. | queried | evaluations / lookup | CPU µs / lookup | process CPU µs / lookup |\n|---:|---:|---:|---:|---:|---:|---:|",
            i.step, i.tolerance, i.step
        );
        for r in report.rows.iter().filter(|r| r.interpolation == Some(i)) {
            let _ = writeln!(
                s,
                "| {} | {:.3}% | {:.3}% | {:.1}% | {:.1} | {:.3} | {:.3} |",
                shown_epsilon(r.epsilon),
                r.rel_rmse * 100.0,
                r.mean_relative * 100.0,
                r.queried * 100.0,
                r.evaluations,
                r.cpu_us,
                r.process_cpu_us
            );
        }
        let _ = writeln!(s);
        ratio_table(s, report, Some(i));
    }
}
