//! Building the irradiance cache: invariants (`validate`), determinism, degenerate inputs,
//! errors, and memory per sample.

use lucent_core::error::BuildError;
use lucent_core::glam::Vec3;
use lucent_core::internals::{LEAF_CAPACITY, MAX_DEPTH};
use lucent_core::{IrradianceCache, Sample};

use crate::common::{Rng, box_samples, sphere_samples};

#[test]
fn random_sets_validate() {
    for (i, n) in [1usize, 2, 7, 8, 9, 63, 64, 65, 1000, 23_000]
        .into_iter()
        .enumerate()
    {
        for samples in [
            box_samples(n, 3.0, i as u64),
            sphere_samples(n, 1.0, 100 + i as u64),
        ] {
            let cache = IrradianceCache::build(&samples).unwrap();
            cache.validate().unwrap_or_else(|e| panic!("n = {n}: {e}"));
            assert_eq!(cache.len(), n);
            let total: f64 = samples.iter().map(|s| s.area as f64).sum();
            assert!((cache.total_area() as f64 - total).abs() <= 1e-5 * total);
        }
    }
}

#[test]
fn empty_cache_is_valid_and_queries_to_zero() {
    let cache = IrradianceCache::build(&[]).unwrap();
    cache.validate().unwrap();
    assert!(cache.is_empty());
    assert_eq!(cache.node_count(), 0);
    assert_eq!(cache.bounds(), None);
}

#[test]
fn build_is_deterministic_and_independent_of_input_order() {
    let samples = sphere_samples(5000, 2.0, 7);
    let a = IrradianceCache::build(&samples).unwrap();
    let b = IrradianceCache::build(&samples).unwrap();
    assert_eq!(a, b);
    // Reversed input: same positions, so the same Morton order wherever codes differ.
    let mut reversed = samples.clone();
    reversed.reverse();
    let c = IrradianceCache::build(&reversed).unwrap();
    c.validate().unwrap();
    assert_eq!(a.node_count(), c.node_count());
    assert_eq!(a.total_area(), c.total_area());
}

#[test]
fn coincident_samples_form_a_balanced_tree() {
    let s = Sample {
        position: Vec3::new(1.0, 2.0, 3.0),
        area: 0.5,
        irradiance: Vec3::ONE,
    };
    for n in [9usize, 64, 65, 1000, 100_000] {
        let cache = IrradianceCache::build(&vec![s; n]).unwrap();
        cache.validate().unwrap();
        // log₈(n/8) levels of count splits, not a chain.
        let bound = (n as f64 / LEAF_CAPACITY as f64).log(8.0).ceil() as usize + 1;
        assert!(
            cache.depth() <= bound,
            "n = {n}: depth {} > {bound}",
            cache.depth()
        );
    }
}

#[test]
fn collinear_and_clustered_samples() {
    let mut rng = Rng(3);
    let line: Vec<Sample> = (0..5000)
        .map(|_| Sample {
            position: Vec3::new(rng.range(-1e3, 1e3), 0.0, 0.0),
            area: 1.0,
            irradiance: Vec3::ONE,
        })
        .collect();
    let cache = IrradianceCache::build(&line).unwrap();
    cache.validate().unwrap();
    assert!(cache.depth() <= MAX_DEPTH);
    // Two far clusters, one of them tiny (exercises the Morton level skipping).
    let mut clusters = box_samples(3000, 1e-4, 4);
    clusters.extend(box_samples(3000, 1.0, 5).into_iter().map(|mut s| {
        s.position += Vec3::splat(1e4);
        s
    }));
    let cache = IrradianceCache::build(&clusters).unwrap();
    cache.validate().unwrap();
}

#[test]
fn extreme_scales_build() {
    for scale in [1e-4_f32, 1.0, 1e4, 1e15] {
        let samples: Vec<Sample> = sphere_samples(2000, scale, 9);
        let cache = IrradianceCache::build(&samples).unwrap();
        cache
            .validate()
            .unwrap_or_else(|e| panic!("scale {scale}: {e}"));
    }
}

