//! A uniform grid over points for fixed-radius neighbour queries, stored sparsely so that a
//! thin surface inside a large box costs memory only for the cells it touches.
//!
//! Points are sorted by cell, so each occupied cell is a contiguous range of the point array;
//! each occupied cell lists the point ranges of its occupied neighbours (itself included, at
//! most 27 cells). Neighbouring cells that differ only in z are adjacent in key order, so their
//! ranges merge: at most 9 ranges per cell. A query around a point scans those ranges, which
//! hold every point closer than the cell size.
//!
//! ```text
//! record_of:    [0,0,0,0, 4,4,4,4,4, 8,8, ...]  record of each (sorted) point's cell
//! records:      [(3, 0), (0, 9), (40, 52), (60, 64), (2, 0), ...]
//!                header (n, 0), then n half-open point ranges, ascending
//! ```
//!
//! A point leads straight to its cell's record, header and ranges side by side: one dependent
//! memory access fewer than separate offset and range arrays, which matters because sample
//! elimination visits neighbourhoods in random order.

use glam::Vec3;
use rayon::prelude::*;

/// Bits per axis of a packed cell key; coordinates are clamped to `0 .. 2²¹`. Clamping is
/// monotone, so points closer than a cell still land in the same or adjacent cells: an absurdly
/// elongated surface only makes cells fuller, never misses a neighbour.
const AXIS_BITS: u32 = 21;
const AXIS_MAX: u64 = (1 << AXIS_BITS) - 1;

/// The grid (see the module documentation for the layout).
pub(super) struct NeighbourGrid {
    record_of: Vec<u32>,
    records: Vec<(u32, u32)>,
}

/// Packs cell coordinates into a key, x-major.
fn pack(c: [u64; 3]) -> u64 {
    (c[0] << (2 * AXIS_BITS)) | (c[1] << AXIS_BITS) | c[2]
}

impl NeighbourGrid {
    /// Builds the grid with cells of edge `cell_size` over `points`, and returns it with the
    /// permutation that sorts the points by cell (`order[k]` is the input index of the k-th
    /// sorted point); ties keep input order. The queries of the grid refer to sorted indices.
    pub(super) fn build(points: &[Vec3], cell_size: f32) -> (NeighbourGrid, Vec<u32>) {
        let origin = points
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |m, &p| m.min(p));
        let inv = 1.0 / (cell_size as f64).max(f64::MIN_POSITIVE);
        let coord = |x: f32, o: f32| {
            ((x as f64 - o as f64) * inv)
                .floor()
                .clamp(0.0, AXIS_MAX as f64) as u64
        };
        let mut keyed: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let c = [
                    coord(p.x, origin.x),
                    coord(p.y, origin.y),
                    coord(p.z, origin.z),
                ];
                (pack(c), i as u32)
            })
            .collect();
        // Keys are unique (the index is part of them), so the unstable sort is deterministic.
        keyed.par_sort_unstable();

        // Occupied cells in key order.
        let mut cell_keys = Vec::new();
        let mut cell_start = Vec::new();
        let mut cell_of = Vec::with_capacity(points.len());
        for (k, &(key, _)) in keyed.iter().enumerate() {
            if cell_keys.last() != Some(&key) {
                cell_keys.push(key);
                cell_start.push(k as u32);
            }
            cell_of.push(cell_keys.len() as u32 - 1);
        }
        cell_start.push(points.len() as u32);
        let order: Vec<u32> = keyed.into_iter().map(|(_, i)| i).collect();

        let table = CellTable::new(&cell_keys);
        let per_cell: Vec<Ranges> = cell_keys
            .par_iter()
            .map(|&key| {
                let c = [
                    key >> (2 * AXIS_BITS),
                    (key >> AXIS_BITS) & AXIS_MAX,
                    key & AXIS_MAX,
                ];
                let mut list = Ranges::default();
                // This loop order visits keys in ascending order, so cells come ascending and
                // runs of consecutive cells merge into one range.
                for dx in -1i64..=1 {
                    for dy in -1i64..=1 {
                        for dz in -1i64..=1 {
                            let n = [c[0] as i64 + dx, c[1] as i64 + dy, c[2] as i64 + dz];
                            if n.iter().any(|&v| v < 0 || v > AXIS_MAX as i64) {
                                continue;
                            }
                            let Some(cell) = table.get(pack(n.map(|v| v as u64))) else {
                                continue;
                            };
                            let (a, b) = (cell_start[cell as usize], cell_start[cell as usize + 1]);
                            list.push(a, b);
                        }
                    }
                }
                list
            })
            .collect();
        let mut records = Vec::with_capacity(per_cell.iter().map(|l| l.len + 1).sum());
        let mut record_start = Vec::with_capacity(per_cell.len());
        for l in &per_cell {
            record_start.push(records.len() as u32);
            records.push((l.len as u32, 0));
            records.extend_from_slice(&l.ranges[..l.len]);
        }
        let record_of = cell_of.iter().map(|&c| record_start[c as usize]).collect();
        (NeighbourGrid { record_of, records }, order)
    }

    /// The point ranges around point `i` (including `i` itself), ascending and disjoint.
    /// Every point closer to `i` than the cell size is in them.
    #[inline]
    pub(super) fn ranges_near(&self, i: u32) -> &[(u32, u32)] {
        let r = self.record_of[i as usize] as usize;
        &self.records[r + 1..r + 1 + self.records[r].0 as usize]
    }
}

