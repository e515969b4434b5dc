//! Shadow-ray BVH and blue-noise sampling throughput.
//!
//! Run: `cargo bench -p lucent-raster --bench geometry`.
//!
//! The random-ray scene: a unit icosphere (6 subdivisions, 81,920 triangles) above a 6×6 floor
//! of 20,000 triangles: 101,920 triangles.
//!
//! The coherent scene is `scenes/sphere-shadow.toml`: a 128-segment UV sphere (16,128
//! triangles) on a floor, half shadowed by a thin plate, and shadow rays from its lit side to
//! the point light in scanline order, as a renderer traces them.

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use glam::Vec3;
use lucent_raster::geometry::shapes::{grid, icosphere};
use lucent_raster::geometry::{Bvh, CLUSTER, ShadowHint, offset_origin};
use lucent_raster::sampling::rng::Pcg32;
use lucent_raster::sampling::{SampleTarget, poisson_samples};
use lucent_raster::scene::Mesh;
use lucent_raster::scene::shapes::{cuboid, plane, sphere};

fn main() {
    divan::main();
}

fn scene() -> Vec<[Vec3; 3]> {
    let mut tris = icosphere(6, Vec3::new(0.0, 0.0, 1.2), 1.0);
    tris.extend(grid(
        Vec3::new(-3.0, -3.0, 0.0),
        Vec3::X * 6.0,
        Vec3::Y * 6.0,
        100,
        100,
    ));
    tris
}

/// Shadow rays from random surface points (offset along the face normal, towards the light) to
/// a point light: about half are blocked (52.8% of this set).
fn shadow_rays(tris: &[[Vec3; 3]], bvh: &Bvh, n: usize) -> Vec<(Vec3, Vec3)> {
    let light = Vec3::new(2.0, -1.5, 5.0);
    let mut rng = Pcg32::new(1, 0);
    (0..n)
        .map(|_| {
            let t = &tris[rng.next_below(tris.len() as u32) as usize];
            let (u, v) = (rng.next_f32() * 0.5, rng.next_f32() * 0.5);
            let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
            let mut normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            if normal.dot(light - p) < 0.0 {
                normal = -normal;
            }
            let o = offset_origin(p, normal, bvh.scale());
            (o, light - o)
        })
        .collect()
}

/// The triangles of `mesh` moved by `offset`.
fn placed(mesh: &Mesh, offset: Vec3) -> impl Iterator<Item = [Vec3; 3]> + '_ {
    mesh.triangles
        .iter()
        .map(move |t| t.map(|i| mesh.positions[i as usize] + offset))
}

/// `scenes/sphere-shadow.toml`'s geometry: sphere, floor, plate. Returns the triangles and the
/// number of sphere triangles (they come first).
fn sphere_shadow_scene() -> (Vec<[Vec3; 3]>, usize) {
    let mut tris: Vec<[Vec3; 3]> = placed(&sphere(1.0, 128), Vec3::new(0.0, 0.0, 1.0)).collect();
    let n_sphere = tris.len();
    tris.extend(placed(
        &plane(glam::Vec2::new(40.0, 60.0)),
        Vec3::new(0.0, 24.0, 0.0),
    ));
    tris.extend(placed(
        &cuboid(Vec3::new(3.0, 7.6, 0.05)),
        Vec3::new(-1.5, 0.2, 2.6),
    ));
    (tris, n_sphere)
}

/// Shadow rays of the coherent scene: a 256×256 pinhole camera at the scene's position looks
/// at the sphere; every pixel whose primary ray hits the sphere on its light-facing side
/// gives one shadow ray (offset along the face normal) to the point light, in scanline order.
/// About half are blocked by the plate.
fn coherent_shadow_rays(tris: &[[Vec3; 3]], n_sphere: usize, bvh: &Bvh) -> Vec<(Vec3, Vec3)> {
    let light = Vec3::new(0.0, -3.0, 5.0);
    let eye = Vec3::new(0.0, -7.0, 1.3);
    let forward = (Vec3::new(0.0, 0.0, 0.9) - eye).normalize();
    let right = forward.cross(Vec3::Z).normalize();
    let up = right.cross(forward);
    let half = (15.0f32).to_radians().tan();
    let side = 256;
    let mut rays = Vec::new();
    for y in 0..side {
        for x in 0..side {
            let sx = ((x as f32 + 0.5) / side as f32 * 2.0 - 1.0) * half;
            let sy = (1.0 - (y as f32 + 0.5) / side as f32 * 2.0) * half;
            let d = forward + right * sx + up * sy;
            let Some(hit) = bvh.intersect(eye, d, f32::INFINITY) else {
                continue;
            };
            if hit.triangle as usize >= n_sphere {
                continue;
            }
            let t = &tris[hit.triangle as usize];
            let p = eye + d * hit.t;
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            if n.dot(light - p) <= 0.0 {
                continue;
            }
            let o = offset_origin(p, n, bvh.scale());
            rays.push((o, light - o));
        }
    }
    rays
}

/// The argument of the random-ray benches: how many triangles a cluster holds at most (1: the
/// tree over single triangles that scenes below `CLUSTERED_FROM` get; `CLUSTER`: the one of
/// larger scenes, built here over the same triangles to compare).
const CLUSTERS: [usize; 2] = [1, CLUSTER];

