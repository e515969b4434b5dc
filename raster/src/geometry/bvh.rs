//! The bounding volume hierarchy over world-space triangles, and its two queries: any hit
//! (shadow rays) and closest hit.
//!
//! Layout: the binary tree the builder makes (a flat array of 32-byte [`BvhNode`]s) collapsed
//! to a 4-wide one, a flat array of 128-byte [`WideNode`]s (each holding its up-to-four
//! children's boxes), which the queries traverse; and the triangles copied into leaf order so
//! a leaf's triangles are contiguous. The binary tree is freed once collapsed, since no query
//! reads it (32 bytes a node, 30–37 bytes a triangle).
//!
//! ```text
//! wide:       [ root: LL LR RL RR | LL: ... | ... ]           (WideNode, 128 bytes each)
//! triangles:  [ tri  | tri | tri | ... ]                     ([Vec3; 3] in leaf order)
//! ids:        [ 17   | 3   | 254 | ... ]                     (input index of each slot)
//! ```
//!
//! Traversal is depth-first over the wide tree with a fixed stack (the builder bounds the
//! depth); each visit tests a node's four boxes at once and a leaf's triangles as soon as its
//! box is hit. Closest-hit visits the nearer children first and skips subtrees entered beyond
//! the best hit so far. Box tests are conservative (see [`RayLanes::slab_test`]) and the
//! triangle test is watertight (see [`Ray`]), so a closed mesh has no cracks for rays to slip
//! through.

use std::fmt;

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::aabb::{Aabb, RayLanes};
use super::build::{self, MAX_DEPTH, MAX_LEAF, MAX_TRIANGLES, SMALL_STACK, WIDE_STACK};
use super::node::{BvhNode, WideNode};
use super::ray::{Hit, Ray};
use crate::memory::{self, OutOfMemory};

/// Box tests accept boxes entered up to this factor beyond the query's limit (`t_max`, or the
/// best hit so far). The slab test is conservative for the exact ray, but the triangle test's
/// distance is rounded and can lie a little *below* the exact one: a triangle reported at
/// `t < t_max`, or at exactly the best `t` (a tie the lower input index must win), could sit in
/// a box whose computed entry is just above that limit. Found by the fuzz target
/// `shadow_rays_match_brute_force` (`crash-tie-on-cube-edge-box-pruned`: a ray through a
/// cube's edge hit the two faces at the same t = 0.72222215, while the entry of the other
/// face's flat box rounded to 0.72222222, so the higher index won). The triangle tests keep the
/// exact limit. 2⁻¹² is far above the few ulps of that case; the triangle test's relative error
/// is not bounded in general (grazing rays), so this makes a disagreement rare, not impossible.
const BOX_T_SLACK: f32 = 1.0 + 1.0 / 4096.0;

/// A BVH over triangles, for shadow rays and closest-hit queries.
///
/// ```
/// use glam::Vec3;
/// use lucent_raster::geometry::Bvh;
///
/// let floor = [[Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)]];
/// let bvh = Bvh::build(&floor);
/// assert!(bvh.occluded(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0), 2.0));
/// let hit = bvh.intersect(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -1.0), 2.0).unwrap();
/// assert_eq!((hit.t, hit.triangle), (1.0, 0));
/// ```
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// The bounds of every triangle ([`Aabb::EMPTY`] when empty).
    pub(super) bounds: Aabb,
    /// The 4-wide tree's nodes, root first (empty for an empty BVH).
    pub(super) wide: Vec<WideNode>,
    /// The most entries the traversal stack can hold on `wide` (see `build::stack_need`):
    /// queries use a [`SMALL_STACK`]-entry stack when it fits, else a [`WIDE_STACK`] one.
    pub(super) stack_need: u32,
    /// The triangles in leaf order.
    pub(super) triangles: Vec<[Vec3; 3]>,
    /// The input index of each slot of `triangles`.
    pub(super) ids: Vec<u32>,
    /// Input triangles left out because a coordinate is not finite, ascending.
    pub(super) skipped: Vec<u32>,
    /// How many input triangles were looked at.
    pub(super) source_len: u32,
}

/// Which triangle blocked the previous shadow ray, for [`Bvh::occluded_hinted`]. Small and
/// `Copy`: keep one per light in each thread's loop over pixels. The default names no
/// triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowHint {
    /// Leaf-order slot of the last occluder found, `u32::MAX` for none.
    pub(super) slot: u32,
}

