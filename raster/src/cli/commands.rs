//! The commands behind the `lucent` command line. Each returns `Err(message)` for a runtime
//! error; the message names the problem (file, key, value).

use std::path::Path;

use lucent_core::{Profile, presets};

#[cfg(feature = "harness")]
use super::BenchArgs;
use super::{BakeArgs, RenderArgs, SamplesArg};
#[cfg(feature = "harness")]
use crate::bench::{self, BenchConfig, BenchScene};
use crate::memory;
use crate::output::{
    Placement, Region, output_target, refuse_read_only, write_exr, write_exr_tile, write_png,
};
use crate::render::{
    self, LIGHTING_COMMENT, METHOD_COMMENT, RenderOptions, during, read_baked_with_provenance,
    write_baked,
};
use crate::scene::{
    MAX_INTERPOLATION_STEP, MAX_PIXELS, MAX_SAMPLES, MAX_SIDE, MAX_THREADS, OutputSettings,
    SampleDensity, SampleRequest, Scene, default_scene, files_read, load_scene,
};

/// Loads the scene named on the command line, or the built-in default, printing its
/// warnings on stderr (and, with `progress`, the time taken while it lasts). Mesh files are
/// read with `--threads` threads when given (checked here, before any reading), else with
/// every core.
fn load(path: Option<&Path>, threads: Option<usize>, progress: bool) -> Result<Scene, String> {
    let read = || match path {
        Some(p) => load_scene(p).map_err(|e| e.to_string()),
        None => Ok(default_scene()),
    };
    if let Some(n) = threads {
        check_threads(n)?;
    }
    let scene = during(progress, "load", || match threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| format!("cannot start {n} threads: {e}"))
            .and_then(|pool| pool.install(read)),
        None => read(),
    })?;
    for warning in &scene.warnings {
        errln!("warning: {warning}");
    }
    Ok(scene)
}

fn check(ok: bool, flag: &str, value: impl std::fmt::Display, range: &str) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(format!("{flag} {value}: must be {range}"))
    }
}

fn density(
    samples: Option<SamplesArg>,
    spacing: Option<f32>,
    max_samples: Option<u64>,
    scene: &mut Scene,
) -> Result<(), String> {
    match samples {
        Some(SamplesArg::Auto) => scene.render.samples = SampleRequest::Auto,
        Some(SamplesArg::Count(n)) => {
            check(
                n >= 1 && n <= MAX_SAMPLES as u64,
                "--samples",
                n,
                &format!("between 1 and {MAX_SAMPLES}, or auto"),
            )?;
            scene.render.samples = SampleDensity::Count(n as u32).into();
        }
        None => {}
    }
    if let Some(s) = spacing {
        check(
            s.is_finite() && s > 0.0,
            "--spacing",
            s,
            "a positive distance",
        )?;
        scene.render.samples = SampleDensity::Spacing(s).into();
    }
    if let Some(m) = max_samples {
        check(
            m >= 1 && m <= MAX_SAMPLES as u64,
            "--max-samples",
            m,
            &format!("between 1 and {MAX_SAMPLES}"),
        )?;
        let given = match scene.render.samples {
            SampleRequest::Auto => None,
            SampleRequest::Density(SampleDensity::Count(n)) => Some(format!("samples = {n}")),
            SampleRequest::Density(SampleDensity::Spacing(s)) => Some(format!("spacing = {s}")),
        };
        if let Some(given) = given {
            return Err(format!(
                "--max-samples {m}: caps the automatic count only, but the render asks for \
                 {given} (add --samples auto)"
            ));
        }
        scene.render.max_samples = Some(m as u32);
    }
    Ok(())
}

/// `--seed`: the range a scene file's `seed` holds (TOML integers are signed 64-bit), so that
/// a seed given on the command line can be written into a scene.
fn seed(seed: Option<u64>, scene: &mut Scene) -> Result<(), String> {
    if let Some(seed) = seed {
        check(
            seed <= i64::MAX as u64,
            "--seed",
            seed,
            &format!("between 0 and {}", i64::MAX),
        )?;
        scene.render.seed = seed;
    }
    Ok(())
}

fn threads(n: Option<usize>, scene: &mut Scene) -> Result<(), String> {
    if let Some(n) = n {
        check_threads(n)?;
        scene.render.threads = Some(n);
    }
    Ok(())
}

