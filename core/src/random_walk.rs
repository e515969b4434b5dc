//! A Monte Carlo reference for diffusion profiles: an analogue random walk of photons in a
//! homogeneous semi-infinite medium, scored as the radial profile of the light that comes
//! back out. Diffusion models (the classical dipole and its successors) are measured against
//! it ([`compare()`]).
//!
//! **What it simulates.** The medium fills z > 0. Lengths are in units of the mean free path
//! ℓ_u = 1/σ_t′, so the reduced extinction is σ_t′ = 1, and scattering is isotropic with the
//! reduced albedo α′ = σ_s′/σ_t′ — the similarity relation σ_s′ = σ_s(1 − g) on which the
//! dipole rests (J01), so that the walk and the models describe the same medium. Each photon
//! carries weight 1 (analogue: no weights, no roulette): free paths are drawn from e^(−s);
//! at each interaction the photon is absorbed with probability 1 − α′ and otherwise takes a
//! uniformly random direction. The boundary z = 0 is a smooth dielectric of relative index
//! η = n_inside / n_outside ≥ 1: a photon that reaches it from inside at cosine μ is reflected
//! back with probability F_r(1/η, μ) (1 beyond the critical angle), and otherwise leaves and
//! is scored at its exit radius r = √(x² + y²).
//!
//! **Illumination** ([`Illumination`]), always entering at the origin (the medium is
//! invariant under translation, so the profile is the response to a point of entry):
//! - a pencil beam at normal incidence: the photon starts heading straight down;
//! - diffuse: incident directions cosine-weighted over the outer hemisphere, accepted with the
//!   entry transmittance 1 − F_r(η, μ_i) (a rejected direction is counted and drawn again),
//!   then refracted by Snell's law.
//!
//! **Normalisation.** Everything is per unit flux *transmitted* into the medium: the profile
//! counts entered photons only, and the entry Fresnel loss is not part of it, as in the
//! models' Rd. R(r) per radial bin is (photons exiting in the annulus) / (photons entered ×
//! annulus area), in 1/ℓ_u²; the total diffuse reflectance is the fraction of entered photons
//! that leave. Standard errors are binomial: each photon lands in a bin or not.
//!
//! **Determinism.** Photons run in chunks of [`CHUNK`]; chunk k draws from a xoshiro256++
//! generator ([`Xoshiro256`]) seeded by a hash of (seed, k), and a chunk's [`Tally`] holds
//! integer counts only, so the profile is the same bits however the chunks are spread over
//! threads and in whatever order their tallies are merged.
//!
//! **Checks** (the tests in `random_walk/tests.rs`). With η = 1 the pencil beam's total is
//! Chandrasekhar's plane albedo 1 − H(1)√(1 − α′) and the diffuse total his spherical albedo
//! ([`HFunction`]); at any η the share of photons leaving after exactly one scattering
//! ([`Tally::single_scattered`]) has a closed form through the Fresnel boundary; at η = 1
//! Christensen & Burley's published fits, made from their own Monte Carlo, match the walk's
//! profiles to a few percent.
//!
//! **What it is for.** Measuring diffusion profiles: `lucent bench --profiles` runs the walk
//! at a fine setting against every model the core has (`BENCHMARKS.md`, "Profiles against a
//! Monte Carlo random walk"), and the tests pin what is known about the classical dipole. It
//! is a reference, not a renderer's profile: nothing in the queries calls it. Every
//! transcendental goes through `crate::math`.

mod chandrasekhar;
mod compare;
mod rng;

use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use crate::fresnel;
use crate::math;
use crate::seed::splitmix64;

pub use chandrasekhar::HFunction;
pub use compare::{COMPARE_RANGE, ProfileComparison, annulus_mean, compare, compare_over};
pub use rng::Xoshiro256;

/// Photons per chunk: the unit of seeding and of parallel work.
pub const CHUNK: u64 = 1 << 14;

/// ln 10.
const LN_10: f64 = core::f64::consts::LN_10;

/// How light enters the medium.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Illumination {
    /// A pencil beam at normal incidence (the "searchlight" of Burley's fits).
    PencilBeam,
    /// Diffuse light: cosine-weighted over the outer hemisphere, refracted in.
    Diffuse,
}

impl Illumination {
    /// A short name for tables and files: `pencil` or `diffuse`.
    pub fn name(self) -> &'static str {
        match self {
            Illumination::PencilBeam => "pencil",
            Illumination::Diffuse => "diffuse",
        }
    }
}

/// Log-spaced radial bins: `per_decade` bins per factor of 10, from `r_min` over `decades`
/// decades (in ℓ_u).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialBins {
    /// The inner edge of the first bin.
    pub r_min: f64,
    /// Bins per decade.
    pub per_decade: u32,
    /// Decades covered.
    pub decades: u32,
}

