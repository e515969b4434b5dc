//! `lucent bench --profiles`: diffusion profiles measured against the Monte Carlo random walk
//! of the core (`lucent_core::internals::random_walk`).
//!
//! ```text
//! for each η (1.3, and 1 where the totals are exact and Burley's fits were made)
//!   × illumination (pencil beam, diffuse) × α′ ∈ {0.1, 0.3, 0.5, 0.7, 0.9, 0.95, 0.99}:
//!     walk   = the random walk, `photons` entered photons, 20 bins per decade
//!     at η = 1: its total against Chandrasekhar's plane / spherical albedo (the reference's
//!               own credibility)
//!     per model in MODELS:
//!         total error          (model total − walk total) / walk total
//!         mean relative error  |R_model − R_walk| / R_walk over the bins in [0.1, 10] ℓ_u,
//!                              the model averaged over each annulus as the walk scores it
//! report: profiles.md, profiles.csv (one row per model × η × illumination × α′),
//!         profile-bins.csv (every bin: walk, its error, every model),
//!         profile-eta<η>-<illumination>-<α′>.svg (log R against log r/ℓ_u, walk and models),
//!         profile-ratio-eta<η>-<illumination>-<α′>.svg (each model / walk against r/ℓ_u)
//! ```
//!
//! A model is one entry of [`MODELS`]: a name and a function from [`ModelInput`] (α′, η, the
//! illumination and the walk's own total, which fits such as Burley's take as their surface
//! albedo) to a [`ModelCurve`], R(r) in units of ℓ_u and its total.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use lucent_core::BurleyFit;
use lucent_core::internals::random_walk::{
    self as walk, COMPARE_RANGE, HFunction, Illumination, ProfileComparison, RadialProfile, Tally,
    WalkSettings,
};
use lucent_core::internals::{
    Boundary, UnitBetterDipole, UnitBurley, UnitDipole, total_reflectance,
};
use rayon::prelude::*;

use super::BenchError;
use crate::output::write_text_atomically;
use crate::plot::{Chart, Series, render_chart};

/// What a model is built from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelInput {
    /// Reduced albedo α′.
    pub albedo: f64,
    /// Relative index η.
    pub eta: f64,
    /// The walk's illumination (a fit made for one configuration may use it).
    pub illumination: Illumination,
    /// The walk's total diffuse reflectance: the surface albedo of models parameterised by
    /// it (Burley's normalised diffusion is compared at the walk's measured total).
    pub walk_total: f64,
}

/// A model's profile: R(r) in 1/ℓ_u² for r in ℓ_u, and its total diffuse reflectance.
pub struct ModelCurve {
    /// R(r).
    pub rd: Box<dyn Fn(f64) -> f64 + Send + Sync>,
    /// ∫ R dA.
    pub total: f64,
}

/// A model in the comparison: a name for the tables and how to build its curve.
#[derive(Clone, Copy)]
pub struct ModelEntry {
    /// Shown in tables, CSV columns and legends.
    pub name: &'static str,
    /// The curve for one walk.
    pub build: fn(&ModelInput) -> ModelCurve,
}

/// The models measured, in table order. Adding one is adding an entry.
pub const MODELS: &[ModelEntry] = &[
    ModelEntry {
        name: "classical dipole",
        build: classical_dipole,
    },
    ModelEntry {
        name: "better dipole",
        build: better_dipole,
    },
    ModelEntry {
        name: "Burley (searchlight fit)",
        build: burley_searchlight,
    },
    ModelEntry {
        name: "Burley (diffuse-transmission fit)",
        build: burley_diffuse,
    },
];

/// The classical dipole of Jensen et al. 2001 (`docs/physics.md` §2), with its closed-form
/// total.
fn classical_dipole(input: &ModelInput) -> ModelCurve {
    let dipole = UnitDipole::new(input.albedo, input.eta);
    ModelCurve {
        rd: Box::new(move |r| dipole.rd(r)),
        total: total_reflectance(input.albedo, input.eta),
    }
}

/// d'Eon's better dipole (2012), with its closed-form total.
fn better_dipole(input: &ModelInput) -> ModelCurve {
    let dipole = UnitBetterDipole::new(input.albedo, &Boundary::new(input.eta));
    ModelCurve {
        rd: Box::new(move |r| dipole.rd(r)),
        total: dipole.total_reflectance(),
    }
}

