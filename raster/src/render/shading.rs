//! Shading one pixel: one shading point per visible surface (the representative sub-sample of
//! each fragment group), or more where its sub-samples see different light, normals or
//! material ([`super::adaptive`]), each weighted by its coverage.
//!
//! - Translucent: the material at the point, E(x) by shadow rays (split methods, highlights),
//!   one cache query, then radiance by the convention of
//!   `docs/physics.md` §17, plus an optional Fresnel-weighted
//!   normalised Blinn–Phong highlight.
//! - Lambert: L = albedo / π · E(x).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{Mat4, Vec2, Vec3};
use lucent_core::internals::fresnel;
use lucent_core::stats::{NoStats, QueryStats, StatsSink};
use lucent_core::{
    Exitance, IrradianceCache, LocalQuadrature, LocalTerm, QuadratureLayout, QueryPlan,
    QuerySettings, ShadingPoint,
};

use super::RenderError;
use super::adaptive::GroupScratch;
use super::attributes::{SurfaceAttributes, TriangleSetup};
use super::edge_refined::{self, RefinePoint};
use super::interpolation::{Block, ExitanceGrid};
use super::prepare::Prepared;
use crate::camera::Camera;
use crate::lights::{Lighting, ShadowHints};
use crate::material::{LocalIntegral, MaterialError, PointMaterial, Shader, TranslucentShader};
use crate::raster::{Fragment, VisibilityBuffer};
use crate::sampling::rng::splitmix64;

/// A translucent object's cache and smoothing.
#[derive(Debug)]
pub struct ObjectCache {
    /// The irradiance cache of the object's samples.
    pub cache: IrradianceCache,
    /// Smoothing radius α = k √Ā.
    pub alpha: f32,
    /// Where K comes from (split methods only).
    pub local: Option<LocalIntegral>,
    /// K when the material does not vary over the surface: computed once here by quadrature
    /// ([`LocalIntegral::exact`]), so it carries no table interpolation error and costs no
    /// lookup at the shading points (a table lookup cost about 6% of a lookup on the sphere).
    pub uniform_k: Option<LocalTerm>,
    /// The edge-refined quadrature when the material does not vary.
    pub quadrature: Option<LocalQuadrature>,
    /// When the material varies: the edge-refined quadrature's layout, which each refined
    /// point's own quadrature is built on.
    pub quadrature_layout: Option<QuadratureLayout>,
    /// When the material does not vary over the surface: the material, and the query's checks
    /// and constants done once ([`IrradianceCache::plan`]) instead of at every shading point.
    pub uniform: Option<UniformMaterial>,
    /// When the material varies over the surface: a plan of its base profile, whose settings
    /// checks and cache scales each shading point reuses ([`IrradianceCache::replan`]).
    pub textured_plan: Option<QueryPlan>,
    /// Unique among the caches of the process: names this cache's plan in a thread's scratch.
    id: u64,
}

/// The next [`ObjectCache`]'s id.
static NEXT_CACHE_ID: AtomicU64 = AtomicU64::new(0);

/// A material that does not vary over the surface, resolved once for an object.
#[derive(Clone, Copy, Debug)]
pub struct UniformMaterial {
    /// The material (the same at every point).
    pub point: PointMaterial,
    /// The query's plan for it on the object's cache.
    pub plan: QueryPlan,
}

