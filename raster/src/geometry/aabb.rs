//! Axis-aligned bounding boxes: the bounds stored in BVH nodes, their surface area for the SAH,
//! and the conservative slab test used during traversal.

use glam::{Vec3, Vec3A, Vec4};
use rayon::prelude::*;

use super::node::WideNode;

/// An axis-aligned box `[min, max]`. The empty box has `min = +∞` and `max = −∞`, so that
/// growing it by any point gives that point's box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box (contains nothing; the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The tight box around a triangle (exact: min/max of the vertex coordinates).
    pub fn from_triangle(t: &[Vec3; 3]) -> Aabb {
        Aabb {
            min: t[0].min(t[1]).min(t[2]),
            max: t[0].max(t[1]).max(t[2]),
        }
    }

    /// True if the box contains no point.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// The smallest box containing both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Grows the box to contain `p`.
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The centre (meaningless for the empty box). Halved before adding, so boxes near the
    /// largest `f32` do not overflow.
    pub fn center(&self) -> Vec3 {
        self.min * 0.5 + self.max * 0.5
    }

    /// Half the surface area, `dx·dy + dy·dz + dz·dx` (0 for the empty box). The SAH only
    /// compares ratios of areas, so the factor 2 is left out.
    pub fn half_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.max - self.min;
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    /// True if `other` lies inside `self` (the empty box lies inside every box).
    pub fn contains(&self, other: &Aabb) -> bool {
        other.is_empty() || (self.min.cmple(other.min).all() && other.max.cmple(self.max).all())
    }

    /// True if the two boxes share a point (closed boxes; never for an empty one).
    pub fn touches(&self, other: &Aabb) -> bool {
        other.min.cmple(self.max).all() && self.min.cmple(other.max).all()
    }

    /// True if every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }
}

/// True when at least half of `items` touch the one before them (`touch` says whether two
/// consecutive ones do): the order of a mesh listed strip by strip. The BVH's clusters and the
/// Voronoi areas' patches rely on it; the loader restores it for a large mesh that lacks it
/// (`scene/spatial_order.rs`), and the BVH builds without clusters where it is missing.
pub(crate) fn in_strips<T: Sync>(items: &[T], touch: impl Fn(&T, &T) -> bool + Sync) -> bool {
    let touching = items.par_windows(2).filter(|w| touch(&w[0], &w[1])).count();
    2 * touching >= items.len()
}

/// The smallest and largest coordinates of the triangles' vertices, per axis, in parallel: min
/// and max are exact, so the values are the serial ones for any thread count (a zero may come
/// out as −0 or +0, which the grids built from them, `p − origin` clamped at 0, cannot tell
/// apart; the renderer's scale, a length, neither).
pub(crate) fn vertex_bounds(triangles: &[[Vec3; 3]]) -> (Vec3, Vec3) {
    let empty = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    triangles
        .par_chunks(1 << 14)
        .map(|chunk| {
            chunk
                .iter()
                .flatten()
                .fold(empty, |(lo, hi), &v| (lo.min(v), hi.max(v)))
        })
        .reduce(|| empty, |(a, b), (c, d)| (a.min(c), b.max(d)))
}

/// `1 + 2γ₃` with `γₙ = n·u / (1 − n·u)` and `u = 2⁻²⁴`: the factor by which the far slab
/// distance is enlarged so that rounding in the slab test never rejects a box the ray touches
/// (Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2); also pbrt-v3 §3.9.2).
const ROBUST_FAR: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Direction components smaller than this in magnitude are replaced by ±`TINY_DIR` before
/// taking the reciprocal, so the reciprocal is finite and the slab test never multiplies
/// `0 · ∞`. The slab test treats such an axis as *parallel*: the ray is inside that slab for
/// every `t` when its origin lies in `[min, max]` (boundary included) and for none otherwise,
/// with no arithmetic. (Computing the slab with the replaced component instead moved the ray
/// off a boundary plane it lies in: a ray with `dir.y = 0` in the plane `y = max.y` of a box
/// left it at `t = 0`, and a ray through the shared edge of two axis-aligned triangles saw only
/// one of them. Found by the fuzz target `shadow_rays_match_brute_force`,
/// `crash-axis-parallel-ray-on-box-face`.) For a non-zero component below `TINY_DIR` this
/// ignores the ray's drift along the axis, which matters only at distances `t` beyond
/// `δ / TINY_DIR` for a slab `δ` away.
const TINY_DIR: f32 = 1e-30;

/// `|inv_dir|` from [`safe_inverse`] at or above which an axis is parallel (see [`TINY_DIR`]).
const PARALLEL_INV: f32 = 1.0 / TINY_DIR;

