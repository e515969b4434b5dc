//! The visibility buffer against scalar and whole-image references.

use super::super::testutil::Rng;
use super::*;

/// A clip-space vertex at sub-sample position `(sx, sy)` of a `cols × rows` grid, `w = 1`.
pub(crate) fn at(sx: f32, sy: f32, z: f32, cols: u32, rows: u32) -> Vec4 {
    Vec4::new(
        2.0 * sx / cols as f32 - 1.0,
        1.0 - 2.0 * sy / rows as f32,
        z,
        1.0,
    )
}

#[test]
fn constructor_validates_before_allocating() {
    assert_eq!(
        VisibilityBuffer::new(0, 5, 2).unwrap_err(),
        RasterError::EmptyImage {
            width: 0,
            height: 5
        }
    );
    assert_eq!(
        VisibilityBuffer::new(5, 0, 2).unwrap_err(),
        RasterError::EmptyImage {
            width: 5,
            height: 0
        }
    );
    assert_eq!(
        VisibilityBuffer::new(5, 5, 0).unwrap_err(),
        RasterError::InvalidAa { aa: 0 }
    );
    assert_eq!(
        VisibilityBuffer::new(5, 5, 9).unwrap_err(),
        RasterError::InvalidAa { aa: 9 }
    );
    // 2^14 × 2^14 pixels at aa = 2 is 2^30 sub-samples; u32::MAX overflows the axis limit.
    let err = VisibilityBuffer::new(1 << 14, 1 << 14, 2).unwrap_err();
    assert_eq!(
        err,
        RasterError::TooLarge {
            width: 1 << 14,
            height: 1 << 14,
            aa: 2
        }
    );
    assert!(err.to_string().contains("16384×16384"), "{err}");
    assert!(VisibilityBuffer::new(u32::MAX, 1, 8).is_err());
    assert!(VisibilityBuffer::new(1 << 20, 1, 2).is_err());
    let ok = VisibilityBuffer::new(3, 2, 2).unwrap();
    assert_eq!((ok.grid_size(), ok.depths().len()), ((6, 4), 24));
    assert!(ok.triangles().iter().all(|&t| t == EMPTY));
}

#[test]
fn depth_test_keeps_nearest_and_earlier_on_ties() {
    let (w, h, aa) = (8, 8, 2);
    let (cols, rows) = (w * aa, h * aa);
    let tri = |z: f32| {
        [
            at(0.0, 0.0, z, cols, rows),
            at(16.0, 0.0, z, cols, rows),
            at(0.0, 16.0, z, cols, rows),
        ]
    };
    for order in [[(1, 0.5), (2, 0.25)], [(2, 0.25), (1, 0.5)]] {
        let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
        for (id, z) in order {
            buf.rasterize_triangle(id, tri(z));
        }
        // The nearer triangle (id 2) wins everywhere, whatever the order.
        let drawn: Vec<_> = buf.triangles().iter().filter(|&&t| t != EMPTY).collect();
        assert_eq!(drawn.len(), 120);
        assert!(drawn.iter().all(|&&t| t == 2));
        assert!(
            buf.depths()
                .iter()
                .all(|&d| d == 0.25 || d == f32::INFINITY)
        );
    }
    // Equal depth: the first drawn stays.
    let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
    buf.rasterize_triangle(7, tri(0.5));
    buf.rasterize_triangle(3, tri(0.5));
    assert!(buf.triangles().iter().all(|&t| t == 7 || t == EMPTY));
    // A triangle exactly at the far plane (z = 1) still draws into an empty buffer.
    buf.clear();
    buf.rasterize_triangle(4, tri(1.0));
    assert_eq!(buf.sample(0, 0, 0, 0), Some((4, 1.0)));
}

