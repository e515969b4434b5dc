//! The peer comparison: lucent's hierarchical lookup against pbrt-v2's `dipolesubsurface`,
//! CPU per lookup against error, measured the way the external figures were.
//!
//! ```text
//! sphere scene, one sub-sample per pixel (aa 1, one lookup per pixel), one thread
//! samples   = baked once (the sphere's count), shared by every render below
//! reference = the exhaustive sum over those samples, per pixel
//! mask      = pixels with exitance in the reference, eroded by 3 × 3 (no silhouette, no
//!             pixel next to the plate's occlusion)
//! for each ε, interleaved over rounds: hierarchical → CPU per lookup (median over rounds),
//!     relRMSE = RMSE / mean and mean relative error of the exitance over the mask
//! curve: CPU per lookup against relRMSE, read at 2%, 0.6% and 0.1% by log–log interpolation
//! ```
//!
//! The peer's figures were measured outside this program, on the same kind of machine, on one
//! thread: [`PBRT_V2`].

use std::time::{Duration, Instant};

use glam::Vec3;
use lucent_core::Method;

mod tables;

pub use tables::{csv, markdown};

use super::BenchError;
use super::runner::median;
use super::scenes::BenchScene;
use crate::render::{ObjectSamples, Render, RenderOptions, bake, render};
use crate::scene::{SampleDensity, Scene};

/// One point of the peer's curve: relRMSE (fraction), mean relative error (fraction), CPU µs
/// per lookup, and its own ε and Rd evaluations per lookup.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeerPoint {
    /// ε of the peer's octree.
    pub epsilon: f32,
    /// RMSE / mean against its exhaustive sum.
    pub rel_rmse: f64,
    /// Mean relative error against its exhaustive sum.
    pub mean_relative: f64,
    /// CPU per lookup, µs.
    pub cpu_us: f64,
    /// Rd evaluations per lookup.
    pub evaluations: f64,
}

/// pbrt-v2's `dipolesubsurface`, measured externally on this machine kind: one thread, the
/// sphere's baked points, error against its own exhaustive sum.
pub const PBRT_V2: [PeerPoint; 5] = [
    PeerPoint {
        epsilon: 0.2,
        rel_rmse: 0.0126,
        mean_relative: 0.0223,
        cpu_us: 18.8,
        evaluations: 216.0,
    },
    PeerPoint {
        epsilon: 0.1,
        rel_rmse: 0.0051,
        mean_relative: 0.0111,
        cpu_us: 35.1,
        evaluations: 413.0,
    },
    PeerPoint {
        epsilon: 0.05,
        rel_rmse: 0.0021,
        mean_relative: 0.0053,
        cpu_us: 63.9,
        evaluations: 751.0,
    },
    PeerPoint {
        epsilon: 0.02,
        rel_rmse: 0.00077,
        mean_relative: 0.0018,
        cpu_us: 146.6,
        evaluations: 1736.0,
    },
    PeerPoint {
        epsilon: 0.01,
        rel_rmse: 0.00038,
        mean_relative: 0.00065,
        cpu_us: 258.3,
        evaluations: 3052.0,
    },
];

/// The relRMSE levels at which the two curves are compared.
pub const PEER_LEVELS: [f64; 3] = [0.02, 0.006, 0.001];

/// What the peer comparison runs.
#[derive(Clone, Debug, PartialEq)]
pub struct PeerConfig {
    /// Image width and height.
    pub resolution: u32,
    /// Irradiance samples asked for.
    pub samples: u32,
    /// ε values of the hierarchical sweep (the last may be huge: the fixed cost).
    pub epsilons: Vec<f32>,
    /// Interleaved rounds; CPU per lookup is the median over them.
    pub rounds: usize,
    /// Sample placement seed.
    pub seed: u64,
    /// Curves with exitance interpolation (`render.interpolation`), each at every ε of
    /// `interpolated_epsilons`: a point is a pixel, queried or blended.
    pub interpolations: Vec<PeerInterpolation>,
    /// ε values of the interpolated curves.
    pub interpolated_epsilons: Vec<f32>,
    /// ε of the one- against two-thread measurement.
    pub scaling_epsilon: f32,
    /// Interleaved rounds of it (0: skip).
    pub scaling_rounds: usize,
}

