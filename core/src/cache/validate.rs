//! `IrradianceCache::validate`: checks every structural and numerical invariant of a built
//! cache. Tests and fuzz targets call it after every build.

use alloc::format;
use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use super::{COUNT_MASK, IrradianceCache, LEAF_BIT, LEAF_CAPACITY, MAX_DEPTH};
use crate::lanes::LANES;
use crate::math;

/// A broken invariant, described.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ValidationError(pub String);

impl fmt::Display for ValidationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "invalid irradiance cache: {}", self.0)
    }
}

impl core::error::Error for ValidationError {}

macro_rules! ensure {
    ($cond:expr, $($msg:tt)*) => {
        if !$cond {
            return Err(ValidationError(format!($($msg)*)));
        }
    };
}

/// |a − b| within a relative tolerance suited to f32 sums of a few hundred terms.
fn close(a: f32, b: f64) -> bool {
    ((a as f64) - b).abs() <= 1e-5 * b.abs().max(a.abs() as f64) + 1e-30
}

impl IrradianceCache {
    /// Checks every invariant: column lengths and zero padding; breadth-first node order with
    /// contiguous children after their parent; leaves of 1..=8 samples partitioning the
    /// samples; depth; Morton order of the samples; every aggregate (area, flux) against a
    /// fresh sum of its children; every sample inside its ancestors' spheres; covariances
    /// positive semi-definite on the diagonal pairs and bounded by the radius.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let (n, m) = (self.len, self.node_len);
        let s = &self.samples;
        let d = &self.nodes;
        for (name, col) in [
            ("pos_x", &s.pos_x),
            ("pos_y", &s.pos_y),
            ("pos_z", &s.pos_z),
            ("area", &s.area),
            ("flux_r", &s.flux_r),
            ("flux_g", &s.flux_g),
            ("flux_b", &s.flux_b),
        ] {
            ensure!(
                col.len() == n + LANES,
                "sample column {name} has {} entries, expected {}",
                col.len(),
                n + LANES
            );
            ensure!(
                col[n..].iter().all(|&v| v == 0.0),
                "sample column {name} padding is not zero"
            );
        }
        for (name, col) in d.float_columns() {
            ensure!(
                col.len() == m + LANES,
                "node column {name} has {} entries, expected {}",
                col.len(),
                m + LANES
            );
            ensure!(
                col[m..].iter().all(|&v| v == 0.0),
                "node column {name} padding is not zero"
            );
            ensure!(
                col.iter().all(|v| v.is_finite()),
                "node column {name} has a non-finite value"
            );
        }
        ensure!(
            d.first.len() == m + LANES && d.info.len() == m + LANES,
            "node index columns have the wrong length"
        );
        ensure!(
            d.info[m..].iter().all(|&v| v == 0),
            "node info padding is not zero"
        );
        ensure!((n == 0) == (m == 0), "{n} samples but {m} nodes");
        if n == 0 {
            return Ok(());
        }

        for i in 0..n {
            ensure!(
                s.pos_x[i].is_finite() && s.pos_y[i].is_finite() && s.pos_z[i].is_finite(),
                "sample {i} position not finite"
            );
            ensure!(
                s.area[i] >= 0.0 && s.area[i].is_finite(),
                "sample {i} area {}",
                s.area[i]
            );
            for f in [s.flux_r[i], s.flux_g[i], s.flux_b[i]] {
                ensure!(f >= 0.0 && f.is_finite(), "sample {i} flux {f}");
            }
        }

        // Morton order.
        let mut prev = 0u64;
        for i in 0..n {
            let code = self
                .grid
                .code(glam::Vec3::new(s.pos_x[i], s.pos_y[i], s.pos_z[i]));
            ensure!(code >= prev, "sample {i} breaks Morton order");
            prev = code;
        }

        // Structure: breadth-first, contiguous children, sample ranges, depth.
        let mut range = vec![(0u32, 0u32); m];
        let mut depth = vec![0usize; m];
        let mut parent_seen = vec![false; m];
        parent_seen[0] = true;
        let mut next_child = 1u32;
        let mut covered = vec![0u8; n];
        for i in 0..m {
            let info = d.info[i];
            let count = info & COUNT_MASK;
            ensure!(
                info & !(COUNT_MASK | LEAF_BIT) == 0,
                "node {i} has stray bits in info {info:#x}"
            );
            ensure!(
                (1..=LEAF_CAPACITY).contains(&count),
                "node {i} has count {count}"
            );
            let first = d.first[i];
            if info & LEAF_BIT != 0 {
                ensure!(
                    (first + count) as usize <= n,
                    "leaf {i} samples {first}+{count} out of range"
                );
                for c in &mut covered[first as usize..(first + count) as usize] {
                    *c += 1;
                }
            } else {
                ensure!(
                    first == next_child,
                    "node {i}: children start at {first}, expected {next_child} (breadth-first)"
                );
                ensure!(
                    (first + count) as usize <= m,
                    "node {i}: children out of range"
                );
                for c in first..first + count {
                    parent_seen[c as usize] = true;
                    depth[c as usize] = depth[i] + 1;
                }
                next_child += count;
            }
        }
        ensure!(
            next_child as usize == m,
            "{} nodes but children account for {next_child}",
            m
        );
        ensure!(parent_seen.iter().all(|&p| p), "a node has no parent");
        ensure!(
            covered.iter().all(|&c| c == 1),
            "leaves do not partition the samples"
        );
        let max_depth = depth.iter().copied().max().unwrap_or(0);
        ensure!(
            max_depth == self.depth && max_depth <= MAX_DEPTH,
            "depth {max_depth} (recorded {}, limit {MAX_DEPTH})",
            self.depth
        );

