//! One site's Voronoi cell restricted to one triangle: the triangle, in its own plane, clipped
//! by the bisectors of the site and its neighbours (Sutherland–Hodgman), with the security
//! radius that proves no further neighbour can cut it.
//!
//! In the triangle's plane the bisector half-space of sites `s` and `j` is the half-plane
//! `2·x·(j − s) ≤ |j|² − |s|²` (coordinates relative to the triangle's first vertex), a line
//! whatever the sites' heights above the plane: the restricted diagram is a power diagram of
//! the projected sites. Everything is computed in `f64` from the `f32` inputs, so the cells of
//! one triangle add up to its area to about 1e-14 relative.
//!
//! ```text
//! Polygon: up to MAX_VERTICES vertices, counter-clockwise in the triangle frame
//!   u: [f64; MAX_VERTICES]   v: [f64; MAX_VERTICES]
//!   label: [u32; MAX_VERTICES]   edge k → k+1 lies on: TRIANGLE_EDGE, or the bisector with
//!                                neighbour `label[k]` (its sorted index)
//! ```

use glam::{DVec2, DVec3, Vec3};

/// Label of a polygon edge that lies on the triangle's boundary.
pub(super) const TRIANGLE_EDGE: u32 = u32::MAX;

/// Most polygon vertices. Each clip adds at most one vertex and a cell restricted to a triangle
/// has few edges (6 on average in the plane); a polygon that would exceed this is clipped no
/// further, which [`Outcome::NeedMore`] reports like an unproven cell.
const MAX_VERTICES: usize = 64;

/// A triangle's orthonormal frame: origin at its first vertex, `e1` along its first edge.
pub(super) struct Frame {
    origin: DVec3,
    e1: DVec3,
    e2: DVec3,
    normal: DVec3,
    /// The second and third vertices in the frame (the first is the origin).
    v1: DVec2,
    v2: DVec2,
}

impl Frame {
    /// The frame, or `None` for a triangle without area (or not finite).
    pub(super) fn new(t: &[Vec3; 3]) -> Option<Frame> {
        let origin = t[0].as_dvec3();
        let (a, b) = (t[1].as_dvec3() - origin, t[2].as_dvec3() - origin);
        let cross = a.cross(b);
        let (la, lc) = (a.length(), cross.length());
        if !(la > 0.0 && lc > 0.0 && lc.is_finite()) {
            return None;
        }
        let e1 = a / la;
        let normal = cross / lc;
        let e2 = normal.cross(e1);
        Some(Frame {
            origin,
            e1,
            e2,
            normal,
            v1: DVec2::new(la, 0.0),
            v2: DVec2::new(b.dot(e1), b.dot(e2)),
        })
    }

    /// The world position of frame coordinates `(u, v)`.
    pub(super) fn point(&self, u: f64, v: f64) -> DVec3 {
        self.origin + self.e1 * u + self.e2 * v
    }
}

/// A convex polygon in a triangle's frame with the origin of each edge (see the module
/// documentation).
pub(super) struct Polygon {
    len: usize,
    /// Squared distance from the site to the farthest vertex, as of the last clip.
    r2: f64,
    u: [f64; MAX_VERTICES],
    v: [f64; MAX_VERTICES],
    label: [u32; MAX_VERTICES],
    /// Scratch for the next polygon.
    next_len: usize,
    nu: [f64; MAX_VERTICES],
    nv: [f64; MAX_VERTICES],
    nlabel: [u32; MAX_VERTICES],
}

impl Default for Polygon {
    fn default() -> Self {
        Polygon {
            len: 0,
            r2: 0.0,
            u: [0.0; MAX_VERTICES],
            v: [0.0; MAX_VERTICES],
            label: [0; MAX_VERTICES],
            next_len: 0,
            nu: [0.0; MAX_VERTICES],
            nv: [0.0; MAX_VERTICES],
            nlabel: [0; MAX_VERTICES],
        }
    }
}