fn check_threads(n: usize) -> Result<(), String> {
    check(
        n >= 1 && n as i64 <= MAX_THREADS,
        "--threads",
        n,
        &format!("between 1 and {MAX_THREADS}"),
    )
}

/// Applies the command-line overrides to the scene, validating each.
fn apply(args: &RenderArgs, scene: &mut Scene) -> Result<(), String> {
    if let Some(m) = args.method {
        scene.render.method = m;
    }
    density(args.samples, args.spacing, args.max_samples, scene)?;
    threads(args.threads, scene)?;
    for (flag, value, slot) in [
        ("--width", args.width, &mut scene.camera.width),
        ("--height", args.height, &mut scene.camera.height),
    ] {
        if let Some(v) = value {
            check(
                v >= 1 && v as i64 <= MAX_SIDE,
                flag,
                v,
                &format!("between 1 and {MAX_SIDE} pixels"),
            )?;
            *slot = v;
        }
    }
    let pixels = scene.camera.width as i64 * scene.camera.height as i64;
    check(
        pixels <= MAX_PIXELS,
        "image size",
        format!("{}×{}", scene.camera.width, scene.camera.height),
        &format!("at most {MAX_PIXELS} pixels"),
    )?;
    if let Some(aa) = args.aa {
        check((1..=8).contains(&aa), "--aa", aa, "between 1 and 8")?;
        scene.render.aa = aa;
    }
    seed(args.seed, scene)?;
    if let Some(e) = args.epsilon {
        check(
            e.is_finite() && e >= 0.0,
            "--epsilon",
            e,
            "a finite number ≥ 0",
        )?;
        scene.render.epsilon = e;
    }
    if let Some(n) = args.interpolation {
        check(
            (1..=MAX_INTERPOLATION_STEP).contains(&n),
            "--interpolation",
            n,
            &format!("between 1 and {MAX_INTERPOLATION_STEP}"),
        )?;
        scene.render.interpolation = n;
    }
    if let Some(t) = args.interpolation_tolerance {
        check(
            t.is_finite() && t >= 0.0,
            "--interpolation-tolerance",
            t,
            "a finite number ≥ 0",
        )?;
        scene.render.interpolation_tolerance = t;
    }
    if let Some(k) = args.smoothing {
        check(
            k.is_finite() && k >= 0.0,
            "--smoothing",
            k,
            "a finite number ≥ 0",
        )?;
        scene.render.smoothing = k;
    }
    if let Some(x) = args.exposure {
        check(
            x.is_finite() && x.abs() <= 64.0,
            "--exposure",
            x,
            "between −64 and 64 stops",
        )?;
        scene.render.exposure = x;
    }
    // Output paths on the command line replace the scene's, both of them: `-o x.png` alone
    // used to write x.png and still overwrite the scene's EXR.
    if args.output.is_some() || args.exr.is_some() {
        scene.output.png = args.output.clone();
        scene.output.exr = args.exr.clone();
    }
    Ok(())
}

/// Checks, before rendering, that every output path can be written: it names a file, its
/// directory exists, it is not itself a directory, a device, a pipe nor a read-only file, no
/// path is given twice, and none is one of the command's inputs — `inputs`, or any file the
/// scene loader read ([`files_read`]: the scene, its meshes, material libraries and
/// textures), compared as canonical paths, so that `-o scene.toml` or a tile named as the
/// merged EXR is refused instead of replaced. Each write is atomic on its own, but a render
/// writes the PNG and then the EXR: without this check, an EXR path in a missing directory
/// failed only after the PNG had been replaced (exit 1 with a changed file), and the whole
/// render was wasted.
pub(super) fn check_outputs(paths: &[&Path], inputs: &[&Path]) -> Result<(), String> {
    let mut read = files_read();
    read.extend(inputs.iter().filter_map(|p| std::fs::canonicalize(p).ok()));
    for (i, path) in paths.iter().enumerate() {
        let shown = path.display();
        if path.file_name().is_none() {
            return Err(format!("{shown}: the output path does not name a file"));
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(format!(
                "{shown}: cannot write there: the directory '{}' does not exist",
                dir.display()
            ));
        }
        if path.is_dir() {
            return Err(format!("{shown}: cannot write there: it is a directory"));
        }
        if paths[..i].contains(path) {
            return Err(format!("{shown}: given as both the PNG and the EXR output"));
        }
        let target = output_target(path).map_err(|e| e.to_string())?;
        refuse_read_only(&target).map_err(|e| e.to_string())?;
        if let Ok(canonical) = std::fs::canonicalize(&target)
            && read.contains(&canonical)
        {
            return Err(format!(
                "{shown}: cannot write there: it is one of this command's inputs; name another \
                 output file"
            ));
        }
    }
    Ok(())
}

