//! Frustum clipping in 2D homogeneous coordinates, projection onto the fixed-point grid, and the
//! depth plane.
//!
//! # Why not clip the 4D vertices?
//!
//! Classic Sutherland–Hodgman clipping interpolates clip-space vertices, and the interpolated
//! point inherits the rounding error of the *largest* coordinate: with a corner at 10^30 even
//! `f64` puts the clipped vertex 10^14 units off, which at viewport scale is garbage. Instead we
//! follow Olano & Greer, "Triangle Scan Conversion using 2D Homogeneous Coordinates" (1997):
//! with corners `Vᵢ = (xᵢ, yᵢ, wᵢ)`, the cross product `Eᵢ = Vⱼ × Vₖ` is the line through the
//! projections of corners `j` and `k`, valid even when some `w` is negative. Each component is
//! one difference of two products of `f32` values, which `f64` forms exactly, so every line is
//! correct to one rounding *relative to its own size*, for any finite input.
//!
//! For a point `p = (X, Y, 1)` in NDC, `lᵢ = Eᵢ·p` are unnormalised perspective barycentrics and
//! `Σ lᵢ·Vᵢ = D·p` with `D = V₀·E₀`. Hence the point of the triangle seen at `p` has
//! `w = D / Σ lᵢ`, and it is on the triangle *and in front of the eye* exactly when
//! `sign(D)·lᵢ >= 0` for all three edges. Its clip-space `z` is `Σ zᵢ lᵢ / Σ lᵢ`, so the near
//! plane `z >= 0` becomes the line `sign(D)·Σ zᵢ Eᵢ`, the far plane `z <= w` the line
//! `sign(D)·Σ (wᵢ − zᵢ) Eᵢ`, and the NDC depth `z / w = (Σ zᵢ Eᵢ)·p / D` is affine in screen
//! space: the [`DepthPlane`].
//!
//! The visible part of the triangle is therefore the **viewport square clipped by at most five
//! lines** (three edges, near, far). We run Sutherland–Hodgman on that square, whose vertices
//! all lie in `[-1, 1]²`, so every intermediate value stays small and nothing can overflow
//! before the fixed-point conversion.
//!
//! # Watertightness
//!
//! The polygon is stored as a cycle of *line ids*; each vertex is the intersection of two
//! consecutive lines, computed by [`Setup::vertex`] from the pair alone, never by interpolating
//! along an edge. The computations are symmetric (`a × b = −(b × a)` bit for bit, and
//! `(−u)/(−v) = u/v`), and two triangles sharing an edge build that edge's line from the same
//! two corners. The endpoints of a shared edge are (a) an original corner, taken directly as
//! `(x/w, y/w)`; (b) its crossing with the near or far plane, computed from the two corners'
//! 4D segment alone; or (c) its crossing with a viewport side. In every case both triangles get
//! bit-identical points, snap them identically, and the fill rule does the rest.

use glam::{DVec2, DVec3, Vec4};

use super::fixed::{FixedPoint, Grid, snap};

/// Capacity of a clipped polygon. The square clipped by five lines has at most 9 vertices in
/// exact arithmetic; the slack absorbs rounding, and pushes beyond it are dropped.
const CAPACITY: usize = 16;

/// Line ids: the viewport sides in counter-clockwise order (NDC, y up)...
const BOTTOM: u8 = 0;
const RIGHT: u8 = 1;
const TOP: u8 = 2;
const LEFT: u8 = 3;
/// ...the triangle edges `E₀, E₁, E₂` (edge `i` is opposite corner `i`)...
const EDGE: u8 = 4;
/// ...and the near and far planes.
const NEAR: u8 = 7;
const FAR: u8 = 8;

