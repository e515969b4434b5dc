//! Surface points, sample counts, and area-uniform points on a triangle mesh: the raw
//! candidates that sample elimination thins out.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::error::{MAX_SAMPLES, SamplingError};
use crate::scene::SampleDensity;

/// A point on a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// World-space position.
    pub position: Vec3,
    /// Index of the triangle in the input slice.
    pub triangle: u32,
    /// Barycentric weights `(b1, b2)` of the triangle's second and third vertex; the first
    /// vertex has `b0 = 1 − b1 − b2`. `position ≈ b0·v0 + b1·v1 + b2·v2`.
    pub bary: Vec2,
}

/// How many samples to place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleTarget {
    /// Exactly this many.
    Count(u32),
    /// As many as hexagonal packing at this spacing (scene units) puts on the surface:
    /// `N = round(2A / (√3 s²))`, the number of cells of area `(√3/2)·s²` (the area per point
    /// of a hexagonal lattice of nearest-neighbour distance `s`) that cover the total area `A`.
    Spacing(f32),
}

impl From<SampleDensity> for SampleTarget {
    fn from(d: SampleDensity) -> Self {
        match d {
            SampleDensity::Count(n) => SampleTarget::Count(n),
            SampleDensity::Spacing(s) => SampleTarget::Spacing(s),
        }
    }
}

impl SampleTarget {
    /// The number of samples for a surface of total area `total_area`, or why there is none:
    /// 0, more than [`MAX_SAMPLES`], or a spacing that is not positive and finite.
    pub fn resolve(self, total_area: f64) -> Result<u32, SamplingError> {
        match self {
            SampleTarget::Count(0) => Err(SamplingError::ZeroCount),
            SampleTarget::Count(n) if n as u64 > MAX_SAMPLES => {
                Err(SamplingError::TooManySamples {
                    count: n as u64,
                    spacing: None,
                    total_area,
                })
            }
            SampleTarget::Count(n) => Ok(n),
            SampleTarget::Spacing(s) => {
                if !(s.is_finite() && s > 0.0) {
                    return Err(SamplingError::InvalidSpacing { spacing: s });
                }
                let s = s as f64;
                let n = (2.0 * total_area / (3.0f64.sqrt() * s * s)).round();
                if n > MAX_SAMPLES as f64 {
                    // Saturating cast: absurd spacings report u64::MAX.
                    Err(SamplingError::TooManySamples {
                        count: n as u64,
                        spacing: Some(s as f32),
                        total_area,
                    })
                } else if n < 1.0 {
                    Err(SamplingError::SpacingTooLarge {
                        spacing: s as f32,
                        total_area,
                    })
                } else {
                    Ok(n as u32)
                }
            }
        }
    }
}

/// The nearest-neighbour distance of a hexagonal lattice of `count` points covering area
/// `total_area`: `√(2A / (√3 N))`, the inverse of [`SampleTarget::Spacing`]'s count. It is
/// `2·r_max` of Yuksel 2015, the largest minimum distance `count` points on the surface can
/// have (for a flat surface, ignoring its boundary).
pub fn hex_spacing(total_area: f64, count: u32) -> f32 {
    (2.0 * total_area / (3.0f64.sqrt() * count.max(1) as f64)).sqrt() as f32
}

/// Area of one triangle, computed in `f64`.
pub fn triangle_area(t: &[Vec3; 3]) -> f64 {
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    0.5 * (b - a).cross(c - a).length()
}

/// Total area of the triangles, summed in `f64` in input order (the mean area per sample is
/// `total_area / N`). Non-finite vertices make it non-finite.
pub fn total_area(triangles: &[[Vec3; 3]]) -> f64 {
    ordered_sum(triangles.len(), |i| triangle_area(&triangles[i]))
}

/// Terms [`ordered_sum`] holds at a time (8 MB).
const SUM_BLOCK: usize = 1 << 20;

