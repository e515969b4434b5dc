//! `lucent bench`: run time against error, the experiment of Neulander 2010's Figures 1–3.
//!
//! ```text
//! for each scene (default bunny, sphere, textured ℓ_u):
//!     ground truth  = local-global, ε_truth, truth_factor × the largest sample count
//!     convergence   = the same at half the density, compared with the truth
//!     for each sample count × method (hierarchical at each ε, local-global, edge-aware,
//!                                        edge-refined):
//!         render once per seed → median time per phase, nodes per lookup, memory,
//!         error (translucent pixels, shadow-edge band) against the truth, seed noise
//!     claim 1:  per count, the three methods at equal ε on one baked sample set, rendered
//!               in interleaved rounds (overhead.rs): medians of per-round ratios
//!     sphere:   exhaustive sum at 18.5k samples vs hierarchical at several ε (speed claim)
//!               peer comparison (peer.rs): one lookup per pixel, one thread, relRMSE against
//!               the exhaustive sum, CPU per lookup beside pbrt-v2's; one against two threads
//!     textured: the power-of-two K table against K by quadrature at every pixel;
//!               K_d and radius from textures against constants, one thread, interleaved
//!               rounds (texture_cost.rs): CPU per lookup, and K over K_d by quadrature
//!     default:  the shipped `lucent` render at 512², written to PNG + EXR, timed end to end
//! report: report.md, results.csv, overhead.csv, peer.csv, <scene>-error-vs-time.svg,
//!         <scene>-edge-error-vs-time.svg, <scene>-figure1.png
//! ```
//!
//! `lucent bench --peer` runs the peer comparison alone ([`run_peer`]); `lucent bench
//! --profiles` measures the diffusion profiles against the core's Monte Carlo random walk
//! ([`run_profiles`], `profiles.rs`).
//!
//! **Ground truth.** The natural truth is the exhaustive sum over a sample set much denser
//! than the test sets. At 16 × 100k samples that is 1.6 M profile evaluations per pixel —
//! hours on two cores — and a point sum without smoothing converges slowly anyway: each
//! pixel's value is dominated by the few samples nearest to it (Rd peaks at r = 0), so
//! doubling the density from 16k to 32k samples still changed the hierarchical truth of the
//! quick bunny by 12.8% (mean relative). The truth is therefore the local-global split
//! (LM07) at ε_truth (0.02) on the dense set, cull tolerance 1e-6: its local term integrates
//! the near-field peak analytically, E(x)·K, and its bias — E assumed constant within
//! α = k·√Ā — shrinks with the spacing (α at 1.6 M samples is a quarter of α at 100k). The
//! same doubling changed it by 2.3% at quick scale and by 0.09–0.8% at full scale, below
//! every error the report lists. The octree's own error at small ε is measured on the
//! sphere: hierarchical at ε = 0.05 is within 2e-5 of the exhaustive sum on the same
//! samples.

mod charts;
mod figures;
mod overhead;
mod peer;
mod profiles;
mod report;
mod runner;
mod scenes;
mod split;
mod texture_cost;

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use charts::{ChartPoint, chart_files, replot, write_charts};
pub use overhead::{OverheadRow, Spread};
pub use peer::{
    PBRT_V2, PEER_LEVELS, PeerConfig, PeerInterpolation, PeerPoint, PeerReport, PeerRow,
};
pub use profiles::{
    CheckRow, MODELS, ModelCurve, ModelEntry, ModelInput, ProfilesConfig, ProfilesReport,
    WalkResult,
};
pub use report::{write_csv, write_markdown, write_overhead_csv};
pub use runner::{MethodSetting, Reference, RunResult};
pub use scenes::BenchScene;
pub use split::TermErrors;
pub use texture_cost::{TextureCost, VERSIONS as TEXTURE_COST_VERSIONS};

use crate::output::{ErrorStats, OutputError, RgbImage, compare, write_exr, write_png};
use crate::plot::PlotError;
use crate::render::{RenderError, RenderOptions, render};
use crate::scene::{SceneError, default_scene};
use lucent_core::Method;

