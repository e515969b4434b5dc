//! Clusters: runs of consecutive triangles that the BVH builder handles as one item.
//!
//! A scanned or tessellated mesh lists its triangles strip by strip, so consecutive triangles
//! usually share corners. Building over runs of [`CLUSTER`] of them instead of single
//! triangles leaves the builder a quarter of the items at every level, and on meshes of
//! millions of triangles the build is the larger part of preparing a render. The price is in
//! the tree: a cluster stays whole in one leaf, so leaves hold up to four triangles where the
//! SAH alone would often have split them.

use rayon::prelude::*;

use super::aabb::in_strips;
use super::build::{Bounds, MAX_LEAF};
use super::node::BvhNode;
use crate::memory::{self, OutOfMemory};

/// Scenes of at least this many triangles are built over clusters of up to [`CLUSTER`]. On a
/// 7.8 M-triangle sphere that took the render's preparation from 1.9 to 1.0 s (the whole
/// render from 5.9 to 4.9 s); from a quarter of a million triangles on, every render measured
/// was faster over clusters (2–13% in total). On the 101,920-triangle bench scene, built that
/// way for the comparison, the build was 3.1× cheaper but random shadow rays from its surface
/// cost 12% more and closest hits 9%; near 130,000 triangles one render of three (a bumped
/// sphere over a floor of 20,000 triangles, 65 rays per pixel) was 6% slower over clusters.
/// Tried: a rule weighing the render's rays against the triangles; it turned clusters off
/// where they were faster (BENCHMARKS.md, "Large meshes").
pub const CLUSTERED_FROM: usize = 1 << 18;
/// Most triangles in a cluster (see [`CLUSTERED_FROM`]). Two were slower for rays than four on
/// the bench scene, and did less for the build.
pub const CLUSTER: usize = 4;
const _: () = assert!(CLUSTER as u32 <= MAX_LEAF, "a cluster fits in one leaf");
/// The box diagonals of a cluster's triangles lie within this factor of each other, so that
/// one large triangle does not spread its box over small ones.
const CLUSTER_SIZE_RATIO: f32 = 4.0;
/// Clusters are formed in runs of this many triangles on every thread; a run's end ends a
/// cluster, so the clusters are the same for any number of threads.
const CLUSTER_CHUNK: usize = 1 << 14;

/// How many triangles a cluster of a scene of `triangles` holds at most: [`CLUSTER`] from
/// [`CLUSTERED_FROM`] on, else 1.
pub(super) fn cluster_size(triangles: usize) -> usize {
    if triangles >= CLUSTERED_FROM {
        CLUSTER
    } else {
        1
    }
}

/// Runs of consecutive triangles of the leaf order built as one item each.
///
/// ```text
/// order:  [ 0 1 2 3 | 4 5 | 6 | 7 8 9 10 | ... ]   (input indices of the finite triangles)
/// first:  [ 0       , 4   , 6 , 7        , ... ]   (where each cluster starts in `order`)
/// size:   [ 4       , 2   , 1 , 4        , ... ]
/// boxes:  [ the union of each cluster's triangles' boxes ]
/// ```
pub(super) struct Clusters {
    first: Vec<u32>,
    pub(super) size: Vec<u8>,
    pub(super) boxes: Vec<Bounds>,
}

impl Clusters {
    /// Cuts `order` into clusters of up to `most` consecutive triangles: a triangle joins the
    /// cluster before it when its box touches the cluster's box and every box diagonal in the
    /// cluster stays within [`CLUSTER_SIZE_RATIO`] of every other. Triangles of one strip of a
    /// mesh share corners, so their boxes touch; a mesh in random order, or a jump from one
    /// object to the next, gives clusters of one.
    pub(super) fn of(
        order: &[u32],
        boxes: &[Bounds],
        most: usize,
    ) -> Result<Clusters, OutOfMemory> {
        let runs: Vec<Vec<(u32, u8, Bounds)>> = order
            .par_chunks(CLUSTER_CHUNK)
            .enumerate()
            .map(|(chunk, run)| {
                let start = chunk * CLUSTER_CHUNK;
                let mut out = Vec::with_capacity(run.len() / most + 1);
                let mut j = 0;
                while j < run.len() {
                    let mut b = boxes[run[j] as usize];
                    let d = b.diagonal();
                    let (mut small, mut large) = (d, d);
                    let mut n = 1;
                    while n < most && j + n < run.len() {
                        let next = boxes[run[j + n] as usize];
                        let d = next.diagonal();
                        let (s, l) = (small.min(d), large.max(d));
                        if !b.touches(next) || l > CLUSTER_SIZE_RATIO * s {
                            break;
                        }
                        (small, large) = (s, l);
                        b = b.union(next);
                        n += 1;
                    }
                    out.push(((start + j) as u32, n as u8, b));
                    j += n;
                }
                out
            })
            .collect();
        let len = runs.iter().map(Vec::len).sum();
        let mut clusters = Clusters {
            first: memory::with_capacity(len, memory::TRIANGLES)?,
            size: memory::with_capacity(len, memory::TRIANGLES)?,
            boxes: memory::with_capacity(len, memory::TRIANGLES)?,
        };
        for (first, size, b) in runs.into_iter().flatten() {
            clusters.first.push(first);
            clusters.size.push(size);
            clusters.boxes.push(b);
        }
        Ok(clusters)
    }

