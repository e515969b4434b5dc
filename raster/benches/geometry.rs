//! Shadow-ray BVH and blue-noise sampling throughput.
//!
//! Run: `cargo bench -p lucent-raster --bench geometry`.
//!
//! The scene: a unit icosphere (6 subdivisions, 81,920 triangles) above a 6×6 floor of 20,000
//! triangles: 101,920 triangles.

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use glam::Vec3;
use lucent_raster::geometry::shapes::{grid, icosphere};
use lucent_raster::geometry::{Bvh, offset_origin};
use lucent_raster::sampling::rng::Pcg32;
use lucent_raster::sampling::{SampleTarget, poisson_samples};

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
/// a point light: about a quarter are blocked.
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

#[divan::bench(sample_count = 20)]
fn bvh_build(bencher: Bencher) {
    let tris = scene();
    bencher
        .counter(ItemsCount::new(tris.len()))
        .bench(|| Bvh::build(black_box(&tris)));
}

#[divan::bench(sample_count = 20)]
fn occluded(bencher: Bencher) {
    let tris = scene();
    let bvh = Bvh::build(&tris);
    let rays = shadow_rays(&tris, &bvh, 100_000);
    bencher.counter(ItemsCount::new(rays.len())).bench(|| {
        rays.iter()
            .filter(|&&(o, d)| bvh.occluded(o, d, 1.0))
            .count()
    });
}

#[divan::bench(sample_count = 20)]
fn intersect(bencher: Bencher) {
    let tris = scene();
    let bvh = Bvh::build(&tris);
    let rays = shadow_rays(&tris, &bvh, 100_000);
    bencher.counter(ItemsCount::new(rays.len())).bench(|| {
        rays.iter()
            .filter_map(|&(o, d)| bvh.intersect(o, d, f32::INFINITY))
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
