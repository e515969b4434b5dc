//! Core micro-benchmarks (divan): `cargo bench -p lucent-core --bench core`.
//!
//! The data set is the talk's sphere (`benches/sphere/mod.rs`): radius 1 cm, marble at 10 mm
//! per unit, lit from +z so there is a terminator, 23k irradiance samples; queries at random
//! points on the surface.
//! Before the timings, `main` prints the cache's bytes per sample and the traversal statistics
//! per method (nodes opened and profile evaluations per query), which divan cannot report.

use divan::{Bencher, black_box};
use lucent_core::glam::Vec3;
use lucent_core::internals::exhaustive_sum_lanes;
use lucent_core::internals::{Lanes, NodeMoments, ScalarLanes, SimdLanes};
use lucent_core::stats::{NoStats, QueryStats};
use lucent_core::{Distance, IrradianceCache, Method, Profile, ProfileModel, QuerySettings};

mod sphere;

use sphere::{QUERIES, samples, setup};

fn settings_eps(method: Method, epsilon: f32) -> QuerySettings {
    QuerySettings {
        method,
        epsilon,
        cull_tolerance: 1e-4,
    }
}

fn main() {
    let s = setup();
    println!(
        "cache: {} samples, {} nodes, depth {}, {} bytes = {:.1} bytes/sample",
        s.cache.len(),
        s.cache.node_count(),
        s.cache.depth(),
        s.cache.memory_bytes(),
        s.cache.memory_bytes() as f64 / s.cache.len() as f64
    );
    for (method, epsilon) in [
        (Method::Hierarchical, 0.05),
        (Method::LocalGlobal, 0.05),
        (Method::EdgeAware, 0.05),
        (Method::Hierarchical, 0.4),
        (Method::LocalGlobal, 0.4),
        (Method::EdgeAware, 0.4),
        (Method::Hierarchical, 2.0),
        (Method::EdgeAware, 2.0),
    ] {
        let mut stats = QueryStats::default();
        for p in &s.points {
            s.cache
                .query_with_stats(
                    &s.profile,
                    p,
                    s.k,
                    &settings_eps(method, epsilon),
                    &mut stats,
                )
                .unwrap();
        }
        let q = stats.queries as f64;
        println!(
            "{:>13} ε {epsilon:<4}: {:.1} nodes opened, {:.1} aggregates, {:.1} samples, {:.1} culled, {:.1} profile evaluations per query",
            method.name(),
            stats.nodes_opened as f64 / q,
            stats.aggregates as f64 / q,
            stats.samples as f64 / q,
            stats.culled as f64 / q,
            stats.profile_evaluations() as f64 / q
        );
    }
    divan::main();
}

/// One RGB profile evaluation per item (scalar `Profile::rd`).
#[divan::bench(counter = divan::counter::ItemsCount::new(1024usize))]
fn rd_scalar(b: Bencher) {
    let p = setup().profile;
    let r2: Vec<f32> = (0..1024).map(|i| i as f32 * 1e-3).collect();
    b.bench(|| {
        let mut acc = Vec3::ZERO;
        for &x in &r2 {
            acc += p.rd(black_box(x));
        }
        acc
    });
}

/// RGB profile evaluations in 8-lane batches, per lane type.
#[divan::bench(types = [ScalarLanes, SimdLanes], counter = divan::counter::ItemsCount::new(1024usize))]
fn rd_lanes<L: Lanes>(b: Bencher) {
    let p = setup().profile;
    let r2: Vec<f32> = (0..1024 + 8).map(|i| i as f32 * 1e-3).collect();
    b.bench(|| {
        let mut acc = L::splat(0.0);
        for i in (0..1024).step_by(8) {
            let rd = p.rd_lanes(L::load(&r2[i..]));
            acc = acc + rd[0] + rd[1] + rd[2];
        }
        acc.reduce_add()
    });
}

/// RGB profile evaluations in 8-lane batches per model (SIMD lanes), the cost that a traversal
/// pays per sample or aggregate: the plain value and the fourth-order node aggregate.
#[divan::bench(args = ProfileModel::ALL.map(|m| m.name()), counter = divan::counter::ItemsCount::new(1024usize))]
fn rd_lanes_per_model(b: Bencher, model: &str) {
    let p = model_profile(model);
    let r2: Vec<f32> = (0..1024 + 8).map(|i| i as f32 * 1e-3).collect();
    b.bench(|| {
        let mut acc = SimdLanes::splat(0.0);
        for i in (0..1024).step_by(8) {
            let rd = p.rd_lanes(SimdLanes::load(&r2[i..]));
            acc = acc + rd[0] + rd[1] + rd[2];
        }
        acc.reduce_add()
    });
}

