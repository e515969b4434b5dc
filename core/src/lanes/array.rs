//! [`ArrayLanes`]: eight lanes as a plain array, for the AVX2 traversal.
//!
//! `wide::f32x8` fixes its representation when the crate is compiled: two SSE registers on
//! baseline x86-64, whatever the function it is used in enables. This type has no fixed
//! representation: every operation is a loop over the eight lanes of a 32-byte-aligned
//! `[f32; 8]` (fully unrolled), which the compiler vectorises for the instruction set of the
//! function it is inlined into. Inside a `#[target_feature(enable = "avx2")]` function that
//! is one ymm register per value; elsewhere, SSE pairs (the baseline path keeps
//! [`super::SimdLanes`], whose SSE code is written out by hand).
//!
//! The arithmetic is that of [`super::SimdLanes`] operation for operation (IEEE-754 single
//! precision, no fused multiply-add, the x86 `minps`/`maxps` semantics for `min`/`max`), so the
//! two types give identical bits (tested in `lanes.rs`, in `core/tests/it/queries.rs` and,
//! compiled for AVX2, in the renderer's `render::simd`). Loops, not `core::array::from_fn` or
//! `map`: inlined into the AVX2 traversal, those were left as out-of-line calls, compiled
//! without AVX2.
//!
//! One operation has no loop the compiler turns into its instruction: a variable permutation
//! of the lanes. [`permute_avx2`] calls AVX2's `vpermps` directly (safe inside
//! `#[target_feature(enable = "avx2")]` code); the traversal gets it as a closure made in the
//! AVX2 function (`Compaction` in `cache/traverse.rs`).

use core::ops::{Add, Div, Mul, Sub};

use super::{LANE_MASKS, LANES, Lanes, Mask};
use crate::math;

/// Eight lanes in a 32-byte-aligned array; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct ArrayLanes(pub [f32; LANES]);

macro_rules! array_binop {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for ArrayLanes {
            type Output = ArrayLanes;
            #[inline(always)]
            fn $f(self, o: ArrayLanes) -> ArrayLanes {
                let mut r = self.0;
                for i in 0..LANES {
                    r[i] $op o.0[i];
                }
                ArrayLanes(r)
            }
        }
    };
}
array_binop!(Add, add, +=);
array_binop!(Sub, sub, -=);
array_binop!(Mul, mul, *=);
array_binop!(Div, div, /=);

impl Lanes for ArrayLanes {
    const NAME: &'static str = "array";
    const INLINE_TRAVERSAL: bool = true;
    #[inline(always)]
    fn splat(v: f32) -> Self {
        ArrayLanes([v; LANES])
    }
    #[inline(always)]
    fn load(src: &[f32]) -> Self {
        let a: [f32; LANES] = src[..LANES].try_into().unwrap_or([0.0; LANES]);
        ArrayLanes(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; LANES] {
        self.0
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // `f32::sqrt` needs std and libm's `sqrtf` is an assembly block the compiler cannot
        // vectorise: `wide`'s packed root (`sqrtps`), exact like every IEEE-754 square root.
        ArrayLanes(wide::f32x8::from(self.0).sqrt().to_array())
    }
    #[inline(always)]
    fn exp_nonpositive(self) -> Self {
        let mut r = self.0;
        for v in &mut r {
            *v = math::exp_nonpositive_lane(*v);
        }
        ArrayLanes(r)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        let mut r = self.0;
        for i in 0..LANES {
            r[i] = if r[i] < o.0[i] { r[i] } else { o.0[i] };
        }
        ArrayLanes(r)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        let mut r = self.0;
        for i in 0..LANES {
            r[i] = if r[i] > o.0[i] { r[i] } else { o.0[i] };
        }
        ArrayLanes(r)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Mask {
        // `wide`'s compare and sign-bit mask (`cmpltps`, `movmskps`): the compiler does not
        // turn the lane loop into a movemask, and the loop cost about a tenth of a lookup.
        let (a, b) = (wide::f32x8::from(self.0), wide::f32x8::from(o.0));
        Mask(a.simd_lt(b).to_bitmask())
    }
    #[inline(always)]
    fn keep(self, m: Mask) -> Self {
        // As `SimdLanes`: all bits or none from the table of lane masks, so the kept lanes keep
        // their bits exactly (−0, NaN payloads) and the others become +0. (Bits taken from
        // `m` lane by lane cost a shuffle per lane.)
        let bits = &LANE_MASKS[(m.0 & 0xff) as usize];
        let mut r = self.0;
        for i in 0..LANES {
            r[i] = f32::from_bits(r[i].to_bits() & bits[i]);
        }
        ArrayLanes(r)
    }
    #[inline(always)]
    fn reduce_add(self) -> f32 {
        let a = self.0;
        ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]))
    }
}

#[cfg(target_arch = "x86")]
use core::arch::x86 as arch;
#[cfg(target_arch = "x86_64")]
use core::arch::x86_64 as arch;

/// Lane i of the result is lane `order`'s byte i (little-endian, each < 8) of `values`: one
/// `vpermps`. The AVX2 traversal's term buffers move the kept lanes of a batch to the front
/// with it (`Compaction` in `cache/traverse.rs`); moved one by one through memory, as on the
/// baseline lanes, that took about a fifth of a lookup. The arrays cost nothing once inlined:
/// the values stay in ymm registers.
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) fn permute_avx2(values: [f32; LANES], order: u64) -> [f32; LANES] {
    from_ymm(arch::_mm256_permutevar8x32_ps(
        to_ymm(values),
        lane_indices(order),
    ))
}

/// Eight index bytes widened to eight 32-bit lanes (`vpmovzxbd`).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[target_feature(enable = "avx2")]
#[inline]
fn lane_indices(order: u64) -> arch::__m256i {
    arch::_mm256_cvtepu8_epi32(arch::_mm_set_epi64x(0, order as i64))
}

/// An array as a ymm value (one register once inlined: no code).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[target_feature(enable = "avx2")]
#[inline]
fn to_ymm(v: [f32; LANES]) -> arch::__m256 {
    arch::_mm256_setr_ps(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7])
}

/// A ymm value as an array (no code once inlined).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[target_feature(enable = "avx2")]
#[inline]
fn from_ymm(v: arch::__m256) -> [f32; LANES] {
    let (lo, hi) = (
        arch::_mm256_castps256_ps128(v),
        arch::_mm256_extractf128_ps::<1>(v),
    );
    let lane = |h: arch::__m128, i: usize| match i {
        0 => arch::_mm_cvtss_f32(h),
        1 => f32::from_bits(arch::_mm_extract_ps::<1>(h) as u32),
        2 => f32::from_bits(arch::_mm_extract_ps::<2>(h) as u32),
        _ => f32::from_bits(arch::_mm_extract_ps::<3>(h) as u32),
    };
    [
        lane(lo, 0),
        lane(lo, 1),
        lane(lo, 2),
        lane(lo, 3),
        lane(hi, 0),
        lane(hi, 1),
        lane(hi, 2),
        lane(hi, 3),
    ]
}