/// `a × b`, written out so that `cross(b, a) == -cross(a, b)` bit for bit.
fn cross(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// Bit `k` set when the clip-space point is outside frustum plane `k`
/// (near `z >= 0`, far `z <= w`, then `-w <= x <= w`, `-w <= y <= w`).
fn outcode(p: Vec4) -> u8 {
    let p = p.as_dvec4();
    let inside = [p.z, p.w - p.z, p.w + p.x, p.w - p.x, p.w + p.y, p.w - p.y];
    (0..6).fold(0, |code, k| code | (u8::from(inside[k] < 0.0) << k))
}

/// Per-triangle data shared by the clipping passes.
struct Setup {
    /// Corners `(x, y, w)`: the `.z` field holds `w`.
    v: [DVec3; 3],
    /// Clip-space `z` per corner.
    z: [f64; 3],
    /// Every line by id, oriented so that the visible side is `line·(X, Y, 1) >= 0`.
    lines: [DVec3; 9],
}

impl Setup {
    /// `None` when `D = 0`: the triangle is degenerate or seen edge-on.
    fn new(clip: [Vec4; 3]) -> Option<(Self, DepthPlaneNdc)> {
        let v = clip.map(|c| DVec3::new(c.x.into(), c.y.into(), c.w.into()));
        let z = clip.map(|c| f64::from(c.z));
        let e = [cross(v[1], v[2]), cross(v[2], v[0]), cross(v[0], v[1])];
        let d = v[0].dot(e[0]);
        if d == 0.0 || !d.is_finite() {
            return None;
        }
        let near = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
        let far = e[0] * (v[0].z - z[0]) + e[1] * (v[1].z - z[1]) + e[2] * (v[2].z - z[2]);
        let s = d.signum();
        let lines = [
            DVec3::new(0.0, 1.0, 1.0),  // bottom: Y >= -1
            DVec3::new(-1.0, 0.0, 1.0), // right:  X <= 1
            DVec3::new(0.0, -1.0, 1.0), // top:    Y <= 1
            DVec3::new(1.0, 0.0, 1.0),  // left:   X >= -1
            e[0] * s,
            e[1] * s,
            e[2] * s,
            near * s,
            far * s,
        ];
        let depth = DepthPlaneNdc(near / d);
        Some((Self { v, z, lines }, depth))
    }

    /// The intersection of lines `a` and `b` in NDC (see the module docs on watertightness).
    fn vertex(&self, a: u8, b: u8) -> DVec2 {
        let (lo, hi) = (a.min(b), a.max(b));
        let is_edge = |id: u8| (EDGE..NEAR).contains(&id);
        if is_edge(lo) && is_edge(hi) {
            // Edges i and j meet at corner 3 − i − j.
            let corner = self.v[usize::from(2 * EDGE + 3 - lo - hi)];
            if corner.z > 0.0 {
                return DVec2::new(corner.x / corner.z, corner.y / corner.z);
            }
        } else if is_edge(lo) && hi >= NEAR {
            // Edge i runs between corners i + 1 and i + 2; where it crosses the plane
            // d = 0 (d = z for near, w − z for far), from the two corners alone.
            let i = usize::from(lo - EDGE);
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let dist = |m: usize| {
                if hi == NEAR {
                    self.z[m]
                } else {
                    self.v[m].z - self.z[m]
                }
            };
            let (dj, dk) = (dist(j), dist(k));
            let (vj, vk) = (self.v[j], self.v[k]);
            let h = DVec3::new(
                dk * vj.x - dj * vk.x,
                dk * vj.y - dj * vk.y,
                dk * vj.z - dj * vk.z,
            );
            if h.z != 0.0 {
                return DVec2::new(h.x / h.z, h.y / h.z);
            }
        }
        let h = cross(self.lines[usize::from(a)], self.lines[usize::from(b)]);
        DVec2::new(h.x / h.z, h.y / h.z)
    }
}

/// NDC depth as an affine function of NDC position: `z = n·(X, Y, 1)`.
#[derive(Clone, Copy, Debug)]
struct DepthPlaneNdc(DVec3);

/// NDC depth as an affine function of sub-sample indices: at the centre of sub-sample
/// `(col, row)` the depth is `a·col + b·row + c`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct DepthPlane {
    a: f64,
    b: f64,
    c: f64,
}

impl DepthPlane {
    /// Converts from NDC (`X = 2(col + ½)/cols − 1`, `Y = 1 − 2(row + ½)/rows`).
    fn new(ndc: DepthPlaneNdc, grid: Grid) -> Option<Self> {
        let n = ndc.0;
        let (cols, rows) = (f64::from(grid.cols), f64::from(grid.rows));
        let plane = Self {
            a: 2.0 * n.x / cols,
            b: -2.0 * n.y / rows,
            c: n.x * (1.0 / cols - 1.0) + n.y * (1.0 - 1.0 / rows) + n.z,
        };
        (plane.a.is_finite() && plane.b.is_finite() && plane.c.is_finite()).then_some(plane)
    }

