//! The octree queries against brute-force oracles: hierarchical vs exhaustive with shrinking
//! error in ε, the split methods vs their every-sample formulas, SIMD vs scalar lanes, cull
//! tolerance, determinism, and the properties every result must have.

use lucent_core::error::QueryError;
use lucent_core::glam::Vec3;
use lucent_core::internals::ScalarLanes;
use lucent_core::internals::{exhaustive_edge_aware, exhaustive_local_global, exhaustive_sum};
use lucent_core::stats::{NoStats, QueryStats};
use lucent_core::{
    Distance, IrradianceCache, LocalIntegralTable, LocalTerm, Method, Profile, ProfileModel,
    QuerySettings, ShadingPoint,
};

use crate::common::{Rng, box_samples, rel_err, sphere_samples, term};

fn profile(ell: f32) -> Profile {
    Profile::from_reflectance(
        Vec3::new(0.8, 0.6, 0.3),
        Distance::MeanFreePath(Vec3::new(ell, ell * 0.7, ell * 0.4)),
        1.3,
    )
    .unwrap()
}

/// Query points on and near the sphere (where shading happens), plus a few off it.
fn query_points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            let v = rng.vec3(-1.0, 1.0).normalize_or(Vec3::X);
            if i % 10 == 9 {
                v * rng.range(0.0, 3.0)
            } else {
                v * rng.range(0.98, 1.02)
            }
        })
        .collect()
}

fn settings(method: Method, epsilon: f32, cull: f32) -> QuerySettings {
    QuerySettings {
        method,
        epsilon,
        cull_tolerance: cull,
    }
}

fn point(x: Vec3) -> ShadingPoint {
    ShadingPoint {
        position: x,
        irradiance: Vec3::new(x.z.max(0.0), 0.5 * x.z.max(0.0), 0.3),
    }
}

/// Relative error with a floor at 1e-3 of the point's total (exitance falls to ~0 on the dark
/// side, where relative error means nothing).
fn err(got: Vec3, want: Vec3) -> f32 {
    ((got - want).abs() / (want.abs() + Vec3::splat(1e-3 * want.max_element() + 1e-30)))
        .max_element()
}

#[test]
fn epsilon_zero_is_the_exhaustive_sum() {
    let cache = IrradianceCache::build(&sphere_samples(4000, 1.0, 1)).unwrap();
    let p = profile(0.05);
    for x in query_points(200, 2) {
        let want = exhaustive_sum(&cache, &p, x);
        for method in [Method::Hierarchical, Method::Exhaustive] {
            let got = cache
                .query(
                    &p,
                    &point(x),
                    term(0.0, Vec3::ZERO),
                    &settings(method, 0.0, 0.0),
                )
                .unwrap();
            assert!(
                rel_err(got.total, want) < 2e-5,
                "{method:?} at {x}: {} vs {want}",
                got.total
            );
        }
    }
}

/// The JB02 approximation error against the exhaustive sum is bounded and shrinks with ε.
/// Errors are relative to the largest exitance of the set (per-point relative error is
/// meaningless deep in shadow, where the exitance is ~0). Bounds: 1.5–2.5× the worst errors
/// measured on this set with fourth-order aggregates (0.0137, 4.6e-4, 2.7e-5, 2.2e-6, 8e-8 —
/// the last is f32 rounding), below the second-order aggregates' 0.024, 7.5e-4, 4.5e-5 at the
/// first three; JB02's plain aggregates measured 0.082, 0.0124, 0.0018, 1.2e-4, <1e-5.
#[test]
fn hierarchical_error_shrinks_with_epsilon() {
    let cache = IrradianceCache::build(&sphere_samples(20_000, 1.0, 3)).unwrap();
    let p = profile(0.05);
    let points = query_points(300, 4);
    let truth: Vec<Vec3> = points
        .iter()
        .map(|&x| exhaustive_sum(&cache, &p, x))
        .collect();
    let scale = truth.iter().map(|t| t.max_element()).fold(0.0, f32::max);
    let mut previous = f32::INFINITY;
    for (epsilon, bound) in [
        (1.0, 0.02),
        (0.2, 7e-4),
        (0.05, 4e-5),
        (0.01, 5e-6),
        (0.001, 2e-7),
    ] {
        let s = settings(Method::Hierarchical, epsilon, 0.0);
        let mut mean = 0.0;
        let mut worst = 0.0_f32;
        for (x, want) in points.iter().zip(&truth) {
            let got = cache
                .query(&p, &point(*x), term(0.0, Vec3::ZERO), &s)
                .unwrap()
                .total;
            let e = (got - *want).abs().max_element() / scale;
            mean += e / points.len() as f32;
            worst = worst.max(e);
        }
        assert!(worst < bound, "ε {epsilon}: worst error {worst} ≥ {bound}");
        assert!(
            mean < previous,
            "ε {epsilon}: mean error {mean} did not shrink from {previous}"
        );
        previous = mean;
    }
}

