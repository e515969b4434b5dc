//! JB02's first pass: blue-noise irradiance samples over the translucent surfaces, their
//! irradiance from the lights (with shadows), and one irradiance cache per translucent object.
//!
//! One Poisson-disk set covers all translucent triangles together, so every object gets the
//! same spacing. Each sample's area is its own share of its object's surface, its cell of the
//! restricted Voronoi diagram ([`crate::sampling::voronoi_areas`]): the areas of an object sum
//! to its surface area, and a sample that stands closer to its neighbours weighs less, so the
//! density fluctuations of the blue noise and the denser samples near a surface's border do not
//! become exitance error as they did with equal areas (total / N, as in JB02). Each sample then
//! moves to its cell's centroid (on the surface, with the normal there), so that the sum of area ×
//! integrand is exact for integrands linear over each cell rather than constant. Cells are per
//! object (a sample never takes area of another object), and so are the caches: light does not
//! diffuse from one object into another.

use std::borrow::Cow;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Vec2, Vec3};
use lucent_core::{CellAverage, IrradianceCache, LocalQuadrature, Method, Sample};
use rayon::prelude::*;

use super::RenderError;
use super::prepare::Prepared;
use crate::lights::{Lighting, ShadowHints};
use crate::memory;
use crate::sampling::rng::splitmix64;
use crate::sampling::{SampleTarget, poisson_samples_with_progress, voronoi_areas_with_progress};
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
    // The translucent triangles: the scene's own slice when the objects' runs of it follow
    // each other (one object, say), else a copy; `starts[k]` is where object k's run begins
    // among them. A copy is 36 bytes a triangle, 280 MB on a 7.8 M-triangle mesh.
    let runs: Vec<(usize, usize)> = objects
        .iter()
        .map(|&o| {
            let first = prep.first_triangle[o] as usize;
            (first, prep.first_triangle[o + 1] as usize)
        })
        .collect();
    let mut starts = Vec::with_capacity(runs.len());
    let mut count = 0;
    for &(a, b) in &runs {
        starts.push(count);
        count += b - a;
    }
    let adjacent = runs.windows(2).all(|w| w[0].1 == w[1].0);
    let triangles: Cow<[[Vec3; 3]]> = match (runs.first(), runs.last()) {
        (Some(&(first, _)), Some(&(_, last))) if adjacent => {
            Cow::Borrowed(&prep.triangles[first..last])
        }
        _ => {
            let mut copy = memory::with_capacity(count, memory::TRIANGLES)?;
            for &(a, b) in &runs {
                copy.extend_from_slice(&prep.triangles[a..b]);
            }
            Cow::Owned(copy)
        }
    };
    // The scene's index of translucent triangle `t`.
    let global = |t: usize| {
        let k = starts.partition_point(|&start| start <= t) - 1;
        runs[k].0 + (t - starts[k])
    };
    let target = match density {
        SampleDensity::Count(n) => SampleTarget::Count(n),
        SampleDensity::Spacing(s) => SampleTarget::Spacing(s),
    };
    // The bar's 1000 steps: the first half placing the samples, the second their areas (on a
    // scanned mesh of millions of triangles, the areas take the longer).
    let shown = AtomicU64::new(0);
    let show = |position: u64| {
        // The areas report from several threads: the bar only moves forward.
        if shown.fetch_max(position, Ordering::Relaxed) < position {
            progress.set_position(position);
        }
    };
    let points = poisson_samples_with_progress(&triangles, target, seed, &|done| {
        show((done.clamp(0.0, 1.0) * 500.0) as u64)
    })
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
        let t = global(p.triangle as usize);
        let object = prep.object_of[t] as usize;
        let k = sets
            .iter()
            .position(|s| s.object == object)
            .expect("sample on a translucent object");
        sets[k].positions.push(p.position);
        placed[k].push((t as u32 - prep.first_triangle[object], p.bary));
    }
    drop(points);
    drop(triangles);
    let mut areas_before = 0;
    for (set, placed) in sets.iter_mut().zip(placed) {
        if set.is_empty() {
            continue;
        }
        let first = prep.first_triangle[set.object] as usize;
        let last = prep.first_triangle[set.object + 1] as usize;
        // Each object's share of the second half: its share of the triangles.
        let share = |done: f32| {
            let triangles =
                areas_before as f64 + done.clamp(0.0, 1.0) as f64 * (last - first) as f64;
            show(500 + (500.0 * triangles / count.max(1) as f64) as u64);
        };
        let cells =
            voronoi_areas_with_progress(&prep.triangles[first..last], &set.positions, &share);
        areas_before += last - first;
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
/// Shadow rays use each object's own occluders ([`Prepared::occluders_for`]). With
/// `method.averages_edge_cells()` (edge-refined), a sample whose cell a shadow edge crosses
/// carries the mean over its cell ([`CellAverage`]).
pub fn light_samples(
    prep: &Prepared,
    sets: &mut [ObjectSamples],
    lighting: &Lighting,
    method: Method,
    progress: &indicatif::ProgressBar,
) {
    let cells = method.averages_edge_cells().then(CellAverage::new);
    for set in sets.iter_mut() {
        let lighting = lighting.with_occluders(prep.occluders_for(set.object));
        let object = set.object as u64;
        set.irradiance = set
            .positions
            .par_iter()
            .zip(&set.normals)
            .zip(&set.areas)
            .enumerate()
            .map_init(ShadowHints::default, |hints, (i, ((&p, &n), &area))| {
                let seed = splitmix64((object << 40) ^ i as u64);
                let e = lighting.irradiance_with(p, n, seed, hints);
                let e = match &cells {
                    Some(cells) => {
                        let sample = CellSample {
                            position: p,
                            normal: n,
                            area,
                            seed,
                        };
                        cell_irradiance(&lighting, cells, &sample, e, hints)
                    }
                    None => e,
                };
                if i % 1024 == 0 {
                    progress.inc(1024);
                }
                e
            })
            .collect();
    }
}

/// One sample, as the cell rule sees it.
struct CellSample {
    position: Vec3,
    normal: Vec3,
    area: f32,
    /// The sample's own light seed (the probes and nodes derive theirs from it).
    seed: u64,
}

/// `e`, the irradiance at the sample, or, where a probe of its cell differs from the sample in
/// which lights reach it ([`Lighting::reach_mask`]: a shadow's edge, a spot's cone), the mean
/// over the cell ([`CellAverage`]; `docs/physics.md` §16). Only the lights with hard shadows
/// are probed and averaged ([`Lighting::hard_only`]); the others' share of `e` is kept. The
/// probes cost one shadow ray per light each.
fn cell_irradiance(
    lighting: &Lighting,
    cells: &CellAverage,
    sample: &CellSample,
    e: Vec3,
    hints: &mut ShadowHints,
) -> Vec3 {
    let rho = CellAverage::radius(sample.area);
    if rho == 0.0 || !lighting.has_hard_lights() {
        return e;
    }
    let (t1, t2) = sample.normal.any_orthonormal_pair();
    let rotation = LocalQuadrature::rotation_for_seed(sample.seed ^ 0x00CE_11A7_E5A3);
    // Occluders within ρ/2 of a point are the surface near the sample curving up.
    let hard = lighting.hard_only().skipping(0.5 * rho);
    let point = |offset: Vec2| {
        sample.position
            + t1 * offset.x
            + t2 * offset.y
            + sample.normal * CellAverage::lift(offset, rho)
    };
    let reach = hard.reach_mask(sample.position, sample.normal, hints);
    let straddles = (0..CellAverage::PROBES).any(|k| {
        let probe = point(cells.probe(k, rho, rotation));
        hard.reach_mask(probe, sample.normal, hints) != reach
    });
    if !straddles {
        return e;
    }
    let nodes: [Vec3; CellAverage::NODES] = core::array::from_fn(|j| {
        let seed = splitmix64(sample.seed.wrapping_add((j as u64 + 1) << 48));
        hard.irradiance_with(
            point(cells.node(j, rho, rotation)),
            sample.normal,
            seed,
            hints,
        )
    });
    let mean = CellAverage::mean(&nodes);
    if lighting.has_soft_lights() {
        let at_centre = lighting.hard_only().irradiance_with(
            sample.position,
            sample.normal,
            sample.seed,
            hints,
        );
        (e - at_centre).max(Vec3::ZERO) + mean
    } else {
        mean
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Bvh;
    use crate::scene::Light;

    #[test]
    fn samples_are_placed_alike_whether_translucent_objects_are_adjacent_or_not() {
        // The translucent triangles are the scene's own slice when their objects follow each
        // other, a copy when an opaque object lies between: the same triangles in the same
        // order, so the same samples on each object.
        let object = |shape: &str, x: f32, material: &str| {
            let size = match shape {
                "sphere" => "radius = 0.5\nsegments = 24",
                _ => "size = [1.0, 1.0, 1.0]",
            };
            format!(
                "[[object]]\nname = \"{shape}{x}\"\nshape = \"{shape}\"\n{size}\n\
                 translate = [{x}, 0.0, 0.0]\nmaterial = \"{material}\"\n"
            )
        };
        let scene = |objects: [String; 3]| {
            let text = format!(
                "[camera]\nposition = [0.0, -6.0, 2.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 30.0\n{}\n\
                 [material.wax]\ntype = \"translucent\"\npreset = \"marble\"\nmm_per_unit = 10.0\n\
                 [material.m]\ntype = \"lambert\"\nalbedo = 0.5\n\
                 [[light]]\ntype = \"point\"\nposition = [0.0, 0.0, 5.0]\nintensity = 1.0\n",
                objects.concat()
            );
            let origin = crate::scene::SceneOrigin::Embedded {
                name: "test.toml".into(),
                files: Vec::new(),
            };
            crate::scene::parse_scene(&text, &origin).unwrap()
        };
        let (sphere, boxed, plate) = (
            object("sphere", 0.0, "wax"),
            object("box", 2.0, "wax"),
            object("box", -2.0, "m"),
        );
        let adjacent = scene([sphere.clone(), boxed.clone(), plate.clone()]);
        let apart = scene([sphere, plate, boxed]);
        let place = |scene: &crate::scene::Scene| {
            let prep = Prepared::new(scene).unwrap();
            let hidden = indicatif::ProgressBar::hidden();
            place_samples(&prep, SampleDensity::Count(600), 7, &hidden).unwrap()
        };
        let (a, b) = (place(&adjacent), place(&apart));
        assert_eq!(a.len(), 2);
        assert_eq!((a[0].object, a[1].object, b[1].object), (0, 1, 2));
        for (a, b) in a.iter().zip(&b) {
            assert!(a.len() > 100);
            assert_eq!(
                (&a.positions, &a.normals, &a.areas),
                (&b.positions, &b.normals, &b.areas)
            );
        }
    }

    /// An opaque plate over x < 0 at height 1, a directional light straight down: the shadow's
    /// edge on the plane z = 0 is the line x = 0.
    fn half_plane_shadow() -> (Vec<Light>, Bvh) {
        let lights = vec![Light::Directional {
            direction: -Vec3::Z,
            color: Vec3::ONE,
            irradiance: 1.0,
        }];
        let plate = Bvh::build(&crate::lights::test_plate(-5.0, 0.0, 5.0, 1.0));
        (lights, plate)
    }

    fn sample(x: f32, rho: f32, seed: u64) -> CellSample {
        CellSample {
            position: Vec3::new(x, 0.3, 0.0),
            normal: Vec3::Z,
            area: core::f32::consts::PI * rho * rho,
            seed,
        }
    }

    /// A cell the edge crosses at distance d·ρ from its sample carries the lit fraction of its
    /// disc, 1 − (θ − sin θ)/(2π) with θ = 2·acos(d) (the dark segment beyond the chord), on
    /// average over the pattern's turns; a cell the edge misses keeps its sample's value bit
    /// for bit.
    #[test]
    fn a_cell_across_a_shadow_edge_carries_its_lit_fraction() {
        let (lights, plate) = half_plane_shadow();
        let lighting = Lighting::new(&lights, Some(&plate), 10.0);
        let cells = CellAverage::new();
        let rho = 0.05;
        let mut hints = ShadowHints::default();
        for d in [-0.5f32, -0.2, 0.2, 0.5] {
            let theta = 2.0 * f64::from(d).acos();
            let lit = 1.0 - (theta - theta.sin()) / (2.0 * std::f64::consts::PI);
            let turns = 200;
            let mut sum = 0.0;
            for seed in 0..turns {
                let s = sample(d * rho, rho, seed);
                let e = lighting.irradiance(s.position, s.normal, s.seed);
                let mean = cell_irradiance(&lighting, &cells, &s, e, &mut hints);
                assert_eq!(mean.x, mean.z);
                sum += f64::from(mean.x);
            }
            let mean = sum / turns as f64;
            assert!((mean - lit).abs() < 0.03, "d = {d}: {mean} vs {lit}");
        }
        for x in [-2.0 * rho, 2.0 * rho, 1.0] {
            let s = sample(x, rho, 7);
            let e = lighting.irradiance(s.position, s.normal, s.seed);
            assert_eq!(cell_irradiance(&lighting, &cells, &s, e, &mut hints), e);
        }
    }

    /// Soft lights are neither probed nor averaged: under an environment alone every sample
    /// keeps its value; with the directional light added, a cell across the edge keeps the
    /// environment's share and averages the directional light's.
    #[test]
    fn soft_lights_keep_their_share() {
        let (mut lights, plate) = half_plane_shadow();
        let sky = Light::Environment {
            color: Vec3::splat(0.25),
            intensity: 1.0,
            map: None,
            rotation_degrees: 0.0,
            samples: 16,
        };
        let cells = CellAverage::new();
        let rho = 0.05;
        let mut hints = ShadowHints::default();
        let only_sky = [sky.clone()];
        let lighting = Lighting::new(&only_sky, Some(&plate), 10.0);
        let s = sample(0.0, rho, 3);
        let e = lighting.irradiance(s.position, s.normal, s.seed);
        assert_eq!(cell_irradiance(&lighting, &cells, &s, e, &mut hints), e);

        lights.push(sky);
        let lighting = Lighting::new(&lights, Some(&plate), 10.0);
        let s = sample(0.2 * rho, rho, 3);
        let e = lighting.irradiance(s.position, s.normal, s.seed);
        let sky_share = e - lighting
            .hard_only()
            .irradiance(s.position, s.normal, s.seed);
        let mean = cell_irradiance(&lighting, &cells, &s, e, &mut hints);
        let directional = mean - sky_share;
        assert!(
            directional.x > 0.3 && directional.x < 1.0,
            "{mean} = {sky_share} + {directional}"
        );
    }

    /// Only edge-refined averages cells; every other method keeps JB02's irradiance at the
    /// sample.
    #[test]
    fn only_edge_refined_averages() {
        for method in Method::ALL {
            assert_eq!(method.averages_edge_cells(), method == Method::EdgeRefined);
        }
    }
}
