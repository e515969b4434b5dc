//! `raster_triangle_in_bounds`: arbitrary clip-space triangles into a visibility buffer.
//!
//! # Input layout
//!
//! ```text
//! size       b0: width − 1 (bits 0–3), height − 1 (bits 4–7); b1: aa − 1 (bits 0–2),
//!            bit 3: a long thin grid instead (THIN_GRIDS[b1 >> 4 mod 4])
//! triangles  until the input ends (at most 16, or 2 on a thin grid), mode b mod 4:
//!   0 exact        w = 2^(i8 mod 21); per corner X = u32 mod (cols·256 + 1),
//!                  Y = u32 mod (rows·256 + 1) (24.8 fixed point), z = u16/65535 (× w)
//!   1 raw          12 raw f32 (NaN, ±∞, huge, w ≤ 0: anything)
//!   2 scaled       scale 2^i8, then 12 × i8·scale
//!   3 perspective  scale 2^(i8 mod 16), 3 view-space corners i8·scale through a fixed
//!                  perspective projection (corners behind the eye, across near and far)
//! ```
//!
//! # What is checked
//!
//! For each triangle drawn alone into a cleared buffer (which must never panic or overflow;
//! fuzz with `-a` so that overflow checks are on):
//!
//! - every sub-sample is either empty (id `EMPTY`, depth +∞) or holds the triangle's id and a
//!   finite depth in [0, 1]; input with NaN or ∞ draws nothing;
//! - **exact oracle**: when every corner has the same power-of-two w, lies inside the view
//!   volume and sits on the 24.8 fixed-point grid of a power-of-two sized buffer, the clipped
//!   and snapped triangle is the input itself, so coverage must equal the top-left fill rule
//!   evaluated with exact integer edge functions at every sub-sample centre;
//! - **margin oracle** (any finite triangle): with the 2D homogeneous edge functions of the
//!   corners (Olano & Greer 1997) and the near and far lines, evaluated independently per
//!   sub-sample centre in f64, a centre farther than 0.02 sub-sample (plus a rounding bound)
//!   inside every line must be covered, and one as far outside any line must not;
//! - the stored depth of a covered sub-sample equals the NDC depth interpolated at its centre
//!   (within an f32 rounding bound), wherever the margin oracle decides it is inside.
//!
//! Then all triangles drawn in order into one buffer must give exactly the per-sub-sample
//! minimum of the single-triangle depths, earlier triangles winning ties.

use glam::{DVec3, Mat4, Vec3, Vec4};
use lucent_raster::raster::{EMPTY, VisibilityBuffer};

use super::input::{Input, pow2};

/// Long thin buffers: `(width, height, aa)`, up to the 2^20 sub-samples per axis limit (kept
/// to at most 2^20 sub-samples in all, so that an input costs milliseconds).
const THIN_GRIDS: [(u32, u32, u32); 4] =
    [(1 << 20, 1, 1), (1, 1 << 20, 1), (4096, 1, 8), (1, 4096, 4)];

/// Distance (in sub-samples) beyond which the margin oracle decides; snapping moves an edge
/// by at most √2/512 ≈ 0.003 sub-sample.
const MARGIN: f64 = 0.02;

/// How one triangle was made.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// On the fixed-point grid, inside the view volume: the exact oracle applies, with the
    /// corners' raw 24.8 coordinates.
    Exact([(i64, i64); 3]),
    /// Anything else.
    Other,
}