/// Checks `--crop` against the image size (after --width and --height) and the outputs: a
/// tile's files are named on the command line, never the scene's (those are the whole image's).
fn check_crop(crop: &Region, args: &RenderArgs, scene: &Scene) -> Result<(), String> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    crop.check_within(w, h).map_err(|e| {
        let from = match (args.width, args.height) {
            (None, None) => "the scene's size",
            _ => "the size after --width/--height",
        };
        format!("--crop {crop}: {e} ({from})")
    })?;
    if args.output.is_none() && args.exr.is_none() {
        return Err(format!(
            "--crop {crop}: name the tile's file with --exr OUT.exr (for `lucent merge`) or -o \
             OUT.png; the scene's [output] files are the whole image's"
        ));
    }
    Ok(())
}

fn seconds(d: std::time::Duration) -> String {
    format!("{:.2} s", d.as_secs_f64())
}

/// Fails when a pixel's radiance, exitance or irradiance is infinite or NaN: a light's
/// intensity or a material's values beyond what 32-bit floats hold. Nothing is written then,
/// rather than an image with holes in it.
fn refuse_non_finite(result: &render::Render) -> Result<(), String> {
    let bad = |p: &render::PixelValue| {
        !(p.color.is_finite() && p.exitance.is_finite() && p.irradiance.is_finite())
    };
    let count = result.pixels.iter().filter(|p| bad(p)).count();
    let Some(first) = result.pixels.iter().position(bad) else {
        return Ok(());
    };
    let region = &result.region;
    let width = (region.x1 - region.x0) as usize;
    let (x, y) = (
        region.x0 as usize + first % width,
        region.y0 as usize + first / width,
    );
    Err(format!(
        "{count} pixel(s) came out infinite or NaN, the first at ({x}, {y}): a light's \
         intensity or a material's values are too large for 32-bit floats; nothing was written"
    ))
}

/// What writing a render's outputs asks for at once, in bytes, for `pixels` pixels. The PNG
/// (8-bit copy and its compressed stream, about 6 bytes per pixel) is written and freed before
/// the EXR, whose alpha and layers are gathered from the pixels and then, like the beauty
/// image, copied channel by channel for the encoder.
fn output_bytes(pixels: usize, output: &OutputSettings) -> u64 {
    let n = pixels as u64;
    let png = if output.png.is_some() { 6 * n } else { 0 };
    let exr = if output.exr.is_some() {
        let l = &output.layers;
        let rgb_layers = [l.exitance, l.local, l.global, l.irradiance]
            .into_iter()
            .filter(|&on| on)
            .count() as u64;
        let gathered = 4 + 12 * rgb_layers + 4 * u64::from(l.depth);
        (12 + 2 * gathered) * n
    } else {
        0
    };
    png.max(exr)
}