impl ObjectCache {
    /// The object's cache, smoothing radius and local term; K is computed once, exactly, and
    /// the query planned once ([`ObjectCache::uniform`]) for a material that does not vary.
    pub fn new(
        cache: IrradianceCache,
        alpha: f32,
        local: Option<LocalIntegral>,
        shader: Option<&TranslucentShader>,
        settings: &QuerySettings,
    ) -> Result<ObjectCache, RenderError> {
        let (uniform_k, quadrature) = match (&local, shader) {
            (Some(term), Some(shader)) if !shader.is_textured() => {
                let point = shader.at(Vec2::ZERO).map_err(|e| {
                    RenderError::Material(MaterialError::Params {
                        material: shader.name.clone(),
                        source: e,
                    })
                })?;
                (
                    Some(term.exact(&point)),
                    Some(edge_refined::quadrature(&point.profile, alpha)),
                )
            }
            _ => (None, None),
        };
        let uniform = match shader {
            Some(shader) if !shader.is_textured() => {
                let local = match (&local, uniform_k) {
                    (Some(_), Some(term)) => Some(term),
                    (None, _) => Some(LocalTerm::NONE),
                    (Some(_), None) => None,
                };
                // A plan the settings or K reject is not made: every point then reports the
                // error itself, as without a plan.
                match (local, shader.at(Vec2::ZERO)) {
                    (Some(local), Ok(point)) => cache
                        .plan(&point.profile, local, settings)
                        .ok()
                        .map(|plan| UniformMaterial { point, plan }),
                    _ => None,
                }
            }
            _ => None,
        };
        let textured_plan = match shader {
            Some(shader) if shader.is_textured() => {
                let base = shader.base_profile();
                let local = match &local {
                    Some(_) => LocalTerm::exact(base, alpha).ok(),
                    None => Some(LocalTerm::NONE),
                };
                local.and_then(|local| cache.plan(base, local, settings).ok())
            }
            _ => None,
        };
        Ok(ObjectCache {
            cache,
            alpha,
            local,
            uniform_k,
            quadrature,
            quadrature_layout: shader
                .filter(|s| s.is_textured())
                .map(|_| edge_refined::layout(alpha)),
            uniform,
            textured_plan,
            id: NEXT_CACHE_ID.fetch_add(1, Ordering::Relaxed),
        })
    }
}

/// A texture-mapped material's working values, kept by a thread and re-made in place at each
/// point ([`TranslucentShader::at_into`], [`IrradianceCache::replan_into`]) rather than built
/// anew and moved: they are a few hundred bytes.
#[derive(Clone, Debug)]
pub(crate) struct TexturedScratch {
    /// The [`ObjectCache`] they belong to.
    cache_id: u64,
    /// The material at the point.
    point: PointMaterial,
    /// The query plan at the point (from the object's template).
    plan: Option<QueryPlan>,
}

/// Everything a pixel's value is made of (coverage-weighted sums over its surfaces).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelValue {
    /// Outgoing radiance.
    pub color: Vec3,
    /// Translucent exitance M_o.
    pub exitance: Vec3,
    /// Local term of the split.
    pub local: Vec3,
    /// Global term.
    pub global: Vec3,
    /// Irradiance at the shading points.
    pub irradiance: Vec3,
    /// Distance along the view axis to the nearest surface (+∞ for none).
    pub depth: f32,
    /// The fraction of the pixel's coverage sub-samples that see a surface (the EXR's alpha).
    pub coverage: f32,
}

impl Default for PixelValue {
    fn default() -> Self {
        PixelValue {
            color: Vec3::ZERO,
            exitance: Vec3::ZERO,
            local: Vec3::ZERO,
            global: Vec3::ZERO,
            irradiance: Vec3::ZERO,
            depth: f32::INFINITY,
            coverage: 0.0,
        }
    }
}

/// What shading records: the traversal events, and (when [`ShadingStats::TIMED`]) the CPU time
/// of every translucent shading point, from the clock read around it.
///
/// The time is what the benchmark's "CPU per lookup" divides: a lookup is the whole translucent
/// point (surface attributes, material, E(x) where the method needs it, the cache query, the
/// radiance), and the opaque pixels of the same image are not charged to it. The two clock
/// readings are included in the time: about 20 ns each with the TSC clock source, several
/// times that on some virtual machines (`lucent bench --peer` measures them).
pub trait ShadingStats: StatsSink {
    /// Whether translucent points are timed.
    const TIMED: bool;
    /// Adds the time one translucent point took.
    #[inline(always)]
    fn translucent_time(&mut self, _elapsed: Duration) {}
}

impl ShadingStats for NoStats {
    const TIMED: bool = false;
}

