//! Exhaustive sums over every sample, no approximation: the ground truth of the renderer's
//! `exhaustive` method, and the brute-force oracles the octree traversals are tested against.

use glam::{DVec3, Vec3};

use super::IrradianceCache;
use crate::kernel::Kernel;
use crate::lanes::{DefaultLanes, LANES, Lanes};
use crate::profile::Profile;

/// M_o(x) = Σ_i Rd(|x − p_i|) E_i A_i over every sample (JB02's sum without the octree), in
/// 8-lane batches with each batch's total accumulated in double precision.
pub fn exhaustive_sum(cache: &IrradianceCache, profile: &Profile, x: Vec3) -> Vec3 {
    exhaustive_sum_lanes::<DefaultLanes>(cache, profile, x)
}

/// [`exhaustive_sum`] with an explicit lane type.
pub fn exhaustive_sum_lanes<L: Lanes>(cache: &IrradianceCache, profile: &Profile, x: Vec3) -> Vec3 {
    // As a query evaluates it (Burley's near-field cap; the dipoles unchanged).
    let profile = &profile.for_sample_area(cache.mean_area());
    let s = &cache.samples;
    let (xx, xy, xz) = (L::splat(x.x), L::splat(x.y), L::splat(x.z));
    let mut total = DVec3::ZERO;
    // The padding is zero flux, so the last partial batch needs no mask.
    for i in (0..cache.len).step_by(LANES) {
        let dx = L::load(&s.pos_x[i..]) - xx;
        let dy = L::load(&s.pos_y[i..]) - xy;
        let dz = L::load(&s.pos_z[i..]) - xz;
        let rd = profile.rd_lanes(dx * dx + dy * dy + dz * dz);
        total.x += (rd[0] * L::load(&s.flux_r[i..])).reduce_add() as f64;
        total.y += (rd[1] * L::load(&s.flux_g[i..])).reduce_add() as f64;
        total.z += (rd[2] * L::load(&s.flux_b[i..])).reduce_add() as f64;
    }
    total.as_vec3()
}

/// The split sums over every sample in double precision: (Σ (1 − w) Rd E A, Σ w Rd E A,
/// Σ w Rd A) for the kernel of radius α ([`crate::kernel`]).
fn split_sums(cache: &IrradianceCache, profile: &Profile, x: Vec3, alpha: f32) -> [DVec3; 3] {
    let profile = &profile.for_sample_area(cache.mean_area());
    let kernel = Kernel::new(alpha);
    let s = &cache.samples;
    let mut sums = [DVec3::ZERO; 3];
    for i in 0..cache.len {
        let r2 = (Vec3::new(s.pos_x[i], s.pos_y[i], s.pos_z[i]) - x).length_squared();
        let flux = DVec3::new(s.flux_r[i] as f64, s.flux_g[i] as f64, s.flux_b[i] as f64);
        let w = kernel.weight(r2) as f64;
        let rd = profile.rd(r2).as_dvec3();
        sums[0] += rd * flux * (1.0 - w);
        sums[1] += rd * flux * w;
        sums[2] += rd * s.area[i] as f64 * w;
    }
    sums
}

/// The LM07 estimate with every sample evaluated, scalar, double-precision sums:
/// M_o = E(x)·K + Σ_i (1 − w(r_i)) Rd(r_i) E_i A_i.
pub fn exhaustive_local_global(
    cache: &IrradianceCache,
    profile: &Profile,
    x: Vec3,
    irradiance: Vec3,
    local_integral: Vec3,
    alpha: f32,
) -> Vec3 {
    let [global, _, _] = split_sums(cache, profile, x, alpha);
    (irradiance.as_dvec3() * local_integral.as_dvec3() + global).as_vec3()
}

/// The N10 estimate with every sample evaluated, scalar, double-precision sums
/// (`docs/physics.md` §13): E_loc = [Rd(0) Ā E(x) + Σ w Rd A E] / [Rd(0) Ā + Σ w Rd A], then
/// M_o = E_loc·K + Σ (1 − w) Rd E A.
pub fn exhaustive_edge_aware(
    cache: &IrradianceCache,
    profile: &Profile,
    x: Vec3,
    irradiance: Vec3,
    local_integral: Vec3,
    alpha: f32,
) -> Vec3 {
    let [global, num, den] = split_sums(cache, profile, x, alpha);
    let centre = profile
        .for_sample_area(cache.mean_area())
        .rd_zero()
        .as_dvec3()
        * cache.mean_area() as f64;
    let e_loc = (centre * irradiance.as_dvec3() + num) / (centre + den);
    let e_loc = DVec3::select(e_loc.is_finite_mask(), e_loc, irradiance.as_dvec3());
    (e_loc * local_integral.as_dvec3() + global).as_vec3()
}