/// `lucent render`.
pub fn render(args: &RenderArgs) -> Result<(), String> {
    let start = std::time::Instant::now();
    let mut scene = load(args.scene.as_deref(), args.threads, !args.quiet)?;
    apply(args, &mut scene)?;
    if let Some(crop) = &args.crop {
        check_crop(crop, args, &scene)?;
    }
    let outputs: Vec<&Path> = [&scene.output.png, &scene.output.exr]
        .into_iter()
        .flatten()
        .map(|p| p.as_path())
        .collect();
    let inputs: Vec<&Path> = args.samples_from.iter().map(|p| p.as_path()).collect();
    check_outputs(&outputs, &inputs)?;
    let baked = match &args.samples_from {
        Some(path) => {
            // Millions of baked samples take seconds to read and match: one phase under the
            // load's progress, its warnings printed once it is cleared.
            let (warnings, matched) = during(!args.quiet, "load", || {
                read_baked_with_provenance(path).map(|(groups, provenance)| {
                    let warnings = provenance.warnings(&scene, path);
                    (warnings, render::match_baked(&scene, groups))
                })
            })
            .map_err(|e| e.to_string())?;
            for warning in warnings {
                errln!("warning: {warning}");
            }
            Some(matched.map_err(|e| e.to_string())?)
        }
        None => None,
    };
    // Reading the scene, its meshes and textures, and any baked samples: with a large scanned
    // mesh this can outlast the render.
    let loaded = start.elapsed();
    let options = RenderOptions {
        baked: baked.as_deref(),
        progress: !args.quiet,
        warn: true,
        crop: args.crop,
        ..RenderOptions::default()
    };
    let result = render::render(&scene, &options).map_err(|e| e.to_string())?;
    refuse_non_finite(&result)?;
    memory::probe(
        output_bytes(result.pixels.len(), &scene.output),
        memory::OUTPUTS,
    )
    .map_err(|e| e.to_string())?;

    let mut written: Vec<String> = Vec::new();
    if let Some(png) = &scene.output.png {
        write_png(png, &result.image, scene.render.exposure).map_err(|e| e.to_string())?;
        written.push(png.display().to_string());
    }
    if let Some(exr) = &scene.output.exr {
        let (alpha, layers) = (result.alpha(), result.layers(&scene.output.layers));
        match args.crop {
            None => write_exr(exr, &result.image, Some(&alpha), &layers),
            Some(region) => {
                let placement = Placement {
                    display: (scene.camera.width, scene.camera.height),
                    region,
                    exposure: scene.render.exposure,
                };
                write_exr_tile(exr, &placement, &result.image, Some(&alpha), &layers)
            }
        }
        .map_err(|e| e.to_string())?;
        written.push(exr.display().to_string());
    }
    if !args.quiet {
        let s = &result.stats;
        let t = &s.timings;
        let region = &result.region;
        let crop = args.crop.map_or(String::new(), |r| {
            format!(", crop {r} ({}×{})", r.width(), r.height())
        });
        let interpolated = if scene.render.interpolation > 1 {
            format!(
                ", {} interpolated (every {} pixels)",
                s.interpolated, scene.render.interpolation
            )
        } else {
            String::new()
        };
        outln!(
            "lucent: {}×{}{crop}, {} samples{}, {}: load {}, prepare {}, sampling {}, irradiance {}, cache {}, raster {}, shading {} ({} queries{interpolated}, {:.3} points per pixel; second pass {}: {} pixels probed, {} refined, {} probes), total {}, cache {:.1} MB, {} thread{}, simd {} → {}",
            scene.camera.width,
            scene.camera.height,
            s.samples,
            s.density
                .as_ref()
                .map_or(String::new(), |d| format!(" ({})", d.describe())),
            scene.render.method.name(),
            seconds(loaded),
            seconds(t.prepare),
            seconds(t.sampling),
            seconds(t.irradiance),
            seconds(t.cache),
            seconds(t.raster),
            seconds(t.shading),
            s.queries,
            s.shading_points as f64 / region.pixels() as f64,
            seconds(t.refine),
            s.probed_pixels,
            s.refined_pixels,
            s.probes,
            seconds(start.elapsed()),
            s.cache_bytes as f64 / 1e6,
            s.threads,
            if s.threads == 1 { "" } else { "s" },
            s.simd,
            written.join(", ")
        );
    }
    Ok(())
}

/// `lucent bake`.
pub fn bake(args: &BakeArgs) -> Result<(), String> {
    let mut scene = load(args.scene.as_deref(), args.threads, !args.quiet)?;
    density(args.samples, args.spacing, args.max_samples, &mut scene)?;
    threads(args.threads, &mut scene)?;
    seed(args.seed, &mut scene)?;
    if let Some(method) = args.method {
        scene.render.method = method;
    }
    check_outputs(&[&args.output], &[])?;
    let start = std::time::Instant::now();
    let (sets, plan) =
        render::bake_planned(&scene, !args.quiet, true).map_err(|e| e.to_string())?;
    let names: Vec<String> = scene.objects.iter().map(|o| o.name.clone()).collect();
    let source = scene
        .source
        .as_ref()
        .map_or("built-in default scene".to_string(), |p| {
            p.display().to_string()
        });
    let provenance = [
        format!("scene {source}"),
        format!("seed {}", scene.render.seed),
        format!("{METHOD_COMMENT}{}", scene.render.method),
        format!(
            "{LIGHTING_COMMENT} {:016x}",
            render::lighting_digest(&scene)
        ),
    ];
    write_baked(&args.output, &sets, &names, &provenance).map_err(|e| e.to_string())?;
    if !args.quiet {
        let n: usize = sets.iter().map(|s| s.len()).sum();
        let how = plan.map_or(String::new(), |d| format!(" ({})", d.describe()));
        outln!(
            "lucent bake: {n} samples{how} on {} objects in {} → {}",
            sets.len(),
            seconds(start.elapsed()),
            args.output.display()
        );
    }
    Ok(())
}

