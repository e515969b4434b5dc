//! Shared helpers for the core's integration tests: a seeded generator and sample sets.

use lucent_core::glam::Vec3;
use lucent_core::{LocalTerm, Sample};

/// A local term with α and K chosen independently (the oracles take them apart).
pub fn term(alpha: f32, k: Vec3) -> LocalTerm {
    lucent_core::internals::local_term(alpha, k)
}

/// SplitMix64: tiny, seeded, good enough for test data.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }
    pub fn vec3(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}

/// `n` samples on the surface of a sphere of radius `r`, with irradiance from a light along +z
/// (a shadow terminator) and random areas around `r²·4π/n`.
pub fn sphere_samples(n: usize, r: f32, seed: u64) -> Vec<Sample> {
    let mut rng = Rng(seed);
    let mean_area = 4.0 * std::f32::consts::PI * r * r / n as f32;
    (0..n)
        .map(|_| {
            let z = rng.range(-1.0, 1.0);
            let phi = rng.range(0.0, std::f32::consts::TAU);
            let s = (1.0 - z * z).max(0.0).sqrt();
            let n = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            let light = n.z.max(0.0);
            Sample {
                position: n * r,
                area: mean_area * rng.range(0.8, 1.2),
                irradiance: Vec3::new(light, 0.5 * light, 0.25 * light + 0.01),
            }
        })
        .collect()
}

/// `n` samples in a random box, random areas and irradiance.
pub fn box_samples(n: usize, size: f32, seed: u64) -> Vec<Sample> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| Sample {
            position: rng.vec3(-size, size),
            area: rng.range(0.0, 2.0) * size * size / n as f32,
            irradiance: rng.vec3(0.0, 4.0),
        })
        .collect()
}

/// Largest relative difference over channels, with an absolute floor relative to `scale`.
pub fn rel_err(got: Vec3, want: Vec3) -> f32 {
    ((got - want).abs() / want.abs().max(Vec3::splat(1e-30))).max_element()
}

/// A square grid of `n × n` samples of spacing `h` centred on the origin, irradiance `e`.
pub fn plane(n: usize, h: f32, e: Vec3) -> Vec<Sample> {
    let half = 0.5 * n as f32 * h;
    let mut samples = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            samples.push(Sample {
                position: Vec3::new(
                    -half + (i as f32 + 0.5) * h,
                    -half + (j as f32 + 0.5) * h,
                    0.0,
                ),
                area: h * h,
                irradiance: e,
            });
        }
    }
    samples
}