/// The reciprocal direction used by [`RayLanes::slab_test`], finite in every component.
pub(crate) fn safe_inverse(dir: Vec3) -> Vec3A {
    let fix = |d: f32| {
        if d.abs() < TINY_DIR {
            TINY_DIR.copysign(d)
        } else {
            d
        }
    };
    Vec3A::new(1.0 / fix(dir.x), 1.0 / fix(dir.y), 1.0 / fix(dir.z))
}

/// The entry distance of the ray `origin + t·dir` into the box `[min, max]` if the ray overlaps
/// it for some `t ∈ [0, t_max]`, else `None`. Conservative: with `inv_dir` from
/// [`safe_inverse`], a box containing a point the ray passes through is never rejected.
/// SIMD (`Vec3A`): the three slabs are computed at once. The one-box reference for
/// [`RayLanes::slab_test`], which computes the same numbers for four boxes.
#[cfg(test)]
pub(crate) fn slab_test(
    min: Vec3A,
    max: Vec3A,
    origin: Vec3A,
    inv_dir: Vec3A,
    t_max: f32,
) -> Option<f32> {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    let (mut near, mut far) = (t0.min(t1), t0.max(t1));
    for a in 0..3 {
        if inv_dir[a].abs() >= PARALLEL_INV {
            let inside = min[a] <= origin[a] && origin[a] <= max[a];
            near[a] = if inside {
                f32::NEG_INFINITY
            } else {
                f32::INFINITY
            };
            far[a] = f32::INFINITY;
        }
    }
    let near = near.max_element().max(0.0);
    let far = (far.min_element() * ROBUST_FAR).min(t_max);
    (near <= far).then_some(near)
}

/// A ray's origin and finite reciprocal direction splatted across four lanes, for testing the
/// four boxes of a [`WideNode`] at once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayLanes {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    /// Axes the ray is parallel to (see [`TINY_DIR`]).
    parallel: [bool; 3],
}

impl RayLanes {
    /// `inv_dir` must come from [`safe_inverse`].
    pub(crate) fn new(origin: Vec3A, inv_dir: Vec3A) -> RayLanes {
        RayLanes {
            origin: [0, 1, 2].map(|a| Vec4::splat(origin[a])),
            inv_dir: [0, 1, 2].map(|a| Vec4::splat(inv_dir[a])),
            parallel: [0, 1, 2].map(|a| inv_dir[a].abs() >= PARALLEL_INV),
        }
    }

