//! Poisson-disk (blue-noise) samples over triangle meshes by weighted sample elimination
//! (Yuksel 2015, "Sample Elimination for Generating Poisson Disk Sample Sets", Computer
//! Graphics Forum 34(2)), run on spatial tiles in parallel.
//!
//! 1. Draw `M = 4N` area-uniform candidates, stratified along a space-filling curve so that their density is nearly exact at every scale (see
//!    `strata.rs`: with independent uniform candidates the output kept ~1–3% low-frequency
//!    density noise, which became per-pixel error). The paper recommends `M = 5N`; with
//!    stratified candidates four per sample give the same sample quality (the box-count noise
//!    and the renders' per-pixel noise are unchanged, the minimum distance 2% smaller:
//!    `BENCHMARKS.md`) for a fifth less work.
//! 2. Give each candidate the weight `w_i = Σ_j (1 − d̂_ij / d_max)^α` over the candidates `j`
//!    closer than `d_max = 2·r_max`, with `α = 8` (the paper's value) and `r_max` the disk
//!    radius of hexagonal packing at `N` points: `d_max` = [`hex_spacing`]`(A, N)`. Distances
//!    are 3-D Euclidean.
//! 3. Remove heavy candidates and subtract their contributions from their neighbours until
//!    `N` remain — heaviest first within each tile, tiles in parallel (below).
//!
//! Weight limiting (the paper's §3.3): `d̂_ij = max(d_ij, d_min)` with `d_min = d_max ·
//! (1 − (N/M)^γ) · β`, `γ = 1.5`, `β = 0.65`, so that very close pairs do not dominate.
//! Elimination on a surface in 3-D uses the 2-D `r_max` (the surface is locally a plane), as
//! the paper does for surface sampling.
//!
//! **Tiles and phases.** Space is cut into cells of edge `d_max` and tiles of 7³ cells
//! (`grid.rs`). Tiles are coloured 0–7 by the parities of their coordinates; tiles of one
//! colour are at least a tile apart, so a tile's removals (which touch only candidates within
//! `d_max`, i.e. the tile and one cell of halo around it) never meet another's of the same
//! colour. The elimination runs in 8 rounds of 8 phases; in each phase every tile of one
//! colour, in parallel, copies its candidates and halo into local memory (positions relative
//! to the tile, in units of `d_max`), removes its heaviest own candidates (ties: the first in
//! local order) until it is down to its target for the round, and writes back the weights of
//! its candidates and halo. The outcome depends only on the phase order, never on timing or
//! the thread count. Each tile keeps exactly `⌊C_t/4⌋ − ⌊C_{t−1}/4⌋` candidates in the end
//! (`C_t`: the candidates of tiles `0..=t`), which sums to exactly `N`; round `r` takes every
//! tile to `quota + excess · (4^((7−r)/8) − 1)/3`, so that the density falls by the same factor
//! (4^(1/8) ≈ 1.19) everywhere in every round, and the colour order rotates with the round.
//! One round (every tile straight to its quota) left a density deficit along the borders of
//! the tiles processed first (they saw their neighbours at 5× density), measured on a 40 × 40
//! plane with 60k samples as 1.2–1.35% std of the counts in 4 × 4 boxes; eight rounds give
//! 0.74–0.86% (the former sequential elimination with quotas per run of 320 candidates along
//! the curve: 0.76–0.81%), 8 × 8 boxes 0.25–0.27% (0.30–0.37%), minimum distance 0.65–0.66 of
//! the hexagonal spacing (0.66–0.67), all with five candidates per sample; with four, 0.65–0.80%,
//! 0.23–0.32% and 0.64–0.65. Tiles of 4³ cells cut the box noise further but forced
//! close pairs (minimum distance 0.15), as small quota groups did before.
//!
//! **Memory.** Candidates are generated on demand, never stored as surface points: block `b`
//! of [`BLOCK`] candidates comes from its own PCG32 stream keyed by the seed and `b`, so it can
//! be regenerated at will, by any thread. A first pass counts the candidates per tile, a
//! second writes each one's position and index straight to its slot (a counting sort), and
//! after the elimination a third regenerates the blocks and keeps the survivors. What is held
//! per candidate is its slot (position and weight, 16 B; a removal sets the weight to −∞) and
//! its index (4 B): per sample (four candidates) about 85 B, then 24 B for the output, the
//! peak of a whole render (the cache build holds less). The tiles' cell lists and neighbour
//! tables are a few bytes per sample.
//!
//! **Cost.** Each weight is summed once (9 contiguous runs of the 27 cells around it, ~130
//! candidates, vectorised), each removal updates the same runs and a small per-tile max-tree
//! (`maxtree.rs`), and every round gathers each tile with its halo again; all of it in a few
//! KB of local memory, so the elimination is bound by arithmetic instead of the memory latency
//! of the former sequential elimination over the whole set (22 s for 1M samples, one thread).
//! Between rounds each tile's live candidates are moved to the front of their cells
//! (`Tiles::compact`), so a gather reads only live slots (about 22 instead of 40 slot reads
//! per sample over the eight rounds) and copies them without a branch on removal; the
//! gathered neighbourhoods, hence the samples, are the same as without it. About 3.8 s of CPU
//! for 1M samples on the sphere with two threads on this machine, spread over the cores by
//! the phases (`examples/placement_cost.rs`; figures in `BENCHMARKS.md`). By perf, the largest
//! parts are the gathers (about a sixth, half of it the first load of a slot that misses the
//! cache, which is why a slot holds its weight and removal, and why a gather counts the live
//! slots before it copies them), the max-tree updates, the weight
//! sums and removals, and the three generation passes (~15%).
//!
//! Alternatives considered: dart throwing cannot hit an exact count; keeping each candidate's
//! neighbour list instead of re-scanning cells costs ~18 entries per candidate (~360 MB at 1M
//! samples); recomputing the weights at every round instead of writing back the halo's cost
//! 25% more time.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec3;
use rayon::prelude::*;