/// With ε = 0 and no culling the split traversals equal their brute-force formulas; with the
/// default ε they stay close.
#[test]
fn split_methods_match_brute_force_oracles() {
    let cache = IrradianceCache::build(&sphere_samples(6000, 1.0, 5)).unwrap();
    let p = profile(0.03);
    for k in [1.0, 2.5] {
        let alpha = cache.smoothing_radius(k);
        let table = LocalIntegralTable::new(&p, alpha, 0.0).unwrap();
        let kk = table.lookup(p.mean_free_path());
        // Both lit-everywhere-in-blue shading points and points whose own irradiance follows
        // the light (zero on the dark side, where N10 skips its deferred unlit subtrees).
        let dark_too = |x: Vec3| ShadingPoint {
            position: x,
            irradiance: Vec3::splat(x.z.max(0.0)),
        };
        for sp in query_points(150, 6)
            .into_iter()
            .flat_map(|x| [point(x), dark_too(x)])
        {
            let x = sp.position;
            let lg = exhaustive_local_global(&cache, &p, x, sp.irradiance, kk, alpha);
            let ea = exhaustive_edge_aware(&cache, &p, x, sp.irradiance, kk, alpha);
            for (method, want) in [(Method::LocalGlobal, lg), (Method::EdgeAware, ea)] {
                let exact = cache
                    .query(&p, &sp, term(alpha, kk), &settings(method, 0.0, 0.0))
                    .unwrap();
                assert!(
                    rel_err(exact.total, want) < 1e-4,
                    "{method:?} ε=0 at {x}: {} vs {want}",
                    exact.total
                );
                assert!(
                    (exact.local + exact.global - exact.total)
                        .abs()
                        .max_element()
                        <= 1e-6 * exact.total.max_element()
                );
                let approx = cache
                    .query(&p, &sp, term(alpha, kk), &settings(method, 0.05, 0.0))
                    .unwrap();
                assert!(
                    err(approx.total, want) < 0.02,
                    "{method:?} ε=0.05 at {x}: {} vs {want}",
                    approx.total
                );
            }
        }
    }
}

/// The scalar fallback and the SIMD lanes agree to 1e-5 relative (the SIMD exp is a
/// polynomial with ~2 ulp error; everything else is the same arithmetic).
#[test]
fn simd_and_scalar_lanes_agree() {
    let cache = IrradianceCache::build(&box_samples(8000, 1.0, 7)).unwrap();
    let p = profile(0.05);
    let alpha = cache.smoothing_radius(2.0);
    let kk = LocalIntegralTable::new(&p, alpha, 0.0)
        .unwrap()
        .lookup(p.mean_free_path());
    for x in query_points(100, 8) {
        for method in Method::ALL {
            let s = settings(method, 0.05, 1e-4);
            let a = cache
                .query_with::<ScalarLanes, _>(&p, &point(x), term(alpha, kk), &s, &mut NoStats)
                .unwrap();
            let b = cache.query(&p, &point(x), term(alpha, kk), &s).unwrap();
            assert!(
                err(a.total, b.total) < 1e-5,
                "{method:?} at {x}: scalar {} simd {}",
                a.total,
                b.total
            );
        }
    }
}

#[test]
fn queries_are_deterministic_across_threads() {
    let cache = IrradianceCache::build(&sphere_samples(5000, 1.0, 9)).unwrap();
    let p = profile(0.05);
    let alpha = cache.smoothing_radius(1.5);
    let s = settings(Method::EdgeAware, 0.05, 1e-4);
    let points = query_points(200, 10);
    let run = || {
        points
            .iter()
            .map(|&x| {
                cache
                    .query(&p, &point(x), term(alpha, Vec3::splat(0.2)), &s)
                    .unwrap()
                    .total
            })
            .collect::<Vec<_>>()
    };
    let first = run();
    let others: Vec<Vec<Vec3>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..4).map(|_| scope.spawn(run)).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for other in others {
        assert!(
            first
                .iter()
                .zip(&other)
                .all(|(a, b)| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits))
        );
    }
}

