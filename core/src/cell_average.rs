//! The irradiance a sample carries where a shadow edge crosses its cell: the mean over the
//! cell instead of the value at its centre (part of the edge-refined method;
//! `docs/physics.md` §16).
//!
//! A sample stands for its cell of area A in every sum (JB02's Σ Rd·E·A), so the exact weight
//! is ∫_cell E dA, and E(centre)·A is a one-point estimate of it. Where E is smooth over the
//! cell the two differ only at second order (each sample sits at its cell's centroid). Where a
//! shadow edge crosses the cell they differ by up to the whole lit level times A, lit or dark
//! by which side of the edge the centre happens to fall on: the error that every split
//! method's global sum carries along a shadow edge at affordable densities. The edge-refined
//! method tests each cell with [`CellAverage::PROBES`] probes and, where a light reaches a probe
//! but not the sample or the other way round (one shadow ray per light and probe, the test is
//! the caller's), lights the sample with the mean over [`CellAverage::NODES`] points spread
//! evenly over the cell. Everywhere else the sample keeps its centre's value, bit for bit.
//!
//! ```text
//!   probes: radius 0.7·ρ,           mean: a Vogel spiral of 16 nodes (equal areas)
//!   the four diagonals                r_j = ρ·√((j + ½)/16),  θ_j = j·γ   (γ = π(3 − √5))
//!      ·       ·                         ·   ·
//!          x                           ·  · x ·  ·      both turned by ψ per sample (a hash),
//!      ·       ·                         ·  ·  ·        so no edge direction is favoured
//!
//!   ρ = √(A/π): the disc of the cell's area about the sample (its cell's centroid)
//! ```
//!
//! The disc stands in for the cell (a Voronoi polygon of about the same extent). Points off the
//! sample lie on its tangent plane, lifted like the refinement's nodes onto the sphere of radius
//! 4ρ that touches the surface there ([`CellAverage::lift`]); the renderer ignores occluders
//! within ρ/2 of them, for the reasons given in [`crate::LocalQuadrature`]'s docs.

use glam::{Vec2, Vec3};

use crate::math;

/// The probes' distance from the sample, in units of ρ.
const PROBE_RADIUS: f32 = 0.7;
/// The sphere the off-centre points are lifted onto has this radius in units of ρ.
const LIFT_RADIUS: f32 = 4.0;

/// The probe and averaging patterns of a cell, on the unit disc (ρ = 1), before the per-sample
/// turn. Build once ([`CellAverage::new`]) and share.
///
/// Layout: `probe[k]` at angle π/4 + k·π/2, radius 0.7; `node[j]` at angle j·γ, radius
/// √((j + ½)/16). 4 × 8 + 16 × 8 = 160 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellAverage {
    probe: [Vec2; CellAverage::PROBES],
    node: [Vec2; CellAverage::NODES],
}

const _: () = assert!(core::mem::size_of::<CellAverage>() == 160);

impl Default for CellAverage {
    fn default() -> Self {
        Self::new()
    }
}

impl CellAverage {
    /// Probes per cell: the points whose irradiance decides whether the cell is averaged.
    pub const PROBES: usize = 4;
    /// Points of the mean over an averaged cell.
    pub const NODES: usize = 16;

    /// The patterns.
    pub fn new() -> Self {
        let probe = core::array::from_fn(|k| {
            let angle = core::f64::consts::FRAC_PI_4 * (2 * k + 1) as f64;
            let (s, c) = math::sin_cos64(angle);
            Vec2::new(c as f32, s as f32) * PROBE_RADIUS
        });
        let golden_angle = core::f64::consts::PI * (3.0 - math::sqrt64(5.0));
        let node = core::array::from_fn(|j| {
            let r = math::sqrt64((j as f64 + 0.5) / Self::NODES as f64);
            let (s, c) = math::sin_cos64(golden_angle * j as f64);
            Vec2::new((c * r) as f32, (s * r) as f32)
        });
        CellAverage { probe, node }
    }

    /// ρ = √(A/π), the radius of the disc of the cell's area (0 for an area that is not
    /// positive and finite).
    pub fn radius(area: f32) -> f32 {
        if area.is_finite() && area > 0.0 {
            math::sqrt(area / core::f32::consts::PI)
        } else {
            0.0
        }
    }

    /// Probe k's position in the tangent frame (scene units) for a cell of radius `rho`, the
    /// pattern turned by `rotation` (cos ψ, sin ψ; [`crate::LocalQuadrature::rotation`]).
    pub fn probe(&self, k: usize, rho: f32, rotation: Vec2) -> Vec2 {
        rotation.rotate(self.probe[k % Self::PROBES]) * rho
    }

