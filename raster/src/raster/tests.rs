//! End-to-end tests of the rasteriser: clip space in, coverage out.
//!
//! The scan converter's exactness is tested in `scan`; here the references are independent of
//! the fixed-point path: rays cast through sub-sample centres (for clipping and perspective) and
//! closed-form regions (for huge triangles). Those references are only compared where they are
//! unambiguous, i.e. where the reference gives the same answer at the sub-sample centre and at
//! points 0.75 sub-samples away in each direction; right on an edge the rasteriser's snapping
//! legitimately decides.

use glam::{DMat4, DVec2, DVec3, DVec4, Mat4, Vec3, Vec4};

use super::clip::clip_and_project;
use super::fixed::{FixedPoint, Grid, HALF, ONE};
use super::scan::scan_triangle;
use super::testutil::{Rng, oracle_covers};
use super::{EMPTY, VisibilityBuffer};

/// Per-sub-sample coverage counts of clip-space triangles through the real clip + scan path
/// (a counter, not the z-buffer, so double coverage is visible).
fn coverage_counts(tris: &[[Vec4; 3]], grid: Grid) -> Vec<u32> {
    let mut counts = vec![0u32; (grid.cols * grid.rows) as usize];
    for &tri in tris {
        for fan in clip_and_project(tri, grid).triangles() {
            scan_triangle(fan, grid, |row, c0, c1| {
                for c in c0..c1 {
                    counts[(row * grid.cols + c) as usize] += 1;
                }
            });
        }
    }
    counts
}

/// Compares `got(c, r)` with a reference region given in sub-sample coordinates wherever the
/// reference is unambiguous; returns how many sub-samples were compared inside and outside.
fn compare_with_region(
    grid: Grid,
    got: impl Fn(u32, u32) -> u32,
    inside: impl Fn(f64, f64) -> bool,
) -> (u32, u32) {
    let h = 0.75;
    let (mut n_in, mut n_out) = (0, 0);
    for r in 0..grid.rows {
        for c in 0..grid.cols {
            let (x, y) = (f64::from(c) + 0.5, f64::from(r) + 0.5);
            let here = inside(x, y);
            let clear = [
                (-h, 0.0),
                (h, 0.0),
                (0.0, -h),
                (0.0, h),
                (h, h),
                (-h, -h),
                (h, -h),
                (-h, h),
            ]
            .iter()
            .all(|(dx, dy)| inside(x + dx, y + dy) == here);
            if !clear {
                continue;
            }
            assert_eq!(
                got(c, r),
                u32::from(here),
                "sub-sample ({c}, {r}) reference inside = {here}"
            );
            if here { n_in += 1 } else { n_out += 1 }
        }
    }
    (n_in, n_out)
}

/// Whether the ray through sub-sample position `(sx, sy)` of `grid` meets the surface
/// `hit(origin, direction) -> Option<world point>` at a point inside the frustum of `vp`.
fn seen(
    vp: DMat4,
    grid: Grid,
    sx: f64,
    sy: f64,
    hit: impl Fn(DVec3, DVec3) -> Option<DVec3>,
) -> bool {
    let nx = 2.0 * sx / f64::from(grid.cols) - 1.0;
    let ny = 1.0 - 2.0 * sy / f64::from(grid.rows);
    let inv = vp.inverse();
    let near = inv.project_point3(DVec3::new(nx, ny, 0.0));
    let far = inv.project_point3(DVec3::new(nx, ny, 1.0));
    let Some(p) = hit(near, (far - near).normalize()) else {
        return false;
    };
    let c: DVec4 = vp * p.extend(1.0);
    c.w > 0.0 && (0.0..=c.w).contains(&c.z)
}

/// Ray / plane `z = height` intersection, in front of `origin`.
fn plane_hit(origin: DVec3, dir: DVec3, height: f64) -> Option<DVec3> {
    let t = (height - origin.z) / dir.z;
    (t.is_finite() && t >= 0.0).then(|| origin + dir * t)
}

