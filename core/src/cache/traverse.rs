//! The one traversal behind the hierarchical (JB02), local-global (LM07) and edge-aware (N10)
//! queries, eight nodes or eight samples per step (the equations: `docs/physics.md` §9–§13).
//!
//! A stack holds internal nodes whose children are still to be examined. Popping a node
//! examines all its children at once in 8 lanes:
//!
//! 1. distance from x to each child's centroid P and to its bounding sphere about P (`dmin2`,
//!    0 inside), a lower bound of the exact gap (rounding and overflow of |x − P|² included:
//!    a node holding x must never look far from it);
//! 2. **prune** children without flux (unlit, shadowed): they add nothing. N10 needs the area
//!    of those touching the α-ball for its local weight — but only if the local irradiance can
//!    be non-zero, so they are *deferred* and visited at the end only if E(x) or the local
//!    numerator turned out positive (in a fully dark neighbourhood, E_loc = 0 whatever the
//!    weight). Without the deferral, N10 cost 26% more than JB02 at ε = 0.4 on a half-lit
//!    sphere, all of it on the dark side;
//! 3. **aggregate** (JB02): x outside the bounds, the bounds clear of the α-ball (split modes,
//!    LM07's refinement rule), and max(A, 2π tr C)/|x − P|² < ε (JB02's ΔΩ = A/|x − P|²,
//!    with the node's flux spread standing in for its area where the spread is the wider; see
//!    [`DISC_AREA_PER_TRACE`]) → one term: the flux times the mean of
//!    Rd over the node *to fourth order* in the Taylor expansion about the centroid, from its
//!    covariance (departure from JB02, which takes Rd at the centroid alone and underestimates
//!    where Rd is convex; see [`crate::Dipole::rd_lanes_corrected`] for the derivation). The
//!    second-order term alone cut the error against the exhaustive sum 5–30× at equal ε on a
//!    23k-sample sphere (the 0.6% image error that plain aggregates reach at ε ≈ 0.4 was
//!    reached at ε ≈ 2 with about a quarter of the evaluations), but left a negative bias of
//!    the order of ε², −0.3% on a uniformly lit plane at the default ε = 0.5; the fourth-order
//!    term, from the covariance under a uniform-disc closure of the fourth moment (no new node
//!    data), brings it to −0.02…−0.07%;
//! 4. **cull**: of the rest, a child is skipped (never one touching the α-ball) when, in every
//!    channel, its contribution bound Rd(dmin)·flux (Rd is decreasing) is at most
//!    `tolerance × (sum so far) × A_child / A_total`. Culled subtrees are disjoint and the
//!    running sum never exceeds the result, so all culled work together is at most
//!    `tolerance × result`. The bound is only evaluated beyond two diffusion lengths, where a
//!    cull can succeed. (A first version compared each subtree with `tolerance × sum` alone;
//!    thousands of culled subtrees then added up to 3% error at ε = 0.001.)
//! 5. open the others: a leaf's samples become terms at once, internal children are pushed,
//!    the nearest last so that it is popped first and the running sum grows fast.
//!
//! Terms are compacted into two small buffers — samples (plain Rd; the kernel in the split
//! modes) and aggregates (corrected Rd; always clear of the α-ball, so no kernel) — and the
//! profile is evaluated on full 8-lane batches only: a first version evaluated Rd on every lane
//! of every examined batch and wasted about three quarters of the lanes.
//!
//! # Where the time goes, and what was cut
//!
//! Counted with callgrind on the half-shadowed sphere (18.5k samples, ε 0.75, 512²), a lookup
//! ran about 14 400 instructions at first: 47% in the corrected profile of aggregate batches,
//! 10% in the plain profile of sample batches, 15% in compaction and the rest in examining
//! nodes. What was cut, each measured on its own (output bit-identical unless noted):
//!
//! - the 8-lane exp and `Lanes::min`/`max` use the plain `minps`/`maxps` and an exact integer
//!   conversion instead of NaN-aware blends and range-checked rounding (−9% shading time);
//! - compaction is branch-free, through a table of lane orders ([`COMPACT`]), and writes four
//!   entries per column when at most four lanes are kept; it had looped over the set bits
//!   and reloaded the buffer length after every store (−10%, then −3%);
//! - the corrected profile shares ½q and ½tr C between sources, writes 1 − ζ as r²/d² and
//!   builds both polynomials from u + 3 (changes float bits by a few ulps; the error against
//!   the exhaustive sum is unchanged to four digits at every ε);
//! - only N10 folds its local sums; the two evaluation functions are out of line, so that the
//!   profile no longer crowds the node loop's registers.
//!
//! The fourth-order term costs about a fifth more instructions per lookup (callgrind, the
//! sphere of `examples/profile_query.rs` at ε 0.5: hierarchical 19 700 → 23 800, edge-aware
//! 21 400 → 25 300; the nodes visited are the same): four more moment columns per aggregate,
//! formed on the node's eight lanes, and seven more operations per source and channel. The
//! first version, with θ₄ and θ₅ written out, cost 3 points more; folding them into the
//! coefficients of θ₃ and θ₂ as polynomials in ρ = r²/d², with coefficients shared by both
//! sources, cut that. At equal bias it is cheaper: ε 1 with the fourth-order term has about
//! the plane bias of the second-order term at ε 0.5, for 13 500 instructions instead of 19 700.
//!
//! Tried and dropped (no gain measured): one division instead of two per source in the
//! corrected profile (a longer dependency chain; the divider was not the bottleneck); an exp
//! taking the positive argument (the compiler had already folded the negation); merging the
//! final partial sample batch into the aggregate batch (JB02: a corrected evaluation costs
//! more than the plain one it saves); re-slicing every column to one length so that one
//! bounds check per node covers all loads (2.6% fewer instructions, no time saved); each
//! node's children starting at a multiple of eight, so that every column load is aligned (no
//! gain); compaction by a three-stage shift-and-blend network on plain arrays instead of
//! [`COMPACT`] (the compiler emitted lane-by-lane moves: 40% slower per lookup).
//!
//! # The AVX2 path
//!
//! `wide::f32x8` is two SSE registers in the default (x86-64 baseline) build. The traversal is
//! also compiled for AVX2, inside [`crate::IrradianceCache::query_planned_avx2`], on
//! [`crate::lanes::ArrayLanes`], whose operations the compiler vectorises to one ymm register.
//! A function only gets AVX2 code if it is inlined into that one, so for that lane type
//! ([`Lanes::INLINE_TRAVERSAL`]) the whole traversal is inlined: the profile evaluations are
//! not kept out of line as above, and the code avoids closures and iterator adapters, which
//! the compiler left as calls compiled without AVX2. Measured on the 23k-sample sphere
//! (`cargo bench -p lucent-raster --bench simd`), a query costs about 20% less than on the
//! baseline lanes at every ε, for both JB02 and N10, with the same bits; the baseline path's
//! code is unchanged (callgrind: the same instruction count within 1%).
//!
//! One instruction has no portable form the compiler would emit: the variable permutation
//! (`vpermps`) that moves a batch's kept lanes to the front of a term buffer. The AVX2 path
//! passes it in as a closure ([`Compaction`]): a closure made inside the `#[target_feature]`
//! function is compiled for AVX2 too, so the intrinsic is safe to call there, and the generic
//! code only calls the closure. Moved lane by lane through memory, the compaction had taken
//! about a fifth of a lookup; with `vpermps` a lookup costs 6–7% less (BENCHMARKS.md, "The
//! floor"). Tried: appending in registers (the pending entries blended with the permuted new
//! ones, every store a whole aligned half) was 4–5% slower than that: the compiler turned the
//! blend and store into a masked store (`vmaskmovps`), which the next load cannot forward from.
//!
//! In the split modes each sample term gets the kernel weight w(r): the global sum gets
//! (1 − w)·Rd·flux and, for N10, the local irradiance gets w·Rd·flux over w·Rd·A. Batches
//! entirely beyond α skip the kernel. Modes are const generics, so each is compiled without the
//! others' work.