/// Finite and non-negative everywhere, and linear in the irradiance.
#[test]
fn results_are_finite_non_negative_and_linear_in_irradiance() {
    let samples = sphere_samples(3000, 1.0, 11);
    let cache = IrradianceCache::build(&samples).unwrap();
    let doubled: Vec<_> = samples
        .iter()
        .map(|s| lucent_core::Sample {
            irradiance: s.irradiance * 2.0,
            ..*s
        })
        .collect();
    let cache2 = IrradianceCache::build(&doubled).unwrap();
    let tripled: Vec<_> = samples
        .iter()
        .map(|s| lucent_core::Sample {
            irradiance: s.irradiance * 3.0,
            ..*s
        })
        .collect();
    let cache3 = IrradianceCache::build(&tripled).unwrap();
    let p = profile(0.05);
    let alpha = cache.smoothing_radius(2.0);
    let kk = Vec3::splat(0.3);
    let mut far = query_points(100, 12);
    far.extend([Vec3::ZERO, Vec3::splat(1e6), Vec3::new(-1e30, 0.0, 1e30)]);
    for x in far {
        for method in Method::ALL {
            let s = settings(method, 0.05, 1e-4);
            let sp = point(x);
            let m1 = cache.query(&p, &sp, term(alpha, kk), &s).unwrap();
            for v in [m1.total, m1.local, m1.global, m1.local_irradiance] {
                assert!(
                    v.is_finite() && v.min_element() >= 0.0,
                    "{method:?} at {x}: {v}"
                );
            }
            // ×2 is exact in binary floating point all the way through, except where products
            // underflow into subnormals (far away, where Rd·flux < 1e-38).
            let sp2 = ShadingPoint {
                irradiance: sp.irradiance * 2.0,
                ..sp
            };
            let m2 = cache2.query(&p, &sp2, term(alpha, kk), &s).unwrap();
            let diff = (m2.total - m1.total * 2.0).abs().max_element();
            assert!(
                diff <= 1e-37 || diff == 0.0,
                "{method:?} at {x}: {} vs {}",
                m2.total,
                m1.total * 2.0
            );
            let sp3 = ShadingPoint {
                irradiance: sp.irradiance * 3.0,
                ..sp
            };
            let m3 = cache3.query(&p, &sp3, term(alpha, kk), &s).unwrap();
            assert!(err(m3.total, m1.total * 3.0) < 1e-5, "{method:?} at {x}");
        }
    }
}

/// Culling skips work, and what it skips adds up to at most `tolerance ×` the result, per
/// channel, at every point (the provable bound of the area-budgeted rule); tolerance 0 culls
/// nothing.
#[test]
fn cull_tolerance_bounds_the_skipped_contribution() {
    let cache = IrradianceCache::build(&sphere_samples(20_000, 1.0, 13)).unwrap();
    for ell in [0.01, 0.05] {
        let p = profile(ell);
        let points = query_points(200, 14);
        for epsilon in [0.001, 0.05] {
            let full: Vec<Vec3> = points
                .iter()
                .map(|&x| {
                    cache
                        .query(
                            &p,
                            &point(x),
                            term(0.0, Vec3::ZERO),
                            &settings(Method::Hierarchical, epsilon, 0.0),
                        )
                        .unwrap()
                        .total
                })
                .collect();
            let mut last_work = u64::MAX;
            for tolerance in [0.0, 1e-4, 1e-3, 1e-2] {
                let s = settings(Method::Hierarchical, epsilon, tolerance);
                let mut stats = QueryStats::default();
                for (x, m0) in points.iter().zip(&full) {
                    let m = cache
                        .query_with_stats(&p, &point(*x), term(0.0, Vec3::ZERO), &s, &mut stats)
                        .unwrap()
                        .total;
                    let skipped = *m0 - m;
                    // Culling only removes non-negative terms; f32 reassociation allows ~1e-6.
                    let slack = 2e-6 * m0.max_element();
                    assert!(
                        skipped.min_element() >= -slack,
                        "ℓ {ell} ε {epsilon} tol {tolerance}: culled result exceeds the full one"
                    );
                    assert!(
                        (skipped - m * tolerance).max_element() <= slack,
                        "ℓ {ell} ε {epsilon} tol {tolerance} at {x}: skipped {skipped} > tol × {m}"
                    );
                }
                if tolerance == 0.0 {
                    assert_eq!(stats.culled, 0);
                } else {
                    assert!(stats.culled > 0, "tolerance {tolerance} culled nothing");
                }
                let work = stats.profile_evaluations();
                assert!(
                    work <= last_work,
                    "tolerance {tolerance}: {work} evaluations, more than {last_work}"
                );
                last_work = work;
            }
        }
    }
}

