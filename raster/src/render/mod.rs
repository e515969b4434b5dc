//! The render pipeline:
//!
//! ```text
//! scene ─ prepare ─┬─ samples (Poisson) ─ irradiance (shadow rays) ─ caches + K tables ─┐
//!                  └─ rasterise (fixed point, supersampled visibility) ───────────────────┴─ shade ─ antialias ─ image
//! ```
//!
//! Work a scene does not need is skipped: no samples, caches or tables without translucent
//! objects; no BVH or shadow rays when nothing can occlude; no K tables for the unsplit
//! methods, and table entries only for the ℓ the shading points ask for. Shading runs on a
//! rayon pool over rows; every pixel depends only on its coordinates, so the image is the same
//! for any thread count. With `aa > 1`, a second pass (`antialias`, `adaptive`) re-shades the
//! pixels whose sub-samples see different light, normals or material at one point per group of
//! alike sub-samples; it reads the first pass's image and writes only its own pixels, so it is
//! deterministic too. With `interpolation > 1` (`interpolation`), the first pass runs in bands
//! of rows, each after the grid of pixels whose exitance the band's other pixels blend from.

mod adaptive;
mod antialias;
mod attributes;
mod baked;
mod convexity;
pub mod density;
mod edge_refined;
mod error;
mod interpolation;
mod irradiance;
mod prepare;
mod progress;
mod shading;
pub mod simd;

use std::borrow::Cow;
use std::time::{Duration, Instant};

use glam::Vec3;
use lucent_core::stats::{NoStats, QueryStats};
use lucent_core::{IrradianceCache, QuerySettings};
use rayon::prelude::*;

pub use adaptive::{GroupScratch, ShadeGroup};
pub use baked::{
    LIGHTING_COMMENT, METHOD_COMMENT, OBJECT_COMMENT, Provenance, lighting_digest, match_baked,
    read_baked, read_baked_with_provenance, write_baked,
};
pub use convexity::cannot_shadow_itself;
pub use density::{DensityOrigin, DensityPlan};
pub use error::RenderError;
pub use irradiance::ObjectSamples;
pub use prepare::{Prepared, can_occlude};
pub use shading::{
    ObjectCache, PixelScratch, PixelValue, PointCounts, Shading, ShadingCounters, ShadingStats,
    UniformMaterial,
};

use crate::lights::Lighting;
use crate::material::{MaterialError, Shader};
use crate::memory;
use crate::output::image::{LAYER_EXITANCE, LAYER_GLOBAL, LAYER_IRRADIANCE, LAYER_LOCAL};
use crate::output::{Layer, Region, RgbImage};
use crate::raster::VisibilityBuffer;
use crate::scene::Scene;
use interpolation::{BAND_GRID_ROWS, ExitanceGrid, Interpolation};
use progress::bar;
pub(crate) use progress::during;

/// Options beyond the scene's own settings.
#[derive(Clone, Copy, Debug, Default)]
pub struct RenderOptions<'a> {
    /// Use these irradiance samples instead of placing and lighting new ones.
    pub baked: Option<&'a [ObjectSamples]>,
    /// Show progress on stderr: a bar on a terminal, a line every 10 s of a long phase elsewhere.
    pub progress: bool,
    /// Print the under-resolution warning ([`DensityPlan::warning`]) on stderr as soon as the
    /// sample count is known (it is in [`RenderStats::warning`] either way).
    pub warn: bool,
    /// Count traversal statistics and time the translucent shading points (slightly slower).
    pub collect_stats: bool,
    /// Compute K by quadrature at every shading point instead of the power-of-two table.
    pub exact_local_integral: bool,
    /// Compute the irradiance at every translucent shading point, even for the methods that
    /// do not need it (hierarchical, exhaustive), so that the irradiance layer is complete.
    /// Implied when the scene asks for the `irradiance` EXR layer.
    pub irradiance_layer: bool,
    /// Shade every fragment once at its representative sub-sample (coverage-only
    /// antialiasing), instead of splitting fragments whose sub-samples see different light,
    /// normals or material (the `adaptive` module). For measurements and tests.
    pub shade_once: bool,
    /// Render only this region of the image (a tile): every pixel of it is bit for bit the
    /// same pixel of the whole render. The first pass also shades a one-pixel margin around
    /// the region, which the second pass compares with; the visibility buffer holds only the
    /// pixels shading reads ([`rasterize_window`]).
    pub crop: Option<Region>,
}

