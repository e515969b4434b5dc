//! Light sources and the irradiance they deliver to a surface point, with shadow rays
//! (`docs/physics.md` §5).
//!
//! Units: point, spot and sphere lights have a radiant intensity I (W/sr, times `color`), so an
//! unoccluded surface at distance d facing the light receives E = I/d²; a directional light
//! gives E = irradiance × cos θ. A sphere light of radius r has radiance L = I/(π r²), which
//! makes it deliver the same E as a point light of intensity I when fully visible; its soft
//! shadows come from `samples` stratified directions in the cone it subtends, each traced.
//! A rect light of area A has radiance L = I/A (I its intensity along its normal), and is
//! sampled at stratified points on its area (`lights/rect.rs`); an environment is a radiance at
//! infinity, constant or a lat-long map, sampled by cosine-weighted or luminance-importance
//! directions (`lights/environment.rs`, [`EnvironmentMap`]). Every area light draws its `samples`
//! variates from the same stratified square ([`strata`]), rotated per point by a hash.
//!
//! Shadow rays start off the surface (see [`offset_origin`]) and test every triangle of the
//! scene through the BVH; a scene where nothing can occlude passes `None` and traces nothing.

use glam::{Vec2, Vec3};

use crate::geometry::{Bvh, ShadowHint, offset_origin};
use crate::sampling::rng::splitmix64;
use crate::sampling::{StratifiedSquare, stratified_square};
use crate::scene::Light;

mod environment;
mod envmap;
mod rect;

pub use envmap::{EnvironmentMap, MapSample, luminance};
pub use rect::{RectFrame, rect_frame};

/// One light's contribution at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incident {
    /// Unit direction from the point towards the light (the cone axis for sphere lights).
    pub direction: Vec3,
    /// Irradiance from this light (cosine and visibility included).
    pub irradiance: Vec3,
}

/// The scene's lights with what they need to cast shadows.
#[derive(Clone, Copy, Debug)]
pub struct Lighting<'a> {
    lights: &'a [Light],
    occluders: Option<&'a Bvh>,
    /// Scene size, for the shadow-ray offset.
    scale: f32,
    /// How far along each shadow ray occluders are ignored (see [`Lighting::skipping`]).
    skip: f32,
    /// Only the lights with hard shadows (see [`Lighting::hard_only`]).
    hard_only: bool,
    /// Whether `lights` holds a light with hard shadows, and one with soft shadows: asked per
    /// sample and per edge-refined node, so counted once here.
    any_hard: bool,
    any_soft: bool,
}

/// What one thread remembers between shadow rays: the last occluder of each of the first
/// [`ShadowHints::LIGHTS`] lights' rays, tested first by the next ray (see
/// [`Bvh::occluded_hinted`]). Neighbouring points in a row are usually shadowed by the same
/// triangle. A hint never changes an answer, only its cost, so images stay the same for any
/// thread count and any order.
#[derive(Clone, Copy, Debug, Default)]
pub struct ShadowHints {
    per_light: [ShadowHint; ShadowHints::LIGHTS],
}

impl ShadowHints {
    /// Lights with a hint of their own (the rays of later lights start without one).
    pub const LIGHTS: usize = 8;
}

/// Lights whose shadows are soft (penumbrae), left out by [`Lighting::hard_only`].
fn is_soft(light: &Light) -> bool {
    matches!(
        light,
        Light::Sphere { .. } | Light::Rect { .. } | Light::Environment { .. }
    )
}

/// 1 − small, so that a shadow ray stops just short of a light it aims at.
const SHORTEN: f32 = 1.0 - 1e-4;

impl<'a> Lighting<'a> {
    /// Lights, the occluders (`None`: nothing can cast a shadow) and the scene's size.
    pub fn new(lights: &'a [Light], occluders: Option<&'a Bvh>, scale: f32) -> Self {
        Lighting {
            lights,
            occluders,
            scale,
            skip: 0.0,
            hard_only: false,
            any_hard: lights.iter().any(|l| !is_soft(l)),
            any_soft: lights.iter().any(is_soft),
        }
    }