    /// The slab test of `slab_test` on the four lanes of `node`: bit `i` of the mask is set if
    /// lane `i` is used and its box overlaps the ray for some `t ∈ [0, t_max]`, and lane `i`
    /// of the vector is its entry distance. Every lane computes exactly the operations of the
    /// one-box test (subtractions, products, minima and maxima are exact in IEEE arithmetic,
    /// and the distances are never NaN because `inv_dir` is finite and non-zero), so it
    /// accepts exactly the boxes that test accepts: conservative in the same way (Ize 2013).
    #[inline(always)]
    pub(crate) fn slab_test(&self, node: &WideNode, t_max: Vec4) -> (u32, Vec4) {
        let slab = |a: usize| {
            let (lo, hi) = (Vec4::from_array(node.min[a]), Vec4::from_array(node.max[a]));
            if self.parallel[a] {
                // Inside the slab for every t, or for none (see `TINY_DIR`).
                let inside = lo.cmple(self.origin[a]) & self.origin[a].cmple(hi);
                let near = Vec4::select(inside, Vec4::NEG_INFINITY, Vec4::INFINITY);
                return (near, Vec4::INFINITY);
            }
            let t0 = (lo - self.origin[a]) * self.inv_dir[a];
            let t1 = (hi - self.origin[a]) * self.inv_dir[a];
            (t0.min(t1), t0.max(t1))
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let near = nx.max(ny).max(nz).max(Vec4::ZERO);
        let far = (fx.min(fy).min(fz) * ROBUST_FAR).min(t_max);
        (near.cmple(far).bitmask() & node.valid as u32, near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slab test on plain `Vec3`s.
    fn slab(min: Vec3, max: Vec3, o: Vec3, inv: Vec3A, t_max: f32) -> Option<f32> {
        slab_test(min.into(), max.into(), o.into(), inv, t_max)
    }

    #[test]
    fn empty_box_is_union_identity() {
        let b = Aabb::from_triangle(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.half_area(), 0.0);
        assert!(b.contains(&Aabb::EMPTY));
        assert!(!Aabb::EMPTY.contains(&b));
    }

    #[test]
    fn half_area_of_unit_cube_is_three() {
        let b = Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        };
        assert_eq!(b.half_area(), 3.0);
    }

    #[test]
    fn four_lane_slab_test_equals_the_one_box_test() {
        use crate::sampling::rng::Pcg32;
        let mut rng = Pcg32::new(11, 2);
        let mut c = |s: f32| (rng.next_f32() * 2.0 - 1.0) * s;
        let mut accepted = 0;
        for k in 0..20_000 {
            let mut node = WideNode::EMPTY;
            let lanes = 1 + k % 4;
            for lane in 0..lanes {
                let (a, b) = (
                    Vec3::new(c(5.0), c(5.0), c(5.0)),
                    Vec3::new(c(5.0), c(5.0), c(5.0)),
                );
                // Some flat boxes, as around axis-aligned triangles.
                let b = if k % 7 == 0 {
                    Vec3::new(b.x, b.y, a.z)
                } else {
                    b
                };
                node.set_lane(
                    lane,
                    &Aabb {
                        min: a.min(b),
                        max: a.max(b),
                    },
                    0,
                    1,
                );
            }
            let o = Vec3::new(c(8.0), c(8.0), c(8.0));
            // Aimed into the region of the boxes; some with zero or tiny components.
            let mut d = Vec3::new(c(4.0), c(4.0), c(4.0)) - o;
            match k % 5 {
                0 => d.x = 0.0,
                1 => d.y = -1e-35,
                _ => {}
            }
            let t_max = if k % 2 == 0 {
                f32::INFINITY
            } else {
                c(10.0).abs()
            };
            let inv = safe_inverse(d);
            let (mask, near) = RayLanes::new(o.into(), inv).slab_test(&node, Vec4::splat(t_max));
            for lane in 0..4 {
                let b = node.lane_bounds(lane);
                let want = (lane < lanes)
                    .then(|| slab(b.min, b.max, o, inv, t_max))
                    .flatten();
                assert_eq!(
                    mask & (1 << lane) != 0,
                    want.is_some(),
                    "case {k} lane {lane}"
                );
                if let Some(t) = want {
                    accepted += 1;
                    assert_eq!(near[lane], t);
                }
            }
        }
        assert!(accepted > 5_000, "only {accepted} boxes hit");
    }

    /// `crash-axis-parallel-ray-on-box-face`: a ray with `dir.y = 0` lying in the plane of a
    /// box's face (`o.y = max.y` or `min.y`) passes through the box's boundary at every `t`; it
    /// used to be moved off that plane by the replaced component and rejected past `t = 0`.
    #[test]
    fn a_parallel_ray_in_a_box_face_plane_is_accepted() {
        let (min, max) = (Vec3::new(0.0, -0.25, 0.0), Vec3::new(1.0, 0.5, 1.0));
        let d = Vec3::new(-2.9, 0.0, 4.5);
        for y in [0.5, -0.25] {
            let o = Vec3::new(1.7, y, -1.0);
            assert!(slab(min, max, o, safe_inverse(d), 1.0).is_some(), "y = {y}");
            let mut node = WideNode::EMPTY;
            node.set_lane(0, &Aabb { min, max }, 0, 1);
            let (mask, _) =
                RayLanes::new(o.into(), safe_inverse(d)).slab_test(&node, Vec4::splat(1.0));
            assert_eq!(mask, 1, "y = {y}");
        }
        // Just outside the slab: rejected; a tiny direction: parallel, not moved by whole units.
        let o = Vec3::new(1.7, 0.5 + 1e-6, -1.0);
        assert_eq!(slab(min, max, o, safe_inverse(d), 1.0), None);
        let tiny = Vec3::new(1e-40, 0.0, 1e-30);
        let o = Vec3::new(0.0, 0.0, -4.0);
        assert!(slab(min, max, o, safe_inverse(tiny), f32::INFINITY).is_some());
    }

    #[test]
    fn slab_handles_zero_direction_components() {
        // Thick box, ray with zero y and z components starting exactly on the y = 0 face plane:
        // 0·∞ must not poison the test, and the grazing ray is (conservatively) accepted.
        let (min, max) = (Vec3::ZERO, Vec3::ONE);
        let inv = safe_inverse(Vec3::X);
        assert!(inv.is_finite());
        let o = Vec3::new(-1.0, 0.0, 0.5);
        assert_eq!(slab(min, max, o, inv, f32::INFINITY), Some(1.0));
        // Outside the y slab: miss.
        assert_eq!(slab(min, max, Vec3::new(-1.0, -0.1, 0.5), inv, 10.0), None);
        // Starting inside gives entry distance 0; pointing away misses.
        assert_eq!(slab(min, max, Vec3::splat(0.5), inv, 1.0), Some(0.0));
        assert_eq!(slab(min, max, o, safe_inverse(-Vec3::X), 10.0), None);
        // t_max shorter than the distance to the box.
        assert_eq!(slab(min, max, o, inv, 0.5), None);
        // A flat box (z extent 0) crossed perpendicularly.
        let flat_max = Vec3::new(1.0, 1.0, 0.0);
        let hit = slab(
            min,
            flat_max,
            Vec3::new(0.5, 0.5, 2.0),
            safe_inverse(-Vec3::Z),
            5.0,
        );
        assert_eq!(hit, Some(2.0));
    }
}
