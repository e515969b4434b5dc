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
        for (g, slot) in self.levels[0].iter_mut().enumerate().take(hi + 1).skip(lo) {
            let first = g * FANOUT;
            let run = &leaves[first..(first + FANOUT).min(leaves.len())];
            let e = Self::best_leaf(run, first, &weight);
            changed |= e != *slot;
            *slot = e;
        }
        for level in 1..self.levels.len() {
            if !changed {
                return;
            }
            changed = false;
            (lo, hi) = (lo / FANOUT, hi / FANOUT);
            let (below, here) = self.levels.split_at_mut(level);
            let (below, here) = (&below[level - 1], &mut here[0]);
            for (g, slot) in here.iter_mut().enumerate().take(hi + 1).skip(lo) {
                let first = g * FANOUT;
                let e = best_of(&below[first..(first + FANOUT).min(below.len())]);
                changed |= e != *slot;
                *slot = e;
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
}