/// Why the benchmark stopped. Each variant that wraps another error returns it from
/// [`source`](std::error::Error::source); the message is the wrapped error's own, which names
/// the file or the problem already.
#[derive(Debug)]
#[non_exhaustive]
pub enum BenchError {
    /// A setting is out of range, or a run is inconsistent (the message says which).
    Invalid(String),
    /// A benchmark scene could not be built.
    Scene(SceneError),
    /// A render failed.
    Render(RenderError),
    /// Writing or comparing images failed.
    Output(OutputError),
    /// Drawing a contact sheet or a chart failed.
    Plot(PlotError),
    /// The report folder could not be created.
    CreateDir {
        /// The folder.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A file of an earlier report could not be read.
    Read {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A `results.csv` to draw charts from is malformed.
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

impl BenchError {
    /// An [`Invalid`](BenchError::Invalid) error with a message.
    pub fn new(message: impl Into<String>) -> Self {
        BenchError::Invalid(message.into())
    }
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BenchError::Invalid(m) => f.write_str(m),
            BenchError::Scene(e) => e.fmt(f),
            BenchError::Render(e) => e.fmt(f),
            BenchError::Output(e) => e.fmt(f),
            BenchError::Plot(e) => e.fmt(f),
            BenchError::CreateDir { path, source } => {
                write!(f, "{}: cannot create: {source}", path.display())
            }
            BenchError::Read { path, source } => write!(f, "{}: {source}", path.display()),
            BenchError::Csv {
                path,
                line,
                message,
            } => write!(f, "{} line {line}: {message}", path.display()),
        }
    }
}

impl std::error::Error for BenchError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            BenchError::Invalid(_) | BenchError::Csv { .. } => None,
            BenchError::Scene(e) => Some(e),
            BenchError::Render(e) => Some(e),
            BenchError::Output(e) => Some(e),
            BenchError::Plot(e) => Some(e),
            BenchError::CreateDir { source, .. } | BenchError::Read { source, .. } => Some(source),
        }
    }
}

// Every step's error becomes a `BenchError` that keeps it.
impl From<OutputError> for BenchError {
    fn from(e: OutputError) -> Self {
        BenchError::Output(e)
    }
}
impl From<PlotError> for BenchError {
    fn from(e: PlotError) -> Self {
        BenchError::Plot(e)
    }
}
impl From<SceneError> for BenchError {
    fn from(e: SceneError) -> Self {
        BenchError::Scene(e)
    }
}
impl From<RenderError> for BenchError {
    fn from(e: RenderError) -> Self {
        BenchError::Render(e)
    }
}

/// What the benchmark runs.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchConfig {
    /// Image width and height.
    pub resolution: u32,
    /// Sample counts.
    pub counts: Vec<u32>,
    /// ε values for the hierarchical method.
    pub epsilons: Vec<f32>,
    /// ε of the split methods' global sum.
    pub split_epsilon: f32,
    /// Seeds: the first gives the error, all of them the noise.
    pub seeds: Vec<u64>,
    /// Ground-truth density as a multiple of the largest count.
    pub truth_factor: u32,
    /// The ground truth's method (see the module doc).
    pub truth_method: Method,
    /// ε of the ground truth's octree sum.
    pub truth_epsilon: f32,
    /// The count of the contact sheets and claims (the talk's 23k).
    pub sheet_count: u32,
    /// Smoothing factors k (α = k·√Ā) at which local-global and edge-aware are compared at
    /// the sheet count (claim 2); the scene's own k is the one every other run uses.
    pub smoothings: Vec<f32>,
    /// Interleaved rounds of the claim-1 overhead measurement per scene and count (0: skip).
    pub overhead_rounds: usize,
    /// Samples of the exhaustive-sum comparison on the sphere.
    pub exhaustive_count: u32,
    /// ε values compared with the exhaustive sum.
    pub exhaustive_epsilons: Vec<f32>,
    /// Time the default scene end to end (the shipped render, 512², PNG + EXR).
    pub end_to_end: bool,
    /// Scenes to run.
    pub scenes: Vec<BenchScene>,
    /// Worker threads (`None` = all cores).
    pub threads: Option<usize>,
    /// The peer comparison (run with the sphere scene; `None` = skip).
    pub peer: Option<PeerConfig>,
}

impl BenchConfig {
    /// The full experiment (5–9 minutes on two cores, with the host's load).
    pub fn full() -> Self {
        BenchConfig {
            resolution: 512,
            counts: vec![2_000, 5_000, 10_000, 23_000, 50_000, 100_000],
            epsilons: vec![0.05, 0.5, 2.0],
            split_epsilon: 0.5,
            seeds: vec![1, 2, 3],
            truth_factor: 16,
            truth_method: Method::LocalGlobal,
            truth_epsilon: 0.02,
            sheet_count: 23_000,
            smoothings: vec![1.0, 1.5, 2.0, 3.0],
            overhead_rounds: 5,
            exhaustive_count: 18_500,
            exhaustive_epsilons: vec![0.05, 0.25, 0.5, 0.75, 1.0, 2.0],
            end_to_end: true,
            scenes: BenchScene::ALL.to_vec(),
            threads: None,
            peer: Some(PeerConfig::full()),
        }
    }