use super::error::SamplingError;
use super::grid::{ChunkCounts, Layout, Neighbourhood, Tiles, count_tiles};
use super::maxtree::MaxTree;
use super::rng::{Pcg32, splitmix64};
use super::strata::Strata;
use super::surface::{AreaDistribution, SampleTarget, SurfacePoint, hex_spacing};
use crate::geometry::vertex_bounds;

/// Candidates per output sample (Yuksel 2015 §5 recommends 5; with stratified candidates 4
/// gives the same quality: see the module documentation).
const CANDIDATE_RATIO: usize = 4;
/// `(N/M)^γ` with `γ = 1.5` (the weight limiting exponent) and `M/N` the candidate ratio,
/// written as `1 / (R·√R)`: `sqrt` is correctly rounded everywhere, `powf` is not, and the
/// samples must be the same bits on every platform.
fn weight_limit_power() -> f64 {
    let r = CANDIDATE_RATIO as f64;
    1.0 / (r * r.sqrt())
}
/// Weight limiting factor β.
const BETA: f64 = 0.65;
/// Candidates drawn from one random stream.
const BLOCK: usize = 4096;
/// Blocks per chunk of the two counting-sort passes.
const CHUNK_BLOCKS: usize = 16;
/// Rounds of elimination (see [`SCHEDULE`]).
const ROUNDS: u32 = 8;

/// `count` blue-noise points on the triangles (see the module documentation for the method).
///
/// Area-uniform in distribution, with a minimum 3-D distance close to that of a hexagonal
/// packing. Exactly `target.resolve(total_area)` points, in candidate order (along a Morton
/// curve over the triangles: spatially coherent); a pure function of the triangles, the
/// target and the seed. Every vertex must be finite and the total area positive.
pub fn poisson_samples(
    triangles: &[[Vec3; 3]],
    target: SampleTarget,
    seed: u64,
) -> Result<Vec<SurfacePoint>, SamplingError> {
    poisson_samples_with_progress(triangles, target, seed, &|_| {})
}

