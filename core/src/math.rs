//! The one place transcendental functions come from.
//!
//! Scalar functions call `libm` (never `f32::exp` and friends, which need `std` and whose
//! results may differ between platforms' C libraries). The 8-lane `exp` used by the SIMD
//! traversal is a polynomial written here, tested against `libm` below.
//!
//! Bit-reproducibility: nothing here uses fused multiply-add or approximate reciprocal
//! instructions, so results depend only on IEEE-754 single-precision arithmetic.

/// e^x (libm).
#[inline]
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

/// e^x in double precision (libm).
#[inline]
pub fn exp64(x: f64) -> f64 {
    libm::exp(x)
}

/// eˣ − 1 without cancellation near 0 (libm).
#[inline]
pub fn expm1_64(x: f64) -> f64 {
    libm::expm1(x)
}

/// √x (libm; exact IEEE rounding).
#[inline]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// √x in double precision (libm).
#[inline]
pub fn sqrt64(x: f64) -> f64 {
    libm::sqrt(x)
}

/// (sin x, cos x) in double precision (libm).
#[inline]
pub fn sin_cos64(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// Natural logarithm (libm).
#[inline]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

/// Natural logarithm in double precision (libm).
#[inline]
pub fn ln64(x: f64) -> f64 {
    libm::log(x)
}

/// Base-2 logarithm (libm).
#[inline]
pub fn log2(x: f32) -> f32 {
    libm::log2f(x)
}

/// 2^x (libm).
#[inline]
pub fn exp2(x: f32) -> f32 {
    libm::exp2f(x)
}

/// Largest integer ≤ x (libm).
#[inline]
pub fn floor(x: f32) -> f32 {
    libm::floorf(x)
}

/// Cosine in double precision (libm).
#[inline]
pub fn cos64(x: f64) -> f64 {
    libm::cos(x)
}

/// Arc cosine in double precision (libm), in [0, π].
#[inline]
pub fn acos64(x: f64) -> f64 {
    libm::acos(x)
}

/// 2^k for an integer k in the normal range [−126, 127] (exact; built from the exponent bits).
#[inline]
pub fn pow2i(k: i32) -> f32 {
    debug_assert!((-126..=127).contains(&k));
    f32::from_bits(((k + 127) as u32) << 23)
}

/// 2^k in double precision for an integer k in [−1022, 1023] (exact; from the exponent bits).
#[inline]
pub fn pow2i64(k: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&k));
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// The floor of log₂ x for finite positive normal x, read off the exponent bits.
#[inline]
pub fn ilog2(x: f32) -> i32 {
    ((x.to_bits() >> 23) & 0xff) as i32 - 127
}

/// Polynomial coefficients of the Cephes single-precision `expf` kernel on
/// r ∈ [−ln2/2, ln2/2]: e^r ≈ 1 + r + r²·P(r).
pub(crate) const EXP_POLY: [f32; 6] = [
    5.000_000_1e-1,
    1.666_666_5e-1,
    4.166_579_6e-2,
    8.333_452e-3,
    1.398_199_9e-3,
    1.987_569_1e-4,
];
/// ln 2 split in two so that n·LN2_HI is exact for |n| ≤ 2^8 (Cody–Waite reduction).
pub(crate) const LN2_HI: f32 = 0.693_359_375;
/// The remainder ln 2 − LN2_HI.
pub(crate) const LN2_LO: f32 = -2.121_944_4e-4;
/// Below this, e^x is flushed to zero (e^−87.3 is about the smallest normal f32).
pub(crate) const EXP_MIN_ARG: f32 = -87.3;

/// e^x for x ≤ 0 by the same reduction and polynomial as the 8-lane version (used to test it
/// lane-for-lane, and by the local-integral table's interpolation, where it costs a quarter of
/// `libm::expf`; the scalar profile calls [`exp`]). Relative error below 4e-7; e^0 = 1
/// exactly.
#[inline]
pub fn exp_nonpositive_poly(x: f32) -> f32 {
    if x.is_nan() {
        return x;
    }
    if x < EXP_MIN_ARG {
        return 0.0;
    }
    let x = x.min(0.0);
    // Round to nearest by adding and subtracting 1.5·2^23 (valid for |x·log2e| < 2^22).
    let magic = 12_582_912.0_f32;
    let n = (x * core::f32::consts::LOG2_E + magic) - magic;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let p = EXP_POLY[0]
        + r * (EXP_POLY[1]
            + r * (EXP_POLY[2] + r * (EXP_POLY[3] + r * (EXP_POLY[4] + r * EXP_POLY[5]))));
    let e = 1.0 + r + r * r * p;
    e * pow2i(n as i32)
}

