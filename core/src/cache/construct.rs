//! Building the cache: validate, quantise, sort by Morton code, split into a breadth-first
//! octree top-down by code prefixes, then aggregate bottom-up.
//!
//! Cost: O(N log N) for the sort; each node's split costs eight binary searches over its
//! range, so the split is O(N log N) too. Deterministic: the sort key (code, input index) is
//! unique, and every sum is taken in a fixed order.

use alloc::vec::Vec;

use glam::{DMat3, DVec3, Vec3};

use super::{
    COUNT_MASK, IrradianceCache, LEAF_BIT, LEAF_CAPACITY, MAX_SAMPLES, Nodes, Sample, Samples,
};
use crate::error::BuildError;
use crate::lanes::LANES;
use crate::morton::Grid;

/// A node while it is being split: its sample range, its first child and child count.
#[derive(Clone, Copy)]
struct Pending {
    start: u32,
    end: u32,
    depth: u32,
    first: u32,
    count: u32,
    leaf: bool,
}

fn check(samples: &[Sample]) -> Result<(), BuildError> {
    if samples.len() > MAX_SAMPLES {
        return Err(BuildError::TooManySamples {
            count: samples.len(),
        });
    }
    // Node sums are stored in f32: the root's (the largest) must fit, or the cache would hold
    // infinities (and `validate` would reject it).
    let mut total_area = 0.0_f64;
    let mut total_flux = DVec3::ZERO;
    for (index, s) in samples.iter().enumerate() {
        if !s.position.is_finite() {
            return Err(BuildError::NonFinitePosition { index });
        }
        if !(s.area.is_finite() && s.area >= 0.0) {
            return Err(BuildError::InvalidArea {
                index,
                value: s.area,
            });
        }
        for value in s.irradiance.to_array() {
            if !(value.is_finite() && value >= 0.0) {
                return Err(BuildError::InvalidIrradiance { index, value });
            }
        }
        let sample_flux = s.irradiance * s.area;
        if !sample_flux.is_finite() {
            return Err(BuildError::InvalidIrradiance {
                index,
                value: sample_flux.max_element(),
            });
        }
        total_area += s.area as f64;
        total_flux += sample_flux.as_dvec3();
    }
    for (quantity, value) in [("area", total_area), ("flux", total_flux.max_element())] {
        if !(value as f32).is_finite() {
            return Err(BuildError::TotalOverflow { quantity, value });
        }
    }
    Ok(())
}

/// The octant boundaries of `codes` (sorted, sharing their prefix above bit `3·triple + 2`).
fn split_by_octant(codes: &[u64], triple: u32, mut emit: impl FnMut(u32, u32)) {
    let digit = |c: &u64| ((c >> (3 * triple)) & 7) as u32;
    let mut lo = 0usize;
    while lo < codes.len() {
        let d = digit(&codes[lo]);
        let hi = lo + codes[lo..].partition_point(|c| digit(c) <= d);
        emit(lo as u32, hi as u32);
        lo = hi;
    }
}

