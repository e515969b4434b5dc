//! Rasteriser throughput at 512×512 pixels with aa = 2 (1024×1024 sub-samples).
//!
//! * `small_triangles_mesh`: a jittered 51×51 grid of 10 px cells, two triangles per cell
//!   (5 202 triangles, drawn row by row as a mesh would be); the counter is triangles, so divan
//!   reports triangles/s.
//! * `small_triangles_scattered`: 10 000 triangles about 10 px across at random positions and
//!   depths: the cache-hostile worst case (every triangle touches ~20 cold rows of an 8 MiB
//!   buffer, so this measures memory latency more than the rasteriser).
//! * `large_triangles`: four full-screen quads (eight triangles) drawn back to front, so every
//!   sub-sample passes the depth test four times; the counter is sub-samples written, so divan
//!   reports sub-samples/s.
//! * `large_triangles_occluded`: the same quads front to back, so after the first layer every
//!   sub-sample fails the depth test (the cheaper, common case behind a near surface).
//!
//! Every iteration starts from a cleared buffer (cloned outside the timed region).
//!
//! Run: `cargo bench -p lucent-raster --bench raster`.

use divan::Bencher;
use divan::counter::ItemsCount;
use glam::Vec4;
use lucent_raster::raster::VisibilityBuffer;

const SIZE: u32 = 512;
const AA: u32 = 2;

fn main() {
    divan::main();
}

/// A clip-space vertex (w = 1) at pixel position `(px, py)`.
fn at(px: f32, py: f32, z: f32) -> Vec4 {
    let s = SIZE as f32;
    Vec4::new(2.0 * px / s - 1.0, 1.0 - 2.0 * py / s, z, 1.0)
}

/// Deterministic pseudo-random numbers in [0, 1) (a 64-bit LCG, high bits).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn small_triangles_set() -> Vec<[Vec4; 3]> {
    let mut rng = Lcg(1);
    (0..10_000)
        .map(|_| {
            let (cx, cy, z) = (
                rng.next() * 502.0 + 5.0,
                rng.next() * 502.0 + 5.0,
                rng.next(),
            );
            let mut corner = || {
                at(
                    cx + (rng.next() - 0.5) * 10.0,
                    cy + (rng.next() - 0.5) * 10.0,
                    z,
                )
            };
            [corner(), corner(), corner()]
        })
        .collect()
}

fn small_mesh_set() -> Vec<[Vec4; 3]> {
    let mut rng = Lcg(2);
    let n = 51;
    let cell = SIZE as f32 / n as f32;
    let mut grid = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let jitter = |k: usize, r: f32| {
                if k == 0 || k == n {
                    0.0
                } else {
                    (r - 0.5) * 0.4 * cell
                }
            };
            let (x, y) = (
                i as f32 * cell + jitter(i, rng.next()),
                j as f32 * cell + jitter(j, rng.next()),
            );
            grid.push(at(x, y, 0.2 + 0.6 * rng.next()));
        }
    }
    let mut tris = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            let k = j * (n + 1) + i;
            tris.push([grid[k], grid[k + 1], grid[k + n + 1]]);
            tris.push([grid[k + 1], grid[k + n + 2], grid[k + n + 1]]);
        }
    }
    tris
}

fn quad(z: f32) -> [[Vec4; 3]; 2] {
    let s = SIZE as f32;
    let (a, b, c, d) = (at(0.0, 0.0, z), at(s, 0.0, z), at(0.0, s, z), at(s, s, z));
    [[a, b, c], [b, d, c]]
}

fn empty_buffer() -> VisibilityBuffer {
    VisibilityBuffer::new(SIZE, SIZE, AA).expect("valid size")
}

fn small(bencher: Bencher, tris: &[[Vec4; 3]]) {
    let empty = empty_buffer();
    bencher
        .counter(ItemsCount::new(tris.len()))
        .with_inputs(|| empty.clone())
        .bench_local_refs(|buf| {
            for (k, tri) in tris.iter().enumerate() {
                buf.rasterize_triangle(k as u32, *tri);
            }
        });
}

#[divan::bench(sample_count = 60, sample_size = 1)]
fn small_triangles_mesh(bencher: Bencher) {
    small(bencher, &small_mesh_set());
}

#[divan::bench(sample_count = 60, sample_size = 1)]
fn small_triangles_scattered(bencher: Bencher) {
    small(bencher, &small_triangles_set());
}

fn large(bencher: Bencher, depths: [f32; 4]) {
    let tris: Vec<[Vec4; 3]> = depths.iter().flat_map(|&z| quad(z)).collect();
    let empty = empty_buffer();
    let subsamples = (SIZE * AA) as usize * (SIZE * AA) as usize * depths.len();
    bencher
        .counter(ItemsCount::new(subsamples))
        .with_inputs(|| empty.clone())
        .bench_local_refs(|buf| {
            for (k, tri) in tris.iter().enumerate() {
                buf.rasterize_triangle(k as u32, *tri);
            }
        });
}

#[divan::bench(sample_count = 60, sample_size = 1)]
fn large_triangles(bencher: Bencher) {
    large(bencher, [0.8, 0.6, 0.4, 0.2]);
}

#[divan::bench(sample_count = 60, sample_size = 1)]
fn large_triangles_occluded(bencher: Bencher) {
    large(bencher, [0.2, 0.4, 0.6, 0.8]);
}