/// How clipping one site's cell against one triangle ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Outcome {
    /// The polygon is the exact cell: every unconsidered site is at least twice as far from the
    /// site as the polygon's farthest vertex (the security radius).
    Done,
    /// The cell misses the triangle.
    Empty,
    /// The neighbour list ran out before the security radius was proven; the polygon's
    /// farthest vertex is at squared distance `.0` from the site. Needs neighbours out to
    /// twice that distance.
    NeedMore(f64),
}

/// A site's neighbour: squared distance and sorted index.
pub(super) type Neighbour = (f64, u32);

impl Polygon {
    /// The cell of `site` restricted to the triangle of `frame`, clipped by `neighbours`
    /// (indices into `sites`; coincident ones are skipped, the caller shares their cell). The
    /// list holds, nearest first, every site closer than `sorted`, then others farther than
    /// that in any order; every site closer than `guaranteed` (≥ `sorted`) is in it.
    pub(super) fn clip_cell(
        &mut self,
        frame: &Frame,
        site: DVec3,
        sites: &[Vec3],
        neighbours: &[Neighbour],
        sorted: f64,
        guaranteed: f64,
    ) -> Outcome {
        let f = frame;
        let (su, sv, h2) = self.whole(f, site);
        let (s2, g2) = (sorted * sorted, guaranteed * guaranteed);
        let mut r2 = self.r2;
        for &(d2, j) in neighbours {
            if d2 == 0.0 {
                continue;
            }
            if 4.0 * r2 <= d2 {
                if d2 <= s2 {
                    // Sorted: every later neighbour, and every unlisted site, is as far.
                    return Outcome::Done;
                }
                // Unsorted: this one cannot cut; a later one might be nearer.
                continue;
            }
            if d2 > s2 && 4.0 * r2 <= s2 {
                // Every site within `sorted` is done and the rest are farther.
                return Outcome::Done;
            }
            let pj = sites[j as usize].as_dvec3();
            let d = pj - site;
            let m = pj + site - 2.0 * f.origin;
            let (a, b, c) = (2.0 * d.dot(f.e1), 2.0 * d.dot(f.e2), d.dot(m));
            if !self.clip(a, b, c, j) {
                return Outcome::Empty;
            }
            r2 = self.vertex_radius2(su, sv, h2);
            self.r2 = r2;
        }
        if 4.0 * r2 <= g2 {
            Outcome::Done
        } else {
            Outcome::NeedMore(r2)
        }
    }

    /// Sets the polygon to the whole triangle of `frame`, as [`Polygon::clip_cell`] leaves it
    /// when no bisector cuts it, and returns the site in the frame: `(u, v, height²)`.
    pub(super) fn whole(&mut self, frame: &Frame, site: DVec3) -> (f64, f64, f64) {
        let f = frame;
        self.len = 3;
        (self.u[0], self.v[0]) = (0.0, 0.0);
        (self.u[1], self.v[1]) = (f.v1.x, f.v1.y);
        (self.u[2], self.v[2]) = (f.v2.x, f.v2.y);
        self.label[..3].fill(TRIANGLE_EDGE);
        let s = site - f.origin;
        let (su, sv, h) = (s.dot(f.e1), s.dot(f.e2), s.dot(f.normal));
        self.r2 = self.vertex_radius2(su, sv, h * h);
        (su, sv, h * h)
    }

    /// Largest squared 3-D distance from the site (frame coordinates `su, sv`, squared height
    /// `h2`) to a vertex: the polygon is convex, so this bounds its every point.
    fn vertex_radius2(&self, su: f64, sv: f64, h2: f64) -> f64 {
        (0..self.len).fold(0.0, |m, k| {
            let (du, dv) = (self.u[k] - su, self.v[k] - sv);
            m.max(du * du + dv * dv + h2)
        })
    }