fn decode_triangle(r: &mut Input, cols: u32, rows: u32) -> ([Vec4; 3], Kind) {
    match r.u8() % 4 {
        0 => {
            let w = pow2(i32::from(r.i8() % 21));
            let mut raw = [(0i64, 0i64); 3];
            let mut clip = [Vec4::ZERO; 3];
            for k in 0..3 {
                let xr = i64::from(r.u32() % (cols.saturating_mul(256).saturating_add(1)));
                let yr = i64::from(r.u32() % (rows.saturating_mul(256).saturating_add(1)));
                let z = f32::from(r.u16()) / 65535.0;
                let x = (xr as f64 / (f64::from(cols) * 128.0) - 1.0) as f32;
                let y = (1.0 - yr as f64 / (f64::from(rows) * 128.0)) as f32;
                raw[k] = (xr, yr);
                clip[k] = Vec4::new(x * w, y * w, z * w, w);
            }
            // Exact only when x, y above are exact: power-of-two grids with cols·256 ≤ 2^24.
            let exact_grid = |n: u32| n.is_power_of_two() && n <= 1 << 16;
            let kind = if exact_grid(cols) && exact_grid(rows) {
                Kind::Exact(raw)
            } else {
                Kind::Other
            };
            (clip, kind)
        }
        1 => {
            let mut c = || Vec4::new(r.f32_bits(), r.f32_bits(), r.f32_bits(), r.f32_bits());
            ([c(), c(), c()], Kind::Other)
        }
        2 => {
            let s = r.pow2_i8();
            let mut c = || {
                let mut v = || f32::from(r.i8()) * s;
                Vec4::new(v(), v(), v(), v())
            };
            ([c(), c(), c()], Kind::Other)
        }
        _ => {
            let s = pow2(i32::from(r.i8() % 16));
            let proj = Mat4::perspective_rh(1.0, 1.3, 0.5, 100.0);
            let mut c = || {
                let mut v = || f32::from(r.i8()) * s;
                proj * Vec3::new(v(), v(), v()).extend(1.0)
            };
            ([c(), c(), c()], Kind::Other)
        }
    }
}

/// Twice the signed area of `a, b, p` on the y-down grid (positive: p right of a → b when
/// looking along it on screen, i.e. inside a clockwise-on-screen triangle).
fn edge(a: (i64, i64), b: (i64, i64), p: (i64, i64)) -> i128 {
    let (ax, ay, bx, by) = (a.0 as i128, a.1 as i128, b.0 as i128, b.1 as i128);
    (bx - ax) * (p.1 as i128 - ay) - (by - ay) * (p.0 as i128 - ax)
}

/// The top-left rule with exact edge functions (Direct3D's definition): a centre on an edge is
/// inside only for a left edge (going up the screen, interior on its right) or a top edge
/// (horizontal, interior below).
fn top_left_covers(tri: [(i64, i64); 3], p: (i64, i64)) -> bool {
    let mut t = tri;
    let area = edge(t[0], t[1], t[2]);
    if area == 0 {
        return false;
    }
    if area < 0 {
        t.swap(1, 2);
    }
    (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let e = edge(a, b, p);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        e > 0 || (e == 0 && (dy < 0 || (dy == 0 && dx > 0)))
    })
}

/// One line of the margin oracle: `value(p) = l·(X, Y, 1)` in NDC, oriented so that inside is
/// positive, with a bound on the rounding of `value`.
#[derive(Clone, Copy, Debug)]
struct Line {
    l: DVec3,
    /// Componentwise bound on |error| of `l`.
    err: DVec3,
}

/// The margin oracle for one finite clip-space triangle (see the module docs).
struct MarginOracle {
    lines: [Line; 5],
    /// NDC depth = depth·(X, Y, 1).
    depth: DVec3,
    /// Whether the depth plane is well enough conditioned to check depths against.
    depth_ok: bool,
    cols: f64,
    rows: f64,
}

/// What the margin oracle says about a sub-sample centre.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    Inside,
    Outside,
    Unsure,
}

const U64: f64 = f64::EPSILON / 2.0;