    /// True when the triangles of `order` come in strips ([`in_strips`]), which cluster. A
    /// mesh in no particular order does not (on a shuffled 2 M-triangle sphere, building its
    /// clusters of one cost 0.07–0.08 s more than the plain build; this test costs a few
    /// milliseconds).
    pub(super) fn worthwhile(order: &[u32], boxes: &[Bounds]) -> bool {
        in_strips(order, |&a, &b| boxes[a as usize].touches(boxes[b as usize]))
    }

    pub(super) fn len(&self) -> usize {
        self.first.len()
    }

    /// The triangles' leaf order from the clusters' (`items`, as the builder left them), and
    /// every leaf of `nodes` moved from cluster slots to triangle slots.
    pub(super) fn expand(
        &self,
        items: &[u32],
        order: &[u32],
        nodes: &mut [BvhNode],
    ) -> Result<Vec<u32>, OutOfMemory> {
        // starts[k]: the triangle slot of cluster slot k; one more entry for the end.
        let mut starts = memory::with_capacity(items.len() + 1, memory::TRIANGLES)?;
        let mut triangles = memory::with_capacity(order.len(), memory::TRIANGLES)?;
        for &c in items {
            starts.push(triangles.len() as u32);
            let first = self.first[c as usize] as usize;
            triangles.extend_from_slice(&order[first..first + self.size[c as usize] as usize]);
        }
        starts.push(triangles.len() as u32);
        nodes.par_iter_mut().filter(|n| n.is_leaf()).for_each(|n| {
            let (a, b) = (
                starts[n.first as usize],
                starts[(n.first + n.count) as usize],
            );
            n.first = a;
            n.count = b - a;
        });
        Ok(triangles)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::aabb::Aabb;
    use super::super::shapes::{grid, icosphere};
    use super::*;
    use crate::sampling::rng::Pcg32;

    fn boxes(tris: &[[Vec3; 3]]) -> Vec<Bounds> {
        tris.iter()
            .map(|t| Bounds::of(&Aabb::from_triangle(t)))
            .collect()
    }

    /// Checks the clusters of `order` against the rule of [`Clusters::of`]: consecutive runs
    /// covering `order` once, each of at most `most`, every triangle touching the box of the
    /// ones before it in its run, diagonals within [`CLUSTER_SIZE_RATIO`], the box their
    /// union; and each run as long as the rule allows (a run ends at `most`, at a chunk's end,
    /// or before a triangle the rule turns away). Returns the number of clusters.
    fn check(order: &[u32], boxes: &[Bounds], most: usize) -> usize {
        let clusters = Clusters::of(order, boxes, most).unwrap();
        let mut next = 0;
        for c in 0..clusters.len() {
            let (first, size) = (clusters.first[c] as usize, clusters.size[c] as usize);
            assert_eq!(first, next, "cluster {c} does not follow the one before");
            assert!((1..=most).contains(&size), "cluster {c} holds {size}");
            let run = &order[first..first + size];
            let (mut union, mut small, mut large) = (Bounds::EMPTY, f32::MAX, 0.0f32);
            for (k, &i) in run.iter().enumerate() {
                let b = boxes[i as usize];
                assert!(k == 0 || union.touches(b), "cluster {c}: a triangle apart");
                assert!(
                    k == 0 || first / CLUSTER_CHUNK == (first + k) / CLUSTER_CHUNK,
                    "cluster {c} spans two chunks"
                );
                union = union.union(b);
                (small, large) = (small.min(b.diagonal()), large.max(b.diagonal()));
            }
            assert!(
                large <= CLUSTER_SIZE_RATIO * small,
                "cluster {c}: sizes apart"
            );
            let bits = |b: Bounds| (b.min.to_array(), b.max.to_array());
            assert_eq!(bits(clusters.boxes[c]), bits(union), "cluster {c}'s box");
            let end = first + size;
            if size < most && end < order.len() && end % CLUSTER_CHUNK != 0 {
                let b = boxes[order[end] as usize];
                let d = b.diagonal();
                let fits = union.touches(b) && large.max(d) <= CLUSTER_SIZE_RATIO * small.min(d);
                assert!(!fits, "cluster {c} stops before a triangle that fits");
            }
            next = end;
        }
        assert_eq!(next, order.len(), "the clusters cover the order");
        clusters.len()
    }

    #[test]
    fn clusters_are_runs_of_touching_triangles_of_one_size() {
        // A grid and a sphere, listed strip by strip, cluster almost fully; the same triangles
        // shuffled hardly cluster at all; a row of touching triangles each 1.8 times the last
        // clusters in threes (1.8³ > 4); and a grid long enough to cross a chunk's end, whose
        // rows of 398 triangles put a run of four across it.
        let mut rng = Pcg32::new(4, 7);
        let plate = grid(Vec3::ZERO, Vec3::X, Vec3::Y, 40, 40);
        let mut shuffled = plate.clone();
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, rng.next_below(i as u32 + 1) as usize);
        }
        let growing: Vec<[Vec3; 3]> = (0..30)
            .map(|i| {
                let s = 1.8f32.powi(i);
                let o = Vec3::new(1.8f32.powi(i) - 1.0, 0.0, 0.0);
                [o, o + Vec3::new(s, 0.0, 0.0), o + Vec3::new(0.0, s, 0.0)]
            })
            .collect();
        let long = grid(Vec3::ZERO, Vec3::X, Vec3::Y, 199, 50);
        assert!(long.len() > CLUSTER_CHUNK);
        for (name, tris, share) in [
            ("grid", plate.clone(), 0.25..0.26),
            ("sphere", icosphere(4, Vec3::ZERO, 1.0), 0.25..0.3),
            ("shuffled grid", shuffled, 0.9..1.0),
            ("growing", growing, 0.33..0.34),
            ("long grid", long, 0.25..0.26),
        ] {
            let order: Vec<u32> = (0..tris.len() as u32).collect();
            let b = boxes(&tris);
            assert_eq!(check(&order, &b, 1), tris.len(), "{name}: one each");
            let n = check(&order, &b, CLUSTER);
            assert!(
                share.contains(&(n as f64 / tris.len() as f64)),
                "{name}: {n} clusters of {}",
                tris.len()
            );
        }
        // The order may skip triangles (the builder leaves non-finite ones out).
        let order: Vec<u32> = (0..plate.len() as u32).filter(|i| i % 5 != 3).collect();
        check(&order, &boxes(&plate), CLUSTER);
    }

    #[test]
    fn only_meshes_in_strip_order_are_worth_clustering() {
        let plate = grid(Vec3::ZERO, Vec3::X, Vec3::Y, 40, 40);
        let order: Vec<u32> = (0..plate.len() as u32).collect();
        assert!(Clusters::worthwhile(&order, &boxes(&plate)));
        // Every second triangle apart from the one before it: half touch, still worth it;
        // every one apart: not.
        let apart = |every: usize| -> Vec<[Vec3; 3]> {
            let mut x = 0.0;
            (0..1000)
                .map(|i| {
                    x += if i % every == 0 { 10.0 } else { 0.5 };
                    let o = Vec3::new(x, 0.0, 0.0);
                    [o, o + Vec3::X, o + Vec3::Y]
                })
                .collect()
        };
        let order: Vec<u32> = (0..1000).collect();
        assert!(Clusters::worthwhile(&order, &boxes(&apart(2))));
        assert!(!Clusters::worthwhile(&order, &boxes(&apart(1))));
    }

    #[test]
    fn expanding_moves_leaves_to_triangle_slots() {
        // Three clusters of 2, 1 and 3 triangles, built into the order 2, 0, 1; a leaf over
        // cluster slots 0..2 and one over slot 2.
        let order = [10, 11, 12, 13, 14, 15];
        let clusters = Clusters {
            first: vec![0, 2, 3],
            size: vec![2, 1, 3],
            boxes: vec![Bounds::EMPTY; 3],
        };
        let mut nodes = [
            BvhNode::new(&Aabb::EMPTY, 1, 0),
            BvhNode::new(&Aabb::EMPTY, 0, 2),
            BvhNode::new(&Aabb::EMPTY, 2, 1),
        ];
        let triangles = clusters.expand(&[2, 0, 1], &order, &mut nodes).unwrap();
        assert_eq!(triangles, [13, 14, 15, 10, 11, 12]);
        assert_eq!(
            (nodes[0].first, nodes[0].count),
            (1, 0),
            "interior nodes stay"
        );
        assert_eq!((nodes[1].first, nodes[1].count), (0, 5));
        assert_eq!((nodes[2].first, nodes[2].count), (5, 1));
    }

    #[test]
    fn only_scenes_of_at_least_clustered_from_triangles_are_clustered() {
        assert_eq!(cluster_size(0), 1);
        assert_eq!(cluster_size(CLUSTERED_FROM - 1), 1);
        assert_eq!(cluster_size(CLUSTERED_FROM), CLUSTER);
    }
}
