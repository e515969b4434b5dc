//! BVH construction: top-down binned SAH (Wald 2007, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies", IEEE Symposium on Interactive Ray Tracing).
//!
//! Every node bins its triangles' centroids into [`BINS`] equal slabs along each axis (a node
//! of more than [`BINNED`] triangles, a regular sample of them), sweeps the bins to price every
//! split plane with the surface area heuristic, and either splits at the cheapest plane or
//! becomes a leaf when that is cheaper (and it holds at most [`MAX_LEAF`] triangles). Each
//! level is O(N), so the build is O(N log N) for the usual balanced splits; to bound the depth
//! (and so the fixed traversal stack) for any input, nodes deeper than [`MEDIAN_DEPTH`] switch
//! to object-median splits, which halve the count, so no path is longer than
//! `MEDIAN_DEPTH + 31` for fewer than 2³¹ triangles.
//!
//! Scenes of hundreds of thousands of triangles and more are built over *clusters* instead of
//! single triangles (`cluster.rs`): runs of up to [`CLUSTER`](super::CLUSTER) consecutive
//! triangles whose boxes touch and are of about one size (a strip of a scanned or tessellated
//! mesh), each priced by the SAH as its triangles and kept whole in one leaf. The build then
//! handles a quarter of the items at every level; rays pay for leaves of whole clusters (see
//! [`CLUSTERED_FROM`](super::CLUSTERED_FROM)).
//!
//! Free of hashing or randomness, so the tree is a pure function of the input: large subtrees
//! are built on two threads and spliced where a one-threaded build puts them, so the node
//! array is the same for any number of threads. Non-finite triangles are left out (and
//! listed); degenerate ones are kept (they have valid boxes and the triangle test never
//! reports a hit on them).

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use crate::memory::{self, OutOfMemory};

use super::aabb::Aabb;
use super::cluster::Clusters;
use super::node::{BvhNode, WideNode};

/// Centroid bins per axis. Wald 2007 found 16–32 bins within a few percent of a full sweep.
pub(super) const BINS: usize = 16;
/// A node of more triangles than this prices its planes from a sample of about this many,
/// every k-th of its triangles (their boxes and the partition stay exact). On a 7.8 M-triangle
/// mesh the split search was a fifth of the render's CPU, most of it binning the top levels'
/// millions of triangles into 16 slabs whose costs a few thousand estimate as well.
pub(super) const BINNED: usize = 1 << 12;
/// Most triangles in one leaf.
pub(super) const MAX_LEAF: u32 = 8;
const _: () = assert!(
    MAX_LEAF <= u8::MAX as u32,
    "WideNode stores leaf sizes in a u8"
);
/// Depth from which splits are object medians (see the module documentation).
pub(super) const MEDIAN_DEPTH: u32 = 32;
/// Bound on the depth of any node (root = 0), and the size of the traversal stack.
pub(super) const MAX_DEPTH: u32 = 64;
/// At most this many input triangles are used (indices are `u32`; node counts `2N − 1`).
pub(super) const MAX_TRIANGLES: usize = 1 << 31;
/// Cost of a traversal step relative to one triangle test. Tried 0.125 (pbrt's ratio), 1, 2
/// and 4 on the bench scene (101,920 triangles, shadow rays from its surface): average leaf
/// sizes 1.1, 1.8, 2.9 and 5.8 triangles, shadow-ray times within 7% of each other (noise on
/// this machine); 1 builds a mid-sized tree.
const TRAVERSAL_COST: f32 = 1.0;

/// Entries of the 4-wide traversal stack that suffice for any tree: each node visit pops one
/// entry and pushes at most four, and the wide tree is no deeper than the binary one
/// (`MAX_DEPTH`).
pub(super) const WIDE_STACK: usize = 3 * MAX_DEPTH as usize + 1;
/// The stack the traversals use when the tree's [`stack_need`] allows (every tree of up to
/// millions of well-spread triangles): zeroing the full [`WIDE_STACK`] for every ray cost
/// 10–15% of a coherent shadow ray.
pub(super) const SMALL_STACK: usize = 32;

