//! The candidates of sample elimination in tiles of cells, for fixed-radius neighbour queries
//! that a task can answer on its own, in cache, while other tasks work on other tiles.
//!
//! Space is cut into cubic cells of edge `cell` (at least the query radius), and cells into
//! tiles of [`TILE_CELLS`]³ cells. Candidates are stored tile by tile, and within a tile cell
//! by cell (each cell a contiguous run of slots); only occupied tiles and cells are stored:
//!
//! ```text
//! slots:      [ (p, w) (p, w) ... | (p, w) ... | ... ]   16 B per candidate: position, weight
//!               tile 0              tile 1
//! index:      [ i i ... | i ... | ... ]                  4 B: its index in generation order
//! tile_start: [ 0, 517, 1032, ... ]                      first slot of each tile (+ end)
//! tile_cells: [ 0, 83, 170, ... ]                        first cell of each tile (+ end)
//! cell_key:   [ (x·8 + y)·8 + z, ... ]                   the cell within its tile (u16)
//! cell_start: [ 0, 6, 11, ... ]                          first slot of each cell
//! cell_end:   [ 4, 9, 15, ... ]                          one past its last live slot
//! plan:       [ (0, 812) (1, 813) ... | ... ]            per tile, the cells its gather
//! plan_start: [ 0, 140, 297, ... ]                       reads: (local cell, cell index)
//! ```
//!
//! [`Tiles::compact`] moves each cell's live candidates to the front of its slots between
//! rounds of the elimination (order kept, the rest marked removed), so a gather reads only
//! live ones: a round removes about a fifth of them, so without it the removed slots pile up
//! and the gathers read nearly twice as many slots over the rounds.
//!
//! [`Tiles::gather`] copies one tile's candidates and those of the adjacent cells of its 26
//! neighbour tiles (the halo) into a [`Neighbourhood`]: a dense block of `(8 + 2)³` cells in
//! local coordinates, so that a query is 9 contiguous runs (cells that differ only in z are
//! adjacent) without hashing. Each tile lists its 26 neighbours (found once through an
//! open-addressing table of the tile keys), and the cells its gather reads, in local order
//! (found once by binary searches in the neighbours' cell keys: the cells never change, only
//! how many live candidates they hold). Before copying, a gather counts the live candidates
//! in a loop of loads alone, so that the cache misses on the halo's scattered slots overlap
//! instead of waiting behind the copy's stores.
//!
//! Building it takes two passes over the candidates, which are generated twice instead of
//! stored twice (see `poisson.rs`): the first counts the candidates of every tile per chunk
//! of candidates, the second writes each candidate straight to its slot (a counting sort);
//! then each tile is sorted by cell on its own.
//!
//! Why the weight lives in the slot (and a removal is its weight set to −∞): a gather reads
//! each candidate's position, whether it is still there and its weight; held together, that
//! is one stream of memory instead of three (positions, a removal bitmap, a weight column).
//! The gathers are bound by memory latency, so this cut their time. The index is only needed
//! at the end, to regenerate the survivors, so it is a column of its own.

use std::sync::atomic::{AtomicU32, Ordering};

use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Cells per tile edge.
pub(super) const TILE_CELLS: u64 = 7;
/// Cells per edge of a [`Neighbourhood`]: the tile and one layer of halo on each side.
pub(super) const LOCAL_CELLS: usize = TILE_CELLS as usize + 2;

/// Bits per axis of a cell coordinate; coordinates are clamped to `0 .. 2²¹`. Clamping is
/// monotone, so points closer than a cell still land in the same or adjacent cells: an absurdly
/// elongated surface only makes cells fuller, never misses a neighbour.
const AXIS_BITS: u32 = 21;
const AXIS_MAX: u64 = (1 << AXIS_BITS) - 1;
/// Bits per axis of a tile coordinate.
const TILE_BITS: u32 = 19;
const _: () = assert!(TILE_CELLS >= 4 && TILE_CELLS <= 16);
const TILE_MAX: u64 = (1 << TILE_BITS) - 1;

/// Packs tile coordinates into a key: their bits interleaved (a Morton code), so that tiles
/// sorted by key are spatially coherent and a phase's tasks, walking them in order, find most
/// of their neighbours' slots in cache.
fn pack(c: [u64; 3]) -> u64 {
    spread(c[0]) | spread(c[1]) << 1 | spread(c[2]) << 2
}

