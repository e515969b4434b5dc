//! A blocked tournament tree over the candidates' weights: which candidate is heaviest, kept
//! up to date as weights drop.
//!
//! The leaves are the caller's (grid-sorted) candidates, read through a weight accessor; level 0 holds the
//! heaviest of each run of [`FANOUT`] leaves, level 1 the heaviest of each run of `FANOUT`
//! level-0 entries, and so on up to a single root:
//!
//! ```text
//! level 2:  [ (w, i) ]                                  root: the heaviest candidate
//! level 1:  [ (w, i) | (w, i) | ... ]                   one per 16 level-0 entries
//! level 0:  [ (w, i) | (w, i) | (w, i) | ... ]          one per 16 leaves
//! leaves:   [ w w w w w w w w w w w w w w w w | w ... ] the caller's weights, grid order
//! ```
//!
//! Why not a heap: sample elimination lowers the weights of ~20 neighbours of each removed
//! candidate. In grid order those neighbours are a handful of contiguous runs, so here an update
//! rescans a few leaf runs the caller has just touched and a few small, cache-resident upper
//! levels. A heap orders by weight, which scatters neighbours across memory: tried first, an
//! exact binary heap (0.8 s of the 1.2 s for 100k samples), a lazy binary heap re-inserting
//! stale entries (4 stale pops per removal, no faster) and an indexed 4-ary heap with inline
//! weights (0.6 s); all were bound by cache misses.
//!
//! Ties go to the lower index (children are scanned in index order and only a strictly larger
//! weight replaces the best), so the order of removal is exactly that of an exact heap keyed by
//! `(weight, −index)`, a pure function of the weights.

/// Entries per run at every level.
pub(super) const FANOUT: usize = 16;

/// The heaviest weight of a run and its leaf index.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    weight: f32,
    leaf: u32,
}

/// The heaviest of `entries`, first one on ties.
#[inline]
fn best_of(entries: &[Entry]) -> Entry {
    let (mut weight, mut leaf) = (entries[0].weight, entries[0].leaf);
    for e in &entries[1..] {
        // Written as selects, so the compiler emits conditional moves, not branches.
        let better = e.weight > weight;
        weight = if better { e.weight } else { weight };
        leaf = if better { e.leaf } else { leaf };
    }
    Entry { weight, leaf }
}

/// The tree (see the module documentation). Leaves are passed in by the caller.
pub(super) struct MaxTree {
    levels: Vec<Vec<Entry>>,
}

impl MaxTree {
    /// Builds the tree over `leaves` (at least one), whose weights `weight` reads, O(n).
    pub(super) fn new<L>(leaves: &[L], weight: impl Fn(&L) -> f32) -> MaxTree {
        let mut levels = vec![
            leaves
                .chunks(FANOUT)
                .enumerate()
                .map(|(g, run)| Self::best_leaf(run, g * FANOUT, &weight))
                .collect::<Vec<Entry>>(),
        ];
        while levels.last().is_some_and(|l| l.len() > 1) {
            let below = levels.last().map_or(&[][..], |l| &l[..]);
            let next = below.chunks(FANOUT).map(best_of).collect();
            levels.push(next);
        }
        MaxTree { levels }
    }

    /// The heaviest leaf of a run starting at leaf `first`.
    #[inline]
    fn best_leaf<L>(run: &[L], first: usize, weight_of: impl Fn(&L) -> f32) -> Entry {
        let (mut weight, mut best) = (weight_of(&run[0]), 0usize);
        for (k, leaf) in run.iter().enumerate().skip(1) {
            let w = weight_of(leaf);
            let better = w > weight;
            weight = if better { w } else { weight };
            best = if better { k } else { best };
        }
        Entry {
            weight,
            leaf: (first + best) as u32,
        }
    }

    /// The leaf of largest weight (lowest index on ties), or `None` for an empty tree.
    pub(super) fn top(&self) -> Option<u32> {
        self.levels.last()?.first().map(|e| e.leaf)
    }

    /// Brings the tree up to date after the weights of `leaves[start..end]` changed.
    pub(super) fn update<L>(
        &mut self,
        leaves: &[L],
        weight: impl Fn(&L) -> f32,
        start: usize,
        end: usize,
    ) {
        if start >= end {
            return;
        }
        let (mut lo, mut hi) = (start / FANOUT, (end - 1) / FANOUT);
        let mut changed = false;
        for g in lo..=hi {
            changed |= self.rescan_leaves(leaves, &weight, g);
        }
        for level in 1..self.levels.len() {
            if !changed {
                return;
            }
            changed = false;
            (lo, hi) = (lo / FANOUT, hi / FANOUT);
            for g in lo..=hi {
                changed |= self.rescan_entry(level, g);
            }
        }
    }

    /// Recomputes level-0 entry `g` from its run of leaves; true if it changed.
    #[inline(always)]
    fn rescan_leaves<L>(&mut self, leaves: &[L], weight: impl Fn(&L) -> f32, g: usize) -> bool {
        let first = g * FANOUT;
        let run = &leaves[first..(first + FANOUT).min(leaves.len())];
        let e = Self::best_leaf(run, first, weight);
        let changed = e != self.levels[0][g];
        self.levels[0][g] = e;
        changed
    }

    /// Recomputes entry `g` of `level` (≥ 1) from the level below; true if it changed.
    #[inline(always)]
    fn rescan_entry(&mut self, level: usize, g: usize) -> bool {
        let (below, here) = self.levels.split_at_mut(level);
        let below = &below[level - 1];
        let first = g * FANOUT;
        let e = best_of(&below[first..(first + FANOUT).min(below.len())]);
        let changed = e != here[0][g];
        here[0][g] = e;
        changed
    }