use glam::{DVec3, Vec3};

use super::{COUNT_MASK, IrradianceCache, LEAF_BIT, MAX_DEPTH};
use crate::dipole::NodeMoments;
use crate::kernel::Kernel;
use crate::lanes::{LANES, Lanes, Mask};
use crate::profile::Profile;
use crate::stats::StatsSink;

/// JB02: octree sum, no smoothing.
pub(crate) const HIERARCHICAL: u8 = 0;
/// LM07: (1 − w)-weighted global sum.
pub(crate) const LOCAL_GLOBAL: u8 = 1;
/// N10: as LM07, plus the kernel-weighted local irradiance sums.
pub(crate) const EDGE_AWARE: u8 = 2;

/// Room for the deepest tree: each level leaves at most 7 siblings on the stack, and N10's
/// deferred pass starts with up to [`DEFERRED`] nodes already on it.
const STACK_SIZE: usize = (LANES - 1) * MAX_DEPTH + LANES + DEFERRED;
/// Term buffer: up to 8 pending terms plus one batch being appended.
const BUFFER: usize = 2 * LANES;
/// Unlit subtrees near x that N10 can defer (more are visited at once).
const DEFERRED: usize = 64;
/// Lane sums are folded into double precision every this many batches, so that a query over
/// millions of samples does not lose digits in f32 (at 10M samples and ε = 0 the plain f32
/// lanes differed from the exhaustive sum by 1.7e-4).
const FOLD_BATCHES: u32 = 32;

/// 2⁻⁶⁴: offsets this much smaller square without overflow (see `descend`).
const SQUARE_SCALE: f32 = 1.0 / 18_446_744_073_709_551_616.0;
/// 1 − 2⁻²⁰: a computed distance times this is at most the exact one (the f32 distance is
/// within about 4·2⁻²⁴ of it: one rounding per difference, square, sum and the root).
const DIST_LOWER: f32 = 1.0 - 1.0 / 1_048_576.0;

