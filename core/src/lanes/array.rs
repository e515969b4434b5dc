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