#[test]
fn stats_count_the_work() {
    let cache = IrradianceCache::build(&box_samples(1000, 1.0, 15)).unwrap();
    let p = profile(0.1);
    let mut stats = QueryStats::default();
    cache
        .query_with_stats(
            &p,
            &point(Vec3::ZERO),
            term(0.0, Vec3::ZERO),
            &settings(Method::Hierarchical, 0.0, 0.0),
            &mut stats,
        )
        .unwrap();
    assert_eq!(
        (stats.queries, stats.samples, stats.aggregates),
        (1, 1000, 0)
    );
    let mut stats = QueryStats::default();
    cache
        .query_with_stats(
            &p,
            &point(Vec3::splat(50.0)),
            term(0.0, Vec3::ZERO),
            &settings(Method::Hierarchical, 0.05, 0.0),
            &mut stats,
        )
        .unwrap();
    assert!(
        stats.samples == 0 && stats.aggregates > 0 && stats.aggregates <= 8,
        "{stats:?}"
    );
}

#[test]
fn invalid_query_inputs_are_errors() {
    let cache = IrradianceCache::build(&box_samples(100, 1.0, 16)).unwrap();
    let p = profile(0.1);
    let s = QuerySettings::default();
    let ok = point(Vec3::ZERO);
    assert_eq!(
        cache.query(&p, &point(Vec3::NAN), LocalTerm::NONE, &s),
        Err(QueryError::NonFinitePosition)
    );
    let bad_e = ShadingPoint {
        irradiance: Vec3::new(-1.0, 0.0, 0.0),
        ..ok
    };
    assert_eq!(
        cache.query(&p, &bad_e, LocalTerm::NONE, &s),
        Err(QueryError::InvalidIrradiance)
    );
    assert_eq!(
        cache.query(&p, &ok, term(0.1, Vec3::splat(f32::NAN)), &s),
        Err(QueryError::InvalidLocalIntegral)
    );
    let bad_s = QuerySettings {
        epsilon: f32::NAN,
        ..s
    };
    assert!(matches!(
        cache.query(&p, &ok, LocalTerm::NONE, &bad_s),
        Err(QueryError::InvalidSetting {
            name: "epsilon",
            ..
        })
    ));
    for alpha in [-1.0, f32::NAN, f32::INFINITY] {
        assert_eq!(
            cache.query(&p, &ok, term(alpha, Vec3::ZERO), &s),
            Err(QueryError::InvalidLocalIntegral),
            "α {alpha}"
        );
    }
}

#[test]
fn empty_and_single_sample_caches() {
    let p = profile(0.1);
    let empty = IrradianceCache::build(&[]).unwrap();
    let s = settings(Method::EdgeAware, 0.05, 1e-4);
    let m = empty
        .query(&p, &point(Vec3::ZERO), term(0.1, Vec3::splat(0.5)), &s)
        .unwrap();
    assert_eq!(m.global, Vec3::ZERO);
    assert!(m.total.is_finite());
    let one = IrradianceCache::build(&box_samples(1, 1.0, 17)).unwrap();
    one.validate().unwrap();
    for method in Method::ALL {
        let m = one
            .query(
                &p,
                &point(Vec3::splat(0.1)),
                term(0.1, Vec3::splat(0.5)),
                &settings(method, 0.05, 1e-4),
            )
            .unwrap();
        assert!(m.total.is_finite() && m.total.min_element() >= 0.0);
    }
}