#[test]
fn clip_space_input_at_exact_positions_matches_oracle() {
    // With a power-of-two grid and w a power of two, NDC → fixed point is exact, so the whole
    // pipeline must reproduce the oracle on the intended fixed-point vertices.
    let (w, h, aa) = (32u32, 16u32, 2u32);
    let grid = Grid {
        cols: w * aa,
        rows: h * aa,
    };
    let mut rng = Rng::new(17);
    for case in 0..500 {
        let wclip = [1.0f32, 2.0, 0.5][case % 3];
        let mut vertex = || {
            let p = FixedPoint {
                x: rng.range_i64(0, i64::from(grid.cols) * ONE + 1) as i32,
                y: rng.range_i64(0, i64::from(grid.rows) * ONE + 1) as i32,
            };
            let ndc_x = p.x as f32 / (ONE as f32 * grid.cols as f32) * 2.0 - 1.0;
            let ndc_y = 1.0 - p.y as f32 / (ONE as f32 * grid.rows as f32) * 2.0;
            (
                p,
                Vec4::new(ndc_x * wclip, ndc_y * wclip, 0.5 * wclip, wclip),
            )
        };
        let (a, b, c) = (vertex(), vertex(), vertex());
        let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
        buf.rasterize_triangle(case as u32, [a.1, b.1, c.1]);
        for r in 0..grid.rows {
            for col in 0..grid.cols {
                let centre = (i64::from(col) * ONE + HALF, i64::from(r) * ONE + HALF);
                let want = oracle_covers([a.0, b.0, c.0], centre);
                let got = buf.triangles()[(r * grid.cols + col) as usize] != EMPTY;
                assert_eq!(got, want, "case {case} sub-sample ({col}, {r})");
            }
        }
    }
}

#[test]
fn triangle_crossing_the_camera_plane_draws_only_its_visible_part() {
    let (w, h, aa) = (64u32, 48u32, 2u32);
    let grid = Grid {
        cols: w * aa,
        rows: h * aa,
    };
    let proj = Mat4::perspective_rh(60f32.to_radians(), w as f32 / h as f32, 1.0, 100.0);
    // View space, in the plane y = −0.3; corner c is behind the eye (view z > 0).
    let (a, b, c) = (
        Vec3::new(-2.0, -0.3, -4.0),
        Vec3::new(2.0, -0.3, -4.0),
        Vec3::new(0.0, -0.3, 3.0),
    );
    let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
    buf.rasterize_triangle(1, [a, b, c].map(|p| proj * p.extend(1.0)));

    let vp = proj.as_dmat4();
    let in_triangle = |p: DVec3| {
        let q = DVec2::new(p.x, p.z);
        let [a, b, c] = [a, b, c].map(|v| DVec2::new(f64::from(v.x), f64::from(v.z)));
        let e = |u: DVec2, v: DVec2| (v - u).perp_dot(q - u);
        let (e0, e1, e2) = (e(a, b), e(b, c), e(c, a));
        (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0)
    };
    // Rotate the view-space plane y = −0.3 to a z-plane for `plane_hit`: swap y and z.
    let hit = |o: DVec3, d: DVec3| {
        plane_hit(DVec3::new(o.x, o.z, o.y), DVec3::new(d.x, d.z, d.y), -0.3)
            .map(|p| DVec3::new(p.x, p.z, p.y))
    };
    let (n_in, n_out) = compare_with_region(
        grid,
        |col, r| u32::from(buf.triangles()[(r * grid.cols + col) as usize] != EMPTY),
        |x, y| seen(vp, grid, x, y, |o, d| hit(o, d).filter(|&p| in_triangle(p))),
    );
    assert!(n_in > 1000 && n_out > 1000, "{n_in} {n_out}");
    // The near-plane cut (view z = −1, screen row ≈ 0.76·rows) is on screen; the rows below it,
    // where a triangle projected without clipping would wrap around, stay empty.
    let cut_row = ((0.5 + 0.3 / 30f32.to_radians().tan() * 0.5) * grid.rows as f32) as u32;
    assert!(cut_row + 2 < grid.rows);
    let empty_row =
        |r: u32| (0..grid.cols).all(|col| buf.triangles()[(r * grid.cols + col) as usize] == EMPTY);
    assert!((cut_row + 2..grid.rows).all(empty_row));
    assert!(!empty_row(cut_row - 2));

    // Entirely behind the eye, or entirely between the eye and the near plane: nothing.
    let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
    let behind = [a, b, c].map(|p| proj * (p + Vec3::new(0.0, 0.0, 7.5)).extend(1.0));
    buf.rasterize_triangle(2, behind);
    let between = [
        Vec3::new(-1.0, -0.3, -0.5),
        Vec3::new(1.0, -0.3, -0.5),
        Vec3::new(0.0, 0.3, -0.9),
    ];
    buf.rasterize_triangle(3, between.map(|p| proj * p.extend(1.0)));
    assert!(buf.triangles().iter().all(|&t| t == EMPTY));
}