/// Traversal counters and translucent shading time, accumulated over any number of pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShadingCounters {
    /// The cache traversals' events.
    pub traversal: QueryStats,
    /// CPU time spent on translucent shading points.
    pub translucent_time: Duration,
}

impl ShadingCounters {
    /// Adds another set of counters (a row's, a band's, a pass's) to these.
    pub fn add(&mut self, other: &ShadingCounters) {
        self.traversal.merge(&other.traversal);
        self.translucent_time += other.translucent_time;
    }
}

impl StatsSink for ShadingCounters {
    #[inline(always)]
    fn node(&mut self) {
        self.traversal.node();
    }
    #[inline(always)]
    fn aggregates(&mut self, n: u32) {
        self.traversal.aggregates(n);
    }
    #[inline(always)]
    fn samples(&mut self, n: u32) {
        self.traversal.samples(n);
    }
    #[inline(always)]
    fn culled(&mut self, n: u32) {
        self.traversal.culled(n);
    }
    #[inline]
    fn merge(&mut self, counts: &QueryStats) {
        self.traversal.merge(counts);
    }
}

impl ShadingStats for ShadingCounters {
    const TIMED: bool = true;
    #[inline(always)]
    fn translucent_time(&mut self, elapsed: Duration) {
        self.translucent_time += elapsed;
    }
}

/// One thread's working memory for [`Shading::pixel`].
#[derive(Clone, Debug, Default)]
pub struct PixelScratch {
    /// The pixel's fragments.
    pub fragments: Vec<Fragment>,
    /// Shadow-ray hints, kept from pixel to pixel.
    pub shadows: ShadowHints,
    /// The pixel's shading points (its fragments, split where the shading varies).
    pub groups: GroupScratch,
    /// The last triangle's shared attributes, kept from pixel to pixel.
    pub(crate) triangle: TriangleSetup,
    /// The last texture-mapped material's point and plan, re-made in place at each point.
    pub(crate) textured: Option<TexturedScratch>,
    /// Translucent points shaded with this scratch so far, by where their exitance came from.
    pub points: PointCounts,
}

/// Translucent shading points by where their exitance came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PointCounts {
    /// A cache query.
    pub queried: u64,
    /// Blended from the interpolation grid's points.
    pub interpolated: u64,
}

/// The read-only state every pixel is shaded from.
pub struct Shading<'a> {
    /// The prepared scene.
    pub prep: &'a Prepared<'a>,
    /// Lights and occluders.
    pub lighting: Lighting<'a>,
    /// Per object: its cache, if translucent.
    pub caches: Vec<Option<ObjectCache>>,
    /// Method, ε and cull tolerance (α is per object).
    pub settings: QuerySettings,
    /// Use a fresh quadrature for K at every point instead of the table (for measuring the
    /// table's error).
    pub exact_local_integral: bool,
    /// Compute E(x) at translucent points even when the method does not use it (for the
    /// irradiance layer).
    pub irradiance_everywhere: bool,
    /// The camera.
    pub camera: &'a Camera,
    /// World → clip.
    pub view_proj: Mat4,
    /// The rasterised visibility.
    pub visibility: &'a VisibilityBuffer,
}