    /// A small version that exercises every step in well under a minute (`--quick`).
    pub fn quick() -> Self {
        BenchConfig {
            resolution: 64,
            counts: vec![1_000, 4_000],
            epsilons: vec![0.5],
            split_epsilon: 0.5,
            seeds: vec![1, 2],
            truth_factor: 4,
            truth_method: Method::LocalGlobal,
            truth_epsilon: 0.05,
            sheet_count: 4_000,
            smoothings: vec![1.5, 3.0],
            overhead_rounds: 2,
            exhaustive_count: 1_000,
            exhaustive_epsilons: vec![0.05, 0.5],
            end_to_end: false,
            // The Burley sphere takes the sphere's code path with another profile; `--scenes
            // sphere-burley` runs it.
            scenes: BenchScene::ALL
                .into_iter()
                .filter(|&s| s != BenchScene::SphereBurley)
                .collect(),
            threads: None,
            peer: Some(PeerConfig::quick()),
        }
    }

    /// The methods run at every count.
    pub fn settings(&self) -> Vec<MethodSetting> {
        let mut s: Vec<MethodSetting> = self
            .epsilons
            .iter()
            .map(|&epsilon| MethodSetting {
                method: Method::Hierarchical,
                epsilon,
            })
            .collect();
        for method in Method::ALL.into_iter().filter(|m| m.is_split()) {
            s.push(MethodSetting {
                method,
                epsilon: self.split_epsilon,
            });
        }
        s
    }

    /// Checks the values (each a clear error, no panic later).
    pub fn validate(&self) -> Result<(), BenchError> {
        let bad = |m: &str| Err(BenchError::new(m.to_string()));
        if !(16..=4096).contains(&self.resolution) {
            return bad("resolution must be in 16..=4096");
        }
        if self.counts.is_empty() || self.counts.iter().any(|&c| !(100..=4_000_000).contains(&c)) {
            return bad("sample counts must be in 100..=4000000");
        }
        if !self.counts.contains(&self.sheet_count) {
            return bad("the sheet count must be one of the sample counts");
        }
        if self.seeds.is_empty() {
            return bad("at least one seed is needed");
        }
        let eps = self
            .epsilons
            .iter()
            .chain(&self.exhaustive_epsilons)
            .chain([&self.split_epsilon, &self.truth_epsilon]);
        if eps.clone().any(|e| !(e.is_finite() && *e > 0.0)) {
            return bad("every ε must be finite and > 0");
        }
        if self
            .smoothings
            .iter()
            .any(|k| !(k.is_finite() && *k > 0.0 && *k <= 16.0))
        {
            return bad("every smoothing factor k must be in (0, 16]");
        }
        if self.overhead_rounds > 100 {
            return bad("overhead rounds must be at most 100");
        }
        if self.truth_factor < 2 {
            return bad("the truth factor must be at least 2 (the convergence check halves it)");
        }
        if self.threads == Some(0) {
            return bad("threads must be at least 1");
        }
        if self.scenes.is_empty() {
            return bad("no scene selected");
        }
        Ok(())
    }

    /// The ground truth's sample count.
    pub fn truth_count(&self) -> u32 {
        let max = self.counts.iter().copied().max().unwrap_or(0);
        max.saturating_mul(self.truth_factor)
    }
}

/// A scene's ground truth and how well it has converged.
#[derive(Clone, Debug)]
pub struct TruthInfo {
    /// The scene.
    pub scene: BenchScene,
    /// Samples placed.
    pub samples: usize,
    /// Its render time.
    pub time: Duration,
    /// The half-density truth against the truth, over translucent pixels.
    pub convergence: ErrorStats,
    /// Translucent pixels and shadow-edge band pixels.
    pub pixels: (usize, usize),
}

/// One row of the exhaustive comparison on the sphere.
#[derive(Clone, Debug)]
pub struct ExhaustiveRow {
    /// The method (hierarchical at some ε, or exhaustive itself).
    pub setting: MethodSetting,
    /// Samples placed.
    pub samples: usize,
    /// Against the exhaustive sum on the same samples, translucent pixels.
    pub error: ErrorStats,
    /// CPU per translucent shading point, µs (see [`RunResult::cpu_us_per_lookup`]).
    pub cpu_us_per_lookup: f64,
    /// The whole shading phase (opaque pixels too) per lookup, µs.
    pub shading_us_per_lookup: f64,
    /// Profile evaluations per lookup.
    pub evaluations_per_lookup: f64,
}

/// The split methods at one smoothing factor, at the sheet count (claim 2).
#[derive(Clone, Debug)]
pub struct SmoothingRow {
    /// The scene.
    pub scene: BenchScene,
    /// k in α = k·√Ā.
    pub smoothing: f32,
    /// Local-global's run.
    pub local_global: RunResult,
    /// Edge-aware's run.
    pub edge_aware: RunResult,
    /// Edge-refined's run.
    pub edge_refined: RunResult,
}

