//! A dense grid of the local integral's share K / K_d over (K_d, ℓ_u), sampled from the tables
//! over K_d ([`crate::LocalIntegralByKd`]) for the range a texture-mapped material can reach, so
//! that a shading point's K costs a bilinear interpolation: no logarithm, no exponential, no
//! check for segments still to be computed.
//!
//! Rows follow ℓ_u at 32 nodes per octave, placed where the bits of q = ℓ_u/α say: the row of q
//! is its exponent and first five mantissa bits, and the remaining 18 bits are the fraction
//! between that node and the next. So the nodes are q = 2^e·(1 + j/32), and the interpolation
//! is linear in q between neighbours 1/32 of an octave apart. Columns are the K_d levels of the
//! tables (i / 64), interpolated linearly in K_d as there:
//!
//! ```text
//!   q = ℓ_u/α,  bits(q) = [ sign | exponent e (8) | j (5) | fraction f (18) ]
//!   row = (bits(q) >> 18) − first_row,  t = f / 2^18
//!
//!   values:  [ level i₀: row 0 … row R−1 ][ level i₀+1: row 0 … row R−1 ] … (f32 each)
//!
//!   K = K_d · lerp(lerp(v[i][r], v[i][r+1], t), lerp(v[i+1][r], v[i+1][r+1], t), s)
//! ```
//!
//! Each value is the tables' own K at that node divided by the level's K_d. The grid adds the
//! linear interpolation's error between nodes (at most about λ²h²/8 for K ∝ e^(−λ log₂ q) over
//! a step h = 1/32 octave: 0.02% where K ∝ ℓ⁻²) to the tables'. Measured against quadrature at
//! each point's own profile, over K_d ∈ [0.005, 0.995] and ℓ_u ∈ [α/32, 8α], every model: see
//! the renderer's test `textured_albedo_and_radius_interpolate_k_within_half_a_percent`.
//!
//! A point outside the grid (a K_d or ℓ_u beyond the range it was built for, or ℓ_u at or below
//! the tables' first node above ℓ_min, or not finite) returns `None`, and the caller uses the
//! tables.

use alloc::vec::Vec;

use crate::math;
use crate::table::LocalIntegralTable;

/// Mantissa bits that select the node within an octave: 32 nodes per octave (16 doubled the
/// worst K error over the tables' own, 0.29% against 0.12%; 32 adds 0.02%).
const NODE_BITS: u32 = 5;
/// Bits of q below the node index: the fraction between two nodes.
const FRACTION_BITS: u32 = 23 - NODE_BITS;
/// 2^−FRACTION_BITS.
const FRACTION_SCALE: f32 = 1.0 / (1u32 << FRACTION_BITS) as f32;
/// Most rows a grid may have (48 octaves, ℓ_u over a factor 2.8·10¹⁴; at most 65 levels ×
/// 1 537 rows × 4 bytes = 400 KB); a wider range is left to the tables.
const MAX_ROWS: u32 = 48 << NODE_BITS;

/// K / K_d at the nodes of a range of K_d levels × a range of ℓ_u (layout in the module docs).
#[derive(Debug)]
pub(crate) struct KdGrid {
    /// `values[(level − first_level) · rows + row]`: K / K_d of that level at row's node.
    values: Vec<f32>,
    /// The first K_d level held.
    first_level: usize,
    /// Levels held (at least 2).
    levels: usize,
    /// `bits(q) >> FRACTION_BITS` of row 0's node.
    first_row: u32,
    /// Rows per level (at least 2).
    rows: usize,
    /// 1/α: q = ℓ_u/α.
    inv_alpha: f32,
}

/// Where one channel falls in the grid: the index of its lower-left value, and the fraction
/// along ℓ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GridPlace {
    base: usize,
    t: f32,
}

impl KdGrid {
    /// The grid over K_d levels `first_level ..= last_level` (indices into `tables`) and
    /// ℓ_u ∈ [`ell_lo`, `ell_hi`] for tables of smoothing radius `alpha` whose first node is
    /// at q = `first_node`; `level_kd(i)` is level i's K_d. `None` when the range is empty,
    /// not finite, or wider than 48 octaves.
    pub(crate) fn new(
        tables: &[LocalIntegralTable],
        level_kd: impl Fn(usize) -> f32,
        (first_level, last_level): (usize, usize),
        (ell_lo, ell_hi): (f32, f32),
        alpha: f32,
        first_node: f32,
    ) -> Option<Self> {
        let inv_alpha = 1.0 / alpha;
        let q_lo = (ell_lo * inv_alpha).max(first_node);
        let q_hi = ell_hi * inv_alpha;
        if !(q_lo >= f32::MIN_POSITIVE && q_hi >= q_lo && q_hi < math::pow2i(126)) {
            return None;
        }
        if !(first_level < last_level && last_level < tables.len()) {
            return None;
        }
        // The node at or below q_lo, and the one above q_hi: every q in range has a node on
        // each side. Starting at the tables' first node or above keeps the grid off their ramp
        // below it.
        let mut first_row = q_lo.to_bits() >> FRACTION_BITS;
        if f32::from_bits(first_row << FRACTION_BITS) < first_node {
            first_row += 1;
        }
        let last_row = (q_hi.to_bits() >> FRACTION_BITS) + 1;
        if !(last_row > first_row && last_row - first_row < MAX_ROWS) {
            return None;
        }
        let rows = (last_row - first_row + 1) as usize;
        let levels = last_level - first_level + 1;
        let mut values = Vec::with_capacity(levels * rows);
        for level in first_level..=last_level {
            let inv_kd = 1.0 / level_kd(level);
            let table = &tables[level];
            for row in 0..rows as u32 {
                let q = f32::from_bits((first_row + row) << FRACTION_BITS);
                // Every level's profile is grey: channel 0 serves all three.
                values.push(table.lookup_channel(0, q * alpha) * inv_kd);
            }
        }
        Some(KdGrid {
            values,
            first_level,
            levels,
            first_row,
            rows,
            inv_alpha,
        })
    }