fn unpack(key: u64) -> [u64; 3] {
    [compact(key), compact(key >> 1), compact(key >> 2)]
}

/// The low 21 bits of `v` moved to every third bit (bit i to bit 3i).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    (x | x << 2) & 0x1249_2492_4924_9249
}

/// The inverse of [`spread`]: every third bit gathered into the low 21.
fn compact(v: u64) -> u64 {
    let mut x = v & 0x1249_2492_4924_9249;
    x = (x | x >> 2) & 0x10c3_0c30_c30c_30c3;
    x = (x | x >> 4) & 0x100f_00f0_0f00_f00f;
    x = (x | x >> 8) & 0x1f_0000_ff00_00ff;
    x = (x | x >> 16) & 0x1f_0000_0000_ffff;
    (x | x >> 32) & 0x1f_ffff
}

/// One candidate while the tiles are built: its position and its index in generation order.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    position: Vec3,
    index: u32,
}

/// One candidate in its tile: its position and its weight (`f32` bits; [`REMOVED`] once it is
/// eliminated). The weight is shared by the tasks of a phase: a slot is read and written by
/// one task only (its own tile's, or that of the one tile of the phase whose halo holds it),
/// so relaxed atomics (plain moves on x86) keep the outcome independent of timing.
#[derive(Debug)]
pub(super) struct Slot {
    pub(super) position: Vec3,
    weight: AtomicU32,
}

/// The weight bits of an eliminated candidate (−∞, below any weight).
pub(super) const REMOVED: u32 = f32::NEG_INFINITY.to_bits();

impl Slot {
    /// Sets the weight (−∞ removes the candidate).
    #[inline]
    pub(super) fn set_weight(&self, w: f32) {
        self.weight.store(w.to_bits(), Ordering::Relaxed);
    }
    /// True once the candidate is eliminated.
    #[inline]
    pub(super) fn removed(&self) -> bool {
        self.weight.load(Ordering::Relaxed) == REMOVED
    }
}

/// Where cells lie: the grid's corner and cell edge.
#[derive(Clone, Copy, Debug)]
pub(super) struct Layout {
    origin: DVec3,
    cell: f64,
}

impl Layout {
    /// Cells of edge `cell` with a corner at `origin` (at or below every point).
    pub(super) fn new(origin: Vec3, cell: f32) -> Layout {
        Layout {
            origin: origin.as_dvec3(),
            cell: (cell as f64).max(f64::MIN_POSITIVE),
        }
    }

    fn cell_of(&self, p: Vec3) -> [u64; 3] {
        let q = (p.as_dvec3() - self.origin) / self.cell;
        // Truncation after clamping at 0 is the floor, and the upper clamp commutes with both;
        // `floor` itself is a library call on the x86-64 baseline (no SSE4.1).
        [q.x, q.y, q.z].map(|v| v.clamp(0.0, AXIS_MAX as f64) as u64)
    }

    /// The key of the tile holding `p`.
    pub(super) fn tile_key(&self, p: Vec3) -> u64 {
        pack(self.cell_of(p).map(|c| c / TILE_CELLS))
    }

    /// The cell of `p` within its tile, `(x·8 + y)·8 + z`.
    fn cell_key(&self, p: Vec3) -> u16 {
        let c = self.cell_of(p).map(|c| c % TILE_CELLS);
        ((c[0] * TILE_CELLS + c[1]) * TILE_CELLS + c[2]) as u16
    }

    /// The minimum corner of tile `key`.
    fn tile_corner(&self, key: u64) -> DVec3 {
        let t = unpack(key);
        let edge = self.cell * TILE_CELLS as f64;
        self.origin + DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64) * edge
    }
}

/// A chunk's tiles: `(tile key, candidates)`, ascending by key.
pub(super) type ChunkCounts = Vec<(u64, u32)>;

/// Counts the candidates `emit`ted per tile (the first pass), ascending by key.
pub(super) fn count_tiles(layout: &Layout, each: impl FnOnce(&mut dyn FnMut(Vec3))) -> ChunkCounts {
    let mut counts: ChunkCounts = Vec::new();
    each(&mut |p| {
        let key = layout.tile_key(p);
        // Consecutive candidates are mostly in the same tile (they come along a curve).
        match counts.last_mut() {
            Some((k, n)) if *k == key => *n += 1,
            _ => counts.push((key, 1)),
        }
    });
    counts.sort_unstable_by_key(|&(k, _)| k);
    let mut merged: ChunkCounts = Vec::with_capacity(counts.len());
    for (k, n) in counts {
        match merged.last_mut() {
            Some((mk, mn)) if *mk == k => *mn += n,
            _ => merged.push((k, n)),
        }
    }
    merged
}

