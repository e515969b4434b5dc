//! The bounding volume hierarchy over world-space triangles, and its two queries: any hit
//! (shadow rays) and closest hit.
//!
//! Layout: a flat array of 32-byte [`BvhNode`]s (root at index 0, siblings adjacent), and the
//! triangles copied into leaf order so a leaf's triangles are contiguous:
//!
//! ```text
//! nodes:      [ root | L | R | LL | LR | RL | RR | ... ]     (BvhNode, 32 bytes each)
//! triangles:  [ tri  | tri | tri | ... ]                     ([Vec3; 3] in leaf order)
//! ids:        [ 17   | 3   | 254 | ... ]                     (input index of each slot)
//! ```
//!
//! Traversal is depth-first with a fixed stack of [`MAX_DEPTH`] entries (the builder bounds the
//! depth); closest-hit visits the nearer child first and skips subtrees entered beyond the best
//! hit so far. Box tests are conservative (see [`slab_test`]) and the triangle test is
//! watertight (see [`Ray`]), so a closed mesh has no cracks for rays to slip through.

use std::fmt;

use glam::{Vec3, Vec3A};

use super::aabb::{Aabb, slab_test};
use super::build::{self, MAX_DEPTH, MAX_LEAF, MAX_TRIANGLES};
use super::node::BvhNode;
use super::ray::{Hit, Ray};

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
    /// The nodes, root first (empty for an empty BVH).
    pub(super) nodes: Vec<BvhNode>,
    /// The triangles in leaf order.
    pub(super) triangles: Vec<[Vec3; 3]>,
    /// The input index of each slot of `triangles`.
    pub(super) ids: Vec<u32>,
    /// Input triangles left out because a coordinate is not finite, ascending.
    pub(super) skipped: Vec<u32>,
    /// How many input triangles were looked at.
    pub(super) source_len: u32,
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
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        let built = build::build(triangles);
        let tris = built.order.iter().map(|&i| triangles[i as usize]).collect();
        Bvh {
            nodes: built.nodes,
            triangles: tris,
            ids: built.order,
            skipped: built.skipped,
            source_len: triangles.len().min(MAX_TRIANGLES) as u32,
        }
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

    /// The node array (root first), for inspection and statistics.
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// Bounds of every triangle ([`Aabb::EMPTY`] when empty).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, BvhNode::bounds)
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
        let Some(ray) = Ray::new(origin, dir) else {
            return false;
        };
        if t_max.is_nan() || t_max <= 0.0 || self.nodes.is_empty() {
            return false;
        }
        let visit = |n: &BvhNode| {
            slab_test(
                Vec3A::from_array(n.min),
                Vec3A::from_array(n.max),
                ray.origin_a,
                ray.inv_dir,
                t_max,
            )
        };
        if visit(&self.nodes[0]).is_none() {
            return false;
        }
        let mut stack = [0u32; MAX_DEPTH as usize];
        let mut sp = 0;
        let mut index = 0u32;
        loop {
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let slots = node.first as usize..(node.first + node.count) as usize;
                for tri in &self.triangles[slots] {
                    if ray.intersect_triangle(tri, t_max).is_some() {
                        return true;
                    }
                }
            } else {
                let left = node.first;
                let hit_l = visit(&self.nodes[left as usize]);
                let hit_r = visit(&self.nodes[left as usize + 1]);
                match (hit_l, hit_r) {
                    (Some(tl), Some(tr)) => {
                        let (near, far) = if tl <= tr {
                            (left, left + 1)
                        } else {
                            (left + 1, left)
                        };
                        stack[sp] = far;
                        sp += 1;
                        index = near;
                        continue;
                    }
                    (Some(_), None) => {
                        index = left;
                        continue;
                    }
                    (None, Some(_)) => {
                        index = left + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                return false;
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
        if t_max.is_nan() || t_max <= 0.0 || self.nodes.is_empty() {
            return None;
        }
        let visit = |n: &BvhNode, limit: f32| {
            slab_test(
                Vec3A::from_array(n.min),
                Vec3A::from_array(n.max),
                ray.origin_a,
                ray.inv_dir,
                limit,
            )
        };
        visit(&self.nodes[0], t_max)?;
        let mut best: Option<Hit> = None;
        let mut best_t = t_max;
        let mut stack = [(0u32, 0.0f32); MAX_DEPTH as usize];
        let mut sp = 0;
        let mut index = 0u32;
        loop {
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                // Equal t must still be considered for the tie-break, so the limit is the next
                // float above the best t once there is one.
                let limit = if best.is_some() {
                    best_t.next_up()
                } else {
                    t_max
                };
                let first = node.first as usize;
                for (k, tri) in self.triangles[first..first + node.count as usize]
                    .iter()
                    .enumerate()
                {
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
            } else {
                let left = node.first;
                let hit_l = visit(&self.nodes[left as usize], best_t);
                let hit_r = visit(&self.nodes[left as usize + 1], best_t);
                match (hit_l, hit_r) {
                    (Some(tl), Some(tr)) => {
                        let ((near, _), far) = if tl <= tr {
                            ((left, tl), (left + 1, tr))
                        } else {
                            ((left + 1, tr), (left, tl))
                        };
                        stack[sp] = far;
                        sp += 1;
                        index = near;
                        continue;
                    }
                    (Some(_), None) => {
                        index = left;
                        continue;
                    }
                    (None, Some(_)) => {
                        index = left + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next subtree that may still hold a hit no farther than the best one.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let (next, entry) = stack[sp];
                if entry <= best_t {
                    index = next;
                    break;
                }
            }
        }
    }

    /// Checks every structural invariant: the node array is a binary tree rooted at 0 with
    /// children stored after their parent, every node reachable exactly once and no deeper than
    /// the traversal stack; every node's bounds are finite and contain its children's bounds or
    /// its triangles' boxes; leaves hold 1 to `MAX_LEAF` triangles and together cover every
    /// slot exactly once; every finite input triangle is referenced exactly once and every
    /// other one is listed in [`Bvh::skipped`].
    pub fn validate(&self) -> Result<(), InvariantError> {
        let n_tris = self.triangles.len();
        ensure!(
            self.ids.len() == n_tris,
            "{} slot ids for {} triangles",
            self.ids.len(),
            n_tris
        );
        ensure!(
            self.nodes.is_empty() == (n_tris == 0),
            "{} nodes for {} triangles",
            self.nodes.len(),
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
        if self.nodes.is_empty() {
            return Ok(());
        }
        // Walk the tree.
        let mut visited = vec![false; self.nodes.len()];
        let mut covered = vec![false; n_tris];
        let mut stack = vec![(0u32, 0u32)];
        while let Some((index, depth)) = stack.pop() {
            ensure!(
                depth < MAX_DEPTH,
                "node {index} at depth {depth} exceeds the traversal stack"
            );
            ensure!(!visited[index as usize], "node {index} reached twice");
            visited[index as usize] = true;
            let node = &self.nodes[index as usize];
            let bounds = node.bounds();
            ensure!(
                bounds.is_finite() && !bounds.is_empty(),
                "node {index} has bounds {bounds:?}"
            );
            if node.is_leaf() {
                ensure!(
                    node.count <= MAX_LEAF,
                    "leaf {index} holds {} triangles",
                    node.count
                );
                let (first, end) = (
                    node.first as usize,
                    node.first as usize + node.count as usize,
                );
                ensure!(
                    end <= n_tris,
                    "leaf {index} covers slots {first}..{end} of {n_tris}"
                );
                for (slot, tri) in self.triangles.iter().enumerate().take(end).skip(first) {
                    ensure!(!covered[slot], "slot {slot} in two leaves");
                    covered[slot] = true;
                    let tb = Aabb::from_triangle(tri);
                    ensure!(
                        bounds.contains(&tb),
                        "leaf {index} bounds {bounds:?} miss slot {slot} box {tb:?}"
                    );
                }
            } else {
                let left = node.first;
                ensure!(
                    left > index && (left as usize + 1) < self.nodes.len(),
                    "interior node {index} has children {left}, {}",
                    left as u64 + 1
                );
                for child in [left, left + 1] {
                    let cb = self.nodes[child as usize].bounds();
                    ensure!(
                        bounds.contains(&cb),
                        "node {index} bounds {bounds:?} do not contain child {child} {cb:?}"
                    );
                    stack.push((child, depth + 1));
                }
            }
        }
        if let Some(i) = visited.iter().position(|&v| !v) {
            return Err(InvariantError {
                message: format!("node {i} is unreachable"),
            });
        }
        if let Some(slot) = covered.iter().position(|&c| !c) {
            return Err(InvariantError {
                message: format!("slot {slot} is in no leaf"),
            });
        }
        Ok(())
    }
}