/// N10's weights Rd·A are scaled per channel by 1/(Rd(0)·Ā): where Rd(0)·Ā is far below f32's
/// normal range (a sphere of radius 1e-9 with ℓ_u = 1e11: ~1e-44) the local irradiance must
/// still match a double-precision evaluation of its formula (found by fuzzing: unscaled, the
/// weights were subnormal and the ratio lost its digits).
#[test]
fn edge_aware_local_irradiance_stays_accurate_when_its_weights_are_tiny() {
    let samples: Vec<lucent_core::Sample> = sphere_samples(2000, 1e-9, 21);
    let cache = IrradianceCache::build(&samples).unwrap();
    let p = profile(1e11);
    let centre = p.rd_zero().as_dvec3() * cache.mean_area() as f64;
    assert!(
        centre.max_element() < 1e-38,
        "the test needs subnormal weights, got {centre}"
    );
    let alpha = cache.smoothing_radius(3.0);
    let kernel = lucent_core::internals::Kernel::new(alpha);
    let kk = LocalIntegralTable::new(&p, alpha, 0.0)
        .unwrap()
        .lookup(p.mean_free_path());
    for x in query_points(60, 22) {
        let x = x * 1e-9;
        let e = Vec3::new(x.z.max(0.0) * 1e9, 0.2, 0.0);
        // E_loc = [Rd(0) Ā E(x) + Σ w Rd A E] / [Rd(0) Ā + Σ w Rd A], in f64.
        let (mut num, mut den) = (centre * e.as_dvec3(), centre);
        for s in cache.samples() {
            let r2 = (s.position - x).length_squared();
            let wrd = p.rd(r2).as_dvec3() * kernel.weight(r2) as f64 * s.area as f64;
            num += wrd * s.irradiance.as_dvec3();
            den += wrd;
        }
        let want = (num / den).as_vec3();
        let sp = ShadingPoint {
            position: x,
            irradiance: e,
        };
        let got = cache
            .query(
                &p,
                &sp,
                term(alpha, kk),
                &settings(Method::EdgeAware, 0.0, 0.0),
            )
            .unwrap();
        assert!(got.total.is_finite());
        let error =
            (got.local_irradiance - want).abs().max_element() / want.abs().max_element().max(1e-6);
        assert!(
            error < 1e-3,
            "at {x}: E_loc {} vs {want}",
            got.local_irradiance
        );
    }
}

/// A jittered square grid of `n`² samples of spacing `h` on the plane z = 0, centred on the
/// origin, with irradiance `e` times a per-sample factor in [0.5, 1.5] per channel.
fn jittered_plane(n: usize, h: f32, e: f32, seed: u64) -> Vec<lucent_core::Sample> {
    let mut rng = Rng(seed);
    let half = n as f32 * h / 2.0;
    let mut samples = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let u = (i as f32 + rng.range(0.0, 1.0)) * h - half;
            let v = (j as f32 + rng.range(0.0, 1.0)) * h - half;
            samples.push(lucent_core::Sample {
                position: Vec3::new(u, v, 0.0),
                area: h * h * rng.range(0.5, 1.5),
                irradiance: rng.vec3(0.5, 1.5) * e,
            });
        }
    }
    samples
}

/// N10's local irradiance against its formula in double precision (the talk's Rd(0)-weighted
/// query, as `core/src/query.rs` states it):
/// E_loc = [Rd(0) Ā E(x) + Σ w Rd A E] / [Rd(0) Ā + Σ w Rd A], within `tolerance` (relative),
/// and the whole edge-aware result against `exhaustive_edge_aware`.
fn assert_edge_aware_matches_f64(
    samples: &[lucent_core::Sample],
    p: &Profile,
    k: f32,
    points: &[ShadingPoint],
    tolerance: f32,
) {
    let cache = IrradianceCache::build(samples).unwrap();
    cache.validate().unwrap();
    let centre = p.rd_zero().as_dvec3() * cache.mean_area() as f64;
    let alpha = cache.smoothing_radius(k);
    let kernel = lucent_core::internals::Kernel::new(alpha);
    let kk = LocalIntegralTable::new(p, alpha, 0.0)
        .unwrap()
        .lookup(p.mean_free_path());
    for sp in points {
        let (x, e) = (sp.position, sp.irradiance);
        let (mut num, mut den) = (centre * e.as_dvec3(), centre);
        for s in cache.samples() {
            let r2 = (s.position - x).length_squared();
            let wrd = p.rd(r2).as_dvec3() * kernel.weight(r2) as f64 * s.area as f64;
            num += wrd * s.irradiance.as_dvec3();
            den += wrd;
        }
        let want = (num / den).as_vec3();
        let got = cache
            .query(
                p,
                sp,
                term(alpha, kk),
                &settings(Method::EdgeAware, 0.0, 0.0),
            )
            .unwrap();
        assert!(got.total.is_finite(), "at {x}: {got:?}");
        let error = rel_err(got.local_irradiance, want);
        assert!(
            error < tolerance,
            "at {x}: E_loc {} vs {want}",
            got.local_irradiance
        );
        let oracle = exhaustive_edge_aware(&cache, p, x, e, kk, alpha);
        assert!(
            rel_err(got.total, oracle) < tolerance,
            "at {x}: {} vs exhaustive {oracle}",
            got.total
        );
    }
}

