//! Small deterministic random number generators: PCG32 for streams of numbers and the
//! SplitMix64 mixer for hashing seeds and indices.
//!
//! Everything random in lucent (sample placement, jitter, test scenes) comes from here, so
//! results are a pure function of the seed on every platform and for every thread count:
//! parallel code gives each block of work its own PCG32 stream, selected by the block index.

/// PCG32, the XSH-RR generator with 64-bit state of O'Neill 2014 ("PCG: A Family of Simple
/// Fast Space-Efficient Statistically Good Algorithms for Random Number Generation",
/// HMC-CS-2014-0905). 2⁶³ independent streams of period 2⁶⁴; seeded like the reference
/// `pcg32_srandom_r`, so `Pcg32::new(42, 54)` reproduces the reference demo's output.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

/// The LCG multiplier of PCG32.
const PCG_MULTIPLIER: u64 = 6_364_136_223_846_793_005;

impl Pcg32 {
    /// A generator at position `seed` of stream `stream` (only the low 63 bits of `stream`
    /// matter).
    pub fn new(seed: u64, stream: u64) -> Pcg32 {
        let mut rng = Pcg32 {
            state: 0,
            inc: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG_MULTIPLIER).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// A uniform `f32` in `[0, 1)` with 24 random bits (every value a multiple of 2⁻²⁴).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// A uniform `f64` in `[0, 1)` with 53 random bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 * (1.0 / 9_007_199_254_740_992.0)
    }

    /// A uniform integer in `[0, bound)` without modulo bias (Lemire 2019, "Fast Random
    /// Integer Generation in an Interval"). `bound = 0` returns 0.
    pub fn next_below(&mut self, bound: u32) -> u32 {
        if bound == 0 {
            return 0;
        }
        let threshold = bound.wrapping_neg() % bound;
        loop {
            let m = self.next_u32() as u64 * bound as u64;
            if (m as u32) >= threshold {
                return (m >> 32) as u32;
            }
        }
    }
}

pub use lucent_core::internals::splitmix64;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg32_matches_the_reference_demo() {
        // pcg32-demo.c, "Round 1", seeded with pcg32_srandom_r(&rng, 42, 54).
        let mut rng = Pcg32::new(42, 54);
        let want = [
            0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e,
        ];
        for w in want {
            assert_eq!(rng.next_u32(), w);
        }
    }

    #[test]
    fn floats_are_in_the_unit_interval_with_the_right_mean() {
        let mut rng = Pcg32::new(1, 2);
        let n = 100_000;
        let (mut s32, mut s64) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let (a, b) = (rng.next_f32(), rng.next_f64());
            assert!((0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
            s32 += a as f64;
            s64 += b;
        }
        // Mean 1/2, standard error sqrt(1/12 / n) ≈ 0.0009; allow 5 sigma.
        assert!((s32 / n as f64 - 0.5).abs() < 0.0046);
        assert!((s64 / n as f64 - 0.5).abs() < 0.0046);
    }

    #[test]
    fn bounded_integers_are_uniform() {
        let mut rng = Pcg32::new(9, 9);
        let mut counts = [0u32; 7];
        for _ in 0..70_000 {
            counts[rng.next_below(7) as usize] += 1;
        }
        // Each bin expects 10000 with sigma ≈ 93; allow 5 sigma.
        assert!(
            counts.iter().all(|&c| c.abs_diff(10_000) < 465),
            "{counts:?}"
        );
        assert_eq!(rng.next_below(0), 0);
    }

    #[test]
    fn streams_and_seeds_differ() {
        let first = |seed, stream| Pcg32::new(seed, stream).next_u32();
        assert_ne!(first(1, 0), first(1, 1));
        assert_ne!(first(1, 0), first(2, 0));
        assert_eq!(first(5, 3), first(5, 3));
    }
}