impl PeerConfig {
    /// The published measurement: 512², 18.5k samples, ε from 0.1 to 5, five rounds.
    pub fn full() -> Self {
        PeerConfig {
            resolution: 512,
            samples: 18_500,
            epsilons: vec![
                0.1, 0.15, 0.25, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 1e9,
            ],
            rounds: 5,
            seed: 1,
            interpolations: vec![
                PeerInterpolation {
                    step: 4,
                    tolerance: 0.25,
                },
                PeerInterpolation {
                    step: 2,
                    tolerance: 1e9,
                },
                PeerInterpolation {
                    step: 4,
                    tolerance: 1e9,
                },
            ],
            interpolated_epsilons: vec![0.5, 0.75, 1.0, 1.5, 3.0, 1e9],
            scaling_epsilon: 0.35,
            scaling_rounds: 7,
        }
    }

    /// A small version for `--quick` and the tests.
    pub fn quick() -> Self {
        PeerConfig {
            resolution: 96,
            samples: 2_000,
            epsilons: vec![0.25, 1.0, 4.0],
            rounds: 1,
            seed: 1,
            interpolations: vec![PeerInterpolation {
                step: 2,
                tolerance: 1e9,
            }],
            interpolated_epsilons: vec![1.0],
            scaling_epsilon: 1.0,
            scaling_rounds: 1,
        }
    }
}

/// Exitance interpolation of one of lucent's curves (`render.interpolation` and
/// `render.interpolation_tolerance`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeerInterpolation {
    /// Grid spacing, pixels.
    pub step: u32,
    /// How alike a block's corners must be.
    pub tolerance: f32,
}

/// One ε of one of lucent's curves. A *lookup* is a translucent shading point (one per pixel):
/// with interpolation, queried or blended, and its CPU time the grid's queries and the blends
/// together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeerRow {
    /// The curve's interpolation (`None`: every point queried).
    pub interpolation: Option<PeerInterpolation>,
    /// The share of the points whose exitance was queried (1 without interpolation).
    pub queried: f64,
    /// ε.
    pub epsilon: f32,
    /// RMSE / mean of the exitance over the mask, against the exhaustive sum.
    pub rel_rmse: f64,
    /// Mean relative error of the exitance over the mask.
    pub mean_relative: f64,
    /// CPU per lookup, µs (median over the rounds).
    pub cpu_us: f64,
    /// The process's CPU time for the whole render (user + system: set-up, rasterising, the
    /// floor's pixels included) per lookup, µs, median over the rounds: an upper bound of the
    /// CPU per lookup that, unlike the in-point clock, a wait for a core does not inflate.
    /// NaN where `/proc/self/stat` is unavailable.
    pub process_cpu_us: f64,
    /// Profile evaluations per lookup.
    pub evaluations: f64,
    /// Of those, node aggregates (the fourth-order term, dearer than a sample's plain Rd).
    pub aggregates: f64,
    /// Internal nodes opened (examined eight children at a time) per lookup.
    pub nodes: f64,
}

/// The outcome of the peer comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct PeerReport {
    /// What ran.
    pub config: PeerConfig,
    /// Samples placed.
    pub samples: usize,
    /// Lookups per render.
    pub lookups: u64,
    /// Pixels in the eroded mask.
    pub pixels: usize,
    /// One row per ε, in the config's order.
    pub rows: Vec<PeerRow>,
    /// The same lookups on one and on two threads.
    pub scaling: Vec<ScalingRow>,
    /// What the two clock readings around each translucent point cost on this host, µs per
    /// lookup (measured in a loop by `lucent bench --peer`); the CPU per lookup includes them.
    pub clock_us: f64,
}

/// One thread count of the scaling measurement (hierarchical at [`PeerConfig::scaling_epsilon`],
/// rounds interleaved with the other thread count).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalingRow {
    /// Worker threads.
    pub threads: usize,
    /// Median over the rounds of the in-point clock time per lookup, µs, summed over threads
    /// (what "CPU per lookup" reports; a thread that the system takes off its core in the
    /// middle of a point is charged for the wait).
    pub cpu_us: f64,
    /// Median over the rounds of the process's CPU time (user + system, from
    /// `/proc/self/stat`, 10 ms ticks) per render, seconds; NaN where unavailable.
    pub process_cpu_s: f64,
    /// Median over the rounds of the shading phase's wall time, seconds.
    pub shading_wall_s: f64,
}

