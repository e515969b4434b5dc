//! Eight f32 lanes: the batch width of every cache traversal.
//!
//! The traversal code is written once against the [`Lanes`] trait and compiled for two lane
//! types:
//!
//! - [`SimdLanes`] (feature `simd`, the default): `wide::f32x8` — two SSE registers on baseline
//!   x86-64, one AVX register where enabled, NEON pairs on aarch64;
//! - [`ScalarLanes`]: a plain `[f32; 8]` evaluated lane by lane with libm — the fallback, and
//!   the reference the SIMD path is tested against;
//! - [`ArrayLanes`] (feature `simd`): an aligned `[f32; 8]` with the arithmetic of
//!   [`SimdLanes`], written for the compiler's vectoriser — the lane type of the AVX2
//!   traversal ([`crate::IrradianceCache::query_planned_avx2`]), where it is one ymm
//!   register.
//!
//! [`DefaultLanes`] is what the public query API uses.
//!
//! Why eight: an octree node has at most eight children and a leaf at most eight samples, so
//! one batch is exactly one node's children or one leaf's samples.

use core::fmt::Debug;
use core::ops::{Add, BitAnd, BitOr, Div, Mul, Not, Sub};

use crate::math;

/// Batch width.
pub const LANES: usize = 8;

/// A lane mask with one bit per lane (bit i = lane i).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mask(pub u32);

impl Mask {
    /// The first `n` lanes set (n ≤ 8).
    #[inline(always)]
    pub fn first(n: u32) -> Mask {
        Mask((1u32 << n.min(8)) - 1)
    }
    /// True if any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0 != 0
    }
}

impl BitAnd for Mask {
    type Output = Mask;
    #[inline(always)]
    fn bitand(self, o: Mask) -> Mask {
        Mask(self.0 & o.0)
    }
}
impl BitOr for Mask {
    type Output = Mask;
    #[inline(always)]
    fn bitor(self, o: Mask) -> Mask {
        Mask(self.0 | o.0)
    }
}
impl Not for Mask {
    type Output = Mask;
    #[inline(always)]
    fn not(self) -> Mask {
        Mask(!self.0 & 0xff)
    }
}

/// Eight f32 lanes with the operations the traversal needs.
pub trait Lanes:
    Copy + Debug + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// A short name for benchmarks and test messages.
    const NAME: &'static str;
    /// Whether the traversal is inlined whole into its caller. False: the profile evaluation
    /// and each mode's traversal stay out of line (`cache/traverse.rs` says why). True for a
    /// lane type compiled inside a `#[target_feature]` function, where an out-of-line call
    /// would be compiled without the feature.
    const INLINE_TRAVERSAL: bool = false;
    /// All lanes `v`.
    fn splat(v: f32) -> Self;
    /// The first eight values of `src` (callers guarantee `src.len() >= 8` through padding).
    fn load(src: &[f32]) -> Self;
    /// The lanes as an array.
    fn to_array(self) -> [f32; LANES];
    /// Lane-wise √.
    fn sqrt(self) -> Self;
    /// Lane-wise e^x for x ≤ 0 (lanes below −87.3 give 0).
    fn exp_nonpositive(self) -> Self;
    /// Lane-wise minimum, `if self < o { self } else { o }`: `o` where either is NaN (the
    /// plain `minps`; every caller clamps against a bound that is never NaN, and the NaN-aware
    /// version cost a compare and a blend more per register).
    fn min(self, o: Self) -> Self;
    /// Lane-wise maximum, `if self > o { self } else { o }`: `o` where either is NaN (`maxps`).
    fn max(self, o: Self) -> Self;
    /// Lanes where `self < o`.
    fn lt(self, o: Self) -> Mask;
    /// Lane i = `if m has lane i { t } else { 0 }`.
    fn keep(self, m: Mask) -> Self;
    /// Sum of the lanes (fixed order, so deterministic).
    fn reduce_add(self) -> f32;
}

/// The lane type used by the public API: SIMD when the `simd` feature is on.
#[cfg(feature = "simd")]
pub type DefaultLanes = SimdLanes;
/// The lane type used by the public API: SIMD when the `simd` feature is on.
#[cfg(not(feature = "simd"))]
pub type DefaultLanes = ScalarLanes;

/// The scalar fallback: eight lanes evaluated one by one with libm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalarLanes(pub [f32; LANES]);

macro_rules! scalar_binop {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for ScalarLanes {
            type Output = ScalarLanes;
            #[inline(always)]
            fn $f(self, o: ScalarLanes) -> ScalarLanes {
                let mut r = [0.0; LANES];
                for i in 0..LANES {
                    r[i] = self.0[i] $op o.0[i];
                }
                ScalarLanes(r)
            }
        }
    };
}
scalar_binop!(Add, add, +);
scalar_binop!(Sub, sub, -);
scalar_binop!(Mul, mul, *);
scalar_binop!(Div, div, /);