/// What the builder returns: the node array and, per leaf slot, the input triangle index.
pub(super) struct Built {
    pub nodes: Vec<BvhNode>,
    pub order: Vec<u32>,
    pub skipped: Vec<u32>,
}

/// Subtrees of at least this many triangles are built on two threads (`rayon::join`), their
/// halves apart; smaller ones in one go. On a 2 M-triangle mesh, 2¹⁴ leaves a few hundred
/// pieces, enough for the threads to share the work and few enough that splicing them is cheap.
pub(super) const PARALLEL_MIN: usize = 1 << 14;

/// A box as the builder keeps it: [`Aabb`]'s arithmetic on 16-byte lanes. `Aabb`'s
/// `Vec3::min`/`max` are NaN-aware and lane by lane; here each is one `minps`/`maxps`, which
/// agree with them on the finite boxes and the empty box the builder combines, so the tree is
/// the same to the bit. 32 bytes, half a cache line; the centroid is computed from it rather
/// than read from an array of its own.
#[derive(Clone, Copy)]
pub(super) struct Bounds {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
}

const _: () = assert!(core::mem::size_of::<Bounds>() == 32);

impl Bounds {
    pub(super) const EMPTY: Bounds = Bounds {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    pub(super) fn of(b: &Aabb) -> Bounds {
        Bounds {
            min: b.min.into(),
            max: b.max.into(),
        }
    }

    fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }

    #[inline(always)]
    pub(super) fn union(self, o: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    #[inline(always)]
    fn grow(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The length of the box's diagonal.
    #[inline(always)]
    pub(super) fn diagonal(self) -> f32 {
        (self.max - self.min).length()
    }

    /// True when the two boxes share a point (closed boxes).
    #[inline(always)]
    pub(super) fn touches(self, o: Bounds) -> bool {
        o.min.cmple(self.max).all() && self.min.cmple(o.max).all()
    }

    /// [`Aabb::center`].
    #[inline(always)]
    fn center(self) -> Vec3A {
        self.min * 0.5 + self.max * 0.5
    }

    /// [`Aabb::half_area`], the same operations in the same order.
    #[inline(always)]
    fn half_area(self) -> f32 {
        if !self.min.cmple(self.max).all() {
            return 0.0;
        }
        let d = self.max - self.min;
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A range of `order` waiting to become node `node`.
struct Task {
    node: u32,
    start: u32,
    end: u32,
    depth: u32,
}

/// A subtree built apart from the rest: [`place`] splices it into the node array exactly where
/// the one-threaded build puts it.
enum Piece {
    /// A subtree built in one go: its nodes in the one-threaded build's order, root first, an
    /// interior node's `first` an index into this array.
    Whole(Vec<BvhNode>),
    /// A node split here, its two halves built apart.
    Split {
        bounds: Bounds,
        halves: Box<(Piece, Piece)>,
    },
}

/// Builds the tree over `triangles` (only the first [`MAX_TRIANGLES`] are looked at), building
/// subtrees of at least `parallel_min` items on two threads, pricing the planes of a node of
/// more than `binned` items from about `binned` of them, and over clusters of up to
/// `cluster` triangles (1: every triangle on its own). The nodes are the same for every
/// `parallel_min` (the one-threaded build's), so that tests can compare a build split into
/// many pieces with one that is not split at all. The renderer passes [`PARALLEL_MIN`],
/// [`BINNED`] and [`super::cluster::cluster_size`]; tests lower `binned` so that small inputs
/// take the sampled path too, and cluster small inputs.
pub(super) fn build_with(
    triangles: &[[Vec3; 3]],
    parallel_min: usize,
    binned: usize,
    cluster: usize,
) -> Result<Built, OutOfMemory> {
    let triangles = &triangles[..triangles.len().min(MAX_TRIANGLES)];
    let boxes = memory::par_collect(
        triangles
            .par_iter()
            .map(|t| Bounds::of(&Aabb::from_triangle(t))),
        memory::TRIANGLES,
    )?;
    let mut order = memory::with_capacity(triangles.len(), memory::TRIANGLES)?;
    let mut skipped = Vec::new();
    for (i, t) in triangles.iter().enumerate() {
        if t.iter().all(|v| v.is_finite()) {
            order.push(i as u32);
        } else {
            skipped.push(i as u32);
        }
    }
    if order.is_empty() {
        return Ok(Built {
            nodes: Vec::new(),
            order,
            skipped,
        });
    }
    let (parallel_min, binned) = (parallel_min.max(2), binned.max(1));
    // A mesh in no particular order would give clusters of one, which only add their
    // bookkeeping to the plain build.
    let clusters = if cluster > 1 && Clusters::worthwhile(&order, &boxes) {
        Some(Clusters::of(
            &order,
            &boxes,
            cluster.min(MAX_LEAF as usize),
        )?)
    } else {
        None
    };
    let Some(clusters) = clusters else {
        let builder = Builder::<false> {
            boxes: &boxes,
            weights: &[],
            binned,
        };
        let nodes = builder.tree(&mut order, parallel_min)?;
        return Ok(Built {
            nodes,
            order,
            skipped,
        });
    };
    drop(boxes);
    let mut items = memory::par_collect(
        (0..clusters.len() as u32).into_par_iter(),
        memory::TRIANGLES,
    )?;
    let builder = Builder::<true> {
        boxes: &clusters.boxes,
        weights: &clusters.size,
        binned,
    };
    let mut nodes = builder.tree(&mut items, parallel_min)?;
    let order = clusters.expand(&items, &order, &mut nodes)?;
    Ok(Built {
        nodes,
        order,
        skipped,
    })
}

/// Writes `piece` into `nodes` where the one-threaded build puts it: its root at `slot`, its
/// descendants appended. That build gives a node's two children adjacent slots when it splits
/// the node, then lays out the whole left subtree below them before the right one's children,
/// so a subtree's descendants are contiguous and in the order of [`Builder::whole`]. `nodes`
/// must have room for them (every caller reserves `2N − 1`).
fn place(piece: Piece, slot: usize, nodes: &mut Vec<BvhNode>) {
    match piece {
        Piece::Whole(own) => {
            // Index k ≥ 1 of `own` goes to `nodes.len() + k − 1`.
            let shift = nodes.len() as u32 - 1;
            nodes[slot] = shifted(own[0], shift);
            nodes.extend(own[1..].iter().map(|&node| shifted(node, shift)));
        }
        Piece::Split { bounds, halves } => {
            let children = nodes.len();
            nodes.push(BvhNode::new(&Aabb::EMPTY, 0, 0));
            nodes.push(BvhNode::new(&Aabb::EMPTY, 0, 0));
            nodes[slot] = BvhNode::new(&bounds.to_aabb(), children as u32, 0);
            let (left, right) = *halves;
            place(left, children, nodes);
            place(right, children + 1, nodes);
        }
    }
}

/// `node` with its children `shift` slots further on (a leaf's triangle slots stay).
fn shifted(mut node: BvhNode, shift: u32) -> BvhNode {
    if !node.is_leaf() {
        node.first += shift;
    }
    node
}

/// Per-triangle data the builder reads. (Tried: each triangle's box and centroid moved with it
/// through the partitions instead of indices into separate arrays: no gain on 2 M triangles. And
/// a split's parts given their bounds from its bins and partition instead of a pass over each:
/// no gain on 100 k or 5 M triangles.)
///
/// An item is a triangle, or with `CLUSTERED` a cluster whose triangles are counted by
/// `weights` (see [`Clusters`]): the SAH counts triangles either way.
struct Builder<'a, const CLUSTERED: bool> {
    boxes: &'a [Bounds],
    /// Triangles per item (empty when not `CLUSTERED`: one each).
    weights: &'a [u8],
    /// About how many items price a node's planes (see [`BINNED`]).
    binned: usize,
}

/// A candidate split: bin plane `bin` (left side = bins `0..=bin`) on `axis`.
#[derive(Clone, Copy)]
struct Split {
    axis: usize,
    bin: usize,
    cost: f32,
}

impl<const CLUSTERED: bool> Builder<'_, CLUSTERED> {
    /// The tree over `items`, root first.
    fn tree(&self, items: &mut [u32], parallel_min: usize) -> Result<Vec<BvhNode>, OutOfMemory> {
        Ok(match self.piece(items, 0, 0, parallel_min)? {
            Piece::Whole(nodes) => nodes,
            split => {
                let mut nodes = memory::with_capacity(2 * items.len() - 1, memory::TRIANGLES)?;
                nodes.push(BvhNode::new(&Aabb::EMPTY, 0, 0));
                place(split, 0, &mut nodes);
                nodes
            }
        })
    }

    /// Triangles in item `i`.
    #[inline(always)]
    fn weight(&self, i: u32) -> u32 {
        if CLUSTERED {
            u32::from(self.weights[i as usize])
        } else {
            1
        }
    }

    /// The subtree over `items` (the slots from `offset` on of the leaf order, at `depth`),
    /// its halves built on two threads while it holds at least `parallel_min` items.
    fn piece(
        &self,
        items: &mut [u32],
        offset: u32,
        depth: u32,
        parallel_min: usize,
    ) -> Result<Piece, OutOfMemory> {
        if items.len() < parallel_min {
            return self.whole(items, offset, depth).map(Piece::Whole);
        }
        let (bounds, cbounds, triangles) = self.bounds(items);
        let Some(mid) = self.choose_split(items, &bounds, &cbounds, depth, triangles) else {
            let leaf = BvhNode::new(&bounds.to_aabb(), offset, items.len() as u32);
            return Ok(Piece::Whole(vec![leaf]));
        };
        let (left, right) = items.split_at_mut(mid as usize);
        let (left, right) = rayon::join(
            || self.piece(left, offset, depth + 1, parallel_min),
            || self.piece(right, offset + mid, depth + 1, parallel_min),
        );
        Ok(Piece::Split {
            bounds,
            halves: Box::new((left?, right?)),
        })
    }

    /// The subtree over `items` (the slots from `offset` on of the leaf order, at `depth`) on
    /// this thread, root first; an interior node's `first` indexes the returned array.
    fn whole(
        &self,
        items: &mut [u32],
        offset: u32,
        depth: u32,
    ) -> Result<Vec<BvhNode>, OutOfMemory> {
        let mut nodes = memory::with_capacity(2 * items.len() - 1, memory::TRIANGLES)?;
        nodes.push(BvhNode::new(&Aabb::EMPTY, 0, 0));
        let mut stack = vec![Task {
            node: 0,
            start: 0,
            end: items.len() as u32,
            depth,
        }];
        while let Some(task) = stack.pop() {
            let items = &mut items[task.start as usize..task.end as usize];
            let (bounds, cbounds, triangles) = self.bounds(items);
            let n = items.len() as u32;
            let mid = match self.choose_split(items, &bounds, &cbounds, task.depth, triangles) {
                None => {
                    let bounds = bounds.to_aabb();
                    nodes[task.node as usize] = BvhNode::new(&bounds, offset + task.start, n);
                    continue;
                }
                Some(mid) => mid,
            };
            let left = nodes.len() as u32;
            nodes.push(BvhNode::new(&Aabb::EMPTY, 0, 0));
            nodes.push(BvhNode::new(&Aabb::EMPTY, 0, 0));
            nodes[task.node as usize] = BvhNode::new(&bounds.to_aabb(), left, 0);
            let split = task.start + mid;
            stack.push(Task {
                node: left + 1,
                start: split,
                end: task.end,
                depth: task.depth + 1,
            });
            stack.push(Task {
                node: left,
                start: task.start,
                end: split,
                depth: task.depth + 1,
            });
        }
        Ok(nodes)
    }

    /// Bounds of the items and of their centroids, and how many triangles they hold.
    fn bounds(&self, items: &[u32]) -> (Bounds, Bounds, u32) {
        let (mut b, mut c, mut triangles) = (Bounds::EMPTY, Bounds::EMPTY, 0);
        for &i in items {
            let own = self.boxes[i as usize];
            b = b.union(own);
            c.grow(own.center());
            triangles += self.weight(i);
        }
        (b, c, triangles)
    }

    /// The centroid of triangle `i`'s box.
    #[inline(always)]
    fn centroid(&self, i: u32) -> Vec3A {
        self.boxes[i as usize].center()
    }

    /// Partitions `items` (holding `triangles`) for a split and returns the size of the left
    /// part, or `None` to make a leaf.
    fn choose_split(
        &self,
        items: &mut [u32],
        bounds: &Bounds,
        cb: &Bounds,
        depth: u32,
        triangles: u32,
    ) -> Option<u32> {
        let n = items.len() as u32;
        if n <= 1 {
            return None;
        }
        let extent = cb.max - cb.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        if extent[axis].is_nan() || extent[axis] <= 0.0 {
            // All centroids coincide: no plane separates them. Split by position in the list.
            return (triangles > MAX_LEAF).then_some(n / 2);
        }
        if depth >= MEDIAN_DEPTH {
            if triangles <= MAX_LEAF {
                return None;
            }
            let key = |&i: &u32| (self.centroid(i)[axis], i);
            items.select_nth_unstable_by(n as usize / 2, |a, b| {
                let (ka, kb) = (key(a), key(b));
                ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1))
            });
            return Some(n / 2);
        }
        let best = self.best_planes(items, cb).into_iter().flatten().fold(
            None,
            |best: Option<Split>, s| match best {
                Some(b) if b.cost <= s.cost => Some(b),
                _ => Some(s),
            },
        );
        let Some(best) = best else {
            return (triangles > MAX_LEAF).then_some(n / 2);
        };
        let parent_area = bounds.half_area();
        let leaf_cost = parent_area * triangles as f32;
        let split_cost = TRAVERSAL_COST * parent_area + best.cost;
        if triangles <= MAX_LEAF && split_cost >= leaf_cost {
            return None;
        }
        let scale = BINS as f32 / extent[best.axis];
        let left_of = |i: u32| self.bin(i, cb, best.axis, scale) <= best.bin;
        // Two-pointer partition: deterministic, in place.
        let (mut lo, mut hi) = (0usize, items.len());
        while lo < hi {
            if left_of(items[lo]) {
                lo += 1;
            } else {
                hi -= 1;
                items.swap(lo, hi);
            }
        }
        Some(lo as u32)
    }

