//! Time and peak transient memory of `voronoi_areas` on the bunny (or a fine sphere), at the
//! sample counts given on the command line:
//!
//! ```sh
//! cargo run --release -p lucent-raster --example voronoi_cost -- 100000 1000000
//! cargo run --release -p lucent-raster --example voronoi_cost -- --sphere 1000000
//! ```
//!
//! Samples come from `poisson_samples` (not timed) and are handed to a fresh child process, so
//! that the placement's freed memory does not hide the peak; the areas are computed five times and the
//! median wall time is printed, the mean CPU time (all threads), with the peak heap growth during one run.

use std::time::Instant;

use glam::Vec3;
use lucent_raster::geometry::shapes::icosphere;
use lucent_raster::sampling::{SampleTarget, poisson_samples, total_area, voronoi_areas};

/// CPU time of the process (user + system, all threads), in seconds (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses): utime is the 12th, stime the 13th.
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

/// A field of `/proc/self/status` in kB (Linux; 0 elsewhere).
fn status_kb(field: &str) -> usize {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sphere = args.iter().any(|a| a == "--sphere");
    let tris: Vec<[Vec3; 3]> = if sphere {
        icosphere(6, Vec3::ZERO, 5.0)
    } else {
        let bunny = lucent_raster::scene::obj::parse_obj(include_bytes!("../../assets/bunny.obj"))
            .expect("bunny");
        bunny
            .triangles
            .iter()
            .map(|t| t.map(|i| bunny.positions[i as usize]))
            .collect()
    };
    // `--child FILE`: the measuring process, started fresh so that the memory of the sample
    // placement is not reused.
    if let Some(k) = args.iter().position(|a| a == "--child") {
        let bytes = std::fs::read(&args[k + 1]).expect("sites file");
        let sites: Vec<Vec3> = bytes
            .chunks_exact(12)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes(c[i..i + 4].try_into().unwrap());
                Vec3::new(f(0), f(4), f(8))
            })
            .collect();
        drop(bytes);
        measure(&tris, &sites);
        return;
    }
    for n in args.iter().filter_map(|a| a.parse::<u32>().ok()) {
        let sites: Vec<Vec3> = poisson_samples(&tris, SampleTarget::Count(n), 1)
            .expect("samples")
            .iter()
            .map(|p| p.position)
            .collect();
        let path = std::env::temp_dir().join(format!("voronoi-cost-{}.bin", std::process::id()));
        let bytes: Vec<u8> = sites
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        std::fs::write(&path, bytes).expect("write sites");
        let mut child = std::process::Command::new(std::env::current_exe().expect("exe"));
        if sphere {
            child.arg("--sphere");
        }
        let status = child.arg("--child").arg(&path).status().expect("child");
        let _ = std::fs::remove_file(&path);
        assert!(status.success());
    }
}

fn measure(tris: &[[Vec3; 3]], sites: &[Vec3]) {
    let n = sites.len();
    // Start the thread pool (its stacks are not transient memory of the computation).
    let _ = voronoi_areas(tris, &sites[..n.min(100)]);
    let mut times = Vec::new();
    let mut peak = 0;
    let mut result = None;
    let cpu = cpu_seconds();
    for run in 0..5 {
        // Peak resident memory of the first run, above what was resident before it
        // (writing 5 to clear_refs resets the high-water mark).
        let _ = std::fs::write("/proc/self/clear_refs", "5");
        let before = status_kb("VmRSS:");
        let t = Instant::now();
        let r = voronoi_areas(tris, sites);
        times.push(t.elapsed().as_secs_f64());
        if run == 0 {
            // The result (4 bytes per sample) is not transient.
            peak = (status_kb("VmHWM:").saturating_sub(before) * 1024).saturating_sub(4 * n);
        }
        result = Some(r);
    }
    let cpu = (cpu_seconds() - cpu) / 5.0;
    times.sort_by(f64::total_cmp);
    let r = result.expect("ran");
    let sum: f64 = r.areas.iter().map(|&a| a as f64).sum();
    let total = total_area(tris);
    println!(
        "{} triangles, {n} samples: median {:.3} s (min {:.3}) wall, {cpu:.3} s CPU per run, \
         peak transient {:.1} bytes/sample, sum/area − 1 = {:.1e}, {:?}",
        tris.len(),
        times[2],
        times[0],
        peak as f64 / n as f64,
        sum / total - 1.0,
        r.stats
    );
}