/// Traversal parameters (validated by the caller).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Params {
    pub epsilon: f32,
    pub cull_tolerance: f32,
    pub kernel: Kernel,
    /// E(x): decides whether N10's deferred unlit subtrees matter.
    pub irradiance: Vec3,
    /// N10: per channel a power of two at most 1/Rd(0), so that Rd·`rd_scale` ≤ 1.
    pub rd_scale: [f32; 3],
    /// N10: a power of two at most 1/Ā, so that A·`area_scale` ≤ A/Ā.
    pub area_scale: f32,
    /// N10: `area_scale` times [`FLUX_HEADROOM`] (a power of two, clamped into f32's normal
    /// range), so that no single flux term E·A/Ā can overflow.
    pub flux_scale: f32,
}

/// N10's flux terms are scaled by this beyond 1/Ā: E·A/Ā itself can exceed f32 (E near
/// f32::MAX on a sample larger than the mean), E·A/Ā·2⁻³² cannot (A/Ā ≤ n < 2³¹). Terms lose
/// digits only below about 2⁻⁹⁴ of E's unit, where they are negligible.
pub(crate) const FLUX_HEADROOM: f32 = 1.0 / 4_294_967_296.0;

/// What a traversal returns, per channel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sums {
    /// Σ Rd·E·A (hierarchical) or Σ (1 − w)·Rd·E·A (split modes).
    pub global: Vec3,
    /// N10: Σ w·Rd·E·A, scaled by `Params::rd_scale` and `Params::flux_scale` (kept in
    /// double precision: the sum of many terms near f32::MAX·2⁻³² must not overflow).
    pub local_flux: DVec3,
    /// N10: Σ w·Rd·A, scaled by `Params::rd_scale` and `Params::area_scale`.
    pub local_weight: DVec3,
    /// N10: the range (min, max) of the samples' irradiance E = Σ_c flux / A within α (samples
    /// of positive area), for the edge-refined method's edge test; (+∞, 0) for none.
    pub irradiance_range: (f32, f32),
}

/// For each 8-bit lane mask, its set lanes in increasing order (then zeros).
const fn compact_table() -> [[u8; LANES]; 256] {
    let mut t = [[0u8; LANES]; 256];
    let mut m = 0;
    while m < 256 {
        let (mut lane, mut n) = (0, 0);
        while lane < LANES {
            if m & (1 << lane) != 0 {
                t[m][n] = lane as u8;
                n += 1;
            }
            lane += 1;
        }
        m += 1;
    }
    t
}
static COMPACT: [[u8; LANES]; 256] = compact_table();

/// How [`Buffer::append`] moves the kept lanes of a batch to the front.
///
/// Index loops rather than iterator adapters or closures here and in the rest of the
/// traversal: the AVX2 path inlines all of it into one function, and there the compiler left
/// such helpers as out-of-line calls, compiled without AVX2.
pub(crate) trait Compaction: Copy {
    /// Writes each of `values` into its column from `len` on, lane `order[i]` at `len + i`;
    /// the first `n` (the kept lanes) must land, the rest may be anything.
    fn compact<L: Lanes, const C: usize>(
        self,
        columns: &mut [[f32; BUFFER]; C],
        len: usize,
        values: [L; C],
        order: &[u8; LANES],
        n: usize,
    );
}

/// Lane by lane, through memory: any instruction set (SSE2 has no variable permutation
/// across eight lanes). Four entries per column when at most four lanes are kept.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneByLane;

impl Compaction for LaneByLane {
    #[inline(always)]
    fn compact<L: Lanes, const C: usize>(
        self,
        columns: &mut [[f32; BUFFER]; C],
        len: usize,
        values: [L; C],
        order: &[u8; LANES],
        n: usize,
    ) {
        if n <= LANES / 2 {
            write_in_order::<L, C, { LANES / 2 }>(columns, len, values, order);
        } else {
            write_in_order::<L, C, LANES>(columns, len, values, order);
        }
    }
}

/// Writes the first `W` lanes of `order` from each of `values` into its column from `len` on.
#[inline(always)]
fn write_in_order<L: Lanes, const C: usize, const W: usize>(
    columns: &mut [[f32; BUFFER]; C],
    len: usize,
    values: [L; C],
    order: &[u8; LANES],
) {
    for c in 0..C {
        let v = values[c].to_array();
        let dst = &mut columns[c][len..len + W];
        for i in 0..W {
            dst[i] = v[(order[i] & 7) as usize];
        }
    }
}

/// A permutation in registers (AVX2's `vpermps`, [`crate::lanes::permute_avx2`]) of a whole
/// column, eight entries written per column. Given as a closure: made inside the one
/// `#[target_feature(enable = "avx2")]` function, the closure is compiled for AVX2 too, so the
/// intrinsic is safe to call there, and the generic traversal only calls the closure.
#[cfg(all(feature = "simd", any(target_arch = "x86", target_arch = "x86_64")))]
#[derive(Clone, Copy, Debug)]
pub(crate) struct InRegisters<F>(pub F);