    /// The bin of triangle `i`'s centroid along `axis`. `scale = BINS / extent`.
    #[inline]
    fn bin(&self, i: u32, cb: &Bounds, axis: usize, scale: f32) -> usize {
        bin_of(self.centroid(i)[axis], cb.min[axis], scale)
    }

    /// On each axis along which the centroids spread, the cheapest of the `BINS − 1` planes that
    /// leave both sides non-empty, priced as `area(L)·|L| + area(R)·|R|` (the parent's area and
    /// the traversal cost are added by the caller). The three axes are binned in one pass over
    /// `items`, each triangle's box read once (a pass per axis read them three times); above
    /// [`Builder::binned`] triangles, over every k-th of them. Both sides of the plane chosen
    /// hold some of those, so neither side of the partition is empty. (Tried: two sets of bins
    /// filled by alternate triangles and merged, against store-to-load waits on runs of one
    /// bin: no gain.)
    fn best_planes(&self, items: &[u32], cb: &Bounds) -> [Option<Split>; 3] {
        let extent = cb.max - cb.min;
        let spread = [0, 1, 2].map(|a| extent[a] > 0.0);
        let scale = [0, 1, 2].map(|a| BINS as f32 / extent[a]);
        let mut counts = [[0u32; BINS]; 3];
        let mut boxes = [[Bounds::EMPTY; BINS]; 3];
        let stride = (items.len() / self.binned).max(1);
        for &i in items.iter().step_by(stride) {
            let b = self.boxes[i as usize];
            let c = b.center();
            for a in 0..3 {
                if spread[a] {
                    let k = bin_of(c[a], cb.min[a], scale[a]);
                    counts[a][k] += self.weight(i);
                    boxes[a][k] = boxes[a][k].union(b);
                }
            }
        }
        [0, 1, 2].map(|a| {
            spread[a]
                .then(|| Self::cheapest_plane(&counts[a], &boxes[a], a))
                .flatten()
        })
    }