#[test]
fn ground_grid_through_near_plane_is_watertight() {
    // A jittered grid on the ground plane z = 0, extending behind the camera (crossing the near
    // and eye planes) and past the image sides: every visible sub-sample is covered exactly
    // once, none twice, the sky never.
    let (w, h, aa) = (96u32, 64u32, 2u32);
    let grid = Grid {
        cols: w * aa,
        rows: h * aa,
    };
    let view = Mat4::look_at_rh(Vec3::new(0.3, -0.2, 1.5), Vec3::new(0.0, 8.0, 0.2), Vec3::Z);
    let proj = Mat4::perspective_rh(70f32.to_radians(), w as f32 / h as f32, 0.5, 60.0);
    let vp = proj * view;
    let (n, half) = (24usize, 20.0f32);
    let mut rng = Rng::new(23);
    let mut verts = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let step = 2.0 * half / n as f32;
            let jitter = |k: usize, rng: &mut Rng| {
                if k == 0 || k == n {
                    0.0
                } else {
                    rng.f32_in(-0.3, 0.3) * step
                }
            };
            let x = -half + i as f32 * step + jitter(i, &mut rng);
            let y = -half + j as f32 * step + jitter(j, &mut rng);
            verts.push(vp * Vec4::new(x, y, 0.0, 1.0));
        }
    }
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let k = j * (n + 1) + i;
            let (a, b, c, d) = (verts[k], verts[k + 1], verts[k + n + 1], verts[k + n + 2]);
            if rng.f64() < 0.5 {
                tris.extend([[a, b, d], [a, d, c]]);
            } else {
                tris.extend([[a, b, c], [b, d, c]]);
            }
        }
    }
    let counts = coverage_counts(&tris, grid);
    assert!(counts.iter().all(|&k| k <= 1), "double coverage");
    let on_ground = |o: DVec3, d: DVec3| {
        plane_hit(o, d, 0.0).filter(|p| p.x.abs() <= 20.0 && p.y.abs() <= 20.0)
    };
    let (n_in, n_out) = compare_with_region(
        grid,
        |c, r| counts[(r * grid.cols + c) as usize],
        |x, y| seen(vp.as_dmat4(), grid, x, y, on_ground),
    );
    assert!(n_in > 5000 && n_out > 1000, "{n_in} {n_out}");
}