impl Default for RadialBins {
    /// 10⁻³ to 10² ℓ_u, 20 bins per decade.
    fn default() -> Self {
        RadialBins {
            r_min: 1e-3,
            per_decade: 20,
            decades: 5,
        }
    }
}

impl RadialBins {
    /// The number of bins.
    pub fn len(&self) -> usize {
        (self.per_decade * self.decades) as usize
    }

    /// Whether there are no bins.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The bin edges, `len() + 1` of them: r_min · 10^(i / per_decade).
    pub fn edges(&self) -> Vec<f64> {
        let step = LN_10 / f64::from(self.per_decade);
        (0..=self.len())
            .map(|i| self.r_min * math::exp64(step * i as f64))
            .collect()
    }
}

/// The settings of one walk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkSettings {
    /// Reduced albedo α′ ∈ [0, 1).
    pub albedo: f64,
    /// Relative index η = n_inside / n_outside, ≥ 1.
    pub eta: f64,
    /// How light enters.
    pub illumination: Illumination,
    /// Photons that enter the medium.
    pub photons: u64,
    /// The seed; chunk k is seeded from (seed, k).
    pub seed: u64,
    /// Where exits are scored.
    pub bins: RadialBins,
}

impl WalkSettings {
    /// α′ and η with the pencil beam, 10⁵ photons, seed 1 and the default bins.
    pub fn new(albedo: f64, eta: f64) -> Self {
        WalkSettings {
            albedo,
            eta,
            illumination: Illumination::PencilBeam,
            photons: 100_000,
            seed: 1,
            bins: RadialBins::default(),
        }
    }

    /// Checks the settings.
    pub fn validate(&self) -> Result<(), WalkError> {
        // α′ = 1 is excluded: with no absorption the walk's length has no finite mean.
        if !(0.0..1.0).contains(&self.albedo) {
            return Err(WalkError::Albedo(self.albedo));
        }
        if !(self.eta >= 1.0 && self.eta <= 10.0) {
            return Err(WalkError::Eta(self.eta));
        }
        if self.photons == 0 {
            return Err(WalkError::NoPhotons);
        }
        let b = self.bins;
        if !(b.r_min > 0.0 && b.r_min.is_finite()) || b.per_decade == 0 || b.decades == 0 {
            return Err(WalkError::Bins);
        }
        if b.per_decade
            .checked_mul(b.decades)
            .is_none_or(|n| n > 100_000)
        {
            return Err(WalkError::Bins);
        }
        Ok(())
    }

    /// The number of chunks: ⌈photons / [`CHUNK`]⌉.
    pub fn chunks(&self) -> u64 {
        self.photons.div_ceil(CHUNK)
    }
}

/// Why a walk cannot run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WalkError {
    /// The reduced albedo is not in [0, 1).
    Albedo(f64),
    /// η is not in [1, 10].
    Eta(f64),
    /// Zero photons.
    NoPhotons,
    /// A bin layout with no bins, more than 100 000, or r_min not positive and finite.
    Bins,
}

impl fmt::Display for WalkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WalkError::Albedo(a) => write!(f, "the reduced albedo must be in [0, 1), got {a}"),
            WalkError::Eta(e) => write!(f, "eta must be in [1, 10], got {e}"),
            WalkError::NoPhotons => f.write_str("a walk needs at least one photon"),
            WalkError::Bins => {
                f.write_str("radial bins need r_min > 0 and between 1 and 100000 bins in all")
            }
        }
    }
}

impl core::error::Error for WalkError {}

/// Integer counts of one or more chunks; merged by adding.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    /// Photons that entered the medium.
    pub entered: u64,
    /// Diffuse directions turned back by the entry Fresnel reflection (drawn again).
    pub entry_reflected: u64,
    /// Photons absorbed inside.
    pub absorbed: u64,
    /// Photons that left through the boundary.
    pub exited: u64,
    /// Exits at r below the first bin.
    pub below_first: u64,
    /// Exits at r beyond the last bin.
    pub beyond_last: u64,
    /// Exits per bin.
    pub bins: Vec<u64>,
    /// Exits after exactly one scattering (the single-scattering part of the total, which
    /// has a closed form to check the boundary against).
    pub single_scattered: u64,
    /// Scattering or absorption events.
    pub interactions: u64,
    /// Internal Fresnel reflections at the boundary.
    pub internal_reflections: u64,
}