/// CPU per lookup of a curve at relRMSE `level`, interpolated linearly in log–log between the
/// two points that bracket it (or extrapolated from the two nearest, then the flag is set).
/// `None` with fewer than two usable points.
pub fn cpu_at(curve: &[(f64, f64)], level: f64) -> Option<(f64, bool)> {
    let mut points: Vec<(f64, f64)> = curve
        .iter()
        .copied()
        .filter(|&(e, t)| e > 0.0 && t > 0.0 && e.is_finite() && t.is_finite())
        .map(|(e, t)| (e.ln(), t.ln()))
        .collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points.dedup_by(|a, b| a.0 == b.0);
    if points.len() < 2 {
        return None;
    }
    let x = level.ln();
    let n = points.len();
    let (i, outside) = match points.iter().position(|p| p.0 >= x) {
        Some(0) => (0, points[0].0 > x),
        Some(k) => (k - 1, false),
        None => (n - 2, true),
    };
    let ((x0, y0), (x1, y1)) = (points[i], points[i + 1]);
    let y = y0 + (y1 - y0) * (x - x0) / (x1 - x0);
    Some((y.exp(), outside))
}

/// Pixels whose whole 3 × 3 neighbourhood lies in `mask` (`width × height`, row-major).
pub fn erode(mask: &[bool], width: usize, height: usize) -> Vec<bool> {
    let mut out = vec![false; mask.len()];
    for y in 1..height.saturating_sub(1) {
        for x in 1..width.saturating_sub(1) {
            out[y * width + x] =
                (y - 1..=y + 1).all(|ny| (x - 1..=x + 1).all(|nx| mask[ny * width + nx]));
        }
    }
    out
}

/// relRMSE (RMSE / mean of the reference) and mean relative error of `test` against
/// `reference` over the masked pixels, every channel counted; channels where the reference is
/// 0 count in the RMSE, not in the relative error.
pub fn relative_errors(test: &[Vec3], reference: &[Vec3], mask: &[bool]) -> (f64, f64) {
    let (mut sq, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    let (mut rel, mut rel_n) = (0.0f64, 0usize);
    for ((a, b), _) in test
        .iter()
        .zip(reference)
        .zip(mask)
        .filter(|(_, keep)| **keep)
    {
        for c in 0..3 {
            let (a, b) = (f64::from(a[c]), f64::from(b[c]));
            let d = a - b;
            sq += d * d;
            sum += b;
            n += 1;
            if b > 0.0 {
                rel += d.abs() / b;
                rel_n += 1;
            }
        }
    }
    if n == 0 || sum <= 0.0 {
        return (f64::NAN, f64::NAN);
    }
    let mean = sum / n as f64;
    (
        (sq / n as f64).sqrt() / mean,
        if rel_n == 0 {
            f64::NAN
        } else {
            rel / rel_n as f64
        },
    )
}

fn options(baked: &[ObjectSamples]) -> RenderOptions<'_> {
    RenderOptions {
        baked: Some(baked),
        collect_stats: true,
        shade_once: true,
        ..RenderOptions::default()
    }
}

fn with_method(base: &Scene, method: Method, epsilon: f32, threads: Option<usize>) -> Scene {
    let mut scene = base.clone();
    scene.render.method = method;
    scene.render.epsilon = epsilon;
    scene.render.threads = threads;
    scene
}

fn exitance(r: &Render) -> Vec<Vec3> {
    r.pixels.iter().map(|p| p.exitance).collect()
}

