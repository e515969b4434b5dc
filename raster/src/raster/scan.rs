//! Exact scanline conversion of one snapped triangle into horizontal spans of sub-samples.
//!
//! The triangle is split at its middle vertex (in y) into an upper and a lower part; each
//! sub-sample row between the top and bottom vertex is bounded by the long edge on one side and
//! by one of the two short edges on the other. Each edge is walked row by row with an integer
//! digital differential analyser that keeps the crossing as *quotient + remainder* (the
//! Bresenham idea): the column boundary is always the exact ceiling of a rational number, never a
//! rounded slope, so the spans equal what exact edge functions would give at every sub-sample
//! centre (the unit tests check this against such an oracle).
//!
//! # Fill rule
//!
//! A sub-sample centre that lies exactly on an edge must belong to exactly one of the two
//! triangles sharing that edge, or shared edges would crack or double-cover. We use the
//! **top-left rule** (as Direct3D and most GPUs do): a centre on an edge is covered only if the
//! edge is a *left* edge (the interior lies to its right, larger x) or a *top* edge (horizontal,
//! the interior below it). In scanline form this becomes two half-open intervals:
//!
//! * rows: a row whose centre `yc` satisfies `y_top <= yc < y_bottom` (top vertex and top
//!   horizontal edges included, bottom excluded);
//! * columns: within a row, centres `xc` with `x_left(yc) <= xc < x_right(yc)` (left edges
//!   included, right edges excluded).
//!
//! A shared edge is the right edge of one triangle and the left edge of the other; both compute
//! the same exact boundary column `⌈x_edge(yc) − ½⌉` (in sub-samples), and one interval is
//! closed where the other is open, so every centre goes to exactly one side.

use super::fixed::{COORD_LIMIT, FixedPoint, Grid, HALF, ONE, ceil_div, first_centre_at_or_after};

/// Walks one edge from its upper vertex `a` to its lower vertex `b` (`a.y < b.y`), producing for
/// each sub-sample row the first column whose centre is at or right of the edge:
/// `col = ⌈(x_edge(yc) − HALF) / ONE⌉`, with
/// `x_edge(yc) = a.x + (b.x − a.x)·(yc − a.y) / (b.y − a.y)`.
///
/// Writing `dy = b.y − a.y` and the numerator `num = (a.x − HALF)·dy + (b.x − a.x)·(yc − a.y)`,
/// the column is `⌈num / den⌉` with `den = ONE·dy`. We keep `col` and the slack
/// `err = col·den − num ∈ [0, den)`; moving down one row adds `step = (b.x − a.x)·ONE` to `num`,
/// i.e. `step_q` whole columns plus a remainder `step_r` that may carry one more column.
#[derive(Clone, Copy, Debug)]
struct EdgeWalker {
    col: i64,
    err: i64,
    den: i64,
    step_q: i64,
    step_r: i64,
}

impl EdgeWalker {
    /// Positions the walker on sub-sample row `row`.
    fn new(a: FixedPoint, b: FixedPoint, row: i64) -> Self {
        let (ax, ay) = (i64::from(a.x), i64::from(a.y));
        let (dx, dy) = (i64::from(b.x) - ax, i64::from(b.y) - ay);
        debug_assert!(dy > 0);
        let den = ONE * dy;
        let yc = row * ONE + HALF;
        let num = (ax - HALF) * dy + dx * (yc - ay);
        let col = ceil_div(num, den);
        let step = dx * ONE;
        Self {
            col,
            err: col * den - num,
            den,
            step_q: step.div_euclid(den),
            step_r: step.rem_euclid(den),
        }
    }

    /// Moves to the next row down.
    #[inline]
    fn step(&mut self) {
        self.col += self.step_q;
        self.err -= self.step_r;
        if self.err < 0 {
            self.col += 1;
            self.err += self.den;
        }
    }
}

/// [`scan_triangle_rows`] over every row of `grid`.
#[cfg(test)]
pub(crate) fn scan_triangle(tri: [FixedPoint; 3], grid: Grid, span: impl FnMut(u32, u32, u32)) {
    scan_triangle_rows(tri, grid, 0..grid.rows, span);
}

