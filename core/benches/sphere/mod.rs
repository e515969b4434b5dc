//! The benchmarks' data set, shared by `core/benches/core.rs` and `raster/benches/simd.rs` (the
//! latter includes this file by path): the talk's sphere, radius 1 cm, marble at 10 mm per
//! unit, lit from +z so that there is a terminator, 23k irradiance samples, and queries at
//! random points on the surface.

use lucent_core::glam::Vec3;
use lucent_core::{IrradianceCache, LocalIntegralTable, LocalTerm, Profile, Sample, ShadingPoint};

/// Irradiance samples on the sphere.
pub const N: usize = 23_000;
/// Query points per benchmark iteration.
pub const QUERIES: usize = 256;

/// SplitMix64 floats in [0, 1): the same points on every machine.
pub struct Rng(pub u64);

impl Rng {
    pub fn f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniformly distributed point on the unit sphere.
    pub fn on_sphere(&mut self) -> Vec3 {
        let z = self.f32() * 2.0 - 1.0;
        let phi = self.f32() * std::f32::consts::TAU;
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), z)
    }
}

/// `n` samples on the sphere, lit from +z, each with an equal share of its area.
pub fn samples(n: usize) -> Vec<Sample> {
    let mut rng = Rng(1);
    let area = 4.0 * std::f32::consts::PI / n as f32;
    (0..n)
        .map(|_| {
            let p = rng.on_sphere();
            Sample {
                position: p,
                area,
                irradiance: Vec3::splat(p.z.max(0.0)),
            }
        })
        .collect()
}

/// The cache of [`N`] samples, the marble, N10's K and the query points, built once.
pub struct Setup {
    pub cache: IrradianceCache,
    pub profile: Profile,
    pub k: LocalTerm,
    pub points: Vec<ShadingPoint>,
    pub table: LocalIntegralTable,
}

/// The shared [`Setup`], built on first use.
pub fn setup() -> &'static Setup {
    static SETUP: std::sync::OnceLock<Setup> = std::sync::OnceLock::new();
    SETUP.get_or_init(|| {
        let cache = IrradianceCache::build(&samples(N)).unwrap();
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
            table,
        }
    })
}