impl Shading<'_> {
    /// Shades pixel (x, y) once per visible object. `scratch` is one thread's working memory,
    /// best kept along a row (its shadow-ray hints); the value does not depend on it.
    pub fn pixel<S: ShadingStats>(
        &self,
        x: u32,
        y: u32,
        scratch: &mut PixelScratch,
        stats: &mut S,
    ) -> Result<PixelValue, RenderError> {
        self.resolve_whole(x, y, scratch);
        self.shade_points(x, y, None, scratch, stats)
    }

    /// Pixel (x, y)'s fragments into `scratch`, one unsplit shading point each.
    fn resolve_whole(&self, x: u32, y: u32, scratch: &mut PixelScratch) {
        self.resolve(x, y, &mut scratch.fragments);
        scratch.groups.whole(&scratch.fragments);
    }

    /// Pixel (x, y)'s fragments, keyed by object, into `fragments`.
    pub(super) fn resolve(&self, x: u32, y: u32, fragments: &mut Vec<Fragment>) {
        let object_of = &self.prep.object_of;
        self.visibility
            .resolve(x, y, |t| object_of[t as usize], fragments);
    }

    /// [`Shading::pixel`], with the exitance blended from `grid` where it may be.
    pub(super) fn pixel_interpolated<S: ShadingStats>(
        &self,
        x: u32,
        y: u32,
        grid: &ExitanceGrid,
        scratch: &mut PixelScratch,
        stats: &mut S,
    ) -> Result<PixelValue, RenderError> {
        self.resolve_whole(x, y, scratch);
        self.shade_points(x, y, Some(grid), scratch, stats)
    }

    /// Shades pixel (x, y) at the points in `scratch.groups` (from [`Shading::pixel`], or
    /// split by [`Shading::split_pixel`]), each weighted by its coverage.
    pub fn shade<S: ShadingStats>(
        &self,
        x: u32,
        y: u32,
        scratch: &mut PixelScratch,
        stats: &mut S,
    ) -> Result<PixelValue, RenderError> {
        self.shade_points(x, y, None, scratch, stats)
    }

    /// [`Shading::shade`]; with a grid, a point that is a grid pixel's reuses its kept
    /// result, and one whose block allows it is blended ([`super::interpolation`]).
    fn shade_points<S: ShadingStats>(
        &self,
        x: u32,
        y: u32,
        grid: Option<&ExitanceGrid>,
        scratch: &mut PixelScratch,
        stats: &mut S,
    ) -> Result<PixelValue, RenderError> {
        let mut value = PixelValue::default();
        let aa = self.visibility.aa();
        let per_sample = 1.0 / (aa * aa) as f32;
        let forward = (self.camera.target - self.camera.position).normalize();
        let groups = std::mem::take(&mut scratch.groups.groups);
        for group in &groups {
            let fragment = &group.fragment;
            let seed = group.seed(self.point_seed(x, y, group.source));
            let translucent = self.caches[fragment.key as usize].is_some();
            // Only a whole fragment covering the pixel takes part: the grid holds no other.
            let grid = grid.filter(|_| translucent && group.part == 0 && self.is_full(fragment));
            let s = match grid.and_then(|g| g.kept(x, y, fragment)) {
                Some(node) => node.surface,
                None => {
                    let block = grid.and_then(|g| g.block(x, y, fragment));
                    let s = self.timed_surface(fragment, seed, scratch, block.as_ref(), stats)?;
                    if translucent {
                        scratch.points.queried += u64::from(!s.interpolated);
                        scratch.points.interpolated += u64::from(s.interpolated);
                    }
                    s
                }
            };
            let w = fragment.coverage as f32 * per_sample;
            value.color += s.color * w;
            value.exitance += s.exitance * w;
            value.local += s.local * w;
            value.global += s.global * w;
            value.irradiance += s.irradiance * w;
            value.coverage += w;
            if group.source == 0 && group.part == 0 {
                value.depth = (s.position - self.camera.position).dot(forward);
            }
        }
        scratch.groups.groups = groups;
        Ok(value)
    }

    /// The seed of the shading point of pixel (x, y)'s fragment `source`, before any split
    /// ([`super::adaptive::ShadeGroup::seed`]).
    pub(super) fn point_seed(&self, x: u32, y: u32, source: usize) -> u64 {
        let pixel_index = y as u64 * self.camera.width as u64 + x as u64;
        splitmix64(pixel_index * 16 + source as u64)
    }

    /// True if `fragment` covers its whole pixel.
    pub(super) fn is_full(&self, fragment: &Fragment) -> bool {
        let aa = self.visibility.aa();
        fragment.coverage == aa * aa
    }

    /// [`Shading::surface`], timed for the statistics when it is translucent.
    pub(super) fn timed_surface<S: ShadingStats>(
        &self,
        fragment: &Fragment,
        seed: u64,
        scratch: &mut PixelScratch,
        block: Option<&Block>,
        stats: &mut S,
    ) -> Result<Surface, RenderError> {
        let timed = S::TIMED && self.caches[fragment.key as usize].is_some();
        let start = timed.then(Instant::now);
        let s = self.surface(
            fragment,
            seed,
            &mut scratch.shadows,
            &mut scratch.triangle,
            &mut scratch.textured,
            block,
            stats,
        )?;
        if let Some(start) = start {
            stats.translucent_time(start.elapsed());
        }
        Ok(s)
    }

    fn surface<S: ShadingStats>(
        &self,
        fragment: &Fragment,
        seed: u64,
        shadows: &mut ShadowHints,
        triangle: &mut TriangleSetup,
        textured: &mut Option<TexturedScratch>,
        block: Option<&Block>,
        stats: &mut S,
    ) -> Result<Surface, RenderError> {
        let prep = self.prep;
        let object = fragment.key as usize;
        let SurfaceAttributes {
            position,
            normal,
            geometric,
            uv,
            view,
        } = self.attributes_on(object, fragment.triangle, fragment.sample, triangle);
        let cos_out = outgoing_cosine(normal, geometric, view);
        let mut out = Surface {
            position,
            normal,
            ..Surface::default()
        };
        let lighting = self.lighting.with_occluders(prep.occluders_for(object));
        match prep.shader_of(object) {
            Shader::Lambert { albedo } => {
                let e = lighting.irradiance_with(position, normal, seed, shadows);
                out.irradiance = e;
                out.color = *albedo * e * std::f32::consts::FRAC_1_PI;
            }
            Shader::Translucent(shader) => {
                let oc = self.caches[object].as_ref().ok_or_else(|| {
                    RenderError::Core(format!("no irradiance cache for object {object}"))
                })?;
                // K by quadrature at every point (a measurement option) bypasses the plan.
                let uniform = oc.uniform.as_ref().filter(|_| !self.exact_local_integral);
                let (point, textured_plan) = match uniform {
                    Some(u) => (&u.point, None),
                    None => {
                        let scratch = match textured {
                            Some(t) if t.cache_id == oc.id => t,
                            _ => textured.insert(TexturedScratch {
                                cache_id: oc.id,
                                point: PointMaterial {
                                    profile: *shader.base_profile(),
                                    kd: None,
                                },
                                plan: oc.textured_plan,
                            }),
                        };
                        shader.at_into(uv, &mut scratch.point).map_err(|e| {
                            RenderError::Material(MaterialError::Params {
                                material: shader.name.clone(),
                                source: e,
                            })
                        })?;
                        (&scratch.point, scratch.plan.as_mut())
                    }
                };
                let method = self.settings.method;
                let blended = block.and_then(|b| b.blend(position, normal));
                let mut e = Vec3::ZERO;
                let mut highlight = Vec3::ZERO;
                if (method.is_split() && blended.is_none())
                    || shader.specular.is_some()
                    || self.irradiance_everywhere
                {
                    lighting.for_each(position, normal, seed, shadows, |incident| {
                        e += incident.irradiance;
                        if let Some(spec) = shader.specular {
                            let h = (incident.direction + view).normalize_or_zero();
                            let n_h = normal.dot(h).max(0.0);
                            let f = fresnel::reflectance(
                                point.profile.eta() as f64,
                                view.dot(h).clamp(0.0, 1.0) as f64,
                            ) as f32;
                            let lobe = (spec.exponent + 8.0) / (8.0 * std::f32::consts::PI)
                                * n_h.powf(spec.exponent);
                            highlight += incident.irradiance * (spec.strength * f * lobe);
                        }
                    });
                }
                // The query, unless the exitance is blended from the grid.
                let m = match blended {
                    Some(m) => m,
                    None => {
                        let query = PointQuery {
                            object: oc,
                            shader,
                            uniform,
                            point,
                            position,
                            normal,
                            irradiance: e,
                            seed,
                        };
                        self.query(&query, textured_plan, &lighting, shadows, stats)?
                    }
                };
                out.exitance = m.total;
                out.local = m.local;
                out.global = m.global;
                out.irradiance = e;
                out.color = point.profile.radiance(m.total, cos_out) + highlight;
                out.interpolated = blended.is_some();
            }
        }
        Ok(out)
    }

    /// The exitance at a translucent point by its cache query, refined at shadow edges
    /// ([`edge_refined`]) where the query asks for it. `textured_plan` is re-made for the
    /// point's material when the object has no uniform one.
    fn query<S: ShadingStats>(
        &self,
        q: &PointQuery,
        textured_plan: Option<&mut QueryPlan>,
        lighting: &Lighting,
        shadows: &mut ShadowHints,
        stats: &mut S,
    ) -> Result<Exitance, RenderError> {
        let PointQuery {
            object: oc,
            shader,
            point,
            position,
            ..
        } = *q;
        let shading_point = ShadingPoint {
            position,
            irradiance: q.irradiance,
        };
        let material_error = |e| {
            RenderError::Material(MaterialError::Params {
                material: shader.name.clone(),
                source: e,
            })
        };
        let (local, m) = match q.uniform {
            Some(u) => (
                u.plan.local(),
                super::simd::query_planned(&oc.cache, &u.plan, &shading_point, stats),
            ),
            None => {
                let local = match (&oc.local, oc.uniform_k) {
                    (Some(_), _) if self.exact_local_integral => {
                        LocalTerm::exact(&point.profile, oc.alpha).map_err(material_error)?
                    }
                    (Some(_), Some(term)) => term,
                    (Some(source), None) => source.lookup(point),
                    (None, _) => LocalTerm::NONE,
                };
                let m = match textured_plan {
                    Some(plan) => {
                        oc.cache
                            .replan_into(plan, &point.profile, local)
                            .and_then(|()| {
                                super::simd::query_planned(&oc.cache, plan, &shading_point, stats)
                            })
                    }
                    None => super::simd::query(
                        &oc.cache,
                        &point.profile,
                        &shading_point,
                        local,
                        &self.settings,
                        stats,
                    ),
                };
                (local, m)
            }
        };
        let m = m.map_err(|source| RenderError::Query { position, source })?;
        if !m.refine {
            return Ok(m);
        }
        let quadrature = match (&oc.quadrature, &oc.quadrature_layout) {
            (Some(quadrature), _) => *quadrature,
            (None, Some(layout)) => LocalQuadrature::with_layout(&point.profile, layout),
            (None, None) => edge_refined::quadrature(&point.profile, oc.alpha),
        };
        let at = RefinePoint {
            position,
            normal: q.normal,
            irradiance: q.irradiance,
            local,
            seed: q.seed,
        };
        Ok(edge_refined::refine(lighting, &quadrature, &at, shadows, m))
    }
}