    /// Averaging node j's position in the tangent frame (scene units), as [`Self::probe`].
    pub fn node(&self, j: usize, rho: f32, rotation: Vec2) -> Vec2 {
        rotation.rotate(self.node[j % Self::NODES]) * rho
    }

    /// How far a point at `offset` from the sample is lifted along the normal, for a cell of
    /// radius `rho`: the sagitta of the sphere of radius 4ρ, at most 0.13·ρ.
    pub fn lift(offset: Vec2, rho: f32) -> f32 {
        let r2 = offset.length_squared();
        let big = LIFT_RADIUS * rho;
        let lift = r2 / (big + math::sqrt((big * big - r2).max(0.0)));
        if lift.is_finite() { lift } else { 0.0 }
    }

    /// The mean of the irradiance at the averaging nodes (node order).
    pub fn mean(at_nodes: &[Vec3; CellAverage::NODES]) -> Vec3 {
        at_nodes.iter().copied().sum::<Vec3>() / Self::NODES as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nodes have equal areas: the fraction of them within radius r of the centre tracks
    /// the disc's area fraction r² to within one node.
    #[test]
    fn nodes_cover_the_disc_evenly() {
        let cells = CellAverage::new();
        for r in [0.25f32, 0.5, 0.75, 1.0] {
            let inside = (0..CellAverage::NODES)
                .filter(|&j| cells.node(j, 1.0, Vec2::X).length() <= r)
                .count();
            let expected = r * r * CellAverage::NODES as f32;
            assert!(
                (inside as f32 - expected).abs() <= 1.0,
                "r = {r}: {inside} nodes, {expected} expected"
            );
        }
        // The centroid of the nodes is near the centre (no side of the cell favoured).
        let centroid: Vec2 = (0..CellAverage::NODES)
            .map(|j| cells.node(j, 1.0, Vec2::X))
            .sum::<Vec2>()
            / CellAverage::NODES as f32;
        assert!(centroid.length() < 0.06, "{centroid}");
    }

    /// The mean of a half-lit cell, a straight edge at distance d from the centre, against the
    /// disc's exact area fraction beyond a chord, (θ − sin θ)/(2π) with θ = 2·acos(d), over
    /// many turns of the pattern: unbiased to a few percent of the lit level, and within one
    /// node's weight at any single turn.
    #[test]
    fn mean_of_a_straight_edge_matches_the_chord_area() {
        let cells = CellAverage::new();
        for d in [-0.6f32, -0.3, 0.0, 0.3, 0.6] {
            let theta = 2.0 * math::acos64(f64::from(d));
            let lit_exact =
                1.0 - (theta - math::sin_cos64(theta).0) / (2.0 * core::f64::consts::PI);
            let turns = 256;
            let mut sum = 0.0;
            for t in 0..turns {
                let rotation = crate::LocalQuadrature::rotation_for_seed(t);
                let at: [Vec3; CellAverage::NODES] = core::array::from_fn(|j| {
                    // Lit where x < d (the lit side holds more than half for d > 0).
                    if cells.node(j, 1.0, rotation).x < d {
                        Vec3::ONE
                    } else {
                        Vec3::ZERO
                    }
                });
                let m = f64::from(CellAverage::mean(&at).x);
                assert!((m - lit_exact).abs() <= 0.19, "d = {d}: {m} vs {lit_exact}");
                sum += m;
            }
            let mean = sum / f64::from(turns as u32);
            assert!(
                (mean - lit_exact).abs() < 0.02,
                "d = {d}: mean {mean} vs exact {lit_exact}"
            );
        }
    }

    #[test]
    fn radius_and_lift() {
        let rho = CellAverage::radius(core::f32::consts::PI * 4.0);
        assert!((rho - 2.0).abs() < 1e-6);
        assert_eq!(CellAverage::radius(-1.0), 0.0);
        assert_eq!(CellAverage::radius(f32::NAN), 0.0);
        // The sagitta of the sphere of radius 4ρ at r = ρ: 4ρ − √(15)ρ.
        let lift = CellAverage::lift(Vec2::new(1.0, 0.0), 1.0);
        assert!((lift - (4.0 - math::sqrt(15.0))).abs() < 1e-6, "{lift}");
        assert_eq!(CellAverage::lift(Vec2::ZERO, 1.0), 0.0);
        assert_eq!(CellAverage::lift(Vec2::X, 0.0), 0.0);
    }
}
