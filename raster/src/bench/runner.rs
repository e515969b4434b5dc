//! Running one benchmark configuration: render it once per seed, take the median time per
//! phase, and measure every error metric against the ground truth.
//!
//! Times are wall clock per phase ([`Timings`]) as the renderer reports them. "CPU per
//! lookup" is the time of the translucent shading points (attributes, material, E(x) where the
//! method needs it, the query, the radiance) summed over threads, per lookup; the whole
//! shading phase per lookup, which also charges the opaque pixels to the lookups, is kept
//! beside it.

use std::time::Duration;

use glam::Vec3;
use lucent_core::stats::QueryStats;

use super::BenchError;
use super::scenes::BenchScene;
use crate::output::{
    ErrorStats, NoiseStats, RgbImage, compare, default_band_radius, seed_noise, shadow_edge_band,
    translucent_mask,
};
use crate::render::{ObjectSamples, Render, RenderOptions, Timings, render};
use crate::scene::{SampleDensity, Scene};
use lucent_core::Method;

/// One method with its settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodSetting {
    /// The method.
    pub method: Method,
    /// JB02 ε of the global (or whole) sum.
    pub epsilon: f32,
}

impl MethodSetting {
    /// `hierarchical eps=0.5`, `edge-aware`, … as in tables and legends (ASCII: the plot
    /// font has no ε).
    pub fn label(&self) -> String {
        match self.method {
            Method::Hierarchical => format!("hierarchical eps={}", self.epsilon),
            Method::Exhaustive => "exhaustive".to_string(),
            m => m.name().to_string(),
        }
    }
}

/// What a reference render provides to every comparison: its image and the regions.
pub struct Reference {
    /// The reference image.
    pub image: RgbImage,
    /// Its exitance per pixel.
    pub exitance: Vec<Vec3>,
    /// Translucent pixels (from its exitance).
    pub translucent: Vec<bool>,
    /// The shadow-edge band (from its irradiance); may select no pixel.
    pub band: Vec<bool>,
    /// Samples it was rendered with.
    pub samples: usize,
    /// Its total render time.
    pub time: Duration,
}

impl Reference {
    /// Takes a render made with the irradiance layer on.
    pub fn new(r: Render) -> Result<Reference, BenchError> {
        let (width, height) = r.image.size();
        let exitance: Vec<Vec3> = r.pixels.iter().map(|p| p.exitance).collect();
        let irradiance: Vec<Vec3> = r.pixels.iter().map(|p| p.irradiance).collect();
        let translucent = translucent_mask(&exitance);
        if !translucent.contains(&true) {
            return Err(BenchError::new(
                "the reference render shows no translucent pixel",
            ));
        }
        let band = shadow_edge_band(
            &irradiance,
            &translucent,
            width,
            height,
            default_band_radius(width, height),
        )?;
        Ok(Reference {
            image: r.image,
            exitance,
            translucent,
            band,
            samples: r.stats.samples,
            time: r.stats.timings.total,
        })
    }

    /// Errors of `image` over the translucent pixels and (if any) the edge band.
    pub fn errors(&self, image: &RgbImage) -> Result<(ErrorStats, Option<ErrorStats>), BenchError> {
        let all = compare(image, &self.image, Some(&self.translucent))?;
        let edge = if self.band.contains(&true) {
            Some(compare(image, &self.image, Some(&self.band))?)
        } else {
            None
        };
        Ok((all, edge))
    }
}

/// The measured outcome of one configuration.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// The scene.
    pub scene: BenchScene,
    /// Method and ε.
    pub setting: MethodSetting,
    /// Samples asked for.
    pub samples: u32,
    /// The smoothing factor k (α = k·√Ā) of the split methods.
    pub smoothing: f32,
    /// Samples placed (first seed).
    pub placed: usize,
    /// Renders (one per seed).
    pub renders: usize,
    /// Median time per phase over the seeds.
    pub timings: Timings,
    /// Worker threads.
    pub threads: usize,
    /// Translucent lookups per render.
    pub queries: u64,
    /// CPU time of the translucent shading points (median over the seeds).
    pub translucent_time: Duration,
    /// Traversal counters of the first seed.
    pub traversal: QueryStats,
    /// Cache bytes (first seed).
    pub cache_bytes: usize,
    /// Error over translucent pixels (first seed against the reference).
    pub error: ErrorStats,
    /// Error in the shadow-edge band, if the reference has one.
    pub edge_error: Option<ErrorStats>,
    /// Seed noise over translucent pixels, with two or more seeds.
    pub noise: Option<NoiseStats>,
}

impl RunResult {
    /// CPU per lookup in µs: the time of the translucent shading points (surface attributes,
    /// material, E(x) where the method needs it, the query, the radiance; see
    /// [`ShadingStats`](crate::render::ShadingStats)) summed over threads, per lookup. The
    /// opaque pixels of the image are not charged to it.
    pub fn cpu_us_per_lookup(&self) -> f64 {
        if self.queries == 0 {
            return 0.0;
        }
        self.translucent_time.as_secs_f64() / self.queries as f64 * 1e6
    }

    /// The whole shading phase (wall × threads, opaque pixels included) per lookup, in µs.
    pub fn shading_us_per_lookup(&self) -> f64 {
        if self.queries == 0 {
            return 0.0;
        }
        self.timings.shading.as_secs_f64() * self.threads as f64 / self.queries as f64 * 1e6
    }

    /// Nodes opened per lookup.
    pub fn nodes_per_lookup(&self) -> f64 {
        per(self.traversal.nodes_opened, self.traversal.queries)
    }