#[test]
fn interpolated_depth_matches_affine_reference() {
    let (w, h, aa) = (16u32, 12u32, 3u32);
    let (cols, rows) = (w * aa, h * aa);
    let v = [
        (1.0f32, 2.0f32, 0.1f32),
        (45.0, 7.0, 0.9),
        (10.0, 35.0, 0.4),
    ];
    let mut buf = VisibilityBuffer::new(w, h, aa).unwrap();
    buf.rasterize_triangle(0, v.map(|(x, y, z)| at(x, y, z, cols, rows)));
    // Reference: barycentric interpolation at the sub-sample centre.
    let (a, b, c) = (v[0], v[1], v[2]);
    let area = (b.0 - a.0) * (c.1 - a.1) - (c.0 - a.0) * (b.1 - a.1);
    let mut covered = 0;
    for r in 0..rows {
        for col in 0..cols {
            let idx = (r * cols + col) as usize;
            if buf.triangles()[idx] == EMPTY {
                continue;
            }
            covered += 1;
            let (px, py) = (col as f32 + 0.5, r as f32 + 0.5);
            let l1 = ((px - a.0) * (c.1 - a.1) - (c.0 - a.0) * (py - a.1)) / area;
            let l2 = ((b.0 - a.0) * (py - a.1) - (px - a.0) * (b.1 - a.1)) / area;
            let z = a.2 + l1 * (b.2 - a.2) + l2 * (c.2 - a.2);
            assert!(
                (buf.depths()[idx] - z).abs() < 1e-4,
                "({col}, {r}): {} vs {z}",
                buf.depths()[idx]
            );
        }
    }
    assert!(covered > 300, "{covered}");
}

#[test]
fn chunked_span_matches_scalar_loop() {
    let mut rng = super::super::testutil::Rng::new(41);
    for len in 0..40usize {
        let old_d: Vec<f32> = (0..len)
            .map(|_| {
                if rng.f64() < 0.2 {
                    f32::INFINITY
                } else {
                    rng.f32_in(0.0, 1.0)
                }
            })
            .collect();
        let old_t: Vec<u32> = (0..len).map(|k| k as u32).collect();
        let (z0, dz) = (rng.f32_in(-0.2, 1.2), rng.f32_in(-0.1, 0.1));
        let first = (len % 5) as f32 * 3.0;
        let (mut d, mut t) = (old_d.clone(), old_t.clone());
        depth_test_span(&mut d, &mut t, z0, dz, first, 99);
        for k in 0..len {
            let z = (z0 + dz * (first + k as f32)).clamp(0.0, 1.0);
            let (want_d, want_t) = if z < old_d[k] {
                (z, 99)
            } else {
                (old_d[k], old_t[k])
            };
            assert_eq!(
                (d[k].to_bits(), t[k]),
                (want_d.to_bits(), want_t),
                "len {len} k {k}"
            );
        }
    }
}

/// A mesh drawn in runs, each into a buffer of its own, then merged, gives the buffer of
/// one run to the bit: ties in depth (copies of triangles, a shared plane) go to the lowest
/// id, triangles crossing the eye plane and bad indices are handled as one run handles
/// them, and ids stop below [`EMPTY`] in every run.
#[test]
fn runs_merged_are_one_run() {
    let mut rng = Rng::new(0x9e37_79b9_7f4a_7c15);
    let mut next = || rng.f32_in(0.0, 1.0);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for k in 0..600u32 {
        let centre = Vec3::new(next() * 2.4 - 1.2, next() * 2.4 - 1.2, 0.0);
        // Depths on a few levels only, so that many triangles tie.
        let z = (next() * 4.0).floor() * 0.25 - 0.25 + if k % 50 == 0 { -1.5 } else { 0.0 };
        let size = 0.05 + next() * 0.6;
        let base = positions.len() as u32;
        for _ in 0..3 {
            let offset = Vec3::new(next() - 0.5, next() - 0.5, 0.0) * size;
            positions.push(centre + offset + Vec3::Z * z);
        }
        triangles.push([base, base + 1, base + 2]);
        if k % 7 == 0 {
            triangles.push([base, base + 1, base + 2]); // an exact copy: a tie
        }
        if k % 97 == 0 {
            triangles.push([base, base + 1, 1 << 30]); // a bad index
        }
    }
    let proj = Mat4::perspective_rh(1.0, 1.0, 0.1, 10.0)
        * Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0));
    for first_id in [0, 7, u32::MAX - 400] {
        let mut one = VisibilityBuffer::new(24, 20, 2).unwrap();
        one.draw_in_runs(proj, &positions, &triangles, first_id, 1);
        assert!(one.triangles().iter().filter(|&&t| t != EMPTY).count() > 500);
        for runs in [2, 3, 5, 16] {
            let mut merged = VisibilityBuffer::new(24, 20, 2).unwrap();
            merged.draw_in_runs(proj, &positions, &triangles, first_id, runs);
            assert_eq!(merged.triangles(), one.triangles(), "{runs} runs");
            let bits = |b: &VisibilityBuffer| -> Vec<u32> {
                b.depths().iter().map(|d| d.to_bits()).collect()
            };
            assert_eq!(bits(&merged), bits(&one), "{runs} runs");
        }
    }
}

