//! The edge-refined query's edge test against a brute-force oracle: a point is flagged exactly
//! when some sample within α (of positive area) has an irradiance (summed over the channels)
//! outside [(1 − τ)·E(x), E(x)/(1 − τ)], τ = `EDGE_THRESHOLD`; unflagged points get edge-aware's result bit for
//! bit, flagged ones edge-aware's global sum.

use lucent_core::glam::Vec3;
use lucent_core::{
    Distance, IrradianceCache, LocalQuadrature, Method, Profile, QuerySettings, Sample,
    ShadingPoint,
};

use crate::common::term;

const EDGE_THRESHOLD: f32 = LocalQuadrature::EDGE_THRESHOLD;

fn profile() -> Profile {
    Profile::from_reflectance(
        Vec3::new(0.8, 0.6, 0.3),
        Distance::MeanFreePath(Vec3::new(0.05, 0.04, 0.02)),
        1.3,
    )
    .unwrap()
}

/// A jittered grid on z = 0 lit for x > 0 (E = (1, 0.8, 0.5)) and dark for x < 0, with a
/// gentle gradient in y, one sample of zero area and a few of extra flux.
fn samples() -> Vec<Sample> {
    let mut out = Vec::new();
    let mut s = 12345u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    for i in 0..60 {
        for j in 0..60 {
            let p = Vec3::new(
                (i as f32 + next()) * 0.02 - 0.6,
                (j as f32 + next()) * 0.02 - 0.6,
                0.0,
            );
            let lit = if p.x > 0.0 { 1.0 + 0.1 * p.y } else { 0.0 };
            let boost = if (i * 60 + j) % 97 == 0 { 2.5 } else { 1.0 };
            let area = if i == 30 && j == 30 { 0.0 } else { 0.0004 };
            out.push(Sample {
                position: p,
                area,
                irradiance: Vec3::new(1.0, 0.8, 0.5) * lit * boost,
            });
        }
    }
    out
}

#[test]
fn the_edge_test_matches_brute_force_and_falls_back_to_edge_aware() {
    let samples = samples();
    let cache = IrradianceCache::build(&samples).unwrap();
    let p = profile();
    let alpha = cache.smoothing_radius(1.5);
    let k = Vec3::new(0.2, 0.15, 0.1);
    let mut flagged = 0;
    let mut unflagged = 0;
    for i in 0..41 {
        for j in [-0.3_f32, 0.0, 0.25] {
            let x = Vec3::new(-0.4 + 0.02 * i as f32, j, 0.0);
            let lit = if x.x > 0.0 { 1.0 + 0.1 * x.y } else { 0.0 };
            let e = Vec3::new(1.0, 0.8, 0.5) * lit;
            let point = ShadingPoint {
                position: x,
                irradiance: e,
            };
            let query = |method| {
                let s = QuerySettings {
                    method,
                    ..QuerySettings::default()
                };
                cache.query(&p, &point, term(alpha, k), &s).unwrap()
            };
            let aware = query(Method::EdgeAware);
            let refined = query(Method::EdgeRefined);
            // Brute force over the samples as the cache stores them (flux / area).
            let ex = e.element_sum();
            let want = samples.iter().any(|s| {
                (s.position - x).length_squared() < alpha * alpha && s.area > 0.0 && {
                    let se = s.irradiance.element_sum();
                    se < (1.0 - EDGE_THRESHOLD) * ex || se * (1.0 - EDGE_THRESHOLD) > ex
                }
            });
            let near_threshold = samples.iter().any(|s| {
                (s.position - x).length_squared() < alpha * alpha && s.area > 0.0 && {
                    let se = s.irradiance.element_sum();
                    (se - (1.0 - EDGE_THRESHOLD) * ex).abs() < 1e-3 * ex
                        || (se * (1.0 - EDGE_THRESHOLD) - ex).abs() < 1e-3 * ex
                }
            });
            if !near_threshold {
                assert_eq!(refined.refine, want, "x {x}");
            }
            assert!(!aware.refine);
            assert_eq!(refined.global, aware.global);
            if refined.refine {
                flagged += 1;
            } else {
                unflagged += 1;
                assert_eq!(refined, aware, "x {x}");
            }
            // Replacing the local term keeps the global sum and adds up.
            let r = refined.with_local(e * k, term(alpha, k));
            assert_eq!(r.total, e * k + aware.global);
            assert_eq!(r.local_irradiance, e);
        }
    }
    // Both sides of the edge, the edge itself and the boosted samples are all exercised.
    assert!(
        flagged > 10 && unflagged > 10,
        "{flagged} flagged, {unflagged} not"
    );
}
