//! What can go wrong when placing samples, with messages that name the culprit.

use std::fmt;

use glam::Vec3;

/// Most samples [`poisson_samples`](super::poisson_samples) will place: the scene's limit
/// ([`crate::scene::MAX_SAMPLES`], 2²⁵). More is almost always a unit mistake (a spacing in
/// millimetres for a scene in metres); the error says how many it would have made.
pub const MAX_SAMPLES: u64 = crate::scene::MAX_SAMPLES as u64;

/// Why samples could not be placed.
#[derive(Clone, Debug, PartialEq)]
pub enum SamplingError {
    /// A vertex has a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Index of the triangle in the input slice.
        triangle: u32,
        /// Which of its vertices (0, 1 or 2).
        vertex: u8,
        /// The offending position.
        position: Vec3,
    },
    /// More triangles than `u32` indices can name.
    TooManyTriangles {
        /// How many were given.
        count: usize,
    },
    /// The triangles have zero total area (or there are none).
    ZeroArea {
        /// How many triangles were given.
        triangles: usize,
    },
    /// `SampleTarget::Count(0)`.
    ZeroCount,
    /// A spacing that is not a positive finite distance.
    InvalidSpacing {
        /// The spacing given.
        spacing: f32,
    },
    /// A spacing so large that not even one sample fits.
    SpacingTooLarge {
        /// The spacing given.
        spacing: f32,
        /// Total area of the surface.
        total_area: f64,
    },
    /// More samples than [`MAX_SAMPLES`] were asked for, directly or through a small spacing.
    TooManySamples {
        /// How many samples would have been made.
        count: u64,
        /// The spacing that led to the count, if one was given.
        spacing: Option<f32>,
        /// Total area of the surface.
        total_area: f64,
    },
}

impl fmt::Display for SamplingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SamplingError::NonFiniteVertex {
                triangle,
                vertex,
                position,
            } => write!(
                f,
                "triangle {triangle}: vertex {vertex} is not finite ({}, {}, {})",
                position.x, position.y, position.z
            ),
            SamplingError::TooManyTriangles { count } => write!(
                f,
                "{count} triangles given; at most {} can be sampled",
                u32::MAX
            ),
            SamplingError::ZeroArea { triangles } => write!(
                f,
                "the surface has zero total area ({triangles} triangles): nowhere to place samples"
            ),
            SamplingError::ZeroCount => write!(f, "sample count is 0; ask for at least 1 sample"),
            SamplingError::InvalidSpacing { spacing } => write!(
                f,
                "sample spacing must be a positive, finite distance; got {spacing}"
            ),
            SamplingError::SpacingTooLarge {
                spacing,
                total_area,
            } => write!(
                f,
                "sample spacing {spacing} is too large for a surface of total area {total_area}: \
                 it would place no sample"
            ),
            SamplingError::TooManySamples {
                count,
                spacing: Some(spacing),
                total_area,
            } => {
                // The count saturates at u64::MAX for absurd spacings: say so, not 18446….
                let count = match *count {
                    u64::MAX => "more than 10¹⁹".to_string(),
                    n => n.to_string(),
                };
                write!(
                    f,
                    "sample spacing {spacing} over a total area of {total_area} would make \
                     {count} samples, more than the limit of {MAX_SAMPLES}; check the scene's \
                     units"
                )
            }
            SamplingError::TooManySamples { count, .. } => write!(
                f,
                "{count} samples asked for, more than the limit of {MAX_SAMPLES}"
            ),
        }
    }
}

impl std::error::Error for SamplingError {}
