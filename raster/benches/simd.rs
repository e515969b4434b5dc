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
use lucent_core::{
    IrradianceCache, LocalIntegralTable, LocalTerm, Method, Profile, QuerySettings, Sample,
    ShadingPoint,
};
use lucent_raster::render::simd::Avx2;

const N: usize = 23_000;
const QUERIES: usize = 256;

fn main() {
    if Avx2::detect().is_none() {
        println!("skipped: this CPU has no AVX2");
        return;
    }
    divan::main();
}

/// SplitMix64 floats in [0, 1).
struct Rng(u64);
impl Rng {
    fn f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn on_sphere(&mut self) -> Vec3 {
        let z = self.f32() * 2.0 - 1.0;
        let phi = self.f32() * std::f32::consts::TAU;
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

struct Setup {
    cache: IrradianceCache,
    profile: Profile,
    k: LocalTerm,
    points: Vec<ShadingPoint>,
}

fn setup() -> &'static Setup {
    static SETUP: std::sync::OnceLock<Setup> = std::sync::OnceLock::new();
    SETUP.get_or_init(|| {
        let mut rng = Rng(1);
        let area = 4.0 * std::f32::consts::PI / N as f32;
        let samples: Vec<Sample> = (0..N)
            .map(|_| {
                let p = rng.on_sphere();
                Sample {
                    position: p,
                    area,
                    irradiance: Vec3::splat(p.z.max(0.0)),
                }
            })
            .collect();
        let cache = IrradianceCache::build(&samples).unwrap();
        let profile =
            Profile::from_preset(lucent_core::presets::find("marble").unwrap(), 10.0).unwrap();
        let alpha = cache.smoothing_radius(1.5);
        let table = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0).unwrap();
        let k = table.local_term(profile.mean_free_path());
        let mut rng = Rng(2);
        let points = (0..QUERIES)
            .map(|_| {
                let p = rng.on_sphere();
                ShadingPoint {
                    position: p,
                    irradiance: Vec3::splat(p.z.max(0.0)),
                }
            })
            .collect();
        Setup {
            cache,
            profile,
            k,
            points,
        }
    })
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