    /// Keeps the part with `a·u + b·v ≤ c` (points on the line count as inside); new edges on
    /// the line get `label`. False if nothing is left.
    fn clip(&mut self, a: f64, b: f64, c: f64, label: u32) -> bool {
        let n = self.len;
        let mut side = [0.0f64; MAX_VERTICES];
        let mut outside = 0;
        for k in 0..n {
            side[k] = a * self.u[k] + b * self.v[k] - c;
            outside += (side[k] > 0.0) as usize;
        }
        if outside == 0 {
            return true;
        }
        if outside == n {
            self.len = 0;
            return false;
        }
        self.next_len = 0;
        let mut prev = n - 1;
        let mut dp = side[prev];
        for k in 0..n {
            let dk = side[k];
            if dk <= 0.0 {
                if dp > 0.0 {
                    // Entering: the new vertex starts the rest of the previous edge.
                    self.push_crossing(prev, k, dp, dk, self.label[prev]);
                }
                self.push(self.u[k], self.v[k], self.label[k]);
            } else if dp <= 0.0 {
                // Leaving: the new vertex starts the edge along the clip line.
                self.push_crossing(prev, k, dp, dk, label);
            }
            prev = k;
            dp = dk;
        }
        std::mem::swap(&mut self.u, &mut self.nu);
        std::mem::swap(&mut self.v, &mut self.nv);
        std::mem::swap(&mut self.label, &mut self.nlabel);
        self.len = self.next_len;
        self.len >= 3
    }

    fn push_crossing(&mut self, p: usize, k: usize, dp: f64, dk: f64, label: u32) {
        // dp and dk have opposite signs (one may be 0), so t ∈ [0, 1].
        let t = dp / (dp - dk);
        let u = self.u[p] + t * (self.u[k] - self.u[p]);
        let v = self.v[p] + t * (self.v[k] - self.v[p]);
        self.push(u, v, label);
    }

    fn push(&mut self, u: f64, v: f64, label: u32) {
        if self.next_len < MAX_VERTICES {
            self.nu[self.next_len] = u;
            self.nv[self.next_len] = v;
            self.nlabel[self.next_len] = label;
            self.next_len += 1;
        }
    }

    /// Squared distance from the site to the farthest vertex (after [`Polygon::clip_cell`]).
    pub(super) fn radius2(&self) -> f64 {
        self.r2
    }

    /// Area and centroid (frame coordinates) of the polygon: the shoelace sums of its
    /// triangles fanned from its first vertex (so that the sums stay small where the polygon
    /// is far from the frame's origin). A polygon without area has its first vertex as
    /// centroid.
    pub(super) fn moment(&self) -> (f64, DVec2) {
        let n = self.len;
        if n == 0 {
            return (0.0, DVec2::ZERO);
        }
        let o = DVec2::new(self.u[0], self.v[0]);
        let (mut twice, mut first) = (0.0, DVec2::ZERO);
        for k in 1..n.saturating_sub(1) {
            let a = DVec2::new(self.u[k], self.v[k]) - o;
            let b = DVec2::new(self.u[k + 1], self.v[k + 1]) - o;
            let t = a.perp_dot(b);
            twice += t;
            first += (a + b) * t;
        }
        if twice > 0.0 {
            (0.5 * twice, o + first / (3.0 * twice))
        } else {
            (0.0, o)
        }
    }

    /// The neighbours whose bisectors bound the polygon.
    pub(super) fn bisector_labels(&self) -> impl Iterator<Item = u32> + '_ {
        self.label[..self.len]
            .iter()
            .copied()
            .filter(|&l| l != TRIANGLE_EDGE)
    }
}

/// The point of triangle `t` nearest to `p`, as barycentric weights of its three vertices
/// (Ericson, Real-Time Collision Detection §5.1.5), in `f64`; the nearest vertex for a
/// triangle without area.
pub(super) fn nearest_on_triangle(p: DVec3, t: &[Vec3; 3]) -> [f64; 3] {
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        let d = [ap, bp, cp].map(|x| x.length_squared());
        let k = (0..3).fold(0, |k, i| if d[i] < d[k] { i } else { k });
        let mut w = [0.0; 3];
        w[k] = 1.0;
        return w;
    }
    let (v, w) = (vb / denom, vc / denom);
    [1.0 - v - w, v, w]
}