/// A translucent point's inputs to its cache query.
struct PointQuery<'p> {
    /// The object's cache, smoothing radius and local-term sources.
    object: &'p ObjectCache,
    /// The object's material (for its name in errors).
    shader: &'p TranslucentShader,
    /// The object's material and plan where they are the same at every point.
    uniform: Option<&'p UniformMaterial>,
    /// The material at the point.
    point: &'p PointMaterial,
    /// Position x.
    position: Vec3,
    /// Unit shading normal at x.
    normal: Vec3,
    /// E(x), where the method uses it.
    irradiance: Vec3,
    /// The point's seed.
    seed: u64,
}

/// The cosine of the outgoing direction for the Fresnel transmittance F_t(η, cos θ_o).
///
/// The camera sees the triangle's front, so the geometric normal (turned towards the camera)
/// has a positive cosine wherever a pixel is covered; the interpolated shading normal need not:
/// at silhouettes and creases it can face away, and its cosine, clamped to 0, made F_t = 0 and
/// the pixel black although light leaves the surface there. The shading normal's cosine is
/// used where it is larger, so smooth meshes keep smooth Fresnel falloff, and the geometric
/// cosine bounds it from below. Both terms are continuous over a triangle, so their maximum is
/// too.
fn outgoing_cosine(shading: Vec3, geometric: Vec3, view: Vec3) -> f32 {
    shading.dot(view).max(geometric.dot(view)).clamp(0.0, 1.0)
}