        // Aggregates, bottom-up, and contiguous sample ranges.
        let centroid =
            |i: usize| glam::Vec3::new(d.centroid_x[i], d.centroid_y[i], d.centroid_z[i]);
        for i in (0..m).rev() {
            let info = d.info[i];
            let (first, count) = (d.first[i] as usize, (info & COUNT_MASK) as usize);
            let mut area = 0.0f64;
            let mut flux = [0.0f64; 3];
            if info & LEAF_BIT != 0 {
                range[i] = (first as u32, (first + count) as u32);
                for j in first..first + count {
                    area += s.area[j] as f64;
                    flux[0] += s.flux_r[j] as f64;
                    flux[1] += s.flux_g[j] as f64;
                    flux[2] += s.flux_b[j] as f64;
                }
            } else {
                range[i] = (range[first].0, range[first + count - 1].1);
                for c in first..first + count {
                    if c > first {
                        ensure!(
                            range[c].0 == range[c - 1].1,
                            "children of node {i} own non-contiguous samples"
                        );
                    }
                    area += d.area[c] as f64;
                    flux[0] += d.flux_r[c] as f64;
                    flux[1] += d.flux_g[c] as f64;
                    flux[2] += d.flux_b[c] as f64;
                    // A child's centroid lies within its parent's sphere (unless that is
                    // unbounded: a radius of f32::MAX, as below).
                    let offset = (centroid(c).as_dvec3() - centroid(i).as_dvec3()).length();
                    ensure!(
                        offset <= (d.radius[i] as f64) * (1.0 + 1e-5) + 1e-30
                            || d.radius[i] == f32::MAX,
                        "node {i}: child {c}'s centroid is outside the node's sphere"
                    );
                }
            }
            ensure!(
                close(d.area[i], area),
                "node {i} area {} != {area}",
                d.area[i]
            );
            ensure!(
                close(d.flux_r[i], flux[0])
                    && close(d.flux_g[i], flux[1])
                    && close(d.flux_b[i], flux[2]),
                "node {i} flux does not match its children"
            );
            // Every sample of the subtree lies within the sphere about the centroid (a radius of
            // f32::MAX stands for a sphere too large for f32: unbounded).
            let r = d.radius[i] as f64;
            let (a, b) = (range[i].0 as usize, range[i].1 as usize);
            let farthest = (a..b)
                .map(|j| {
                    (glam::Vec3::new(s.pos_x[j], s.pos_y[j], s.pos_z[j]).as_dvec3()
                        - centroid(i).as_dvec3())
                    .length()
                })
                .fold(0.0f64, f64::max);
            ensure!(
                farthest <= r * (1.0 + 1e-6) + 1e-30 || d.radius[i] == f32::MAX,
                "node {i}: a sample lies {farthest} from the centroid, radius {r}"
            );
            // The covariance: non-negative variances, |off-diagonals| ≤ geometric means, and the
            // total variance at most the squared radius.
            let (xx, yy, zz) = (d.cov_xx[i] as f64, d.cov_yy[i] as f64, d.cov_zz[i] as f64);
            ensure!(
                xx >= 0.0 && yy >= 0.0 && zz >= 0.0,
                "node {i}: negative variance"
            );
            let slack = 1e-5 * (xx + yy + zz) + 1e-30;
            for (c, p, q) in [
                (d.cov_xy[i] as f64, xx, yy),
                (d.cov_xz[i] as f64, xx, zz),
                (d.cov_yz[i] as f64, yy, zz),
            ] {
                ensure!(
                    c.abs() <= math::sqrt64(p * q) + slack,
                    "node {i}: covariance {c} exceeds √({p}·{q})"
                );
            }
            ensure!(
                xx + yy + zz <= r * r * (1.0 + 1e-5) + 1e-30,
                "node {i}: total variance {} exceeds radius² {}",
                xx + yy + zz,
                r * r
            );
        }
        ensure!(
            range[0] == (0, n as u32),
            "root covers samples {:?}, expected 0..{n}",
            range[0]
        );
        let mean = d.area[0] as f64 / n as f64;
        ensure!(
            close(self.mean_area, mean),
            "mean area {} != {mean}",
            self.mean_area
        );
        Ok(())
    }
}

/// Helper for tests: the leaf sample counts (for statistics in benches and tests).
#[allow(dead_code)]
pub(crate) fn leaf_sizes(cache: &IrradianceCache) -> Vec<u32> {
    (0..cache.node_len)
        .filter(|&i| cache.nodes.info[i] & LEAF_BIT != 0)
        .map(|i| cache.nodes.info[i] & COUNT_MASK)
        .collect()
}
