//! Surface points, sample counts, and area-uniform points on a triangle mesh: the raw
//! candidates that sample elimination thins out.

use glam::{Vec2, Vec3};

use super::error::{MAX_SAMPLES, SamplingError};
use crate::parallel::{first_where, ordered_sum};
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
        if let Some(i) = first_where(triangles, |t| non_finite(t).is_some()) {
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
