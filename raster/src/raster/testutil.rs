//! Test helpers: a seeded generator and the exact edge-function oracle of the fill rule.
//!
//! The oracle is written independently of the scan converter: it evaluates the edge functions
//! of the snapped vertices at a sub-sample centre in 128-bit integers and applies the top-left
//! rule edge by edge, exactly as Direct3D specifies it.

use super::fixed::FixedPoint;

/// SplitMix64: small, seeded, good enough for test inputs.
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub(crate) fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub(crate) fn f32_in(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f64() as f32
    }

    /// Uniform integer in [lo, hi).
    pub(crate) fn range_i64(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next_u64() % (hi - lo) as u64) as i64
    }
}

/// Twice the signed area of `a, b, c` (positive when clockwise on a y-down screen).
fn cross(a: (i128, i128), b: (i128, i128), c: (i128, i128)) -> i128 {
    (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
}

/// Top-left test for the edge `a → b` of a polygon with positive [`cross`] orientation: the
/// interior lies where the edge function is positive, so a *left* edge runs upwards (dy < 0) and
/// a *top* edge is horizontal running right (interior below).
fn is_top_left(a: (i128, i128), b: (i128, i128)) -> bool {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    dy < 0 || (dy == 0 && dx > 0)
}

fn edge_accepts(a: (i128, i128), b: (i128, i128), p: (i128, i128)) -> bool {
    let e = cross(a, b, p);
    e > 0 || (e == 0 && is_top_left(a, b))
}

fn wide(p: FixedPoint) -> (i128, i128) {
    (i128::from(p.x), i128::from(p.y))
}

/// Whether the triangle covers the raw fixed-point point `p` under the top-left rule.
pub(crate) fn oracle_covers(tri: [FixedPoint; 3], p: (i64, i64)) -> bool {
    oracle_in_convex_polygon(&tri, p)
}

/// Whether the convex polygon (either winding) covers `p` under the top-left rule.
pub(crate) fn oracle_in_convex_polygon(poly: &[FixedPoint], p: (i64, i64)) -> bool {
    let mut v: Vec<(i128, i128)> = poly.iter().copied().map(wide).collect();
    let area: i128 = (1..v.len().saturating_sub(1))
        .map(|k| cross(v[0], v[k], v[k + 1]))
        .sum();
    if area == 0 {
        return false;
    }
    if area < 0 {
        v.reverse();
    }
    let p = (i128::from(p.0), i128::from(p.1));
    (0..v.len()).all(|k| edge_accepts(v[k], v[(k + 1) % v.len()], p))
}
