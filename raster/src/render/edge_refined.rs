//! The edge-refined local term at one shading point: the irradiance at the core's quadrature
//! nodes on the tangent disc ([`lucent_core::LocalQuadrature`]), from the same lights, occluders and
//! shadow rays that light the irradiance samples.
//!
//! Called only where the edge-refined query flagged the point (the samples' irradiance within
//! α is not uniform); everywhere else the method is edge-aware's, at no extra cost.
//!
//! ```text
//!          n (the normal at x, used for every node's cosine)
//!          ↑
//!    ·  ·  x  ·  ·      x′ = x + offset.x·t₁ + offset.y·t₂ + lift·n
//!   ───────┼───────     (t₁, t₂) ⟂ n; the pattern turned by a hash of the shading point's
//!                       seed, so neighbouring pixels see different node angles
//! ```

use glam::Vec3;
use lucent_core::{Exitance, LocalQuadrature, LocalTerm, Profile, QuadratureLayout};

use crate::lights::{Lighting, ShadowHints};
use crate::sampling::rng::splitmix64;

/// The quadrature of the edge-refined method for `profile` and α (the default node count).
pub fn quadrature(profile: &Profile, alpha: f32) -> LocalQuadrature {
    LocalQuadrature::with_layout(profile, &layout(alpha))
}

/// The layout of [`quadrature`] at α: what a texture-mapped material's refined points share.
pub fn layout(alpha: f32) -> QuadratureLayout {
    QuadratureLayout::new(
        alpha,
        LocalQuadrature::DEFAULT_RINGS,
        LocalQuadrature::DEFAULT_PER_RING,
    )
}

/// What the refinement needs to know about the shading point.
#[derive(Clone, Copy, Debug)]
pub struct RefinePoint {
    /// Position x.
    pub position: Vec3,
    /// Unit shading normal at x (the nodes' tangent disc and their cosine).
    pub normal: Vec3,
    /// E(x).
    pub irradiance: Vec3,
    /// The local term (α and K) the query at x was given.
    pub local: LocalTerm,
    /// The shading point's seed (rotation of the pattern, area-light strata of the nodes).
    pub seed: u64,
}

