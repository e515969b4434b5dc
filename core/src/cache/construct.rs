//! Building the cache: validate, quantise, sort by Morton code, split into a breadth-first
//! octree top-down by code prefixes, then aggregate each node over its own (contiguous) run of
//! samples.
//!
//! Cost: O(N log N) for the sort; each node's split costs eight binary searches over its
//! range, so the split is O(N log N) too, and so is the aggregation (each sample is read twice
//! per ancestor). Deterministic: the sort key (code, input index) is unique, and every sum is
//! taken in a fixed order.
//!
//! Memory: besides the input and the cache itself, the build holds the sort keys (16 bytes per
//! sample, freed once the columns are gathered), the sorted codes (8, freed after the split)
//! and the split's node records (24 per node); every node's sums are local to its own
//! aggregation, so nothing else grows with N.

use alloc::vec::Vec;

use core::ops::Range;

use glam::{DVec3, Vec3};

use super::{
    COUNT_MASK, IrradianceCache, LEAF_BIT, LEAF_CAPACITY, MAX_SAMPLES, Nodes, Sample, Samples,
};
use crate::error::BuildError;
use crate::lanes::LANES;
use crate::math;
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
        // At most f32::MAX itself, as documented: a total beyond it by less than half an ulp
        // would round to f32::MAX and pass a test of the rounded value.
        if !(value <= f64::from(f32::MAX)) {
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
        drop(codes);

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

/// One node's sums over its samples, in double precision.
#[derive(Clone, Copy)]
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

/// Sample `j`'s position and flux in double precision.
#[inline]
fn sample_at(s: &Samples, j: usize) -> (DVec3, DVec3) {
    (
        DVec3::new(s.pos_x[j] as f64, s.pos_y[j] as f64, s.pos_z[j] as f64),
        DVec3::new(s.flux_r[j] as f64, s.flux_g[j] as f64, s.flux_b[j] as f64),
    )
}

impl Sums {
    /// The sums over the samples `range` (in order: the same input gives the same bits).
    fn over(s: &Samples, range: Range<usize>) -> Sums {
        let mut acc = Sums {
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            area: 0.0,
            flux: DVec3::ZERO,
            weighted: DVec3::ZERO,
            weight: 0.0,
            area_weighted: DVec3::ZERO,
            position_sum: DVec3::ZERO,
            count: 0.0,
        };
        for j in range {
            let (pos, flux) = sample_at(s, j);
            let area = s.area[j] as f64;
            let w = flux.x + flux.y + flux.z;
            acc.lo = acc.lo.min(pos);
            acc.hi = acc.hi.max(pos);
            acc.area += area;
            acc.flux += flux;
            acc.weighted += pos * w;
            acc.weight += w;
            acc.area_weighted += pos * area;
            acc.position_sum += pos;
            acc.count += 1.0;
        }
        acc
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
    /// This node's total weight under its own weighting.
    fn total_weight(&self) -> f64 {
        if self.weight > 0.0 {
            self.weight
        } else if self.area > 0.0 {
            self.area
        } else {
            self.count
        }
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

/// A node's weighted covariance about its centroid (the centroid's weights), in the order
/// `[xx, yy, zz, xy, xz, yz]`, and the radius of the sphere about its centroid as stored (f32)
/// that holds all its samples, exact and rounded up. Two-pass (the centroid first), so no
/// cancellation; a covariance that does not fit f32 (coordinates beyond ~1e19) is zero, and
/// the node's aggregate falls back to JB02's plain one.
fn spread(s: &Samples, range: Range<usize>, sums: &Sums, centre: DVec3) -> ([f32; 6], f32) {
    let stored = centre.as_vec3().as_dvec3();
    let mut acc = [0.0f64; 6];
    let mut r2 = 0.0f64;
    for j in range {
        let (pos, flux) = sample_at(s, j);
        let w = sums.sample_weight(flux, s.area[j] as f64);
        let d = pos - centre;
        for (a, v) in acc.iter_mut().zip([
            d.x * d.x,
            d.y * d.y,
            d.z * d.z,
            d.y * d.x,
            d.z * d.x,
            d.z * d.y,
        ]) {
            *a += v * w;
        }
        r2 = r2.max((pos - stored).length_squared());
    }
    let scale = 1.0 / sums.total_weight().max(f64::MIN_POSITIVE);
    let cov = acc.map(|a| a * scale);
    let cov = if cov
        .iter()
        .all(|v| v.is_finite() && v.abs() <= f32::MAX as f64)
    {
        cov.map(|v| v as f32)
    } else {
        [0.0; 6]
    };
    let r = math::sqrt64(r2).min(f32::MAX as f64);
    let rounded = r as f32;
    let radius = if (rounded as f64) < r {
        rounded.next_up()
    } else {
        rounded
    };
    (cov, radius)
}

/// Writes the node columns, each node's aggregates summed afresh over its own sample range
/// (every range is contiguous in Morton order), and returns the root's bounds.
///
/// Nothing is held per node but its output: the bottom-up sweep this replaced kept double-
/// precision sums, centroids and covariances of every node at once (264 bytes per node, about
/// 100 bytes per sample, the peak of a whole render). The price is that each sample is read
/// twice per ancestor, O(N · depth), which the radius already cost.
fn aggregate(pending: &[Pending], s: &Samples) -> (Nodes, Option<(Vec3, Vec3)>) {
    let padded = pending.len() + LANES;
    let column = || Vec::with_capacity(padded);
    let mut d = Nodes {
        area: column(),
        flux_r: column(),
        flux_g: column(),
        flux_b: column(),
        centroid_x: column(),
        centroid_y: column(),
        centroid_z: column(),
        radius: column(),
        cov_xx: column(),
        cov_yy: column(),
        cov_zz: column(),
        cov_xy: column(),
        cov_xz: column(),
        cov_yz: column(),
        first: Vec::with_capacity(padded),
        info: Vec::with_capacity(padded),
    };
    let mut root_bounds = None;
    for p in pending {
        let range = p.start as usize..p.end as usize;
        let sums = Sums::over(s, range.clone());
        let centre = sums.centroid();
        let (cov, radius) = spread(s, range, &sums, centre);
        if root_bounds.is_none() {
            root_bounds = Some((sums.lo.as_vec3(), sums.hi.as_vec3()));
        }
        d.area.push(sums.area as f32);
        d.flux_r.push(sums.flux.x as f32);
        d.flux_g.push(sums.flux.y as f32);
        d.flux_b.push(sums.flux.z as f32);
        d.centroid_x.push(centre.x as f32);
        d.centroid_y.push(centre.y as f32);
        d.centroid_z.push(centre.z as f32);
        d.radius.push(radius);
        for (c, v) in [
            &mut d.cov_xx,
            &mut d.cov_yy,
            &mut d.cov_zz,
            &mut d.cov_xy,
            &mut d.cov_xz,
            &mut d.cov_yz,
        ]
        .into_iter()
        .zip(cov)
        {
            c.push(v);
        }
        d.first.push(p.first);
        d.info
            .push((p.count & COUNT_MASK) | if p.leaf { LEAF_BIT } else { 0 });
    }
    for c in [
        &mut d.area,
        &mut d.flux_r,
        &mut d.flux_g,
        &mut d.flux_b,
        &mut d.centroid_x,
        &mut d.centroid_y,
        &mut d.centroid_z,
        &mut d.radius,
        &mut d.cov_xx,
        &mut d.cov_yy,
        &mut d.cov_zz,
        &mut d.cov_xy,
        &mut d.cov_xz,
        &mut d.cov_yz,
    ] {
        c.resize(padded, 0.0);
    }
    d.first.resize(padded, 0);
    d.info.resize(padded, 0);
    (d, root_bounds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    /// Every node's aggregates, the independent way: bottom-up over the children in double
    /// precision, centroids and covariances combined by the parallel-axis theorem
    /// (C = Σ_c W_c (C_c + (P_c − P)(P_c − P)ᵀ) / W), against what the build stored.
    fn check_against_bottom_up(samples: &[Sample]) {
        let cache = IrradianceCache::build(samples).unwrap();
        cache.validate().unwrap();
        let (s, d, m) = (&cache.samples, &cache.nodes, cache.node_len);
        // (area, flux, Σw p, Σw, Σ A p, Σ p, count, lo, hi) per node.
        #[derive(Clone, Copy)]
        struct Node {
            area: f64,
            flux: DVec3,
            wp: DVec3,
            w: f64,
            ap: DVec3,
            p: DVec3,
            n: f64,
            range: (usize, usize),
        }
        let mut nodes = alloc::vec![
            Node {
                area: 0.0,
                flux: DVec3::ZERO,
                wp: DVec3::ZERO,
                w: 0.0,
                ap: DVec3::ZERO,
                p: DVec3::ZERO,
                n: 0.0,
                range: (0, 0),
            };
            m
        ];
        let mut centre = alloc::vec![DVec3::ZERO; m];
        let mut cov = alloc::vec![DMat3::ZERO; m];
        let outer = |v: DVec3| DMat3::from_cols(v * v.x, v * v.y, v * v.z);
        // How node `i` weighs a sample or child: flux, else area, else count.
        let weigh = |node: &Node, w: f64, area: f64, n: f64| {
            if node.w > 0.0 {
                w
            } else if node.area > 0.0 {
                area
            } else {
                n
            }
        };
        for i in (0..m).rev() {
            let (first, count) = (d.first[i] as usize, (d.info[i] & COUNT_MASK) as usize);
            let leaf = d.info[i] & LEAF_BIT != 0;
            let mut node = nodes[i];
            let children = first..first + count;
            if leaf {
                node.range = (first, first + count);
                for j in children.clone() {
                    let (p, f) = sample_at(s, j);
                    let w = f.x + f.y + f.z;
                    node.area += s.area[j] as f64;
                    node.flux += f;
                    node.wp += p * w;
                    node.w += w;
                    node.ap += p * s.area[j] as f64;
                    node.p += p;
                    node.n += 1.0;
                }
            } else {
                node.range = (nodes[first].range.0, nodes[first + count - 1].range.1);
                for c in children.clone() {
                    let k = nodes[c];
                    node.area += k.area;
                    node.flux += k.flux;
                    node.wp += k.wp;
                    node.w += k.w;
                    node.ap += k.ap;
                    node.p += k.p;
                    node.n += k.n;
                }
            }
            let total = weigh(&node, node.w, node.area, node.n);
            let mut c = if node.w > 0.0 {
                node.wp / node.w
            } else if node.area > 0.0 {
                node.ap / node.area
            } else {
                node.p / node.n
            };
            let (lo, hi) = (node.range.0..node.range.1)
                .map(|j| sample_at(s, j).0)
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p), hi.max(p))
                });
            c = c.clamp(lo, hi);
            let mut acc = DMat3::ZERO;
            if leaf {
                for j in children {
                    let (p, f) = sample_at(s, j);
                    acc += outer(p - c) * weigh(&node, f.x + f.y + f.z, s.area[j] as f64, 1.0);
                }
            } else {
                for k in children {
                    let w = weigh(&node, nodes[k].w, nodes[k].area, nodes[k].n);
                    acc += (cov[k] + outer(centre[k] - c)) * w;
                }
            }
            nodes[i] = node;
            centre[i] = c;
            cov[i] = acc * (1.0 / total.max(f64::MIN_POSITIVE));

            let scale = (hi - lo).length().max(f64::MIN_POSITIVE);
            let rel = |got: f32, want: f64, of: f64| {
                assert!(
                    (got as f64 - want).abs() <= 1e-6 * of + 1e-30,
                    "node {i}: {got} against {want}"
                );
            };
            rel(d.area[i], node.area, node.area);
            for (got, want) in [d.flux_r[i], d.flux_g[i], d.flux_b[i]]
                .into_iter()
                .zip(node.flux.to_array())
            {
                rel(got, want, want);
            }
            let stored = DVec3::new(
                d.centroid_x[i] as f64,
                d.centroid_y[i] as f64,
                d.centroid_z[i] as f64,
            );
            for (got, want) in stored.to_array().into_iter().zip(c.to_array()) {
                rel(got as f32, want, scale + want.abs());
            }
            let trace = cov[i].x_axis.x + cov[i].y_axis.y + cov[i].z_axis.z;
            for (got, (a, b)) in [
                (d.cov_xx[i], (0, 0)),
                (d.cov_yy[i], (1, 1)),
                (d.cov_zz[i], (2, 2)),
                (d.cov_xy[i], (0, 1)),
                (d.cov_xz[i], (0, 2)),
                (d.cov_yz[i], (1, 2)),
            ] {
                rel(got, cov[i].col(a)[b], trace);
            }
            // The radius: the farthest sample from the stored centroid, rounded up by at most
            // one f32 step.
            let far = (node.range.0..node.range.1)
                .map(|j| (sample_at(s, j).0 - stored).length())
                .fold(0.0f64, f64::max);
            assert!(d.radius[i] as f64 >= far, "node {i}: radius below a sample");
            assert!(
                d.radius[i] as f64 <= far * (1.0 + 2e-7) + 1e-30,
                "node {i}: radius {} for {far}",
                d.radius[i]
            );
        }
    }

    /// A pseudo-random sphere with a terminator (unlit nodes fall back to area weights), some
    /// samples with zero area and, on request, every sample dark and without area (uniform
    /// weights), or on a few coincident points (count splits).
    fn samples(n: usize, mode: u32) -> Vec<Sample> {
        let mut state = 0x2545_f491_4f6c_dd1du64 ^ n as u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|i| {
                let z = next() * 2.0 - 1.0;
                let phi = next() * core::f32::consts::TAU;
                let r = libm::sqrtf((1.0 - z * z).max(0.0));
                let p = match mode {
                    2 => Vec3::splat((i % 3) as f32),
                    _ => Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z) * 3.0,
                };
                let lit = if mode == 1 { 0.0 } else { p.x.max(0.0) };
                let area = if mode == 1 || i % 7 == 0 { 0.0 } else { next() };
                Sample {
                    position: p + Vec3::new(10.0, -4.0, 2.0),
                    area,
                    irradiance: Vec3::new(lit, 0.5 * lit, 0.25 * lit),
                }
            })
            .collect()
    }

    #[test]
    fn aggregates_match_the_bottom_up_sums() {
        for n in [1usize, 8, 9, 100, 5000, 60_000] {
            check_against_bottom_up(&samples(n, 0));
        }
        check_against_bottom_up(&samples(3000, 1));
        check_against_bottom_up(&samples(3000, 2));
    }
}