    /// The cheapest plane between the bins of `axis` (see [`Builder::best_planes`]). Only the
    /// bins holding triangles are swept (most are empty in the many small nodes): the planes
    /// between two of them make one partition at one cost, and of those the sweep keeps the
    /// first, the plane right after the left one, as a sweep over every bin does.
    fn cheapest_plane(counts: &[u32; BINS], boxes: &[Bounds; BINS], axis: usize) -> Option<Split> {
        let mut filled = [0usize; BINS];
        let mut m = 0;
        for (k, &count) in counts.iter().enumerate() {
            filled[m] = k;
            m += (count > 0) as usize;
        }
        let filled = &filled[..m];
        // right_cost[j] describes the filled bins after filled[j] (the right side of its plane).
        let mut right_cost = [0.0f32; BINS];
        let (mut acc, mut count) = (Bounds::EMPTY, 0u32);
        for j in (1..m).rev() {
            acc = acc.union(boxes[filled[j]]);
            count += counts[filled[j]];
            right_cost[j - 1] = acc.half_area() * count as f32;
        }
        let (mut acc, mut count) = (Bounds::EMPTY, 0u32);
        let mut best: Option<Split> = None;
        for (j, &k) in filled.iter().enumerate().take(m.saturating_sub(1)) {
            acc = acc.union(boxes[k]);
            count += counts[k];
            let cost = acc.half_area() * count as f32 + right_cost[j];
            if best.is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: k, cost });
            }
        }
        best
    }
}