impl ScalarLanes {
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> ScalarLanes {
        let mut r = self.0;
        for v in &mut r {
            *v = f(*v);
        }
        ScalarLanes(r)
    }
}

impl Lanes for ScalarLanes {
    const NAME: &'static str = "scalar";
    #[inline(always)]
    fn splat(v: f32) -> Self {
        ScalarLanes([v; LANES])
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let mut r = [0.0; LANES];
        r.copy_from_slice(&src[..LANES]);
        ScalarLanes(r)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        self.0
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(math::sqrt)
    }
    #[inline(always)]
    fn exp_nonpositive(self) -> Self {
        self.map(math::exp)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        let mut r = self.0;
        for i in 0..LANES {
            r[i] = if r[i] < o.0[i] { r[i] } else { o.0[i] };
        }
        ScalarLanes(r)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        let mut r = self.0;
        for i in 0..LANES {
            r[i] = if r[i] > o.0[i] { r[i] } else { o.0[i] };
        }
        ScalarLanes(r)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Mask {
        let mut m = 0;
        for i in 0..LANES {
            m |= ((self.0[i] < o.0[i]) as u32) << i;
        }
        Mask(m)
    }
    #[inline(always)]
    fn keep(self, m: Mask) -> Self {
        let mut r = self.0;
        for (i, v) in r.iter_mut().enumerate() {
            if m.0 & (1 << i) == 0 {
                *v = 0.0;
            }
        }
        ScalarLanes(r)
    }
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        let a = self.0;
        ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]))
    }
}

/// Lane masks as floats with all bits set, indexed by an 8-bit lane mask (`keep` of the SIMD
/// lane types: one load and an `and`).
#[cfg(feature = "simd")]
const fn lane_mask_table() -> [[u32; LANES]; 256] {
    let mut t = [[0u32; LANES]; 256];
    let mut m = 0;
    while m < 256 {
        let mut i = 0;
        while i < LANES {
            if m & (1 << i) != 0 {
                t[m][i] = u32::MAX;
            }
            i += 1;
        }
        m += 1;
    }
    t
}
#[cfg(feature = "simd")]
pub(crate) static LANE_MASKS: [[u32; LANES]; 256] = lane_mask_table();

#[cfg(feature = "simd")]
pub use simd::SimdLanes;

#[cfg(feature = "simd")]
mod array;
#[cfg(feature = "simd")]
pub use array::ArrayLanes;
#[cfg(all(feature = "simd", any(target_arch = "x86", target_arch = "x86_64")))]
pub(crate) use array::permute_avx2;

#[cfg(feature = "simd")]
mod simd {
    use super::*;
    use wide::f32x8;

    /// Eight lanes in SIMD registers (`wide::f32x8`).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct SimdLanes(pub f32x8);

    macro_rules! simd_binop {
        ($tr:ident, $f:ident, $op:tt) => {
            impl $tr for SimdLanes {
                type Output = SimdLanes;
                #[inline(always)]
                fn $f(self, o: SimdLanes) -> SimdLanes {
                    SimdLanes(self.0 $op o.0)
                }
            }
        };
    }
    simd_binop!(Add, add, +);
    simd_binop!(Sub, sub, -);
    simd_binop!(Mul, mul, *);
    simd_binop!(Div, div, /);

