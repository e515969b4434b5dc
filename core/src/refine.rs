//! The edge-refined local term: a deterministic quadrature of the irradiance itself over the
//! smoothing disc, where the irradiance within α is not uniform (a departure from N10;
//! `docs/physics.md` §16).
//!
//! Every split method computes M_o = local + Σ_cut (1 − w)·Rd·E·A, and the exact local term is
//!
//! ```text
//! local(x) = ∫_{|x′ − x| < α} w(|x′ − x|) · Rd(|x′ − x|) · E(x′) dA′     (LM07; w of docs/physics.md §11)
//! ```
//!
//! LM07 takes E(x′) ≈ E(x) (local = E(x)·K, a hard step at a shadow edge); N10 takes the
//! kernel-weighted average of the cache's samples (E_loc·K, soft but blurred by the sample
//! spacing and biased by where the few samples within α happen to lie). Where the irradiance
//! within α is not uniform, the edge-refined method evaluates the integral itself with nodes
//! x′ on the tangent disc of x and E(x′) from the renderer's shadow rays:
//!
//! ```text
//! local(x) = K · ( E(x) + Σ_i f_i · (E(x′_i) − E(x)) ),    Σ_i f_i = 1 (per channel)
//! ```
//!
//! Written about E(x), the sum is exactly E(x)·K (bit for bit, LM07's value) wherever the
//! nodes see the irradiance of x, whatever the rounding of the weights.
//!
//! # The nodes
//!
//! `rings` radii × `per_ring` angles. The radii are importance-placed for the integrand's
//! radial density p(ρ) = ρ·w(ρ)·Rd(ρα) on ρ = r/α ∈ [0, 1] (the same integrand as K): its
//! cumulative distribution (the mean over the channels of each channel's normalised one) is
//! split into `rings` strata of equal mass, and each ring lies at its stratum's mass median.
//! Ring j's weight in channel c is that channel's mass in the stratum over its K, divided
//! among the ring's nodes; the masses telescope, so the fractions sum to 1 in every channel.
//!
//! ```text
//!    ρ = 0 ──●────●──────●────────●──────────── ρ = 1     rings at the mass medians,
//!          |stratum|stratum |  stratum  | stratum  |     equal mass of p each (mean channel)
//!
//!        · ·          ring j: angles 2π(k + j·φ)/per_ring + ψ,  k = 0 … per_ring − 1
//!     ·   x   ·       φ = (√5 − 1)/2 staggers the rings (no two rings line up);
//!        · ·          ψ rotates the whole pattern per pixel (see [`LocalQuadrature::rotation`])
//! ```
//!
//! The cumulative distribution is tabulated with 2-point Gauss–Legendre on 32 intervals
//! uniform in √ρ (denser near x, where Rd peaks when ℓ ≪ α) and inverted by linear
//! interpolation: 64 profile evaluations per construction (once per object for a material that
//! does not vary, per refined point for a textured one).
//!
//! # Where the nodes lie on curved and thin geometry
//!
//! The nodes lie on the tangent disc of x, bent up (towards the normal) onto the sphere of
//! radius 4α that touches the surface at x ([`LocalQuadrature::lift`]): on a concave surface
//! whose radius of curvature is at least 4α they stay above it (on the tangent plane itself
//! they would lie inside the surface, and its own triangles would shadow them), and on a
//! convex one they lie somewhat above it. Their shadow rays ignore occluders within α/2 of the
//! node ([`LocalQuadrature::shadow_skip`]), as if each node moved α/2 towards the light: that
//! steps over the surface near x where it curves up more sharply than the lift (a crease, a
//! fold, or the flat triangles under a node on the tangent plane of an interpolated normal),
//! which would otherwise shadow the node and darken the local term, without moving where the
//! ray meets anything farther away (the parallax of lifting the node as far). An occluder
//! closer than α/2 to the surface is not seen by the nodes. E(x′) is evaluated with the normal at x: to first
//! order in the disc's size the cosine's variation over the disc cancels by the kernel's
//! radial symmetry, so only shadowing and second-order curvature terms are refined. Where the
//! surface turns more sharply within α (an ear's rim, a thin fin), the nodes beyond the rim see
//! the light the tangent plane would see, not what the surface there receives; the
//! refinement is then no better founded than N10's average, which it replaces only where the
//! samples disagree with E(x).