/// The tiles (see the module documentation for the layout).
pub(super) struct Tiles {
    layout: Layout,
    keys: Vec<u64>,
    /// The 27 tiles around each tile (itself in the middle), `u32::MAX` where there is none.
    neighbours: Vec<[u32; 27]>,
    /// First slot of each tile, and the number of slots at the end.
    tile_start: Vec<u32>,
    /// First cell of each tile, and the number of cells at the end.
    tile_cells: Vec<u32>,
    cell_key: Vec<u16>,
    cell_start: Vec<u32>,
    /// One past the last live slot of each cell: [`Tiles::compact`] moves each cell's live
    /// candidates to its front, so a gather reads only those.
    cell_end: Vec<u32>,
    /// The candidates, tile by tile and cell by cell.
    pub(super) slots: Vec<Slot>,
    /// Each slot's candidate index in generation order.
    pub(super) index: Vec<u32>,
    /// The cells each tile's gather reads, `(local cell, cell index)` in local cell order
    /// ([`Tiles::gather_plan`]), tile after tile.
    plan: Vec<(u16, u32)>,
    /// First entry of each tile in `plan` (+ end).
    plan_start: Vec<u32>,
}

impl Tiles {
    /// Builds the tiles from the per-chunk counts of the first pass and a second pass,
    /// `generate(chunk, emit)`, which must emit the same candidates `(index, position)` in the
    /// same order as the first pass did for that chunk.
    pub(super) fn build(
        layout: Layout,
        counts: &[ChunkCounts],
        generate: impl Fn(usize, &mut dyn FnMut(u32, Vec3)) + Sync,
    ) -> Tiles {
        let mut keys: Vec<u64> = counts.iter().flatten().map(|&(k, _)| k).collect();
        keys.par_sort_unstable();
        keys.dedup();
        let table = CellTable::new(&keys);
        // Each chunk's first slot in each of its tiles: tiles in key order, chunks in order
        // within a tile, candidates in generation order within a chunk.
        let mut size = vec![0u32; keys.len()];
        let offsets: Vec<Vec<(u64, u32)>> = counts
            .iter()
            .map(|chunk| {
                chunk
                    .iter()
                    .map(|&(k, n)| {
                        let t = table.get(k).expect("tile counted") as usize;
                        let at = size[t];
                        size[t] += n;
                        (k, at)
                    })
                    .collect()
            })
            .collect();
        let mut tile_start = Vec::with_capacity(keys.len() + 1);
        let mut total = 0u32;
        for &n in &size {
            tile_start.push(total);
            total += n;
        }
        tile_start.push(total);
        drop(size);

        // Second pass: every slot is written exactly once, by the chunk that owns it, so
        // relaxed atomic stores (plain moves on x86) make the scatter safe and deterministic.
        let scatter: Vec<[AtomicU32; 4]> = (0..total)
            .into_par_iter()
            .map(|_| [const { AtomicU32::new(0) }; 4])
            .collect();
        offsets.par_iter().enumerate().for_each(|(c, chunk)| {
            let mut cursor: Vec<u32> = chunk
                .iter()
                .map(|&(k, at)| tile_start[table.get(k).expect("tile") as usize] + at)
                .collect();
            let mut last = 0usize;
            generate(c, &mut |index, p| {
                let key = layout.tile_key(p);
                if chunk[last].0 != key {
                    last = chunk.partition_point(|&(k, _)| k < key);
                }
                let s = &scatter[cursor[last] as usize];
                cursor[last] += 1;
                for (a, v) in s
                    .iter()
                    .zip([p.x.to_bits(), p.y.to_bits(), p.z.to_bits(), index])
                {
                    a.store(v, Ordering::Relaxed);
                }
            });
        });
        drop(offsets);
        // Reuses the allocation (same size and alignment).
        let mut slots: Vec<Candidate> = scatter
            .into_iter()
            .map(|s| {
                let [x, y, z, index] = s.map(AtomicU32::into_inner);
                Candidate {
                    position: Vec3::new(f32::from_bits(x), f32::from_bits(y), f32::from_bits(z)),
                    index,
                }
            })
            .collect();

        // Sort each tile by cell (ties: generation order, so unique keys), and list its cells.
        let mut parts = Vec::with_capacity(keys.len());
        let mut rest = &mut slots[..];
        for t in 0..keys.len() {
            let (part, tail) = rest.split_at_mut((tile_start[t + 1] - tile_start[t]) as usize);
            parts.push((tile_start[t], part));
            rest = tail;
        }
        let cells: Vec<Vec<(u16, u32)>> = parts
            .into_par_iter()
            .map(|(first, part)| {
                let mut keyed: Vec<(u16, u32, Candidate)> = part
                    .iter()
                    .map(|s| (layout.cell_key(s.position), s.index, *s))
                    .collect();
                keyed.sort_unstable_by_key(|&(key, index, _)| (key, index));
                let mut cells: Vec<(u16, u32)> = Vec::new();
                for (k, (&(key, _, s), out)) in keyed.iter().zip(part.iter_mut()).enumerate() {
                    *out = s;
                    if cells.last().is_none_or(|&(c, _)| c != key) {
                        cells.push((key, first + k as u32));
                    }
                }
                cells
            })
            .collect();
        let mut tile_cells = Vec::with_capacity(keys.len() + 1);
        let count: usize = cells.iter().map(Vec::len).sum();
        let (mut cell_key, mut cell_start) = (Vec::with_capacity(count), Vec::with_capacity(count));
        let mut cell_end = Vec::with_capacity(count);
        for (t, c) in cells.iter().enumerate() {
            tile_cells.push(cell_key.len() as u32);
            cell_key.extend(c.iter().map(|&(k, _)| k));
            cell_start.extend(c.iter().map(|&(_, s)| s));
            cell_end.extend(c.iter().skip(1).map(|&(_, s)| s));
            if !c.is_empty() {
                cell_end.push(tile_start[t + 1]);
            }
        }
        tile_cells.push(cell_key.len() as u32);
        let index: Vec<u32> = slots.par_iter().map(|c| c.index).collect();
        // Reuses the allocation again: every weight starts at zero.
        let slots: Vec<Slot> = slots
            .into_iter()
            .map(|c| Slot {
                position: c.position,
                weight: AtomicU32::new(0),
            })
            .collect();
        let neighbours = keys
            .par_iter()
            .map(|&key| {
                let tile = unpack(key);
                let mut near = [u32::MAX; 27];
                let mut k = 0;
                for dx in -1i64..=1 {
                    for dy in -1i64..=1 {
                        for dz in -1i64..=1 {
                            let n = [
                                tile[0] as i64 + dx,
                                tile[1] as i64 + dy,
                                tile[2] as i64 + dz,
                            ];
                            if n.iter().all(|&v| (0..=TILE_MAX as i64).contains(&v)) {
                                near[k] = table.get(pack(n.map(|v| v as u64))).unwrap_or(u32::MAX);
                            }
                            k += 1;
                        }
                    }
                }
                near
            })
            .collect();
        let mut tiles = Tiles {
            layout,
            keys,
            neighbours,
            tile_start,
            tile_cells,
            cell_key,
            cell_start,
            cell_end,
            slots,
            index,
            plan: Vec::new(),
            plan_start: Vec::new(),
        };
        let plans: Vec<Vec<(u16, u32)>> = (0..tiles.len())
            .into_par_iter()
            .map(|t| tiles.gather_plan(t))
            .collect();
        tiles.plan_start = Vec::with_capacity(plans.len() + 1);
        tiles.plan = Vec::with_capacity(plans.iter().map(Vec::len).sum());
        for p in plans {
            tiles.plan_start.push(tiles.plan.len() as u32);
            tiles.plan.extend(p);
        }
        tiles.plan_start.push(tiles.plan.len() as u32);
        tiles
    }