impl ShadowHint {
    /// The hint that names no triangle.
    pub const NONE: ShadowHint = ShadowHint { slot: u32::MAX };

    /// The leaf-order slot of the last occluder found, if any.
    pub fn slot(&self) -> Option<u32> {
        (self.slot != u32::MAX).then_some(self.slot)
    }
}

impl Default for ShadowHint {
    fn default() -> Self {
        ShadowHint::NONE
    }
}

/// A broken invariant found by [`Bvh::validate`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InvariantError {
    /// What is wrong, naming the node or slot.
    pub message: String,
}

impl fmt::Display for InvariantError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "BVH invariant broken: {}", self.message)
    }
}

impl std::error::Error for InvariantError {}

/// `Err(InvariantError)` with a formatted message unless `cond` holds.
macro_rules! ensure {
    ($cond:expr, $($msg:tt)+) => {
        if !$cond {
            return Err(InvariantError { message: format!($($msg)+) });
        }
    };
}

impl Bvh {
    /// Builds the BVH (binned SAH; see the `build` module). Triangles with a non-finite
    /// coordinate are left out (see [`Bvh::skipped`]); zero-area ones are kept and never hit.
    /// Deterministic, O(N log N). Only the first 2³¹ triangles are used.
    ///
    /// Panics if memory runs out; [`Bvh::try_build`] reports that instead.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        Self::try_build(triangles).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`Bvh::build`], or [`OutOfMemory`] if the allocator refuses one of its buffers.
    ///
    /// From [`CLUSTERED_FROM`](super::CLUSTERED_FROM) triangles on, the tree is built over
    /// clusters of up to [`CLUSTER`](super::CLUSTER) consecutive triangles (see
    /// [`Bvh::try_build_clustered`]).
    pub fn try_build(triangles: &[[Vec3; 3]]) -> Result<Bvh, OutOfMemory> {
        let cluster = super::cluster::cluster_size(triangles.len().min(MAX_TRIANGLES));
        Self::try_build_with(triangles, build::BINNED, cluster)
    }

    /// [`Bvh::try_build`] over clusters of up to `cluster` consecutive triangles whose boxes
    /// touch, whatever the number of triangles (1: every triangle on its own; more than a
    /// leaf's eight is taken as eight). Clusters make the build about three times cheaper and
    /// rays 9–12% dearer: worth it where the triangles far outnumber the rays the tree will
    /// answer. Queries give the same answers either way. Triangles in no particular order
    /// (fewer than half touching the one before) are built one by one all the same.
    pub fn try_build_clustered(
        triangles: &[[Vec3; 3]],
        cluster: usize,
    ) -> Result<Bvh, OutOfMemory> {
        Self::try_build_with(triangles, build::BINNED, cluster)
    }

    /// [`Bvh::try_build_clustered`], a node's planes priced from about `binned` of its items
    /// (tests set it low, so that small inputs take the sampled path too).
    pub(super) fn try_build_with(
        triangles: &[[Vec3; 3]],
        binned: usize,
        cluster: usize,
    ) -> Result<Bvh, OutOfMemory> {
        let build::Built {
            nodes,
            order,
            skipped,
        } = build::build_with(triangles, build::PARALLEL_MIN, binned, cluster)?;
        // The binary tree is collapsed and freed before the triangles are copied, so that the
        // two are never held at once (this is where the preparation's memory peaks).
        let wide = build::collapse(&nodes)?;
        let bounds = nodes.first().map_or(Aabb::EMPTY, BvhNode::bounds);
        drop(nodes);
        let tris = memory::par_collect(
            order.par_iter().map(|&i| triangles[i as usize]),
            memory::TRIANGLES,
        )?;
        Ok(Bvh {
            stack_need: build::stack_need(&wide) as u32,
            wide,
            bounds,
            triangles: tris,
            ids: order,
            skipped,
            source_len: triangles.len().min(MAX_TRIANGLES) as u32,
        })
    }

    /// Number of triangles in the BVH (input triangles less the skipped ones).
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True if the BVH holds no triangle (every query misses).
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Indices of input triangles left out because a coordinate is not finite, ascending.
    pub fn skipped(&self) -> &[u32] {
        &self.skipped
    }

    /// The input index of the triangle in leaf-order `slot` (as a [`ShadowHint`] names it),
    /// `None` for a slot past the end.
    pub fn triangle_index(&self, slot: u32) -> Option<u32> {
        self.ids.get(slot as usize).copied()
    }