use glam::{Vec2, Vec3};

use crate::kernel::Kernel;
use crate::lanes::{DefaultLanes, LANES, Lanes};
use crate::local_term::LocalTerm;
use crate::math;
use crate::profile::Profile;

/// The most rings a quadrature can have.
pub const MAX_RINGS: usize = 16;
/// The most nodes on one ring.
pub const MAX_PER_RING: usize = 16;
/// The most nodes in all.
pub const MAX_NODES: usize = 64;
/// The rings of the edge-refined method (chosen by measurement, see `BENCHMARKS.md`).
pub const DEFAULT_RINGS: usize = 3;
/// The nodes per ring of the edge-refined method.
pub const DEFAULT_PER_RING: usize = 4;
/// The edge test: the irradiance of the samples within α (summed over the channels) is
/// uniform when every sample's E lies in [(1 − τ)·E(x), E(x)/(1 − τ)] (E(x) also summed; τ = ½:
/// within a factor of 2). Beyond it, the edge-refined method refines the local term. Chosen by
/// cost: a shadow edge changes E by far more, while the cosine falloff over a curved surface
/// changes it by 10–50% within α over much of a lit object (at τ = 0.1 the bunny's shading cost
/// 53% more than edge-aware's, at 2× above and ½ below 18.7%).
pub const EDGE_THRESHOLD: f32 = 0.5;

/// The edge test: true when the irradiance sums in `range` (lowest, highest; an empty range,
/// lowest > highest, is uniform) all lie in [(1 − τ)·E, E/(1 − τ)] of E = `e` summed over the
/// channels, τ = `threshold`.
pub(crate) fn uniform_within(range: (f32, f32), e: Vec3, threshold: f32) -> bool {
    let (lo, hi) = range;
    if lo > hi {
        return true;
    }
    let ex = e.x + e.y + e.z;
    lo >= (1.0 - threshold) * ex && hi * (1.0 - threshold) <= ex
}

/// Intervals of the tabulated radial distribution (uniform in √ρ).
const INTERVALS: usize = 32;

/// Gauss nodes of the radial CDF: two per interval (a multiple of [`LANES`]).
const NODES: usize = 2 * INTERVALS;
const _: () = assert!(NODES.is_multiple_of(LANES));
/// The sphere the nodes are lifted onto has this radius in units of α.
const LIFT_RADIUS: f32 = 4.0;
/// The nodes' shadow rays ignore occluders within this many α of the node (module docs;
/// 0.25, 0.5 and 1 measured on the bunny, `BENCHMARKS.md`).
const SHADOW_SKIP: f32 = 0.5;

/// The nodes and weights of the edge-refined local term for one profile and α.
///
/// Layout: node n = j·per_ring + k (ring j, angle k); `offset[n]` is its unrotated position
/// on the tangent disc in scene units, `fraction[j]` the weight of each node of ring j.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalQuadrature {
    alpha: f32,
    rings: usize,
    per_ring: usize,
    offset: [Vec2; MAX_NODES],
    fraction: [Vec3; MAX_RINGS],
}