/// What one shading point contributes.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Surface {
    pub position: Vec3,
    /// The shading normal (unit, towards the camera).
    pub normal: Vec3,
    pub color: Vec3,
    pub exitance: Vec3,
    pub local: Vec3,
    pub global: Vec3,
    pub irradiance: Vec3,
    /// The exitance was blended from the grid ([`super::interpolation`]), not queried.
    pub interpolated: bool,
}

#[cfg(test)]
mod tests {
    use std::borrow::Cow;

    use lucent_core::internals::fresnel;
    use lucent_core::{Distance, Profile};

    use super::*;
    use crate::render::irradiance::build_caches;
    use crate::render::{RenderOptions, bake, render};
    use crate::scene::{Material, Medium, SceneOrigin, TranslucentMaterial, parse_scene};
    use lucent_core::internals::UnitDipole;
    use lucent_core::internals::local_integral_unit;

    /// K by a quadrature of its own for each channel of `profile` (the definition, not the
    /// table's code path).
    fn quadrature_k(profile: &lucent_core::Profile, alpha: f32) -> Vec3 {
        let eta = f64::from(profile.eta());
        Vec3::from(profile.dipoles().expect("a classical dipole").map(|d| {
            let a = f64::from(alpha) / f64::from(d.mean_free_path());
            local_integral_unit(&UnitDipole::new(d.albedo(), eta), a) as f32
        }))
    }