    /// Depth at the start of a span and the increment per sub-sample along it.
    #[inline]
    pub(crate) fn span(&self, row: u32, col: u32) -> (f32, f32) {
        let z = self.a * f64::from(col) + self.b * f64::from(row) + self.c;
        (z as f32, self.a as f32)
    }
}

/// The visible part of a triangle: a convex polygon of snapped points (empty when nothing is
/// visible) and the triangle's depth plane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ScreenPolygon {
    points: [FixedPoint; CAPACITY],
    n: usize,
    /// Depth of the (unclipped) triangle's plane.
    pub depth: DepthPlane,
}

impl ScreenPolygon {
    fn empty() -> Self {
        Self {
            points: [FixedPoint { x: 0, y: 0 }; CAPACITY],
            n: 0,
            depth: DepthPlane::default(),
        }
    }

    /// The snapped vertices.
    pub(crate) fn points(&self) -> &[FixedPoint] {
        &self.points[..self.n]
    }

    /// The polygon as a triangle fan around its first vertex.
    pub(crate) fn triangles(&self) -> impl Iterator<Item = [FixedPoint; 3]> + '_ {
        let p = self.points();
        (1..p.len().saturating_sub(1)).map(move |k| [p[0], p[k], p[k + 1]])
    }
}

/// A polygon as a cycle of lines: vertex `k` is where the edge on `line[k - 1]` meets the edge
/// on `line[k]`; `pos[k]` caches it.
#[derive(Clone, Copy)]
struct LinePolygon {
    line: [u8; CAPACITY],
    pos: [DVec2; CAPACITY],
    n: usize,
}

impl LinePolygon {
    fn push(&mut self, line: u8, pos: DVec2) {
        if self.n < CAPACITY {
            self.line[self.n] = line;
            self.pos[self.n] = pos;
            self.n += 1;
        }
    }

    /// One Sutherland–Hodgman pass against line `m`.
    fn clip(&self, setup: &Setup, m: u8) -> Self {
        let l = setup.lines[usize::from(m)];
        let inside = |p: DVec2| l.x * p.x + l.y * p.y + l.z >= 0.0;
        let mut out = Self {
            line: [0; CAPACITY],
            pos: [DVec2::ZERO; CAPACITY],
            n: 0,
        };
        for k in 0..self.n {
            let (a, b) = (self.pos[k], self.pos[(k + 1) % self.n]);
            let edge = self.line[k];
            match (inside(a), inside(b)) {
                (true, true) => out.push(edge, a),
                (true, false) => {
                    out.push(edge, a);
                    out.push(m, setup.vertex(edge, m)); // leaving: continue along m
                }
                (false, true) => out.push(edge, setup.vertex(m, edge)), // entering
                (false, false) => {}
            }
        }
        out
    }
}

/// The visible part of a clip-space triangle in NDC, and its depth plane; `None` when nothing
/// is visible, when any input coordinate is NaN or infinite, or when the triangle is degenerate
/// or seen exactly edge-on.
fn visible_ndc(clip: [Vec4; 3]) -> Option<(LinePolygon, DepthPlaneNdc)> {
    if !clip.iter().all(|v| v.is_finite()) {
        return None;
    }
    let codes = clip.map(outcode);
    if codes[0] & codes[1] & codes[2] != 0 {
        return None; // entirely outside one plane
    }
    let (setup, depth) = Setup::new(clip)?;
    let mut poly = LinePolygon {
        line: [0; CAPACITY],
        pos: [DVec2::ZERO; CAPACITY],
        n: 0,
    };
    if codes.iter().all(|&c| c == 0) && setup.v.iter().all(|v| v.z > 0.0) {
        // Entirely inside the frustum: the corners themselves (corner k continues along the
        // edge opposite corner k + 2).
        for (k, v) in setup.v.iter().enumerate() {
            poly.push(EDGE + ((k as u8 + 2) % 3), DVec2::new(v.x / v.z, v.y / v.z));
        }
        return Some((poly, depth));
    }
    for (prev, line) in [(LEFT, BOTTOM), (BOTTOM, RIGHT), (RIGHT, TOP), (TOP, LEFT)] {
        poly.push(line, setup.vertex(prev, line));
    }
    let straddled = codes[0] | codes[1] | codes[2];
    let near_far = [(0, NEAR), (1, FAR)];
    let planes = near_far
        .iter()
        .filter(|(bit, _)| straddled & (1 << bit) != 0)
        .map(|&(_, id)| id);
    for m in (EDGE..EDGE + 3).chain(planes) {
        poly = poly.clip(&setup, m);
        if poly.n < 3 {
            return None;
        }
    }
    Some((poly, depth))
}