/// A buffer holding a window of the image has, at every sub-sample of the window, the
/// whole image's triangle and depth to the bit: spans cut at the window's left edge keep
/// the depths counted from their start, rows above it are skipped exactly, triangles
/// skipped as missing the window miss it (an eighth cross the eye plane, where a projected
/// triangle is not the hull of its projected corners), and a mesh drawn in runs merges
/// alike.
#[test]
fn a_window_holds_the_whole_images_bits() {
    let mut rng = Rng::new(0x5eed);
    let mut next = || rng.f32_in(0.0, 1.0);
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for k in 0..400u32 {
        let mut centre = Vec3::new(next() * 2.6 - 1.3, next() * 2.6 - 1.3, next() - 0.5);
        if k % 8 == 0 {
            centre.z += 1.8;
        }
        let size = 0.05 + next() * 0.9;
        let base = positions.len() as u32;
        for _ in 0..3 {
            // Tilted: each corner at its own depth, so that depths vary along a span.
            let offset = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * size;
            positions.push(centre + offset);
        }
        triangles.push([base, base + 1, base + 2]);
    }
    let proj = Mat4::perspective_rh(1.0, 1.0, 0.1, 10.0)
        * Mat4::from_translation(Vec3::new(0.0, 0.0, -1.5));
    let (w, h) = (37u32, 29u32);
    for aa in [1, 2, 3] {
        let mut whole = VisibilityBuffer::new(w, h, aa).unwrap();
        whole.draw_in_runs(proj, &positions, &triangles, 0, 1);
        let windows = [
            Region::full(w, h),
            Region {
                x0: 5,
                y0: 3,
                x1: 20,
                y1: 17,
            },
            Region {
                x0: 0,
                y0: 28,
                x1: 37,
                y1: 29,
            },
            Region {
                x0: 36,
                y0: 0,
                x1: 37,
                y1: 29,
            },
            Region {
                x0: 11,
                y0: 11,
                x1: 12,
                y1: 12,
            },
        ];
        let mut seen = 0;
        for (k, window) in windows.into_iter().enumerate() {
            let mut part = VisibilityBuffer::new_window(w, h, aa, window).unwrap();
            part.draw_in_runs(proj, &positions, &triangles, 0, 1 + k % 3);
            let held = (window.width() * window.height() * aa * aa) as usize;
            assert_eq!(part.depths().len(), held);
            for y in window.y0..window.y1 {
                for x in window.x0..window.x1 {
                    for (i, j) in (0..aa).flat_map(|j| (0..aa).map(move |i| (i, j))) {
                        let bits = |b: &VisibilityBuffer| {
                            b.sample(x, y, i, j).map(|(t, d)| (t, d.to_bits()))
                        };
                        assert_eq!(bits(&part), bits(&whole), "aa {aa} {window} ({x}, {y})");
                        seen += usize::from(bits(&part).is_some());
                    }
                }
            }
        }
        assert!(
            seen > 1000 * (aa * aa) as usize,
            "aa {aa}: {seen} sub-samples drawn"
        );
    }
}