    /// The same lighting with only the lights whose shadows have hard edges: point, spot and
    /// directional lights (a spot's cone is soft, its shadows are not). Sphere, rect and
    /// environment lights are left out: their penumbrae are smooth at the scale of a sample's
    /// cell or the smoothing radius, and each of their estimates costs `samples` rays. The
    /// edge-refined method refines only what these lights deliver.
    pub fn hard_only(self) -> Self {
        Lighting {
            hard_only: true,
            ..self
        }
    }

    /// True if some light's shadows have hard edges ([`Lighting::hard_only`] keeps it).
    pub fn has_hard_lights(&self) -> bool {
        self.any_hard
    }

    /// True if some light is left out by [`Lighting::hard_only`].
    pub fn has_soft_lights(&self) -> bool {
        self.any_soft
    }

    /// The same lights with shadow rays that ignore occluders within `distance` of the point
    /// (0, negative or not finite: none ignored): as if the point moved that far towards each
    /// light, without moving where the ray meets anything farther away. The edge-refined
    /// nodes use it to step over the crease of a concave surface they lie under.
    pub fn skipping(self, distance: f32) -> Self {
        let skip = if distance.is_finite() && distance > 0.0 {
            distance
        } else {
            0.0
        };
        Lighting { skip, ..self }
    }

    /// Lights that [`Lighting::reach_mask`] reports on (later ones are ignored there).
    pub const MASK_LIGHTS: usize = 32;

    /// The same lights with other occluders (e.g. without the triangles of the object the
    /// rays leave, when it cannot shadow itself).
    pub fn with_occluders(self, occluders: Option<&'a Bvh>) -> Self {
        Lighting { occluders, ..self }
    }

    /// True if nothing can cast shadows (no shadow rays are traced).
    pub fn unshadowed(&self) -> bool {
        self.occluders.is_none()
    }

    fn visible(&self, p: Vec3, n: Vec3, dir: Vec3, t_max: f32, hint: &mut ShadowHint) -> bool {
        match self.occluders {
            None => true,
            Some(bvh) => {
                // Leave from the side the light is on.
                let side = if n.dot(dir) >= 0.0 { n } else { -n };
                if t_max <= self.skip {
                    return true;
                }
                let origin = offset_origin(p, side, self.scale) + dir * self.skip;
                !bvh.occluded_hinted(origin, dir, t_max - self.skip, hint)
            }
        }
    }

    /// Total irradiance at `p` on a surface with unit normal `n`. `seed` decorrelates the
    /// area-light strata between points (deterministically).
    pub fn irradiance(&self, p: Vec3, n: Vec3, seed: u64) -> Vec3 {
        self.irradiance_with(p, n, seed, &mut ShadowHints::default())
    }

    /// [`Lighting::irradiance`] with a thread's shadow-ray hints (same answer, faster along a
    /// row of neighbouring points).
    pub fn irradiance_with(&self, p: Vec3, n: Vec3, seed: u64, hints: &mut ShadowHints) -> Vec3 {
        let mut e = Vec3::ZERO;
        self.for_each(p, n, seed, hints, |i| e += i.irradiance);
        e
    }