/// The bin of coordinate `x` of a box starting at `min`, `scale = BINS / extent`.
#[inline(always)]
fn bin_of(x: f32, min: f32, scale: f32) -> usize {
    // Clamped as a float first (NaN to 0, as the saturating cast to usize does), then cast
    // through i32: one truncation and two checks that never fail, where the cast to usize
    // took two truncations and the fix-ups of a 64-bit unsigned saturation (the one-threaded
    // build 15% faster).
    ((x - min) * scale).max(0.0).min((BINS - 1) as f32) as i32 as usize
}

/// Collapses the binary tree into the 4-wide one that queries traverse. Each wide node takes
/// the two children of a binary node and, while it has fewer than four lanes, replaces the
/// interior lane of largest surface area by that node's two children (the first one on a
/// tie), as in Wald, Benthin & Boulos 2008: big boxes are the ones most rays enter, so opening
/// them saves the most visits. Leaves are the binary tree's leaves, unchanged. Lanes keep the
/// binary tree's left-to-right order; the children of one wide node get consecutive indices.
/// Deterministic, O(N).
pub(super) fn collapse(nodes: &[BvhNode]) -> Result<Vec<WideNode>, OutOfMemory> {
    let Some(root) = nodes.first() else {
        return Ok(Vec::new());
    };
    let mut wide = memory::with_capacity(nodes.len() / 3 + 1, memory::TRIANGLES)?;
    wide.push(WideNode::EMPTY);
    if root.is_leaf() {
        wide[0].set_lane(0, &root.bounds(), root.first, root.count as u8);
        return Ok(wide);
    }
    let mut stack = vec![(0u32, 0u32)];
    while let Some((binary, index)) = stack.pop() {
        let first = nodes[binary as usize].first;
        let mut lanes = [first, first + 1, 0, 0];
        let mut len = 2;
        while len < 4 {
            let mut widest: Option<(usize, f32)> = None;
            for (i, &n) in lanes[..len].iter().enumerate() {
                let node = &nodes[n as usize];
                if node.is_leaf() {
                    continue;
                }
                let area = node.bounds().half_area();
                if widest.is_none_or(|(_, a)| area > a) {
                    widest = Some((i, area));
                }
            }
            let Some((i, _)) = widest else { break };
            let first = nodes[lanes[i] as usize].first;
            lanes.copy_within(i + 1..len, i + 2);
            lanes[i] = first;
            lanes[i + 1] = first + 1;
            len += 1;
        }
        let mut node = WideNode::EMPTY;
        for (lane, &n) in lanes[..len].iter().enumerate() {
            let child = &nodes[n as usize];
            if child.is_leaf() {
                node.set_lane(lane, &child.bounds(), child.first, child.count as u8);
            } else {
                let at = wide.len() as u32;
                wide.push(WideNode::EMPTY);
                node.set_lane(lane, &child.bounds(), at, 0);
                stack.push((n, at));
            }
        }
        wide[index as usize] = node;
    }
    Ok(wide)
}