    /// A uniform material's K in the object cache is the quadrature to f32 rounding, not the
    /// table's interpolation (which differs from it by more here).
    #[test]
    fn uniform_k_is_the_quadrature() {
        let shader = match Shader::new(&Material::Translucent(TranslucentMaterial {
            name: "marble".into(),
            medium: Medium::Preset {
                name: "marble".into(),
                mm_per_unit: 10.0,
            },
            model: lucent_core::ProfileModel::default(),
            specular: None,
        }))
        .unwrap()
        {
            Shader::Translucent(t) => *t,
            Shader::Lambert { .. } => unreachable!(),
        };
        let profile = shader.at(Vec2::ZERO).unwrap().profile;
        let ell = profile.mean_free_path();
        for alpha in [0.01_f32, 0.03, 0.05, 0.2] {
            let local = shader.local_term(alpha, alpha / 1024.0).unwrap();
            let LocalIntegral::Single(table) = &local else {
                panic!("a preset has one table")
            };
            let interpolated = table.lookup(ell);
            let oc = ObjectCache::new(
                IrradianceCache::build(&[]).unwrap(),
                alpha,
                Some(local),
                Some(&shader),
                &QuerySettings::default(),
            )
            .unwrap();
            let got = oc.uniform_k.expect("uniform material");
            assert_eq!(got.alpha(), alpha);
            let got = got.k();
            let want = quadrature_k(&profile, alpha);
            let error = ((got - want) / want).abs().max_element();
            assert!(error <= f32::EPSILON, "α {alpha}: K {got} vs {want}");
            assert!(
                ((interpolated - want) / want).abs().max_element() > 1e-5,
                "α {alpha}: the table's {interpolated} is no test of exactness"
            );
        }
    }