impl LocalQuadrature {
    /// The rings of the edge-refined method (chosen by measurement, see `BENCHMARKS.md`).
    pub const DEFAULT_RINGS: usize = DEFAULT_RINGS;
    /// The nodes per ring of the edge-refined method.
    pub const DEFAULT_PER_RING: usize = DEFAULT_PER_RING;
    /// The most nodes a quadrature has: the length of the `at_nodes` slice
    /// [`LocalQuadrature::local_term`] reads at most.
    pub const MAX_NODES: usize = MAX_NODES;
    /// The edge test's threshold τ of [`crate::Method::EdgeRefined`]: a point is flagged
    /// ([`crate::Exitance::refine`]) unless every sample within α has its irradiance (summed
    /// over the channels) in [(1 − τ)·E(x), E(x)/(1 − τ)].
    pub const EDGE_THRESHOLD: f32 = EDGE_THRESHOLD;

    /// The quadrature for `profile` and smoothing radius `alpha` with `rings` radii and
    /// `per_ring` angles (each clamped to 1 ..= its maximum, and rings·per_ring to
    /// [`LocalQuadrature::MAX_NODES`] by reducing the rings). α = 0 or non-finite gives one
    /// node at x.
    pub fn new(profile: &Profile, alpha: f32, rings: usize, per_ring: usize) -> Self {
        Self::with_layout(profile, &QuadratureLayout::new(alpha, rings, per_ring))
    }

    /// [`LocalQuadrature::new`] with the part that does not depend on the profile done once
    /// (a texture-mapped material builds a quadrature per refined point); the same bits.
    pub fn with_layout(profile: &Profile, layout: &QuadratureLayout) -> Self {
        let QuadratureLayout {
            alpha,
            rings,
            per_ring,
            ..
        } = *layout;
        let cdf = RadialCdf::new(profile, layout);
        let mut fraction = [Vec3::ZERO; MAX_RINGS];
        let mut offset = [Vec2::ZERO; MAX_NODES];
        for j in 0..rings {
            let lo = cdf.at_reference_mass(j as f64 / rings as f64);
            let hi = cdf.at_reference_mass((j + 1) as f64 / rings as f64);
            let mid = cdf.at_reference_mass((j as f64 + 0.5) / rings as f64);
            let mass: [f64; 3] =
                core::array::from_fn(|c| (cdf.mass(c, hi) - cdf.mass(c, lo)) / per_ring as f64);
            fraction[j] = Vec3::from(mass.map(|m| m as f32));
            let rho = mid * mid; // t = √ρ
            for k in 0..per_ring {
                let (c, s) = layout.direction[j * per_ring + k];
                offset[j * per_ring + k] = Vec2::new((c * rho) as f32, (s * rho) as f32) * alpha;
            }
        }
        LocalQuadrature {
            alpha,
            rings,
            per_ring,
            offset,
            fraction,
        }
    }

    /// α.
    pub fn alpha(&self) -> f32 {
        self.alpha
    }
    /// The number of nodes (rings × per ring).
    pub fn len(&self) -> usize {
        self.rings * self.per_ring
    }
    /// Never: a quadrature has at least one node.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Rings.
    pub fn rings(&self) -> usize {
        self.rings
    }
    /// Nodes per ring.
    pub fn per_ring(&self) -> usize {
        self.per_ring
    }

    /// Node n's position on the tangent disc (scene units, in the tangent frame's two axes),
    /// the pattern turned by `rotation` (cos ψ, sin ψ), see [`LocalQuadrature::rotation`].
    pub fn offset(&self, n: usize, rotation: Vec2) -> Vec2 {
        rotation.rotate(self.offset[n % MAX_NODES])
    }

    /// How far node n's position is lifted along the normal: the sagitta of the sphere of
    /// radius 4α, 4α − √((4α)² − r²) ≤ 0.13 α (see the module docs).
    pub fn lift(&self, n: usize) -> f32 {
        let r2 = self.offset[n % MAX_NODES].length_squared();
        let big = LIFT_RADIUS * self.alpha;
        r2 / (big + math::sqrt((big * big - r2).max(0.0)))
    }

    /// How far along each node's shadow rays occluders are ignored: α/2 (see the module docs).
    pub fn shadow_skip(&self) -> f32 {
        SHADOW_SKIP * self.alpha
    }

