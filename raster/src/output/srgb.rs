//! The sRGB transfer function (IEC 61966-2-1) and an exact, deterministic 8-bit encoder.
//!
//! Encoding (linear → sRGB), for linear `x` in [0, 1]:
//!
//! ```text
//! srgb(x) = 12.92 · x                     if x ≤ 0.0031308
//!         = 1.055 · x^(1/2.4) − 0.055     otherwise
//! ```
//!
//! and decoding is its inverse (`v / 12.92` below `v = 0.04045`, `((v + 0.055) / 1.055)^2.4`
//! above).
//!
//! # The 8-bit encoder
//!
//! With exposure `E` stops, the exposed value `v = x · 2^E` is computed in `f32` (exact for
//! integer `E`), and its code is `round(255 · srgb(clamp(v, 0, 1)))`. Instead of evaluating
//! `powf` per pixel (slow, and whose last bit depends on the platform's libm), [`Srgb8Encoder`]
//! precomputes the 255 decision thresholds `T_k = srgb⁻¹((k + ½) / 255)` in `f64`, rounds each
//! *up* to the nearest `f32` and finds the code by binary search: code ≥ k + 1 exactly when
//! `v ≥ T_k`. This is the exact rounding of the real-valued function for every `f32` input,
//! and the same on every platform: each `T_k` is more than 10⁻¹² (relative) away from the
//! nearest `f32`, far more than any libm's `f64` error (tested). NaN encodes to 0, +∞ to 255.

/// Linear → sRGB-encoded value (no clamping; meaningful on [0, 1]).
pub fn linear_to_srgb(x: f64) -> f64 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB-encoded value → linear (no clamping; meaningful on [0, 1]).
pub fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The linear value of every 8-bit sRGB code.
pub fn srgb8_to_linear_table() -> [f32; 256] {
    let mut table = [0.0f32; 256];
    for (k, t) in table.iter_mut().enumerate() {
        *t = srgb_to_linear(k as f64 / 255.0) as f32;
    }
    table
}

/// Linear float → 8-bit sRGB code with a fixed exposure, exactly rounded (see the module doc).
#[derive(Clone, Debug)]
pub struct Srgb8Encoder {
    /// `thresholds[k]` = the smallest `f32` ≥ `srgb⁻¹((k + ½) / 255)`.
    thresholds: [f32; 255],
    /// `2^exposure`.
    scale: f32,
}

impl Srgb8Encoder {
    /// An encoder that multiplies by `2^exposure` (exposure in stops) before encoding.
    pub fn new(exposure: f32) -> Self {
        let mut thresholds = [0.0f32; 255];
        for (k, t) in thresholds.iter_mut().enumerate() {
            let exact = srgb_to_linear((k as f64 + 0.5) / 255.0);
            let mut f = exact as f32;
            if (f as f64) < exact {
                f = f.next_up();
            }
            *t = f;
        }
        Srgb8Encoder {
            thresholds,
            scale: (exposure as f64).exp2() as f32,
        }
    }

    /// The 8-bit code of the linear value `x`.
    #[inline]
    pub fn encode(&self, x: f32) -> u8 {
        let v = x * self.scale;
        // The number of thresholds ≤ v is the code (0..=255); NaN is below every threshold.
        self.thresholds.partition_point(|&t| t <= v) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference: the real-valued definition evaluated in f64, clamped and rounded, applied
    /// to the exposed value `x · 2^exposure` rounded to f32 (as documented).
    fn oracle(x: f32, exposure: f64) -> u8 {
        let exposed = x * exposure.exp2() as f32;
        let v = (exposed as f64).clamp(0.0, 1.0);
        (linear_to_srgb(v) * 255.0).round() as u8
    }

    #[test]
    fn hand_computed_codes() {
        let e = Srgb8Encoder::new(0.0);
        // 0.5^(1/2.4) = 0.7491535; 1.055·0.7491535 − 0.055 = 0.7353569; ·255 = 187.516 → 188.
        assert_eq!(e.encode(0.5), 188);
        // 0.18^(1/2.4) = 0.4894286; → 0.4613472; ·255 = 117.644 → 118.
        assert_eq!(e.encode(0.18), 118);
        // Linear segment: 12.92·0.001 = 0.01292; ·255 = 3.2946 → 3.
        assert_eq!(e.encode(0.001), 3);
        // 12.92·0.002 = 0.02584; ·255 = 6.589 → 7.
        assert_eq!(e.encode(0.002), 7);
        // 0.0031308 is the knee: 12.92·0.0031308 = 0.040450; ·255 = 10.31 → 10.
        assert_eq!(e.encode(0.0031308), 10);
        assert_eq!(e.encode(0.0), 0);
        assert_eq!(e.encode(1.0), 255);
        assert_eq!(e.encode(-3.0), 0);
        assert_eq!(e.encode(7.0), 255);
        assert_eq!(e.encode(f32::NAN), 0);
        assert_eq!(e.encode(f32::INFINITY), 255);
        assert_eq!(e.encode(f32::NEG_INFINITY), 0);
    }

    #[test]
    fn exposure_scales_by_powers_of_two() {
        // +1 stop: 0.25 → 0.5 → 188; −2 stops: 2.0 → 0.5 → 188.
        assert_eq!(Srgb8Encoder::new(1.0).encode(0.25), 188);
        assert_eq!(Srgb8Encoder::new(-2.0).encode(2.0), 188);
        // +0.5 stop: 0.5·√2 = 0.70711; ^(1/2.4) = 0.86566 → 0.85827; ·255 = 218.86 → 219.
        assert_eq!(Srgb8Encoder::new(0.5).encode(0.5), 219);
    }

    #[test]
    fn matches_f64_oracle_on_a_dense_sweep() {
        for exposure in [0.0f64, 1.0, -1.5] {
            let e = Srgb8Encoder::new(exposure as f32);
            // Every 97th f32 bit pattern between 1e-6 and 2.0, plus exact code midpoints.
            let lo = 1e-6f32.to_bits();
            let hi = 2.0f32.to_bits();
            let mut bits = lo;
            while bits < hi {
                let x = f32::from_bits(bits);
                assert_eq!(
                    e.encode(x),
                    oracle(x, exposure),
                    "x = {x:e}, exposure {exposure}"
                );
                bits += 97;
            }
        }
    }

    #[test]
    fn thresholds_are_tight() {
        // Just below each threshold gives k, at the threshold k + 1.
        let e = Srgb8Encoder::new(0.0);
        for (k, &t) in e.thresholds.iter().enumerate() {
            // The exact threshold is not within 1e-12 of an f32, so a slightly different
            // libm `powf` cannot move it to another f32.
            let exact = srgb_to_linear((k as f64 + 0.5) / 255.0);
            assert!((t as f64 - exact) / exact > 1e-12, "k = {k}");
            assert!((exact - t.next_down() as f64) / exact > 1e-12, "k = {k}");
            assert_eq!(e.encode(t) as usize, k + 1);
            assert_eq!(e.encode(t.next_down()) as usize, k);
        }
    }

    #[test]
    fn decode_inverts_encode_on_codes() {
        let table = srgb8_to_linear_table();
        let e = Srgb8Encoder::new(0.0);
        for (k, &lin) in table.iter().enumerate() {
            assert_eq!(e.encode(lin) as usize, k);
        }
        // Hand values: code 188 → ((188/255 + 0.055)/1.055)^2.4 = 0.50289.
        assert!((table[188] - 0.502886).abs() < 1e-5, "{}", table[188]);
        assert_eq!(table[0], 0.0);
        assert_eq!(table[255], 1.0);
    }
}
