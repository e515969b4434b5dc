//! The closed-form check of `docs/physics.md` §12: on a flat, uniformly lit surface much
//! larger than the diffusion length, every method's exitance is E · Rd_total(α′).

use lucent_core::glam::Vec3;
use lucent_core::{
    Distance, IrradianceCache, LocalIntegralTable, Method, Profile, QuerySettings, Sample,
    ShadingPoint,
};

use crate::common::{Rng, rel_err};

/// A square grid of spacing `h` over [−half, half]², all with irradiance `e`.
fn plane(half: f32, h: f32, e: Vec3) -> Vec<Sample> {
    let n = (2.0 * half / h) as i32;
    let mut samples = Vec::with_capacity((n * n) as usize);
    for i in 0..n {
        for j in 0..n {
            let p = Vec3::new(
                -half + (i as f32 + 0.5) * h,
                -half + (j as f32 + 0.5) * h,
                0.0,
            );
            samples.push(Sample {
                position: p,
                area: h * h,
                irradiance: e,
            });
        }
    }
    samples
}

#[test]
fn every_method_reproduces_e_times_rd_total_on_a_lit_plane() {
    // ℓ_u = 1; K_d per channel gives ℓ_d ≈ 2.4, 3.6 and 5 (the longest tail is 50 ℓ_u / 5 = 10
    // diffusion lengths inside the plane's edge: e^−10).
    let profile = Profile::from_reflectance(
        Vec3::new(0.3, 0.5, 0.6),
        Distance::MeanFreePath(Vec3::ONE),
        1.3,
    )
    .unwrap();
    let e = Vec3::new(1.0, 2.0, 0.5);
    let h = 0.2;
    let cache = IrradianceCache::build(&plane(50.0, h, e)).unwrap();
    cache.validate().unwrap();
    let want = e * profile.total_reflectance();

    let mut rng = Rng(1);
    for _ in 0..8 {
        // Anywhere near the centre, on or between samples.
        let x = Vec3::new(rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), 0.0);
        let point = ShadingPoint {
            position: x,
            irradiance: e,
        };
        // Required: 1% (every method) and 0.5% (the split methods). Measured: 0.0001%
        // exhaustive, 0.0034% hierarchical (second-order aggregates; 0.39% with JB02's plain
        // ones), local-global and edge-aware 0.056% at k = 1.5 and 0.041% at k = 3, but 0.44%
        // at k = 1: α is then one grid step, and the kernel's ramp (1 − w is 0.07 at 0.4α and 1
        // at α) meets the grid's first ring of neighbours at r = α exactly, an
        // alias a blue-noise set does not have. The bounds catch regressions.
        for (method, tolerance) in [
            (Method::Exhaustive, 0.0001),
            (Method::Hierarchical, 0.0002),
            (Method::LocalGlobal, 0.001),
            (Method::EdgeAware, 0.001),
        ] {
            for k in [1.0, 1.5, 3.0] {
                let alpha = cache.smoothing_radius(k);
                let table = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0).unwrap();
                let settings = QuerySettings {
                    method,
                    epsilon: 0.05,
                    cull_tolerance: 1e-4,
                };
                let m = cache
                    .query(
                        &profile,
                        &point,
                        table.local_term(profile.mean_free_path()),
                        &settings,
                    )
                    .unwrap();
                let err = rel_err(m.total, want);
                let tolerance = if k == 1.0 && method.is_split() {
                    0.005
                } else {
                    tolerance
                };
                assert!(
                    err < tolerance,
                    "{method:?} k {k} at {x}: {} vs {want} ({:.3}%)",
                    m.total,
                    err * 100.0
                );
                if method == Method::EdgeAware {
                    // Uniform irradiance: the kernel-weighted local irradiance is E itself.
                    assert!(rel_err(m.local_irradiance, e) < 1e-5);
                }
            }
        }
    }
}