/// `Σ term(i)` for `i` in `0..n`, added one by one in index order as a serial loop adds them,
/// so with the same bits for any thread count; the terms are computed on every thread, a
/// block at a time. (Millions of triangles' areas took a tenth of a second on one thread.)
pub(crate) fn ordered_sum(n: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
    ordered_sum_in_blocks(n, SUM_BLOCK, term)
}

/// [`ordered_sum`] with `block` terms at a time.
fn ordered_sum_in_blocks(n: usize, block: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
    let mut total = 0.0;
    let mut terms = Vec::with_capacity(n.min(block));
    for start in (0..n).step_by(block.max(1)) {
        terms.clear();
        terms.par_extend((start..n.min(start + block)).into_par_iter().map(&term));
        for &t in &terms {
            total += t;
        }
    }
    total
}

/// The validated triangle set: every vertex finite, at most `u32::MAX` triangles, positive
/// total area. (Candidates themselves come from [`super::strata::Strata`].)
pub(super) struct AreaDistribution {
    total: f64,
}

impl AreaDistribution {
    /// Validates the triangles and sums their areas.
    pub(super) fn new(triangles: &[[Vec3; 3]]) -> Result<AreaDistribution, SamplingError> {
        if triangles.len() > u32::MAX as usize {
            return Err(SamplingError::TooManyTriangles {
                count: triangles.len(),
            });
        }
        let non_finite = |t: &[Vec3; 3]| t.iter().position(|v| !v.is_finite());
        if let Some(i) = triangles
            .par_iter()
            .position_first(|t| non_finite(t).is_some())
        {
            let t = &triangles[i];
            let k = non_finite(t).unwrap_or(0);
            return Err(SamplingError::NonFiniteVertex {
                triangle: i as u32,
                vertex: k as u8,
                position: t[k],
            });
        }
        let total = total_area(triangles);
        if total > 0.0 {
            Ok(AreaDistribution { total })
        } else {
            Err(SamplingError::ZeroArea {
                triangles: triangles.len(),
            })
        }
    }

    /// Total area.
    pub(super) fn total(&self) -> f64 {
        self.total
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::testutil::Rng;

    /// The sum in blocks on any number of threads has the bits of the serial loop, on terms
    /// of every magnitude (where the order of the additions shows in the result).
    #[test]
    fn ordered_sum_has_the_serial_bits() {
        let mut rng = Rng::new(11);
        let terms: Vec<f64> = (0..5000)
            .map(|_| (rng.f32_in(0.0, 1.0) as f64) * 10f64.powi((rng.f32_in(-8.0, 8.0)) as i32))
            .collect();
        let mut serial = 0.0;
        for &t in &terms {
            serial += t;
        }
        // A different order gives other bits on these terms, so the test can tell.
        assert_ne!(terms.iter().rev().sum::<f64>().to_bits(), serial.to_bits());
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for block in [1, 7, 64, 4999, 5000, 100_000] {
                let sum = pool.install(|| ordered_sum_in_blocks(terms.len(), block, |i| terms[i]));
                assert_eq!(
                    sum.to_bits(),
                    serial.to_bits(),
                    "{threads} threads, blocks of {block}"
                );
            }
        }
        assert_eq!(ordered_sum(0, |_| 1.0), 0.0);
    }

    /// The first non-finite vertex in input order is the one reported.
    #[test]
    fn the_first_non_finite_vertex_is_reported() {
        let mut tris = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]; 100_000];
        tris[70_000][2] = Vec3::new(0.0, f32::INFINITY, 0.0);
        tris[30_000][1] = Vec3::NAN;
        tris[90_000][0] = Vec3::NAN;
        match AreaDistribution::new(&tris) {
            Err(SamplingError::NonFiniteVertex {
                triangle, vertex, ..
            }) => assert_eq!((triangle, vertex), (30_000, 1)),
            Err(e) => panic!("{e}"),
            Ok(_) => panic!("accepted a NaN vertex"),
        }
        assert!((AreaDistribution::new(&tris[..30_000]).unwrap().total() - 15_000.0).abs() < 1e-9);
    }
}
