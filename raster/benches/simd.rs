//! The cache query on the two traversal paths (`cargo bench -p lucent-raster --bench simd`):
//! the baseline lanes against the AVX2 build of the same traversal, through the renderer's
//! dispatch (`render::simd`). Skipped, with a message, on a CPU without AVX2.
//!
//! The data set is that of the core's benchmarks: a sphere of radius 1 cm, marble at 10 mm per
//! unit, lit from +z (a terminator), 23k irradiance samples, queries at random points on the
//! surface, cull tolerance 1e-4.

use divan::{Bencher, black_box};
use lucent_core::glam::Vec3;
use lucent_core::stats::NoStats;
use lucent_core::{Method, QuerySettings};
use lucent_raster::render::simd::Avx2;

/// The core's benchmark data set (only the table goes unread here).
#[allow(dead_code)]
#[path = "../../core/benches/sphere/mod.rs"]
mod sphere;

use sphere::{QUERIES, setup};

fn main() {
    if Avx2::detect().is_none() {
        println!("skipped: this CPU has no AVX2");
        return;
    }
    divan::main();
}

fn run(b: Bencher, method: Method, epsilon: f32, avx2: bool) {
    let s = setup();
    let settings = QuerySettings {
        method,
        epsilon,
        cull_tolerance: 1e-4,
    };
    let path = if avx2 { Avx2::detect() } else { None };
    b.counter(divan::counter::ItemsCount::new(QUERIES))
        .bench(|| {
            let mut acc = Vec3::ZERO;
            for p in &s.points {
                let p = black_box(p);
                let m = match path {
                    Some(avx2) => avx2.query(&s.cache, &s.profile, p, s.k, &settings, &mut NoStats),
                    None => s
                        .cache
                        .query_with_stats(&s.profile, p, s.k, &settings, &mut NoStats),
                };
                acc += m.unwrap().total;
            }
            acc
        });
}

/// JB02 at ε from 0.05 (pbrt-v2's default) to 2; `true` is the AVX2 path.
#[divan::bench(args = [(0.05, false), (0.05, true), (0.5, false), (0.5, true), (2.0, false), (2.0, true)])]
fn hierarchical(b: Bencher, (epsilon, avx2): (f32, bool)) {
    run(b, Method::Hierarchical, epsilon, avx2);
}

/// N10 (the default method); see [`hierarchical`].
#[divan::bench(args = [(0.05, false), (0.05, true), (0.5, false), (0.5, true), (2.0, false), (2.0, true)])]
fn edge_aware(b: Bencher, (epsilon, avx2): (f32, bool)) {
    run(b, Method::EdgeAware, epsilon, avx2);
}
