//! Wall and CPU time of the two steps of sample placement, weighted sample elimination
//! (`poisson_samples`) and the restricted Voronoi areas (`voronoi_areas`), on the first
//! translucent object of a scene:
//!
//! ```sh
//! cargo run --release -p lucent-raster --example placement_cost -- scenes/sphere-shadow.toml 1000000 5
//! ```
//!
//! Arguments: the scene, the sample count, the number of runs (medians are printed, with each
//! run's figures). CPU time is the process's user + system time over all threads.
//!
//! Each run also prints a hash of the samples' positions and one of their cells' areas and
//! centroids: a change meant to keep the output must keep both.

use std::path::Path;
use std::time::Instant;

use lucent_raster::render::Prepared;
use lucent_raster::sampling::{SampleTarget, poisson_samples, voronoi_areas};
use lucent_raster::scene::load_scene;

/// CPU time of the process (user + system, all threads), in seconds (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    if f.len() < 13 {
        return 0.0;
    }
    (f[11] + f[12]) / 100.0
}

/// FNV-1a over the values' bits: equal output across builds and thread counts.
fn fnv1a(values: impl Iterator<Item = f32>) -> u64 {
    values.fold(0xcbf2_9ce4_8422_2325u64, |h, v| {
        (h ^ v.to_bits() as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = load_scene(Path::new(&args[0])).expect("scene");
    let n: u32 = args
        .get(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let runs: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(3);
    let prep = Prepared::new(&scene).expect("prepared");
    let object = prep.translucent_objects()[0];
    let (a, b) = (
        prep.first_triangle[object] as usize,
        prep.first_triangle[object + 1] as usize,
    );
    let tris = &prep.triangles[a..b];
    let (mut ew, mut ec, mut vw, mut vc) = (vec![], vec![], vec![], vec![]);
    for run in 0..runs {
        let (t, c) = (Instant::now(), cpu_seconds());
        let points = poisson_samples(tris, SampleTarget::Count(n), 1).expect("samples");
        let (e_wall, e_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
        let sites: Vec<_> = points.iter().map(|p| p.position).collect();
        let hash = fnv1a(sites.iter().flat_map(|p| p.to_array()));
        drop(points);
        let (t, c) = (Instant::now(), cpu_seconds());
        let areas = voronoi_areas(tris, &sites);
        let (v_wall, v_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
        assert_eq!(areas.areas.len(), n as usize);
        let cells = fnv1a(
            areas
                .areas
                .iter()
                .copied()
                .chain(areas.centroids.iter().flat_map(|c| {
                    [
                        c.position.x,
                        c.position.y,
                        c.position.z,
                        c.bary.x,
                        c.bary.y,
                        f32::from_bits(c.triangle),
                    ]
                })),
        );
        println!(
            "run {run}: elimination {e_wall:.3} s wall, {e_cpu:.2} s CPU; voronoi {v_wall:.3} s \
             wall, {v_cpu:.2} s CPU; samples {hash:016x}, cells {cells:016x}"
        );
        ew.push(e_wall);
        ec.push(e_cpu);
        vw.push(v_wall);
        vc.push(v_cpu);
    }
    println!(
        "median of {runs}: elimination {:.3} s wall, {:.2} s CPU; voronoi {:.3} s wall, {:.2} s \
         CPU; both {:.3} s wall",
        median(ew.clone()),
        median(ec),
        median(vw.clone()),
        median(vc),
        median(ew.iter().zip(&vw).map(|(a, b)| a + b).collect())
    );
}