/// The merged point ranges around one cell (at most 9: one per (dx, dy) column).
#[derive(Clone, Copy, Default)]
struct Ranges {
    ranges: [(u32, u32); 9],
    len: usize,
}

impl Ranges {
    /// Appends `a..b`, merging it into the last range when they touch.
    fn push(&mut self, a: u32, b: u32) {
        if self.len > 0 && self.ranges[self.len - 1].1 == a {
            self.ranges[self.len - 1].1 = b;
        } else {
            self.ranges[self.len] = (a, b);
            self.len += 1;
        }
    }
}

/// Open-addressing hash table from cell key to cell index (linear probing, Fibonacci hashing;
/// deterministic, no random state).
struct CellTable {
    slots: Vec<(u64, u32)>,
    shift: u32,
}

impl CellTable {
    const EMPTY: u32 = u32::MAX;

    fn new(keys: &[u64]) -> CellTable {
        let bits = (keys.len() * 2).max(2).next_power_of_two().trailing_zeros();
        let mut table = CellTable {
            slots: vec![(0, Self::EMPTY); 1 << bits],
            shift: 64 - bits,
        };
        let mask = table.slots.len() - 1;
        for (cell, &key) in keys.iter().enumerate() {
            let mut s = table.slot(key);
            while table.slots[s].1 != Self::EMPTY {
                s = (s + 1) & mask;
            }
            table.slots[s] = (key, cell as u32);
        }
        table
    }

    #[inline]
    fn slot(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize
    }

    #[inline]
    fn get(&self, key: u64) -> Option<u32> {
        let mask = self.slots.len() - 1;
        let mut s = self.slot(key);
        loop {
            let (k, cell) = self.slots[s];
            if cell == Self::EMPTY {
                return None;
            }
            if k == key {
                return Some(cell);
            }
            s = (s + 1) & mask;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn finds_exactly_the_brute_force_neighbours() {
        let mut rng = Pcg32::new(11, 0);
        // Points on two parallel planes and a sparse cloud: many empty cells.
        let mut pts: Vec<Vec3> = (0..3000)
            .map(|k| {
                let (a, b) = (rng.next_f32() * 4.0, rng.next_f32() * 4.0);
                match k % 3 {
                    0 => Vec3::new(a, b, 0.0),
                    1 => Vec3::new(a, b, 0.3),
                    _ => Vec3::new(a, b, rng.next_f32() * 50.0),
                }
            })
            .collect();
        pts.push(pts[5]); // an exact duplicate
        let r = 0.21;
        let (grid, order) = NeighbourGrid::build(&pts, r);
        let sorted: Vec<Vec3> = order.iter().map(|&i| pts[i as usize]).collect();
        let mut seen = vec![false; pts.len()];
        for &i in &order {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
        }
        for i in 0..sorted.len() as u32 {
            let mut got = Vec::new();
            let ranges = grid.ranges_near(i);
            assert!(ranges.windows(2).all(|w| w[0].1 < w[1].0), "{ranges:?}");
            for &(a, b) in ranges {
                for j in a..b {
                    if j != i && sorted[i as usize].distance(sorted[j as usize]) < r {
                        got.push(j);
                    }
                }
            }
            let want: Vec<u32> = (0..sorted.len() as u32)
                .filter(|&j| j != i && sorted[i as usize].distance(sorted[j as usize]) < r)
                .collect();
            assert_eq!(got, want, "point {i}");
        }
    }
}