    /// Calls `f` with each light's contribution at `p` (lights that deliver nothing are
    /// skipped); `hints` as for [`Lighting::irradiance_with`].
    pub fn for_each(
        &self,
        p: Vec3,
        n: Vec3,
        seed: u64,
        hints: &mut ShadowHints,
        mut f: impl FnMut(Incident),
    ) {
        for (index, light) in self.lights.iter().enumerate() {
            if self.hard_only && is_soft(light) {
                continue;
            }
            let mut spare = ShadowHint::NONE;
            let hint = hints.per_light.get_mut(index).unwrap_or(&mut spare);
            let incident = match *light {
                Light::Point {
                    position,
                    color,
                    intensity,
                } => self.point(p, n, position, color * intensity, 1.0, hint),
                Light::Spot {
                    position,
                    direction,
                    inner_angle_degrees,
                    outer_angle_degrees,
                    color,
                    intensity,
                } => {
                    let to_p = (p - position).normalize_or_zero();
                    let cos = to_p.dot(direction);
                    let (ci, co) = (
                        inner_angle_degrees.to_radians().cos(),
                        outer_angle_degrees.to_radians().cos(),
                    );
                    let falloff = smoothstep(co, ci, cos);
                    if falloff <= 0.0 {
                        continue;
                    }
                    self.point(p, n, position, color * intensity, falloff, hint)
                }
                Light::Directional {
                    direction,
                    color,
                    irradiance,
                } => {
                    let dir = -direction;
                    let cos = n.dot(dir);
                    if cos <= 0.0 || !self.visible(p, n, dir, f32::MAX, hint) {
                        continue;
                    }
                    Some(Incident {
                        direction: dir,
                        irradiance: color * (irradiance * cos),
                    })
                }
                Light::Sphere {
                    center,
                    radius,
                    color,
                    intensity,
                    samples,
                } => self.sphere(
                    p,
                    n,
                    center,
                    radius,
                    color * intensity,
                    samples,
                    splitmix64(seed ^ index as u64),
                    hint,
                ),
                Light::Rect {
                    center,
                    normal,
                    right,
                    up_axis,
                    size,
                    color,
                    intensity,
                    samples,
                } => self.rect(
                    p,
                    n,
                    &RectFrame {
                        center,
                        normal,
                        right,
                        up: up_axis,
                        size,
                    },
                    color * intensity,
                    samples,
                    splitmix64(seed ^ index as u64),
                    hint,
                ),
                Light::Environment {
                    color,
                    intensity,
                    ref map,
                    rotation_degrees,
                    samples,
                } => self.environment(
                    p,
                    n,
                    color * intensity,
                    map.as_deref(),
                    rotation_degrees,
                    samples,
                    splitmix64(seed ^ index as u64),
                    hint,
                ),
            };
            if let Some(i) = incident {
                f(i);
            }
        }
    }

    /// Which of the first [`Lighting::MASK_LIGHTS`] lights reach `p` on a surface with unit
    /// normal `n`, one bit each (bit `i` for light `i`), from one shadow ray per light: the
    /// light faces the surface, `p` is inside a spot's outer cone, and the ray is unoccluded
    /// (a sphere or rect light's ray aims at its centre; an environment's follows the normal). Cheaper than [`Lighting::for_each`] (one ray
    /// per sphere light instead of its `samples`); it tells apart points on either side of a
    /// shadow edge, not how much light arrives.
    pub fn reach_mask(&self, p: Vec3, n: Vec3, hints: &mut ShadowHints) -> u32 {
        let mut mask = 0;
        for (index, light) in self.lights.iter().enumerate().take(Self::MASK_LIGHTS) {
            if self.hard_only && is_soft(light) {
                continue;
            }
            let mut spare = ShadowHint::NONE;
            let hint = hints.per_light.get_mut(index).unwrap_or(&mut spare);
            let towards = |target: Vec3, stop_short: f32, hint: &mut ShadowHint| {
                let to = target - p;
                let d = to.length();
                let dir = to / d;
                d > stop_short
                    && n.dot(dir) > 0.0
                    && self.visible(p, n, dir, (d - stop_short) * SHORTEN, hint)
            };
            let reaches = match *light {
                Light::Point { position, .. } => towards(position, 0.0, hint),
                Light::Spot {
                    position,
                    direction,
                    inner_angle_degrees,
                    outer_angle_degrees,
                    ..
                } => {
                    let cos = (p - position).normalize_or_zero().dot(direction);
                    let falloff = smoothstep(
                        outer_angle_degrees.to_radians().cos(),
                        inner_angle_degrees.to_radians().cos(),
                        cos,
                    );
                    falloff > 0.0 && towards(position, 0.0, hint)
                }
                Light::Directional { direction, .. } => {
                    let dir = -direction;
                    n.dot(dir) > 0.0 && self.visible(p, n, dir, f32::MAX, hint)
                }
                Light::Sphere { center, radius, .. } => {
                    // Inside the light counts as lit, as in `sphere`.
                    (center - p).length() <= radius || towards(center, radius, hint)
                }
                Light::Rect { center, normal, .. } => {
                    (p - center).dot(normal) > 0.0 && towards(center, 0.0, hint)
                }
                // The ray along the normal: open sky above the point or not.
                Light::Environment { .. } => self.visible(p, n, n, f32::MAX, hint),
            };
            if reaches {
                mask |= 1 << index;
            }
        }
        mask
    }