#[test]
fn huge_triangles_cover_exactly_their_part_of_the_viewport() {
    let (w, h, aa) = (40u32, 30u32, 2u32);
    let grid = Grid {
        cols: w * aa,
        rows: h * aa,
    };
    for big in [1e6f32, 1e15, 1e30, 3e38] {
        // Contains the whole viewport.
        let all = [
            Vec4::new(-big, -big, 0.5, 1.0),
            Vec4::new(big, -big, 0.5, 1.0),
            Vec4::new(0.0, big, 0.5, 1.0),
        ];
        assert!(
            coverage_counts(&[all], grid).iter().all(|&k| k == 1),
            "{big}"
        );
        // Half-plane ndc_y < ndc_x through the viewport diagonal.
        let half = [
            Vec4::new(-big, -big, 0.5, 1.0),
            Vec4::new(big, big, 0.5, 1.0),
            Vec4::new(big, -big, 0.5, 1.0),
        ];
        let counts = coverage_counts(&[half], grid);
        let (n_in, n_out) = compare_with_region(
            grid,
            |c, r| counts[(r * grid.cols + c) as usize],
            |x, y| {
                let (nx, ny) = (
                    2.0 * x / f64::from(grid.cols) - 1.0,
                    1.0 - 2.0 * y / f64::from(grid.rows),
                );
                ny < nx
            },
        );
        assert!(n_in > 1000 && n_out > 1000, "{big}: {n_in} {n_out}");
        // The same through the buffer, including depth.
        let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
        buf.rasterize_triangle(9, half);
        let drawn: Vec<u32> = buf.triangles().iter().map(|&t| u32::from(t == 9)).collect();
        assert_eq!(drawn, counts);
        assert!(buf.depths().iter().all(|&d| d == 0.5 || d == f32::INFINITY));
    }
}

#[test]
fn degenerate_and_hostile_input_never_panics_or_draws_garbage() {
    let (w, h, aa) = (20u32, 10u32, 3u32);
    let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
    let v = |x: f32, y: f32, z: f32, w: f32| Vec4::new(x, y, z, w);
    let nothing = [
        [
            v(0.0, 0.0, 0.5, 1.0),
            v(0.5, 0.5, 0.5, 1.0),
            v(-0.5, -0.5, 0.5, 1.0),
        ], // collinear
        [v(0.1, 0.2, 0.5, 1.0); 3], // a point
        [
            v(f32::NAN, 0.0, 0.5, 1.0),
            v(1.0, 0.0, 0.5, 1.0),
            v(0.0, 1.0, 0.5, 1.0),
        ],
        [
            v(0.0, 0.0, 0.5, f32::INFINITY),
            v(1.0, 0.0, 0.5, 1.0),
            v(0.0, 1.0, 0.5, 1.0),
        ],
        [v(0.0, 0.0, 0.0, 0.0); 3], // homogeneous origin
        [
            v(1e30, 1e30, 0.5, 1e-30),
            v(1e30, 2e30, 0.5, 1e-30),
            v(3e30, 1e30, 0.5, 1e-30),
        ], // far off
        [
            v(-1.0, -1.0, 0.5, -1.0),
            v(1.0, -1.0, 0.5, -1.0),
            v(0.0, 1.0, 0.5, -1.0),
        ], // w < 0
    ];
    for tri in nothing {
        buf.rasterize_triangle(1, tri);
        assert!(buf.triangles().iter().all(|&t| t == EMPTY), "{tri:?}");
    }
    // Fuzz: any finite or non-finite mix must not panic; what is drawn has valid depth.
    let mut rng = Rng::new(99);
    let specials = [
        0.0f32,
        -0.0,
        1.0,
        -1.0,
        1e-45,
        1e-30,
        1e30,
        3.4e38,
        -3.4e38,
        f32::NAN,
        f32::INFINITY,
    ];
    for _ in 0..20_000 {
        let mut c = || {
            if rng.f64() < 0.3 {
                specials[rng.range_i64(0, specials.len() as i64) as usize]
            } else {
                rng.f32_in(-3.0, 3.0)
            }
        };
        let tri = [
            v(c(), c(), c(), c()),
            v(c(), c(), c(), c()),
            v(c(), c(), c(), c()),
        ];
        buf.rasterize_triangle(2, tri);
    }
    assert!(
        buf.depths()
            .iter()
            .all(|&d| (0.0..=1.0).contains(&d) || d == f32::INFINITY)
    );
    // Mesh with garbage positions and indices.
    let positions = [
        Vec3::NAN,
        Vec3::splat(1e30),
        Vec3::ZERO,
        Vec3::new(0.5, 0.5, 0.5),
    ];
    buf.rasterize_mesh(
        Mat4::IDENTITY,
        &positions,
        &[[0, 1, 2], [1, 2, 3], [3, 3, 3], [7, 8, 9]],
        5,
    );
}