#[cfg(all(feature = "simd", any(target_arch = "x86", target_arch = "x86_64")))]
impl<F: Fn([f32; LANES], u64) -> [f32; LANES] + Copy> Compaction for InRegisters<F> {
    #[inline(always)]
    fn compact<L: Lanes, const C: usize>(
        self,
        columns: &mut [[f32; BUFFER]; C],
        len: usize,
        values: [L; C],
        order: &[u8; LANES],
        _n: usize,
    ) {
        let order = u64::from_le_bytes(*order);
        for c in 0..C {
            let moved = (self.0)(values[c].to_array(), order);
            columns[c][len..len + LANES].copy_from_slice(&moved);
        }
    }
}

/// Pending terms, `C` columns in structure-of-arrays form.
struct Buffer<const C: usize> {
    columns: [[f32; BUFFER]; C],
    len: usize,
}

impl<const C: usize> Buffer<C> {
    fn new() -> Self {
        Buffer {
            columns: [[0.0; BUFFER]; C],
            len: 0,
        }
    }

    /// Appends the lanes of `keep`; true when a full batch is ready.
    ///
    /// Branch-free: every column gets eight entries at `len`, the kept lanes first in order
    /// (from [`COMPACT`]), and `len` grows by the number kept; the entries past it are
    /// overwritten by the next append or masked when evaluated. The first version looped over
    /// the set bits of `keep` and stored lane by lane, reloading `len` after every store.
    #[inline(always)]
    fn append<L: Lanes, K: Compaction>(&mut self, keep: Mask, values: [L; C], by: K) -> bool {
        let order = &COMPACT[(keep.0 & 0xff) as usize];
        let len = self.len.min(LANES);
        let n = keep.0.count_ones() as usize;
        by.compact(&mut self.columns, len, values, order, n);
        self.len = len + n;
        self.len >= LANES
    }

    /// The first eight entries of every column.
    #[inline(always)]
    fn batch<L: Lanes>(&self) -> [L; C] {
        let mut batch = [L::splat(0.0); C];
        for c in 0..C {
            batch[c] = L::load(&self.columns[c]);
        }
        batch
    }

    /// Drops the first batch: fixed-size moves of the upper half (< 8 entries) to the front.
    #[inline(always)]
    fn consume(&mut self) {
        for column in &mut self.columns {
            let (lo, hi) = column.split_at_mut(LANES);
            lo.copy_from_slice(hi);
        }
        self.len -= LANES;
    }
}

/// 2π: times a node's tr C, the area of the uniform disc whose covariance has that trace, so
/// that the aggregation rule reads max(A, 2π tr C)/|x − P|² < ε.
///
/// The fourth-order aggregate is a Taylor expansion about the centroid whose terms are powers
/// of the moments over r² (q, tr C, |Cv|²/r², tr C² in [`crate::Dipole::rd_lanes_corrected`]),
/// so what decides whether it has converged is the flux's spread, tr C/r², more than A/r².
/// For an evenly lit, evenly sampled flat patch the two agree (a disc of area A has
/// tr C = A/2π) and the rule is JB02's. They part where the flux spreads wider than the area
/// suggests: a sliver where an octant clips a curved surface, a strip, a node lit only at its
/// rim. There the area alone aggregates a node whose expansion is still poor at x: isolated
/// pixels 20× worse than the rest on a scanned mesh at ε 0.5, for 3–5% fewer evaluations
/// (BENCHMARKS.md, "The aggregation rule"). The spread alone, without the area, almost doubled
/// the mean relative error.
const DISC_AREA_PER_TRACE: f32 = 2.0 * core::f32::consts::PI;

struct Walker<'a, L: Lanes, S: StatsSink, K: Compaction, const MODE: u8> {
    cache: &'a IrradianceCache,
    profile: &'a Profile,
    kernel: Kernel,
    rd_scale: [f32; 3],
    area_scale: f32,
    flux_scale: f32,
    x: [L; 3],
    /// Sample terms: r², flux r g b, area.
    samples: Buffer<5>,
    /// Aggregate terms: r², flux r g b, then the node's moments (see [`NodeMoments`]):
    /// vᵀCv/r², tr C, |Cv|²/r², tr C².
    aggregates: Buffer<8>,
    global: [L; 3],
    local_flux: [L; 3],
    local_weight: [L; 3],
    /// N10: lane-wise min and max of the samples' irradiance within α (see `Sums`).
    range: [L; 2],
    /// The lane sums folded so far, in double precision.
    folded: [[f64; 3]; 3],
    /// Batches evaluated since the last fold.
    batches: u32,
    /// N10: unlit subtrees meeting the α-ball, visited at the end only if they matter.
    deferred: [u32; DEFERRED],
    deferred_len: usize,
    stats: &'a mut S,
    /// How the term buffers are appended to.
    compaction: K,
}

