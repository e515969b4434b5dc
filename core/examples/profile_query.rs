//! Runs one query configuration in a loop, for profiling (`perf record`):
//! `cargo run --release -p lucent-core --example profile_query -- [METHOD] [ε] [seconds]`
//! (METHOD one of `Method::ALL`'s names; default hierarchical).

use lucent_core::glam::Vec3;
use lucent_core::{
    IrradianceCache, LocalIntegralTable, Method, Profile, QuerySettings, Sample, ShadingPoint,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let method = match args.get(1) {
        Some(name) => name.parse().unwrap_or_else(|e| panic!("{e}")),
        None => Method::Hierarchical,
    };
    let epsilon: f32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.4);
    let seconds: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5.0);
    // The sphere of the core benches: 23k samples, marble at 10 mm per unit, lit from +z.
    let mut state = 1u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut on_sphere = || {
        let z = next() * 2.0 - 1.0;
        let phi = next() * std::f32::consts::TAU;
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    let n = 23_000;
    let samples: Vec<Sample> = (0..n)
        .map(|_| {
            let p = on_sphere();
            Sample {
                position: p,
                area: 4.0 * std::f32::consts::PI / n as f32,
                irradiance: Vec3::splat(p.z.max(0.0)),
            }
        })
        .collect();
    let points: Vec<ShadingPoint> = (0..256)
        .map(|_| {
            let p = on_sphere();
            ShadingPoint {
                position: p,
                irradiance: Vec3::splat(p.z.max(0.0)),
            }
        })
        .collect();
    let cache = IrradianceCache::build(&samples).unwrap();
    let profile =
        Profile::from_preset(lucent_core::presets::find("marble").unwrap(), 10.0).unwrap();
    let alpha = cache.smoothing_radius(1.5);
    let k = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0)
        .unwrap()
        .local_term(profile.mean_free_path());
    let settings = QuerySettings {
        method,
        epsilon,
        cull_tolerance: 1e-4,
    };
    let start = std::time::Instant::now();
    let mut queries = 0u64;
    let mut sum = Vec3::ZERO;
    while start.elapsed().as_secs_f64() < seconds {
        for p in &points {
            sum += cache.query(&profile, p, k, &settings).unwrap().total;
        }
        queries += points.len() as u64;
    }
    let ns = start.elapsed().as_nanos() as f64 / queries as f64;
    println!(
        "{} ε {epsilon}: {queries} queries, {ns:.0} ns per query (checksum {})",
        method.name(),
        sum.x
    );
}