/// A triangle with a corner behind the eye whose projected corners all lie left of the
/// window still covers it: beyond the eye plane its projection wraps to the right. The
/// window's cull tests the corners in clip space, where the triangle is their hull.
#[test]
fn a_triangle_through_the_eye_plane_is_not_culled_by_its_projected_corners() {
    let clip = [
        Vec4::new(-1.0, -0.5, 0.5, 1.0),
        Vec4::new(2.0, 0.0, -0.5, -1.0), // behind the eye: x/w = −2
        Vec4::new(-1.0, 0.5, 0.5, 1.0),
    ];
    let right = Region {
        x0: 8,
        y0: 0,
        x1: 16,
        y1: 16,
    };
    let mut whole = VisibilityBuffer::new(16, 16, 1).unwrap();
    let mut part = VisibilityBuffer::new_window(16, 16, 1, right).unwrap();
    whole.rasterize_triangle(1, clip);
    part.rasterize_triangle(1, clip);
    let drawn = |b: &VisibilityBuffer| {
        (8..16)
            .flat_map(|x| (0..16).map(move |y| (x, y)))
            .filter(|&(x, y)| b.sample(x, y, 0, 0).is_some())
            .count()
    };
    assert!(drawn(&whole) > 4, "{}", drawn(&whole));
    assert_eq!(drawn(&part), drawn(&whole));
}

#[test]
fn a_window_is_checked_and_bounds_only_its_own_size() {
    let outside = Region {
        x0: 2,
        y0: 2,
        x1: 9,
        y1: 4,
    };
    assert_eq!(
        VisibilityBuffer::new_window(8, 8, 2, outside).unwrap_err(),
        RasterError::WindowOutside {
            window: outside,
            width: 8,
            height: 8
        }
    );
    let empty = Region {
        x0: 3,
        y0: 3,
        x1: 3,
        y1: 5,
    };
    assert!(VisibilityBuffer::new_window(8, 8, 2, empty).is_err());
    // 16384² pixels at aa = 2 exceed the sub-samples a buffer may hold; a window of it
    // does not, so tiles can render images larger than one buffer.
    assert!(VisibilityBuffer::new(1 << 14, 1 << 14, 2).is_err());
    let tile = Region {
        x0: 9000,
        y0: 100,
        x1: 9512,
        y1: 612,
    };
    let buf = VisibilityBuffer::new_window(1 << 14, 1 << 14, 2, tile).unwrap();
    assert_eq!(buf.depths().len(), 512 * 512 * 4);
    assert_eq!((buf.grid_size(), buf.window()), ((1 << 15, 1 << 15), tile));
    // The axis limit stays the image's: the fixed-point grid spans the whole image.
    let small = Region {
        x0: 0,
        y0: 0,
        x1: 1,
        y1: 1,
    };
    assert!(VisibilityBuffer::new_window(1 << 20, 1, 2, small).is_err());
}

#[test]
fn mesh_ids_are_offset_and_bad_indices_skipped() {
    let (w, h) = (8u32, 8u32);
    let positions = [
        Vec3::new(-1.0, 1.0, 0.5),
        Vec3::new(1.0, 1.0, 0.5),
        Vec3::new(-1.0, -1.0, 0.5),
        Vec3::new(1.0, -1.0, 0.5),
    ];
    // Top-left half, a bad triangle, bottom-right half.
    let tris = [[0, 1, 2], [0, 1, 99], [1, 3, 2]];
    let mut buf = VisibilityBuffer::new(w, h, 1).unwrap();
    buf.rasterize_mesh(Mat4::IDENTITY, &positions, &tris, 100);
    let ids: Vec<u32> = buf.triangles().to_vec();
    assert!(ids.iter().all(|&t| t == 100 || t == 102), "{ids:?}");
    // The diagonal's 8 centres lie on both triangles' shared edge; it is a right edge of the
    // top-left triangle and a left edge of the other, so the other gets them.
    assert_eq!(ids.iter().filter(|&&t| t == 100).count(), 28); // 7 + 6 + … + 1
    assert_eq!(ids.iter().filter(|&&t| t == 102).count(), 36); // 8 + 7 + … + 1
    // Ids never reach EMPTY: only the first triangle fits below u32::MAX.
    buf.clear();
    buf.rasterize_mesh(
        Mat4::IDENTITY,
        &positions,
        &[[0, 1, 2], [1, 3, 2]],
        u32::MAX - 1,
    );
    assert!(
        buf.triangles()
            .iter()
            .all(|&t| t == u32::MAX - 1 || t == EMPTY)
    );
    assert_eq!(buf.triangles().iter().filter(|&&t| t == EMPTY).count(), 36);
}