/// Runs the comparison; `log` receives a line per ε.
pub fn run(config: &PeerConfig, log: &mut dyn FnMut(&str)) -> Result<PeerReport, BenchError> {
    let series: Vec<(Option<PeerInterpolation>, f32)> = config
        .epsilons
        .iter()
        .map(|&e| (None, e))
        .chain(config.interpolations.iter().flat_map(|&i| {
            config
                .interpolated_epsilons
                .iter()
                .map(move |&e| (Some(i), e))
        }))
        .collect();
    if series.iter().any(|(_, e)| !(e.is_finite() && *e > 0.0)) {
        return Err(BenchError::new("every ε must be finite and > 0"));
    }
    if config.interpolations.iter().any(|i| {
        !((2..=crate::scene::MAX_INTERPOLATION_STEP).contains(&i.step)
            && i.tolerance.is_finite()
            && i.tolerance >= 0.0)
    }) {
        return Err(BenchError::new(format!(
            "an interpolation needs a step in 2..={} and a finite tolerance ≥ 0",
            crate::scene::MAX_INTERPOLATION_STEP
        )));
    }
    if config.rounds == 0 {
        return Err(BenchError::new(
            "the peer comparison needs at least one round",
        ));
    }
    let mut base = BenchScene::Sphere.load(config.resolution)?;
    base.render.aa = 1;
    base.render.samples = SampleDensity::Count(config.samples).into();
    base.render.seed = config.seed;
    let samples = bake(&base, false)?;
    let placed: usize = samples.iter().map(ObjectSamples::len).sum();
    log(&format!(
        "peer: exhaustive sum over {placed} samples, {}²",
        config.resolution
    ));
    let exhaustive = render(
        &with_method(&base, Method::Exhaustive, 0.5, None),
        &options(&samples),
    )?;
    let reference = exitance(&exhaustive);
    let (w, h) = (config.resolution as usize, config.resolution as usize);
    let mask = erode(&crate::output::translucent_mask(&reference), w, h);
    let pixels = mask.iter().filter(|&&m| m).count();
    if pixels == 0 {
        return Err(BenchError::new(
            "the peer comparison's mask is empty (resolution too small?)",
        ));
    }
    // Rounds interleave the curves' points, so that a change of the host's load spreads over
    // all.
    let mut times: Vec<Vec<Duration>> = vec![Vec::new(); series.len()];
    let mut process: Vec<Vec<Duration>> = vec![Vec::new(); series.len()];
    let mut rows: Vec<Option<PeerRow>> = vec![None; series.len()];
    let mut lookups = 0;
    for _ in 0..config.rounds {
        for (i, &(interpolation, epsilon)) in series.iter().enumerate() {
            let mut scene = with_method(&base, Method::Hierarchical, epsilon, Some(1));
            if let Some(i) = interpolation {
                scene.render.interpolation = i.step;
                scene.render.interpolation_tolerance = i.tolerance;
            }
            let before = process_cpu();
            let r = render(&scene, &options(&samples))?;
            if let (Some(a), Some(b)) = (before, process_cpu()) {
                process[i].push(b.saturating_sub(a));
            }
            // Per point of the image, for every curve: the per-point curves (first in every
            // round) count them. With interpolation, queries + blends is a little more: a grid
            // row between two bands is queried twice, and charged to the points.
            if interpolation.is_none() || lookups == 0 {
                lookups = r.stats.queries + r.stats.interpolated;
            }
            let points = lookups;
            times[i].push(r.stats.translucent_time.unwrap_or_default());
            if rows[i].is_none() {
                let (rel_rmse, mean_relative) = relative_errors(&exitance(&r), &reference, &mask);
                let t = r.stats.traversal.unwrap_or_default();
                let per_query = |n: u64| {
                    if points == 0 {
                        0.0
                    } else {
                        n as f64 / points as f64
                    }
                };
                rows[i] = Some(PeerRow {
                    interpolation,
                    queried: per_query(r.stats.queries),
                    epsilon,
                    rel_rmse,
                    mean_relative,
                    cpu_us: 0.0,
                    process_cpu_us: f64::NAN,
                    evaluations: per_query(t.profile_evaluations()),
                    aggregates: per_query(t.aggregates),
                    nodes: per_query(t.nodes_opened),
                });
            }
        }
    }
    let rows: Vec<PeerRow> = rows
        .into_iter()
        .zip(times.into_iter().zip(process))
        .filter_map(|(row, (t, p))| {
            let mut row = row?;
            let per_lookup = |d: Duration| d.as_secs_f64() / lookups.max(1) as f64 * 1e6;
            row.cpu_us = per_lookup(median(t));
            if !p.is_empty() {
                row.process_cpu_us = per_lookup(median(p));
            }
            Some(row)
        })
        .collect();
    for r in &rows {
        let curve = match r.interpolation {
            Some(i) => format!(
                "every {} pixels (tolerance {}), {:.0}% queried, ",
                i.step,
                i.tolerance,
                r.queried * 100.0
            ),
            None => String::new(),
        };
        log(&format!(
            "peer: hierarchical {curve}ε {:<6} relRMSE {:.3}%, mean rel. {:.3}%, {:.1} evaluations ({:.1} aggregates), {:.1} nodes, {:.3} µs/lookup ({:.3} process CPU)",
            r.epsilon,
            r.rel_rmse * 100.0,
            r.mean_relative * 100.0,
            r.evaluations,
            r.aggregates,
            r.nodes,
            r.cpu_us,
            r.process_cpu_us
        ));
    }
    let scaling = scaling(config, &base, &samples, log)?;
    let clock_us = clock_pair_us(CLOCK_ROUNDS, CLOCK_PAIRS);
    log(&format!(
        "peer: the clock readings around a point: {:.1} ns per lookup",
        clock_us * 1e3
    ));
    Ok(PeerReport {
        config: config.clone(),
        samples: placed,
        lookups,
        pixels,
        rows,
        scaling,
        clock_us,
    })
}