/// The split methods' errors at the sheet count split into the global and the local term (see
/// the `split` module), per region.
#[derive(Clone, Debug)]
pub struct ErrorSplit {
    /// The scene.
    pub scene: BenchScene,
    /// Samples of the split runs.
    pub samples: usize,
    /// The smoothing factor the truth was re-rendered with to match their α.
    pub truth_smoothing: f32,
    /// Shadow-edge band: local-global, edge-aware, edge-refined.
    pub band: [TermErrors; 3],
    /// Translucent pixels: local-global, edge-aware, edge-refined.
    pub translucent: [TermErrors; 3],
}

/// The K table against exact K per pixel (textured scene, edge-aware).
#[derive(Clone, Debug)]
pub struct TableCheck {
    /// Samples.
    pub samples: usize,
    /// The table render against the exact-K render, translucent pixels.
    pub error: ErrorStats,
    /// The exact-K render against the ground truth (for scale).
    pub exact_error: ErrorStats,
    /// Shading time with the table.
    pub table_shading: Duration,
    /// Shading time with K by quadrature at every point.
    pub exact_shading: Duration,
}

/// Everything measured.
#[derive(Clone, Debug)]
pub struct BenchReport {
    /// What ran.
    pub config: BenchConfig,
    /// Per scene.
    pub truths: Vec<TruthInfo>,
    /// Every configuration.
    pub runs: Vec<RunResult>,
    /// The sphere's exhaustive comparison.
    pub exhaustive: Vec<ExhaustiveRow>,
    /// Local-global and edge-aware at several smoothing factors, per scene.
    pub smoothing: Vec<SmoothingRow>,
    /// Their errors split into the two terms, per scene.
    pub splits: Vec<ErrorSplit>,
    /// Claim 1 by interleaved rounds, per scene and count.
    pub overhead: Vec<OverheadRow>,
    /// The textured scene's table check.
    pub table: Option<TableCheck>,
    /// Texture-mapped K_d and radius against constants on the textured slab.
    pub texture_cost: Option<TextureCost>,
    /// The default scene end to end (render + PNG + EXR).
    pub end_to_end: Option<Duration>,
    /// The peer comparison on the sphere, if run.
    pub peer: Option<PeerReport>,
    /// Per scene, the caption of its contact sheet (what its rows and columns show).
    pub figure_captions: Vec<(BenchScene, String)>,
    /// Worker threads.
    pub threads: usize,
    /// Wall time of the whole benchmark.
    pub wall: Duration,
}