/// [`poisson_samples`], calling `progress` with the fraction of the work done (non-decreasing,
/// ending at 1) between its steps, from the calling thread.
pub fn poisson_samples_with_progress(
    triangles: &[[Vec3; 3]],
    target: SampleTarget,
    seed: u64,
    progress: &dyn Fn(f32),
) -> Result<Vec<SurfacePoint>, SamplingError> {
    let dist = AreaDistribution::new(triangles)?;
    let n = target.resolve(dist.total())? as usize;
    let m = n * CANDIDATE_RATIO;
    let bounds = vertex_bounds(triangles);
    let strata = Strata::new(triangles, bounds, dist.total(), m);
    let steps = (3 + 8 * ROUNDS) as f32;
    let mut step = 0.0;
    let mut advance = || {
        step += 1.0;
        progress(step / steps);
    };

    // 1. Candidates, generated on demand: block `b` is candidates `b·BLOCK ..` from their own
    // stream, the same for any thread count.
    let blocks = m.div_ceil(BLOCK);
    let block = |b: usize, emit: &mut dyn FnMut(usize, SurfacePoint)| {
        let stream = b as u64;
        let mut rng = Pcg32::new(splitmix64(seed ^ splitmix64(stream)), stream);
        let first = b * BLOCK;
        strata.candidates(triangles, first, BLOCK.min(m - first), m, &mut rng, emit);
    };
    let chunks = blocks.div_ceil(CHUNK_BLOCKS);
    let chunk = |c: usize, emit: &mut dyn FnMut(u32, Vec3)| {
        for b in c * CHUNK_BLOCKS..((c + 1) * CHUNK_BLOCKS).min(blocks) {
            block(b, &mut |i, p| emit(i as u32, p.position));
        }
    };

    // 2. Tiles: counted, then filled.
    let d_max = hex_spacing(dist.total(), n as u32);
    let d_min = (d_max as f64 * (1.0 - weight_limit_power()) * BETA) as f32;
    let origin = bounds.0;
    // Cells slightly larger than d_max, so rounding in the cell coordinates cannot separate a
    // pair closer than d_max.
    let layout = Layout::new(origin, d_max * 1.0001);
    let counts: Vec<ChunkCounts> = (0..chunks)
        .into_par_iter()
        .map(|c| count_tiles(&layout, |emit| chunk(c, &mut |_, p| emit(p))))
        .collect();
    advance();
    let mut tiles = Tiles::build(layout, &counts, chunk);
    drop(counts);
    advance();

    // 3. Elimination, tile by tile. Quotas: tile t keeps ⌊C_t/R⌋ − ⌊C_{t−1}/R⌋ of its
    // candidates, C_t counting the candidates of tiles 0..=t and R the candidate ratio, which
    // sums to exactly N.
    let mut quota = Vec::with_capacity(tiles.len());
    let mut seen = 0usize;
    for t in 0..tiles.len() {
        let before = seen / CANDIDATE_RATIO;
        seen += tiles.slot_range(t).len();
        quota.push((seen / CANDIDATE_RATIO - before) as u32);
    }
    let mut by_colour: [Vec<u32>; 8] = Default::default();
    for t in 0..tiles.len() {
        by_colour[tiles.colour(t)].push(t as u32);
    }
    let kernel = Kernel::new(d_min / d_max);
    // Every candidate's weight, summed once over its neighbours (any order: nothing changes
    // yet), then kept up to date by the removals. Each slot is written by one task only: its
    // own tile's, or that of the one tile of the phase whose halo holds it (tiles of a colour
    // are a tile apart, and halos one cell deep).
    (0..tiles.len())
        .into_par_iter()
        .for_each_init(Scratch::default, |scratch, t| {
            sum_weights(&tiles, t, d_max, &kernel, scratch)
        });
    for (round, &left) in SCHEDULE.iter().enumerate() {
        for c in 0..8 {
            let colour = &by_colour[(c + round) % 8];
            colour
                .par_iter()
                .for_each_init(Scratch::default, |scratch, &t| {
                    let t = t as usize;
                    let count = tiles.slot_range(t).len();
                    let q = quota[t] as usize;
                    let keep = q + ((count - q) as f64 * left) as usize;
                    eliminate(&tiles, t, keep, d_max, &kernel, scratch);
                });
            advance();
        }
        if round + 1 < SCHEDULE.len() {
            tiles.compact();
        }
    }

    // 4. The survivors, regenerated from their streams.
    // A bitmap by candidate index, set in parallel: OR is commutative, so the bits do not
    // depend on the order of the stores.
    let keep: Vec<AtomicU64> = (0..blocks * BLOCK / 64)
        .into_par_iter()
        .map(|_| AtomicU64::new(0))
        .collect();
    tiles
        .slots
        .par_chunks(1 << 16)
        .zip(tiles.index.par_chunks(1 << 16))
        .for_each(|(slots, index)| {
            for (slot, &i) in slots.iter().zip(index) {
                if !slot.removed() {
                    keep[i as usize / 64].fetch_or(1 << (i % 64), Ordering::Relaxed);
                }
            }
        });
    drop(tiles);
    let keep: Vec<u64> = keep.into_iter().map(AtomicU64::into_inner).collect();
    let per_block: Vec<usize> = keep
        .chunks(BLOCK / 64)
        .map(|w| w.iter().map(|x| x.count_ones() as usize).sum())
        .collect();
    let mut out = vec![
        SurfacePoint {
            position: Vec3::ZERO,
            triangle: 0,
            bary: glam::Vec2::ZERO,
        };
        n
    ];
    let mut parts = Vec::with_capacity(blocks);
    let mut rest = &mut out[..];
    for &c in &per_block {
        let (part, tail) = rest.split_at_mut(c);
        parts.push(part);
        rest = tail;
    }
    parts.into_par_iter().enumerate().for_each(|(b, part)| {
        let mut k = 0;
        block(b, &mut |i, p| {
            if keep[i / 64] >> (i % 64) & 1 != 0 {
                part[k] = p;
                k += 1;
            }
        });
    });
    advance();
    Ok(out)
}