    /// [`MaxTree::update`] for several runs of leaves whose weights have **fallen** (never
    /// risen), `ranges` ascending and disjoint (a removal's neighbourhood): each level is
    /// brought up to date once for all of them, so that the upper entries the runs share are
    /// rescanned once instead of once per run, and a run of leaves is rescanned only if its
    /// heaviest leaf was among those changed. The tree ends in the same state as after one
    /// `update` per run (every entry is the best of its children, ties to the lower index,
    /// whatever order it was recomputed in).
    pub(super) fn update_ranges<L>(
        &mut self,
        leaves: &[L],
        weight: impl Fn(&L) -> f32,
        ranges: &[(u32, u32)],
    ) {
        const MAX_RUNS: usize = 16;
        debug_assert!(
            ranges.windows(2).all(|w| w[0].1 <= w[1].0),
            "runs not ascending"
        );
        if ranges.len() > MAX_RUNS {
            for &(a, b) in ranges {
                self.update(leaves, &weight, a as usize, b as usize);
            }
            return;
        }
        // Per run: its span of entries at the current level, and whether an entry it
        // recomputed there changed (only then can its parents be stale). Above the leaves, an
        // entry another run recomputed first is skipped: that run carries the flag.
        //
        // Weights only fall (the caller subtracts non-negative kernel values, and removal and
        // locking lower a weight to −∞ or f32::MIN), so a run of leaves whose heaviest leaf is
        // untouched keeps it: only the runs whose best leaf lies in a changed range are
        // rescanned (each by the range holding that leaf).
        let mut spans = [(0usize, 0usize, false); MAX_RUNS];
        let mut any = false;
        for (span, &(a, b)) in spans.iter_mut().zip(ranges) {
            if a >= b {
                continue;
            }
            let (lo, hi) = (a as usize / FANOUT, (b as usize - 1) / FANOUT);
            let mut changed = false;
            for g in lo..=hi {
                if (a..b).contains(&self.levels[0][g].leaf) {
                    changed |= self.rescan_leaves(leaves, &weight, g);
                }
            }
            *span = (lo, hi, changed);
            any |= changed;
        }
        for level in 1..self.levels.len() {
            if !any {
                return;
            }
            any = false;
            let mut done = None::<usize>;
            for span in spans.iter_mut().take(ranges.len()) {
                let (lo, hi) = (span.0 / FANOUT, span.1 / FANOUT);
                let mut changed = false;
                if span.2 {
                    for g in lo.max(done.map_or(0, |d| d + 1))..=hi {
                        changed |= self.rescan_entry(level, g);
                    }
                    done = Some(done.map_or(hi, |d| d.max(hi)));
                }
                *span = (lo, hi, changed);
                any |= changed;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn top_is_the_exact_argmax_while_weights_drop() {
        let mut rng = Pcg32::new(3, 3);
        for n in [1usize, 15, 16, 17, 300, 5000] {
            // Few distinct weights, so ties are common.
            let mut w: Vec<f32> = (0..n).map(|_| rng.next_below(20) as f32).collect();
            let mut tree = MaxTree::new(&w, |&x| x);
            for _ in 0..n {
                // The reference: scan for the largest weight, lowest index on ties.
                let want = (0..n)
                    .max_by(|&a, &b| w[a].total_cmp(&w[b]).then(b.cmp(&a)))
                    .unwrap();
                let got = tree.top().unwrap() as usize;
                assert_eq!(got, want, "n = {n}");
                // Remove it, and lower a run of weights around a random place.
                w[got] = f32::NEG_INFINITY;
                tree.update(&w, |&x| x, got, got + 1);
                let a = rng.next_below(n as u32) as usize;
                let b = (a + rng.next_below(40) as usize).min(n);
                for x in &mut w[a..b] {
                    *x -= rng.next_below(3) as f32;
                }
                tree.update(&w, |&x| x, a, b);
            }
        }
    }

    /// Batched updates leave the tree exactly as one update per run does.
    #[test]
    fn update_ranges_equals_one_update_per_run() {
        let mut rng = Pcg32::new(5, 9);
        for n in [1usize, 16, 17, 255, 4097, 20_000] {
            let mut w: Vec<f32> = (0..n).map(|_| rng.next_below(50) as f32).collect();
            let mut batched = MaxTree::new(&w, |&x| x);
            let mut single = MaxTree::new(&w, |&x| x);
            for _ in 0..300 {
                // Up to 12 ascending, disjoint runs (some empty, some adjacent).
                let mut ranges = Vec::new();
                let mut at = rng.next_below(n as u32) as usize;
                for _ in 0..=rng.next_below(12) {
                    let a = (at + rng.next_below(3) as usize * rng.next_below(200) as usize).min(n);
                    let b = (a + rng.next_below(70) as usize).min(n);
                    ranges.push((a as u32, b as u32));
                    at = b;
                }
                for &(a, b) in &ranges {
                    for x in &mut w[a as usize..b as usize] {
                        *x -= rng.next_below(4) as f32;
                    }
                }
                batched.update_ranges(&w, |&x| x, &ranges);
                for &(a, b) in &ranges {
                    single.update(&w, |&x| x, a as usize, b as usize);
                }
                assert_eq!(batched.levels, single.levels, "n = {n}, runs {ranges:?}");
            }
        }
    }
}