/// Wall-clock time per phase.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Scene preparation (materials, BVH).
    pub prepare: Duration,
    /// Placing irradiance samples.
    pub sampling: Duration,
    /// Irradiance at the samples (shadow rays).
    pub irradiance: Duration,
    /// Building caches and local-integral tables.
    pub cache: Duration,
    /// Rasterisation.
    pub raster: Duration,
    /// Shading every pixel (both passes).
    pub shading: Duration,
    /// Of that, the second pass: probing the pixels next to a change and shading again those
    /// whose sub-samples differ.
    pub refine: Duration,
    /// Everything.
    pub total: Duration,
}

/// What a render did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Irradiance samples over all translucent objects.
    pub samples: usize,
    /// How the sample count was chosen (`None` without translucent objects).
    pub density: Option<DensityPlan>,
    /// The under-resolution warning, if the samples are too far apart for the material.
    pub warning: Option<String>,
    /// Bytes held by the irradiance caches.
    pub cache_bytes: usize,
    /// Points shaded: one per pixel and visible object in the first pass, and every point of
    /// the pixels the second pass shades again ([`RenderStats::refined_pixels`]).
    pub shading_points: u64,
    /// Translucent shading points whose exitance was queried from the cache (cache queries),
    /// both passes, the interpolation grid's included.
    pub queries: u64,
    /// Translucent shading points whose exitance was blended from the interpolation grid
    /// (`render.interpolation`), not queried.
    pub interpolated: u64,
    /// Sub-samples probed to decide where to shade more than once (one shadow ray per light
    /// each).
    pub probes: u64,
    /// Pixels probed by the second pass (their radiance differs from a neighbour's).
    pub probed_pixels: u64,
    /// Pixels shaded a second time, at more than one point per object.
    pub refined_pixels: u64,
    /// Traversal counters, if collected.
    pub traversal: Option<QueryStats>,
    /// CPU time of the translucent shading points summed over threads, if collected (see
    /// [`ShadingStats`]).
    pub translucent_time: Option<Duration>,
    /// Time per phase.
    pub timings: Timings,
    /// Threads used.
    pub threads: usize,
    /// The traversal's instruction set ([`simd::selected`]).
    pub simd: simd::Simd,
}

/// A rendered image with its layers.
#[derive(Clone, Debug)]
pub struct Render {
    /// Linear radiance of the rendered region.
    pub image: RgbImage,
    /// Per-pixel breakdown of the rendered region, row-major.
    pub pixels: Vec<PixelValue>,
    /// The rendered region of the camera's image (all of it unless
    /// [`RenderOptions::crop`]).
    pub region: Region,
    /// What it took.
    pub stats: RenderStats,
}

impl Render {
    /// Per pixel, the fraction of its coverage sub-samples that see a surface: the alpha of
    /// the beauty image, whose radiance is already weighted by it (premultiplied, as OpenEXR
    /// expects).
    pub fn alpha(&self) -> Vec<f32> {
        self.pixels.iter().map(|p| p.coverage).collect()
    }