/// Squared distance from `p` to triangle `t`, in `f64`.
pub(super) fn distance2_to_triangle(p: DVec3, t: &[Vec3; 3]) -> f64 {
    let [_, v, w] = nearest_on_triangle(p, t);
    let a = t[0].as_dvec3();
    let q = a + (t[1].as_dvec3() - a) * v + (t[2].as_dvec3() - a) * w;
    (p - q).length_squared()
}

/// A lower bound on the squared distance from `p` to triangle `t` as computed here (by
/// [`distance2_to_triangle`], or from [`nearest_on_triangle`]'s weights): the distance to the
/// triangle's bounding box, less a slack far above those computations' rounding (a few ulps of
/// the largest coordinate). A few operations, against the exact test's projections and
/// branches: a triangle it puts beyond a limit is beyond it for the exact test too, so skipping
/// it changes no decision. 0 when `p` is within the slack of the box; NaN (no bound) when a
/// coordinate is NaN. (A triangle whose corners round onto one line has no computed distance,
/// NaN, and no [`Frame`]: its callers skip it either way.)
#[inline]
pub(super) fn box_distance2_below(p: DVec3, t: &[Vec3; 3]) -> f64 {
    // NaN anywhere makes the sum NaN (as do opposite infinities: no bound there either).
    if (t[0] + t[1] + t[2]).as_dvec3().is_nan() || p.is_nan() {
        return f64::NAN;
    }
    // min and max are exact in f32.
    let lo = t[0].min(t[1]).min(t[2]).as_dvec3();
    let hi = t[0].max(t[1]).max(t[2]).as_dvec3();
    box_bound(p, lo, hi)
}

/// [`box_distance2_below`] for every triangle inside the box `[lo, hi]` at once: the same bound
/// with the box for the triangle's. It is at most the bound of each such triangle (a larger box
/// is nearer, its slack no smaller, and every rounded step is monotone), so a limit it exceeds,
/// each of theirs exceeds too. NaN when `p` is NaN.
#[inline]
pub(super) fn box_distance2_below_all(p: DVec3, lo: Vec3, hi: Vec3) -> f64 {
    if p.is_nan() {
        return f64::NAN;
    }
    box_bound(p, lo.as_dvec3(), hi.as_dvec3())
}

/// The bound of [`box_distance2_below`] from the box's corners.
#[inline(always)]
fn box_bound(p: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    let gap = (lo - p).max(p - hi).max(DVec3::ZERO);
    let slack = ROUNDING_SLACK * p.abs().max(lo.abs()).max(hi.abs()).max_element();
    // (g − s)² ≥ (1 − ε)·g² − s²/ε for any ε > 0 (as 2gs ≤ ε·g² + s²/ε): no square root.
    let bound = (1.0 - SLACK_SPLIT) * gap.length_squared() - slack * slack / SLACK_SPLIT;
    bound.max(0.0)
}

/// The ε of [`box_distance2_below`]'s bound: the bound gives up this fraction of the squared
/// distance to avoid a square root.
const SLACK_SPLIT: f64 = 1e-6;

