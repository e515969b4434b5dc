//! The environment light (`docs/physics.md` §5.2): radiance arriving from every direction at
//! infinity, either constant or from a lat-long [`EnvironmentMap`], blocked by the scene.
//!
//! Both estimators take the N variates of [`strata`] (rotated per point by the point's hash,
//! so neighbouring points sample different directions and the result is the same for any
//! thread count) and trace one unbounded shadow ray per direction above the surface:
//!
//! - **constant** radiance L: cosine-weighted directions, p(ω) = (n·ω)/π, so
//!   E = (π L / N) Σₖ Vₖ, exactly π L for an unoccluded point;
//! - **map** radiance L(ω): ⌈N/2⌉ directions from the map's luminance-importance density p_m
//!   (see [`EnvironmentMap`]) and ⌊N/2⌋ cosine-weighted ones, p_c(ω) = max(0, n·ω)/π, with a
//!   second stratified set, combined by the balance heuristic of multiple importance sampling
//!   (Veach & Guibas 1995): E = Σₖ Vₖ L(ωₖ) max(0, n·ωₖ) / (N_m p_m(ωₖ) + N_c p_c(ωₖ)) over
//!   both sets. The map's density finds small bright sources (a sun); the cosine density
//!   makes a smooth sky over an open receiver nearly exact, where luminance sampling alone
//!   leaves the cosine's variation as noise. Directions below the surface's horizon
//!   contribute nothing and cost no ray.
//!
//! The reported incident direction (used by the specular highlight, which treats each light
//! as coming from one direction) is the contribution-weighted mean of the visible directions.

use glam::{Vec2, Vec3};

use std::f32::consts::FRAC_1_PI;

use super::{EnvironmentMap, Incident, Lighting, luminance, strata};
use crate::geometry::ShadowHint;
use crate::sampling::rng::splitmix64;

/// The cosine-weighted direction about `n` (with tangents `t`, `b`) for the variates `u`
/// (Malley's method: uniform on the disk by polar coordinates, lifted to the hemisphere).
fn cosine_direction(n: Vec3, t: Vec3, b: Vec3, u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = std::f32::consts::TAU * u.y;
    let z = (1.0 - u.x).max(0.0).sqrt();
    t * (r * phi.cos()) + b * (r * phi.sin()) + n * z
}

/// A map-frame direction turned by `rotation` (cos, sin) about +z.
fn rotate_z(d: Vec3, (cos, sin): (f32, f32)) -> Vec3 {
    Vec3::new(cos * d.x - sin * d.y, sin * d.x + cos * d.y, d.z)
}

impl Lighting<'_> {
    /// The environment's irradiance at `p` (module docs); `radiance` is `color × intensity`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn environment(
        &self,
        p: Vec3,
        n: Vec3,
        radiance: Vec3,
        map: Option<&EnvironmentMap>,
        rotation_degrees: f32,
        samples: u32,
        seed: u64,
        hint: &mut ShadowHint,
    ) -> Option<Incident> {
        let count = samples.max(1);
        let mut sum = Vec3::ZERO;
        let mut toward = Vec3::ZERO;
        match map {
            None => {
                let (t, b) = n.any_orthonormal_pair();
                let mut visible = 0u32;
                for u in strata(count, seed) {
                    let dir = cosine_direction(n, t, b, u);
                    if self.visible(p, n, dir, f32::MAX, hint) {
                        visible += 1;
                        toward += dir;
                    }
                }
                sum = radiance * (std::f32::consts::PI * visible as f32);
            }
            Some(map) => {
                if map.is_black() {
                    return None;
                }
                let (sin, cos) = rotation_degrees.to_radians().sin_cos();
                let (to_world, to_map) = ((cos, sin), (cos, -sin));
                // Half the rays (the odd one included) from the map's density, half
                // cosine-weighted; each weighed by the balance heuristic.
                let from_map = count.div_ceil(2);
                let from_cosine = count - from_map;
                let (nm, nc) = (from_map as f32, from_cosine as f32);
                let mut add = |dir: Vec3, texel: Vec3, pdf_map: f32, cos: f32| {
                    if self.visible(p, n, dir, f32::MAX, hint) {
                        let e = texel * (cos / (nm * pdf_map + nc * cos * FRAC_1_PI));
                        sum += e;
                        toward += dir * luminance(e);
                    }
                };
                for u in strata(from_map, seed) {
                    let s = map.sample(u)?;
                    let dir = rotate_z(s.direction, to_world);
                    let cos = n.dot(dir);
                    if cos > 0.0 {
                        add(dir, s.radiance, s.pdf, cos);
                    }
                }
                if from_cosine > 0 {
                    let (t, b) = n.any_orthonormal_pair();
                    for u in strata(from_cosine, splitmix64(seed)) {
                        let dir = cosine_direction(n, t, b, u);
                        let cos = n.dot(dir);
                        let (texel, pdf_map) = map.radiance_and_pdf(rotate_z(dir, to_map));
                        if cos > 0.0 && texel.max_element() > 0.0 {
                            add(dir, texel, pdf_map, cos);
                        }
                    }
                }
                sum *= radiance;
                if !(sum.max_element() > 0.0) {
                    return None;
                }
                return Some(Incident {
                    direction: toward.normalize_or(n),
                    irradiance: sum,
                });
            }
        }
        if !(sum.max_element() > 0.0) {
            return None;
        }
        Some(Incident {
            direction: toward.normalize_or(n),
            irradiance: sum / count as f32,
        })
    }
}

#[cfg(test)]
mod tests;