    /// The EXR layers the scene asks for, in a fixed order.
    pub fn layers(&self, wanted: &crate::scene::ExrLayers) -> Vec<Layer> {
        let rgb = |name: &str, f: fn(&PixelValue) -> Vec3| {
            Layer::rgb(name, self.pixels.iter().map(f).collect())
        };
        let mut layers = Vec::new();
        if wanted.exitance {
            layers.push(rgb(LAYER_EXITANCE, |p| p.exitance));
        }
        if wanted.local {
            layers.push(rgb(LAYER_LOCAL, |p| p.local));
        }
        if wanted.global {
            layers.push(rgb(LAYER_GLOBAL, |p| p.global));
        }
        if wanted.irradiance {
            layers.push(rgb(LAYER_IRRADIANCE, |p| p.irradiance));
        }
        if wanted.depth {
            layers.push(Layer::depth(self.pixels.iter().map(|p| p.depth).collect()));
        }
        layers
    }
}

fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, RenderError> {
    let n = threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    rayon::ThreadPoolBuilder::new()
        .num_threads(n.max(1))
        .build()
        .map_err(RenderError::Threads)
}

/// Places and lights the irradiance samples of a scene (what `lucent bake` writes).
pub fn bake(scene: &Scene, progress: bool) -> Result<Vec<ObjectSamples>, RenderError> {
    bake_planned(scene, progress, false).map(|(sets, _)| sets)
}

/// [`bake`], also returning how the count was chosen; `warn` prints the under-resolution
/// warning (for the scene's method) on stderr.
pub fn bake_planned(
    scene: &Scene,
    progress: bool,
    warn: bool,
) -> Result<(Vec<ObjectSamples>, Option<DensityPlan>), RenderError> {
    let pool = thread_pool(scene.render.threads)?;
    pool.install(|| {
        let prep = during(progress, "prepare", || Prepared::new(scene))?;
        let plan = density::plan(&prep, &scene.render, None)?;
        warn_once(warn, plan.as_ref(), scene);
        let lighting = Lighting::new(&scene.lights, prep.occluders.as_ref(), prep.scale);
        let b = bar(progress, 1000, "sampling");
        let mut sets = match &plan {
            Some(plan) => irradiance::place_samples(&prep, plan.density(), scene.render.seed, &b)?,
            None => Vec::new(),
        };
        b.finish_and_clear();
        let total: usize = sets.iter().map(|s| s.len()).sum();
        let b = bar(progress, total as u64, "irradiance");
        irradiance::light_samples(&prep, &mut sets, &lighting, scene.render.method, &b);
        b.finish_and_clear();
        Ok((sets, plan))
    })
}

/// The under-resolution warning of a plan; printed on stderr when `print`.
fn warn_once(print: bool, plan: Option<&DensityPlan>, scene: &Scene) -> Option<String> {
    let warning = plan?.warning(scene.render.method, scene.render.smoothing)?;
    if print {
        // A closed standard error must not stop the render.
        let _ = std::io::Write::write_fmt(
            &mut std::io::stderr().lock(),
            format_args!("warning: {warning}\n"),
        );
    }
    Some(warning)
}

/// Renders a scene.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<Render, RenderError> {
    let pool = thread_pool(scene.render.threads)?;
    let threads = pool.current_num_threads();
    pool.install(|| render_in_pool(scene, options, threads))
}