/// [`box_distance2_below`]'s slack, relative to the largest coordinate involved. The computed
/// nearest point is off the exact one by a few ulps of the coordinates (about 1e-15 relative).
const ROUNDING_SLACK: f64 = 1e-12;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    #[test]
    fn an_unclipped_triangle_keeps_its_area_and_a_bisector_halves_a_square_cell() {
        let t = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let f = Frame::new(&t).unwrap();
        let mut p = Polygon::default();
        let site = DVec3::new(0.5, 0.5, 0.0);
        // Nobody within 10: the whole triangle.
        assert_eq!(p.clip_cell(&f, site, &[], &[], 10.0, 10.0), Outcome::Done);
        let (a, c) = p.moment();
        assert!((a - 2.0).abs() < 1e-12);
        assert!(f.point(c.x, c.y).distance(DVec3::new(2.0, 2.0, 0.0) / 3.0) < 1e-12);
        // A neighbour at (1.5, 0.5), 0.25 above the plane: in the plane its bisector is
        // shifted away from it by the squared height over twice the distance, x = 1 + 0.0625/2.
        let j = DVec3::new(1.5, 0.5, 0.25);
        let sites = [j.as_vec3()];
        let n = [(site.distance_squared(j), 0)];
        assert_eq!(p.clip_cell(&f, site, &sites, &n, 10.0, 10.0), Outcome::Done);
        let x = 1.0 + 0.0625 / 2.0;
        let want = 2.0 - (2.0 - x) * (2.0 - x) / 2.0;
        // The centroid: the triangle's less the cut-off corner's (x..2 along the base).
        let corner = (2.0 - x) * (2.0 - x) / 2.0;
        let corner_c = DVec3::new((2.0 * x + 2.0) / 3.0, (2.0 - x) / 3.0, 0.0);
        let want_c = (DVec3::new(2.0, 2.0, 0.0) / 3.0 * 2.0 - corner_c * corner) / want;
        let (a, c) = p.moment();
        assert!((a - want).abs() < 1e-12, "{a} vs {want}");
        assert!(
            f.point(c.x, c.y).distance(want_c) < 1e-12,
            "{c} vs {want_c}"
        );
        assert_eq!(p.bisector_labels().collect::<Vec<_>>(), vec![0]);
        // Without the guarantee, the cell is not proven.
        assert!(matches!(
            p.clip_cell(&f, site, &sites, &n, 0.1, 0.1),
            Outcome::NeedMore(_)
        ));
        // A neighbour that takes everything.
        let far = DVec3::new(-5.0, -5.0, 0.0);
        let close = DVec3::new(0.6, 0.6, 0.0);
        let sites = [Vec3::ZERO, close.as_vec3()];
        let n = [(far.distance_squared(close), 1)];
        assert_eq!(
            p.clip_cell(&f, far, &sites, &n, 100.0, 100.0),
            Outcome::Empty
        );
    }

    #[test]
    fn distance_to_a_triangle_matches_dense_sampling() {
        let t = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.2, 0.1),
            Vec3::new(0.3, 1.1, -0.2),
        ];
        let mut rng = crate::sampling::rng::Pcg32::new(3, 0);
        for _ in 0..200 {
            let p = DVec3::new(
                rng.next_f32() as f64 * 3.0 - 1.0,
                rng.next_f32() as f64 * 3.0 - 1.0,
                rng.next_f32() as f64 * 2.0 - 1.0,
            );
            let mut best = f64::INFINITY;
            let n = 300;
            for i in 0..=n {
                for k in 0..=n - i {
                    let (b1, b2) = (i as f64 / n as f64, k as f64 / n as f64);
                    let q = t[0].as_dvec3() * (1.0 - b1 - b2)
                        + t[1].as_dvec3() * b1
                        + t[2].as_dvec3() * b2;
                    best = best.min(p.distance_squared(q));
                }
            }
            let d = distance2_to_triangle(p, &t);
            assert!(
                d <= best + 1e-12 && best.sqrt() - d.sqrt() < 4e-3,
                "{d} {best}"
            );
        }
    }

    #[test]
    fn the_box_bound_is_below_both_computed_distances() {
        // Both ways the module computes a distance: `distance2_to_triangle`, and the nearest
        // point from `nearest_on_triangle`'s weights as the centroids do. Small triangles far
        // from the origin (where rounding is largest), slivers, points near and far, in and
        // off the plane.
        let mut rng = Pcg32::new(31, 7);
        let mut useful = 0;
        for case in 0..20_000 {
            let offset = [0.0, 1.0, 1e3, 3e4][case % 4];
            let size = [1e-3, 0.1, 1.0][case / 4 % 3];
            let corner = |rng: &mut Pcg32| {
                Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32() * 0.01) * size as f32
                    + Vec3::splat(offset as f32)
            };
            let t = [corner(&mut rng), corner(&mut rng), corner(&mut rng)];
            let reach = size * [0.0, 0.5, 2.0, 20.0][case / 12 % 4];
            let p = t[0].as_dvec3()
                + DVec3::new(
                    rng.next_f32() as f64 - 0.3,
                    rng.next_f32() as f64 - 0.3,
                    rng.next_f32() as f64 - 0.5,
                ) * reach;
            let bound = box_distance2_below(p, &t);
            let exact = distance2_to_triangle(p, &t);
            let w = nearest_on_triangle(p, &t);
            let q = t[0].as_dvec3() * w[0] + t[1].as_dvec3() * w[1] + t[2].as_dvec3() * w[2];
            let centroid_way = p.distance_squared(q);
            if exact.is_nan() {
                // Corners rounded onto one point or line: no distance (and no `Frame`), so
                // the callers skip the triangle whatever the bound says.
                assert!(Frame::new(&t).is_none(), "case {case}");
                continue;
            }
            assert!(
                bound <= exact && bound <= centroid_way,
                "case {case}: bound {bound:e}, distances {exact:e} and {centroid_way:e}"
            );
            useful += usize::from(bound > 0.25 * exact);
        }
        // It must also prune: most points well off a small triangle get a real bound.
        assert!(useful > 8_000, "{useful}");
        let nan = [Vec3::NAN, Vec3::ZERO, Vec3::X];
        assert!(box_distance2_below(DVec3::splat(5.0), &nan).is_nan());
    }

    #[test]
    fn a_run_bound_is_below_each_of_its_triangles_bounds() {
        // Runs of 1 to 16 triangles scattered over a patch, the patch near and far from the
        // origin and from 0 to 3 of its sizes off it: the run's bound never exceeds any of
        // its triangles' (so skipping the run skips only triangles each test skips).
        let mut rng = Pcg32::new(5, 11);
        let (mut runs, mut pruned) = (0, 0);
        for case in 0..5_000 {
            let offset = [0.0, -1.0, 1e3, -3e4][case % 4] as f32;
            let size = [1e-3, 0.1, 1.0][case / 4 % 3] as f32;
            let mut corner = || {
                Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * size
                    + Vec3::splat(offset)
            };
            let tris: Vec<[Vec3; 3]> = (0..1 + case % 16)
                .map(|_| [corner(), corner(), corner()])
                .collect();
            let away = [0.0, 0.5, 1.5, 3.0][case / 12 % 4] * size as f64;
            let p = tris[0][0].as_dvec3()
                + DVec3::new(
                    rng.next_f32() as f64 - 0.5,
                    rng.next_f32() as f64 - 0.5,
                    rng.next_f32() as f64 - 0.5,
                ) * size as f64
                + DVec3::splat(away);
            let lo = tris.iter().flatten().fold(Vec3::INFINITY, |m, &v| m.min(v));
            let hi = tris
                .iter()
                .flatten()
                .fold(Vec3::NEG_INFINITY, |m, &v| m.max(v));
            let run = box_distance2_below_all(p, lo, hi);
            for t in &tris {
                let own = box_distance2_below(p, t);
                assert!(run <= own, "case {case}: run {run:e} > triangle {own:e}");
            }
            runs += 1;
            pruned += usize::from(run > 0.0);
        }
        assert!(pruned > runs / 4, "{pruned} of {runs} runs with a bound");
        assert!(box_distance2_below_all(DVec3::NAN, Vec3::ZERO, Vec3::ONE).is_nan());
    }
}