impl IrradianceCache {
    /// Builds a cache from irradiance samples (positions, areas, irradiance; any order).
    ///
    /// Errors on non-finite positions, negative or non-finite areas or irradiance (naming the
    /// sample), a total area or flux beyond the f32 range, and more than [`MAX_SAMPLES`]
    /// samples. An empty slice gives an empty cache.
    pub fn build(input: &[Sample]) -> Result<IrradianceCache, BuildError> {
        check(input)?;
        let n = input.len();

        // Quantise and sort.
        let (lo, hi) = input
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s.position), hi.max(s.position))
            });
        let grid = if n > 0 {
            Grid::new(lo, hi)
        } else {
            Grid {
                origin: Vec3::ZERO,
                scale: 0.0,
            }
        };
        let mut keys: Vec<(u64, u32)> = input
            .iter()
            .enumerate()
            .map(|(i, s)| (grid.code(s.position), i as u32))
            .collect();
        keys.sort_unstable();
        let codes: Vec<u64> = keys.iter().map(|k| k.0).collect();

        let samples = gather_samples(input, &keys);
        drop(keys);

        // Split top-down, breadth-first: node i's children are appended as one run.
        let mut pending: Vec<Pending> = Vec::with_capacity(n / 2 + 1);
        if n > 0 {
            pending.push(Pending {
                start: 0,
                end: n as u32,
                depth: 0,
                first: 0,
                count: 0,
                leaf: false,
            });
        }
        let mut i = 0;
        while i < pending.len() {
            let p = pending[i];
            let len = p.end - p.start;
            if len <= LEAF_CAPACITY {
                pending[i] = Pending {
                    first: p.start,
                    count: len,
                    leaf: true,
                    ..p
                };
                i += 1;
                continue;
            }
            let first_child = pending.len() as u32;
            let range = &codes[p.start as usize..p.end as usize];
            let (a, b) = (range[0], range[range.len() - 1]);
            let child = |start: u32, end: u32| Pending {
                start,
                end,
                depth: p.depth + 1,
                first: 0,
                count: 0,
                leaf: false,
            };
            if a != b {
                // The highest differing bit of the first and last code names the level at which
                // this run splits; levels above it would have a single child and are skipped.
                let triple = (63 - (a ^ b).leading_zeros()) / 3;
                split_by_octant(range, triple, |s, e| {
                    pending.push(child(p.start + s, p.start + e))
                });
            } else {
                // Coincident (quantised) positions: split by count into up to 8 equal runs.
                // At least one full leaf per child, at most eight children.
                let per = LEAF_CAPACITY.max(len.div_ceil(LEAF_CAPACITY));
                let mut s = p.start;
                while s < p.end {
                    let e = (s + per).min(p.end);
                    pending.push(child(s, e));
                    s = e;
                }
            }
            let count = pending.len() as u32 - first_child;
            pending[i] = Pending {
                first: first_child,
                count,
                ..p
            };
            i += 1;
        }

        let depth = pending.iter().map(|p| p.depth as usize).max().unwrap_or(0);
        let (nodes, bounds) = aggregate(&pending, &samples);
        let mean_area = if n > 0 {
            (nodes.area[0] as f64 / n as f64) as f32
        } else {
            0.0
        };
        let mut cache = IrradianceCache {
            samples,
            nodes,
            len: n,
            node_len: pending.len(),
            grid,
            mean_area,
            depth,
            bounds,
        };
        cache.shrink();
        Ok(cache)
    }

    fn shrink(&mut self) {
        let s = &mut self.samples;
        for c in [
            &mut s.pos_x,
            &mut s.pos_y,
            &mut s.pos_z,
            &mut s.area,
            &mut s.flux_r,
            &mut s.flux_g,
            &mut s.flux_b,
        ] {
            c.shrink_to_fit();
        }
        let n = &mut self.nodes;
        for c in [
            &mut n.area,
            &mut n.flux_r,
            &mut n.flux_g,
            &mut n.flux_b,
            &mut n.centroid_x,
            &mut n.centroid_y,
            &mut n.centroid_z,
            &mut n.radius,
            &mut n.cov_xx,
            &mut n.cov_yy,
            &mut n.cov_zz,
            &mut n.cov_xy,
            &mut n.cov_xz,
            &mut n.cov_yz,
        ] {
            c.shrink_to_fit();
        }
        n.first.shrink_to_fit();
        n.info.shrink_to_fit();
    }
}

/// The sample columns in Morton order, padded with `LANES` zeros.
fn gather_samples(input: &[Sample], keys: &[(u64, u32)]) -> Samples {
    let padded = keys.len() + LANES;
    let column = |f: &dyn Fn(&Sample) -> f32| {
        let mut c = Vec::with_capacity(padded);
        c.extend(keys.iter().map(|&(_, i)| f(&input[i as usize])));
        c.resize(padded, 0.0);
        c
    };
    Samples {
        pos_x: column(&|s| s.position.x),
        pos_y: column(&|s| s.position.y),
        pos_z: column(&|s| s.position.z),
        area: column(&|s| s.area),
        flux_r: column(&|s| s.irradiance.x * s.area),
        flux_g: column(&|s| s.irradiance.y * s.area),
        flux_b: column(&|s| s.irradiance.z * s.area),
    }
}