/// Shading points at, near and between the samples of `jittered_plane(n, h, ..)`, with
/// irradiance `e` at x (0 for every other point: E_loc must then come from the cache alone).
fn plane_points(n: usize, h: f32, e: f32, seed: u64) -> Vec<ShadingPoint> {
    let mut rng = Rng(seed);
    let half = n as f32 * h / 2.0;
    (0..40)
        .map(|i| ShadingPoint {
            position: Vec3::new(rng.range(-half, half), rng.range(-half, half), 0.0),
            irradiance: if i % 2 == 0 {
                Vec3::ZERO
            } else {
                rng.vec3(0.5, 1.5) * e
            },
        })
        .collect()
}

/// N10's weights are scaled by powers of two near 1/Rd(0) and 1/Ā, each on its own: where Ā
/// is subnormal (< 2⁻¹²⁶; here a plane of spacing 2⁻⁶⁴, Ā ≈ 2⁻¹²⁸) a single factor
/// 1/(Rd(0)·Ā) made Rd·factor overflow to +∞, E_loc became ∞/∞ and fell back to E(x) — found
/// by fuzzing (`crash-subnormal-mean-area-scale-overflow`: one sample of area 2⁻¹²⁸ at x,
/// E_loc 0 instead of E/2).
#[test]
fn edge_aware_local_irradiance_survives_a_subnormal_mean_area() {
    let h = 2f32.powi(-64);
    let samples = jittered_plane(32, h, 1.0, 31);
    let cache = IrradianceCache::build(&samples).unwrap();
    assert!(
        cache.mean_area() < f32::MIN_POSITIVE,
        "the test needs a subnormal mean area, got {}",
        cache.mean_area()
    );
    // α = 8·√Ā ≈ 8 spacings: above the 1.1e-19 below which the kernel acts as α = 0, so that
    // about 200 samples weigh E_loc. ℓ_u near the smallest the dipole represents (Rd is
    // nearly flat over α).
    let k = 8.0;
    assert!(cache.smoothing_radius(k) > 2e-19);
    let p = profile(1e-12);
    assert_edge_aware_matches_f64(&samples, &p, k, &plane_points(32, h, 1.0, 32), 1e-4);
}

/// The scaled local flux sum is also kept ≤ 1 (scaled by a power of two near 1/Φ): scaled by
/// 1/(Rd(0)·Ā) alone, it is about Σ w·E over the α-ball, and irradiances near 10³⁷ over the
/// ~700 samples of a wide α-ball overflowed f32, although E_loc itself (a weighted mean of
/// the irradiances) is representable.
#[test]
fn edge_aware_local_irradiance_survives_huge_irradiance_in_a_wide_kernel() {
    let h = 0.1;
    let samples = jittered_plane(40, h, 1e37, 33);
    // ℓ_u far beyond α = 1.5: Rd is nearly Rd(0) over the whole α-ball.
    let p = profile(100.0);
    assert_edge_aware_matches_f64(&samples, &p, 15.0, &plane_points(40, h, 1e37, 34), 1e-4);
}

/// [`unlit_surface_failures`] finds none.
fn assert_unlit_surface_weighed(spread: f32, trials: usize, seed: u64) {
    let failures = unlit_surface_failures(spread, trials, seed);
    assert!(
        failures.is_empty(),
        "{} failures: {:?}",
        failures.len(),
        &failures[..failures.len().min(4)]
    );
}