    /// End to end: a uniformly lit marble plane's `local` layer is E·K with K by quadrature
    /// at the render's own smoothing radius (from the same baked samples).
    #[test]
    fn lit_plane_local_layer_is_e_times_exact_k() {
        let text = r#"
[camera]
position = [0.0, 0.0, 30.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 2.0
width = 8
height = 8

[[object]]
name = "slab"
shape = "plane"
size = [4.0, 4.0]
material = "marble"

[material.marble]
type = "translucent"
preset = "marble"
mm_per_unit = 10.0

[[light]]
type = "directional"
direction = [0.0, 0.0, -1.0]
irradiance = 2.0

[render]
method = "local-global"
samples = 8000
aa = 1
"#;
        let scene = parse_scene(
            text,
            &SceneOrigin::Embedded {
                name: "plane.toml".into(),
                files: Vec::new(),
            },
        )
        .unwrap();
        let sets = bake(&scene, false).unwrap();
        let alpha = build_caches(&sets).unwrap()[0].smoothing_radius(scene.render.smoothing);
        let Shader::Translucent(shader) = Shader::new(&scene.materials[0]).unwrap() else {
            panic!("marble is translucent")
        };
        let profile = shader.at(Vec2::ZERO).unwrap().profile;
        let k = quadrature_k(&profile, alpha);
        let r = render(
            &scene,
            &RenderOptions {
                baked: Some(&sets),
                ..RenderOptions::default()
            },
        )
        .unwrap();
        for p in &r.pixels {
            assert!(
                (p.irradiance - Vec3::splat(2.0)).abs().max_element() < 1e-4,
                "E {}",
                p.irradiance
            );
            let want = p.irradiance * k;
            assert!(
                ((p.local - want) / want).abs().max_element() <= 2.0 * f32::EPSILON,
                "local {} vs E·K {want} (α {alpha})",
                p.local
            );
        }
    }

    #[test]
    fn the_outgoing_cosine_is_positive_on_every_visible_surface() {
        let view = Vec3::Z;
        let facing = Vec3::Z;
        // A shading normal that faces away (a silhouette): the geometric cosine stands in.
        let away = Vec3::new(0.9, 0.0, -0.3).normalize();
        let tilted = Vec3::new(0.6, 0.0, 0.8);
        assert_eq!(outgoing_cosine(away, tilted, view), 0.8);
        // Where the shading normal sees the camera better, it is used (smooth falloff).
        assert_eq!(outgoing_cosine(facing, tilted, view), 1.0);
        assert_eq!(outgoing_cosine(tilted, facing, view), 1.0);
    }

    /// A lit translucent square facing the camera whose vertex normals all face away from
    /// it (as at a coarse mesh's silhouette): its radiance must be F_t at the cosine of the
    /// surface the camera sees, not 0.
    #[test]
    fn shading_normals_facing_away_do_not_blacken_a_visible_surface() {
        let (nx, nz) = (100f32.to_radians().sin(), 100f32.to_radians().cos());
        let obj = format!(
            "v -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\nvn {nx} 0 {nz}\n\
             f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"
        );
        let text = r#"
[camera]
position = [0.0, 0.0, 30.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov = 10.0
width = 12
height = 12

[[object]]
name = "square"
obj = "square.obj"
material = "wax"

[material.wax]
type = "translucent"
kd = [0.5, 0.3, 0.15]
mean_free_path = 0.5
eta = 1.4

[[light]]
type = "directional"
direction = [-0.9, 0.0, -0.43588989]
irradiance = 2.0

[render]
method = "edge-aware"
samples = 20000
aa = 1
"#;
        let scene = parse_scene(
            text,
            &SceneOrigin::Embedded {
                name: "square.toml".into(),
                files: vec![("square.obj".into(), Cow::Owned(obj.into_bytes()))],
            },
        )
        .unwrap();
        let r = render(&scene, &RenderOptions::default()).unwrap();
        let profile = Profile::from_reflectance(
            Vec3::new(0.5, 0.3, 0.15),
            Distance::MeanFreePath(Vec3::splat(0.5)),
            1.4,
        )
        .unwrap();
        // The camera is 30 units away and the view 5 units across: every pixel sees the
        // square within 5° of its normal, where F_t differs from normal incidence by < 0.1%.
        assert!(
            (fresnel::transmittance(1.4, 5f32.to_radians().cos())
                / fresnel::transmittance(1.4, 1.0)
                - 1.0)
                .abs()
                < 1e-3
        );
        for p in &r.pixels {
            assert!(p.exitance.min_element() > 0.0, "exitance {}", p.exitance);
            let want = profile.radiance(p.exitance, 1.0);
            let error = ((p.color - want).abs() / want).max_element();
            assert!(error < 2e-3, "color {} vs {want}", p.color);
        }
    }
}