    impl Lanes for SimdLanes {
        const NAME: &'static str = "simd";
        #[inline(always)]
        fn splat(v: f32) -> Self {
            SimdLanes(f32x8::splat(v))
        }
        #[inline(always)]
        fn load(src: &[f32]) -> Self {
            let a: [f32; LANES] = src[..LANES].try_into().unwrap_or([0.0; LANES]);
            SimdLanes(f32x8::from(a))
        }
        #[inline(always)]
        fn to_array(self) -> [f32; LANES] {
            self.0.to_array()
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            SimdLanes(self.0.sqrt())
        }
        #[inline(always)]
        fn exp_nonpositive(self) -> Self {
            SimdLanes(math::exp_nonpositive_x8(self.0))
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            SimdLanes(self.0.fast_min(o.0))
        }
        #[inline(always)]
        fn max(self, o: Self) -> Self {
            SimdLanes(self.0.fast_max(o.0))
        }
        #[inline(always)]
        fn lt(self, o: Self) -> Mask {
            Mask(self.0.simd_lt(o.0).to_bitmask())
        }
        #[inline(always)]
        fn keep(self, m: Mask) -> Self {
            let bits: f32x8 = wide::bytemuck::cast(LANE_MASKS[(m.0 & 0xff) as usize]);
            SimdLanes(self.0 & bits)
        }
        #[inline(always)]
        fn reduce_add(self) -> f32 {
            let a = self.0.to_array();
            ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_ops<L: Lanes>() {
        let a = [1.0, -2.0, 3.5, 0.0, 8.0, -0.5, 100.0, 1e-3];
        let b = [2.0, -3.0, 3.5, 1.0, -8.0, 0.5, 0.25, 1e3];
        let (la, lb) = (L::load(&a), L::load(&b));
        for i in 0..LANES {
            assert_eq!((la + lb).to_array()[i], a[i] + b[i]);
            assert_eq!((la * lb).to_array()[i], a[i] * b[i]);
            assert_eq!((la / lb).to_array()[i], a[i] / b[i]);
            assert_eq!(la.min(lb).to_array()[i], a[i].min(b[i]));
            assert_eq!(la.max(lb).to_array()[i], a[i].max(b[i]));
            // NaN in either operand gives the second one.
            let nan = L::splat(f32::NAN);
            assert!(nan.min(lb).to_array()[i] == b[i] && nan.max(lb).to_array()[i] == b[i]);
            assert!(la.min(nan).to_array()[i].is_nan() && la.max(nan).to_array()[i].is_nan());
            assert_eq!(la.lt(lb).0 >> i & 1 == 1, a[i] < b[i]);
            assert_eq!(
                nan.lt(lb).0 | la.lt(nan).0,
                0,
                "NaN is never less or greater"
            );
            let kept = la.keep(Mask(0b1010_0101)).to_array()[i];
            assert_eq!(kept, if 0b1010_0101 >> i & 1 == 1 { a[i] } else { 0.0 });
        }
        let sum = ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]));
        assert_eq!(la.reduce_add(), sum);
        assert_eq!(Mask::first(3), Mask(0b111));
        assert_eq!(!Mask(0b1), Mask(0xfe));
    }

    #[test]
    fn scalar_lanes_ops() {
        check_ops::<ScalarLanes>();
    }

    #[cfg(feature = "simd")]
    #[test]
    fn simd_lanes_ops() {
        check_ops::<SimdLanes>();
    }

    #[cfg(feature = "simd")]
    #[test]
    fn array_lanes_ops() {
        check_ops::<ArrayLanes>();
    }

    /// Every operation of [`ArrayLanes`] gives the bits of [`SimdLanes`], on values that
    /// include ±0, subnormals, infinities and NaN.
    #[cfg(feature = "simd")]
    #[test]
    fn array_lanes_equal_simd_lanes_bit_for_bit() {
        let specials = [
            0.0,
            -0.0,
            1e-40,
            -1e-40,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MAX,
            -87.4,
            -3.25,
            2.5,
            1e30,
        ];
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            match state % 4 {
                0 => specials[(state >> 8) as usize % specials.len()],
                1 => f32::from_bits((state >> 32) as u32),
                _ => ((state >> 40) as f32 / 16_777_216.0 - 0.75) * 200.0,
            }
        };
        // Bits, except that any NaN equals any other (the compiler may commute the operands
        // of an addition or a product, and with them which NaN payload propagates).
        let bits = |l: [f32; LANES]| l.map(|v| if v.is_nan() { u32::MAX } else { v.to_bits() });
        for _ in 0..20_000 {
            let a: [f32; LANES] = core::array::from_fn(|_| next());
            let b: [f32; LANES] = core::array::from_fn(|_| next());
            let (sa, sb) = (SimdLanes::load(&a), SimdLanes::load(&b));
            let (aa, ab) = (ArrayLanes::load(&a), ArrayLanes::load(&b));
            let pairs = [
                ((sa + sb).to_array(), (aa + ab).to_array()),
                ((sa - sb).to_array(), (aa - ab).to_array()),
                ((sa * sb).to_array(), (aa * ab).to_array()),
                ((sa / sb).to_array(), (aa / ab).to_array()),
                (sa.sqrt().to_array(), aa.sqrt().to_array()),
                (
                    sa.exp_nonpositive().to_array(),
                    aa.exp_nonpositive().to_array(),
                ),
                (sa.min(sb).to_array(), aa.min(ab).to_array()),
                (sa.max(sb).to_array(), aa.max(ab).to_array()),
            ];
            for (s, r) in pairs {
                assert_eq!(bits(s), bits(r), "a = {a:?}, b = {b:?}");
            }
            assert_eq!(sa.lt(sb), aa.lt(ab));
            let m = Mask((a[0].to_bits() ^ b[1].to_bits()) & 0xff);
            assert_eq!(bits(sa.keep(m).to_array()), bits(aa.keep(m).to_array()));
            let sums = (sa.reduce_add(), aa.reduce_add());
            assert_eq!(bits([sums.0; LANES]), bits([sums.1; LANES]));
        }
    }
}