/// Queries N10 at each of eight unlit samples spread over `spread` (x on their leaf's sphere),
/// with one lit sample far away; returns the queries whose E_loc misses x's own weight.
fn unlit_surface_failures(spread: f32, trials: usize, seed: u64) -> Vec<(usize, Vec3, Vec3)> {
    let p = profile(0.5);
    let mut rng = Rng(seed);
    let mut failures = Vec::new();
    for trial in 0..trials {
        // Near ±f32::MAX: corners of the cube (random signs), so that the sphere saturates.
        let mut position = || {
            if spread > 1e38 {
                let c = |r: &mut Rng| {
                    r.range(0.9, 1.0) * spread * if r.f32() < 0.5 { -1.0 } else { 1.0 }
                };
                Vec3::new(c(&mut rng), c(&mut rng), c(&mut rng))
            } else {
                rng.vec3(-spread, spread)
            }
        };
        let mut samples: Vec<lucent_core::Sample> = (0..8)
            .map(|_| lucent_core::Sample {
                position: position(),
                area: 1.0,
                irradiance: Vec3::ZERO,
            })
            .collect();
        samples.push(lucent_core::Sample {
            position: Vec3::splat((10.0 * spread).min(3.3e38)),
            area: 1.0,
            irradiance: Vec3::ONE,
        });
        let cache = IrradianceCache::build(&samples).unwrap();
        let alpha = cache.smoothing_radius(2.0);
        let kk = LocalIntegralTable::new(&p, alpha, 0.0)
            .unwrap()
            .lookup(p.mean_free_path());
        for s in &samples[..8] {
            let sp = ShadingPoint {
                position: s.position,
                irradiance: Vec3::ONE,
            };
            let got = cache
                .query(
                    &p,
                    &sp,
                    term(alpha, kk),
                    &settings(Method::EdgeAware, 0.0, 0.0),
                )
                .unwrap();
            // Every other sample is far beyond α: E_loc = Rd(0)·Ā / (Rd(0)·Ā + Rd(0)·A).
            let want = cache.mean_area() / (cache.mean_area() + 1.0);
            if rel_err(got.local_irradiance, Vec3::splat(want)) > 1e-5 {
                failures.push((trial, s.position, got.local_irradiance));
            }
        }
    }
    failures
}

/// N10 weighs the unlit samples within α of x, so a node's sphere must test as holding x when
/// x is one of its samples, however large the sphere: the f32 distance to the centroid can
/// exceed the (rounded-up) radius by a few ulps, which on a sphere of radius 10⁹ is ~100 units,
/// far beyond α = 2 — the node was pruned as unlit and far, and E_loc lost x's own weight
/// (5 of these 8000 queries, E_loc 1 instead of 1/2).
#[test]
fn edge_aware_weighs_unlit_samples_on_the_surface_of_a_huge_node() {
    assert_unlit_surface_weighed(1e9, 1000, 41);
}

/// The same where the distance to the centroid squares past f32::MAX (spread 10²⁰): the
/// squared distance was +∞, the node looked infinitely far although it holds x (found by
/// fuzzing, `crash-centroid-distance-squared-overflows`).
#[test]
fn edge_aware_weighs_unlit_samples_of_a_node_beyond_f32_squares() {
    assert_unlit_surface_weighed(1e20, 50, 42);
}

/// The same near ±f32::MAX (spread 3.2·10³⁸): the offsets to the centroids overflow too, and
/// the root's radius saturates at f32::MAX, which stands for an unbounded sphere (found by
/// fuzzing, `crash-unbounded-root-near-f32-max`).
#[test]
fn edge_aware_weighs_unlit_samples_near_f32_max() {
    assert_unlit_surface_weighed(3.2e38, 50, 43);
}

