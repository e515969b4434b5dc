//! JB02's first pass: blue-noise irradiance samples over the translucent surfaces, their
//! irradiance from the lights (with shadows), and one irradiance cache per translucent object.
//!
//! One Poisson-disk set covers all translucent triangles together, so every object gets the
//! same spacing. Each sample's area is its own share of its object's surface, its cell of the
//! restricted Voronoi diagram ([`voronoi_areas`]): the areas of an object sum to its surface
//! area, and a sample that stands closer to its neighbours weighs less, so the density
//! fluctuations of the blue noise and the denser samples near a surface's border do not become
//! exitance error as they did with equal areas (total / N, as in JB02). Each sample then moves
//! to its cell's centroid (on the surface, with the normal there), so that the sum of area ×
//! integrand is exact for integrands linear over each cell rather than constant. Cells are per
//! object (a sample never takes area of another object), and so are the caches: light does not
//! diffuse from one object into another.

use glam::{Vec2, Vec3};
use lucent_core::{IrradianceCache, Sample};
use rayon::prelude::*;

use super::RenderError;
use super::prepare::Prepared;
use crate::lights::{Lighting, ShadowHints};
use crate::sampling::rng::splitmix64;
use crate::sampling::{SampleTarget, poisson_samples_with_progress, voronoi_areas};
use crate::scene::SampleDensity;

/// The samples on one translucent object.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectSamples {
    /// Index of the object in the scene.
    pub object: usize,
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit shading normals.
    pub normals: Vec<Vec3>,
    /// Areas (scene units²): each sample's cell of the restricted Voronoi diagram of its
    /// object's samples, so they sum to the object's surface area.
    pub areas: Vec<f32>,
    /// Irradiance (filled when the samples are lit).
    pub irradiance: Vec<Vec3>,
}

impl ObjectSamples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.positions.len()
    }
    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
}

/// Places blue-noise samples over every translucent object (empty if there is none).
pub fn place_samples(
    prep: &Prepared,
    density: SampleDensity,
    seed: u64,
    progress: &indicatif::ProgressBar,
) -> Result<Vec<ObjectSamples>, RenderError> {
    let objects = prep.translucent_objects();
    if objects.is_empty() {
        return Ok(Vec::new());
    }
    // The translucent triangles, and where each came from.
    let mut triangles = Vec::new();
    let mut global = Vec::new();
    for &o in &objects {
        let (a, b) = (
            prep.first_triangle[o] as usize,
            prep.first_triangle[o + 1] as usize,
        );
        triangles.extend_from_slice(&prep.triangles[a..b]);
        global.extend((a..b).map(|t| t as u32));
    }
    let target = match density {
        SampleDensity::Count(n) => SampleTarget::Count(n),
        SampleDensity::Spacing(s) => SampleTarget::Spacing(s),
    };
    let show = |done: f32| progress.set_position((done * 1000.0) as u64);
    let points = poisson_samples_with_progress(&triangles, target, seed, &show)
        .map_err(RenderError::Sampling)?;

    let mut sets: Vec<ObjectSamples> = objects
        .iter()
        .map(|&object| ObjectSamples {
            object,
            ..Default::default()
        })
        .collect();
    // Each set's samples as placed: (triangle of the object, barycentrics).
    let mut placed: Vec<Vec<(u32, Vec2)>> = vec![Vec::new(); sets.len()];
    for p in &points {
        let t = global[p.triangle as usize] as usize;
        let object = prep.object_of[t] as usize;
        let k = sets
            .iter()
            .position(|s| s.object == object)
            .expect("sample on a translucent object");
        sets[k].positions.push(p.position);
        placed[k].push((t as u32 - prep.first_triangle[object], p.bary));
    }
    drop(points);
    for (set, placed) in sets.iter_mut().zip(placed) {
        if set.is_empty() {
            continue;
        }
        let first = prep.first_triangle[set.object] as usize;
        let last = prep.first_triangle[set.object + 1] as usize;
        let cells = voronoi_areas(&prep.triangles[first..last], &set.positions);
        set.areas = cells.areas;
        let mesh = &prep.scene.objects[set.object].mesh;
        set.normals.reserve_exact(placed.len());
        for ((position, c), (triangle, bary)) in
            set.positions.iter_mut().zip(cells.centroids).zip(placed)
        {
            // Every placed sample lies on a triangle with area, so its cell has a centroid;
            // the sample stays where it was placed otherwise.
            let (triangle, bary) = if c.triangle == u32::MAX {
                (triangle, bary)
            } else {
                *position = c.position;
                (c.triangle, c.bary)
            };
            let tri = mesh.triangles[triangle as usize];
            let b = [1.0 - bary.x - bary.y, bary.x, bary.y];
            let n = (0..3).fold(Vec3::ZERO, |n, k| n + mesh.normals[tri[k] as usize] * b[k]);
            set.normals.push(n.normalize_or(Vec3::Z));
        }
    }
    sets.retain(|s| !s.is_empty());
    Ok(sets)
}

/// Irradiance at every sample (in parallel; each sample's value depends only on its index).
/// Shadow rays use each object's own occluders ([`Prepared::occluders_for`]).
pub fn light_samples(
    prep: &Prepared,
    sets: &mut [ObjectSamples],
    lighting: &Lighting,
    progress: &indicatif::ProgressBar,
) {
    for set in sets.iter_mut() {
        let lighting = lighting.with_occluders(prep.occluders_for(set.object));
        let object = set.object as u64;
        set.irradiance = set
            .positions
            .par_iter()
            .zip(&set.normals)
            .enumerate()
            .map_init(ShadowHints::default, |hints, (i, (&p, &n))| {
                let e =
                    lighting.irradiance_with(p, n, splitmix64((object << 40) ^ i as u64), hints);
                if i % 1024 == 0 {
                    progress.inc(1024);
                }
                e
            })
            .collect();
    }
}

/// Builds one cache per object's samples.
pub fn build_caches(sets: &[ObjectSamples]) -> Result<Vec<IrradianceCache>, RenderError> {
    sets.iter()
        .map(|s| build_cache(s.object, &cache_samples(s)))
        .collect()
}

/// [`build_caches`], releasing each object's samples as its cache is built, so that a render
/// never holds a set, its copy for the build and the cache at once (40 bytes per sample less at
/// the peak). Returns each cache with its object's index.
pub fn build_caches_releasing(
    sets: Vec<ObjectSamples>,
) -> Result<Vec<(usize, IrradianceCache)>, RenderError> {
    sets.into_iter()
        .map(|set| {
            let samples = cache_samples(&set);
            let object = set.object;
            drop(set);
            Ok((object, build_cache(object, &samples)?))
        })
        .collect()
}

fn cache_samples(s: &ObjectSamples) -> Vec<Sample> {
    (0..s.len())
        .map(|i| Sample {
            position: s.positions[i],
            area: s.areas[i],
            irradiance: s.irradiance[i],
        })
        .collect()
}

fn build_cache(object: usize, samples: &[Sample]) -> Result<IrradianceCache, RenderError> {
    // Samples are validated where they are made (placement, lights, the PLY reader), so what
    // the build can still reject is sums beyond f32: a scene far too large or lights far too
    // bright. That is a limit of the input, not an internal error.
    IrradianceCache::build(samples).map_err(|e| {
        RenderError::Limit(format!(
            "the irradiance samples of object {object} exceed single precision: {e} (scene too \
             large, or lights too bright?)"
        ))
    })
}
