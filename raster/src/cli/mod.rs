//! The `lucent` command line: `render` (the default), `bake`, `merge`, `presets`, and with the feature
//! `harness` (on by default) `compare` and `bench`.
//!
//! Exit codes: 0 success, 1 a runtime error (bad scene, missing file, …; the message names the
//! problem), 2 a usage error (unknown flag, malformed value; printed by clap).

/// `println!` for the command's report on standard output, in a function returning
/// `Result<(), String>`: a reader that closed the pipe (`lucent compare a.exr b.exr | head -1`)
/// has seen what it wanted, so that ends the output quietly; any other write error is the
/// command's error.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::write_line(format_args!($($arg)*))?
    };
}

/// `eprintln!` that ignores a failed write: a closed standard error must neither panic
/// (exit 101) nor stop a render over a warning.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::cli::write_error_line(format_args!($($arg)*))
    };
}

mod commands;
#[cfg(feature = "harness")]
mod compare;
mod merge;

use std::path::PathBuf;

use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand};
use lucent_core::Method;

use crate::output::Region;

/// Writes one line to standard output (see [`outln`]).
fn write_line(line: std::fmt::Arguments) -> Result<(), String> {
    use std::io::Write;
    match writeln!(std::io::stdout().lock(), "{line}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

fn write_error_line(line: std::fmt::Arguments) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// Render translucent materials: point-based subsurface scattering (Jensen & Buhler 2002,
/// Langlands & Mertens 2007, Neulander 2010).
///
/// With no arguments, renders the built-in default scene (a marble bunny with a shadow edge)
/// to lucent.png and lucent.exr in the current directory.
#[derive(Debug, Parser)]
#[command(
    name = "lucent",
    version,
    args_conflicts_with_subcommands = true,
    max_term_width = 100
)]
pub struct Cli {
    /// The command (default: render).
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Render options, when no command is given.
    #[command(flatten)]
    pub render: RenderArgs,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a scene to PNG and/or OpenEXR (the default command).
    Render(RenderArgs),
    /// Place and light a scene's irradiance samples and write them to a PLY point cloud, for
    /// `render --samples-from`.
    Bake(BakeArgs),
    /// Assemble tiles rendered with `render --crop … --exr` into the whole image (PNG and/or
    /// OpenEXR), the same bytes a single render writes.
    Merge(MergeArgs),
    /// List the measured materials (Jensen et al. 2001) usable as `preset = "…"`.
    Presets,
    /// Run time against error: render the benchmark scenes at several sample counts with
    /// every method, measure time, memory and error against a ground truth, and write a
    /// report folder (Markdown, CSV, plots, Figure-1 contact sheets).
    #[cfg(feature = "harness")]
    Bench(BenchArgs),
    /// Compare two images (OpenEXR or PNG): RMSE, mean relative error, maximum error, over all
    /// pixels and, from the reference EXR's exitance and irradiance layers, over the
    /// translucent pixels and the band around shadow edges; optionally seed noise.
    #[cfg(feature = "harness")]
    Compare(CompareArgs),
}