    /// Profile evaluations (aggregates + samples) per lookup.
    pub fn evaluations_per_lookup(&self) -> f64 {
        per(self.traversal.profile_evaluations(), self.traversal.queries)
    }
}

fn per(n: u64, d: u64) -> f64 {
    if d == 0 { 0.0 } else { n as f64 / d as f64 }
}

/// The median of some durations (mean of the middle two for an even count).
pub fn median(mut d: Vec<Duration>) -> Duration {
    if d.is_empty() {
        return Duration::ZERO;
    }
    d.sort();
    let n = d.len();
    if n % 2 == 1 {
        d[n / 2]
    } else {
        (d[n / 2 - 1] + d[n / 2]) / 2
    }
}

/// The median of each phase.
pub fn median_timings(all: &[Timings]) -> Timings {
    let m = |f: fn(&Timings) -> Duration| median(all.iter().map(f).collect());
    Timings {
        prepare: m(|t| t.prepare),
        sampling: m(|t| t.sampling),
        irradiance: m(|t| t.irradiance),
        cache: m(|t| t.cache),
        raster: m(|t| t.raster),
        shading: m(|t| t.shading),
        refine: m(|t| t.refine),
        total: m(|t| t.total),
    }
}

/// The scene set up for one render.
pub fn configure(base: &Scene, setting: MethodSetting, samples: u32, seed: u64) -> Scene {
    let mut scene = base.clone();
    scene.render.method = setting.method;
    scene.render.epsilon = setting.epsilon;
    scene.render.samples = SampleDensity::Count(samples).into();
    scene.render.seed = seed;
    scene
}

/// Renders with traversal statistics (and the irradiance layer when `reference_layers`), from
/// `baked` samples instead of placing and lighting new ones when given.
pub fn render_once(
    scene: &Scene,
    reference_layers: bool,
    baked: Option<&[ObjectSamples]>,
) -> Result<Render, BenchError> {
    let options = RenderOptions {
        collect_stats: true,
        irradiance_layer: reference_layers,
        baked,
        ..RenderOptions::default()
    };
    Ok(render(scene, &options)?)
}

/// Renders one configuration for every seed and measures it. Returns the result and the
/// first seed's render (for figures).
pub fn run_config(
    base: &Scene,
    scene: BenchScene,
    setting: MethodSetting,
    samples: u32,
    seeds: &[u64],
    reference: &Reference,
) -> Result<(RunResult, Render), BenchError> {
    let mut renders = Vec::with_capacity(seeds.len());
    for &seed in seeds {
        renders.push(render_once(
            &configure(base, setting, samples, seed),
            false,
            None,
        )?);
    }
    let first = &renders[0];
    let (error, edge_error) = reference.errors(&first.image)?;
    let noise = if renders.len() >= 2 {
        let images: Vec<&RgbImage> = renders.iter().map(|r| &r.image).collect();
        Some(seed_noise(&images, Some(&reference.translucent))?)
    } else {
        None
    };
    let timings: Vec<Timings> = renders.iter().map(|r| r.stats.timings).collect();
    let result = RunResult {
        scene,
        setting,
        samples,
        smoothing: base.render.smoothing,
        placed: first.stats.samples,
        renders: renders.len(),
        timings: median_timings(&timings),
        threads: first.stats.threads,
        queries: first.stats.queries,
        translucent_time: median(
            renders
                .iter()
                .map(|r| r.stats.translucent_time.unwrap_or_default())
                .collect(),
        ),
        traversal: first.stats.traversal.unwrap_or_default(),
        cache_bytes: first.stats.cache_bytes,
        error,
        edge_error,
        noise,
    };
    let first = renders.swap_remove(0);
    Ok((result, first))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_of_odd_and_even_counts() {
        let ms = |v: &[u64]| median(v.iter().map(|&x| Duration::from_millis(x)).collect());
        assert_eq!(ms(&[5, 1, 3]), Duration::from_millis(3));
        assert_eq!(ms(&[4, 1, 3, 10]), Duration::from_micros(3500));
        assert_eq!(ms(&[]), Duration::ZERO);
    }

    #[test]
    fn a_render_against_itself_has_zero_error_and_the_reference_finds_its_edge() {
        let base = BenchScene::Sphere.load(48).unwrap();
        let setting = MethodSetting {
            method: Method::EdgeAware,
            epsilon: 0.5,
        };
        let truth = render_once(&configure(&base, setting, 1500, 1), true, None).unwrap();
        let reference = Reference::new(truth).unwrap();
        assert!(
            reference.band.contains(&true),
            "the sphere's shadow edge is found"
        );
        let (result, first) = run_config(
            &base,
            BenchScene::Sphere,
            setting,
            1500,
            &[1, 2],
            &reference,
        )
        .unwrap();
        assert_eq!(first.image.pixels(), reference.image.pixels());
        assert_eq!(result.error.rmse, 0.0);
        assert_eq!(result.edge_error.map(|e| e.rmse), Some(0.0));
        let noise = result.noise.unwrap();
        assert!(noise.rms > 0.0, "another seed moves the samples: {noise:?}");
        assert!(result.queries > 0 && result.evaluations_per_lookup() > 0.0);
        assert!(result.cpu_us_per_lookup() > 0.0);
        // The translucent points are part of the shading phase, which also shades the floor.
        assert!(
            result.cpu_us_per_lookup() < result.shading_us_per_lookup(),
            "{} vs {}",
            result.cpu_us_per_lookup(),
            result.shading_us_per_lookup()
        );
    }
}