/// The share of each tile's excess candidates (over its quota) left after each round:
/// `(R^((ROUNDS − 1 − r)/ROUNDS) − 1) / (R − 1)` for round `r` and the candidate ratio R = 4,
/// so that the density falls by the same factor, 4^(1/8) ≈ 1.19, every round. (Constants, not
/// `powf`, whose rounding differs between platforms.)
const SCHEDULE: [f64; ROUNDS as usize] = [0.788, 0.610, 0.460, 0.333, 0.227, 0.138, 0.063, 0.0];

/// A task's working memory, reused across its tiles.
#[derive(Default)]
struct Scratch {
    near: Neighbourhood,
    weights: Vec<f32>,
    sign: Vec<f32>,
}

/// Sums the weights of tile `t`'s candidates over their neighbourhoods, into their slots.
fn sum_weights(tiles: &Tiles, t: usize, d_max: f32, kernel: &Kernel, scratch: &mut Scratch) {
    let near = &mut scratch.near;
    tiles.gather(t, d_max, near);
    let mut runs = [(0u32, 0u32); 9];
    for i in 0..near.len() {
        if near.own[i] {
            near.runs_near(near.cell[i], &mut runs);
            let p = [near.x[i], near.y[i], near.z[i]];
            let w: f32 = runs
                .iter()
                .map(|&(a, b)| kernel.sum(p, near, a as usize..b as usize))
                .sum();
            tiles.slots[near.slot[i] as usize].set_weight(w);
        }
    }
}

