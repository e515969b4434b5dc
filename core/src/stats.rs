//! Per-query statistics for benchmarks, at no cost to the normal path: the traversal is
//! generic over a [`StatsSink`], and the normal queries use [`NoStats`], whose empty methods
//! compile to nothing.

/// Receives traversal events.
pub trait StatsSink {
    /// A query began ([`crate::IrradianceCache::query_with_stats`]).
    #[inline(always)]
    fn query(&mut self) {}
    /// An internal node was opened (its up-to-8 children examined in one batch).
    #[inline(always)]
    fn node(&mut self) {}
    /// `n` node aggregates were used instead of their samples.
    #[inline(always)]
    fn aggregates(&mut self, _n: u32) {}
    /// `n` samples were evaluated individually.
    #[inline(always)]
    fn samples(&mut self, _n: u32) {}
    /// `n` subtrees were skipped as negligible.
    #[inline(always)]
    fn culled(&mut self, _n: u32) {}
    /// The events another sink counted, passed on: how a query that counts into a
    /// [`QueryStats`] (the AVX2 traversal, compiled once for that type) reports to any sink.
    /// The default replays them one by one; sinks that count override it.
    #[inline]
    fn merge(&mut self, counts: &QueryStats) {
        for _ in 0..counts.queries {
            self.query();
        }
        for _ in 0..counts.nodes_opened {
            self.node();
        }
        let saturate = |n: u64| u32::try_from(n).unwrap_or(u32::MAX);
        self.aggregates(saturate(counts.aggregates));
        self.samples(saturate(counts.samples));
        self.culled(saturate(counts.culled));
    }
}

/// Discards every event.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoStats;

impl StatsSink for NoStats {
    #[inline(always)]
    fn merge(&mut self, _counts: &QueryStats) {}
}

/// Counts traversal events (accumulates over any number of queries).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryStats {
    /// Queries counted.
    pub queries: u64,
    /// Internal nodes opened.
    pub nodes_opened: u64,
    /// Node aggregates used (one profile evaluation each).
    pub aggregates: u64,
    /// Samples evaluated individually (one profile evaluation each).
    pub samples: u64,
    /// Subtrees skipped by the cull tolerance.
    pub culled: u64,
}

impl QueryStats {
    /// Profile evaluations (RGB triples): aggregates plus samples.
    pub fn profile_evaluations(&self) -> u64 {
        self.aggregates + self.samples
    }
}

impl StatsSink for QueryStats {
    #[inline(always)]
    fn query(&mut self) {
        self.queries += 1;
    }
    #[inline(always)]
    fn node(&mut self) {
        self.nodes_opened += 1;
    }
    #[inline(always)]
    fn aggregates(&mut self, n: u32) {
        self.aggregates += n as u64;
    }
    #[inline(always)]
    fn samples(&mut self, n: u32) {
        self.samples += n as u64;
    }
    #[inline(always)]
    fn culled(&mut self, n: u32) {
        self.culled += n as u64;
    }
    #[inline]
    fn merge(&mut self, counts: &QueryStats) {
        self.queries += counts.queries;
        self.nodes_opened += counts.nodes_opened;
        self.aggregates += counts.aggregates;
        self.samples += counts.samples;
        self.culled += counts.culled;
    }
}