/// Loops and reading pairs per loop of the clock measurement ([`clock_pair_us`]).
pub(super) const CLOCK_ROUNDS: usize = 5;
pub(super) const CLOCK_PAIRS: u32 = 200_000;

/// The time of the in-point clock itself: a reading before a point and the elapsed time after
/// it, as [`crate::render::ShadingStats`] takes them, with nothing in between; median over
/// `rounds` loops of `pairs` pairs, µs per pair. Measured rather than assumed, since the clock
/// source's cost varies by host (see `ShadingStats`).
fn clock_pair_us(rounds: usize, pairs: u32) -> f64 {
    let per_round: Vec<Duration> = (0..rounds.max(1))
        .map(|_| {
            let mut total = Duration::ZERO;
            let loop_start = Instant::now();
            for _ in 0..pairs {
                let start = std::hint::black_box(Instant::now());
                total += start.elapsed();
            }
            std::hint::black_box(total);
            loop_start.elapsed() / pairs.max(1)
        })
        .collect();
    median(per_round).as_secs_f64() * 1e6
}

/// CPU time of the whole process so far (user + system), from `/proc/self/stat` (Linux; its
/// ticks are 1/100 s); `None` where that file is missing or unreadable.
fn process_cpu() -> Option<Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces, in parentheses): state is 3rd,
    // utime the 14th and stime the 15th of the whole line.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<u64>().ok();
    let total = ticks(11)? + ticks(12)?;
    Some(Duration::from_millis(total * 10))
}