/// Christensen & Burley's normalised diffusion (2015) with the surface albedo A set to the
/// walk's measured total, as in their comparison: its total error is zero by construction,
/// and only the shape is measured.
fn burley(input: &ModelInput, fit: BurleyFit) -> ModelCurve {
    let profile = UnitBurley::new(input.walk_total, fit);
    ModelCurve {
        rd: Box::new(move |r| profile.rd(r)),
        total: input.walk_total,
    }
}

/// [`burley`] with the searchlight fit of s(A) (made for a pencil beam).
fn burley_searchlight(input: &ModelInput) -> ModelCurve {
    burley(input, BurleyFit::Searchlight)
}

/// [`burley`] with the diffuse-transmission fit of s(A) (made for diffuse light).
fn burley_diffuse(input: &ModelInput) -> ModelCurve {
    burley(input, BurleyFit::DiffuseTransmission)
}

/// The run's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfilesConfig {
    /// Reduced albedos.
    pub albedos: Vec<f64>,
    /// Relative indices η, each a section of the report. At η = 1 the walk's totals are also
    /// checked against Chandrasekhar's exact values.
    pub etas: Vec<f64>,
    /// Entered photons per walk (per η, albedo and illumination).
    pub photons: u64,
    /// The walks' seed.
    pub seed: u64,
    /// Albedos drawn as profile charts (those not in `albedos` are skipped).
    pub plot_albedos: Vec<f64>,
    /// Worker threads (default: all cores). The result does not depend on it.
    pub threads: Option<usize>,
}

/// The albedos of the published table.
const ALBEDOS: [f64; 7] = [0.1, 0.3, 0.5, 0.7, 0.9, 0.95, 0.99];

impl ProfilesConfig {
    /// The published measurement: 8 × 10⁶ photons per walk, η = 1.3 (skin) and η = 1 (the
    /// index-matched boundary, where the walk has exact totals and Burley's fits were made);
    /// about 70 s on one core.
    pub fn full() -> Self {
        ProfilesConfig {
            albedos: ALBEDOS.to_vec(),
            etas: vec![1.3, 1.0],
            photons: 8_000_000,
            seed: 1,
            plot_albedos: vec![0.5, 0.95],
            threads: None,
        }
    }

    /// A small version for `--quick` and the tests (10⁵ photons per walk).
    pub fn quick() -> Self {
        ProfilesConfig {
            photons: 100_000,
            ..Self::full()
        }
    }
}

/// One walk and its models.
#[derive(Clone, Debug)]
pub struct WalkResult {
    /// The walk.
    pub profile: RadialProfile,
    /// Wall time of the walk, seconds.
    pub seconds: f64,
    /// Per model (in [`MODELS`] order): its total and the comparison.
    pub models: Vec<(f64, ProfileComparison)>,
}

/// A walk's total at η = 1 against Chandrasekhar's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckRow {
    /// Illumination.
    pub illumination: Illumination,
    /// α′.
    pub albedo: f64,
    /// The walk's total.
    pub walk: f64,
    /// Its standard error.
    pub std_error: f64,
    /// Plane albedo at μ₀ = 1 (pencil) or spherical albedo (diffuse).
    pub exact: f64,
}

impl CheckRow {
    /// (walk − exact) / standard error.
    pub fn z(&self) -> f64 {
        (self.walk - self.exact) / self.std_error
    }
}

/// Everything `--profiles` measured.
#[derive(Clone, Debug)]
pub struct ProfilesReport {
    /// The settings.
    pub config: ProfilesConfig,
    /// The walks at η = 1 against Chandrasekhar.
    pub checks: Vec<CheckRow>,
    /// The walks: per η, pencil beam then diffuse, each in albedo order.
    pub walks: Vec<WalkResult>,
    /// Wall time of the whole run, seconds.
    pub seconds: f64,
}

/// The two illuminations, in table order.
const ILLUMINATIONS: [Illumination; 2] = [Illumination::PencilBeam, Illumination::Diffuse];

