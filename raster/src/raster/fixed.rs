//! The fixed-point format of the sub-sample grid, and the integer helpers the edge walker needs.
//!
//! After clipping, vertices are projected to **sub-sample space** (pixel coordinates times `aa`,
//! so sub-sample `(c, r)` of the whole image has its centre at `(c + ½, r + ½)`) and snapped to a
//! signed **24.8** fixed-point number stored in an `i32`:
//!
//! ```text
//!   bit 31                              8 7            0
//!  ┌─────────────────────────────────────┬──────────────┐
//!  │ sign + integer part (sub-samples)   │ fraction     │   value = raw / 256 sub-samples
//!  └─────────────────────────────────────┴──────────────┘
//!   e.g. 3.5 sub-samples = 0x0000_0380 = 896;  the centre of sub-sample c is c·256 + 128
//! ```
//!
//! The precision is 1/256 of a sub-sample, i.e. `1 / (256·aa)` of a pixel (1/512 pixel at
//! `aa = 2`). Snapping rounds to the nearest representable value, so a vertex moves by at most
//! 1/512 of a sub-sample.
//!
//! Range: the buffer limits each axis of the sub-sample grid to [`MAX_GRID_AXIS`] = 2^20
//! sub-samples and clipping keeps projected vertices inside the grid, so raw coordinates lie in
//! `[0, 2^28]`. The edge walker accepts anything within ±[`COORD_LIMIT`] = ±2^29; every product
//! it forms (coordinate difference × coordinate difference, each below 2^30) stays below 2^61,
//! so `i64` arithmetic is exact and cannot overflow.

/// Fractional bits of the fixed-point format.
pub(crate) const FRAC_BITS: u32 = 8;
/// One sub-sample in raw fixed-point units.
pub(crate) const ONE: i64 = 1 << FRAC_BITS;
/// Half a sub-sample: sub-sample centres sit at `c·ONE + HALF`.
pub(crate) const HALF: i64 = ONE / 2;
/// Largest number of sub-samples along one axis of a buffer.
pub(crate) const MAX_GRID_AXIS: u32 = 1 << 20;
/// Largest |raw coordinate| the edge walker accepts.
pub(crate) const COORD_LIMIT: i64 = 1 << 29;

/// The sub-sample grid of a buffer: `cols = width·aa` by `rows = height·aa`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Grid {
    /// Sub-samples per row.
    pub cols: u32,
    /// Rows of sub-samples.
    pub rows: u32,
}

/// A point in 24.8 fixed-point sub-sample coordinates (x right, y down).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FixedPoint {
    /// Raw x (value = x / 256 sub-samples).
    pub x: i32,
    /// Raw y (value = y / 256 sub-samples).
    pub y: i32,
}

/// Snaps a coordinate given in sub-samples to raw fixed point, rounding to nearest (ties away
/// from zero). The caller keeps `v` inside the grid; the cast saturates anyway.
pub(crate) fn snap(v: f64) -> i32 {
    (v * ONE as f64).round() as i32
}

/// `⌈n / d⌉` for `d > 0`, exact for every `i64` numerator.
pub(crate) fn ceil_div(n: i64, d: i64) -> i64 {
    debug_assert!(d > 0);
    let q = n.div_euclid(d);
    if n.rem_euclid(d) == 0 { q } else { q + 1 }
}

/// Index of the first sub-sample whose centre is at or after raw coordinate `raw`, i.e. the
/// smallest `k` with `k·ONE + HALF >= raw`.
pub(crate) fn first_centre_at_or_after(raw: i64) -> i64 {
    ceil_div(raw - HALF, ONE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ceil_div_matches_rational_ceiling() {
        for n in -50i64..=50 {
            for d in 1i64..=9 {
                let expected = (n as f64 / d as f64).ceil() as i64;
                assert_eq!(ceil_div(n, d), expected, "{n}/{d}");
            }
        }
        assert_eq!(ceil_div(i64::MIN, 1), i64::MIN);
        assert_eq!(ceil_div(i64::MAX, 2), i64::MAX / 2 + 1);
    }

    #[test]
    fn first_centre_is_inclusive_at_the_centre() {
        // Centre of sub-sample 3 is 3·256 + 128 = 896.
        assert_eq!(first_centre_at_or_after(896), 3);
        assert_eq!(first_centre_at_or_after(897), 4);
        assert_eq!(first_centre_at_or_after(895), 3);
        assert_eq!(first_centre_at_or_after(128 - 256), -1);
        assert_eq!(first_centre_at_or_after(0), 0);
    }

    #[test]
    fn snap_rounds_to_nearest_256th() {
        assert_eq!(snap(3.5), 896);
        assert_eq!(snap(1.0 / 512.0 - 1e-9), 0);
        assert_eq!(snap(1.0 / 512.0 + 1e-9), 1);
        assert_eq!(snap(-0.25), -64);
        assert_eq!(snap(f64::NAN), 0);
        assert_eq!(snap(1e300), i32::MAX);
    }
}