fn render_in_pool(
    scene: &Scene,
    options: &RenderOptions,
    threads: usize,
) -> Result<Render, RenderError> {
    let start = Instant::now();
    let simd = simd::selected().map_err(RenderError::Simd)?;
    let mut timings = Timings::default();
    let settings = &scene.render;
    let camera = &scene.camera;
    let region = options
        .crop
        .unwrap_or(Region::full(camera.width, camera.height));
    region
        .check_within(camera.width, camera.height)
        .map_err(RenderError::Crop)?;

    let t = Instant::now();
    let prep = during(options.progress, "prepare", || Prepared::new(scene))?;
    let lighting = Lighting::new(&scene.lights, prep.occluders.as_ref(), prep.scale);
    timings.prepare = t.elapsed();

    // Irradiance samples: placed and lit here, or taken from a baked set.
    let baked_count = options
        .baked
        .map(|b| b.iter().map(ObjectSamples::len).sum());
    let plan = density::plan(&prep, settings, baked_count)?;
    let warning = warn_once(options.warn, plan.as_ref(), scene);
    let sets: Cow<[ObjectSamples]> = match (options.baked, &plan) {
        (Some(baked), _) => {
            baked::check_fits(&prep, baked)?;
            Cow::Borrowed(baked)
        }
        (None, None) => Cow::Owned(Vec::new()),
        (None, Some(plan)) => {
            let t = Instant::now();
            let b = bar(options.progress, 1000, "sampling");
            let mut sets = irradiance::place_samples(&prep, plan.density(), settings.seed, &b)?;
            b.finish_and_clear();
            timings.sampling = t.elapsed();
            let t = Instant::now();
            let total: usize = sets.iter().map(|s| s.len()).sum();
            let b = bar(options.progress, total as u64, "irradiance");
            irradiance::light_samples(&prep, &mut sets, &lighting, scene.render.method, &b);
            b.finish_and_clear();
            timings.irradiance = t.elapsed();
            Cow::Owned(sets)
        }
    };
    let sample_count: usize = sets.iter().map(|s| s.len()).sum();
    let (area, count) = sets
        .iter()
        .flat_map(|s| &s.areas)
        .fold((0.0, 0usize), |(a, n), &x| (a + f64::from(x), n + 1));

    // Caches, and K tables for the split methods.
    let t = Instant::now();
    let method = settings.method;
    let built = match sets {
        Cow::Borrowed(baked) => baked
            .iter()
            .map(|s| s.object)
            .zip(irradiance::build_caches(baked)?)
            .collect(),
        Cow::Owned(sets) => irradiance::build_caches_releasing(sets)?,
    };
    let mut caches: Vec<Option<ObjectCache>> = (0..scene.objects.len()).map(|_| None).collect();
    let query_settings = QuerySettings {
        method,
        epsilon: settings.epsilon,
        cull_tolerance: settings.cull_tolerance,
    };
    let mut cache_bytes = 0;
    let local_term = |object: usize, alpha: f32| match prep.shader_of(object) {
        Shader::Translucent(shader) if method.is_split() && alpha > 0.0 => {
            let ell_min = settings.ell_min.unwrap_or(alpha / 1024.0);
            shader
                .local_term(alpha, ell_min)
                .map(Some)
                .map_err(|e| MaterialError::Params {
                    material: shader.name.clone(),
                    source: e,
                })
                .map_err(RenderError::Material)
        }
        _ => Ok(None),
    };
    let translucent_shader = |object: usize| match prep.shader_of(object) {
        Shader::Translucent(shader) => Some(&**shader),
        _ => None,
    };
    for (object, cache) in built {
        let alpha = cache.smoothing_radius(settings.smoothing);
        let local = local_term(object, alpha)?;
        cache_bytes += cache.memory_bytes();
        caches[object] = Some(ObjectCache::new(
            cache,
            alpha,
            local,
            translucent_shader(object),
            &query_settings,
        )?);
    }
    // A translucent object far smaller than the sample spacing can receive no sample at all.
    // It gets an empty cache and the smoothing radius of the shared spacing: the split methods
    // shade it with their local term alone, E(x)·K (the Lambertian limit when α ≫ ℓ), the
    // unsplit ones with no subsurface light. (Without this, shading it failed with "internal
    // error: no irradiance cache".)
    let spacing_area = if count > 0 {
        (area / count as f64) as f32
    } else {
        0.0
    };
    for object in prep.translucent_objects() {
        if caches[object].is_none() {
            let alpha = settings.smoothing * spacing_area.sqrt();
            caches[object] = Some(ObjectCache::new(
                IrradianceCache::build(&[]).map_err(RenderError::Cache)?,
                alpha,
                local_term(object, alpha)?,
                translucent_shader(object),
                &query_settings,
            )?);
        }
    }
    timings.cache = t.elapsed();

    // The second pass compares each pixel with its eight neighbours' first-pass values, so
    // the first pass covers a one-pixel margin around the region.
    let refine = scene.render.aa > 1 && !options.shade_once;
    let shaded = region.grown(u32::from(refine), camera.width, camera.height);
    let interpolation = (settings.interpolation > 1 && !prep.translucent_objects().is_empty())
        .then_some(Interpolation {
            step: settings.interpolation,
            tolerance: settings.interpolation_tolerance,
        });

    // Rasterise every object, into the pixels shading reads: the shaded ones, and with
    // interpolation the grid pixels up to a step beyond them.
    let t = Instant::now();
    let read = shaded.grown(
        interpolation.map_or(0, |i| i.step),
        camera.width,
        camera.height,
    );
    let (visibility, view_proj) = rasterize_window(&prep, read)?;
    timings.raster = t.elapsed();

    // Shade.
    let t = Instant::now();
    let shading = Shading {
        prep: &prep,
        lighting,
        caches,
        settings: query_settings,
        exact_local_integral: options.exact_local_integral,
        irradiance_everywhere: options.irradiance_layer || scene.output.layers.irradiance,
        camera,
        view_proj,
        visibility: &visibility,
    };
    let b = bar(options.progress, u64::from(shaded.height()), "shading");
    // With interpolation, the image is shaded in bands of grid rows, each after its grid.
    let band_rows = match interpolation {
        Some(i) => i.step * BAND_GRID_ROWS,
        None => shaded.height(),
    }
    .max(1);
    let row_width = shaded.width().max(1) as usize;
    // Shaded in place, one row per task: a single buffer, touched once (fresh pages cost a
    // fault each; rows gathered into a second buffer doubled that).
    let mut pixels = memory::filled(
        shaded.pixels() as usize,
        PixelValue::default(),
        memory::PIXELS,
    )?;
    let mut counters = ShadingCounters::default();
    let (mut shading_points, mut queries, mut interpolated) = (0, 0, 0);
    let (mut probes, mut probed_pixels, mut refined_pixels) = (0, 0, 0);
    for (band, y0) in pixels
        .chunks_mut(band_rows as usize * row_width)
        .zip((shaded.y0..shaded.y1).step_by(band_rows as usize))
    {
        let y1 = (y0 + band_rows).min(shaded.y1);
        let grid = match interpolation {
            Some(settings) => {
                let rows = Region { y0, y1, ..shaded };
                let (grid, cost) =
                    ExitanceGrid::build(&shading, settings, rows, options.collect_stats)?;
                counters.add(&cost.stats);
                queries += cost.queries;
                Some(grid)
            }
            None => None,
        };
        let rows: Vec<Result<Row, RenderError>> = band
            .par_chunks_mut(row_width)
            .zip(y0..y1)
            // One scratch per rayon job, not per row: its buffers and the last triangle's
            // set-up are reused along the job's rows (the values do not depend on it).
            .map_init(PixelScratch::default, |scratch, (out, y)| {
                let mut row = Row::default();
                let before = scratch.points;
                for (x, slot) in (shaded.x0..shaded.x1).zip(out.iter_mut()) {
                    *slot = match (&grid, options.collect_stats) {
                        (Some(g), true) => {
                            shading.pixel_interpolated(x, y, g, scratch, &mut row.stats)?
                        }
                        (Some(g), false) => {
                            shading.pixel_interpolated(x, y, g, scratch, &mut NoStats)?
                        }
                        (None, true) => shading.pixel(x, y, scratch, &mut row.stats)?,
                        (None, false) => shading.pixel(x, y, scratch, &mut NoStats)?,
                    };
                    row.points += scratch.groups.groups.len() as u64;
                }
                row.queries = scratch.points.queried - before.queried;
                row.interpolated = scratch.points.interpolated - before.interpolated;
                b.inc(1);
                Ok(row)
            })
            .collect();
        for row in rows {
            let row = row?;
            counters.add(&row.stats);
            shading_points += row.points;
            queries += row.queries;
            interpolated += row.interpolated;
        }
    }
    b.finish_and_clear();
    // Second pass: where the shading varies within a pixel, more points.
    if refine {
        let t = Instant::now();
        let refined =
            antialias::refine(&shading, &mut pixels, shaded, region, options.collect_stats)?;
        counters.add(&refined.stats);
        shading_points += refined.points;
        queries += refined.queries;
        probes = refined.probes;
        refined_pixels = refined.reshaded;
        probed_pixels = refined.flagged;
        timings.refine = t.elapsed();
    }
    counters.traversal.queries = queries;
    timings.shading = t.elapsed();
    timings.total = start.elapsed();

    let pixels = if shaded == region {
        pixels
    } else {
        region.cut(&shaded, &pixels)
    };
    let image = RgbImage::from_pixels(
        region.width(),
        region.height(),
        pixels.iter().map(|p| p.color).collect(),
    )
    .map_err(RenderError::Image)?;
    Ok(Render {
        image,
        pixels,
        region,
        stats: RenderStats {
            samples: sample_count,
            density: plan,
            warning,
            cache_bytes,
            shading_points,
            queries,
            interpolated,
            probes,
            probed_pixels,
            refined_pixels,
            traversal: options.collect_stats.then_some(counters.traversal),
            translucent_time: options.collect_stats.then_some(counters.translucent_time),
            timings,
            threads,
            simd,
        },
    })
}