    /// The row of ℓ_u (as an offset into a level) and the fraction to the next row, `None`
    /// outside the grid (and for NaN, negative or infinite ℓ_u: their bits fall outside).
    #[inline]
    pub(crate) fn row(&self, ell: f32) -> Option<(usize, f32)> {
        let bits = (ell * self.inv_alpha).to_bits();
        let row = (bits >> FRACTION_BITS).wrapping_sub(self.first_row) as usize;
        // The last row is only ever the upper neighbour.
        if row >= self.rows - 1 {
            return None;
        }
        let t = (bits & ((1 << FRACTION_BITS) - 1)) as f32 * FRACTION_SCALE;
        Some((row, t))
    }

    /// Where a channel at K_d level `level` and `row` (from [`KdGrid::row`]) falls, `None` when
    /// the level and the next are not both held.
    #[inline]
    pub(crate) fn place(&self, level: usize, (row, t): (usize, f32)) -> Option<GridPlace> {
        let offset = level.wrapping_sub(self.first_level);
        if offset >= self.levels - 1 {
            return None;
        }
        Some(GridPlace {
            base: offset * self.rows + row,
            t,
        })
    }

    /// K / K_d at `place`, `s` of the way from its level to the next.
    #[inline]
    pub(crate) fn share(&self, place: GridPlace, s: f32) -> f32 {
        let GridPlace { base, t } = place;
        let pair = |i: usize| match self.values.get(i..i + 2) {
            Some(&[a, b]) => a + (b - a) * t,
            _ => f32::NAN,
        };
        let lo = pair(base);
        let hi = pair(base + self.rows);
        lo + (hi - lo) * s
    }

    /// Bytes of grid values.
    pub(crate) fn bytes(&self) -> usize {
        self.values.len() * core::mem::size_of::<f32>()
    }

    /// Checks the grid's invariants: its size, at least two levels and rows, every value finite
    /// and non-negative, and K / K_d non-increasing along ℓ_u within each level (to f32
    /// rounding).
    pub(crate) fn validate(&self) -> Result<(), &'static str> {
        if self.levels < 2 || self.rows < 2 {
            return Err("fewer than two levels or rows");
        }
        if self.values.len() != self.levels * self.rows {
            return Err("values are not levels × rows");
        }
        if self.values.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err("a value is negative or not finite");
        }
        for level in self.values.chunks_exact(self.rows) {
            if level.windows(2).any(|w| w[1] > w[0] * (1.0 + 1e-6)) {
                return Err("K rises with the mean free path");
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    /// Consecutive rows are consecutive nodes 2^e·(1 + j/N), N nodes per octave, and the
    /// fraction is linear in q between them (the bits of q in a row are an arithmetic
    /// progression).
    #[test]
    fn rows_and_fractions_follow_the_bits() {
        let n = 1usize << NODE_BITS;
        let grid = KdGrid {
            values: alloc::vec![0.0; 2 * 3 * n],
            first_level: 0,
            levels: 2,
            first_row: 0.5f32.to_bits() >> FRACTION_BITS,
            rows: 3 * n,
            inv_alpha: 1.0,
        };
        assert_eq!(grid.row(0.5), Some((0, 0.0)));
        assert_eq!(grid.row(0.5 * (1.0 + 1.0 / n as f32)), Some((1, 0.0)));
        assert_eq!(grid.row(1.0 + 0.5 / n as f32), Some((n, 0.5)));
        assert_eq!(grid.row(1.0 + 0.25 / n as f32), Some((n, 0.25)));
        // Rows reach 0.5·2³ = 4, and the last row is only an upper neighbour: q in the last
        // node's interval is outside.
        assert!(grid.row(3.99).is_none());
        assert!(grid.row(3.5).is_some());
        for bad in [0.25, 1e9, f32::NAN, -1.0, f32::INFINITY, 0.0] {
            assert!(grid.row(bad).is_none(), "{bad}");
        }
        assert!(grid.place(1, (0, 0.0)).is_none());
        assert!(grid.place(0, (0, 0.0)).is_some());
    }
}