#[cfg(feature = "simd")]
mod wide_exp {
    use super::*;
    use wide::{f32x8, i32x8};

    /// e^x on eight lanes for x ≤ 0 (the dipole only ever needs e^(−σ d)): Cody–Waite range
    /// reduction x = n ln2 + r, the Cephes degree-7 kernel on r, and 2^n assembled from
    /// exponent bits. Lanes below −87.3 give 0; NaN lanes give NaN. Same arithmetic, lane for
    /// lane, as [`exp_nonpositive_poly`].
    #[inline(always)]
    pub fn exp_nonpositive_x8(x: f32x8) -> f32x8 {
        let zero = f32x8::splat(0.0);
        let underflow = x.simd_lt(f32x8::splat(EXP_MIN_ARG));
        // The plain min/max (`minps`/`maxps`): the NaN-aware ones cost a compare and a blend
        // each, and NaN lanes are restored below.
        let xc = x.fast_max(f32x8::splat(EXP_MIN_ARG)).fast_min(zero);
        let magic = f32x8::splat(12_582_912.0);
        let n = (xc * f32x8::splat(core::f32::consts::LOG2_E) + magic) - magic;
        let r = (xc - n * f32x8::splat(LN2_HI)) - n * f32x8::splat(LN2_LO);
        let c = |i: usize| f32x8::splat(EXP_POLY[i]);
        let p = c(0) + r * (c(1) + r * (c(2) + r * (c(3) + r * (c(4) + r * c(5)))));
        let e = f32x8::splat(1.0) + r + r * r * p;
        // n is an integer-valued float in [−126, 0]: its exponent bits give 2^n exactly (the
        // plain conversion is exact on integers; `round_int` adds range checks not needed here).
        let bits: i32x8 = (n.fast_round_int() + i32x8::splat(127)) << 23;
        let scale: f32x8 = wide::bytemuck::cast(bits);
        // x − x is 0, or NaN in NaN lanes (and in −∞ lanes, which underflow): adding it keeps
        // NaN lanes NaN for two instructions where a compare and a select took four. Then
        // flush underflow to zero.
        #[allow(clippy::eq_op)] // x − x is the point: 0, or NaN
        let nan_or_zero = x - x;
        underflow.select(zero, e * scale + nan_or_zero)
    }
}

#[cfg(feature = "simd")]
pub use wide_exp::exp_nonpositive_x8;

/// [`exp_nonpositive_poly`] of eight values at once, bit for bit: the 8-lane version where the
/// `simd` feature is on, else a loop. For callers that gather several exponentials (a
/// texture-mapped material's dipoles and K per shading point) and need the scalar path's bits
/// in every build — the scalar lanes' `exp_nonpositive` is libm's.
#[inline]
pub fn exp_nonpositive_poly_8(x: [f32; 8]) -> [f32; 8] {
    #[cfg(feature = "simd")]
    {
        exp_nonpositive_x8(wide::f32x8::from(x)).to_array()
    }
    #[cfg(not(feature = "simd"))]
    {
        x.map(exp_nonpositive_poly)
    }
}