/// The same hierarchical render on one and two threads, in interleaved rounds.
fn scaling(
    config: &PeerConfig,
    base: &Scene,
    samples: &[ObjectSamples],
    log: &mut dyn FnMut(&str),
) -> Result<Vec<ScalingRow>, BenchError> {
    const THREADS: [usize; 2] = [1, 2];
    if config.scaling_rounds == 0 {
        return Ok(Vec::new());
    }
    let mut point = [Vec::new(), Vec::new()];
    let mut process = [Vec::new(), Vec::new()];
    let mut wall = [Vec::new(), Vec::new()];
    for _ in 0..config.scaling_rounds {
        for (i, &threads) in THREADS.iter().enumerate() {
            let scene = with_method(
                base,
                Method::Hierarchical,
                config.scaling_epsilon,
                Some(threads),
            );
            let before = process_cpu();
            let r = render(&scene, &options(samples))?;
            let after = process_cpu();
            let lookups = r.stats.queries.max(1) as f64;
            point[i].push(r.stats.translucent_time.unwrap_or_default().as_secs_f64() / lookups);
            if let (Some(a), Some(b)) = (before, after) {
                process[i].push((b - a).as_secs_f64());
            }
            wall[i].push(r.stats.timings.shading.as_secs_f64());
        }
    }
    let median = |mut v: Vec<f64>| {
        if v.is_empty() {
            return f64::NAN;
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            (v[n / 2 - 1] + v[n / 2]) / 2.0
        }
    };
    let rows: Vec<ScalingRow> = THREADS
        .iter()
        .enumerate()
        .map(|(i, &threads)| ScalingRow {
            threads,
            cpu_us: median(std::mem::take(&mut point[i])) * 1e6,
            process_cpu_s: median(std::mem::take(&mut process[i])),
            shading_wall_s: median(std::mem::take(&mut wall[i])),
        })
        .collect();
    for r in &rows {
        log(&format!(
            "peer: ε {} on {} thread(s): {:.3} µs/lookup in-point, process CPU {:.3} s per render, shading wall {:.3} s",
            config.scaling_epsilon, r.threads, r.cpu_us, r.process_cpu_s, r.shading_wall_s
        ));
    }
    Ok(rows)
}

/// A curve read at one level: CPU per lookup (µs) and whether it was extrapolated.
pub type Reading = Option<(f64, bool)>;