/// Eliminates tile `t`'s candidates, heaviest first (ties: the first in local order), until
/// `keep` are left, and brings the weights of the tile and its halo up to date.
///
/// Halo candidates repel but are never removed: they are held negated (`−w`, below every
/// live own weight, which is at least the self term `kernel(0) > 0`), and a removal adds to
/// them what it subtracts from the own candidates.
fn eliminate(
    tiles: &Tiles,
    t: usize,
    keep: usize,
    d_max: f32,
    kernel: &Kernel,
    scratch: &mut Scratch,
) {
    let near = &mut scratch.near;
    tiles.gather(t, d_max, near);
    let mut alive = near.own.iter().filter(|&&o| o).count();
    if alive <= keep {
        return;
    }
    let (w, sign) = (&mut scratch.weights, &mut scratch.sign);
    w.clear();
    sign.clear();
    for (&own, &x) in near.own.iter().zip(&near.w) {
        let s = if own { 1.0 } else { -1.0 };
        w.push(s * x);
        sign.push(s);
    }
    let mut runs = [(0u32, 0u32); 9];
    let mut tree = MaxTree::new(w, |&x| x);
    while alive > keep {
        let Some(i) = tree.top() else { break };
        let i = i as usize;
        debug_assert!(near.own[i] && w[i] > 0.0);
        w[i] = f32::NEG_INFINITY;
        alive -= 1;
        near.runs_near(near.cell[i], &mut runs);
        let p = [near.x[i], near.y[i], near.z[i]];
        for &(a, b) in &runs {
            let r = a as usize..b as usize;
            kernel.subtract(p, near, r.clone(), &sign[r.clone()], &mut w[r]);
        }
        tree.update_ranges(w, |&x| x, &runs);
    }
    // The removed (own) candidates are written back as −∞: removed.
    for ((&slot, &s), &x) in near.slot.iter().zip(sign.iter()).zip(w.iter()) {
        tiles.slots[slot as usize].set_weight(s * x);
    }
}

/// The pair weight `(1 − max(d, d_min) / d_max)^α` for `d < d_max`, else 0, written without
/// branches, on positions in units of `d_max` (so the squares stay small in any scene).
/// Symmetric to the bit (`w(p, q) == w(q, p)`: the differences only change sign).
struct Kernel {
    /// `d_min / d_max`.
    d_min_rel: f32,
}

/// Lanes of the weight sum: eight independent partial sums, added in a fixed order, so the
/// compiler can vectorise while the result stays a pure function of the input.
const LANES: usize = 8;

impl Kernel {
    fn new(d_min_rel: f32) -> Kernel {
        Kernel { d_min_rel }
    }

    #[inline(always)]
    fn weight(&self, dx: f32, dy: f32, dz: f32) -> f32 {
        let d = (dx * dx + dy * dy + dz * dz).sqrt().max(self.d_min_rel);
        let t = (1.0 - d).max(0.0);
        // t⁸ by squaring (not `powi`, whose rounding is unspecified across platforms).
        let t2 = t * t;
        let t4 = t2 * t2;
        t4 * t4
    }

    /// `Σ_j w(p, q_j)` over the points `range` of `near`.
    #[inline]
    fn sum(&self, p: [f32; 3], near: &Neighbourhood, range: std::ops::Range<usize>) -> f32 {
        let (x, y, z) = (
            &near.x[range.clone()],
            &near.y[range.clone()],
            &near.z[range],
        );
        let mut acc = [0.0f32; LANES];
        let full = x.len() / LANES * LANES;
        for c in (0..full).step_by(LANES) {
            let (x, y, z) = (&x[c..c + LANES], &y[c..c + LANES], &z[c..c + LANES]);
            for l in 0..LANES {
                acc[l] += self.weight(x[l] - p[0], y[l] - p[1], z[l] - p[2]);
            }
        }
        let mut total = acc.iter().sum::<f32>();
        for j in full..x.len() {
            total += self.weight(x[j] - p[0], y[j] - p[1], z[j] - p[2]);
        }
        total
    }

    /// `w_j −= s_j · w(p, q_j)` over the points `range` of `near` (`s` and `w` are that
    /// range's signs and weights).
    #[inline]
    fn subtract(
        &self,
        p: [f32; 3],
        near: &Neighbourhood,
        range: std::ops::Range<usize>,
        s: &[f32],
        w: &mut [f32],
    ) {
        let (x, y, z) = (
            &near.x[range.clone()],
            &near.y[range.clone()],
            &near.z[range],
        );
        for ((((w, &s), &x), &y), &z) in w.iter_mut().zip(s).zip(x).zip(y).zip(z) {
            *w -= s * self.weight(x - p[0], y - p[1], z - p[2]);
        }
    }
}