impl<L: Lanes, S: StatsSink, K: Compaction, const MODE: u8> Walker<'_, L, S, K, MODE> {
    /// Folds the lane sums into the double-precision totals every [`FOLD_BATCHES`] batches.
    #[inline(always)]
    fn count_batch(&mut self) {
        self.batches += 1;
        if self.batches == FOLD_BATCHES {
            self.fold();
        }
    }

    /// Adds the lane sums to the double-precision totals and clears them (only N10 has local
    /// sums: the other modes skip their six reductions of zeros).
    #[inline(always)]
    fn fold(&mut self) {
        let zero = L::splat(0.0);
        for c in 0..3 {
            self.folded[0][c] += self.global[c].reduce_add() as f64;
            self.global[c] = zero;
        }
        if MODE == EDGE_AWARE {
            for c in 0..3 {
                self.folded[1][c] += self.local_flux[c].reduce_add() as f64;
                self.folded[2][c] += self.local_weight[c].reduce_add() as f64;
                self.local_flux[c] = zero;
                self.local_weight[c] = zero;
            }
        }
        self.batches = 0;
    }

    /// A running total per channel (folded plus lanes): 0 = global, 1 = local flux.
    #[inline(always)]
    fn running(&self, which: usize) -> [f64; 3] {
        let lanes = if which == 0 {
            &self.global
        } else {
            &self.local_flux
        };
        let mut total = self.folded[which];
        for c in 0..3 {
            total[c] += lanes[c].reduce_add() as f64;
        }
        total
    }

    /// Evaluates the first `n ≤ 8` sample terms.
    ///
    /// Kept out of line (like [`Walker::evaluate_aggregates`]): inlined at every call site, the
    /// three-channel profile crowded the node loop's registers; out of line, query_with ran 4%
    /// fewer instructions and divan's query_hierarchical 2–4% faster. Except for a lane type
    /// that inlines the whole traversal ([`Lanes::INLINE_TRAVERSAL`]): the AVX2 path, where
    /// an out-of-line function would be compiled without AVX2 (and where a value takes one
    /// register instead of two, so the node loop is not crowded).
    #[inline(always)]
    fn evaluate_samples(&mut self, n: usize) {
        if L::INLINE_TRAVERSAL {
            self.sample_terms(n);
        } else {
            self.sample_terms_out_of_line(n);
        }
    }

    #[inline(never)]
    fn sample_terms_out_of_line(&mut self, n: usize) {
        self.sample_terms(n);
    }

    #[inline(always)]
    fn sample_terms(&mut self, n: usize) {
        self.count_batch();
        let [r2, fr, fg, fb, area] = self.samples.batch::<L>();
        let valid = Mask::first(n as u32);
        let flux = [fr.keep(valid), fg.keep(valid), fb.keep(valid)];
        let rd = self.profile.rd_lanes(r2);
        if MODE == HIERARCHICAL || !r2.lt(L::splat(self.kernel.radius2())).any() {
            for c in 0..3 {
                self.global[c] = self.global[c] + rd[c] * flux[c];
            }
            return;
        }
        let w = self.kernel.weight_lanes(r2);
        let one_minus_w = L::splat(1.0) - w;
        // N10's sums are scaled so that they stay near the unit whatever the units: the
        // weight w·Rd·A as w·(Rd/Rd(0))·(A/Ā), its flux as w·(Rd/Rd(0))·(E·A/Ā)·2⁻³². Unscaled,
        // Rd·A underflowed to subnormals at tiny scales and the local irradiance lost every
        // digit. Each factor is scaled on its own, by a power of two (exact, see `Params`):
        // one combined factor 1/(Rd(0)·Ā) overflowed Rd·factor to +∞ where Ā < 2⁻¹²⁷ (∞/∞ =
        // NaN, and E_loc fell back to E(x)).
        let raw_area = area;
        let area = area.keep(valid) * L::splat(self.area_scale);
        let flux_scale = L::splat(self.flux_scale);
        for c in 0..3 {
            // The kernel factor multiplies the flux first: where it is 0, a term is 0 even if
            // Rd·flux would overflow (∞·0 = NaN otherwise).
            self.global[c] = self.global[c] + rd[c] * (flux[c] * one_minus_w);
            if MODE == EDGE_AWARE {
                let weight = rd[c] * L::splat(self.rd_scale[c]) * w;
                self.local_flux[c] = self.local_flux[c] + weight * (flux[c] * flux_scale);
                self.local_weight[c] = self.local_weight[c] + weight * area;
            }
        }
        if MODE == EDGE_AWARE {
            self.irradiance_range(r2, flux, raw_area, valid);
        }
    }

    /// The edge-refined method's edge test: the range of E = Σ_c flux / A over the samples
    /// within α with positive area (the lanes left out divide by zero, and are masked).
    #[inline(always)]
    fn irradiance_range(&mut self, r2: L, flux: [L; 3], area: L, valid: Mask) {
        let zero = L::splat(0.0);
        let inside = valid & r2.lt(L::splat(self.kernel.radius2())) & zero.lt(area);
        let e = ((flux[0] + flux[1] + flux[2]) / area).keep(inside);
        self.range[0] = self.range[0].min(e + L::splat(f32::MAX).keep(!inside));
        self.range[1] = self.range[1].max(e);
    }

    /// Evaluates the first `n ≤ 8` aggregate terms (all clear of the α-ball: global only);
    /// out of line as [`Walker::evaluate_samples`].
    #[inline(always)]
    fn evaluate_aggregates(&mut self, n: usize) {
        if L::INLINE_TRAVERSAL {
            self.aggregate_terms(n);
        } else {
            self.aggregate_terms_out_of_line(n);
        }
    }

    #[inline(never)]
    fn aggregate_terms_out_of_line(&mut self, n: usize) {
        self.aggregate_terms(n);
    }

    #[inline(always)]
    fn aggregate_terms(&mut self, n: usize) {
        self.count_batch();
        let [r2, fr, fg, fb, q, trace, cross, trace_sq] = self.aggregates.batch::<L>();
        let valid = Mask::first(n as u32);
        let moments = NodeMoments {
            q,
            trace,
            cross,
            trace_sq,
        };
        let rd = self.profile.rd_lanes_corrected(r2, &moments);
        let flux = [fr, fg, fb];
        for c in 0..3 {
            self.global[c] = self.global[c] + rd[c] * flux[c].keep(valid);
        }
    }

    /// Turns one leaf's samples into terms. `near`: the leaf's sphere meets the α-ball.
    #[inline(always)]
    fn leaf(&mut self, node: usize, near: bool) {
        let nodes = &self.cache.nodes;
        let s = &self.cache.samples;
        let first = nodes.first[node] as usize;
        let count = nodes.info[node] & COUNT_MASK;
        self.stats.samples(count);
        let px = L::load(&s.pos_x[first..]) - self.x[0];
        let py = L::load(&s.pos_y[first..]) - self.x[1];
        let pz = L::load(&s.pos_z[first..]) - self.x[2];
        let r2 = px * px + py * py + pz * pz;
        let flux = [
            L::load(&s.flux_r[first..]),
            L::load(&s.flux_g[first..]),
            L::load(&s.flux_b[first..]),
        ];
        let mut keep = Mask::first(count);
        if !(MODE == EDGE_AWARE && near) {
            // Samples without flux add nothing (N10 near x still needs their area).
            keep = keep & L::splat(0.0).lt(flux[0] + flux[1] + flux[2]);
        }
        let area = if MODE == EDGE_AWARE {
            L::load(&s.area[first..])
        } else {
            L::splat(0.0)
        };
        if self
            .samples
            .append(keep, [r2, flux[0], flux[1], flux[2], area], self.compaction)
        {
            self.evaluate_samples(LANES);
            self.samples.consume();
        }
    }

    /// Opens a node found to need opening: a leaf's samples now, an internal node later.
    #[inline(always)]
    fn open(&mut self, node: usize, near: bool, stack: &mut [u32; STACK_SIZE], sp: &mut usize) {
        if self.cache.nodes.info[node] & LEAF_BIT != 0 {
            self.leaf(node, near);
        } else {
            stack[*sp] = node as u32;
            *sp += 1;
        }
    }

    /// Pops and examines nodes until the stack is empty. `DEFER`: N10 may set unlit subtrees
    /// near x aside instead of opening them (a constant: each pass is compiled on its own, and
    /// the renderer's shading ran 7% fewer instructions than with a run-time flag, by
    /// callgrind; divan saw no difference in time).
    #[inline(always)]
    fn descend<const DEFER: bool>(
        &mut self,
        params: &Params,
        stack: &mut [u32; STACK_SIZE],
        mut sp: usize,
    ) {
        let nodes = &self.cache.nodes;
        let zero = L::splat(0.0);
        let eps = L::splat(params.epsilon);
        let alpha2 = L::splat(if MODE == HIERARCHICAL {
            0.0
        } else {
            self.kernel.radius2()
        });
        let tolerance = params.cull_tolerance;
        let total_area = nodes.area[0].max(f32::MIN_POSITIVE);
        // Culling is only attempted beyond two diffusion lengths of the slowest channel.
        let sigma_tr_min = self.profile.decay_rate().min_element();
        let cull_from = 2.0 / sigma_tr_min;
        let cull_from2 = L::splat(cull_from * cull_from);
        let [xx, xy, xz] = self.x;

        while sp > 0 {
            sp -= 1;
            let node = stack[sp] as usize;
            self.stats.node();
            let first = nodes.first[node] as usize;
            let valid = Mask::first(nodes.info[node] & COUNT_MASK);

            // Offsets to the centroids, and the gap to each bounding sphere.
            let cx = lanes_at::<L>(&nodes.centroid_x, first) - xx;
            let cy = lanes_at::<L>(&nodes.centroid_y, first) - xy;
            let cz = lanes_at::<L>(&nodes.centroid_z, first) - xz;
            let dist2 = cx * cx + cy * cy + cz * cz;
            let mut dist = dist2.sqrt();
            let radius = lanes_at::<L>(&nodes.radius, first);
            let overflowed = !dist2.lt(L::splat(f32::INFINITY));
            if overflowed.any() {
                // Centroids beyond ~1.8e19 square to +∞ (Rd is 0 there, but the node's sphere
                // may still hold x): their distance again, through coordinates scaled by 2⁻⁶⁴
                // (the offsets themselves can overflow near ±f32::MAX). A radius of f32::MAX
                // stands for a sphere too large for f32 (see `validate`): it holds x.
                let s = L::splat(SQUARE_SCALE);
                let sx = lanes_at::<L>(&nodes.centroid_x, first) * s - xx * s;
                let sy = lanes_at::<L>(&nodes.centroid_y, first) * s - xy * s;
                let sz = lanes_at::<L>(&nodes.centroid_z, first) * s - xz * s;
                let scaled = (sx * sx + sy * sy + sz * sz).sqrt() * L::splat(1.0 / SQUARE_SCALE);
                let bounded = radius.lt(L::splat(f32::MAX));
                dist = dist.keep(!overflowed) + scaled.keep(overflowed & bounded);
            }
            // A lower bound of the gap to the sphere (the radius is rounded up; `dist` is within
            // 2⁻²² of the exact distance): x on a large sphere's surface must test as inside,
            // or an unlit node holding x is pruned from N10's weights.
            let gap = (dist * L::splat(DIST_LOWER) - radius).max(zero);
            let dmin2 = gap * gap;
            let flux = [
                lanes_at::<L>(&nodes.flux_r, first),
                lanes_at::<L>(&nodes.flux_g, first),
                lanes_at::<L>(&nodes.flux_b, first),
            ];
            let near = dmin2.lt(alpha2); // the sphere meets the α-ball (never in JB02 mode)
            let lit = zero.lt(flux[0] + flux[1] + flux[2]);
            let mut live = valid & lit;
            if MODE == EDGE_AWARE {
                let unlit_near = valid & near & !lit;
                if DEFER {
                    let mut bits = unlit_near.0;
                    while bits != 0 {
                        let lane = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        if self.deferred_len < DEFERRED {
                            self.deferred[self.deferred_len] = (first + lane) as u32;
                            self.deferred_len += 1;
                        } else {
                            live = live | Mask(1 << lane);
                        }
                    }
                } else {
                    live = live | unlit_near;
                }
            }
            if !live.any() {
                continue;
            }

            let area = lanes_at::<L>(&nodes.area, first);
            let outside = radius.lt(dist * L::splat(DIST_LOWER));
            // tr C decides the aggregation as well as feeding the aggregate's moments.
            let (sxx, syy, szz) = (
                lanes_at::<L>(&nodes.cov_xx, first),
                lanes_at::<L>(&nodes.cov_yy, first),
                lanes_at::<L>(&nodes.cov_zz, first),
            );
            let trace = sxx + syy + szz;
            let small = (L::splat(DISC_AREA_PER_TRACE) * trace)
                .max(area)
                .lt(eps * dist2);
            let aggregate = live & outside & !near & small;
            if aggregate.any() {
                self.stats.aggregates(aggregate.0.count_ones());
                // The moments of the fourth-order aggregate (v = P − x): vᵀCv, |Cv|², tr C
                // and tr C².
                let (sxy, sxz, syz) = (
                    lanes_at::<L>(&nodes.cov_xy, first),
                    lanes_at::<L>(&nodes.cov_xz, first),
                    lanes_at::<L>(&nodes.cov_yz, first),
                );
                let cvx = sxx * cx + sxy * cy + sxz * cz;
                let cvy = sxy * cx + syy * cy + syz * cz;
                let cvz = sxz * cx + syz * cy + szz * cz;
                let vcv = cx * cvx + cy * cvy + cz * cvz;
                let cv2 = cvx * cvx + cvy * cvy + cvz * cvz;
                let trace_sq = sxx * sxx
                    + syy * syy
                    + szz * szz
                    + L::splat(2.0) * (sxy * sxy + sxz * sxz + syz * syz);
                // Aggregated lanes are outside their sphere, so dist2 > 0 there. Mathematically
                // q ≤ λ_max ≤ tr C and q² ≤ p = vᵀC²v/r² ≤ λ_max q; the clamps keep rounding
                // within those bounds and overflowed lanes (∞/∞) finite.
                let inv_dist2 = L::splat(1.0) / dist2;
                let q = (vcv * inv_dist2).min(trace).max(zero);
                let cross = (cv2 * inv_dist2).min(trace * q).max(q * q);
                if self.aggregates.append(
                    aggregate,
                    [dist2, flux[0], flux[1], flux[2], q, trace, cross, trace_sq],
                    self.compaction,
                ) {
                    self.evaluate_aggregates(LANES);
                    self.aggregates.consume();
                }
            }

            let mut open = live & !aggregate;
            if !open.any() {
                continue;
            }
            let cullable = open & !near & cull_from2.lt(dmin2);
            if tolerance > 0.0 && cullable.any() {
                let running = self.running(0);
                let running = [running[0] as f32, running[1] as f32, running[2] as f32];
                if running[0] > 0.0 || running[1] > 0.0 || running[2] > 0.0 {
                    // Area-budgeted bound: Rd(dmin)·flux ≤ tol · running · A_node / A_total.
                    let bound = self.profile.rd_lanes(dmin2);
                    let budget = area * L::splat(tolerance / total_area);
                    let mut negligible = Mask(0xff);
                    for c in 0..3 {
                        // Not (budget · running < bound · flux).
                        negligible =
                            negligible & !(budget * L::splat(running[c])).lt(bound[c] * flux[c]);
                    }
                    let culled = cullable & negligible;
                    open = open & !culled;
                    self.stats.culled(culled.0.count_ones());
                }
            }

            let dmin2 = dmin2.to_array();
            let mut nearest = (f32::INFINITY, usize::MAX);
            let mut bits = open.0;
            while bits != 0 {
                let lane = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let child = first + lane;
                if nodes.info[child] & LEAF_BIT == 0 && dmin2[lane] < nearest.0 {
                    nearest = (dmin2[lane], sp);
                }
                self.open(child, near.0 >> lane & 1 == 1, stack, &mut sp);
            }
            if nearest.1 != usize::MAX {
                stack.swap(nearest.1, sp - 1);
            }
        }
    }

    #[inline(always)]
    fn run(&mut self, params: &Params) {
        if self.cache.node_len == 0 {
            return;
        }
        let mut stack = [0u32; STACK_SIZE];
        if self.cache.nodes.info[0] & LEAF_BIT != 0 {
            self.leaf(0, true);
        } else {
            stack[0] = 0;
            if MODE == EDGE_AWARE {
                self.descend::<true>(params, &mut stack, 1);
            } else {
                self.descend::<false>(params, &mut stack, 1);
            }
        }
        self.flush_samples();
        if MODE == EDGE_AWARE && self.deferred_len > 0 {
            // The deferred unlit subtrees only weigh the local irradiance; with no light at x
            // and none in the local numerator, E_loc is 0 whatever their weight.
            let numerator = self.running(1);
            if params.irradiance.max_element() > 0.0 || numerator.iter().any(|&v| v > 0.0) {
                let deferred = self.deferred;
                let mut sp = 0;
                for &node in &deferred[..self.deferred_len] {
                    self.open(node as usize, true, &mut stack, &mut sp);
                }
                self.descend::<false>(params, &mut stack, sp);
                self.flush_samples();
            }
        }
        if self.aggregates.len > 0 {
            self.evaluate_aggregates(self.aggregates.len);
            self.aggregates.len = 0;
        }
    }

    /// Evaluates the last, partial batch of samples.
    #[inline(always)]
    fn flush_samples(&mut self) {
        if self.samples.len > 0 {
            self.evaluate_samples(self.samples.len);
            self.samples.len = 0;
        }
    }
}