/// `m` with its local term replaced by the quadrature of the irradiance over the α-disc.
///
/// Only the lights with hard shadows are traced at the nodes ([`Lighting::hard_only`]); the
/// other lights' share of E(x) stands for theirs at every node. Without a hard-shadowed light
/// `m` (edge-aware's result) is returned as it is.
pub fn refine(
    lighting: &Lighting,
    quadrature: &LocalQuadrature,
    point: &RefinePoint,
    shadows: &mut ShadowHints,
    m: Exitance,
) -> Exitance {
    if !lighting.has_hard_lights() {
        return m;
    }
    let (t1, t2) = point.normal.any_orthonormal_pair();
    let rotation = LocalQuadrature::rotation_for_seed(point.seed ^ 0x005E_ED0F_ED6E);
    // The soft lights' share of E(x), the same at every node (none: the nodes' sums are the
    // hard lights' alone, as without soft lights they are E(x′) itself).
    let soft = lighting.has_soft_lights().then(|| {
        let hard =
            lighting
                .hard_only()
                .irradiance_with(point.position, point.normal, point.seed, shadows);
        (point.irradiance - hard).max(Vec3::ZERO)
    });
    // Occluders within α/2 of a node are the surface near x curving up, not a shadow's edge.
    let lighting = lighting.hard_only().skipping(quadrature.shadow_skip());
    let mut at = [Vec3::ZERO; lucent_core::LocalQuadrature::MAX_NODES];
    for (n, e) in at.iter_mut().enumerate().take(quadrature.len()) {
        let o = quadrature.offset(n, rotation);
        let p = point.position + t1 * o.x + t2 * o.y + point.normal * quadrature.lift(n);
        let seed = splitmix64(point.seed.wrapping_add((n as u64 + 1) << 48));
        let hard = lighting.irradiance_with(p, point.normal, seed, shadows);
        *e = match soft {
            Some(soft) => soft + hard,
            None => hard,
        };
    }
    let local = quadrature.local_term(point.irradiance, point.local, &at[..quadrature.len()]);
    m.with_local(local, point.local)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Bvh;
    use crate::scene::Light;

    fn marble() -> Profile {
        Profile::from_preset(lucent_core::presets::find("marble").unwrap(), 20.0).unwrap()
    }

    /// On a uniformly lit plane every node sees E(x): the refined local term is E·K exactly,
    /// whatever the rotation; a tilted light gives E·cos θ at every node (the normal at x).
    #[test]
    fn a_uniformly_lit_plane_gives_e_times_k_exactly() {
        let lights = [Light::Directional {
            direction: Vec3::new(0.6, 0.0, -0.8),
            color: Vec3::new(1.0, 0.5, 0.25),
            irradiance: 2.5,
        }];
        let lighting = Lighting::new(&lights, None, 10.0);
        let q = quadrature(&marble(), 0.08);
        let local = LocalTerm::exact(&marble(), 0.08).unwrap();
        let k = local.k();
        for seed in [0u64, 1, 77, u64::MAX] {
            let position = Vec3::new(0.3, -1.2, 0.0);
            let e = lighting.irradiance(position, Vec3::Z, seed);
            let point = RefinePoint {
                position,
                normal: Vec3::Z,
                irradiance: e,
                local,
                seed,
            };
            let m = Exitance {
                global: Vec3::splat(0.5),
                refine: true,
                ..Exitance::default()
            };
            let r = refine(&lighting, &q, &point, &mut ShadowHints::default(), m);
            assert_eq!(r.local, e * k);
            assert_eq!(r.total, e * k + Vec3::splat(0.5));
        }
    }

    /// In a crease: the floor z = 0 meets a wall rising at 30° from x = 0.02, all lit from
    /// straight above. Nodes of a point at the origin beyond the wall's foot lie under it (its
    /// triangles shadow them) but within α/2 of it, so the skipped stretch steps over the wall
    /// and the refined term is the uniform E·K, exactly.
    #[test]
    fn a_crease_does_not_shadow_the_nodes() {
        let lights = [Light::Directional {
            direction: -Vec3::Z,
            color: Vec3::ONE,
            irradiance: 1.0,
        }];
        let slope = 30f32.to_radians().tan();
        let (foot, far) = (0.02, 2.0);
        let wall = |y0: f32, y1: f32| {
            let at = |x: f32, y: f32| Vec3::new(x, y, (x - foot) * slope);
            [
                [at(foot, y0), at(far, y0), at(far, y1)],
                [at(foot, y0), at(far, y1), at(foot, y1)],
            ]
        };
        let bvh = Bvh::build(&wall(-2.0, 2.0));
        let lighting = Lighting::new(&lights, Some(&bvh), 2.0);
        let q = quadrature(&marble(), 0.08);
        assert!(q.shadow_skip() == 0.04);
        let local = LocalTerm::exact(&marble(), 0.08).unwrap();
        let k = local.k();
        let e = lighting.irradiance(Vec3::ZERO, Vec3::Z, 0);
        assert_eq!(e, Vec3::ONE);
        let mut under = 0;
        for seed in 0..16u64 {
            let point = RefinePoint {
                position: Vec3::ZERO,
                normal: Vec3::Z,
                irradiance: e,
                local,
                seed,
            };
            let m = Exitance {
                refine: true,
                ..Exitance::default()
            };
            let r = refine(&lighting, &q, &point, &mut ShadowHints::default(), m);
            assert_eq!(r.local, e * k, "seed {seed}");
            // Without the skip, the nodes under the wall would be dark.
            let rotation = LocalQuadrature::rotation_for_seed(seed ^ 0x005E_ED0F_ED6E);
            for n in 0..q.len() {
                let o = q.offset(n, rotation);
                let p = Vec3::new(o.x, o.y, q.lift(n));
                if lighting.irradiance(p, Vec3::Z, 0) == Vec3::ZERO {
                    under += 1;
                }
            }
        }
        assert!(
            under >= 16,
            "{under} nodes under the wall: no test of the skip"
        );
    }

    /// Without a light with hard shadows nothing is traced: edge-aware's result comes back as
    /// it is, even where the query flagged the point.
    #[test]
    fn soft_lights_alone_leave_edge_aware_s_result() {
        let lights = [Light::Environment {
            color: Vec3::ONE,
            intensity: 1.0,
            map: None,
            rotation_degrees: 0.0,
            samples: 16,
        }];
        let lighting = Lighting::new(&lights, None, 10.0);
        let local = LocalTerm::exact(&marble(), 0.08).unwrap();
        let point = RefinePoint {
            position: Vec3::ZERO,
            normal: Vec3::Z,
            irradiance: Vec3::splat(3.0),
            local,
            seed: 5,
        };
        let m = Exitance {
            local: Vec3::splat(0.25),
            global: Vec3::splat(0.5),
            total: Vec3::splat(0.75),
            refine: true,
            ..Exitance::default()
        };
        let q = quadrature(&marble(), 0.08);
        let r = refine(&lighting, &q, &point, &mut ShadowHints::default(), m);
        assert_eq!(r, m);
    }
}