    /// Number of tiles.
    pub(super) fn len(&self) -> usize {
        self.keys.len()
    }

    /// The slots of tile `t`.
    pub(super) fn slot_range(&self, t: usize) -> std::ops::Range<usize> {
        self.tile_start[t] as usize..self.tile_start[t + 1] as usize
    }

    /// The colour of tile `t`, 0–7: the parities of its coordinates. Tiles of one colour are
    /// at least a tile apart, so their neighbourhoods (a tile and one cell around it) do not
    /// reach each other's candidates.
    pub(super) fn colour(&self, t: usize) -> usize {
        let c = unpack(self.keys[t]);
        ((c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2) as usize
    }

    /// Moves the live candidates of every cell to the front of its slots (keeping their
    /// order), marks the vacated slots removed and shortens the cell, so that later gathers
    /// read only live candidates. Gathers see the same candidates in the same order as before.
    pub(super) fn compact(&mut self) {
        let mut parts = Vec::with_capacity(self.len());
        let (mut slots, mut index, mut ends) = (
            &mut self.slots[..],
            &mut self.index[..],
            &mut self.cell_end[..],
        );
        for t in 0..self.keys.len() {
            let n = (self.tile_start[t + 1] - self.tile_start[t]) as usize;
            let cells = (self.tile_cells[t + 1] - self.tile_cells[t]) as usize;
            let (s, s_rest) = std::mem::take(&mut slots).split_at_mut(n);
            let (i, i_rest) = std::mem::take(&mut index).split_at_mut(n);
            let (e, e_rest) = std::mem::take(&mut ends).split_at_mut(cells);
            let first_cell = self.tile_cells[t] as usize;
            let starts = &self.cell_start[first_cell..first_cell + cells];
            parts.push((self.tile_start[t], s, i, e, starts));
            (slots, index, ends) = (s_rest, i_rest, e_rest);
        }
        parts
            .into_par_iter()
            .for_each(|(base, slots, index, ends, starts)| {
                for (end, &start) in ends.iter_mut().zip(starts) {
                    let (a, b) = ((start - base) as usize, (*end - base) as usize);
                    let mut k = a;
                    for j in a..b {
                        let w = *slots[j].weight.get_mut();
                        if w != REMOVED {
                            slots[k].position = slots[j].position;
                            *slots[k].weight.get_mut() = w;
                            index[k] = index[j];
                            k += 1;
                        }
                    }
                    for slot in &mut slots[k..b] {
                        *slot.weight.get_mut() = REMOVED;
                    }
                    *end = base + k as u32;
                }
            });
    }

    /// The cells a gather of tile `t` reads, `(local cell, cell index)` in local cell order:
    /// the tile's own cells and the adjacent cells of its 26 neighbour tiles. The cells of a
    /// tile never change, so this is found once, when the tiles are built.
    fn gather_plan(&self, t: usize) -> Vec<(u16, u32)> {
        let k = TILE_CELLS as i64;
        let local = |key: u16, shift: [i64; 3]| -> Option<usize> {
            let c = [key as i64 / (k * k), key as i64 / k % k, key as i64 % k];
            let mut l = [0usize; 3];
            for a in 0..3 {
                let v = c[a] + shift[a] * k + 1;
                if !(0..LOCAL_CELLS as i64).contains(&v) {
                    return None;
                }
                l[a] = v as usize;
            }
            Some((l[0] * LOCAL_CELLS + l[1]) * LOCAL_CELLS + l[2])
        };
        let mut plan = Vec::new();
        let mut near = self.neighbours[t].iter();
        for dx in -1i64..=1 {
            for dy in -1i64..=1 {
                for dz in -1i64..=1 {
                    let u = *near.next().expect("27 neighbours");
                    if u == u32::MAX {
                        continue;
                    }
                    // Only the cells of `u` next to this tile: along an axis where `u` is
                    // offset, its first or last layer. Keys are x-major, so a fixed (x, y) is
                    // one run of keys, found by binary search.
                    let layer = |d: i64| match d {
                        1 => 0..1,
                        -1 => k - 1..k,
                        _ => 0..k,
                    };
                    let (first, last) = (
                        self.tile_cells[u as usize] as usize,
                        self.tile_cells[u as usize + 1] as usize,
                    );
                    let keys = &self.cell_key[first..last];
                    let mut add = |c: usize| {
                        if let Some(l) = local(keys[c], [dx, dy, dz]) {
                            plan.push((l as u16, (first + c) as u32));
                        }
                    };
                    if dx == 0 && dy == 0 {
                        (0..keys.len()).for_each(&mut add);
                    } else {
                        for x in layer(dx) {
                            for y in layer(dy) {
                                let lo = ((x * k + y) * k) as u16;
                                let a = keys.partition_point(|&c| c < lo);
                                let b = a + keys[a..].partition_point(|&c| c < lo + k as u16);
                                (a..b).for_each(&mut add);
                            }
                        }
                    }
                }
            }
        }
        // Every local cell is one cell of one tile: the keys are unique.
        plan.sort_unstable_by_key(|&(l, _)| l);
        plan
    }

    /// Copies tile `t`'s candidates and its halo into `out`, with their weights, leaving out
    /// the removed ones, with positions relative to the tile's corner in units of `unit`.
    pub(super) fn gather(&self, t: usize, unit: f32, out: &mut Neighbourhood) {
        out.runs.clear();
        let own_cells = self.tile_cells[t]..self.tile_cells[t + 1];
        let plan = self.plan_start[t] as usize..self.plan_start[t + 1] as usize;
        out.runs.extend(self.plan[plan].iter().map(|&(l, c)| {
            let c = c as usize;
            let own = own_cells.contains(&(c as u32));
            (l as u32, self.cell_start[c], self.cell_end[c], own)
        }));

        let corner = self.layout.tile_corner(self.keys[t]);
        let inv = 1.0 / unit as f64;
        // The live candidates are counted first, in a loop of loads alone: the slots of the
        // halo are scattered over 26 other tiles and mostly miss the cache, and without stores
        // in between the processor keeps many of those misses in flight at once.
        let live: usize = out
            .runs
            .iter()
            .map(|&(_, a, b, _)| {
                self.slots[a as usize..b as usize]
                    .iter()
                    .filter(|s| s.weight.load(Ordering::Relaxed) != REMOVED)
                    .count()
            })
            .sum();
        // Written without a branch on removal (a coin flip in the middle rounds): every slot
        // is copied, and the write position advances only past live ones.
        out.resize(live);
        let mut n = 0usize;
        let mut next = 0usize;
        for &(l, a, b, own) in &out.runs {
            while next <= l as usize {
                out.start[next] = n as u32;
                next += 1;
            }
            for (s, slot) in (a..b).zip(&self.slots[a as usize..b as usize]) {
                let w = slot.weight.load(Ordering::Relaxed);
                let q = (slot.position.as_dvec3() - corner) * inv;
                out.x[n] = q.x as f32;
                out.y[n] = q.y as f32;
                out.z[n] = q.z as f32;
                out.w[n] = f32::from_bits(w);
                out.cell[n] = l as u16;
                out.slot[n] = s;
                out.own[n] = own;
                n += (w != REMOVED) as usize;
            }
        }
        out.truncate(n);
        let len = out.x.len() as u32;
        for s in &mut out.start[next..] {
            *s = len;
        }
    }
}

/// One tile and its halo in local coordinates (see [`Tiles::gather`]), reused across tiles.
///
/// ```text
/// x, y, z:  [ 0.2  0.9  0.4  8.1 … ]     positions (tile corner = 0), in local cell order
/// cell:     [ 0    0    111  111 … ]     their local cells, (x·10 + y)·10 + z
/// w:        [ 3.1  2.7  4.0  3.9 … ]     their weights when gathered
/// slot:     [ 9    14   1032 1033 … ]    their slots in `Tiles::slots`
/// own:      [ no   no   yes  yes … ]     the tile's own (else halo)
/// start:    [ 0, 0, 2, 2, 2, ... ]       first point of each of the 10³ local cells (+ end)
/// ```
#[derive(Clone)]
pub(super) struct Neighbourhood {
    pub(super) x: Vec<f32>,
    pub(super) y: Vec<f32>,
    pub(super) z: Vec<f32>,
    pub(super) w: Vec<f32>,
    pub(super) cell: Vec<u16>,
    pub(super) slot: Vec<u32>,
    pub(super) own: Vec<bool>,
    start: Vec<u32>,
    runs: Vec<(u32, u32, u32, bool)>,
}

impl Default for Neighbourhood {
    fn default() -> Neighbourhood {
        Neighbourhood {
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            w: Vec::new(),
            cell: Vec::new(),
            slot: Vec::new(),
            own: Vec::new(),
            start: vec![0; LOCAL_CELLS * LOCAL_CELLS * LOCAL_CELLS + 1],
            runs: Vec::new(),
        }
    }
}

impl Neighbourhood {
    /// Room for `n` points (one more, for the last, possibly removed, write).
    fn resize(&mut self, n: usize) {
        let n = n + 1;
        self.x.resize(n, 0.0);
        self.y.resize(n, 0.0);
        self.z.resize(n, 0.0);
        self.w.resize(n, 0.0);
        self.cell.resize(n, 0);
        self.slot.resize(n, 0);
        self.own.resize(n, false);
    }