/// One lane of [`exp_nonpositive_x8`], the same operations in the same order, branch-free so
/// that a loop of eight calls vectorises (the AVX2 traversal's [`crate::lanes::ArrayLanes`]).
/// 2^n is assembled without a float-to-int conversion: n + (2²³ + 127) is exact (n is an
/// integer in [−126, 0]) and holds n + 127 in its low mantissa bits, which the shift moves
/// into the exponent field while the shift drops the rest: the bits of the conversion route.
#[cfg(feature = "simd")]
#[inline(always)]
pub(crate) fn exp_nonpositive_lane(x: f32) -> f32 {
    let underflow = x < EXP_MIN_ARG;
    // `minps`/`maxps` semantics (the second operand where either is NaN), as the 8-lane
    // version: NaN lanes are restored below.
    let xc = if x > EXP_MIN_ARG { x } else { EXP_MIN_ARG };
    let xc = if xc < 0.0 { xc } else { 0.0 };
    let magic = 12_582_912.0_f32;
    let n = (xc * core::f32::consts::LOG2_E + magic) - magic;
    let r = (xc - n * LN2_HI) - n * LN2_LO;
    let c = EXP_POLY;
    let p = c[0] + r * (c[1] + r * (c[2] + r * (c[3] + r * (c[4] + r * c[5]))));
    let e = 1.0 + r + r * r * p;
    let scale = f32::from_bits((n + 8_388_735.0).to_bits() << 23);
    #[allow(clippy::eq_op)] // x − x is the point: 0, or NaN
    let nan_or_zero = x - x;
    let v = e * scale + nan_or_zero;
    if underflow { 0.0 } else { v }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative error of the polynomial against libm over the whole range the dipole uses.
    #[test]
    fn exp_polynomial_matches_libm() {
        let mut worst = 0.0_f32;
        let mut x = -87.0_f32;
        while x <= 0.0 {
            let got = exp_nonpositive_poly(x);
            let want = exp(x);
            worst = worst.max(((got - want) / want).abs());
            x += 0.000_37;
        }
        assert!(worst < 4e-7, "worst relative error {worst}");
        assert_eq!(exp_nonpositive_poly(0.0), 1.0);
        assert_eq!(exp_nonpositive_poly(-200.0), 0.0);
        assert_eq!(exp_nonpositive_poly(f32::NEG_INFINITY), 0.0);
        assert!(exp_nonpositive_poly(f32::NAN).is_nan());
    }

    /// Eight lanes at once ([`exp_nonpositive_poly_8`]: [`exp_nonpositive_x8`] with `simd`, a
    /// loop without) are the scalar polynomial bit for bit, in either build.
    #[test]
    fn exp_x8_equals_scalar_polynomial_lane_for_lane() {
        let mut x = -90.0_f32;
        while x <= 0.0 {
            let lanes = [
                x,
                x * 0.5,
                x * 0.25,
                x * 0.125,
                x * 0.01,
                x * 1e-4,
                -0.0,
                x * 0.9,
            ];
            let got = exp_nonpositive_poly_8(lanes);
            for (g, l) in got.iter().zip(lanes) {
                assert_eq!(g.to_bits(), exp_nonpositive_poly(l).to_bits(), "x = {l}");
            }
            x += 0.0123;
        }
        let special = [
            f32::NAN,
            f32::NEG_INFINITY,
            -87.31,
            -87.29,
            0.0,
            -1e-30,
            -1.0,
            -2.0,
        ];
        let got = exp_nonpositive_poly_8(special);
        assert!(got[0].is_nan());
        assert_eq!(got[1], 0.0);
        assert_eq!(got[2], 0.0);
        assert!(got[3] > 0.0);
        assert_eq!(got[4], 1.0);
    }

    #[cfg(feature = "simd")]
    #[test]
    fn exp_lane_equals_x8_bit_for_bit() {
        use wide::f32x8;
        let mut lanes = [0.0_f32; 8];
        let mut x = -95.0_f32;
        let mut i = 0;
        let check = |lanes: [f32; 8]| {
            let want = exp_nonpositive_x8(f32x8::from(lanes)).to_array();
            for (w, l) in want.iter().zip(lanes) {
                assert_eq!(w.to_bits(), exp_nonpositive_lane(l).to_bits(), "x = {l}");
            }
        };
        while x <= 1.0 {
            lanes[i % 8] = x;
            i += 1;
            if i % 8 == 0 {
                check(lanes);
            }
            x += 0.001_37;
        }
        check([
            f32::NAN,
            f32::NEG_INFINITY,
            f32::INFINITY,
            -87.3,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::MAX,
        ]);
    }

    #[test]
    fn pow2_and_ilog2_are_exact() {
        for k in -126..=127 {
            let p = pow2i(k);
            assert_eq!(p, libm::exp2f(k as f32));
            assert_eq!(ilog2(p), k);
            assert_eq!(ilog2(p * 1.999), k);
        }
    }
}
