//! Tests of the restricted Voronoi areas: the sum, a brute-force oracle, a regular grid,
//! determinism, coincident samples, degenerate and thin geometry, the redo path.

use glam::Vec3;

use super::*;
use crate::geometry::shapes::{grid, icosphere};
use crate::sampling::rng::Pcg32;
use crate::sampling::{SampleTarget, poisson_samples, total_area};

/// A sphere above a floor (curved and flat, different triangle sizes).
fn sphere_and_plane() -> Vec<[Vec3; 3]> {
    crate::sampling::tests::sphere_over_floor(2)
}

fn poisson(tris: &[[Vec3; 3]], n: u32, seed: u64) -> Vec<Vec3> {
    poisson_samples(tris, SampleTarget::Count(n), seed)
        .unwrap()
        .iter()
        .map(|p| p.position)
        .collect()
}

fn sum(a: &[f32]) -> f64 {
    a.iter().map(|&x| x as f64).sum()
}

/// The areas sum to the mesh area and are all positive.
fn check_sum(tris: &[[Vec3; 3]], r: &VoronoiAreas, tolerance: f64) {
    let total = total_area(tris);
    let got = sum(&r.areas);
    assert!(
        ((got - total) / total).abs() < tolerance,
        "sum {got} vs area {total} ({:e} relative), {:?}",
        (got - total) / total,
        r.stats
    );
    assert!(r.areas.iter().all(|&a| a > 0.0), "{:?}", r.stats);
}

#[test]
fn areas_sum_to_the_surface_area() {
    let tris = sphere_and_plane();
    for (n, seed) in [(1, 1), (7, 2), (500, 3), (5000, 4)] {
        let sites = poisson(&tris, n, seed);
        let r = voronoi_areas(&tris, &sites);
        check_sum(&tris, &r, 1e-6);
        assert_eq!(r.stats.empty, 0);
        // Not all equal: the cells follow the arrangement.
        if n > 100 {
            let mean = total_area(&tris) / n as f64;
            let spread = r
                .areas
                .iter()
                .map(|&a| (a as f64 / mean - 1.0).abs())
                .fold(0.0, f64::max);
            assert!(spread > 0.05 && spread < 3.0, "spread {spread}");
        }
    }
    // The bunny: 3674 triangles of very different sizes, thin ears.
    let bunny =
        crate::scene::obj::parse_obj(include_bytes!("../../../../assets/bunny.obj")).unwrap();
    let tris: Vec<[Vec3; 3]> = bunny
        .triangles
        .iter()
        .map(|t| t.map(|i| bunny.positions[i as usize]))
        .collect();
    let r = voronoi_areas(&tris, &poisson(&tris, 20_000, 1));
    check_sum(&tris, &r, 1e-6);
}

/// Brute force: every triangle cut into `n²` sub-triangles, each given whole to the sample
/// nearest its centroid.
fn oracle(tris: &[[Vec3; 3]], sites: &[Vec3], n: u32) -> Vec<f64> {
    oracle_cells(tris, sites, n)
        .into_iter()
        .map(|(a, _)| a)
        .collect()
}

/// [`oracle`]'s areas with the cells' centroids (not moved onto the surface).
fn oracle_cells(tris: &[[Vec3; 3]], sites: &[Vec3], n: u32) -> Vec<(f64, glam::DVec3)> {
    let mut cells = vec![(0.0f64, glam::DVec3::ZERO); sites.len()];
    for t in tris {
        for sub in grid_of_triangle(t, n) {
            let c = (sub[0] + sub[1] + sub[2]) / 3.0;
            let nearest = (0..sites.len())
                .min_by(|&a, &b| {
                    let (da, db) = (
                        c.distance_squared(sites[a].as_dvec3()),
                        c.distance_squared(sites[b].as_dvec3()),
                    );
                    da.total_cmp(&db)
                })
                .unwrap();
            let a = 0.5 * (sub[1] - sub[0]).cross(sub[2] - sub[0]).length();
            cells[nearest].0 += a;
            cells[nearest].1 += c * a;
        }
    }
    for (a, first) in &mut cells {
        *first /= a.max(f64::MIN_POSITIVE);
    }
    cells
}