impl MarginOracle {
    fn new(clip: [Vec4; 3], cols: u32, rows: u32) -> Option<Self> {
        let v = clip.map(|c| DVec3::new(c.x.into(), c.y.into(), c.w.into()));
        let z = clip.map(|c| f64::from(c.z));
        let cross = |a: DVec3, b: DVec3| a.cross(b);
        let e = [cross(v[1], v[2]), cross(v[2], v[0]), cross(v[0], v[1])];
        // |error| of each cross component: one rounding of a difference of exact products.
        let e_err = [(1, 2), (2, 0), (0, 1)].map(|(i, j)| {
            let (a, b) = (v[i].abs(), v[j].abs());
            DVec3::new(
                a.y * b.z + a.z * b.y,
                a.z * b.x + a.x * b.z,
                a.x * b.y + a.y * b.x,
            ) * U64
        });
        let d = v[0].dot(e[0]);
        let d_err = 4.0 * U64 * v[0].abs().dot(e[0].abs()) + v[0].abs().dot(e_err[0]);
        if !(d.abs() > 4.0 * d_err) || !d.is_finite() {
            return None; // degenerate or too close to it to know the orientation
        }
        let s = d.signum();
        let combo = |k: [f64; 3]| {
            let l = e[0] * k[0] + e[1] * k[1] + e[2] * k[2];
            let err = (0..3)
                .map(|i| (e[i].abs() * 4.0 * U64 + e_err[i]) * k[i].abs())
                .fold(DVec3::ZERO, |a, b| a + b);
            Line { l: l * s, err }
        };
        let edge_line = |i: usize| Line {
            l: e[i] * s,
            err: e_err[i],
        };
        let near = combo(z);
        let far = combo([v[0].z - z[0], v[1].z - z[1], v[2].z - z[2]]);
        let depth = near.l * s / d;
        let depth_ok = depth.is_finite()
            && near.err.max_element() * 1e6 < near.l.abs().max_element().max(d.abs());
        Some(MarginOracle {
            lines: [edge_line(0), edge_line(1), edge_line(2), near, far],
            depth,
            depth_ok,
            cols: f64::from(cols),
            rows: f64::from(rows),
        })
    }

    /// NDC position of the centre of sub-sample `(col, row)`.
    fn ndc(&self, col: u32, row: u32) -> DVec3 {
        DVec3::new(
            2.0 * (f64::from(col) + 0.5) / self.cols - 1.0,
            1.0 - 2.0 * (f64::from(row) + 0.5) / self.rows,
            1.0,
        )
    }

    fn verdict(&self, col: u32, row: u32) -> Verdict {
        let p = self.ndc(col, row);
        let mut inside = true;
        for line in &self.lines {
            let value = line.l.dot(p);
            let bound = line.err.dot(p.abs()) + 4.0 * U64 * line.l.abs().dot(p.abs());
            // Gradient in sub-sample units: X = 2(col + ½)/cols − 1, Y = 1 − 2(row + ½)/rows.
            // A line with no gradient (e.g. the near plane of a triangle at constant w) is a
            // constant: everywhere inside or everywhere outside.
            let g = (2.0 * line.l.x / self.cols).hypot(2.0 * line.l.y / self.rows);
            if !value.is_finite() || !g.is_finite() {
                return Verdict::Unsure;
            }
            if value < -(MARGIN * g + bound) {
                return Verdict::Outside;
            }
            if value <= MARGIN * g + bound {
                inside = false;
            }
        }
        if inside {
            Verdict::Inside
        } else {
            Verdict::Unsure
        }
    }

    /// The NDC depth at the centre of `(col, row)` and a bound on how far an f32 span
    /// evaluation may be from it.
    fn depth(&self, col: u32, row: u32) -> (f64, f64) {
        let p = self.ndc(col, row);
        let z = self.depth.dot(p);
        // The span evaluates z0 + dz·k in f32 with z0 = a·col + b·row + c.
        let (a, b) = (
            2.0 * self.depth.x / self.cols,
            2.0 * self.depth.y / self.rows,
        );
        let scale =
            a.abs() * self.cols * 2.0 + b.abs() * self.rows + self.depth.abs().dot(DVec3::ONE);
        (z, 1e-6 + 4.0 * f64::from(f32::EPSILON) * scale)
    }
}

