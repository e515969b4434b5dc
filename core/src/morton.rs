//! Fixed-point quantisation and 3-D Morton (Z-order) codes.
//!
//! Positions are mapped into a cube grid of 2²¹ cells per axis (the largest that fits three
//! axes in a `u64`), and the three 21-bit integer coordinates are interleaved:
//!
//! ```text
//! bit  62 61 60   59 58 57   …   2  1  0
//!       z  y  x    z  y  x   …   z  y  x      (x in the lowest bit of each triple)
//!      └ level 0 ┘└ level 1 ┘    └ level 20 ┘
//! ```
//!
//! so the 3 bits of level L (L = 0 coarsest) are bits 3·(20 − L) … 3·(20 − L) + 2, and a node of
//! the octree at level L is a run of sorted codes sharing their top 3·L bits.
//! Worked example: cell (x, y, z) = (1, 0, 1) at the finest level → code 0b101 = 5.

use glam::Vec3;

/// Bits per axis.
pub const BITS: u32 = 21;
/// Octree levels a Morton code can distinguish.
pub const LEVELS: u32 = BITS;
/// Grid cells per axis.
pub const CELLS: u32 = 1 << BITS;

/// The quantisation grid: an axis-aligned cube enclosing all positions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// The cube's minimum corner.
    pub origin: Vec3,
    /// Cells per scene unit (0 when all positions coincide).
    pub scale: f32,
}

impl Grid {
    /// The grid over the bounding box `[lo, hi]` (cubic, so cells are cubes).
    pub fn new(lo: Vec3, hi: Vec3) -> Self {
        let extent = (hi - lo).max_element();
        // Slightly less than CELLS so that `hi` itself quantises into the last cell.
        let scale = if extent > 0.0 && extent.is_finite() {
            (CELLS as f32 - 1.0) / extent
        } else {
            0.0
        };
        Grid { origin: lo, scale }
    }

    /// Integer cell coordinates of `p` (clamped into the grid).
    #[inline]
    pub fn quantise(&self, p: Vec3) -> [u32; 3] {
        let q = (p - self.origin) * self.scale;
        let max = (CELLS - 1) as f32;
        // `as u32` saturates and maps NaN to 0; the clamp keeps rounding at the top in range.
        [
            q.x.clamp(0.0, max) as u32,
            q.y.clamp(0.0, max) as u32,
            q.z.clamp(0.0, max) as u32,
        ]
    }

    /// The Morton code of `p`.
    #[inline]
    pub fn code(&self, p: Vec3) -> u64 {
        let [x, y, z] = self.quantise(p);
        encode(x, y, z)
    }
}

/// Spreads the low 21 bits of `v` so that bit i moves to bit 3i.
#[inline]
fn spread(v: u32) -> u64 {
    let mut x = (v & (CELLS - 1)) as u64;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// Interleaves three 21-bit coordinates (x lowest).
#[inline]
pub fn encode(x: u32, y: u32, z: u32) -> u64 {
    spread(x) | (spread(y) << 1) | (spread(z) << 2)
}

/// The octant (0..8) of `code` at octree level `level` (0 = coarsest).
#[inline]
pub fn octant(code: u64, level: u32) -> u32 {
    ((code >> (3 * (LEVELS - 1 - level))) & 7) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bit-by-bit interleave: the obvious, slow oracle.
    fn encode_naive(x: u32, y: u32, z: u32) -> u64 {
        let mut code = 0u64;
        for i in 0..BITS {
            code |= (((x >> i) & 1) as u64) << (3 * i);
            code |= (((y >> i) & 1) as u64) << (3 * i + 1);
            code |= (((z >> i) & 1) as u64) << (3 * i + 2);
        }
        code
    }

    #[test]
    fn encode_matches_naive_interleave() {
        assert_eq!(encode(1, 0, 1), 5);
        let mut s = 0x1234_5678_u32;
        for _ in 0..10_000 {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            let (x, y, z) = (
                s & (CELLS - 1),
                (s >> 5) & (CELLS - 1),
                s.rotate_left(11) & (CELLS - 1),
            );
            assert_eq!(encode(x, y, z), encode_naive(x, y, z));
        }
        let m = CELLS - 1;
        assert_eq!(encode(m, m, m), (1u64 << 63) - 1);
    }

    #[test]
    fn octants_read_levels_coarse_to_fine() {
        let top = CELLS / 2; // the top bit of each axis
        let code = encode(top, 0, top);
        assert_eq!(octant(code, 0), 0b101);
        for level in 1..LEVELS {
            assert_eq!(octant(code, level), 0);
        }
        assert_eq!(octant(encode(1, 1, 0), LEVELS - 1), 0b011);
    }

    #[test]
    fn quantise_covers_the_box_and_clamps() {
        let g = Grid::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 2.5));
        assert_eq!(g.quantise(Vec3::new(-1.0, 0.0, 2.0)), [0, 0, 0]);
        let hi = g.quantise(Vec3::new(1.0, 0.5, 2.5));
        assert_eq!(hi[0], CELLS - 1);
        assert!(hi[1] < CELLS && hi[2] < CELLS);
        assert_eq!(g.quantise(Vec3::splat(1e30)), [CELLS - 1; 3]);
        assert_eq!(g.quantise(Vec3::splat(-1e30)), [0; 3]);
        // All positions equal: a degenerate grid puts everything in cell 0.
        let flat = Grid::new(Vec3::ONE, Vec3::ONE);
        assert_eq!(flat.quantise(Vec3::ONE), [0, 0, 0]);
    }
}