/// Rasterises every object of a prepared scene into the supersampled visibility buffer; also
/// returns the world → clip transform used. Triangle ids are indices into
/// [`Prepared::triangles`].
pub fn rasterize(prep: &Prepared) -> Result<(VisibilityBuffer, glam::Mat4), RenderError> {
    let camera = &prep.scene.camera;
    rasterize_window(prep, Region::full(camera.width, camera.height))
}

/// [`rasterize`] into a buffer that holds only the pixels of `window` (a tile and what its
/// shading reads), each with the bits the whole image's buffer has there.
pub fn rasterize_window(
    prep: &Prepared,
    window: Region,
) -> Result<(VisibilityBuffer, glam::Mat4), RenderError> {
    let scene = prep.scene;
    let camera = &scene.camera;
    let (near, far) = depth_range(prep, camera);
    let view_proj = camera.view_projection(near, far);
    let mut visibility =
        VisibilityBuffer::new_window(camera.width, camera.height, scene.render.aa, window)
            .map_err(RenderError::Raster)?;
    for (i, object) in scene.objects.iter().enumerate() {
        visibility.rasterize_mesh(
            view_proj,
            &object.mesh.positions,
            &object.mesh.triangles,
            prep.first_triangle[i],
        );
    }
    Ok((visibility, view_proj))
}

/// What shading one row cost.
#[derive(Default)]
struct Row {
    stats: ShadingCounters,
    points: u64,
    queries: u64,
    interpolated: u64,
}

/// Near and far planes that enclose the scene: far beyond the farthest corner, near as far out
/// as possible (depth precision) but never beyond the nearest geometry.
fn depth_range(prep: &Prepared, camera: &crate::camera::Camera) -> (f32, f32) {
    let forward = (camera.target - camera.position).normalize_or(Vec3::NEG_Z);
    let (mut lo, mut hi) = (f32::INFINITY, 0.0_f32);
    for v in prep.triangles.iter().flatten() {
        let d = (*v - camera.position).dot(forward);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let far = (hi * 1.01).max(1e-3);
    let near = if lo > 0.0 {
        (lo * 0.5).max(far * 1e-5)
    } else {
        far * 1e-4
    };
    (near, far)
}