#[divan::bench(args = CLUSTERS, sample_count = 20)]
fn bvh_build(bencher: Bencher, cluster: usize) {
    let tris = scene();
    bencher
        .counter(ItemsCount::new(tris.len()))
        .bench(|| Bvh::try_build_clustered(black_box(&tris), cluster).unwrap());
}

#[divan::bench(args = CLUSTERS, sample_count = 20)]
fn occluded(bencher: Bencher, cluster: usize) {
    let tris = scene();
    let bvh = Bvh::try_build_clustered(&tris, cluster).unwrap();
    let rays = shadow_rays(&tris, &bvh, 100_000);
    bencher.counter(ItemsCount::new(rays.len())).bench(|| {
        rays.iter()
            .filter(|&&(o, d)| bvh.occluded(o, d, 1.0))
            .count()
    });
}

#[divan::bench(args = CLUSTERS, sample_count = 20)]
fn intersect(bencher: Bencher, cluster: usize) {
    let tris = scene();
    let bvh = Bvh::try_build_clustered(&tris, cluster).unwrap();
    let rays = shadow_rays(&tris, &bvh, 100_000);
    bencher.counter(ItemsCount::new(rays.len())).bench(|| {
        rays.iter()
            .filter_map(|&(o, d)| bvh.intersect(o, d, f32::INFINITY))
            .count()
    });
}

#[divan::bench(sample_count = 40)]
fn occluded_coherent(bencher: Bencher) {
    let (tris, n_sphere) = sphere_shadow_scene();
    let bvh = Bvh::build(&tris);
    let rays = coherent_shadow_rays(&tris, n_sphere, &bvh);
    // The bench means what it says only if the plate blocks about half the rays.
    let blocked = rays
        .iter()
        .filter(|&&(o, d)| bvh.occluded(o, d, 1.0))
        .count();
    assert!(rays.len() > 5_000 && (blocked * 10).abs_diff(rays.len() * 5) < rays.len() * 2);
    bencher.counter(ItemsCount::new(rays.len())).bench(|| {
        rays.iter()
            .filter(|&&(o, d)| bvh.occluded(o, d, 1.0))
            .count()
    });
}

#[divan::bench(sample_count = 40)]
fn occluded_coherent_hinted(bencher: Bencher) {
    let (tris, n_sphere) = sphere_shadow_scene();
    let bvh = Bvh::build(&tris);
    let rays = coherent_shadow_rays(&tris, n_sphere, &bvh);
    bencher.counter(ItemsCount::new(rays.len())).bench(|| {
        let mut hint = ShadowHint::default();
        rays.iter()
            .filter(|&&(o, d)| bvh.occluded_hinted(o, d, 1.0, &mut hint))
            .count()
    });
}

#[divan::bench(args = [10_000, 100_000, 1_000_000], sample_count = 5)]
fn poisson(bencher: Bencher, n: u32) {
    let tris = scene();
    bencher
        .counter(ItemsCount::new(n))
        .bench(|| poisson_samples(black_box(&tris), SampleTarget::Count(n), 1));
}

/// A tessellated unit cube turned off the axes (`n`×`n` quads a side, outward faces, each
/// triangle with its own corners): convex, but the boxes of its coplanar vertices straddle
/// every face's plane, so the convexity test's work grows like V·F until its cap.
fn tessellated_cube(n: u32) -> Mesh {
    let turn = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
    let mut positions = Vec::new();
    for axis in 0..3 {
        for side in [-0.5f32, 0.5] {
            let (mut u, mut v) = (Vec3::ZERO, Vec3::ZERO);
            u[(axis + 1) % 3] = 1.0;
            v[(axis + 2) % 3] = 1.0;
            let mut normal = Vec3::ZERO;
            normal[axis] = side;
            let (u, v) = if side > 0.0 { (u, v) } else { (v, u) };
            let corner = normal - (u + v) * 0.5;
            positions.extend(grid(corner, u, v, n, n).into_iter().flatten());
        }
    }
    let positions: Vec<Vec3> = positions.into_iter().map(|p| turn * p).collect();
    Mesh {
        normals: vec![Vec3::Z; positions.len()],
        triangles: (0..positions.len() as u32 / 3)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect(),
        positions,
        uvs: None,
    }
}

/// `cannot_shadow_itself` on a convex sphere (16k and 262k triangles, accepted), the default
/// scene's bunny outline stand-in (a sphere with one face flipped: rejected at once), and a
/// turned tessellated cube (the worst case, 24k triangles).
#[divan::bench(args = ["sphere-128", "sphere-512", "flipped-face", "turned-cube-32"], sample_count = 5)]
fn convexity(bencher: Bencher, which: &str) {
    let mesh = match which {
        "sphere-128" => sphere(1.0, 128),
        "sphere-512" => sphere(1.0, 512),
        "flipped-face" => {
            let mut m = sphere(1.0, 128);
            m.triangles[5000].swap(1, 2);
            m
        }
        _ => tessellated_cube(32),
    };
    bencher
        .counter(ItemsCount::new(mesh.triangles.len()))
        .bench(|| lucent_raster::render::cannot_shadow_itself(black_box(&mesh)));
}