/// Runs the walks and compares every model.
pub fn run(
    config: &ProfilesConfig,
    log: &mut dyn FnMut(&str),
) -> Result<ProfilesReport, BenchError> {
    let start = Instant::now();
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = config.threads {
        builder = builder.num_threads(n);
    }
    let pool = builder
        .build()
        .map_err(|e| BenchError::new(format!("cannot start the worker threads: {e}")))?;
    let mut walks = Vec::new();
    let mut checks = Vec::new();
    for &eta in &config.etas {
        for illumination in ILLUMINATIONS {
            for &albedo in &config.albedos {
                let s = WalkSettings {
                    illumination,
                    photons: config.photons,
                    seed: config.seed,
                    ..WalkSettings::new(albedo, eta)
                };
                s.validate().map_err(|e| BenchError::new(e.to_string()))?;
                let t = Instant::now();
                let tally = pool.install(|| {
                    (0..s.chunks())
                        .into_par_iter()
                        .map(|chunk| walk::walk_chunk(&s, chunk))
                        .reduce(Tally::default, |mut a, b| {
                            a.merge(&b);
                            a
                        })
                });
                let profile = RadialProfile::from_tally(&s, &tally);
                let seconds = t.elapsed().as_secs_f64();
                let input = ModelInput {
                    albedo,
                    eta,
                    illumination,
                    walk_total: profile.total,
                };
                let models = MODELS
                    .iter()
                    .map(|m| {
                        let curve = (m.build)(&input);
                        (curve.total, walk::compare(&profile, &curve.rd, curve.total))
                    })
                    .collect();
                if eta == 1.0 {
                    let h = HFunction::new(albedo);
                    checks.push(CheckRow {
                        illumination,
                        albedo,
                        walk: profile.total,
                        std_error: profile.total_std_error,
                        exact: match illumination {
                            Illumination::PencilBeam => h.plane_albedo(1.0),
                            Illumination::Diffuse => h.spherical_albedo(),
                        },
                    });
                }
                log(&format!(
                    "η = {eta}, {} α′ = {albedo}: total {:.5} ± {:.5} ({seconds:.1} s)",
                    illumination.name(),
                    profile.total,
                    profile.total_std_error
                ));
                walks.push(WalkResult {
                    profile,
                    seconds,
                    models,
                });
            }
        }
    }
    if !checks.is_empty() {
        log(&format!(
            "η = 1 against Chandrasekhar: largest |z| {:.2}",
            checks.iter().map(|c| c.z().abs()).fold(0.0, f64::max)
        ));
    }
    Ok(ProfilesReport {
        config: config.clone(),
        checks,
        walks,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// A fraction as a signed percentage.
fn percent(x: f64) -> String {
    format!("{:+.1}%", 100.0 * x)
}

/// The walks at one η under one illumination, in albedo order.
fn walks_of(report: &ProfilesReport, eta: f64, illumination: Illumination) -> Vec<&WalkResult> {
    report
        .walks
        .iter()
        .filter(|w| {
            w.profile.settings.eta == eta && w.profile.settings.illumination == illumination
        })
        .collect()
}

/// `profiles.md`: per η the walks' totals and one table per model, then the check against
/// Chandrasekhar.
pub fn markdown(report: &ProfilesReport) -> String {
    let c = &report.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# lucent bench --profiles\n\nAnalogue random walk in a semi-infinite medium (reduced coefficients, isotropic scattering, σ_t′ = 1), {} entered photons per walk, seed {}; radii in ℓ_u = 1/σ_t′, 20 bins per decade. Per unit flux transmitted into the medium. Pencil beam = normal incidence; diffuse = cosine-weighted incidence refracted in. Mean relative error over the bins whose centre lies in [{}, {}] ℓ_u, each model averaged over the bin's annulus; Burley's A is the walk's total, so its total error is zero by construction. Total run time {:.1} s.",
        c.photons, c.seed, COMPARE_RANGE.0, COMPARE_RANGE.1, report.seconds
    );
    for &eta in &c.etas {
        let pencil = walks_of(report, eta, Illumination::PencilBeam);
        let diffuse = walks_of(report, eta, Illumination::Diffuse);
        let _ = writeln!(
            s,
            "\n## η = {eta}\n\n### The walk's totals\n\nNoise: the walk's mean relative standard error over the compared bins; a model equal to the truth would show a mean relative error of about 0.8 × this (the mean of |N(0, σ)| is 0.8σ).\n\n| α′ | pencil | pencil: noise | diffuse | diffuse: noise |\n|---:|---:|---:|---:|---:|"
        );
        for (p, d) in pencil.iter().zip(&diffuse) {
            let _ = writeln!(
                s,
                "| {} | {:.5} ± {:.5} | {:.1}% | {:.5} ± {:.5} | {:.1}% |",
                p.profile.settings.albedo,
                p.profile.total,
                p.profile.total_std_error,
                100.0 * walk_noise(&p.profile),
                d.profile.total,
                d.profile.total_std_error,
                100.0 * walk_noise(&d.profile)
            );
        }
        for (m, model) in MODELS.iter().enumerate() {
            let _ = writeln!(
                s,
                "\n### {} (η = {eta})\n\nTotal error = (model − walk) / walk; mean rel. = mean |R_model − R_walk| / R_walk over [{}, {}] ℓ_u; signed = its signed mean (negative: too dark).\n\n| α′ | pencil: total error | pencil: mean rel. | pencil: signed | diffuse: total error | diffuse: mean rel. | diffuse: signed |\n|---:|---:|---:|---:|---:|---:|---:|",
                model.name, COMPARE_RANGE.0, COMPARE_RANGE.1
            );
            for (p, d) in pencil.iter().zip(&diffuse) {
                let (a, b) = (p.models[m].1, d.models[m].1);
                let _ = writeln!(
                    s,
                    "| {} | {} | {:.1}% | {} | {} | {:.1}% | {} |",
                    p.profile.settings.albedo,
                    percent(a.total_relative_error),
                    100.0 * a.mean_relative_error,
                    percent(a.mean_signed_relative_error),
                    percent(b.total_relative_error),
                    100.0 * b.mean_relative_error,
                    percent(b.mean_signed_relative_error)
                );
            }
        }
    }
    if !report.checks.is_empty() {
        let _ = writeln!(
            s,
            "\n## The walk at η = 1 against Chandrasekhar\n\nThe exact totals of an index-matched half-space: 1 − H(1)√(1 − α′) under the pencil beam, 1 − 2√(1 − α′)∫H μ dμ under diffuse light.\n\n| illumination | α′ | walk | exact | z |\n|---|---:|---:|---:|---:|"
        );
        for r in &report.checks {
            let _ = writeln!(
                s,
                "| {} | {} | {:.5} ± {:.5} | {:.5} | {:+.2} |",
                r.illumination.name(),
                r.albedo,
                r.walk,
                r.std_error,
                r.exact,
                r.z()
            );
        }
    }
    s
}

/// The walk's mean relative standard error over the bins a comparison uses (centre in
/// [`COMPARE_RANGE`], at least one photon).
fn walk_noise(p: &RadialProfile) -> f64 {
    let relative: Vec<f64> = (0..p.len())
        .filter(|&i| {
            (COMPARE_RANGE.0..=COMPARE_RANGE.1).contains(&p.centre(i)) && p.reflectance[i] > 0.0
        })
        .map(|i| p.std_error[i] / p.reflectance[i])
        .collect();
    relative.iter().sum::<f64>() / relative.len().max(1) as f64
}

/// `profiles.csv`: one row per model × illumination × albedo.
pub fn csv(report: &ProfilesReport) -> String {
    let mut s = String::from(
        "model,illumination,albedo,eta,photons,walk_total,walk_total_se,model_total,total_rel_error,mean_rel_error,mean_signed_rel_error,bins\n",
    );
    for w in &report.walks {
        let p = &w.profile;
        for (model, (total, c)) in MODELS.iter().zip(&w.models) {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{}",
                model.name,
                p.settings.illumination.name(),
                p.settings.albedo,
                p.settings.eta,
                p.settings.photons,
                p.total,
                p.total_std_error,
                total,
                c.total_relative_error,
                c.mean_relative_error,
                c.mean_signed_relative_error,
                c.bins
            );
        }
    }
    s
}

/// `profile-bins.csv`: every bin of every walk, with each model's annulus mean.
pub fn bins_csv(report: &ProfilesReport) -> String {
    let mut s = String::from("illumination,albedo,eta,r_inner,r_outer,r_centre,walk_r,walk_se");
    for m in MODELS {
        let _ = write!(s, ",{}", m.name.replace(' ', "_"));
    }
    s.push('\n');
    for w in &report.walks {
        let p = &w.profile;
        let curves = model_curves(p);
        for i in 0..p.len() {
            let (a, b) = (p.edges[i], p.edges[i + 1]);
            let _ = write!(
                s,
                "{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
                p.settings.illumination.name(),
                p.settings.albedo,
                p.settings.eta,
                a,
                b,
                p.centre(i),
                p.reflectance[i],
                p.std_error[i]
            );
            for curve in &curves {
                let _ = write!(s, ",{:.6e}", walk::annulus_mean(&curve.rd, a, b));
            }
            s.push('\n');
        }
    }
    s
}

/// Every model's curve for a walk.
fn model_curves(p: &RadialProfile) -> Vec<ModelCurve> {
    let input = ModelInput {
        albedo: p.settings.albedo,
        eta: p.settings.eta,
        illumination: p.settings.illumination,
        walk_total: p.total,
    };
    MODELS.iter().map(|m| (m.build)(&input)).collect()
}

/// The radii the charts show, ℓ_u: from well inside the compared range to where the walk's
/// bins thin out.
const PLOT_RANGE: (f64, f64) = (0.01, 30.0);

/// The chart of one walk: `profile-eta<η>-<illumination>-<α′>.svg`.
pub fn plot_file(eta: f64, illumination: Illumination, albedo: f64) -> String {
    format!("profile-eta{eta}-{}-{albedo}.svg", illumination.name())
}

/// The chart of every model divided by the walk: `profile-ratio-eta<η>-<illumination>-<α′>.svg`.
pub fn ratio_plot_file(eta: f64, illumination: Illumination, albedo: f64) -> String {
    format!(
        "profile-ratio-eta{eta}-{}-{albedo}.svg",
        illumination.name()
    )
}

/// Bins whose walk value has a larger relative standard error are left out of the ratio
/// chart: their ratio would be noise.
const RATIO_MAX_NOISE: f64 = 0.1;

/// Draws, for each plotted albedo at every η, R(r) of the walk and every model
/// ([`plot_file`], log–log: the shapes over five decades) and every model's ratio to the walk
/// ([`ratio_plot_file`], where errors of a few percent show); returns the files.
pub fn write_plots(report: &ProfilesReport, out: &Path) -> Result<Vec<PathBuf>, BenchError> {
    let mut written = Vec::new();
    for w in &report.walks {
        let p = &w.profile;
        let settings = &p.settings;
        if !report.config.plot_albedos.contains(&settings.albedo) {
            continue;
        }
        let shown: Vec<usize> = (0..p.len())
            .filter(|&i| (PLOT_RANGE.0..=PLOT_RANGE.1).contains(&p.centre(i)))
            .collect();
        // Each model's annulus means over the shown bins.
        let means: Vec<Vec<f64>> = model_curves(p)
            .iter()
            .map(|curve| {
                shown
                    .iter()
                    .map(|&i| walk::annulus_mean(&curve.rd, p.edges[i], p.edges[i + 1]))
                    .collect()
            })
            .collect();
        let mut series = vec![Series {
            label: "random walk".to_string(),
            points: shown
                .iter()
                .map(|&i| (p.centre(i), p.reflectance[i]))
                .collect(),
        }];
        // The walk as the line at 1, so that each model keeps its colour of the other chart.
        let mut ratios = vec![Series {
            label: "random walk (= 1)".to_string(),
            points: shown.iter().map(|&i| (p.centre(i), 1.0)).collect(),
        }];
        for (model, values) in MODELS.iter().zip(&means) {
            series.push(Series {
                label: model.name.to_string(),
                points: shown
                    .iter()
                    .zip(values)
                    .map(|(&i, &v)| (p.centre(i), v))
                    .collect(),
            });
            ratios.push(Series {
                label: model.name.to_string(),
                points: shown
                    .iter()
                    .zip(values)
                    .filter(|&(&i, _)| p.std_error[i] <= RATIO_MAX_NOISE * p.reflectance[i])
                    .filter(|&(&i, _)| p.reflectance[i] > 0.0)
                    .map(|(&i, &v)| (p.centre(i), v / p.reflectance[i]))
                    .collect(),
            });
        }
        let illumination = match settings.illumination {
            Illumination::PencilBeam => "pencil beam",
            Illumination::Diffuse => "diffuse",
        };
        let what = format!(
            "α′ = {}, η = {}, {illumination}",
            settings.albedo, settings.eta
        );
        let charts = [
            (
                Chart {
                    title: format!("R(r), {what}"),
                    x_label: "r / ℓ_u".to_string(),
                    y_label: "R(r) · ℓ_u²".to_string(),
                    series,
                    log_x: true,
                    log_y: true,
                },
                plot_file(settings.eta, settings.illumination, settings.albedo),
            ),
            (
                Chart {
                    title: format!("model / walk, {what}"),
                    x_label: "r / ℓ_u".to_string(),
                    y_label: "R_model / R_walk".to_string(),
                    series: ratios,
                    log_x: true,
                    log_y: true,
                },
                ratio_plot_file(settings.eta, settings.illumination, settings.albedo),
            ),
        ];
        for (chart, file) in charts {
            let svg = render_chart(&chart, 800, 560)?;
            let path = out.join(file);
            write_text_atomically(&path, &svg)?;
            written.push(path);
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::xml::check_well_formed;

    fn tiny() -> ProfilesConfig {
        ProfilesConfig {
            albedos: vec![0.5, 0.95],
            photons: 20_000,
            plot_albedos: vec![0.95],
            threads: Some(2),
            ..ProfilesConfig::full()
        }
    }

    #[test]
    fn a_small_run_writes_consistent_tables_and_charts() {
        let report = run(&tiny(), &mut |_| {}).unwrap();
        assert_eq!(report.walks.len(), 8);
        assert_eq!(report.checks.len(), 4);
        for c in &report.checks {
            // Chandrasekhar's totals: the walk is within 4.5 standard errors of each.
            assert!(c.z().abs() < 4.5, "{c:?}");
        }
        // The dipole's comparison is the core's, on the same walk.
        for w in &report.walks {
            let p = &w.profile;
            let (albedo, eta) = (p.settings.albedo, p.settings.eta);
            let d = UnitDipole::new(albedo, eta);
            let want = walk::compare(p, |r| d.rd(r), total_reflectance(albedo, eta));
            assert_eq!(w.models[0].1, want);
        }

        let md = markdown(&report);
        assert!(md.contains("### classical dipole (η = 1.3)"));
        assert!(md.contains("### better dipole (η = 1)"));
        // α′ = 0.95 in each η's totals table and each model's.
        let rows = md.lines().filter(|l| l.starts_with("| 0.95 |")).count();
        assert_eq!(rows, 2 * (1 + MODELS.len()));

        let table = csv(&report);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 1 + 8 * MODELS.len());
        let columns = lines[0].split(',').count();
        assert!(lines.iter().all(|l| l.split(',').count() == columns));
        let bins = bins_csv(&report);
        assert_eq!(bins.lines().count(), 1 + 8 * 100);
        let columns = bins.lines().next().unwrap().split(',').count();
        assert_eq!(columns, 8 + MODELS.len());

        let dir = std::env::temp_dir().join(format!("lucent-profiles-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let files = write_plots(&report, &dir).unwrap();
        assert_eq!(files.len(), 8);
        assert!(files.contains(&dir.join("profile-eta1.3-pencil-0.95.svg")));
        assert!(files.contains(&dir.join("profile-ratio-eta1-diffuse-0.95.svg")));
        for f in &files {
            let svg = std::fs::read_to_string(f).unwrap();
            check_well_formed(&svg).unwrap();
            assert!(svg.contains("random walk") && svg.contains("classical dipole"));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_thread_count_does_not_change_the_result() {
        let one = ProfilesConfig {
            albedos: vec![0.7],
            etas: vec![1.3],
            threads: Some(1),
            ..tiny()
        };
        let two = ProfilesConfig {
            threads: Some(2),
            ..one.clone()
        };
        let (a, b) = (
            run(&one, &mut |_| {}).unwrap(),
            run(&two, &mut |_| {}).unwrap(),
        );
        assert!(a.checks.is_empty());
        for (x, y) in a.walks.iter().zip(&b.walks) {
            assert_eq!(x.profile, y.profile);
        }
    }

    #[test]
    fn a_model_can_take_the_walk_total_as_its_albedo() {
        // A model whose total is the walk's own has no total error, the way Burley's
        // normalised diffusion is compared at A = the walk's total.
        fn echo(input: &ModelInput) -> ModelCurve {
            ModelCurve {
                rd: Box::new(|_| 1.0),
                total: input.walk_total,
            }
        }
        let entry = ModelEntry {
            name: "echo",
            build: echo,
        };
        let s = WalkSettings {
            photons: 5_000,
            ..WalkSettings::new(0.8, 1.3)
        };
        let p = walk::run(&s).unwrap();
        let curve = (entry.build)(&ModelInput {
            albedo: 0.8,
            eta: 1.3,
            illumination: s.illumination,
            walk_total: p.total,
        });
        assert_eq!(
            walk::compare(&p, &curve.rd, curve.total).total_relative_error,
            0.0
        );
    }
}
