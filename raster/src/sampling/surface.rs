//! Surface points, sample counts, and area-uniform points on a triangle mesh: the raw
//! candidates that sample elimination thins out.

use glam::{DVec3, Vec2, Vec3};

use super::error::{MAX_SAMPLES, SamplingError};
use super::rng::Pcg32;
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
    triangles.iter().map(triangle_area).sum()
}

/// Picks triangles with probability proportional to their area: inversion of the cumulative
/// areas, started from a guide table (Chen & Asau 1974, "On generating random variates from an
/// empirical distribution") so that a lookup costs O(1) on average instead of a bisection's
/// O(log n) cache misses. The answer is exactly the bisection's.
pub(super) struct AreaDistribution {
    /// `cumulative[i]` = total area of triangles `0..=i`.
    cumulative: Vec<f64>,
    /// `guide[k]` = the first triangle whose cumulative area exceeds `k/len` of the total.
    guide: Vec<u32>,
    /// The last triangle with positive area (the fallback when rounding lands past the end).
    last_positive: u32,
}

impl AreaDistribution {
    /// Validates the triangles (finite, at most `u32::MAX`, positive total area) and builds
    /// the distribution.
    pub(super) fn new(triangles: &[[Vec3; 3]]) -> Result<AreaDistribution, SamplingError> {
        if triangles.len() > u32::MAX as usize {
            return Err(SamplingError::TooManyTriangles {
                count: triangles.len(),
            });
        }
        let mut cumulative = Vec::with_capacity(triangles.len());
        let mut sum = 0.0f64;
        let mut last_positive = None;
        for (i, t) in triangles.iter().enumerate() {
            if let Some(k) = t.iter().position(|v| !v.is_finite()) {
                return Err(SamplingError::NonFiniteVertex {
                    triangle: i as u32,
                    vertex: k as u8,
                    position: t[k],
                });
            }
            let a = triangle_area(t);
            if a > 0.0 {
                last_positive = Some(i as u32);
            }
            sum += a;
            cumulative.push(sum);
        }
        let n = cumulative.len();
        let mut guide = Vec::with_capacity(n);
        let mut i = 0;
        for k in 0..n {
            let threshold = k as f64 / n as f64 * sum;
            while i + 1 < n && cumulative[i] <= threshold {
                i += 1;
            }
            guide.push(i as u32);
        }
        match last_positive {
            Some(last_positive) => Ok(AreaDistribution {
                cumulative,
                guide,
                last_positive,
            }),
            None => Err(SamplingError::ZeroArea {
                triangles: triangles.len(),
            }),
        }
    }

    /// Total area.
    pub(super) fn total(&self) -> f64 {
        self.cumulative.last().copied().unwrap_or(0.0)
    }

    /// The first triangle whose cumulative area exceeds `u` (zero-area triangles never are),
    /// or the last one of positive area if rounding put `u` at the very end.
    fn find(&self, u: f64) -> u32 {
        let n = self.cumulative.len();
        let k = ((u / self.total() * n as f64) as usize).min(n - 1);
        let mut i = self.guide[k] as usize;
        // The guide is a starting point; these loops make the answer exact whatever rounding
        // did to the bucket index.
        while i > 0 && self.cumulative[i - 1] > u {
            i -= 1;
        }
        while i < n && self.cumulative[i] <= u {
            i += 1;
        }
        if i >= n { self.last_positive } else { i as u32 }
    }

    /// An area-uniform random point: a triangle chosen by area, then a uniform point in it by
    /// the square-root warp (Osada et al. 2002, "Shape Distributions", eq. 1).
    pub(super) fn sample(&self, triangles: &[[Vec3; 3]], rng: &mut Pcg32) -> SurfacePoint {
        let i = self.find(rng.next_f64() * self.total());
        let t = &triangles[i as usize];
        let su = rng.next_f32().sqrt();
        let b2 = su * rng.next_f32();
        let b1 = su - b2;
        SurfacePoint {
            position: point_at(t, b1, b2),
            triangle: i,
            bary: Vec2::new(b1, b2),
        }
    }
}

/// `b0·v0 + b1·v1 + b2·v2`, evaluated in `f64` and rounded once.
fn point_at(t: &[Vec3; 3], b1: f32, b2: f32) -> Vec3 {
    let (b1, b2) = (b1 as f64, b2 as f64);
    let p: DVec3 = t[0].as_dvec3() * (1.0 - b1 - b2) + t[1].as_dvec3() * b1 + t[2].as_dvec3() * b2;
    p.as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guided_inversion_matches_bisection() {
        let mut rng = Pcg32::new(4, 4);
        // Areas spanning decades, with zero-area triangles among them.
        let tris: Vec<[Vec3; 3]> = (0..500)
            .map(|i| {
                let s = if i % 7 == 0 {
                    0.0
                } else {
                    10f32.powf(rng.next_f32() * 4.0 - 2.0)
                };
                [Vec3::ZERO, Vec3::X * s, Vec3::Y]
            })
            .collect();
        let d = AreaDistribution::new(&tris).unwrap();
        for _ in 0..20_000 {
            let u = rng.next_f64() * d.total();
            let want = d.cumulative.partition_point(|&c| c <= u) as u32;
            assert_eq!(d.find(u), want);
            assert!(triangle_area(&tris[want as usize]) > 0.0);
        }
        assert_eq!(d.find(d.total()), d.last_positive);
        assert_eq!(d.find(0.0), 1);
    }
}