#[test]
fn bad_samples_are_typed_errors_naming_the_sample() {
    let good = Sample {
        position: Vec3::ZERO,
        area: 1.0,
        irradiance: Vec3::ONE,
    };
    let cases = [
        (
            Sample {
                position: Vec3::new(f32::NAN, 0.0, 0.0),
                ..good
            },
            "position",
        ),
        (
            Sample {
                position: Vec3::new(0.0, f32::INFINITY, 0.0),
                ..good
            },
            "position",
        ),
        (Sample { area: -1.0, ..good }, "area"),
        (
            Sample {
                area: f32::NAN,
                ..good
            },
            "area",
        ),
        (
            Sample {
                irradiance: Vec3::new(0.0, -1.0, 0.0),
                ..good
            },
            "irradiance",
        ),
        (
            Sample {
                irradiance: Vec3::new(0.0, 0.0, f32::INFINITY),
                ..good
            },
            "irradiance",
        ),
        (
            Sample {
                area: 1e30,
                irradiance: Vec3::splat(1e30),
                ..good
            },
            "irradiance",
        ),
    ];
    for (bad, what) in cases {
        let samples = [good, good, bad, good];
        let err = IrradianceCache::build(&samples).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("sample 2") && msg.contains(what), "{msg}");
        assert!(matches!(
            err,
            BuildError::NonFinitePosition { index: 2 }
                | BuildError::InvalidArea { index: 2, .. }
                | BuildError::InvalidIrradiance { index: 2, .. }
        ));
    }
}

/// Each sample valid, but the f32 node sums would overflow: rejected, not built into a cache
/// with infinite aggregates (found by the fuzz target `cache_query_matches_exhaustive`).
#[test]
fn totals_beyond_f32_are_typed_errors() {
    let big = |x: f32, irradiance: f32| Sample {
        position: Vec3::new(x, 0.0, 0.0),
        area: 2e38,
        irradiance: Vec3::splat(irradiance),
    };
    let err = IrradianceCache::build(&[big(0.0, 0.0), big(1.0, 0.0)]).unwrap_err();
    assert!(
        matches!(
            err,
            BuildError::TotalOverflow {
                quantity: "area",
                ..
            }
        ),
        "{err}"
    );
    let small = |x: f32| Sample {
        area: 1.0,
        irradiance: Vec3::splat(2e38),
        ..big(x, 0.0)
    };
    let err = IrradianceCache::build(&[small(0.0), small(1.0)]).unwrap_err();
    assert!(err.to_string().contains("total flux"), "{err}");
    let one = IrradianceCache::build(&[big(0.0, 0.0)]).unwrap();
    one.validate().unwrap();
}

/// The memory budget: at most 64 bytes per sample, everything included.
#[test]
fn memory_per_sample_is_within_budget() {
    for n in [2_000usize, 23_000, 100_000] {
        let cache = IrradianceCache::build(&sphere_samples(n, 1.0, 11)).unwrap();
        let per = cache.memory_bytes() as f64 / n as f64;
        assert!(per <= 64.0, "n = {n}: {per:.1} bytes per sample");
    }
}

#[test]
fn samples_round_trip_through_the_cache() {
    let samples = box_samples(500, 1.0, 12);
    let cache = IrradianceCache::build(&samples).unwrap();
    let mut back: Vec<Sample> = cache.samples().collect();
    let key = |s: &Sample| {
        (
            s.position.x.to_bits(),
            s.position.y.to_bits(),
            s.position.z.to_bits(),
        )
    };
    back.sort_by_key(key);
    let mut want = samples.clone();
    want.sort_by_key(key);
    for (a, b) in back.iter().zip(&want) {
        assert_eq!(a.position, b.position);
        assert_eq!(a.area, b.area);
        if b.area > 0.0 {
            assert!(
                ((a.irradiance - b.irradiance).abs() / b.irradiance.max(Vec3::splat(1e-6)))
                    .max_element()
                    < 1e-5
            );
        }
    }
}

/// Samples near ±f32::MAX: a node's sphere is then too large for f32 and its radius saturates
/// at f32::MAX ("unbounded"); `validate()` allowed that for the samples but not for the child
/// centroids, and rejected the cache (found by fuzzing, `crash-saturated-radius-child-centroid`).
#[test]
fn corners_near_f32_max_validate() {
    let m = 3.19e38;
    let mut samples = Vec::new();
    for (i, (x, y, z)) in [
        (-m, -m, 0.67 * m),
        (-m, -m, -m),
        (-m, 0.52 * m, -m),
        (-m, m, m),
    ]
    .into_iter()
    .enumerate()
    {
        for copy in 0..3 {
            samples.push(Sample {
                position: Vec3::new(x, y, z),
                area: 2.5e27,
                irradiance: Vec3::splat(if copy == 0 && i == 3 { 1.0 } else { 0.0 }),
            });
        }
    }
    samples.push(Sample {
        position: Vec3::ZERO,
        area: 0.0,
        irradiance: Vec3::ZERO,
    });
    let cache = IrradianceCache::build(&samples).unwrap();
    cache.validate().unwrap();
}