    /// Node n's weight per channel (the fractions sum to 1 in each channel).
    pub fn fraction(&self, n: usize) -> Vec3 {
        self.fraction[(n / self.per_ring).min(MAX_RINGS - 1)]
    }

    /// A rotation (cos ψ, sin ψ) of the pattern from a hash: ψ = 2π·(the hash's top 53 bits
    /// as a fraction), deterministic, so that neighbouring pixels turn it differently and the
    /// remaining angular error becomes fine noise instead of a pattern.
    pub fn rotation(hash: u64) -> Vec2 {
        let u = (hash >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        let (s, c) = math::sin_cos64(2.0 * core::f64::consts::PI * u);
        Vec2::new(c as f32, s as f32)
    }

    /// [`LocalQuadrature::rotation`] of a seed that need not be well mixed (a pixel index, a
    /// sample number): the seed is spread over 64 bits by SplitMix64 first.
    pub fn rotation_for_seed(seed: u64) -> Vec2 {
        Self::rotation(crate::seed::splitmix64(seed))
    }

    /// The local term K·(E(x) + Σ fᵢ·(E(x′ᵢ) − E(x))) from the irradiance `at_nodes` (node
    /// order; missing nodes count as E(x)), K that of `term` (the query's, for this
    /// quadrature's α). Equal to E(x)·K exactly where every node sees E(x).
    pub fn local_term(&self, e_x: Vec3, term: LocalTerm, at_nodes: &[Vec3]) -> Vec3 {
        let k = term.k();
        let mut sum = Vec3::ZERO;
        for (n, e) in at_nodes.iter().enumerate().take(self.len()) {
            sum += self.fraction(n) * (*e - e_x);
        }
        (k * (e_x + sum)).max(Vec3::ZERO)
    }
}

/// What a [`LocalQuadrature`] is built from besides the profile: α, the node counts (clamped
/// as [`LocalQuadrature::new`] clamps them), each node's direction on the disc, and the radial
/// distribution's Gauss nodes (r² at each, and its weight ρ·w(ρ)·dρ). Made once per α and
/// node counts, it serves every profile ([`LocalQuadrature::with_layout`]).
#[derive(Clone, Debug, PartialEq)]
pub struct QuadratureLayout {
    alpha: f32,
    rings: usize,
    per_ring: usize,
    /// (cos, sin) of node j·per_ring + k's angle 2π(k + j·φ)/per_ring.
    direction: [(f64, f64); MAX_NODES],
    /// r² = (t²α)² at Gauss node i of the radial distribution (t = √ρ).
    r2: [f32; NODES],
    /// ρ·w(ρ)·2t·h/2 at Gauss node i: its weight in the radial mass, Rd aside.
    weight: [f64; NODES],
}

impl QuadratureLayout {
    /// The layout of [`LocalQuadrature::new`]`(_, alpha, rings, per_ring)`.
    pub fn new(alpha: f32, rings: usize, per_ring: usize) -> Self {
        let per_ring = per_ring.clamp(1, MAX_PER_RING);
        let rings = rings.clamp(1, MAX_RINGS).min(MAX_NODES / per_ring);
        let alpha = if alpha.is_finite() && alpha > 0.0 {
            alpha
        } else {
            0.0
        };
        let golden = (math::sqrt64(5.0) - 1.0) / 2.0;
        let mut direction = [(0.0, 0.0); MAX_NODES];
        for j in 0..rings {
            for k in 0..per_ring {
                let angle =
                    2.0 * core::f64::consts::PI * (k as f64 + j as f64 * golden) / per_ring as f64;
                let (s, c) = math::sin_cos64(angle);
                direction[j * per_ring + k] = (c, s);
            }
        }
        // Node i = 2m + n: interval m's n-th 2-point Gauss–Legendre node on [0, 1].
        let g = 0.5 / math::sqrt64(3.0);
        let h = 1.0 / INTERVALS as f64;
        let nodes = [0.5 - g, 0.5 + g];
        let t: [f64; NODES] = core::array::from_fn(|i| ((i / 2) as f64 + nodes[i % 2]) * h);
        let r2 = core::array::from_fn(|i| {
            let r = t[i] * t[i] * f64::from(alpha);
            (r * r) as f32
        });
        let weight = core::array::from_fn(|i| {
            let rho = t[i] * t[i];
            // dρ = 2t dt; each Gauss node weighs h/2.
            rho * Kernel::weight_unit(rho) * 2.0 * t[i] * h * 0.5
        });
        QuadratureLayout {
            alpha,
            rings,
            per_ring,
            direction,
            r2,
            weight,
        }
    }