/// The fourth-order node aggregate per model (SIMD lanes), per RGB evaluation.
#[divan::bench(args = ProfileModel::ALL.map(|m| m.name()), counter = divan::counter::ItemsCount::new(1024usize))]
fn rd_lanes_corrected_per_model(b: Bencher, model: &str) {
    let p = model_profile(model);
    let r2: Vec<f32> = (0..1024 + 8).map(|i| 0.01 + i as f32 * 1e-3).collect();
    let m = NodeMoments {
        q: SimdLanes::splat(1e-5),
        trace: SimdLanes::splat(2e-5),
        cross: SimdLanes::splat(1e-10),
        trace_sq: SimdLanes::splat(2e-10),
    };
    b.bench(|| {
        let mut acc = SimdLanes::splat(0.0);
        for i in (0..1024).step_by(8) {
            let rd = p.rd_lanes_corrected(SimdLanes::load(&r2[i..]), black_box(&m));
            acc = acc + rd[0] + rd[1] + rd[2];
        }
        acc.reduce_add()
    });
}

/// The bench sphere's marble under the model named `name`, same K_d and ℓ_u.
fn model_profile(name: &str) -> Profile {
    let base = setup().profile;
    let model = ProfileModel::ALL
        .into_iter()
        .find(|m| m.name() == name)
        .expect("a model name");
    Profile::from_reflectance_with(
        model,
        base.total_reflectance(),
        Distance::MeanFreePath(base.mean_free_path()),
        base.eta(),
    )
    .unwrap()
}

/// Cache construction, samples per second.
#[divan::bench(args = [2_000, 23_000, 100_000])]
fn build(b: Bencher, n: usize) {
    let input = samples(n);
    b.counter(divan::counter::ItemsCount::new(n))
        .bench(|| IrradianceCache::build(black_box(&input)).unwrap());
}

fn run_queries<L: Lanes>(b: Bencher, method: Method, epsilon: f32) {
    let s = setup();
    let settings = settings_eps(method, epsilon);
    b.counter(divan::counter::ItemsCount::new(QUERIES))
        .bench(|| {
            let mut acc = Vec3::ZERO;
            for p in &s.points {
                acc += s
                    .cache
                    .query_with::<L, _>(&s.profile, black_box(p), s.k, &settings, &mut NoStats)
                    .unwrap()
                    .total;
            }
            acc
        });
}

/// Queries per second per method at 23k samples (cull tolerance 1e-4, k 1.5), at ε from 0.05
/// (pbrt-v2's default) to 2 (about the 0.6% image error of the C++ reference that `lucent
/// bench` compares with, `REFERENCE_ERROR` in `raster/src/bench/report.rs`, with lucent's
/// second-order aggregates; its fourth-order ones are more accurate still).
#[divan::bench(types = [ScalarLanes, SimdLanes], args = [0.05, 0.4, 1.0, 2.0])]
fn query_hierarchical<L: Lanes>(b: Bencher, epsilon: f32) {
    run_queries::<L>(b, Method::Hierarchical, epsilon);
}

/// See [`query_hierarchical`].
#[divan::bench(types = [ScalarLanes, SimdLanes], args = [0.05, 0.4, 1.0, 2.0])]
fn query_local_global<L: Lanes>(b: Bencher, epsilon: f32) {
    run_queries::<L>(b, Method::LocalGlobal, epsilon);
}

/// See [`query_hierarchical`].
#[divan::bench(types = [ScalarLanes, SimdLanes], args = [0.05, 0.4, 1.0, 2.0])]
fn query_edge_aware<L: Lanes>(b: Bencher, epsilon: f32) {
    run_queries::<L>(b, Method::EdgeAware, epsilon);
}

/// The exhaustive sum over all 23k samples (per query).
#[divan::bench(types = [ScalarLanes, SimdLanes], sample_count = 20)]
fn query_exhaustive<L: Lanes>(b: Bencher) {
    let s = setup();
    b.counter(divan::counter::ItemsCount::new(16usize))
        .bench(|| {
            let mut acc = Vec3::ZERO;
            for p in &s.points[..16] {
                acc += exhaustive_sum_lanes::<L>(&s.cache, &s.profile, black_box(p.position));
            }
            acc
        });
}

/// Local-integral table lookups on cached nodes (varying ℓ over two decades).
#[divan::bench(counter = divan::counter::ItemsCount::new(1024usize))]
fn table_lookup(b: Bencher) {
    let s = setup();
    let base = s.profile.mean_free_path();
    let ells: Vec<Vec3> = (0..1024)
        .map(|i| base * (0.1 + 9.9 * i as f32 / 1024.0))
        .collect();
    s.table
        .prefill(base.min_element() * 0.1, base.max_element() * 10.0);
    b.bench(|| {
        let mut acc = Vec3::ZERO;
        for &l in &ells {
            acc += s.table.lookup(black_box(l));
        }
        acc
    });
}

/// The same with one ℓ for the three channels (a scalar mean-free-path texture): one
/// logarithm per lookup instead of three.
#[divan::bench(counter = divan::counter::ItemsCount::new(1024usize))]
fn table_lookup_shared(b: Bencher) {
    let s = setup();
    let base = s.profile.mean_free_path().x;
    let ells: Vec<Vec3> = (0..1024)
        .map(|i| Vec3::splat(base * (0.1 + 9.9 * i as f32 / 1024.0)))
        .collect();
    s.table.prefill(base * 0.1, base * 10.0);
    b.bench(|| {
        let mut acc = Vec3::ZERO;
        for &l in &ells {
            acc += s.table.lookup(black_box(l));
        }
        acc
    });
}