/// Options of `render`.
#[derive(Debug, Args, Clone, Default)]
pub struct RenderArgs {
    /// Scene file (TOML, see docs/scene-format.md). Without it, the built-in default scene.
    pub scene: Option<PathBuf>,
    /// Write the PNG here (8-bit sRGB). With -o or --exr, the command line names every file
    /// written: the scene's `[output]` png and exr are not written.
    #[arg(short, long, value_name = "OUT.png")]
    pub output: Option<PathBuf>,
    /// Write the OpenEXR here (linear float, with alpha and the scene's `[output]` layers).
    /// With -o or --exr, the command line names every file written.
    #[arg(long, value_name = "OUT.exr")]
    pub exr: Option<PathBuf>,
    /// Subsurface method (docs/scene-format.md describes each).
    #[arg(long, value_parser = method_parser())]
    pub method: Option<Method>,
    /// Irradiance samples over all translucent surfaces: `auto` (the default, unless the scene
    /// gives a count) spaces them a quarter of the smallest diffuse mean free path ℓ_d of the
    /// translucent materials apart, up to --max-samples; or a count N.
    #[arg(long, value_name = "N|auto", value_parser = parse_samples, conflicts_with = "spacing")]
    pub samples: Option<SamplesArg>,
    /// Irradiance sample spacing in scene units (instead of a count).
    #[arg(long, value_name = "DISTANCE")]
    pub spacing: Option<f32>,
    /// The most samples `auto` may place (default: what half the available memory holds at
    /// 600 bytes per sample, at most 33554432).
    #[arg(long, value_name = "N")]
    pub max_samples: Option<u64>,
    /// Image width in pixels.
    #[arg(long, value_name = "W")]
    pub width: Option<u32>,
    /// Image height in pixels.
    #[arg(long, value_name = "H")]
    pub height: Option<u32>,
    /// Worker threads, for reading mesh files and rendering (default: all cores). The image
    /// does not depend on it.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Anti-aliasing: AA × AA coverage samples per pixel (1–8).
    #[arg(long, value_name = "AA")]
    pub aa: Option<u32>,
    /// Seed of the irradiance sample placement.
    #[arg(long)]
    pub seed: Option<u64>,
    /// JB02 solid-angle threshold ε (smaller = more accurate, slower).
    #[arg(long)]
    pub epsilon: Option<f32>,
    /// Exitance interpolation: query the subsurface exitance only at every N-th pixel in x and
    /// y and interpolate between them where the four corners of a block are alike (1–16; 1,
    /// the default, queries every pixel).
    #[arg(long, value_name = "N")]
    pub interpolation: Option<u32>,
    /// How alike the corners must be: per channel, the largest exitance at most 1 + T times
    /// the smallest (default 0.25).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub interpolation_tolerance: Option<f32>,
    /// Smoothing radius factor k of the split methods (α = k·√(mean sample area)).
    #[arg(long, value_name = "K")]
    pub smoothing: Option<f32>,
    /// Exposure in stops, applied to the PNG.
    #[arg(long, value_name = "STOPS", allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Load irradiance samples baked by `lucent bake` instead of placing and lighting new ones.
    #[arg(long, value_name = "FILE.ply")]
    pub samples_from: Option<PathBuf>,
    /// Render only the pixels x0..x1 × y0..y1 (x1, y1 exclusive) of the image, a tile for
    /// `lucent merge`: each is bit for bit the pixel of a whole render. --exr writes the tile
    /// with its place in the image; -o writes the tile alone as a PNG. Outputs must be named on
    /// the command line. Use the same samples for every tile (--samples-from).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop)]
    pub crop: Option<Region>,
    /// Print nothing but errors and warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

fn parse_crop(text: &str) -> Result<Region, String> {
    Region::parse(text)
}

/// Options of `merge`.
#[derive(Debug, Args, Clone)]
pub struct MergeArgs {
    /// The tiles (OpenEXR files written by `render --crop … --exr`), in any order; together
    /// they must cover the image exactly once.
    #[arg(required = true, value_name = "TILE.exr")]
    pub tiles: Vec<PathBuf>,
    /// Write the merged image as a PNG (8-bit sRGB at the tiles' exposure).
    #[arg(short, long, value_name = "OUT.png")]
    pub output: Option<PathBuf>,
    /// Write the merged image as an OpenEXR (beauty, alpha and every layer of the tiles).
    #[arg(long, value_name = "OUT.exr")]
    pub exr: Option<PathBuf>,
    /// The PNG's exposure in stops, instead of the one recorded in the tiles.
    #[arg(long, value_name = "STOPS", allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--samples`: `auto` or a count (its range is checked with the scene, exit status 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplesArg {
    /// The automatic count.
    Auto,
    /// This many.
    Count(u64),
}

/// `--method`: one of the core's [`Method::ALL`] names, listed by `--help` and by the error
/// for any other value.
fn method_parser() -> impl TypedValueParser<Value = Method> {
    PossibleValuesParser::new(Method::ALL.map(Method::name)).try_map(|name| name.parse::<Method>())
}

fn parse_samples(text: &str) -> Result<SamplesArg, String> {
    if text == crate::scene::AUTO {
        return Ok(SamplesArg::Auto);
    }
    text.parse()
        .map(SamplesArg::Count)
        .map_err(|_| "expected a sample count (a positive integer) or `auto`".to_string())
}

/// Options of `bake`.
#[derive(Debug, Args, Clone)]
pub struct BakeArgs {
    /// Scene file (TOML). Without it, the built-in default scene.
    pub scene: Option<PathBuf>,
    /// Where to write the samples (binary PLY).
    #[arg(short, long, value_name = "OUT.ply", default_value = "samples.ply")]
    pub output: PathBuf,
    /// The method whose rule lights the samples (default: the scene's): edge-refined lights
    /// a sample whose cell a hard shadow's edge crosses by the mean over its cell, every other
    /// method at the sample.
    #[arg(long, value_parser = method_parser())]
    pub method: Option<Method>,
    /// Irradiance samples over all translucent surfaces: `auto` (the default, unless the scene
    /// gives a count) spaces them a quarter of the smallest diffuse mean free path ℓ_d of the
    /// translucent materials apart, up to --max-samples; or a count N.
    #[arg(long, value_name = "N|auto", value_parser = parse_samples, conflicts_with = "spacing")]
    pub samples: Option<SamplesArg>,
    /// Irradiance sample spacing in scene units (instead of a count).
    #[arg(long, value_name = "DISTANCE")]
    pub spacing: Option<f32>,
    /// The most samples `auto` may place (default: what half the available memory holds at
    /// 600 bytes per sample, at most 33554432).
    #[arg(long, value_name = "N")]
    pub max_samples: Option<u64>,
    /// Seed of the sample placement.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads, for reading mesh files and baking (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print nothing but errors and warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Options of `bench`.
#[cfg(feature = "harness")]
#[derive(Debug, Args, Clone)]
pub struct BenchArgs {
    /// Where to write the report (report.md, results.csv, SVG charts, PNG contact sheets).
    #[arg(short, long, value_name = "DIR", default_value = "bench-report")]
    pub output: PathBuf,
    /// Run nothing: draw the error-against-time charts again from the results.csv in the
    /// output folder (written by an earlier run).
    #[arg(long)]
    pub replot: bool,
    /// A small version (64², two sample counts) that finishes in well under a minute.
    #[arg(long)]
    pub quick: bool,
    /// Run only the peer comparison (sphere, one lookup per pixel, one thread: CPU per lookup
    /// against relRMSE beside pbrt-v2's), writing peer.md and peer.csv; about a minute.
    #[arg(long)]
    pub peer: bool,
    /// Run only the diffusion profiles against a Monte Carlo random walk (η = 1.3 and 1,
    /// seven albedos, pencil beam and diffuse light), writing profiles.md, profiles.csv,
    /// profile-bins.csv and SVG charts of R(r); about 70 s on one core.
    #[arg(long, conflicts_with = "peer")]
    pub profiles: bool,
    /// Only these scenes (default, sphere, textured), comma-separated.
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub scenes: Vec<String>,
    /// Sample counts instead of the preset's, comma-separated.
    #[arg(long, value_delimiter = ',', value_name = "N,N,...")]
    pub counts: Vec<u32>,
    /// Seeds per configuration (the noise needs two or more).
    #[arg(long, value_name = "N")]
    pub seeds: Option<u32>,
    /// Image width and height.
    #[arg(long, value_name = "PIXELS")]
    pub resolution: Option<u32>,
    /// Interleaved rounds of the overhead and texture-cost measurements (default 5, quick 2;
    /// more narrow their spread on a noisy host).
    #[arg(long, value_name = "N")]
    pub rounds: Option<usize>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Options of `compare`.
#[cfg(feature = "harness")]
#[derive(Debug, Args, Clone)]
pub struct CompareArgs {
    /// The image under test (.exr or .png).
    pub test: PathBuf,
    /// The reference image (.exr or .png), same size.
    pub reference: PathBuf,
    /// Also write an error heat map (PNG).
    #[arg(long, value_name = "OUT.png")]
    pub heatmap: Option<PathBuf>,
    /// Heat map of relative instead of absolute error.
    #[arg(long)]
    pub relative: bool,
    /// Heat map on a logarithmic scale (4 decades).
    #[arg(long)]
    pub log: bool,
    /// Also report seed noise: the per-pixel standard deviation across TEST and these renders
    /// of the same scene with other sample seeds.
    #[arg(long, value_name = "IMAGE", num_args = 1..)]
    pub noise_with: Vec<PathBuf>,
}

/// Runs the command line and returns the process exit code.
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    let result = match cli.command {
        None => commands::render(&cli.render),
        Some(Command::Render(args)) => commands::render(&args),
        Some(Command::Bake(args)) => commands::bake(&args),
        Some(Command::Merge(args)) => merge::merge(&args),
        Some(Command::Presets) => commands::presets(),
        #[cfg(feature = "harness")]
        Some(Command::Compare(args)) => compare::compare(&args),
        #[cfg(feature = "harness")]
        Some(Command::Bench(args)) => commands::bench(&args),
    };
    match result {
        Ok(()) => 0,
        Err(message) => {
            errln!("error: {message}");
            1
        }
    }
}