impl Tally {
    /// Adds another tally's counts (same bins).
    pub fn merge(&mut self, other: &Tally) {
        self.entered += other.entered;
        self.entry_reflected += other.entry_reflected;
        self.absorbed += other.absorbed;
        self.exited += other.exited;
        self.below_first += other.below_first;
        self.beyond_last += other.beyond_last;
        self.interactions += other.interactions;
        self.internal_reflections += other.internal_reflections;
        self.single_scattered += other.single_scattered;
        if self.bins.len() < other.bins.len() {
            self.bins.resize(other.bins.len(), 0);
        }
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            *a += b;
        }
    }
}

/// Runs chunk `chunk` of the walk (photons `chunk·CHUNK` up to the total). Settings are
/// assumed valid ([`WalkSettings::validate`]).
pub fn walk_chunk(settings: &WalkSettings, chunk: u64) -> Tally {
    let first = chunk.saturating_mul(CHUNK);
    let count = settings.photons.saturating_sub(first).min(CHUNK);
    let mut rng = Xoshiro256::from_seed(splitmix64(settings.seed ^ splitmix64(chunk)));
    let edges = settings.bins.edges();
    let scale = f64::from(settings.bins.per_decade) / LN_10;
    let mut tally = Tally {
        bins: vec![0; settings.bins.len()],
        ..Tally::default()
    };
    for _ in 0..count {
        let direction = match settings.illumination {
            Illumination::PencilBeam => [0.0, 0.0, 1.0],
            Illumination::Diffuse => diffuse_entry(settings.eta, &mut rng, &mut tally),
        };
        tally.entered += 1;
        match trace(settings, direction, &mut rng, &mut tally) {
            None => tally.absorbed += 1,
            Some(r) => {
                tally.exited += 1;
                match bin_of(r, &edges, settings.bins.r_min, scale) {
                    Bin::Below => tally.below_first += 1,
                    Bin::Beyond => tally.beyond_last += 1,
                    Bin::Inside(i) => tally.bins[i] += 1,
                }
            }
        }
    }
    tally
}

/// Runs the whole walk on the calling thread.
pub fn run(settings: &WalkSettings) -> Result<RadialProfile, WalkError> {
    settings.validate()?;
    let mut tally = Tally::default();
    for chunk in 0..settings.chunks() {
        tally.merge(&walk_chunk(settings, chunk));
    }
    Ok(RadialProfile::from_tally(settings, &tally))
}

/// A direction into the medium for diffuse illumination: cosine-weighted outside, accepted
/// with probability F_t(η, μ_i), refracted. Rejections are counted in the tally.
fn diffuse_entry(eta: f64, rng: &mut Xoshiro256, tally: &mut Tally) -> [f64; 3] {
    loop {
        // μ_i = √u has density 2μ on [0, 1]: cosine-weighted.
        let cos_i = math::sqrt64(rng.uniform());
        let phi = 2.0 * core::f64::consts::PI * rng.uniform();
        if rng.uniform() < fresnel::reflectance(eta, cos_i) {
            tally.entry_reflected += 1;
            continue;
        }
        let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
        let sin_t = math::sqrt64(sin2_t);
        let cos_t = math::sqrt64(1.0 - sin2_t);
        let (s, c) = math::sin_cos64(phi);
        return [sin_t * c, sin_t * s, cos_t];
    }
}

/// A uniformly random direction on the unit sphere.
fn isotropic(rng: &mut Xoshiro256) -> [f64; 3] {
    let cos = 1.0 - 2.0 * rng.uniform();
    let sin = math::sqrt64((1.0 - cos * cos).max(0.0));
    let (s, c) = math::sin_cos64(2.0 * core::f64::consts::PI * rng.uniform());
    [sin * c, sin * s, cos]
}

/// Follows one photon entering at the origin along `direction` (z > 0 points into the
/// medium) until it is absorbed (`None`) or leaves at radius r (`Some(r)`).
fn trace(
    settings: &WalkSettings,
    mut direction: [f64; 3],
    rng: &mut Xoshiro256,
    tally: &mut Tally,
) -> Option<f64> {
    let inverse_eta = 1.0 / settings.eta;
    let mut p = [0.0f64; 3];
    let mut scatterings = 0u32;
    loop {
        // Free path s ~ e^(−s); 1 − u ∈ (0, 1], so the logarithm is finite.
        let s = -math::ln64(1.0 - rng.uniform());
        if direction[2] < 0.0 && p[2] + s * direction[2] <= 0.0 {
            // The path crosses the boundary: move to it.
            let t = p[2] / -direction[2];
            p[0] += t * direction[0];
            p[1] += t * direction[1];
            // From inside the relative index is 1/η: total internal reflection beyond the
            // critical angle, where `reflectance` returns 1.
            let f = fresnel::reflectance(inverse_eta, -direction[2]);
            let reflect = f >= 1.0 || (f > 0.0 && rng.uniform() < f);
            if !reflect {
                if scatterings == 1 {
                    tally.single_scattered += 1;
                }
                return Some(math::sqrt64(p[0] * p[0] + p[1] * p[1]));
            }
            tally.internal_reflections += 1;
            // Mirror and go on with the rest of the free path (the path length is
            // memoryless, so the remainder is as good as a fresh draw).
            direction[2] = -direction[2];
            let rest = s - t;
            p[0] += rest * direction[0];
            p[1] += rest * direction[1];
            p[2] = rest * direction[2];
        } else {
            p[0] += s * direction[0];
            p[1] += s * direction[1];
            p[2] += s * direction[2];
        }
        tally.interactions += 1;
        if rng.uniform() >= settings.albedo {
            return None;
        }
        scatterings += 1;
        direction = isotropic(rng);
    }
}