/// A plan made once per material gives every method's result bit for bit, and its checks are
/// the query's: bad settings and K fail at planning, a bad point at the query.
#[test]
fn planned_queries_equal_plain_ones_bit_for_bit() {
    let cache = IrradianceCache::build(&sphere_samples(3000, 1.0, 7)).unwrap();
    let p = profile(0.05);
    let local = term(0.04, Vec3::new(0.3, 0.2, 0.1));
    for method in Method::ALL {
        let s = settings(method, 0.4, 1e-4);
        let plan = cache.plan(&p, local, &s).unwrap();
        assert_eq!(plan.local(), local);
        for x in query_points(200, 3) {
            let mut counted = (QueryStats::default(), QueryStats::default());
            let want = cache
                .query_with_stats(&p, &point(x), local, &s, &mut counted.0)
                .unwrap();
            let got = cache
                .query_planned(&plan, &point(x), &mut counted.1)
                .unwrap();
            assert_eq!(got, want, "{method:?} at {x}");
            assert_eq!(counted.0, counted.1, "{method:?} at {x}");
        }
    }
    let bad = settings(Method::Hierarchical, f32::NAN, 1e-4);
    assert!(matches!(
        cache.plan(&p, local, &bad),
        Err(QueryError::InvalidSetting {
            name: "epsilon",
            ..
        })
    ));
    assert_eq!(
        cache
            .plan(
                &p,
                term(0.04, Vec3::new(-1.0, 0.0, 0.0)),
                &settings(Method::LocalGlobal, 0.4, 0.0)
            )
            .unwrap_err(),
        QueryError::InvalidLocalIntegral
    );
    let plan = cache
        .plan(&p, local, &settings(Method::EdgeAware, 0.4, 1e-4))
        .unwrap();
    let nan = ShadingPoint {
        position: Vec3::new(f32::NAN, 0.0, 0.0),
        irradiance: Vec3::ONE,
    };
    assert_eq!(
        cache.query_planned(&plan, &nan, &mut NoStats).unwrap_err(),
        QueryError::NonFinitePosition
    );
    let negative = ShadingPoint {
        position: Vec3::ZERO,
        irradiance: Vec3::new(0.0, -1.0, 0.0),
    };
    assert_eq!(
        cache
            .query_planned(&plan, &negative, &mut NoStats)
            .unwrap_err(),
        QueryError::InvalidIrradiance
    );
}

/// A plan re-made for another material at each point ([`IrradianceCache::replan`], what a
/// texture-mapped material does) is the plan made from scratch: the same results, bit for bit,
/// for every method and model, with another α as well as the same; a bad K still fails. So is
/// one plan re-made in place from material to material ([`IrradianceCache::replan_into`]),
/// and a bad K leaves it as it was.
#[test]
fn replanned_queries_equal_plain_ones_bit_for_bit() {
    let cache = IrradianceCache::build(&sphere_samples(2000, 1.0, 8)).unwrap();
    let base = profile(0.05);
    let base_local = term(0.04, Vec3::new(0.3, 0.2, 0.1));
    for method in Method::ALL {
        let s = settings(method, 0.4, 1e-4);
        let template = cache.plan(&base, base_local, &s).unwrap();
        let mut in_place = template;
        for model in ProfileModel::ALL {
            for (i, (ell, alpha)) in [(0.02, 0.04), (0.2, 0.04), (0.05, 0.07)]
                .into_iter()
                .enumerate()
            {
                let p = Profile::from_reflectance_with(
                    model,
                    Vec3::new(0.5, 0.7, 0.9),
                    Distance::MeanFreePath(Vec3::splat(ell)),
                    1.4,
                )
                .unwrap();
                let local = term(alpha, Vec3::new(0.1, 0.2, 0.3));
                let replanned = cache.replan(&template, &p, local).unwrap();
                assert_eq!(replanned.local(), local);
                cache.replan_into(&mut in_place, &p, local).unwrap();
                let bad = term(alpha, Vec3::new(f32::NAN, 0.0, 0.0));
                assert_eq!(
                    cache.replan_into(&mut in_place, &base, bad),
                    Err(QueryError::InvalidLocalIntegral)
                );
                assert_eq!(in_place.local(), local);
                assert_eq!(in_place.profile(), replanned.profile());
                for x in query_points(40, 10 + i as u64) {
                    let want = cache.query(&p, &point(x), local, &s).unwrap();
                    let got = cache.query_planned(&replanned, &point(x), &mut NoStats);
                    assert_eq!(got.unwrap(), want, "{method:?} {model:?} ℓ {ell} α {alpha}");
                    let got = cache.query_planned(&in_place, &point(x), &mut NoStats);
                    assert_eq!(got.unwrap(), want, "in place: {method:?} {model:?} ℓ {ell}");
                }
            }
        }
    }
    let template = cache
        .plan(&base, base_local, &settings(Method::EdgeAware, 0.4, 1e-4))
        .unwrap();
    for bad in [
        term(0.04, Vec3::new(-1.0, 0.0, 0.0)),
        term(0.04, Vec3::new(f32::NAN, 0.0, 0.0)),
    ] {
        assert_eq!(
            cache.replan(&template, &base, bad).unwrap_err(),
            QueryError::InvalidLocalIntegral
        );
    }
}
