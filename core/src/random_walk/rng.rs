//! The random walk's generator: xoshiro256++ (Blackman & Vigna 2021, "Scrambled linear
//! pseudorandom number generators"), seeded through SplitMix64 as its authors recommend.
//!
//! Small, fast, with a 2²⁵⁶ − 1 period and no failures in BigCrush; its output is a pure
//! function of the seed, so a walk gives the same bits on every platform and thread count.

use crate::seed::splitmix64;

/// The golden-ratio increment of SplitMix64.
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// A xoshiro256++ generator.
#[derive(Clone, Debug)]
pub struct Xoshiro256 {
    state: [u64; 4],
}

impl Xoshiro256 {
    /// A generator whose state is the next four outputs of a SplitMix64 generator at `seed`
    /// (never all zero: SplitMix64's output function is a bijection, so four consecutive
    /// outputs are distinct).
    pub fn from_seed(seed: u64) -> Self {
        let mut state = [0; 4];
        for (i, s) in state.iter_mut().enumerate() {
            *s = splitmix64(seed.wrapping_add((i as u64).wrapping_mul(GAMMA)));
        }
        Xoshiro256 { state }
    }

    /// A generator with exactly this state (for checking against the reference outputs).
    #[cfg(test)]
    fn from_state(state: [u64; 4]) -> Self {
        Xoshiro256 { state }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.state;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// A uniform number in [0, 1) with 53 random bits (the top ones, which are the best
    /// scrambled).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_outputs_match_the_recurrence_worked_by_hand() {
        // From state (1, 2, 3, 4): rotl(1 + 4, 23) + 1 = 5·2²³ + 1; then the state becomes
        // (7, 0, 262146, rotl(6, 45)) and rotl(7 + 6·2⁴⁵, 23) + 7 = 7·2²³ + 3·2⁵ + 7.
        let mut rng = Xoshiro256::from_state([1, 2, 3, 4]);
        assert_eq!(rng.next_u64(), 5 * (1 << 23) + 1);
        assert_eq!(rng.next_u64(), 7 * (1 << 23) + 96 + 7);
    }

    #[test]
    fn uniform_is_in_the_unit_interval_with_the_right_mean() {
        let mut rng = Xoshiro256::from_seed(7);
        let n = 100_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = rng.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        // Mean 1/2 with standard error √(1/12 / n) ≈ 0.0009.
        assert!((sum / n as f64 - 0.5).abs() < 0.004);
        let mut other = Xoshiro256::from_seed(8);
        assert_ne!(Xoshiro256::from_seed(7).next_u64(), other.next_u64());
    }
}