/// Where an exit radius falls.
enum Bin {
    Below,
    Inside(usize),
    Beyond,
}

/// The bin of radius r: from the logarithm, then corrected against the edges themselves so
/// that rounding in either cannot put r on the wrong side of an edge.
fn bin_of(r: f64, edges: &[f64], r_min: f64, scale: f64) -> Bin {
    let bins = edges.len() - 1;
    if r < edges[0] {
        return Bin::Below;
    }
    if r >= edges[bins] {
        return Bin::Beyond;
    }
    let guess = (math::ln64(r / r_min) * scale).max(0.0) as usize;
    let mut i = guess.min(bins - 1);
    while i > 0 && r < edges[i] {
        i -= 1;
    }
    while i + 1 < bins && r >= edges[i + 1] {
        i += 1;
    }
    Bin::Inside(i)
}

/// The walk's result: R(r) per radial bin, the total diffuse reflectance, their standard
/// errors, and the counts they come from.
#[derive(Clone, Debug, PartialEq)]
pub struct RadialProfile {
    /// The settings of the walk.
    pub settings: WalkSettings,
    /// Bin edges in ℓ_u (one more than bins).
    pub edges: Vec<f64>,
    /// R per bin, 1/ℓ_u²: exits in the annulus / (entered photons × annulus area).
    pub reflectance: Vec<f64>,
    /// The standard error of each bin's R.
    pub std_error: Vec<f64>,
    /// Total diffuse reflectance: exited / entered.
    pub total: f64,
    /// The standard error of the total.
    pub total_std_error: f64,
    /// The counts.
    pub tally: Tally,
}

impl RadialProfile {
    /// The profile of a tally of the walk with these settings.
    pub fn from_tally(settings: &WalkSettings, tally: &Tally) -> Self {
        let edges = settings.bins.edges();
        let n = tally.entered.max(1) as f64;
        // A binomial count k of n: p = k/n, standard error √(p(1 − p)/n).
        let binomial = |k: u64| {
            let p = k as f64 / n;
            (p, math::sqrt64((p * (1.0 - p)).max(0.0) / n))
        };
        let (mut reflectance, mut std_error) = (Vec::new(), Vec::new());
        for (i, &k) in tally.bins.iter().enumerate() {
            let area = annulus_area(edges[i], edges[i + 1]);
            let (p, e) = binomial(k);
            reflectance.push(p / area);
            std_error.push(e / area);
        }
        let (total, total_std_error) = binomial(tally.exited);
        RadialProfile {
            settings: *settings,
            edges,
            reflectance,
            std_error,
            total,
            total_std_error,
            tally: tally.clone(),
        }
    }

    /// The number of bins.
    pub fn len(&self) -> usize {
        self.reflectance.len()
    }

    /// Whether there are no bins.
    pub fn is_empty(&self) -> bool {
        self.reflectance.is_empty()
    }

    /// Bin i's geometric centre √(r_i r_{i+1}).
    pub fn centre(&self, i: usize) -> f64 {
        math::sqrt64(self.edges[i] * self.edges[i + 1])
    }

    /// Bin i's annulus area π(r_{i+1}² − r_i²).
    pub fn area(&self, i: usize) -> f64 {
        annulus_area(self.edges[i], self.edges[i + 1])
    }

    /// Σ R_i · area_i: the reflectance that exits within the bins (the total less the exits
    /// below the first bin and beyond the last).
    pub fn binned_total(&self) -> f64 {
        (0..self.len())
            .map(|i| self.reflectance[i] * self.area(i))
            .sum()
    }
}

/// π(b² − a²).
fn annulus_area(a: f64, b: f64) -> f64 {
    core::f64::consts::PI * (b - a) * (b + a)
}

#[cfg(test)]
mod tests;