/// Calls `span(row, first_col, end_col)` (end exclusive, never empty) for every sub-sample row of
/// `grid` within `rows` that the triangle covers, top to bottom, using the top-left fill rule.
/// Works for either winding; zero-area triangles produce nothing. Coordinates must lie within
/// ±`COORD_LIMIT` (clipping guarantees it); anything else is ignored rather than risking
/// overflow. The spans on `rows` are those of a scan over every row: the edge walkers start on
/// the first row of `rows` exactly where they would arrive stepping down from the top.
pub(crate) fn scan_triangle_rows(
    tri: [FixedPoint; 3],
    grid: Grid,
    rows: std::ops::Range<u32>,
    mut span: impl FnMut(u32, u32, u32),
) {
    let in_range =
        |p: &FixedPoint| i64::from(p.x).abs() <= COORD_LIMIT && i64::from(p.y).abs() <= COORD_LIMIT;
    if !tri.iter().all(in_range) {
        return;
    }
    // Sort by y (then x, only to make the order fully defined): v0 top, v2 bottom.
    let mut v = tri;
    v.sort_unstable_by_key(|p| (p.y, p.x));
    let [v0, v1, v2] = v;
    let (x0, y0) = (i64::from(v0.x), i64::from(v0.y));
    let (x1, y1) = (i64::from(v1.x), i64::from(v1.y));
    let (x2, y2) = (i64::from(v2.x), i64::from(v2.y));

    // Twice the signed area; positive when v1 lies right of the long edge v0 → v2, which then
    // bounds the spans on the left.
    let cross = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
    if cross == 0 {
        return;
    }
    let long_is_left = cross > 0;

    let first_row = i64::from(rows.start);
    let rows = i64::from(grid.rows.min(rows.end));
    let cols = i64::from(grid.cols);
    let row_top = first_centre_at_or_after(y0).max(first_row);
    let row_end = first_centre_at_or_after(y2).min(rows);
    if row_top >= row_end {
        return;
    }
    let row_mid = first_centre_at_or_after(y1).clamp(row_top, row_end);

    let mut long = EdgeWalker::new(v0, v2, row_top);
    let mut emit = |row: i64, long: &EdgeWalker, short: &EdgeWalker| {
        let (left, right) = if long_is_left {
            (long.col, short.col)
        } else {
            (short.col, long.col)
        };
        let (c0, c1) = (left.clamp(0, cols), right.clamp(0, cols));
        if c0 < c1 {
            // All three values are within the u32 grid after clamping.
            span(row as u32, c0 as u32, c1 as u32);
        }
    };

    // Upper part: rows with y0 <= yc < y1 (non-empty implies y1 > y0).
    if row_top < row_mid {
        let mut short = EdgeWalker::new(v0, v1, row_top);
        for row in row_top..row_mid {
            emit(row, &long, &short);
            long.step();
            short.step();
        }
    }
    // Lower part: rows with y1 <= yc < y2 (non-empty implies y2 > y1).
    if row_mid < row_end {
        let mut short = EdgeWalker::new(v1, v2, row_mid);
        for row in row_mid..row_end {
            emit(row, &long, &short);
            long.step();
            short.step();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{Rng, oracle_covers};
    use super::*;

    fn fp(x: i64, y: i64) -> FixedPoint {
        FixedPoint {
            x: x as i32,
            y: y as i32,
        }
    }

    /// Coverage mask of one triangle from the scan converter, checking spans are well-formed.
    fn scan_mask(tri: [FixedPoint; 3], grid: Grid) -> Vec<u8> {
        let mut mask = vec![0u8; (grid.cols * grid.rows) as usize];
        let mut last_row = None;
        scan_triangle(tri, grid, |row, c0, c1| {
            assert!(c0 < c1 && c1 <= grid.cols && row < grid.rows);
            assert!(last_row.is_none_or(|r| r < row), "rows must increase");
            last_row = Some(row);
            for c in c0..c1 {
                mask[(row * grid.cols + c) as usize] += 1;
            }
        });
        mask
    }

    fn oracle_mask(tri: [FixedPoint; 3], grid: Grid) -> Vec<u8> {
        let mut mask = vec![0u8; (grid.cols * grid.rows) as usize];
        for r in 0..grid.rows {
            for c in 0..grid.cols {
                let centre = (i64::from(c) * ONE + HALF, i64::from(r) * ONE + HALF);
                mask[(r * grid.cols + c) as usize] = u8::from(oracle_covers(tri, centre));
            }
        }
        mask
    }

    fn assert_same(tri: [FixedPoint; 3], grid: Grid) {
        let got = scan_mask(tri, grid);
        let want = oracle_mask(tri, grid);
        if got != want {
            let bad = got.iter().zip(&want).position(|(a, b)| a != b).unwrap();
            panic!(
                "triangle {tri:?}: sub-sample ({}, {}) scan {} oracle {}",
                bad as u32 % grid.cols,
                bad as u32 / grid.cols,
                got[bad],
                want[bad]
            );
        }
    }

    #[test]
    fn random_triangles_match_exact_edge_function_oracle() {
        let grid = Grid { cols: 40, rows: 33 };
        let mut rng = Rng::new(7);
        for case in 0..3000 {
            // Alternate between arbitrary 1/256 positions, positions on a coarse lattice (many
            // centres exactly on edges and vertices) and triangles poking out of the grid.
            let (quantum, lo, hi) = match case % 3 {
                0 => (1, -3 * ONE, 43 * ONE),
                1 => (HALF, 0, 40 * ONE),
                _ => (ONE / 4, -200 * ONE, 240 * ONE),
            };
            let mut p = || {
                fp(
                    rng.range_i64(lo, hi) / quantum * quantum,
                    rng.range_i64(lo, hi) / quantum * quantum,
                )
            };
            let tri = [p(), p(), p()];
            assert_same(tri, grid);
        }
    }

    #[test]
    fn axis_aligned_and_degenerate_cases_match_oracle() {
        let grid = Grid { cols: 16, rows: 16 };
        let c = |k: i64| k * ONE + HALF; // a centre coordinate
        let cases = [
            [fp(c(2), c(2)), fp(c(10), c(2)), fp(c(2), c(10))], // flat top, vertices on centres
            [fp(c(2), c(10)), fp(c(10), c(10)), fp(c(10), c(2))], // flat bottom
            [fp(c(3), c(3)), fp(c(3), c(3)), fp(c(9), c(7))],   // two equal vertices
            [fp(c(1), c(1)), fp(c(5), c(5)), fp(c(9), c(9))],   // collinear
            [fp(0, 0), fp(16 * ONE, 0), fp(0, 16 * ONE)],       // exact half of the grid
            [fp(7, 9), fp(7, 9), fp(7, 9)],                     // a point
        ];
        for tri in cases {
            assert_same(tri, grid);
            let mut rev = tri;
            rev.swap(0, 1);
            assert_same(rev, grid);
        }
        assert!(scan_mask(cases[3], grid).iter().all(|&m| m == 0));
        assert_eq!(
            scan_mask(cases[4], grid)
                .iter()
                .map(|&m| u32::from(m))
                .sum::<u32>(),
            120
        );
    }

    #[test]
    fn a_range_of_rows_gets_the_whole_scans_spans_on_it() {
        // Random triangles, partly off the grid, raw coordinates with fractions: the walkers
        // started on a later row must land where stepping down from the top puts them.
        let grid = Grid { cols: 37, rows: 41 };
        let mut rng = Rng::new(5);
        let mut spans_checked = 0;
        for _ in 0..3000 {
            let mut point = || {
                fp(
                    rng.range_i64(-4 * ONE, 41 * ONE),
                    rng.range_i64(-4 * ONE, 45 * ONE),
                )
            };
            let tri = [point(), point(), point()];
            let mut whole = Vec::new();
            scan_triangle(tri, grid, |r, a, b| whole.push((r, a, b)));
            for rows in [0..41, 0..1, 3..17, 17..18, 40..41, 20..20, 30..60, 41..50] {
                let mut part = Vec::new();
                scan_triangle_rows(tri, grid, rows.clone(), |r, a, b| part.push((r, a, b)));
                let want: Vec<_> = whole
                    .iter()
                    .copied()
                    .filter(|s| rows.contains(&s.0))
                    .collect();
                assert_eq!(part, want, "rows {rows:?} of {tri:?}");
                spans_checked += part.len();
            }
        }
        assert!(spans_checked > 10_000, "{spans_checked}");
    }

    #[test]
    fn out_of_range_coordinates_are_ignored() {
        let grid = Grid { cols: 8, rows: 8 };
        let far = (COORD_LIMIT + 1) as i32;
        let tri = [fp(0, 0), FixedPoint { x: far, y: 0 }, fp(0, 8 * ONE)];
        assert!(scan_mask(tri, grid).iter().all(|&m| m == 0));
    }

    /// Counts how often each sub-sample is covered by a set of triangles.
    fn count(tris: &[[FixedPoint; 3]], grid: Grid) -> Vec<u32> {
        let mut counts = vec![0u32; (grid.cols * grid.rows) as usize];
        for &tri in tris {
            scan_triangle(tri, grid, |row, c0, c1| {
                for c in c0..c1 {
                    counts[(row * grid.cols + c) as usize] += 1;
                }
            });
        }
        counts
    }

    #[test]
    fn fan_around_shared_vertex_covers_each_sample_once() {
        let grid = Grid { cols: 64, rows: 64 };
        let mut rng = Rng::new(11);
        for _ in 0..20 {
            // Centre on a lattice of quarter samples, rim vertices at arbitrary 1/256 positions
            // on a convex polygon (angles sorted), so the union is that convex polygon.
            let centre = fp(
                32 * ONE + rng.range_i64(-8, 8) * ONE / 4,
                32 * ONE + rng.range_i64(-8, 8) * ONE / 4,
            );
            let n = 3 + rng.range_i64(0, 14) as usize;
            let mut angles: Vec<f64> = (0..n)
                .map(|k| (k as f64 + rng.f64() * 0.3) * std::f64::consts::TAU / n as f64)
                .collect();
            angles.sort_by(f64::total_cmp);
            let rim: Vec<FixedPoint> = angles
                .iter()
                .map(|a| {
                    fp(
                        32 * ONE + (a.cos() * 28.0 * ONE as f64) as i64,
                        32 * ONE + (a.sin() * 28.0 * ONE as f64) as i64,
                    )
                })
                .collect();
            let tris: Vec<_> = (0..n).map(|k| [centre, rim[k], rim[(k + 1) % n]]).collect();
            let counts = count(&tris, grid);
            for r in 0..grid.rows {
                for c in 0..grid.cols {
                    let centre_pt = (i64::from(c) * ONE + HALF, i64::from(r) * ONE + HALF);
                    // The union is the convex rim polygon; the oracle applies the same
                    // top-left rule to its outer edges.
                    let inside = super::super::testutil::oracle_in_convex_polygon(&rim, centre_pt);
                    assert_eq!(
                        counts[(r * grid.cols + c) as usize],
                        u32::from(inside),
                        "fan sample ({c}, {r})"
                    );
                }
            }
        }
    }

    #[test]
    fn jittered_grid_of_cells_covers_rectangle_exactly_once() {
        let grid = Grid { cols: 50, rows: 40 };
        let mut rng = Rng::new(5);
        // A 9×7 lattice of vertices; interior vertices jittered, border ones on the rectangle
        // [x0, x1) × [y0, y1), which is also the top-left-rule coverage of the rectangle.
        let (nx, ny) = (9usize, 7usize);
        let (x0, x1, y0, y1) = (3 * ONE + 77, 47 * ONE + 3, 2 * ONE + HALF, 38 * ONE + 200);
        let mut verts = vec![fp(0, 0); nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let mut x = x0 + (x1 - x0) * i as i64 / (nx - 1) as i64;
                let mut y = y0 + (y1 - y0) * j as i64 / (ny - 1) as i64;
                if i > 0 && i < nx - 1 {
                    x += rng.range_i64(-300, 300);
                }
                if j > 0 && j < ny - 1 {
                    y += rng.range_i64(-300, 300);
                }
                verts[j * nx + i] = fp(x, y);
            }
        }
        let mut tris = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let (a, b, c, d) = (
                    verts[j * nx + i],
                    verts[j * nx + i + 1],
                    verts[(j + 1) * nx + i],
                    verts[(j + 1) * nx + i + 1],
                );
                // Alternate the diagonal so both orientations of shared diagonals occur.
                if (i + j) % 2 == 0 {
                    tris.push([a, b, d]);
                    tris.push([a, d, c]);
                } else {
                    tris.push([a, b, c]);
                    tris.push([b, d, c]);
                }
            }
        }
        let counts = count(&tris, grid);
        for r in 0..grid.rows {
            for c in 0..grid.cols {
                let (xc, yc) = (i64::from(c) * ONE + HALF, i64::from(r) * ONE + HALF);
                let inside = x0 <= xc && xc < x1 && y0 <= yc && yc < y1;
                assert_eq!(
                    counts[(r * grid.cols + c) as usize],
                    u32::from(inside),
                    "grid sample ({c}, {r})"
                );
            }
        }
    }
}