/// Per-node sums in double precision while aggregating.
#[derive(Clone, Copy, Default)]
struct Sums {
    lo: DVec3,
    hi: DVec3,
    area: f64,
    flux: DVec3,
    /// Σ w p with w = flux_r + flux_g + flux_b, and Σ w.
    weighted: DVec3,
    weight: f64,
    /// Σ A p (the fallback centroid for nodes without flux).
    area_weighted: DVec3,
    /// Σ p and the sample count (the centroid of nodes with neither flux nor area).
    position_sum: DVec3,
    count: f64,
}

impl Sums {
    fn empty() -> Sums {
        Sums {
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            ..Default::default()
        }
    }
    fn add(&mut self, o: &Sums) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
        self.area += o.area;
        self.flux += o.flux;
        self.weighted += o.weighted;
        self.weight += o.weight;
        self.area_weighted += o.area_weighted;
        self.position_sum += o.position_sum;
        self.count += o.count;
    }
    /// The weight of one sample under this node's weighting (flux, else area, else uniform).
    fn sample_weight(&self, flux: DVec3, area: f64) -> f64 {
        if self.weight > 0.0 {
            flux.x + flux.y + flux.z
        } else if self.area > 0.0 {
            area
        } else {
            1.0
        }
    }
    /// The total weight of a child under this node's weighting.
    fn child_weight(&self, child: &Sums) -> f64 {
        if self.weight > 0.0 {
            child.weight
        } else if self.area > 0.0 {
            child.area
        } else {
            child.count
        }
    }
    /// This node's total weight under its own weighting.
    fn total_weight(&self) -> f64 {
        self.child_weight(self)
    }
    fn centroid(&self) -> DVec3 {
        let c = if self.weight > 0.0 {
            self.weighted / self.weight
        } else if self.area > 0.0 {
            self.area_weighted / self.area
        } else {
            self.position_sum / self.count.max(1.0)
        };
        c.clamp(self.lo, self.hi)
    }
}

/// Aggregates bottom-up (children have larger indices than parents, so a reverse sweep sees
/// every child before its parent) and writes the node columns.
#[allow(clippy::type_complexity)]
fn aggregate(pending: &[Pending], s: &Samples) -> (Nodes, Option<(Vec3, Vec3)>) {
    let count = pending.len();
    let mut sums = alloc::vec![Sums::empty(); count];
    for i in (0..count).rev() {
        let p = pending[i];
        let mut acc = Sums::empty();
        if p.leaf {
            for j in p.first as usize..(p.first + p.count) as usize {
                let pos = DVec3::new(s.pos_x[j] as f64, s.pos_y[j] as f64, s.pos_z[j] as f64);
                let flux = DVec3::new(s.flux_r[j] as f64, s.flux_g[j] as f64, s.flux_b[j] as f64);
                let area = s.area[j] as f64;
                let w = flux.x + flux.y + flux.z;
                acc.add(&Sums {
                    lo: pos,
                    hi: pos,
                    area,
                    flux,
                    weighted: pos * w,
                    weight: w,
                    area_weighted: pos * area,
                    position_sum: pos,
                    count: 1.0,
                });
            }
        } else {
            for c in p.first as usize..(p.first + p.count) as usize {
                acc.add(&sums[c]);
            }
        }
        sums[i] = acc;
    }

    let centroids: Vec<DVec3> = sums.iter().map(Sums::centroid).collect();
    let covariances = covariances(pending, s, &sums, &centroids);
    let radii = radii(pending, s, &centroids);

    let padded = count + LANES;
    let column = |values: &mut dyn Iterator<Item = f32>| {
        let mut c = Vec::with_capacity(padded);
        c.extend(values);
        c.resize(padded, 0.0);
        c
    };
    let cov = |a: usize, b: usize| column(&mut covariances.iter().map(|m| m.col(a)[b] as f32));
    let mut first = Vec::with_capacity(padded);
    let mut info = Vec::with_capacity(padded);
    for p in pending {
        first.push(p.first);
        info.push((p.count & COUNT_MASK) | if p.leaf { LEAF_BIT } else { 0 });
    }
    first.resize(padded, 0);
    info.resize(padded, 0);
    let root_bounds = sums.first().map(|r| (r.lo.as_vec3(), r.hi.as_vec3()));
    let nodes = Nodes {
        area: column(&mut sums.iter().map(|s| s.area as f32)),
        flux_r: column(&mut sums.iter().map(|s| s.flux.x as f32)),
        flux_g: column(&mut sums.iter().map(|s| s.flux.y as f32)),
        flux_b: column(&mut sums.iter().map(|s| s.flux.z as f32)),
        centroid_x: column(&mut centroids.iter().map(|c| c.x as f32)),
        centroid_y: column(&mut centroids.iter().map(|c| c.y as f32)),
        centroid_z: column(&mut centroids.iter().map(|c| c.z as f32)),
        radius: column(&mut radii.into_iter()),
        cov_xx: cov(0, 0),
        cov_yy: cov(1, 1),
        cov_zz: cov(2, 2),
        cov_xy: cov(0, 1),
        cov_xz: cov(0, 2),
        cov_yz: cov(1, 2),
        first,
        info,
    };
    (nodes, root_bounds)
}