    /// α (0 when the one given was not finite and positive).
    pub fn alpha(&self) -> f32 {
        self.alpha
    }
}

/// The cumulative radial mass of ρ·w(ρ)·Rd(ρα) per channel, at the interval boundaries
/// t_m = m/32 of t = √ρ, normalised to 1 at ρ = 1.
struct RadialCdf {
    mass: [[f64; INTERVALS + 1]; 3],
    reference: [f64; INTERVALS + 1],
}

impl RadialCdf {
    fn new(profile: &Profile, layout: &QuadratureLayout) -> Self {
        let mut mass = [[0.0; INTERVALS + 1]; 3];
        // Rd at every Gauss node, eight at a time as the traversal evaluates it (a textured
        // material builds a quadrature per refined point, and the scalar Rd's libm
        // exponentials cost about six times as much).
        let mut rd = [[0.0f32; NODES]; 3];
        for (chunk, r2) in layout.r2.chunks_exact(LANES).enumerate() {
            let values = profile.rd_lanes(DefaultLanes::load(r2));
            for (c, v) in values.iter().enumerate() {
                rd[c][chunk * LANES..(chunk + 1) * LANES].copy_from_slice(&v.to_array());
            }
        }
        for m in 0..INTERVALS {
            let mut add = [0.0; 3];
            for j in [2 * m, 2 * m + 1] {
                for (c, a) in add.iter_mut().enumerate() {
                    *a += layout.weight[j] * f64::from(rd[c][j]);
                }
            }
            for c in 0..3 {
                mass[c][m + 1] = mass[c][m] + add[c];
            }
        }
        let mut reference = [0.0; INTERVALS + 1];
        let mut channels = 0;
        for column in &mut mass {
            let total = column[INTERVALS];
            if total > 0.0 && total.is_finite() {
                for v in column.iter_mut() {
                    *v /= total;
                }
            } else {
                // No usable mass (α = 0, or Rd vanishing): uniform in t.
                for (m, v) in column.iter_mut().enumerate() {
                    *v = m as f64 / INTERVALS as f64;
                }
            }
            column[INTERVALS] = 1.0;
            for (r, v) in reference.iter_mut().zip(column.iter()) {
                *r += v;
            }
            channels += 1;
        }
        for r in &mut reference {
            *r /= f64::from(channels);
        }
        RadialCdf { mass, reference }
    }

    /// The t where the reference distribution reaches `p` ∈ [0, 1] (linear between boundaries).
    fn at_reference_mass(&self, p: f64) -> f64 {
        if p <= 0.0 {
            return 0.0;
        }
        if p >= 1.0 {
            return 1.0;
        }
        let m = self
            .reference
            .partition_point(|&v| v < p)
            .clamp(1, INTERVALS);
        let (lo, hi) = (self.reference[m - 1], self.reference[m]);
        let s = if hi > lo { (p - lo) / (hi - lo) } else { 0.0 };
        (m as f64 - 1.0 + s) / INTERVALS as f64
    }