    /// The 4-wide tree's node array (root first) that the queries traverse.
    pub fn wide_nodes(&self) -> &[WideNode] {
        &self.wide
    }

    /// Bounds of every triangle ([`Aabb::EMPTY`] when empty).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The scene scale to pass to [`offset_origin`](super::offset_origin): the largest absolute
    /// coordinate of the bounds (0 when empty).
    pub fn scale(&self) -> f32 {
        let b = self.bounds();
        if b.is_empty() {
            0.0
        } else {
            b.min.abs().max(b.max.abs()).max_element()
        }
    }

    /// True if the segment `origin + t·dir`, `t ∈ (0, t_max)`, hits any triangle. Stops at the
    /// first hit found. A non-finite origin or direction, a zero direction, or `t_max ≤ 0` (or
    /// NaN) is never occluded; `t_max = ∞` asks about the whole ray.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let mut throwaway = ShadowHint::NONE;
        self.occluded_hinted(origin, dir, t_max, &mut throwaway)
    }

    /// [`Bvh::occluded`], trying the triangle in `hint` first and recording in it the occluder
    /// found. The answer is always exactly that of `occluded` (any triangle hit in
    /// `(0, t_max)` means occluded, so which one is tested first cannot change it); only the
    /// time differs. Neighbouring shadow rays towards the same light are mostly blocked by the
    /// same triangle, so a renderer that keeps one hint per light (and per thread) while it
    /// walks the pixels in order answers most blocked rays with one triangle test instead of a
    /// traversal. A miss leaves the hint as it is. A hint from another BVH is harmless: it
    /// names a triangle of this one or none.
    ///
    /// ```
    /// use glam::Vec3;
    /// use lucent_raster::geometry::{Bvh, ShadowHint};
    ///
    /// let floor = [[Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)]];
    /// let bvh = Bvh::build(&floor);
    /// let mut hint = ShadowHint::default();
    /// for x in [-0.2, -0.1, 0.0, 0.1] {
    ///     let origin = Vec3::new(x, 0.0, 1.0);
    ///     assert!(bvh.occluded_hinted(origin, -Vec3::Z, 2.0, &mut hint));
    /// }
    /// assert_eq!(hint.slot(), Some(0));
    /// ```
    pub fn occluded_hinted(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        hint: &mut ShadowHint,
    ) -> bool {
        let Some(ray) = Ray::new(origin, dir) else {
            return false;
        };
        if t_max.is_nan() || t_max <= 0.0 || self.wide.is_empty() {
            return false;
        }
        if let Some(tri) = self.triangles.get(hint.slot as usize)
            && ray.intersect_triangle(tri, t_max).is_some()
        {
            return true;
        }
        let hit = if self.stack_need as usize <= SMALL_STACK {
            self.any_hit::<SMALL_STACK>(&ray, t_max)
        } else {
            self.any_hit::<WIDE_STACK>(&ray, t_max)
        };
        match hit {
            Some(slot) => {
                hint.slot = slot;
                true
            }
            None => false,
        }
    }

    /// The slot of some triangle hit in `(0, t_max)`, if any: depth-first over the wide tree,
    /// testing a leaf as soon as its box is hit, stopping at the first hit. `N ≥ stack_need`.
    pub(super) fn any_hit<const N: usize>(&self, ray: &Ray, t_max: f32) -> Option<u32> {
        let lanes = RayLanes::new(ray.origin_a, ray.inv_dir);
        let limit = Vec4::splat(t_max * BOX_T_SLACK);
        let mut stack = [0u32; N];
        let mut sp = 0;
        let mut index = 0u32;
        loop {
            let node = &self.wide[index as usize];
            let (mut mask, _) = lanes.slab_test(node, limit);
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let (child, count) = (node.child[lane], node.count[lane] as u32);
                if count == 0 {
                    stack[sp] = child;
                    sp += 1;
                    continue;
                }
                for slot in child..child + count {
                    if ray
                        .intersect_triangle(&self.triangles[slot as usize], t_max)
                        .is_some()
                    {
                        return Some(slot);
                    }
                }
            }
            if sp == 0 {
                return None;
            }
            sp -= 1;
            index = stack[sp];
        }
    }

    /// The closest hit of the ray `origin + t·dir` with `t ∈ (0, t_max)`, if any. When two
    /// triangles are hit at exactly the same `t` (a shared edge), the lower input index wins,
    /// so the answer does not depend on the tree's shape. Invalid rays (as for
    /// [`Bvh::occluded`]) hit nothing.
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let ray = Ray::new(origin, dir)?;
        if t_max.is_nan() || t_max <= 0.0 || self.wide.is_empty() {
            return None;
        }
        if self.stack_need as usize <= SMALL_STACK {
            self.closest_hit::<SMALL_STACK>(&ray, t_max)
        } else {
            self.closest_hit::<WIDE_STACK>(&ray, t_max)
        }
    }

    /// The closest hit for [`Bvh::intersect`] (a valid ray and range, a non-empty tree).
    /// `N ≥ stack_need`.
    pub(super) fn closest_hit<const N: usize>(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let lanes = RayLanes::new(ray.origin_a, ray.inv_dir);
        let mut best: Option<Hit> = None;
        let mut best_t = t_max;
        let mut stack = [(0u32, 0.0f32); N];
        let mut sp = 0;
        let mut index = 0u32;
        loop {
            let node = &self.wide[index as usize];
            let box_t = best_t * BOX_T_SLACK;
            let (mut mask, near) = lanes.slab_test(node, Vec4::splat(box_t));
            let near = near.to_array();
            // The lanes hit, nearest first (at most four: insertion sort).
            let mut order = [0usize; 4];
            let mut n = 0;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let mut k = n;
                while k > 0 && near[order[k - 1]] > near[lane] {
                    order[k] = order[k - 1];
                    k -= 1;
                }
                order[k] = lane;
                n += 1;
            }
            // Leaves are tested now, nearest first; interior children are pushed farthest
            // first, so the nearest is popped next.
            for &lane in order[..n].iter().rev() {
                if node.count[lane] == 0 {
                    stack[sp] = (node.child[lane], near[lane]);
                    sp += 1;
                }
            }
            for &lane in &order[..n] {
                let count = node.count[lane] as usize;
                if count == 0 || near[lane] > box_t {
                    continue;
                }
                // Equal t must still be considered for the tie-break, so the limit is the next
                // float above the best t once there is one.
                let limit = if best.is_some() {
                    best_t.next_up()
                } else {
                    t_max
                };
                let first = node.child[lane] as usize;
                for (k, tri) in self.triangles[first..first + count].iter().enumerate() {
                    if let Some((t, u, v)) = ray.intersect_triangle(tri, limit) {
                        let id = self.ids[first + k];
                        if best.is_none_or(|b| t < b.t || (t == b.t && id < b.triangle)) {
                            best = Some(Hit {
                                t,
                                triangle: id,
                                u,
                                v,
                            });
                            best_t = t;
                        }
                    }
                }
            }
            // Pop the next subtree that may still hold a hit no farther than the best one.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let (next, entry) = stack[sp];
                if entry <= best_t * BOX_T_SLACK {
                    index = next;
                    break;
                }
            }
        }
    }

    /// Checks every structural invariant: the triangles and their input indices (every finite
    /// input triangle referenced exactly once, every other one listed in [`Bvh::skipped`]),
    /// then the wide tree's (see [`WideNode`]): rooted at 0, children after their parent,
    /// every node reachable once and shallower than `MAX_DEPTH` (so the traversal stack of
    /// `3·MAX_DEPTH + 1` entries suffices) and the recorded stack need right; used lanes first,
    /// unused lanes zero; every lane box finite and inside its parent lane's box, a leaf lane's
    /// box containing its triangles' boxes; leaves of 1 to `MAX_LEAF` triangles that together
    /// cover every slot exactly once; and [`Bvh::bounds`] the union of the root's lanes.
    pub fn validate(&self) -> Result<(), InvariantError> {
        let n_tris = self.triangles.len();
        ensure!(
            self.ids.len() == n_tris,
            "{} slot ids for {} triangles",
            self.ids.len(),
            n_tris
        );
        ensure!(
            self.wide.is_empty() == (n_tris == 0),
            "{} wide nodes for {} triangles",
            self.wide.len(),
            n_tris
        );
        // Every input triangle: referenced once, or skipped.
        let mut seen = vec![false; self.source_len as usize];
        for (slot, &id) in self.ids.iter().enumerate() {
            ensure!(
                id < self.source_len,
                "slot {slot} refers to triangle {id} of {}",
                self.source_len
            );
            ensure!(
                !seen[id as usize],
                "triangle {id} referenced twice (slot {slot})"
            );
            seen[id as usize] = true;
            ensure!(
                self.triangles[slot].iter().all(|v| v.is_finite()),
                "slot {slot} (triangle {id}) is not finite"
            );
        }
        for (k, &id) in self.skipped.iter().enumerate() {
            ensure!(
                id < self.source_len && !seen[id as usize],
                "skipped triangle {id} is also referenced or out of range"
            );
            ensure!(
                k == 0 || self.skipped[k - 1] < id,
                "skipped list not ascending at {id}"
            );
            seen[id as usize] = true;
        }
        if let Some(id) = seen.iter().position(|&s| !s) {
            return Err(InvariantError {
                message: format!("triangle {id} is neither referenced nor skipped"),
            });
        }
        self.validate_wide()
    }

    /// The wide tree's part of [`Bvh::validate`].
    fn validate_wide(&self) -> Result<(), InvariantError> {
        if self.wide.is_empty() {
            ensure!(
                self.bounds == Aabb::EMPTY,
                "an empty tree with bounds {:?}",
                self.bounds
            );
            return Ok(());
        }
        let n_tris = self.triangles.len();
        let mut visited = vec![false; self.wide.len()];
        let mut covered = vec![false; n_tris];
        let mut stack: Vec<(u32, u32, Option<Aabb>)> = vec![(0, 0, None)];
        while let Some((index, depth, parent)) = stack.pop() {
            ensure!(
                depth < MAX_DEPTH,
                "wide node {index} at depth {depth} exceeds the traversal stack"
            );
            ensure!(!visited[index as usize], "wide node {index} reached twice");
            visited[index as usize] = true;
            let node = &self.wide[index as usize];
            ensure!(
                matches!(node.valid, 0b1 | 0b11 | 0b111 | 0b1111),
                "wide node {index} has lane mask {:#06b}",
                node.valid
            );
            for lane in 0..4 {
                let (child, count) = (node.child[lane], node.count[lane]);
                let bounds = node.lane_bounds(lane);
                if node.valid & (1 << lane) == 0 {
                    ensure!(
                        child == 0
                            && count == 0
                            && bounds.min == Vec3::ZERO
                            && bounds.max == Vec3::ZERO,
                        "wide node {index}: unused lane {lane} is not zero"
                    );
                    continue;
                }
                ensure!(
                    bounds.is_finite() && !bounds.is_empty(),
                    "wide node {index} lane {lane} has bounds {bounds:?}"
                );
                if let Some(p) = parent {
                    ensure!(
                        p.contains(&bounds),
                        "wide node {index} lane {lane} bounds {bounds:?} escape the parent's {p:?}"
                    );
                }
                if count > 0 {
                    let (first, end) = (child as usize, child as usize + count as usize);
                    ensure!(
                        count as u32 <= MAX_LEAF && end <= n_tris,
                        "wide node {index} lane {lane} covers slots {first}..{end} of {n_tris}"
                    );
                    for (slot, tri) in self.triangles.iter().enumerate().take(end).skip(first) {
                        ensure!(!covered[slot], "slot {slot} in two leaves");
                        covered[slot] = true;
                        let tb = Aabb::from_triangle(tri);
                        ensure!(
                            bounds.contains(&tb),
                            "wide node {index} lane {lane} bounds {bounds:?} miss slot {slot} box {tb:?}"
                        );
                    }
                } else {
                    ensure!(
                        child > index && (child as usize) < self.wide.len(),
                        "wide node {index} lane {lane} has child {child}"
                    );
                    stack.push((child, depth + 1, Some(bounds)));
                }
            }
        }
        if let Some(i) = visited.iter().position(|&v| !v) {
            return Err(InvariantError {
                message: format!("wide node {i} is unreachable"),
            });
        }
        let need = build::stack_need(&self.wide);
        ensure!(
            need == self.stack_need as usize && need <= WIDE_STACK,
            "traversal stack need {need} (recorded {}, at most {WIDE_STACK})",
            self.stack_need
        );
        if let Some(slot) = covered.iter().position(|&c| !c) {
            return Err(InvariantError {
                message: format!("slot {slot} is in no leaf"),
            });
        }
        let root = &self.wide[0];
        let union = (0..root.len()).fold(Aabb::EMPTY, |b, lane| b.union(&root.lane_bounds(lane)));
        ensure!(
            union == self.bounds,
            "bounds {:?} are not the root's {union:?}",
            self.bounds
        );
        Ok(())
    }
}