/// The eight entries of `column` from `first` (a node's children, a leaf's samples).
#[inline(always)]
fn lanes_at<L: Lanes>(column: &[f32], first: usize) -> L {
    L::load(&column[first..])
}

/// Runs one traversal in mode `MODE` for the shading point `x`: out of line, unless the lane
/// type inlines the whole traversal into its caller ([`Lanes::INLINE_TRAVERSAL`]).
#[inline(always)]
pub(crate) fn traverse<L: Lanes, S: StatsSink, K: Compaction, const MODE: u8>(
    cache: &IrradianceCache,
    profile: &Profile,
    x: Vec3,
    params: &Params,
    stats: &mut S,
    compaction: K,
) -> Sums {
    if L::INLINE_TRAVERSAL {
        walk::<L, S, K, MODE>(cache, profile, x, params, stats, compaction)
    } else {
        walk_out_of_line::<L, S, K, MODE>(cache, profile, x, params, stats, compaction)
    }
}

#[inline(never)]
fn walk_out_of_line<L: Lanes, S: StatsSink, K: Compaction, const MODE: u8>(
    cache: &IrradianceCache,
    profile: &Profile,
    x: Vec3,
    params: &Params,
    stats: &mut S,
    compaction: K,
) -> Sums {
    walk::<L, S, K, MODE>(cache, profile, x, params, stats, compaction)
}