    /// Channel c's normalised mass below t (linear between boundaries).
    fn mass(&self, c: usize, t: f64) -> f64 {
        let x = (t * INTERVALS as f64).clamp(0.0, INTERVALS as f64);
        let m = (x as usize).min(INTERVALS - 1);
        let s = x - m as f64;
        self.mass[c][m] + s * (self.mass[c][m + 1] - self.mass[c][m])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dipole::UnitDipole;
    use crate::quadrature::GaussLegendre;
    use crate::table::local_integral_unit;

    fn marble(mm_per_unit: f32) -> Profile {
        Profile::from_preset(crate::presets::find("marble").unwrap(), mm_per_unit).unwrap()
    }

    #[test]
    fn fractions_sum_to_one_and_a_uniform_disc_gives_e_times_k() {
        let p = marble(20.0);
        for alpha in [0.001_f32, 0.05, 0.2, 3.0] {
            for (rings, per_ring) in [(1, 1), (2, 3), (4, 4), (8, 8), (16, 4)] {
                let q = LocalQuadrature::new(&p, alpha, rings, per_ring);
                assert_eq!(q.len(), rings * per_ring);
                let sum = (0..q.len()).fold(Vec3::ZERO, |s, n| s + q.fraction(n));
                assert!((sum - Vec3::ONE).abs().max_element() < 1e-5, "Σf = {sum}");
                let e = Vec3::new(2.0, 0.7, 1e-3);
                let k = Vec3::new(0.3, 0.2, 0.1);
                let term = LocalTerm::new(alpha, k);
                let nodes = [e; MAX_NODES];
                assert_eq!(q.local_term(e, term, &nodes[..q.len()]), e * k);
                // Every node dark: the local term vanishes (to rounding of Σf).
                let dark = q.local_term(e, term, &[Vec3::ZERO; MAX_NODES]);
                assert!(dark.max_element() <= 1e-5 * (e * k).max_element(), "{dark}");
                // Nodes inside the disc, rings in increasing radius.
                for n in 0..q.len() {
                    let r = q.offset(n, Vec2::X).length();
                    assert!(r < alpha && r > 0.0);
                    if n >= per_ring {
                        assert!(r > q.offset(n - per_ring, Vec2::X).length());
                    }
                    assert!(q.lift(n) >= 0.0 && q.lift(n) <= 0.13 * alpha);
                }
            }
        }
        // Counts out of range are clamped, never a panic.
        assert_eq!(LocalQuadrature::new(&p, 0.1, 0, 0).len(), 1);
        assert_eq!(LocalQuadrature::new(&p, 0.1, 100, 100).len(), MAX_NODES);
        assert_eq!(LocalQuadrature::new(&p, f32::NAN, 4, 4).alpha(), 0.0);
    }

    /// One layout serves every profile: the same quadrature, bit for bit, as building it from
    /// scratch, for every model and for albedos and mean free paths far apart.
    #[test]
    fn a_shared_layout_gives_the_quadrature_of_new() {
        use crate::profile::{Distance, ProfileModel};
        for (alpha, rings, per_ring) in [(0.05_f32, 3, 4), (0.7, 16, 4), (f32::NAN, 2, 2)] {
            let layout = QuadratureLayout::new(alpha, rings, per_ring);
            for model in ProfileModel::ALL {
                for (kd, ell) in [(0.2, 0.01), (0.8, 0.05), (0.97, 2.0)] {
                    let p = Profile::from_reflectance_with(
                        model,
                        Vec3::new(kd, kd * 0.5, 0.9),
                        Distance::MeanFreePath(Vec3::new(ell, ell * 3.0, ell)),
                        1.3,
                    )
                    .unwrap();
                    let shared = LocalQuadrature::with_layout(&p, &layout);
                    assert_eq!(shared, LocalQuadrature::new(&p, alpha, rings, per_ring));
                    assert_eq!(shared.alpha(), layout.alpha());
                }
            }
        }
    }

    /// The weights integrate a radial function g against w·Rd: Σ f·g(r) against the
    /// integral by Gauss–Legendre of the definition (an independent quadrature).
    #[test]
    fn radial_moments_match_the_integral() {
        let p = marble(20.0);
        let rule = GaussLegendre::<32>::new();
        for alpha in [0.02_f32, 0.1, 0.5] {
            let q = LocalQuadrature::new(&p, alpha, 8, 1);
            for c in 0..3 {
                let d = &p.dipoles().unwrap()[c];
                let dip = UnitDipole::new(d.albedo(), f64::from(p.eta()));
                let ell = f64::from(d.mean_free_path());
                let a = f64::from(alpha);
                let k = local_integral_unit(&dip, a / ell);
                // g(r) = (r/α)²: ∫ w Rd g dA / K.
                let mut num = 0.0;
                for i in 0..64 {
                    let (lo, hi) = (a * i as f64 / 64.0, a * (i + 1) as f64 / 64.0);
                    num += rule.integrate(lo, hi, |r| {
                        2.0 * core::f64::consts::PI
                            * r
                            * Kernel::weight_unit(r / a)
                            * dip.rd(r / ell)
                            / (ell * ell)
                            * (r / a)
                            * (r / a)
                    });
                }
                let want = num / k;
                let got: f64 = (0..q.len())
                    .map(|n| {
                        let r = f64::from(q.offset(n, Vec2::X).length()) / a;
                        f64::from(q.fraction(n)[c]) * r * r
                    })
                    .sum();
                assert!(
                    (got - want).abs() < 0.01,
                    "α {alpha} c {c}: {got} vs {want}"
                );
            }
        }
    }

    /// A straight edge at distance d from x: the lit share of the weight, averaged over
    /// rotations, against the exact share by quadrature; the default 12 nodes get within 2% of K.
    #[test]
    fn half_plane_share_averaged_over_rotations() {
        let p = marble(20.0);
        let alpha = 0.1_f32;
        let q = LocalQuadrature::new(&p, alpha, DEFAULT_RINGS, DEFAULT_PER_RING);
        let d0 = &p.dipoles().unwrap()[1];
        let dip = UnitDipole::new(d0.albedo(), f64::from(p.eta()));
        let ell = f64::from(d0.mean_free_path());
        let a = f64::from(alpha);
        let rule = GaussLegendre::<32>::new();
        for d in [-0.6, -0.2, 0.0, 0.3, 0.8] {
            // Exact: ∫ over r of 2r·arccos(d/r)·w·Rd for d ≥ 0 (the lit side x′ > d·α).
            let dd = d * a;
            let share = |dd: f64| {
                let mut s = 0.0;
                for i in 0..64 {
                    let (lo, hi) = (a * i as f64 / 64.0, a * (i + 1) as f64 / 64.0);
                    s += rule.integrate(lo, hi, |r| {
                        let ang = if r <= dd.abs() {
                            0.0
                        } else {
                            math::acos64(dd.abs() / r)
                        };
                        2.0 * r * ang * Kernel::weight_unit(r / a) * dip.rd(r / ell) / (ell * ell)
                    });
                }
                s / local_integral_unit(&dip, a / ell)
            };
            let want = if dd >= 0.0 {
                share(dd)
            } else {
                1.0 - share(dd)
            };
            let mut mean = 0.0;
            let turns = 256u64;
            for t in 0..turns {
                // Evenly spread turns (the renderer's hash spreads them at random).
                let rot = LocalQuadrature::rotation((t << 56) + (1 << 55));
                mean += (0..q.len())
                    .filter(|&n| f64::from(q.offset(n, rot).x) > dd)
                    .map(|n| f64::from(q.fraction(n)[1]))
                    .sum::<f64>()
                    / turns as f64;
            }
            assert!((mean - want).abs() < 0.02, "d {d}: {mean} vs {want}");
        }
    }
}