/// Clips a clip-space triangle to the view frustum and projects the visible part onto `grid`
/// (empty when nothing is visible; see [`visible_ndc`]).
pub(crate) fn clip_and_project(clip: [Vec4; 3], grid: Grid) -> ScreenPolygon {
    let mut out = ScreenPolygon::empty();
    let Some((poly, depth)) = visible_ndc(clip) else {
        return out;
    };
    let Some(depth) = DepthPlane::new(depth, grid) else {
        return out;
    };
    let (cols, rows) = (f64::from(grid.cols), f64::from(grid.rows));
    // A vertex of a polygon inside the square lies in [-1, 1]² up to rounding. One far outside
    // is the intersection of two nearly parallel lines (e.g. coinciding near and far lines of
    // a triangle seen edge-on), computed with an error larger than the polygon; clamping it
    // would invent area, dropping it only shrinks the convex polygon.
    let sane = |p: &&DVec2| p.is_finite() && p.x.abs() <= 1.0 + 1e-6 && p.y.abs() <= 1.0 + 1e-6;
    for p in poly.pos[..poly.n].iter().filter(sane) {
        // Inside [-1, 1]² up to rounding; clamping removes the rounding.
        let (x, y) = (p.x.clamp(-1.0, 1.0), p.y.clamp(-1.0, 1.0));
        out.points[out.n] = FixedPoint {
            x: snap((x * 0.5 + 0.5) * cols),
            y: snap((0.5 - y * 0.5) * rows),
        };
        out.n += 1;
    }
    if out.n < 3 {
        return ScreenPolygon::empty();
    }
    out.depth = depth;
    out
}

#[cfg(test)]
mod tests {
    use super::super::fixed::ONE;
    use super::super::testutil::Rng;
    use super::*;

    const GRID: Grid = Grid { cols: 64, rows: 32 };

    #[test]
    fn inside_triangle_is_projected_exactly() {
        // NDC (−0.5, 0.5) → sub-sample (16, 8); (0.5, 0.5) → (48, 8); (0, −0.5) → (32, 24).
        let tri = [
            Vec4::new(-1.0, 1.0, 0.5, 2.0),
            Vec4::new(0.5, 0.5, 0.25, 1.0),
            Vec4::new(0.0, -2.0, 1.0, 4.0),
        ];
        let poly = clip_and_project(tri, GRID);
        let got: Vec<_> = poly.points().iter().map(|p| (p.x, p.y)).collect();
        let o = ONE as i32;
        assert_eq!(
            got,
            vec![(16 * o, 8 * o), (48 * o, 8 * o), (32 * o, 24 * o)]
        );
        // Every corner has NDC depth 0.25, so the plane is flat.
        for (c, r) in [(0, 0), (63, 31), (20, 10)] {
            let (z, dz) = poly.depth.span(r, c);
            assert!((z - 0.25).abs() < 1e-6 && dz.abs() < 1e-9, "{z} {dz}");
        }
    }

    #[test]
    fn triangle_behind_near_plane_or_outside_is_rejected() {
        let behind = [
            Vec4::new(0.0, 0.0, -0.1, 1.0),
            Vec4::new(1.0, 0.0, -0.2, 1.0),
            Vec4::new(0.0, 1.0, -0.3, 1.0),
        ];
        assert!(clip_and_project(behind, GRID).points().is_empty());
        let right = behind.map(|v| Vec4::new(v.x + 3.0, v.y, 0.5, 1.0));
        assert!(clip_and_project(right, GRID).points().is_empty());
    }