/// At each of [`PEER_LEVELS`]: the level, lucent's and the peer's CPU per lookup, lucent's on
/// the curve of `interpolation` (`None`: every point queried).
pub fn ratios(
    report: &PeerReport,
    interpolation: Option<PeerInterpolation>,
) -> Vec<(f64, Reading, Reading)> {
    let ours: Vec<(f64, f64)> = report
        .rows
        .iter()
        .filter(|r| r.interpolation == interpolation)
        .map(|r| (r.rel_rmse, r.cpu_us))
        .collect();
    let theirs: Vec<(f64, f64)> = PBRT_V2.iter().map(|p| (p.rel_rmse, p.cpu_us)).collect();
    PEER_LEVELS
        .iter()
        .map(|&level| (level, cpu_at(&ours, level), cpu_at(&theirs, level)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_log_interpolation_is_exact_on_a_power_law_and_flags_extrapolation() {
        // t = 2 · e^−0.5: a straight line in log–log.
        let curve: Vec<(f64, f64)> = [0.001, 0.004, 0.01, 0.03]
            .iter()
            .map(|&e: &f64| (e, 2.0 * e.powf(-0.5)))
            .collect();
        for (level, outside) in [(0.002, false), (0.01, false), (0.05, true), (0.0005, true)] {
            let (t, flag) = cpu_at(&curve, level).unwrap();
            let want = 2.0 * level.powf(-0.5);
            assert!((t / want - 1.0).abs() < 1e-12, "{level}: {t} vs {want}");
            assert_eq!(flag, outside, "{level}");
        }
        assert_eq!(cpu_at(&curve[..1], 0.01), None);
        // The peer's own curve at its measured points gives its measured times.
        let pbrt: Vec<(f64, f64)> = PBRT_V2.iter().map(|p| (p.rel_rmse, p.cpu_us)).collect();
        let (t, flag) = cpu_at(&pbrt, 0.0051).unwrap();
        assert!((t - 35.1).abs() < 1e-9 && !flag);
    }

    #[test]
    fn process_cpu_time_grows_with_work() {
        if !cfg!(target_os = "linux") {
            return;
        }
        let before = process_cpu().expect("/proc/self/stat is readable on Linux");
        // Busy work until the clock has ticked three times (10 ms each), or 5 s of wall time.
        let start = std::time::Instant::now();
        let mut x = 1.0f64;
        let mut after = before;
        while after < before + Duration::from_millis(30) && start.elapsed().as_secs() < 5 {
            for _ in 0..100_000 {
                x = std::hint::black_box(x * 1.000_000_1 + 1e-9);
            }
            after = process_cpu().unwrap();
        }
        assert!(
            after >= before + Duration::from_millis(30),
            "{before:?} → {after:?} in {:?}",
            start.elapsed()
        );
    }

    #[test]
    fn erosion_keeps_only_pixels_whose_neighbourhood_is_inside() {
        // A 5 × 4 block inside a 7 × 6 image: its 3 × 2 interior survives.
        let (w, h) = (7, 6);
        let mask: Vec<bool> = (0..w * h)
            .map(|i| (1..6).contains(&(i % w)) && (1..5).contains(&(i / w)))
            .collect();
        let eroded = erode(&mask, w, h);
        let kept: Vec<usize> = (0..w * h).filter(|&i| eroded[i]).collect();
        assert_eq!(
            kept,
            vec![
                2 * w + 2,
                2 * w + 3,
                2 * w + 4,
                3 * w + 2,
                3 * w + 3,
                3 * w + 4
            ]
        );
    }

    #[test]
    fn relative_errors_match_their_definitions() {
        let reference = [Vec3::splat(1.0), Vec3::splat(3.0), Vec3::splat(100.0)];
        let test = [Vec3::splat(1.1), Vec3::splat(2.7), Vec3::splat(0.0)];
        let (rel_rmse, mean_rel) = relative_errors(&test, &reference, &[true, true, false]);
        // Over the first two pixels: d = 0.1, −0.3; mean 2; relative 0.1 and 0.1.
        let want = ((0.01 + 0.09) / 2.0f64).sqrt() / 2.0;
        assert!((rel_rmse - want).abs() < 1e-6, "{rel_rmse} vs {want}");
        assert!((mean_rel - 0.1).abs() < 1e-6, "{mean_rel}");
    }

    /// The quick comparison runs end to end: the error falls as ε does, and ε = 0 … is not
    /// accepted.
    #[test]
    fn the_quick_comparison_orders_its_errors_by_epsilon() {
        let report = run(&PeerConfig::quick(), &mut |_| {}).unwrap();
        assert_eq!(report.rows.len(), 4);
        assert!(report.pixels > 100 && report.lookups as usize > report.pixels);
        // The interpolated curve's point: a share of the pixels queried, a lookup cheaper
        // than a query at the same ε.
        let [per_point @ .., blended] = &report.rows[..] else {
            unreachable!()
        };
        assert_eq!(blended.interpolation.map(|i| i.step), Some(2));
        assert!(per_point.iter().all(|r| r.queried == 1.0));
        assert!(
            blended.queried > 0.2 && blended.queried < 0.6,
            "{}",
            blended.queried
        );
        assert!(blended.evaluations < 0.6 * per_point[1].evaluations);
        assert!(markdown(&report).contains("With exitance interpolation (`interpolation = 2`"));
        assert_eq!(csv(&report).lines().count(), 5);
        let errors: Vec<f64> = per_point.iter().map(|r| r.rel_rmse).collect();
        assert!(errors[0] < errors[1] && errors[1] < errors[2], "{errors:?}");
        assert!(
            report
                .rows
                .iter()
                .all(|r| r.cpu_us > 0.0 && r.evaluations > 0.0)
        );
        // Coarser ε aggregates more: a larger share of the evaluations are aggregates.
        let share: Vec<f64> = report
            .rows
            .iter()
            .map(|r| r.aggregates / r.evaluations)
            .collect();
        assert!(
            share.iter().all(|s| (0.0..=1.0).contains(s)) && share[0] < share[2],
            "{share:?}"
        );
        assert!(markdown(&report).contains("pbrt-v2 dipolesubsurface"));
        assert_eq!(
            report.scaling.iter().map(|r| r.threads).collect::<Vec<_>>(),
            vec![1, 2]
        );
        assert!(report.scaling.iter().all(|r| r.cpu_us > 0.0));
        // The clock pair is measured, and is a small part of a lookup that it times.
        assert!(
            report.clock_us > 0.0 && report.rows.iter().all(|r| report.clock_us < r.cpu_us),
            "{} µs",
            report.clock_us
        );
        assert!(markdown(&report).contains("ratio without the clock readings"));
        let mut bad = PeerConfig::quick();
        bad.epsilons = vec![0.0];
        assert!(run(&bad, &mut |_| {}).is_err());
        let mut bad = PeerConfig::quick();
        bad.interpolations[0].step = 1;
        assert!(run(&bad, &mut |_| {}).is_err());
    }
}