/// `lucent presets`.
pub fn presets() -> Result<(), String> {
    outln!(
        "Measured materials of Jensen et al. 2001; coefficients per mm (scale with mm_per_unit)."
    );
    outln!(
        "{:<10} {:>22} {:>24} {:>5} {:>20}",
        "name",
        "σ_s′ R G B",
        "σ_a R G B",
        "η",
        "Rd_total R G B"
    );
    for p in &presets::PRESETS {
        let rd = Profile::from_preset(p, 1.0)
            .map_err(|e| format!("preset {}: {e}", p.name))?
            .total_reflectance();
        let [s, a] = [p.sigma_s_prime, p.sigma_a];
        outln!(
            "{:<10} {:>6.2} {:>6.2} {:>6.2}   {:>7.4} {:>7.4} {:>7.4} {:>5.2} {:>6.3} {:>6.3} {:>6.3}",
            p.name,
            s[0],
            s[1],
            s[2],
            a[0],
            a[1],
            a[2],
            p.eta,
            rd.x,
            rd.y,
            rd.z
        );
    }
    Ok(())
}

/// `lucent bench`.
#[cfg(feature = "harness")]
pub fn bench(args: &BenchArgs) -> Result<(), String> {
    if args.replot {
        let files = bench::replot(&args.output).map_err(|e| format!("bench: {e}"))?;
        if !args.quiet {
            for file in files {
                errln!("{}", file.display());
            }
        }
        return Ok(());
    }
    if args.profiles {
        let mut config = if args.quick {
            bench::ProfilesConfig::quick()
        } else {
            bench::ProfilesConfig::full()
        };
        config.threads = args.threads;
        let quiet = args.quiet;
        bench::run_profiles(&config, &args.output, &mut |line| {
            if !quiet {
                errln!("{line}");
            }
        })
        .map_err(|e| format!("bench: {e}"))?;
        return Ok(());
    }
    if args.peer {
        let mut peer = if args.quick {
            bench::PeerConfig::quick()
        } else {
            bench::PeerConfig::full()
        };
        if let Some(r) = args.resolution {
            check((16..=4096).contains(&r), "--resolution", r, "16 to 4096")?;
            peer.resolution = r;
        }
        let quiet = args.quiet;
        bench::run_peer(&peer, &args.output, &mut |line| {
            if !quiet {
                errln!("{line}");
            }
        })
        .map_err(|e| format!("bench: {e}"))?;
        return Ok(());
    }
    let mut config = if args.quick {
        BenchConfig::quick()
    } else {
        BenchConfig::full()
    };
    if !args.scenes.is_empty() {
        config.scenes = args
            .scenes
            .iter()
            .map(|name| {
                BenchScene::from_name(name).ok_or_else(|| {
                    format!(
                        "--scenes: unknown scene '{name}' (expected default, sphere or textured)"
                    )
                })
            })
            .collect::<Result<_, _>>()?;
    }
    if !args.counts.is_empty() {
        config.counts = args.counts.clone();
        if !config.counts.contains(&config.sheet_count) {
            config.sheet_count = config.counts[config.counts.len() / 2];
        }
    }
    if let Some(n) = args.seeds {
        check((1..=16).contains(&n), "--seeds", n, "1 to 16")?;
        config.seeds = (1..=u64::from(n)).collect();
    }
    if let Some(r) = args.resolution {
        config.resolution = r;
        config.end_to_end &= r == 512;
    }
    if let Some(n) = args.rounds {
        check((1..=100).contains(&n), "--rounds", n, "1 to 100")?;
        config.overhead_rounds = n;
    }
    config.threads = args.threads;
    let quiet = args.quiet;
    bench::run(&config, &args.output, &mut |line| {
        if !quiet {
            errln!("{line}");
        }
    })
    .map_err(|e| format!("bench: {e}"))?;
    Ok(())
}