#[inline(always)]
fn walk<L: Lanes, S: StatsSink, K: Compaction, const MODE: u8>(
    cache: &IrradianceCache,
    profile: &Profile,
    x: Vec3,
    params: &Params,
    stats: &mut S,
    compaction: K,
) -> Sums {
    let zero = [L::splat(0.0); 3];
    let mut walker = Walker::<L, S, K, MODE> {
        cache,
        profile,
        kernel: params.kernel,
        rd_scale: params.rd_scale,
        area_scale: params.area_scale,
        flux_scale: params.flux_scale,
        x: [L::splat(x.x), L::splat(x.y), L::splat(x.z)],
        samples: Buffer::new(),
        aggregates: Buffer::new(),
        global: zero,
        local_flux: zero,
        local_weight: zero,
        range: [L::splat(f32::MAX), L::splat(0.0)],
        folded: [[0.0; 3]; 3],
        batches: 0,
        deferred: [0; DEFERRED],
        deferred_len: 0,
        stats,
        compaction,
    };
    walker.run(params);
    walker.fold();
    let [global, local_flux, local_weight] = walker.folded.map(DVec3::from_array);
    let [lo, hi] = walker.range.map(|r| r.to_array());
    let lo = lo.into_iter().fold(f32::INFINITY, f32::min);
    Sums {
        global: global.as_vec3(),
        local_flux,
        local_weight,
        irradiance_range: (
            if lo == f32::MAX { f32::INFINITY } else { lo },
            hi.into_iter().fold(0.0, f32::max),
        ),
    }
}