/// Runs the benchmark, writing the report into `out` (created if needed); `log` receives a
/// line per step.
pub fn run(
    config: &BenchConfig,
    out: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<BenchReport, BenchError> {
    config.validate()?;
    let start = Instant::now();
    std::fs::create_dir_all(out).map_err(|source| BenchError::CreateDir {
        path: out.to_path_buf(),
        source,
    })?;
    let mut report = BenchReport {
        config: config.clone(),
        truths: Vec::new(),
        runs: Vec::new(),
        exhaustive: Vec::new(),
        smoothing: Vec::new(),
        splits: Vec::new(),
        overhead: Vec::new(),
        table: None,
        texture_cost: None,
        end_to_end: None,
        peer: None,
        figure_captions: Vec::new(),
        threads: 0,
        wall: Duration::ZERO,
    };
    for &scene in &config.scenes {
        run_scene(config, scene, out, &mut report, log)?;
    }
    if config.end_to_end && config.scenes.contains(&BenchScene::Default) {
        report.end_to_end = Some(end_to_end(out, config.threads)?);
        log(&format!(
            "default scene end to end (render + PNG + EXR): {:.3} s",
            report.end_to_end.unwrap_or_default().as_secs_f64()
        ));
    }
    report.wall = start.elapsed();
    write_markdown(&report, &out.join("report.md"))?;
    write_csv(&report, &out.join("results.csv"))?;
    write_overhead_csv(&report, &out.join("overhead.csv"))?;
    if let Some(peer) = &report.peer {
        crate::output::write_text_atomically(&out.join("peer.csv"), &peer::csv(peer))?;
    }
    log(&format!(
        "report: {} ({:.0} s)",
        out.join("report.md").display(),
        report.wall.as_secs_f64()
    ));
    Ok(report)
}

fn run_scene(
    config: &BenchConfig,
    scene: BenchScene,
    out: &Path,
    report: &mut BenchReport,
    log: &mut dyn FnMut(&str),
) -> Result<(), BenchError> {
    let name = scene.name();
    let mut base = scene.load(config.resolution)?;
    base.render.threads = config.threads;
    let mut truth_scene = base.clone();
    truth_scene.render.cull_tolerance = truth_scene.render.cull_tolerance.min(1e-6);
    let truth_setting = MethodSetting {
        method: config.truth_method,
        epsilon: config.truth_epsilon,
    };
    let n = config.truth_count();
    log(&format!("{name}: ground truth, {n} samples"));
    // The truth's samples are placed and lit once: the error split renders them again.
    let start = Instant::now();
    let truth_run = runner::configure(&truth_scene, truth_setting, n, 1000);
    let truth_samples = crate::render::bake(&truth_run, false)?;
    let placing = start.elapsed();
    let truth = runner::render_once(&truth_run, true, Some(&truth_samples))?;
    let mut reference = Reference::new(truth)?;
    reference.time += placing;
    log(&format!("{name}: convergence check, {} samples", n / 2));
    let half = runner::render_once(
        &runner::configure(&truth_scene, truth_setting, n / 2, 1001),
        false,
        None,
    )?;
    let convergence = compare(&half.image, &reference.image, Some(&reference.translucent))?;
    report.truths.push(TruthInfo {
        scene,
        samples: reference.samples,
        time: reference.time,
        convergence,
        pixels: (
            reference.translucent.iter().filter(|&&b| b).count(),
            reference.band.iter().filter(|&&b| b).count(),
        ),
    });

    let mut sheet_images = Vec::new();
    let mut split_runs = Vec::new();
    for &count in &config.counts {
        for setting in config.settings() {
            let (result, first) =
                runner::run_config(&base, scene, setting, count, &config.seeds, &reference)?;
            log(&format!(
                "{name}: {:>7} samples, {:<20} {:>8.3} s, {:>6.2} µs/lookup, error {:.3e}, edge {:.3e}",
                count,
                setting.label(),
                result.timings.total.as_secs_f64(),
                result.cpu_us_per_lookup(),
                result.error.mean_relative_l1,
                result.edge_error.map_or(f64::NAN, |e| e.mean_relative_l1)
            ));
            report.threads = result.threads;
            if count == config.sheet_count {
                // The error split compares the split methods.
                if setting.method.is_split() {
                    split_runs.push((first.stats.samples, first.pixels));
                }
                sheet_images.push((setting, first.image));
            }
            report.runs.push(result);
        }
    }
    if config.overhead_rounds > 0 {
        for &count in &config.counts {
            let row = overhead::measure(
                &base,
                scene,
                count,
                config.split_epsilon,
                config.overhead_rounds,
                config.seeds[0],
            )?;
            log(&format!(
                "{name}: {count:>7} samples, overhead over {} interleaved rounds: edge-aware {:+.1}% vs hierarchical, {:+.1}% vs local-global",
                row.rounds,
                row.vs_hierarchical.median * 100.0,
                row.vs_local_global.median * 100.0
            ));
            report.overhead.push(row);
        }
    }
    let sweep = smoothing_sweep(config, scene, &base, report, &reference, log)?;
    report.smoothing.extend(sweep);
    if let [(samples, lm), (_, n10), (_, refined)] = &split_runs[..] {
        let mut matched = truth_run.clone();
        matched.render.smoothing =
            split::matched_smoothing(base.render.smoothing, reference.samples, *samples);
        log(&format!(
            "{name}: the truth again at k = {} (the α of {samples} samples), for the error split",
            matched.render.smoothing
        ));
        let exact = runner::render_once(&matched, false, Some(&truth_samples))?;
        let exact_global: Vec<glam::Vec3> = exact.pixels.iter().map(|p| p.global).collect();
        let errors = |mask: &[bool]| {
            [lm, n10, refined]
                .map(|run| split::term_errors(&reference.exitance, &exact_global, run, mask))
        };
        report.splits.push(ErrorSplit {
            scene,
            samples: *samples,
            truth_smoothing: matched.render.smoothing,
            band: errors(&reference.band),
            translucent: errors(&reference.translucent),
        });
    }
    if let Some(caption) = figures::write_scene_figures(
        config,
        scene,
        report,
        &reference,
        &sheet_images,
        base.render.exposure,
        out,
    )? {
        report.figure_captions.push((scene, caption));
    }

    match scene {
        BenchScene::Textured => {
            report.table = Some(table_check(
                config,
                &base,
                report,
                &sheet_images,
                &reference,
                log,
            )?);
            if config.overhead_rounds > 0 {
                log(&format!(
                    "textured: K_d and radius from textures against constants, {} rounds",
                    config.overhead_rounds
                ));
                let setting = MethodSetting {
                    method: Method::EdgeRefined,
                    epsilon: config.split_epsilon,
                };
                let cost = texture_cost::measure(
                    &base,
                    setting,
                    config.sheet_count,
                    config.seeds[0],
                    config.overhead_rounds,
                )?;
                log(&format!(
                    "textured: CPU per lookup {:.2} / {:.2} / {:.2} µs (constant / uniform / varying texture), K table vs quadrature {:.3}% mean, {:.3}% max",
                    cost.lookup_us[0],
                    cost.lookup_us[1],
                    cost.lookup_us[2],
                    cost.table_mean_relative * 100.0,
                    cost.table_max_relative * 100.0
                ));
                report.texture_cost = Some(cost);
            }
        }
        BenchScene::Sphere => {
            report.exhaustive = exhaustive_check(config, &base, log)?;
            if let Some(peer) = &config.peer {
                report.peer = Some(peer::run(peer, log)?);
            }
        }
        BenchScene::Default | BenchScene::SphereBurley => {}
    }
    Ok(())
}

/// The split methods at the sheet count for every smoothing factor of the config (claim 2). At
/// the scene's own k the main runs are reused.
///
/// Why a sweep: at k = 1.5 the two differ little in the shadow-edge band, because most of the
/// band's error there is the global sum's, which both share (the `split` step: on the
/// sphere at 23k the global term errs by 2.1% of the band's exitance, the local term by 1.6%
/// for local-global and 0.8% for edge-aware). A larger α moves work from
/// the noisy global sum to the local term: local-global's edge then hardens (N10's Figure 1
/// and `docs/physics.md` §12), edge-aware's does not.
fn smoothing_sweep(
    config: &BenchConfig,
    scene: BenchScene,
    base: &crate::scene::Scene,
    report: &BenchReport,
    reference: &Reference,
    log: &mut dyn FnMut(&str),
) -> Result<Vec<SmoothingRow>, BenchError> {
    let n = config.sheet_count;
    let setting = |method| MethodSetting {
        method,
        epsilon: config.split_epsilon,
    };
    let (lm, n10, refined) = (
        setting(Method::LocalGlobal),
        setting(Method::EdgeAware),
        setting(Method::EdgeRefined),
    );
    let mut rows = Vec::new();
    for &k in &config.smoothings {
        let (local_global, edge_aware, edge_refined) = if k == base.render.smoothing {
            match (
                report::find(report, scene, lm, n),
                report::find(report, scene, n10, n),
                report::find(report, scene, refined, n),
            ) {
                (Some(l), Some(e), Some(r)) => (l.clone(), e.clone(), r.clone()),
                _ => {
                    return Err(BenchError::new(
                        "internal: the split runs at the sheet count are missing",
                    ));
                }
            }
        } else {
            let mut with_k = base.clone();
            with_k.render.smoothing = k;
            let run = |s| -> Result<RunResult, BenchError> {
                Ok(runner::run_config(&with_k, scene, s, n, &config.seeds, reference)?.0)
            };
            (run(lm)?, run(n10)?, run(refined)?)
        };
        log(&format!(
            "{}: {n} samples, k = {k}: edge band local-global {:.3e}, edge-aware {:.3e}, edge-refined {:.3e}",
            scene.name(),
            local_global
                .edge_error
                .map_or(f64::NAN, |e| e.mean_relative_l1),
            edge_aware
                .edge_error
                .map_or(f64::NAN, |e| e.mean_relative_l1),
            edge_refined
                .edge_error
                .map_or(f64::NAN, |e| e.mean_relative_l1),
        ));
        rows.push(SmoothingRow {
            scene,
            smoothing: k,
            local_global,
            edge_aware,
            edge_refined,
        });
    }
    Ok(rows)
}

/// Edge-aware with K from the table against K by quadrature at every shading point. The table
/// side is the main run at the sheet count (its first seed's image, its median shading time):
/// only the quadrature render is new.
fn table_check(
    config: &BenchConfig,
    base: &crate::scene::Scene,
    report: &BenchReport,
    sheet_images: &[(MethodSetting, RgbImage)],
    reference: &Reference,
    log: &mut dyn FnMut(&str),
) -> Result<TableCheck, BenchError> {
    let setting = MethodSetting {
        method: Method::EdgeAware,
        epsilon: config.split_epsilon,
    };
    let run = report::find(report, BenchScene::Textured, setting, config.sheet_count);
    let image = sheet_images.iter().find(|(s, _)| *s == setting);
    let (Some(run), Some((_, table_image))) = (run, image) else {
        return Err(BenchError::new(
            "internal: the edge-aware run at the sheet count is missing",
        ));
    };
    log(&format!(
        "textured: K table vs K by quadrature, {} samples",
        config.sheet_count
    ));
    let scene = runner::configure(base, setting, config.sheet_count, config.seeds[0]);
    let options = RenderOptions {
        collect_stats: true,
        exact_local_integral: true,
        ..RenderOptions::default()
    };
    let exact = render(&scene, &options)?;
    let error = compare(table_image, &exact.image, Some(&reference.translucent))?;
    let exact_error = compare(&exact.image, &reference.image, Some(&reference.translucent))?;
    Ok(TableCheck {
        samples: run.placed,
        error,
        exact_error,
        table_shading: run.timings.shading,
        exact_shading: exact.stats.timings.shading,
    })
}

/// Hierarchical at several ε against the exhaustive sum on the same samples (the sphere).
fn exhaustive_check(
    config: &BenchConfig,
    base: &crate::scene::Scene,
    log: &mut dyn FnMut(&str),
) -> Result<Vec<ExhaustiveRow>, BenchError> {
    let n = config.exhaustive_count;
    let seed = config.seeds[0];
    log(&format!("sphere: exhaustive sum, {n} samples"));
    let exhaustive_setting = MethodSetting {
        method: Method::Exhaustive,
        epsilon: config.split_epsilon,
    };
    let exhaustive = runner::render_once(
        &runner::configure(base, exhaustive_setting, n, seed),
        true,
        None,
    )?;
    let reference = Reference::new(exhaustive)?;
    // CPU per lookup is measured on one thread: two threads on this machine's two (shared)
    // cores do not scale perfectly, and the reference figure is CPU time per lookup.
    let mut single = base.clone();
    single.render.threads = Some(1);
    let mut rows = Vec::new();
    for &epsilon in &config.exhaustive_epsilons {
        let setting = MethodSetting {
            method: Method::Hierarchical,
            epsilon,
        };
        let (r, _) =
            runner::run_config(&single, BenchScene::Sphere, setting, n, &[seed], &reference)?;
        log(&format!(
            "sphere: {n} samples, {:<20} {:>6.2} µs/lookup, {:.1} evaluations/lookup, error vs exhaustive {:.3e}",
            setting.label(),
            r.cpu_us_per_lookup(),
            r.evaluations_per_lookup(),
            r.error.mean_relative_l1
        ));
        rows.push(ExhaustiveRow {
            setting,
            samples: r.placed,
            error: r.error,
            cpu_us_per_lookup: r.cpu_us_per_lookup(),
            shading_us_per_lookup: r.shading_us_per_lookup(),
            evaluations_per_lookup: r.evaluations_per_lookup(),
        });
    }
    Ok(rows)
}

/// Runs the peer comparison alone (`lucent bench --peer`), writing `peer.md` and `peer.csv`
/// into `out` (created if needed).
pub fn run_peer(
    config: &PeerConfig,
    out: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<PeerReport, BenchError> {
    std::fs::create_dir_all(out).map_err(|source| BenchError::CreateDir {
        path: out.to_path_buf(),
        source,
    })?;
    let report = peer::run(config, log)?;
    let md = format!("# lucent bench --peer\n\n{}", peer::markdown(&report));
    crate::output::write_text_atomically(&out.join("peer.md"), &md)?;
    crate::output::write_text_atomically(&out.join("peer.csv"), &peer::csv(&report))?;
    log(&format!("report: {}", out.join("peer.md").display()));
    Ok(report)
}

/// Runs the diffusion profiles against the Monte Carlo random walk alone (`lucent bench
/// --profiles`), writing `profiles.md`, `profiles.csv`, `profile-bins.csv` and the profile
/// charts into `out` (created if needed).
pub fn run_profiles(
    config: &ProfilesConfig,
    out: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<ProfilesReport, BenchError> {
    std::fs::create_dir_all(out).map_err(|source| BenchError::CreateDir {
        path: out.to_path_buf(),
        source,
    })?;
    let report = profiles::run(config, log)?;
    crate::output::write_text_atomically(&out.join("profiles.md"), &profiles::markdown(&report))?;
    crate::output::write_text_atomically(&out.join("profiles.csv"), &profiles::csv(&report))?;
    crate::output::write_text_atomically(
        &out.join("profile-bins.csv"),
        &profiles::bins_csv(&report),
    )?;
    profiles::write_plots(&report, out)?;
    log(&format!("report: {}", out.join("profiles.md").display()));
    Ok(report)
}

/// The shipped default render, timed from loading the scene to the renamed output files.
fn end_to_end(out: &Path, threads: Option<usize>) -> Result<Duration, BenchError> {
    let dir: PathBuf = out.join("default-scene");
    std::fs::create_dir_all(&dir).map_err(|source| BenchError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })?;
    let start = Instant::now();
    let mut scene = default_scene();
    scene.render.threads = threads;
    let options = RenderOptions::default();
    let r = render(&scene, &options)?;
    write_png(&dir.join("lucent.png"), &r.image, scene.render.exposure)?;
    write_exr(
        &dir.join("lucent.exr"),
        &r.image,
        Some(&r.alpha()),
        &r.layers(&scene.output.layers),
    )?;
    Ok(start.elapsed())
}

#[cfg(test)]
mod tests {
    use std::error::Error as _;

    use super::*;

    #[test]
    fn errors_keep_their_source_and_message() {
        let dir = Path::new("/nonexistent/lucent-bench");
        let e = replot(dir).unwrap_err();
        assert!(matches!(e, BenchError::Read { .. }), "{e:?}");
        assert!(e.to_string().contains("results.csv"), "{e}");
        let io = e.source().and_then(|s| s.downcast_ref::<std::io::Error>());
        assert_eq!(io.map(|e| e.kind()), Some(std::io::ErrorKind::NotFound));

        let render = RenderError::Limit("too many triangles".into());
        let e = BenchError::from(render);
        assert_eq!(e.to_string(), "too many triangles");
        assert!(
            e.source()
                .and_then(|s| s.downcast_ref::<RenderError>())
                .is_some()
        );
        assert!(BenchError::new("bad").source().is_none());
    }

    #[test]
    fn replot_rejects_a_malformed_table_by_line() {
        let dir = std::env::temp_dir().join(format!("lucent-replot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let header = "scene,method,epsilon,smoothing,total_s,error_mean_rel,edge_mean_rel";
        for (body, needle) in [
            ("scene,method\n", "no column 'epsilon'"),
            (
                &*format!("{header}\nsphere,edge-aware,0.5,1.5,x,0.1,\n"),
                "line 2: 'x' is not a number",
            ),
            (
                &*format!("{header}\nsphere,edge-aware,0.5\n"),
                "line 2: 3 cells",
            ),
            (
                &*format!("{header}\n../x,edge-aware,0.5,1.5,1,0.1,\n"),
                "not a scene name",
            ),
        ] {
            std::fs::write(dir.join("results.csv"), body).unwrap();
            let e = replot(&dir).unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        }
        // A good table: one series per method, the sweep's other k left out.
        let rows = format!(
            "{header}\nsphere,hierarchical,0.5,1.5,1,0.2,0.3\nsphere,edge-aware,0.5,1.5,2,0.1,\n\
             sphere,edge-aware,0.5,3,4,0.05,\n"
        );
        std::fs::write(dir.join("results.csv"), rows).unwrap();
        let files = replot(&dir).unwrap();
        assert_eq!(files.len(), 2);
        let svg = std::fs::read_to_string(&files[0]).unwrap();
        assert!(svg.contains("data-label=\"hierarchical eps=0.5\""), "{svg}");
        assert!(svg.contains("data-label=\"edge-aware\""), "{svg}");
        // Two markers and the legend's two swatches: the row at k = 3 is not drawn.
        assert_eq!(svg.matches("<circle cx").count(), 4, "{svg}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn presets_are_valid_and_their_sheet_count_is_run() {
        for c in [BenchConfig::full(), BenchConfig::quick()] {
            c.validate().unwrap();
            assert!(c.counts.contains(&c.sheet_count));
            assert!(
                c.epsilons.contains(&c.split_epsilon),
                "the overhead claim needs it"
            );
            // Hierarchical at each ε, then local-global, edge-aware and edge-refined.
            assert_eq!(c.settings().len(), c.epsilons.len() + 3);
        }
        assert_eq!(BenchConfig::full().truth_count(), 1_600_000);
    }

    #[test]
    fn validation_names_the_bad_value() {
        let check = |f: fn(&mut BenchConfig), needle: &str| {
            let mut c = BenchConfig::quick();
            f(&mut c);
            let e = c.validate().unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
        };
        check(|c| c.resolution = 8, "resolution");
        check(|c| c.counts = vec![10], "sample counts");
        check(|c| c.counts.clear(), "sample counts");
        check(|c| c.sheet_count = 3_000, "sheet count");
        check(|c| c.seeds.clear(), "seed");
        check(|c| c.epsilons = vec![f32::NAN], "ε");
        check(|c| c.truth_epsilon = 0.0, "ε");
        check(|c| c.truth_factor = 1, "truth factor");
        check(|c| c.smoothings = vec![0.0], "smoothing");
        check(|c| c.smoothings = vec![f32::INFINITY], "smoothing");
        check(|c| c.scenes.clear(), "scene");
        check(|c| c.threads = Some(0), "threads");
        check(|c| c.overhead_rounds = 1000, "overhead rounds");
    }
}