/// Every centroid lies on its triangle, at the barycentrics it reports.
fn check_on_surface(tris: &[[Vec3; 3]], r: &VoronoiAreas) {
    for c in &r.centroids {
        let t = &tris[c.triangle as usize];
        let (b1, b2) = (c.bary.x, c.bary.y);
        assert!(b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 + 1e-6, "{c:?}");
        let q = t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2;
        let scale = t[0]
            .abs()
            .max(t[1].abs())
            .max(t[2].abs())
            .max_element()
            .max(1.0);
        assert!(q.distance(c.position) < 1e-5 * scale, "{c:?} vs {q}");
    }
}

/// The `n²` sub-triangles of a triangle (f64).
fn grid_of_triangle(t: &[Vec3; 3], n: u32) -> Vec<[glam::DVec3; 3]> {
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    let p = |i: u32, j: u32| a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64);
    let mut out = Vec::new();
    for j in 0..n {
        for i in 0..n - j {
            out.push([p(i, j), p(i + 1, j), p(i, j + 1)]);
            if i + j + 1 < n {
                out.push([p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
    }
    out
}

#[test]
fn matches_a_brute_force_oracle_within_its_discretisation_error() {
    // A coarse sphere and a tilted square: 80 + 8 triangles, 60 samples.
    let mut tris = icosphere(1, Vec3::new(0.0, 0.0, 0.0), 1.0);
    tris.extend(grid(
        Vec3::new(-1.5, -1.5, -1.3),
        Vec3::new(3.0, 0.0, 0.4),
        Vec3::Y * 3.0,
        2,
        2,
    ));
    let sites = poisson(&tris, 60, 5);
    let r = voronoi_areas(&tris, &sites);
    check_sum(&tris, &r, 1e-6);
    let mean = total_area(&tris) / sites.len() as f64;
    let errors = |n: u32| -> f64 {
        let o = oracle(&tris, &sites, n);
        r.areas
            .iter()
            .zip(&o)
            .map(|(&a, &b)| (a as f64 - b).abs() / mean)
            .fold(0.0, f64::max)
    };
    // A misassigned sub-triangle lies on a cell's boundary: the error is at most the cell's
    // perimeter (≈ 4√mean) times a sub-triangle's size, and it falls as that does. Errors on
    // the two sides of a boundary mostly cancel, so a quarter of that bound is asserted
    // (measured: 4.1e-2 of the mean area at 16², 1.05e-2 at 64², against 4.0e-2).
    let (coarse, fine) = (errors(16), errors(64));
    let edge = 3.0 / 2.0 / 64.0; // the plane's triangles are the largest: 1.5 units
    let bound = mean.sqrt() * edge / mean;
    println!(
        "oracle: max error {coarse:.2e} (16²), {fine:.2e} (64²) of the mean area, bound {bound:.2e}"
    );
    assert!(
        fine < bound,
        "max error {fine} of the mean area, bound {bound}"
    );
    assert!(
        fine < 0.5 * coarse,
        "error does not fall: {coarse} → {fine}"
    );
    // Centroids: the oracle's are those of the sub-triangles' union, off the surface where a
    // cell bends over the sphere's edges (by up to 0.15 spacings on this coarse sphere). Each
    // reported centroid must be as near to the oracle's as the surface allows: the distance
    // beyond the oracle's own distance to the surface, in units of the spacing √mean
    // (measured: 2.6e-2 at 16², 4.5e-3 at 64²).
    check_on_surface(&tris, &r);
    let centroid_error = |n: u32| -> f64 {
        oracle_cells(&tris, &sites, n)
            .iter()
            .zip(&r.centroids)
            .map(|(&(_, c), got)| {
                let depth = tris
                    .iter()
                    .map(|t| distance2_to_triangle(c, t))
                    .fold(f64::INFINITY, f64::min)
                    .sqrt();
                (c.distance(got.position.as_dvec3()) - depth) / mean.sqrt()
            })
            .fold(0.0, f64::max)
    };
    let (coarse, fine) = (centroid_error(16), centroid_error(64));
    println!("oracle: centroids within {coarse:.2e} (16²), {fine:.2e} (64²) of the spacing");
    assert!(fine < 0.02 && fine < coarse, "{coarse} → {fine}");
}

#[test]
fn a_regular_grid_of_samples_gets_exactly_its_grid_cells() {
    // A 10 × 10 plane in 8 × 8 quads, samples on a 0.5 lattice offset by 0.1 from the corner:
    // interior cells are 0.5 × 0.5; border cells are cut by the plane's edge.
    let tris = grid(Vec3::ZERO, Vec3::X * 10.0, Vec3::Y * 10.0, 8, 8);
    let mut sites = Vec::new();
    for j in 0..20 {
        for i in 0..20 {
            sites.push(Vec3::new(0.1 + 0.5 * i as f32, 0.1 + 0.5 * j as f32, 0.0));
        }
    }
    let r = voronoi_areas(&tris, &sites);
    check_sum(&tris, &r, 1e-6);
    for j in 0..20 {
        for i in 0..20 {
            let a = r.areas[j * 20 + i] as f64;
            let width = |k: usize| match k {
                0 => 0.35,
                19 => 10.0 - 9.35,
                _ => 0.5,
            };
            let want = width(i) * width(j);
            assert!((a - want).abs() < 1e-5, "cell ({i}, {j}): {a} vs {want}");
            // The centroid: the site's own position inside, the middle of the cut cell at
            // the border.
            let middle = |k: usize| match k {
                0 => 0.175,
                19 => 9.675,
                _ => 0.1 + 0.5 * k as f32,
            };
            let c = r.centroids[j * 20 + i].position;
            let want = Vec3::new(middle(i), middle(j), 0.0);
            assert!(
                c.distance(want) < 1e-5,
                "cell ({i}, {j}): centroid {c} vs {want}"
            );
        }
    }
}

#[test]
fn the_same_bits_for_any_thread_count() {
    let tris = sphere_and_plane();
    let sites = poisson(&tris, 3000, 9);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| voronoi_areas(&tris, &sites))
    };
    let one = run(1);
    for threads in [2, 3] {
        let other = run(threads);
        assert_eq!(
            one.areas.iter().map(|a| a.to_bits()).collect::<Vec<_>>(),
            other.areas.iter().map(|a| a.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(one.stats, other.stats);
        assert_eq!(one.centroids, other.centroids);
    }
}

#[test]
fn coincident_samples_share_their_cell() {
    let tris = grid(Vec3::ZERO, Vec3::X * 4.0, Vec3::Y * 4.0, 4, 4);
    let mut sites = poisson(&tris, 200, 2);
    let alone = voronoi_areas(&tris, &sites);
    sites.push(sites[17]);
    sites.push(sites[17]);
    let r = voronoi_areas(&tris, &sites);
    check_sum(&tris, &r, 1e-6);
    assert_eq!(r.stats.shared, 3);
    for k in [17, 200, 201] {
        assert!((r.areas[k] - alone.areas[17] / 3.0).abs() < 1e-6 * alone.areas[17]);
    }
    assert_eq!(r.areas[16], alone.areas[16]);
}

#[test]
fn degenerate_triangles_own_nothing_and_non_finite_sites_are_skipped() {
    let mut tris = sphere_and_plane();
    let sites = poisson(&tris, 800, 3);
    let plain = voronoi_areas(&tris, &sites);
    // Zero-area triangles (a point, a line) and a near-sliver inside the floor.
    let (a, b) = (Vec3::new(0.3, 0.2, 0.0), Vec3::new(0.9, 0.2, 0.0));
    tris.push([a, a, a]);
    tris.push([a, b, (a + b) * 0.5]);
    tris.push([Vec3::splat(f32::NAN), a, b]);
    let mut with_nan = sites.clone();
    with_nan.push(Vec3::new(f32::NAN, 0.0, 0.0));
    let r = voronoi_areas(&tris, &with_nan);
    assert_eq!(r.areas[sites.len()], 0.0);
    assert_eq!(&r.areas[..sites.len()], &plain.areas[..]);
}

#[test]
fn centroids_lie_on_triangles_with_area() {
    // An L of two unit squares, in z = 0 and in x = 0, and one site on their shared edge: its
    // cell is the whole L, whose centroid (1/4, 1/2, 1/4) lies off both. A triangle shrunk to
    // a point right there has no area, and lies among the floor's triangles in their patches.
    let mut tris = grid(Vec3::ZERO, Vec3::X, Vec3::Y, 8, 8);
    let c = Vec3::new(0.25, 0.5, 0.25);
    tris.insert(70, [c; 3]);
    tris.extend(grid(Vec3::ZERO, Vec3::Y, Vec3::Z, 8, 8));
    let r = voronoi_areas(&tris, &[Vec3::new(0.0, 0.5, 0.0)]);
    assert!((r.areas[0] - 2.0).abs() < 1e-6, "{}", r.areas[0]);
    assert_ne!(r.centroids[0].triangle, 70);
    check_on_surface(&tris, &r);
    let off = r.centroids[0].position.distance(c);
    assert!((off - 0.25).abs() < 1e-5, "{off}");
}

#[test]
fn thin_sheets_and_holes_keep_the_sum_exact() {
    // Two parallel squares 0.02 apart (far thinner than the spacing) with samples on both:
    // cells reach through, the sum stays exact.
    let mut tris = grid(Vec3::ZERO, Vec3::X * 3.0, Vec3::Y * 3.0, 3, 3);
    tris.extend(grid(
        Vec3::new(0.0, 3.0, 0.02),
        Vec3::X * 3.0,
        Vec3::NEG_Y * 3.0,
        3,
        3,
    ));
    let sites = poisson(&tris, 400, 4);
    let r = voronoi_areas(&tris, &sites);
    check_sum(&tris, &r, 1e-6);

    // A plane whose samples leave a hole 3 spacings wide, and a far triangle with none: those
    // triangles are redone with a wider reach.
    let mut tris = grid(Vec3::ZERO, Vec3::X * 6.0, Vec3::Y * 6.0, 24, 24);
    let mut rng = Pcg32::new(8, 1);
    let sites: Vec<Vec3> = (0..2000)
        .map(|_| Vec3::new(rng.next_f32() * 6.0, rng.next_f32() * 6.0, 0.0))
        .filter(|p| p.distance(Vec3::new(3.0, 3.0, 0.0)) > 0.6)
        .collect();
    tris.push([
        Vec3::new(20.0, 0.0, 5.0),
        Vec3::new(21.0, 0.0, 5.0),
        Vec3::new(20.0, 1.0, 5.0),
    ]);
    let r = voronoi_areas(&tris, &sites);
    assert!(r.stats.redone > 1, "{:?}", r.stats);
    check_sum(&tris, &r, 1e-6);
}

#[test]
fn whole_triangles_give_the_bits_clipping_gives() {
    // Fine meshes against few samples (most triangles lie in one cell) and a coarse one, with
    // a few samples at the same position.
    let fine = icosphere(5, Vec3::ZERO, 1.0);
    let mut cases = vec![
        (fine.clone(), poisson(&fine, 300, 1)),
        (fine.clone(), poisson(&fine, 3000, 2)),
        (sphere_and_plane(), poisson(&sphere_and_plane(), 500, 3)),
    ];
    let mut doubled = poisson(&fine, 400, 4);
    doubled.extend_from_within(..20);
    cases.push((fine, doubled));
    for (tris, sites) in cases {
        let with = areas_of_cells(&tris, &sites, true, &|_| {});
        let without = areas_of_cells(&tris, &sites, false, &|_| {});
        // The triangles of other sites' cells are not even looked at.
        assert!(
            with.stats.clipped + with.stats.whole < without.stats.clipped,
            "{:?} {:?}",
            with.stats,
            without.stats
        );
        assert_eq!(
            (with.stats.redone, with.stats.shared),
            (without.stats.redone, without.stats.shared)
        );
        let bits = |r: &VoronoiAreas| -> Vec<u32> {
            r.areas
                .iter()
                .map(|a| a.to_bits())
                .chain(
                    r.centroids
                        .iter()
                        .flat_map(|c| c.position.to_array().map(f32::to_bits)),
                )
                .collect()
        };
        assert_eq!(bits(&with), bits(&without));
        assert_eq!(with.centroids, without.centroids);
    }
}

/// The progress reported covers the whole run, from its steps and its tasks, and reporting it
/// changes nothing.
#[test]
fn progress_reaches_one_and_changes_nothing() {
    let tris = icosphere(5, Vec3::ZERO, 1.0);
    let sites = poisson(&tris, 3000, 5);
    let reports = std::sync::Mutex::new(Vec::new());
    let with = voronoi_areas_with_progress(&tris, &sites, &|done| {
        reports.lock().expect("reports").push(done)
    });
    let without = voronoi_areas(&tris, &sites);
    assert_eq!(with.areas, without.areas);
    assert_eq!(with.stats, without.stats);
    let reports = reports.into_inner().expect("reports");
    assert!(
        reports.iter().all(|d| (0.0..=1.0).contains(d)),
        "{reports:?}"
    );
    assert_eq!(reports.last(), Some(&1.0));
    // The steps, and the tasks of the clipping between them.
    for step in [0.3, 0.55, 0.9] {
        assert!(
            reports.iter().any(|&d| (d - step).abs() < 1e-6),
            "{step}: {reports:?}"
        );
    }
    assert!(reports.iter().any(|&d| d > 0.55 && d < 0.9), "{reports:?}");
}