    fn point(
        &self,
        p: Vec3,
        n: Vec3,
        position: Vec3,
        intensity: Vec3,
        falloff: f32,
        hint: &mut ShadowHint,
    ) -> Option<Incident> {
        let to_light = position - p;
        let d2 = to_light.length_squared();
        if !(d2 > 0.0) {
            return None;
        }
        let d = d2.sqrt();
        let dir = to_light / d;
        let cos = n.dot(dir);
        if cos <= 0.0 || !self.visible(p, n, dir, d * SHORTEN, hint) {
            return None;
        }
        Some(Incident {
            direction: dir,
            irradiance: intensity * (falloff * cos / d2),
        })
    }

    /// Stratified directions uniform in the cone subtended by the sphere; each is traced.
    #[allow(clippy::too_many_arguments)]
    fn sphere(
        &self,
        p: Vec3,
        n: Vec3,
        center: Vec3,
        radius: f32,
        intensity: Vec3,
        samples: u32,
        seed: u64,
        hint: &mut ShadowHint,
    ) -> Option<Incident> {
        let to_center = center - p;
        let d2 = to_center.length_squared();
        let d = d2.sqrt();
        if !(d > radius) {
            // Inside the light: treat as fully lit from the centre direction.
            return self.point(p, n, center, intensity, 1.0, hint);
        }
        let axis = to_center / d;
        let sin2_max = ((radius / d) * (radius / d)).min(1.0);
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        // 1 − cos θ_max without cancellation: in f32, 1 − cos θ_max of a light 10⁻³ of its
        // distance across came out twice too large (or 0 below that).
        let one_minus_cos_max = sin2_max / (1.0 + cos_max);
        // Radiance I/(π r²) times the cone's solid angle 2π(1 − cos θ_max)
        // = 2π r²/(d²(1 + cos θ_max)): the r² cancel, so a vanishing radius gives the point
        // light's I/d² instead of ∞ · 0.
        let radiance_times_solid_angle = intensity * (2.0 / (d2 * (1.0 + cos_max)));
        let (t, b) = axis.any_orthonormal_pair();
        let mut sum = 0.0;
        let count = samples.max(1);
        for u in strata(count, seed) {
            // 1 − cos α, and sin²α = (1 − cos α)(1 + cos α), each without cancellation.
            let one_minus_cos_a = u.x * one_minus_cos_max;
            let cos_a = 1.0 - one_minus_cos_a;
            let sin_a = (one_minus_cos_a * (2.0 - one_minus_cos_a)).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u.y;
            let dir =
                (t * (sin_a * phi.cos()) + b * (sin_a * phi.sin()) + axis * cos_a).normalize();
            let cos = n.dot(dir);
            if cos <= 0.0 {
                continue;
            }
            // Distance to the near side of the sphere along dir.
            let along = d * cos_a;
            let off_axis = d * sin_a;
            let t_hit = along - ((radius - off_axis) * (radius + off_axis)).max(0.0).sqrt();
            if self.visible(p, n, dir, t_hit.max(0.0) * SHORTEN, hint) {
                sum += cos;
            }
        }
        if sum <= 0.0 {
            return None;
        }
        Some(Incident {
            direction: axis,
            irradiance: radiance_times_solid_angle * (sum / count as f32),
        })
    }
}

/// The `count` variates of an area light at one point: [`stratified_square`] with a
/// Cranley–Patterson rotation taken from the point's `seed` (24 bits per axis), so that
/// neighbouring points see different, equally stratified patterns and the result does not
/// depend on the order points are lit in.
pub fn strata(count: u32, seed: u64) -> StratifiedSquare {
    let rotation = Vec2::new(
        (seed >> 40) as f32 / (1u64 << 24) as f32,
        ((seed >> 16) & 0xff_ffff) as f32 / (1u64 << 24) as f32,
    );
    stratified_square(count, rotation)
}

fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    if edge1 <= edge0 {
        return if x >= edge1 { 1.0 } else { 0.0 };
    }
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Two triangles covering the rectangle [x0, x1] × [−half, half] at height h, facing ±z: an
/// occluder for the tests of shadows (a plate far wider than the lit area is a half-plane).
#[cfg(test)]
pub(crate) fn test_plate(x0: f32, x1: f32, half: f32, h: f32) -> [[Vec3; 3]; 2] {
    let corner = |x: f32, y: f32| Vec3::new(x, y, h);
    [
        [corner(x0, -half), corner(x1, -half), corner(x1, half)],
        [corner(x0, -half), corner(x1, half), corner(x0, half)],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plate over x ∈ [x0, x1], y ∈ [−5, 5] at height h (two triangles).
    fn plate(x0: f32, x1: f32, h: f32) -> [[Vec3; 3]; 2] {
        test_plate(x0, x1, 5.0, h)
    }

    fn point_light(position: Vec3, intensity: f32) -> Light {
        Light::Point {
            position,
            color: Vec3::ONE,
            intensity,
        }
    }

    #[test]
    fn point_light_follows_inverse_square_and_cosine() {
        let lights = [point_light(Vec3::new(0.0, 0.0, 2.0), 8.0)];
        let l = Lighting::new(&lights, None, 1.0);
        let e = l.irradiance(Vec3::ZERO, Vec3::Z, 0);
        assert!((e - Vec3::splat(2.0)).abs().max_element() < 1e-6);
        // 60° off the normal: cos = 0.5.
        let n = Vec3::new(3f32.sqrt() / 2.0, 0.0, 0.5);
        assert!((l.irradiance(Vec3::ZERO, n, 0).x - 1.0).abs() < 1e-5);
        // From behind: nothing.
        assert_eq!(l.irradiance(Vec3::ZERO, -Vec3::Z, 0), Vec3::ZERO);
    }

    #[test]
    fn occluder_casts_a_shadow() {
        let lights = [point_light(Vec3::new(0.0, 0.0, 2.0), 1.0)];
        // A triangle between the point and the light.
        let bvh = Bvh::build(&[[
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ]]);
        let l = Lighting::new(&lights, Some(&bvh), 2.0);
        assert_eq!(l.irradiance(Vec3::ZERO, Vec3::Z, 0), Vec3::ZERO);
        assert!(l.irradiance(Vec3::new(5.0, 0.0, 0.0), Vec3::Z, 0).x > 0.0);
    }

    /// `skipping(s)` ignores exactly the occluders nearer than s along the ray, for every kind
    /// of light; beyond the light itself nothing can occlude.
    #[test]
    fn skipping_ignores_only_the_near_occluders() {
        // A plate at height 1 over x < 1, and one at height 3 over x < 1.
        let mut tris = plate(-5.0, 1.0, 1.0).to_vec();
        tris.extend(plate(-5.0, 1.0, 3.0));
        let bvh = Bvh::build(&tris);
        let near_only = Bvh::build(&plate(-5.0, 1.0, 1.0));
        let sphere = Light::Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 0.2,
            color: Vec3::ONE,
            intensity: 25.0,
            samples: 4,
        };
        let directional = Light::Directional {
            direction: -Vec3::Z,
            color: Vec3::ONE,
            irradiance: 1.0,
        };
        let rect = Light::Rect {
            center: Vec3::new(0.0, 0.0, 5.0),
            normal: -Vec3::Z,
            right: -Vec3::X,
            up_axis: Vec3::Y,
            size: Vec2::new(0.4, 0.3),
            color: Vec3::ONE,
            intensity: 25.0,
            samples: 4,
        };
        for light in [
            point_light(Vec3::new(0.0, 0.0, 5.0), 25.0),
            sphere,
            directional,
            rect,
        ] {
            let lights = [light];
            let open = Lighting::new(&lights, None, 5.0).irradiance(Vec3::ZERO, Vec3::Z, 3);
            assert!(open.x > 0.5, "{:?}: {open}", lights[0]);
            let l = Lighting::new(&lights, Some(&bvh), 5.0);
            assert_eq!(l.irradiance(Vec3::ZERO, Vec3::Z, 3), Vec3::ZERO);
            // Stepping over the plate at height 1 still meets the one at height 3.
            assert_eq!(
                l.skipping(1.5).irradiance(Vec3::ZERO, Vec3::Z, 3),
                Vec3::ZERO
            );
            assert_eq!(
                l.skipping(0.9).irradiance(Vec3::ZERO, Vec3::Z, 3),
                Vec3::ZERO
            );
            // Without the far plate, skipping 1.5 sees the light as if nothing occluded.
            let near = Lighting::new(&lights, Some(&near_only), 5.0);
            assert_eq!(
                near.skipping(0.9).irradiance(Vec3::ZERO, Vec3::Z, 3),
                Vec3::ZERO
            );
            assert_eq!(near.skipping(1.5).irradiance(Vec3::ZERO, Vec3::Z, 3), open);
            // Nonsense distances skip nothing.
            for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
                assert_eq!(
                    near.skipping(bad).irradiance(Vec3::ZERO, Vec3::Z, 3),
                    Vec3::ZERO
                );
            }
        }
        // A point light nearer than the skip is visible whatever lies between.
        let lights = [point_light(Vec3::new(0.0, 0.0, 2.0), 4.0)];
        let l = Lighting::new(&lights, Some(&near_only), 5.0);
        assert_eq!(l.irradiance(Vec3::ZERO, Vec3::Z, 0), Vec3::ZERO);
        assert_eq!(
            l.skipping(2.5).irradiance(Vec3::ZERO, Vec3::Z, 0),
            Vec3::ONE
        );
    }

    #[test]
    fn hints_carried_along_a_row_change_no_value() {
        // Three lights (point, sphere, directional) and two occluders with edges between them:
        // a row of points crosses lit, shadowed and half-lit stretches.
        let lights = [
            point_light(Vec3::new(0.0, 0.0, 3.0), 4.0),
            Light::Sphere {
                center: Vec3::new(1.0, 0.0, 4.0),
                radius: 0.5,
                color: Vec3::ONE,
                intensity: 9.0,
                samples: 16,
            },
            Light::Directional {
                direction: Vec3::new(0.3, 0.0, -1.0).normalize(),
                color: Vec3::ONE,
                irradiance: 1.0,
            },
        ];
        let mut tris = plate(-3.0, -0.5, 1.5).to_vec();
        tris.extend(plate(0.7, 1.5, 1.0));
        let bvh = Bvh::build(&tris);
        let l = Lighting::new(&lights, Some(&bvh), 5.0);
        let mut hints = ShadowHints::default();
        let (mut dark, mut lit) = (0, 0);
        for i in 0..400 {
            let p = Vec3::new(-4.0 + i as f32 * 0.02, 0.1, 0.0);
            let seed = i as u64;
            let with = l.irradiance_with(p, Vec3::Z, seed, &mut hints);
            assert_eq!(with, l.irradiance(p, Vec3::Z, seed), "at {p}");
            if with.x < 1e-3 {
                dark += 1;
            } else {
                lit += 1;
            }
        }
        assert!(
            dark > 20 && lit > 20,
            "the row crosses shadows: {dark} dark, {lit} lit"
        );
    }

    /// Each bit of the reach mask is whether that light alone delivers light (the hard
    /// lights), or reaches the centre of a sphere light, along a row that crosses two plates'
    /// shadows, the spot's cone and a terminator.
    #[test]
    fn reach_mask_bits_are_each_lights_visibility() {
        let lights = [
            point_light(Vec3::new(0.0, 0.0, 3.0), 4.0),
            Light::Directional {
                direction: Vec3::new(0.3, 0.0, -1.0).normalize(),
                color: Vec3::ONE,
                irradiance: 1.0,
            },
            Light::Spot {
                position: Vec3::new(-1.0, 0.0, 4.0),
                direction: Vec3::new(0.0, 0.0, -1.0),
                inner_angle_degrees: 20.0,
                outer_angle_degrees: 30.0,
                color: Vec3::ONE,
                intensity: 5.0,
            },
            Light::Sphere {
                center: Vec3::new(1.0, 0.0, 4.0),
                radius: 0.5,
                color: Vec3::ONE,
                intensity: 9.0,
                samples: 16,
            },
            // Below the surface: never reaches it.
            point_light(Vec3::new(0.0, 0.0, -3.0), 4.0),
            Light::Rect {
                center: Vec3::new(-2.0, 0.0, 4.0),
                normal: -Vec3::Z,
                right: -Vec3::X,
                up_axis: Vec3::Y,
                size: Vec2::new(1.0, 2.0),
                color: Vec3::ONE,
                intensity: 9.0,
                samples: 16,
            },
        ];
        let mut tris = plate(-3.0, -0.5, 1.5).to_vec();
        tris.extend(plate(0.7, 1.5, 1.0));
        let bvh = Bvh::build(&tris);
        let mut hints = ShadowHints::default();
        let mut seen = [[false; 2]; 6];
        for i in 0..400 {
            let p = Vec3::new(-4.0 + i as f32 * 0.02, 0.1, 0.0);
            let mask = Lighting::new(&lights, Some(&bvh), 5.0).reach_mask(p, Vec3::Z, &mut hints);
            for (k, light) in lights.iter().enumerate() {
                let bit = mask >> k & 1 == 1;
                seen[k][usize::from(bit)] = true;
                let want = match *light {
                    Light::Sphere { center, .. } | Light::Rect { center, .. } => {
                        let point = [point_light(center, 1.0)];
                        Lighting::new(&point, Some(&bvh), 5.0)
                            .irradiance(p, Vec3::Z, 0)
                            .x
                            > 0.0
                    }
                    _ => {
                        let one = std::slice::from_ref(light);
                        Lighting::new(one, Some(&bvh), 5.0)
                            .irradiance(p, Vec3::Z, 0)
                            .x
                            > 0.0
                    }
                };
                assert_eq!(bit, want, "light {k} at {p}");
            }
        }
        // Every light but the one below is both seen and hidden somewhere along the row.
        assert_eq!(seen[..4], [[true, true]; 4]);
        assert_eq!(seen[4], [true, false]);
        assert_eq!(seen[5], [true, true]);
        assert_eq!(mask_bits_beyond_32(), 0);
    }

    /// Lights past the 32nd leave the mask alone.
    fn mask_bits_beyond_32() -> u32 {
        let mut lights = vec![point_light(Vec3::new(0.0, 0.0, -1.0), 1.0); 32];
        lights.push(point_light(Vec3::new(0.0, 0.0, 1.0), 1.0));
        Lighting::new(&lights, None, 1.0).reach_mask(
            Vec3::ZERO,
            Vec3::Z,
            &mut ShadowHints::default(),
        )
    }

    #[test]
    fn unoccluded_sphere_light_equals_a_point_light() {
        let sphere = [Light::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 0.5,
            color: Vec3::ONE,
            intensity: 16.0,
            samples: 64,
        }];
        let point = [point_light(Vec3::new(0.0, 0.0, 4.0), 16.0)];
        let es = Lighting::new(&sphere, None, 1.0)
            .irradiance(Vec3::ZERO, Vec3::Z, 7)
            .x;
        let ep = Lighting::new(&point, None, 1.0)
            .irradiance(Vec3::ZERO, Vec3::Z, 7)
            .x;
        // Exact for a facing surface: E = L π sin²θ_max = I/d².
        assert!((es - ep).abs() / ep < 0.01, "{es} vs {ep}");
    }

    #[test]
    fn a_vanishing_sphere_light_is_a_point_light() {
        // r² underflows f32 at these radii: I/(π r²) alone is ∞ and the cone's solid angle 0.
        let point = [point_light(Vec3::new(1.0, 0.0, 4.0), 16.0)];
        let ep = Lighting::new(&point, None, 1.0).irradiance(Vec3::ZERO, Vec3::Z, 7);
        for radius in [1e-3, 1e-12, 1e-20, 1e-30, 1e-45] {
            let sphere = [Light::Sphere {
                center: Vec3::new(1.0, 0.0, 4.0),
                radius,
                color: Vec3::ONE,
                intensity: 16.0,
                samples: 16,
            }];
            let es = Lighting::new(&sphere, None, 1.0).irradiance(Vec3::ZERO, Vec3::Z, 7);
            assert!(es.is_finite(), "radius {radius}: {es}");
            assert!(
                (es - ep).abs().max_element() <= 2e-3 * ep.x,
                "radius {radius}: {es} vs {ep}"
            );
        }
    }

    #[test]
    fn sphere_light_gives_a_penumbra() {
        let lights = [Light::Sphere {
            center: Vec3::new(0.0, 0.0, 4.0),
            radius: 1.0,
            color: Vec3::ONE,
            intensity: 16.0,
            samples: 64,
        }];
        // A half-plane occluder x < 0 at height 2: points under its edge are half lit.
        let h = 2.0;
        let bvh = Bvh::build(&[
            [
                Vec3::new(-100.0, -100.0, h),
                Vec3::new(0.0, -100.0, h),
                Vec3::new(0.0, 100.0, h),
            ],
            [
                Vec3::new(-100.0, -100.0, h),
                Vec3::new(0.0, 100.0, h),
                Vec3::new(-100.0, 100.0, h),
            ],
        ]);
        let l = Lighting::new(&lights, Some(&bvh), 10.0);
        let open = Lighting::new(&lights, None, 10.0);
        let dark = l.irradiance(Vec3::new(-3.0, 0.0, 0.0), Vec3::Z, 1).x;
        assert_eq!(dark, 0.0);
        let lit = Vec3::new(3.0, 0.0, 0.0);
        assert_eq!(
            l.irradiance(lit, Vec3::Z, 1),
            open.irradiance(lit, Vec3::Z, 1)
        );
        // Right under the edge the plane hides exactly the half of the light with x < 0.
        let edge =
            l.irradiance(Vec3::ZERO, Vec3::Z, 1).x / open.irradiance(Vec3::ZERO, Vec3::Z, 1).x;
        assert!((edge - 0.5).abs() < 0.05, "edge fraction {edge}");
        // And the penumbra is graded: a quarter of the way across it is neither.
        let quarter = l.irradiance(Vec3::new(0.25, 0.0, 0.0), Vec3::Z, 1).x
            / open.irradiance(Vec3::new(0.25, 0.0, 0.0), Vec3::Z, 1).x;
        assert!(
            quarter > 0.55 && quarter < 0.95,
            "quarter fraction {quarter}"
        );
    }

    #[test]
    fn spot_and_directional_lights() {
        let spot = [Light::Spot {
            position: Vec3::new(0.0, 0.0, 1.0),
            direction: -Vec3::Z,
            inner_angle_degrees: 10.0,
            outer_angle_degrees: 20.0,
            color: Vec3::ONE,
            intensity: 1.0,
        }];
        let l = Lighting::new(&spot, None, 1.0);
        assert!((l.irradiance(Vec3::ZERO, Vec3::Z, 0).x - 1.0).abs() < 1e-6);
        assert_eq!(l.irradiance(Vec3::new(1.0, 0.0, 0.0), Vec3::Z, 0).x, 0.0); // 45° off axis
        let sun = [Light::Directional {
            direction: Vec3::new(0.0, 0.0, -1.0),
            color: Vec3::new(1.0, 0.5, 0.25),
            irradiance: 2.0,
        }];
        let e = Lighting::new(&sun, None, 1.0).irradiance(Vec3::ZERO, Vec3::Z, 0);
        assert!((e - Vec3::new(2.0, 1.0, 0.5)).abs().max_element() < 1e-6);
    }
}