    #[test]
    fn non_finite_input_is_rejected() {
        let good = [
            Vec4::new(0.0, 0.0, 0.5, 1.0),
            Vec4::new(1.0, 0.0, 0.5, 1.0),
            Vec4::new(0.0, 1.0, 0.5, 1.0),
        ];
        assert!(!clip_and_project(good, GRID).points().is_empty());
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for k in 0..12 {
                let mut tri = good;
                tri[k / 4][k % 4] = bad;
                assert!(clip_and_project(tri, GRID).points().is_empty(), "{tri:?}");
            }
        }
    }

    #[test]
    fn shared_edge_gets_identical_endpoints_in_both_triangles() {
        // Edge a–b leaves the frustum through the near plane (b is behind the eye) and the
        // right side; the triangles traverse it in opposite directions.
        let a = Vec4::new(0.3, 0.1, 0.7, 1.0);
        let b = Vec4::new(5.0, -0.4, -2.0, -1.5);
        let c1 = Vec4::new(-0.5, 0.9, 0.5, 1.0);
        let c2 = Vec4::new(0.2, -0.9, 0.3, 1.0);
        for (p, q) in [(a, b), (b, a)] {
            let first = clip_and_project([p, q, c1], GRID);
            let second = clip_and_project([c2, q, p], GRID);
            let shared: Vec<_> = first
                .points()
                .iter()
                .filter(|p| second.points().contains(p))
                .collect();
            // Corner a plus the point where a–b leaves the visible region.
            assert_eq!(
                shared.len(),
                2,
                "{:?} vs {:?}",
                first.points(),
                second.points()
            );
        }
    }

    #[test]
    fn random_shared_edges_get_identical_endpoints() {
        // Two triangles a-b-c1 and b-a-c2 share the edge a–b, which crosses the near plane, the
        // eye plane, the far plane and the image sides in random ways. The vertices of each
        // visible polygon that lie on the projected line a–b must be bit-identical (before
        // snapping, so that even a last-bit difference is caught).
        let mut rng = Rng::new(31);
        let mut compared = 0;
        for _ in 0..20_000 {
            let mut v = || {
                let w = rng.f32_in(-1.0, 3.0);
                Vec4::new(
                    rng.f32_in(-3.0, 3.0),
                    rng.f32_in(-3.0, 3.0),
                    rng.f32_in(-1.0, 1.2) * w.abs(),
                    w,
                )
            };
            let (a, b, c1, c2) = (v(), v(), v(), v());
            let xyw = |p: Vec4| DVec3::new(p.x.into(), p.y.into(), p.w.into());
            let line = cross(xyw(a), xyw(b));
            let on_line = |p: &&DVec2| {
                (line.x * p.x + line.y * p.y + line.z).abs() < 1e-9 * line.truncate().length()
            };
            let on_edge = |tri: [Vec4; 3]| {
                let mut points: Vec<DVec2> = visible_ndc(tri).map_or(Vec::new(), |(poly, _)| {
                    poly.pos[..poly.n].iter().filter(on_line).copied().collect()
                });
                points.sort_by(|p, q| p.x.total_cmp(&q.x).then(p.y.total_cmp(&q.y)));
                points
            };
            let (p1, p2) = (on_edge([a, b, c1]), on_edge([b, a, c2]));
            if p1.len() != 2 || p2.len() != 2 {
                continue; // edge not visible, or another vertex happens to lie on the line
            }
            assert_eq!(p1, p2, "{a} {b} {c1} {c2}");
            compared += 1;
        }
        assert!(compared > 2000, "{compared}");
    }

    #[test]
    fn random_and_huge_triangles_stay_in_grid_and_small() {
        let mut rng = Rng::new(3);
        let limit_x = i32::try_from(i64::from(GRID.cols) * ONE).unwrap();
        let limit_y = i32::try_from(i64::from(GRID.rows) * ONE).unwrap();
        for case in 0..20_000 {
            let scale = [1.0f32, 10.0, 1e6, 1e30, 3e38][case % 5];
            let mut v = || {
                Vec4::new(
                    rng.f32_in(-scale, scale),
                    rng.f32_in(-scale, scale),
                    rng.f32_in(-scale, scale),
                    rng.f32_in(-scale, scale),
                )
            };
            let poly = clip_and_project([v(), v(), v()], GRID);
            assert!(poly.points().len() <= 9);
            for p in poly.points() {
                assert!(
                    (0..=limit_x).contains(&p.x) && (0..=limit_y).contains(&p.y),
                    "{p:?}"
                );
            }
        }
    }
}