/// The property of the fuzz target `raster_triangle_in_bounds` (see the module docs); panics
/// when it fails.
pub fn raster_triangle_in_bounds(data: &[u8]) {
    let mut r = Input::new(data);
    let (b0, b1) = (r.u8(), r.u8());
    let (width, height, aa, max_triangles) = if b1 & 8 != 0 {
        let (w, h, aa) = THIN_GRIDS[usize::from(b1 >> 4) % THIN_GRIDS.len()];
        (w, h, aa, 2)
    } else {
        (
            1 + u32::from(b0 & 15),
            1 + u32::from(b0 >> 4),
            1 + u32::from(b1 & 7),
            16,
        )
    };
    let mut single = VisibilityBuffer::new(width, height, aa).expect("valid size");
    let mut shared = single.clone();
    let (cols, rows) = single.grid_size();
    let mut want_depth = vec![f32::INFINITY; single.depths().len()];
    let mut want_id = vec![EMPTY; single.depths().len()];

    let mut id = 0u32;
    while !r.is_empty() && id < max_triangles {
        let (clip, kind) = decode_triangle(&mut r, cols, rows);
        let what = format!("triangle {id} {clip:?} on {width}×{height} aa {aa}");
        single.clear();
        single.rasterize_triangle(id, clip);
        shared.rasterize_triangle(id, clip);

        let finite = clip.iter().all(|v| v.is_finite());
        let oracle = if finite {
            MarginOracle::new(clip, cols, rows)
        } else {
            None
        };
        for row in 0..rows {
            for col in 0..cols {
                let i = row as usize * cols as usize + col as usize;
                let (t, d) = (single.triangles()[i], single.depths()[i]);
                let covered = t != EMPTY;
                if covered {
                    assert_eq!(t, id, "{what}: wrong id at ({col}, {row})");
                    assert!(
                        (0.0..=1.0).contains(&d),
                        "{what}: depth {d} at ({col}, {row})"
                    );
                    assert!(finite, "{what}: non-finite input drew ({col}, {row})");
                } else {
                    assert_eq!(d, f32::INFINITY, "{what}: empty sub-sample with a depth");
                }
                if let Kind::Exact(raw) = kind {
                    let centre = (i64::from(col) * 256 + 128, i64::from(row) * 256 + 128);
                    assert_eq!(
                        covered,
                        top_left_covers(raw, centre),
                        "{what}: exact coverage at ({col}, {row}), raw corners {raw:?}"
                    );
                }
                if let Some(o) = &oracle {
                    let verdict = o.verdict(col, row);
                    assert!(
                        verdict != Verdict::Inside || covered,
                        "{what}: ({col}, {row}) is inside by more than {MARGIN} but not covered"
                    );
                    assert!(
                        verdict != Verdict::Outside || !covered,
                        "{what}: ({col}, {row}) is outside by more than {MARGIN} but covered"
                    );
                    if covered && verdict == Verdict::Inside && o.depth_ok {
                        let (z, tol) = o.depth(col, row);
                        assert!(
                            (f64::from(d) - z.clamp(0.0, 1.0)).abs() <= tol,
                            "{what}: depth {d} at ({col}, {row}), expected {z} ± {tol}"
                        );
                    }
                }
                if covered && d < want_depth[i] {
                    want_depth[i] = d;
                    want_id[i] = id;
                }
            }
        }
        id += 1;
    }
    assert!(
        shared.triangles() == want_id.as_slice(),
        "drawing in sequence must keep the nearest, earliest triangle"
    );
    let same_depth = shared
        .depths()
        .iter()
        .zip(&want_depth)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same_depth, "drawing in sequence changed a depth");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn top_left_rule_splits_a_shared_edge() {
        // Two triangles sharing the diagonal of a 2×2-sub-sample square; the centre (1.5, 1.5)
        // sub-samples … every centre of the square is covered exactly once.
        let (a, b, c, d) = ((0, 0), (512, 0), (0, 512), (512, 512));
        for y in 0..2 {
            for x in 0..2 {
                let p = (x * 256 + 128, y * 256 + 128);
                let n = u32::from(top_left_covers([a, b, c], p))
                    + u32::from(top_left_covers([b, d, c], p));
                assert_eq!(n, 1, "centre {p:?}");
            }
        }
        // A degenerate triangle covers nothing.
        assert!(!top_left_covers([a, d, (256, 256)], (128, 128)));
    }

    #[test]
    fn margin_oracle_agrees_with_a_simple_triangle() {
        // The lower-left half of NDC at w = 1, depth 0.5: centre (0, rows − 1) is inside.
        let clip = [
            Vec4::new(-1.0, -1.0, 0.5, 1.0),
            Vec4::new(1.0, -1.0, 0.5, 1.0),
            Vec4::new(-1.0, 1.0, 0.5, 1.0),
        ];
        let o = MarginOracle::new(clip, 8, 8).expect("well conditioned");
        assert_eq!(o.verdict(0, 7), Verdict::Inside);
        assert_eq!(o.verdict(7, 0), Verdict::Outside);
        let (z, tol) = o.depth(0, 7);
        assert!((z - 0.5).abs() < 1e-12 && tol < 1e-5);
    }
}