/// Per node, the weighted covariance of its samples about its centroid (the same weights as
/// the centroid), bottom-up by the parallel-axis theorem:
/// C = Σ_children W_c (C_c + (P_c − P)(P_c − P)ᵀ) / W.
fn covariances(pending: &[Pending], s: &Samples, sums: &[Sums], centroids: &[DVec3]) -> Vec<DMat3> {
    let outer = |d: DVec3| DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    let mut cov = alloc::vec![DMat3::ZERO; pending.len()];
    for i in (0..pending.len()).rev() {
        let p = pending[i];
        let node = &sums[i];
        let centre = centroids[i];
        let mut acc = DMat3::ZERO;
        if p.leaf {
            for j in p.first as usize..(p.first + p.count) as usize {
                let pos = DVec3::new(s.pos_x[j] as f64, s.pos_y[j] as f64, s.pos_z[j] as f64);
                let flux = DVec3::new(s.flux_r[j] as f64, s.flux_g[j] as f64, s.flux_b[j] as f64);
                acc += outer(pos - centre) * node.sample_weight(flux, s.area[j] as f64);
            }
        } else {
            for c in p.first as usize..(p.first + p.count) as usize {
                acc += (cov[c] + outer(centroids[c] - centre)) * node.child_weight(&sums[c]);
            }
        }
        cov[i] = acc * (1.0 / node.total_weight().max(f64::MIN_POSITIVE));
    }
    // A node whose covariance does not fit f32 (coordinates beyond ~1e19) gets none: its
    // aggregate falls back to JB02's plain one.
    for c in &mut cov {
        if !c
            .to_cols_array()
            .iter()
            .all(|v| v.is_finite() && v.abs() <= f32::MAX as f64)
        {
            *c = DMat3::ZERO;
        }
    }
    cov
}

/// Per node, the radius of the sphere about its centroid that holds all its samples, exact
/// (every sample visited once per ancestor), measured about the centroid as stored (f32) and
/// rounded up.
fn radii(pending: &[Pending], s: &Samples, centroids: &[DVec3]) -> Vec<f32> {
    pending
        .iter()
        .zip(centroids)
        .map(|(p, &centre)| {
            let centre = centre.as_vec3().as_dvec3();
            let mut r2 = 0.0f64;
            for j in p.start as usize..p.end as usize {
                let pos = DVec3::new(s.pos_x[j] as f64, s.pos_y[j] as f64, s.pos_z[j] as f64);
                r2 = r2.max((pos - centre).length_squared());
            }
            let r = libm::sqrt(r2).min(f32::MAX as f64);
            let rounded = r as f32;
            if (rounded as f64) < r {
                rounded.next_up()
            } else {
                rounded
            }
        })
        .collect()
}