/// The most entries the traversal stack of `Bvh`'s queries can hold on `wide`: a visit to a
/// node pushes its interior lanes on top of what its ancestors left, and a child is visited
/// with its parent's entries less the one popped to reach it. At most [`WIDE_STACK`].
pub(super) fn stack_need(wide: &[WideNode]) -> usize {
    if wide.is_empty() {
        return 0;
    }
    let interior = |n: &WideNode| (0..n.len()).filter(|&l| n.count[l] == 0).count();
    let mut need = 0;
    // (node, entries on the stack when it is visited)
    let mut stack = vec![(0u32, 0usize)];
    while let Some((index, base)) = stack.pop() {
        let node = &wide[index as usize];
        let pushed = interior(node);
        need = need.max(base + pushed);
        for lane in 0..node.len() {
            if node.count[lane] == 0 {
                stack.push((node.child[lane], base + pushed - 1));
            }
        }
    }
    need
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// The sweep over every bin, as the builder made it before it skipped the empty ones.
    fn every_bin_cheapest_plane(
        counts: &[u32; BINS],
        boxes: &[Bounds; BINS],
        axis: usize,
    ) -> Option<Split> {
        // right_cost[k] and right_count[k] describe bins k+1.. (the right side of plane k).
        let mut right_cost = [0.0f32; BINS];
        let mut right_count = [0u32; BINS];
        let (mut acc, mut count) = (Bounds::EMPTY, 0u32);
        for k in (1..BINS).rev() {
            acc = acc.union(boxes[k]);
            count += counts[k];
            right_cost[k - 1] = acc.half_area() * count as f32;
            right_count[k - 1] = count;
        }
        let (mut acc, mut count) = (Bounds::EMPTY, 0u32);
        let mut best: Option<Split> = None;
        for k in 0..BINS - 1 {
            acc = acc.union(boxes[k]);
            count += counts[k];
            if count == 0 || right_count[k] == 0 {
                continue;
            }
            let cost = acc.half_area() * count as f32 + right_cost[k];
            if best.is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: k, cost });
            }
        }
        best
    }

    /// The sweep over the filled bins keeps the plane, and the cost to the bit, that a sweep
    /// over every bin keeps: on bins mostly empty, mostly full, with equal boxes (ties) and
    /// with one or no filled bin.
    #[test]
    fn filled_bins_give_the_plane_of_every_bin() {
        let mut rng = Pcg32::new(9, 3);
        let mut compared = 0;
        for case in 0..20_000 {
            let mut counts = [0u32; BINS];
            let mut boxes = [Bounds::EMPTY; BINS];
            let fill = [0.05, 0.2, 0.5, 1.0][case % 4];
            for k in 0..BINS {
                if rng.next_f32() < fill {
                    counts[k] = 1 + rng.next_u32() % 5;
                    let lo = Vec3A::new(k as f32, rng.next_f32(), rng.next_f32());
                    let size = Vec3A::new(rng.next_f32(), 1.0, rng.next_f32());
                    boxes[k] = Bounds {
                        min: lo,
                        max: lo + size,
                    };
                    // Every fifth case's boxes are one box, so that every plane ties.
                    if case % 5 == 0 {
                        boxes[k] = Bounds {
                            min: Vec3A::ZERO,
                            max: Vec3A::ONE,
                        };
                        counts[k] = 1;
                    }
                }
            }
            let key = |s: Option<Split>| s.map(|s| (s.axis, s.bin, s.cost.to_bits()));
            let (new, old) = (
                key(Builder::<false>::cheapest_plane(&counts, &boxes, 1)),
                key(every_bin_cheapest_plane(&counts, &boxes, 1)),
            );
            assert_eq!(new, old, "{counts:?}");
            compared += new.is_some() as u32;
        }
        assert!(compared > 15_000);
    }

    /// [`Bounds`] gives [`Aabb`]'s bits for every operation the builder uses, on finite
    /// boxes from tiny to huge, points, and the empty box.
    #[test]
    fn bounds_arithmetic_is_aabbs_to_the_bit() {
        let mut rng = Pcg32::new(5, 17);
        let point = |rng: &mut Pcg32| {
            let scale = [1e-30f32, 1e-3, 1.0, 1e4, 1e30][rng.next_u32() as usize % 5];
            Vec3::new(
                (rng.next_f32() - 0.5) * scale,
                (rng.next_f32() - 0.5) * scale,
                (rng.next_f32() - 0.5) * scale,
            )
        };
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        let same = |a: &Aabb, b: Bounds| {
            bits(a.min) == bits(b.min.into()) && bits(a.max) == bits(b.max.into())
        };
        for _ in 0..20_000 {
            let ta = [point(&mut rng), point(&mut rng), point(&mut rng)];
            let tb = [point(&mut rng), point(&mut rng), point(&mut rng)];
            let (a, b) = (Aabb::from_triangle(&ta), Aabb::from_triangle(&tb));
            let (ba, bb) = (Bounds::of(&a), Bounds::of(&b));
            for (x, y) in [
                (a, b),
                (a, Aabb::EMPTY),
                (Aabb::EMPTY, b),
                (Aabb::EMPTY, Aabb::EMPTY),
            ] {
                let (bx, by) = (Bounds::of(&x), Bounds::of(&y));
                assert!(same(&x.union(&y), bx.union(by)));
                assert_eq!(
                    x.union(&y).half_area().to_bits(),
                    bx.union(by).half_area().to_bits()
                );
            }
            assert!(same(&a, ba) && same(&ba.to_aabb(), ba));
            assert_eq!(bits(a.center()), bits(ba.center().into()));
            let (mut grown, mut bgrown) = (a, ba);
            grown.grow(b.center());
            bgrown.grow(bb.center());
            assert!(same(&grown, bgrown));
        }
    }

    /// [`bin_of`] clamps before its cast; every input gets the bin of the saturating cast's
    /// definition, so the trees are the same: bin edges and the values just beside them, the
    /// extremes, NaN, infinities and random coordinates at every scale.
    #[test]
    fn bins_are_those_of_the_saturating_cast() {
        let reference = |x: f32, min: f32, scale: f32| (((x - min) * scale) as usize).min(BINS - 1);
        let mut rng = Pcg32::new(9, 3);
        let mut cases = Vec::new();
        for k in 0..=BINS + 1 {
            let edge = k as f32 / BINS as f32;
            for x in [edge, edge.next_up(), edge.next_down()] {
                cases.push((x, 0.0, BINS as f32));
            }
        }
        for x in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            -0.0,
            0.0,
        ] {
            cases.push((x, 0.0, BINS as f32));
            cases.push((1.0, x, BINS as f32));
            cases.push((1.0, 0.0, x));
        }
        for _ in 0..100_000 {
            let scale = [1e-30f32, 1e-3, 1.0, 1e4, 1e30][rng.next_u32() as usize % 5];
            let min = (rng.next_f32() - 0.5) * scale;
            let extent = rng.next_f32() * scale;
            let x = min + (rng.next_f32() * 1.2 - 0.1) * extent;
            cases.push((x, min, BINS as f32 / extent));
        }
        for (x, min, scale) in cases {
            assert_eq!(
                bin_of(x, min, scale),
                reference(x, min, scale),
                "{x} {min} {scale}"
            );
        }
    }
}