    fn truncate(&mut self, n: usize) {
        self.x.truncate(n);
        self.y.truncate(n);
        self.z.truncate(n);
        self.w.truncate(n);
        self.cell.truncate(n);
        self.slot.truncate(n);
        self.own.truncate(n);
    }

    /// Number of points.
    pub(super) fn len(&self) -> usize {
        self.x.len()
    }

    /// The point runs around local cell `cell` (an own point's): 9 contiguous, ascending,
    /// disjoint runs covering the 27 cells around it, which hold every point closer than a
    /// cell.
    #[inline]
    pub(super) fn runs_near(&self, cell: u16, out: &mut [(u32, u32); 9]) {
        const L: usize = LOCAL_CELLS;
        let c = cell as usize;
        let mut k = 0;
        for dx in [c - L * L, c, c + L * L] {
            for d in [dx - L, dx, dx + L] {
                out[k] = (self.start[d - 1], self.start[d + 2]);
                k += 1;
            }
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
    fn tile_keys_interleave_the_bits() {
        let mut rng = Pcg32::new(2, 2);
        for _ in 0..1000 {
            let c = [0; 3].map(|_: u64| rng.next_below(1 << TILE_BITS) as u64);
            let mut want = 0u64;
            for bit in 0..TILE_BITS {
                for (a, &v) in c.iter().enumerate() {
                    want |= (v >> bit & 1) << (3 * bit + a as u32);
                }
            }
            assert_eq!(pack(c), want);
            assert_eq!(unpack(want), c);
        }
    }

    /// Every tile's neighbourhood, queried around each of its own points, holds exactly the
    /// points (not skipped) closer than a cell, by brute force; every point is in exactly one
    /// tile; the slots of each cell are in generation order.
    #[test]
    fn neighbourhoods_hold_exactly_the_brute_force_neighbours() {
        let mut rng = Pcg32::new(11, 0);
        // Points on two parallel planes and a sparse cloud: many empty cells and tiles.
        let mut pts: Vec<Vec3> = (0..6000)
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
        let layout = Layout::new(Vec3::ZERO, r);
        // Three chunks of unequal size.
        let bounds = [0, 1000, 1001, pts.len()];
        let chunk = |c: usize, emit: &mut dyn FnMut(u32, Vec3)| {
            for i in bounds[c]..bounds[c + 1] {
                emit(i as u32, pts[i]);
            }
        };
        let counts: Vec<ChunkCounts> = (0..3)
            .map(|c| count_tiles(&layout, |emit| chunk(c, &mut |_, p| emit(p))))
            .collect();
        let tiles = Tiles::build(layout, &counts, chunk);
        assert!(tiles.len() > 8);
        let mut seen = vec![false; pts.len()];
        for (s, &i) in tiles.slots.iter().zip(&tiles.index) {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
            assert_eq!(s.position, pts[i as usize]);
        }
        let skipped = |s: u32| s % 7 == 3;
        for (s, slot) in tiles.slots.iter().enumerate() {
            slot.set_weight(if skipped(s as u32) {
                f32::NEG_INFINITY
            } else {
                s as f32
            });
        }
        let mut near = Neighbourhood::default();
        let mut runs = [(0, 0); 9];
        let mut owned = 0;
        for t in 0..tiles.len() {
            let range = tiles.slot_range(t);
            let key = |s: usize| (layout.cell_key(tiles.slots[s].position), tiles.index[s]);
            assert!(
                range
                    .clone()
                    .zip(range.clone().skip(1))
                    .all(|(a, b)| key(a) < key(b))
            );
            tiles.gather(t, 0.5, &mut near);
            for i in 0..near.len() {
                assert!(!skipped(near.slot[i]));
                assert_eq!(near.w[i], near.slot[i] as f32);
                if !near.own[i] {
                    assert!(!range.contains(&(near.slot[i] as usize)));
                    continue;
                }
                assert!(range.contains(&(near.slot[i] as usize)));
                owned += 1;
                near.runs_near(near.cell[i], &mut runs);
                assert!(runs.windows(2).all(|w| w[0].1 <= w[1].0), "{runs:?}");
                let me = tiles.slots[near.slot[i] as usize].position;
                let mut got: Vec<u32> = runs
                    .iter()
                    .flat_map(|&(a, b)| a..b)
                    .map(|j| near.slot[j as usize])
                    .filter(|&s| me.distance(tiles.slots[s as usize].position) < r)
                    .collect();
                got.sort_unstable();
                let want: Vec<u32> = (0..tiles.slots.len() as u32)
                    .filter(|&s| !skipped(s) && me.distance(tiles.slots[s as usize].position) < r)
                    .collect();
                assert_eq!(got, want, "tile {t}, slot {}", near.slot[i]);
                // Local coordinates: the tile corner is 0, the unit 0.5.
                let q = near.x[i] * 0.5;
                assert!((q - (me.x - layout.tile_corner(tiles.keys[t]).x as f32)).abs() < 1e-5);
            }
        }
        assert_eq!(
            owned,
            (0..pts.len() as u32).filter(|&s| !skipped(s)).count()
        );
    }

    /// Compaction leaves every gather the same points, in the same order, with the same
    /// weights and positions, and the same set of live candidate indices, round after round.
    #[test]
    fn compaction_keeps_every_gather() {
        let mut rng = Pcg32::new(4, 7);
        let pts: Vec<Vec3> = (0..5000)
            .map(|_| {
                Vec3::new(
                    rng.next_f32() * 3.0,
                    rng.next_f32() * 3.0,
                    rng.next_f32() * 0.5,
                )
            })
            .collect();
        let layout = Layout::new(Vec3::ZERO, 0.17);
        let chunk = |_: usize, emit: &mut dyn FnMut(u32, Vec3)| {
            for (i, &p) in pts.iter().enumerate() {
                emit(i as u32, p);
            }
        };
        let counts = vec![count_tiles(&layout, |emit| chunk(0, &mut |_, p| emit(p)))];
        let mut tiles = Tiles::build(layout, &counts, chunk);
        assert!(tiles.len() > 8);
        let snapshot = |tiles: &Tiles| {
            let mut near = Neighbourhood::default();
            let mut all = Vec::new();
            for t in 0..tiles.len() {
                tiles.gather(t, 0.5, &mut near);
                let moved: Vec<(Vec3, u32)> = near
                    .slot
                    .iter()
                    .map(|&s| (tiles.slots[s as usize].position, tiles.index[s as usize]))
                    .collect();
                all.push((
                    near.x.clone(),
                    near.y.clone(),
                    near.z.clone(),
                    near.w.clone(),
                    near.cell.clone(),
                    near.own.clone(),
                    moved,
                ));
            }
            let mut live: Vec<u32> = tiles
                .slots
                .iter()
                .zip(&tiles.index)
                .filter(|(s, _)| !s.removed())
                .map(|(_, &i)| i)
                .collect();
            live.sort_unstable();
            (all, live)
        };
        for (s, slot) in tiles.slots.iter().enumerate() {
            slot.set_weight(s as f32);
        }
        for round in 0..3u32 {
            // Remove about a third of what is left, at random.
            for slot in &tiles.slots {
                if !slot.removed() && rng.next_below(3) == 0 {
                    slot.set_weight(f32::NEG_INFINITY);
                }
            }
            let before = snapshot(&tiles);
            tiles.compact();
            let after = snapshot(&tiles);
            assert!(before.1.len() < pts.len(), "round {round}");
            assert_eq!(before.1, after.1, "live set, round {round}");
            assert_eq!(before.0, after.0, "gathers, round {round}");
            // Each cell's live slots are at its front, the rest of its slots removed.
            for (c, (&a, &b)) in tiles.cell_start.iter().zip(&tiles.cell_end).enumerate() {
                let next = tiles
                    .cell_start
                    .get(c + 1)
                    .copied()
                    .unwrap_or(tiles.slots.len() as u32);
                assert!(a <= b && b <= next, "cell {c}");
                for s in a..next {
                    assert_eq!(
                        tiles.slots[s as usize].removed(),
                        s >= b,
                        "cell {c}, slot {s}"
                    );
                }
            }
        }
    }
}
