//! The RGB diffusion profile of a material: three channels of one model sharing one η, built
//! from coefficients, from artist parameters (K_d with a distance, JB02 §4) or from a measured
//! preset; plus the conversion from exitance to radiance (the project's convention,
//! `docs/physics.md` §17).
//!
//! The models (`docs/physics.md` §18):
//!
//! | [`ProfileModel`] | channel type | albedo parameter | total reflectance |
//! |---|---|---|---|
//! | `Dipole` (default; J01, the seed's) | [`Dipole`] | α′ | closed form, inverted for K_d |
//! | `BetterDipole` (d'Eon 2012) | [`BetterDipole`] | α′ | closed form, inverted for K_d |
//! | `Burley(fit)` (Christensen & Burley 2015) | [`Burley`] | A = K_d | A |
//!
//! Every model takes its lengths from the mean free path ℓ_u = 1/σ_t′. The traversal evaluates
//! a profile through [`Profile::rd_lanes`] and [`Profile::rd_lanes_corrected`], one `match` per
//! batch of eight: the classical dipole inlined into the traversal (the hot path), the others
//! in a call of their own.

use glam::Vec3;

use crate::better_dipole::{self, BetterDipole, Boundary};
use crate::burley::{Burley, BurleyFit};
use crate::dipole::{self, Dipole, NodeMoments};
use crate::error::ParamError;
use crate::fresnel;
use crate::lanes::Lanes;
use crate::math;
use crate::presets::Preset;
use crate::unit_profile::UnitProfile;

/// K_d is clamped into [`KD_MIN`, `KD_MAX`] before inversion, so that α′ stays representable
/// (1 − α′ must not round to 0, nor α′ to 0). Values in (0, 1) outside this band are accepted
/// and clamped; values outside (0, 1) are errors.
pub const KD_MIN: f32 = 1e-5;
/// Upper end of the K_d clamp; see [`KD_MIN`].
pub const KD_MAX: f32 = 1.0 - 1e-5;

/// Which mean free path a distance is. Both conventions are common and confused in public
/// docs (`docs/physics.md` §1), so the API names them apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Distance {
    /// ℓ_u = 1/σ_t′, the mean free path: N10's ℓ_u, pbrt-v3's `mfp`.
    MeanFreePath(Vec3),
    /// ℓ_d = 1/σ_tr, the diffuse mean free path: JB02's and pbrt-v2's `meanfreepath`. For
    /// every model it is converted with the classical dipole's relation,
    /// ℓ_u = ℓ_d √(3(1 − α′)) with α′ = Rd_total⁻¹(K_d), so that one (K_d, ℓ_d) means the same
    /// ℓ_u whatever the model.
    DiffuseMeanFreePath(Vec3),
}

/// The diffusion model of a profile.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ProfileModel {
    /// The classical dipole of Jensen et al. 2001 (the seed's, and the default).
    #[default]
    Dipole,
    /// d'Eon's better dipole (2012).
    BetterDipole,
    /// Christensen & Burley's normalised diffusion (2015) with one of its fits of d.
    Burley(BurleyFit),
}

impl ProfileModel {
    /// Every model.
    pub const ALL: [ProfileModel; 4] = [
        ProfileModel::Dipole,
        ProfileModel::BetterDipole,
        ProfileModel::Burley(BurleyFit::Searchlight),
        ProfileModel::Burley(BurleyFit::DiffuseTransmission),
    ];

    /// A short name (`dipole`, `better-dipole`, `burley`, `burley-diffuse`).
    pub fn name(self) -> &'static str {
        match self {
            ProfileModel::Dipole => "dipole",
            ProfileModel::BetterDipole => "better-dipole",
            ProfileModel::Burley(BurleyFit::Searchlight) => "burley",
            ProfileModel::Burley(BurleyFit::DiffuseTransmission) => "burley-diffuse",
        }
    }

    /// The model's total reflectance for its albedo parameter (α′ for the dipoles, A for
    /// Burley) and η.
    pub fn total_reflectance(self, albedo: f64, eta: f64) -> f64 {
        match self {
            ProfileModel::Dipole => dipole::total_reflectance(albedo, eta),
            ProfileModel::BetterDipole => better_dipole::total_reflectance(albedo, eta),
            ProfileModel::Burley(_) => albedo,
        }
    }

    /// The albedo parameter whose total reflectance is `kd` ∈ (0, 1) (callers validate).
    pub fn albedo_from_total_reflectance(self, kd: f64, eta: f64) -> f64 {
        match self {
            ProfileModel::Dipole => dipole::albedo_from_total_reflectance(kd, eta),
            ProfileModel::BetterDipole => better_dipole::albedo_from_total_reflectance(kd, eta),
            ProfileModel::Burley(_) => kd,
        }
    }
}

/// The three channels, one model.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Channels {
    Dipole([Dipole; 3]),
    BetterDipole([BetterDipole; 3], Boundary),
    Burley([Burley; 3], BurleyFit),
}

/// Applies an expression to the channel array of whichever model (the channel types share
/// their method names).
macro_rules! each_model {
    ($profile:expr, $c:ident => $e:expr) => {
        match &$profile.channels {
            Channels::Dipole($c) => $e,
            Channels::BetterDipole($c, _) => $e,
            Channels::Burley($c, _) => $e,
        }
    };
}

/// A material's diffusion profile, per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    channels: Channels,
    eta: f32,
    /// 1 / (π (1 − F_dr,ext(η))), the exitance → radiance factor (`docs/physics.md` §17).
    radiance_scale: f32,
}

fn check_kd(kd: f32) -> Result<f32, ParamError> {
    if !kd.is_finite() {
        return Err(ParamError::NotFinite {
            name: "kd",
            value: kd,
        });
    }
    if !(kd > 0.0 && kd < 1.0) {
        return Err(ParamError::ReflectanceOutOfRange { value: kd });
    }
    Ok(kd.clamp(KD_MIN, KD_MAX))
}

fn check_distance(name: &'static str, v: f32) -> Result<(), ParamError> {
    if !v.is_finite() {
        Err(ParamError::NotFinite { name, value: v })
    } else if v <= 0.0 {
        Err(ParamError::NotPositive { name, value: v })
    } else {
        Ok(())
    }
}

/// Three fallible channel constructions in one array.
fn try_channels<T>(
    mut f: impl FnMut(usize) -> Result<T, ParamError>,
) -> Result<[T; 3], ParamError> {
    Ok([f(0)?, f(1)?, f(2)?])
}

impl Profile {
    /// Largest accepted relative index of refraction η (the constructors reject larger ones).
    pub const MAX_ETA: f32 = dipole::MAX_ETA;

    /// Assembles a profile from three channels with the same η.
    fn from_channels(channels: Channels, eta: f32) -> Self {
        let fdr_ext = fresnel::diffuse_reflectance_exact(eta as f64);
        let radiance_scale = (1.0 / (core::f64::consts::PI * (1.0 - fdr_ext))) as f32;
        Profile {
            channels,
            eta,
            radiance_scale,
        }
    }

    /// From absorption σ_a and reduced scattering σ_s′ per channel (per scene unit) and η:
    /// the classical dipole.
    pub fn from_coefficients(
        sigma_a: Vec3,
        sigma_s_prime: Vec3,
        eta: f32,
    ) -> Result<Self, ParamError> {
        Self::from_coefficients_with(ProfileModel::Dipole, sigma_a, sigma_s_prime, eta)
    }

    /// From σ_a and σ_s′ under any model: the dipoles take α′ = σ_s′/σ_t′ and σ_t′ as they are;
    /// Burley, whose parameters are a surface albedo and ℓ, takes ℓ = 1/σ_t′ and for A the better
    /// dipole's total reflectance of α′ (the closer of the two dipoles to transport, measured
    /// in `BENCHMARKS.md`, "Profiles against a Monte Carlo random walk").
    pub fn from_coefficients_with(
        model: ProfileModel,
        sigma_a: Vec3,
        sigma_s_prime: Vec3,
        eta: f32,
    ) -> Result<Self, ParamError> {
        dipole::check_eta(eta)?;
        let mut albedo = [0.0; 3];
        let mut sigma_t = [0.0; 3];
        for c in 0..3 {
            check_distance("sigma_a", sigma_a[c])?;
            check_distance("sigma_s_prime", sigma_s_prime[c])?;
            sigma_t[c] = sigma_a[c] as f64 + sigma_s_prime[c] as f64;
            albedo[c] = sigma_s_prime[c] as f64 / sigma_t[c];
        }
        if let ProfileModel::Burley(_) = model {
            albedo = albedo.map(|a| better_dipole::total_reflectance(a, eta as f64));
        }
        Self::from_albedo_and_extinction_with(model, albedo, sigma_t, eta)
    }

    /// From artist parameters (JB02 §4 reparameterisation, `docs/physics.md` §4): the total
    /// diffuse reflectance K_d per channel (in (0, 1), clamped to [`KD_MIN`, `KD_MAX`]) and a
    /// distance, for the classical dipole. α′ = Rd_total⁻¹(K_d); then σ_t′ = 1/ℓ_u, or
    /// σ_t′ = σ_tr/√(3(1−α′)) with σ_tr = 1/ℓ_d.
    pub fn from_reflectance(kd: Vec3, distance: Distance, eta: f32) -> Result<Self, ParamError> {
        Self::from_reflectance_with(ProfileModel::Dipole, kd, distance, eta)
    }

    /// [`Profile::from_reflectance`] under any model: the model's albedo parameter whose total
    /// reflectance is K_d (for Burley, A = K_d), and ℓ_u from the distance.
    pub fn from_reflectance_with(
        model: ProfileModel,
        kd: Vec3,
        distance: Distance,
        eta: f32,
    ) -> Result<Self, ParamError> {
        dipole::check_eta(eta)?;
        let mut albedo = [0.0; 3];
        let mut sigma_t = [0.0; 3];
        for c in 0..3 {
            let kd = check_kd(kd[c])? as f64;
            albedo[c] = model.albedo_from_total_reflectance(kd, eta as f64);
            sigma_t[c] = match distance {
                Distance::MeanFreePath(l) => {
                    check_distance("mean_free_path", l[c])?;
                    1.0 / l[c] as f64
                }
                Distance::DiffuseMeanFreePath(l) => {
                    check_distance("diffuse_mean_free_path", l[c])?;
                    let sigma_tr = 1.0 / l[c] as f64;
                    let dipole_albedo = if model == ProfileModel::Dipole {
                        albedo[c]
                    } else {
                        dipole::albedo_from_total_reflectance(kd, eta as f64)
                    };
                    sigma_tr / math::sqrt64(3.0 * (1.0 - dipole_albedo))
                }
            };
        }
        Self::from_albedo_and_extinction_with(model, albedo, sigma_t, eta)
    }

    /// From the reduced albedo α′ (in (0, 1]) and reduced extinction σ_t′ = 1/ℓ_u (per scene
    /// unit) per channel, and η, for the classical dipole: the form texture-mapped parameters
    /// arrive in (see [`crate::dipole::AlbedoInverter`]).
    pub fn from_albedo_and_extinction(
        albedo: [f64; 3],
        sigma_t: [f64; 3],
        eta: f32,
    ) -> Result<Self, ParamError> {
        Self::from_albedo_and_extinction_with(ProfileModel::Dipole, albedo, sigma_t, eta)
    }

    /// From the model's albedo parameter (α′ for the dipoles, A for Burley) and σ_t′ = 1/ℓ_u
    /// per channel, and η.
    pub fn from_albedo_and_extinction_with(
        model: ProfileModel,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
        eta: f32,
    ) -> Result<Self, ParamError> {
        dipole::check_eta(eta)?;
        let channels = match model {
            ProfileModel::Dipole => Channels::Dipole(try_channels(|c| {
                Dipole::from_albedo_and_extinction(albedo[c], sigma_t[c], eta)
            })?),
            ProfileModel::BetterDipole => {
                let boundary = Boundary::new(eta as f64);
                Channels::BetterDipole(
                    try_channels(|c| {
                        BetterDipole::with_boundary(albedo[c], sigma_t[c], &boundary)
                    })?,
                    boundary,
                )
            }
            ProfileModel::Burley(fit) => Channels::Burley(
                try_channels(|c| {
                    check_extinction(sigma_t[c])?;
                    Burley::new(albedo[c], 1.0 / sigma_t[c], fit)
                })?,
                fit,
            ),
        };
        Ok(Self::from_channels(channels, eta))
    }

    /// From a measured material of J01 (see [`crate::presets`]) and the number of millimetres
    /// per scene unit (the table is per mm; a scene modelled in centimetres passes 10).
    pub fn from_preset(preset: &Preset, mm_per_unit: f32) -> Result<Self, ParamError> {
        Self::from_preset_with(ProfileModel::Dipole, preset, mm_per_unit)
    }

    /// [`Profile::from_preset`] under any model ([`Profile::from_coefficients_with`]).
    pub fn from_preset_with(
        model: ProfileModel,
        preset: &Preset,
        mm_per_unit: f32,
    ) -> Result<Self, ParamError> {
        check_distance("mm_per_unit", mm_per_unit)?;
        let s = Vec3::splat(mm_per_unit);
        Self::from_coefficients_with(
            model,
            Vec3::from(preset.sigma_a) * s,
            Vec3::from(preset.sigma_s_prime) * s,
            preset.eta,
        )
    }

    /// The same material (same albedo parameter and η per channel) with a different mean free
    /// path ℓ_u per channel: how a texture-mapped ℓ_u is applied at a shading point. Cheap (no
    /// inversion).
    pub fn with_mean_free_path(&self, ell_u: Vec3) -> Result<Self, ParamError> {
        for c in 0..3 {
            check_distance("mean_free_path", ell_u[c])?;
        }
        let albedo = self.albedo_parameters();
        self.with_albedo_and_extinction(albedo, ell_u.to_array().map(|l| 1.0 / l as f64))
    }

    /// The same model and η with new albedo parameters and σ_t′ per channel: a texture-mapped
    /// material at one shading point. Cheaper than [`Profile::from_albedo_and_extinction_with`]
    /// (keeps the η-only terms computed for this profile).
    pub fn with_albedo_and_extinction(
        &self,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
    ) -> Result<Self, ParamError> {
        self.rebuilt(albedo, sigma_t, None)
    }

    /// [`Profile::with_albedo_and_extinction`] for albedo parameters inverted from a known total
    /// reflectance `kd` under this model (a texture's K_d at the shading point): the classical
    /// dipole takes `kd` as its Rd_total instead of evaluating Rd_total(α′) again (two double
    /// exponentials per channel; they agree to the inversion's accuracy, 1e-4).
    #[inline]
    pub fn with_reflectance_albedo_and_extinction(
        &self,
        kd: Vec3,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
    ) -> Result<Self, ParamError> {
        self.rebuilt(albedo, sigma_t, Some(kd))
    }

    /// [`Profile::with_albedo_and_extinction`] (`kd` `None`) or
    /// [`Profile::with_reflectance_albedo_and_extinction`] written into `out`, the same bits:
    /// for a caller that keeps one profile per thread and re-makes it at every shading point
    /// instead of moving a new one. On an error `out` is a copy of this profile.
    #[inline]
    pub fn rebuild_into(
        &self,
        out: &mut Profile,
        kd: Option<Vec3>,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
    ) -> Result<(), ParamError> {
        *out = *self;
        out.refill(albedo, sigma_t, kd)
            .inspect_err(|_| *out = *self)
    }

    #[inline]
    fn rebuilt(
        &self,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
        kd: Option<Vec3>,
    ) -> Result<Self, ParamError> {
        // Built in a copy of this profile, its channels overwritten in place.
        let mut out = *self;
        out.refill(albedo, sigma_t, kd)?;
        Ok(out)
    }

    /// Overwrites the channels with the same model's for new albedo parameters and σ_t′ (η and
    /// the model's η-only terms kept); `kd` is the known Rd_total where there is one.
    #[inline]
    fn refill(
        &mut self,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
        kd: Option<Vec3>,
    ) -> Result<(), ParamError> {
        let eta = self.eta;
        match &mut self.channels {
            Channels::Dipole(ch) => {
                // η was validated when this profile was built: A(η) once for three channels.
                let a = dipole::boundary_term(eta as f64);
                let rd_total = core::array::from_fn(|c| {
                    // A constant K_d (only ℓ textured) keeps α′: reuse its Rd_total.
                    if albedo[c] == ch[c].albedo() {
                        ch[c].total_reflectance() as f64
                    } else if let Some(kd) = kd {
                        kd[c] as f64
                    } else {
                        dipole::total_reflectance(albedo[c], eta as f64)
                    }
                });
                Dipole::fill_from_known_terms(ch, a, rd_total, albedo, sigma_t)?;
            }
            Channels::BetterDipole(ch, boundary) => {
                let boundary = *boundary;
                *ch = try_channels(|c| {
                    BetterDipole::with_boundary(albedo[c], sigma_t[c], &boundary)
                })?;
            }
            Channels::Burley(ch, fit) => {
                let fit = *fit;
                *ch = try_channels(|c| {
                    check_extinction(sigma_t[c])?;
                    Burley::new(albedo[c], 1.0 / sigma_t[c], fit)
                })?;
            }
        }
        Ok(())
    }

    /// The profile as a query on a cache of mean sample area `mean_area` evaluates it: for
    /// Burley, whose R diverges at r = 0, point values capped at the disc average over the
    /// mean sample's disc ([`Burley::with_near_cap`]); the dipoles are returned unchanged.
    #[inline]
    pub fn for_sample_area(&self, mean_area: f32) -> Self {
        match &self.channels {
            Channels::Burley(ch, fit) => Profile {
                channels: Channels::Burley(ch.map(|b| b.with_near_cap(mean_area)), *fit),
                ..*self
            },
            _ => *self,
        }
    }

    /// The model.
    pub fn model(&self) -> ProfileModel {
        match &self.channels {
            Channels::Dipole(_) => ProfileModel::Dipole,
            Channels::BetterDipole(..) => ProfileModel::BetterDipole,
            Channels::Burley(_, fit) => ProfileModel::Burley(*fit),
        }
    }
    /// The classical dipole's channels, if this is one.
    pub fn dipoles(&self) -> Option<&[Dipole; 3]> {
        match &self.channels {
            Channels::Dipole(ch) => Some(ch),
            _ => None,
        }
    }
    /// The unitless shape of channel `c` (ℓ_u = 1, double precision): for quadratures.
    pub fn unit_shape(&self, c: usize) -> UnitProfile {
        UnitProfile::new(self.model(), self.albedo_parameters()[c], self.eta as f64)
    }
    /// Relative index of refraction.
    pub fn eta(&self) -> f32 {
        self.eta
    }
    /// Rd(r) per channel from r².
    #[inline]
    pub fn rd(&self, r2: f32) -> Vec3 {
        each_model!(self, c => Vec3::new(c[0].rd(r2), c[1].rd(r2), c[2].rd(r2)))
    }
    /// Rd on eight squared distances, per channel.
    #[inline(always)]
    #[doc(hidden)]
    pub fn rd_lanes<L: Lanes>(&self, r2: L) -> [L; 3] {
        match &self.channels {
            Channels::Dipole(c) => [c[0].rd_lanes(r2), c[1].rd_lanes(r2), c[2].rd_lanes(r2)],
            Channels::BetterDipole(c, _) => better_dipole_lanes(c, r2),
            Channels::Burley(c, _) => burley_lanes(c, r2),
        }
    }
    /// Fourth-order corrected node aggregate per channel (see
    /// [`Dipole::rd_lanes_corrected`]).
    #[inline(always)]
    #[doc(hidden)]
    pub fn rd_lanes_corrected<L: Lanes>(&self, r2: L, m: &NodeMoments<L>) -> [L; 3] {
        match &self.channels {
            Channels::Dipole(c) => [
                c[0].rd_lanes_corrected(r2, m),
                c[1].rd_lanes_corrected(r2, m),
                c[2].rd_lanes_corrected(r2, m),
            ],
            Channels::BetterDipole(c, _) => better_dipole_lanes_corrected(c, r2, m),
            Channels::Burley(c, _) => burley_lanes_corrected(c, r2, m),
        }
    }
    /// Rd(0) per channel: N10's weight for the shading point itself (for Burley, the cap of
    /// [`Profile::for_sample_area`]).
    #[inline]
    pub fn rd_zero(&self) -> Vec3 {
        each_model!(self, c => Vec3::from(c.map(|d| d.rd_zero())))
    }
    /// Rd_total per channel: the albedo of a flat, uniformly lit surface.
    pub fn total_reflectance(&self) -> Vec3 {
        each_model!(self, c => Vec3::from(c.map(|d| d.total_reflectance())))
    }
    /// The model's albedo parameter per channel: α′ for the dipoles, A for Burley.
    pub fn albedo_parameters(&self) -> [f64; 3] {
        each_model!(self, c => c.map(|d| d.albedo()))
    }
    /// The albedo parameter per channel in single precision (α′ for the dipoles, A for Burley).
    pub fn albedo(&self) -> Vec3 {
        Vec3::from(self.albedo_parameters().map(|a| a as f32))
    }
    /// Mean free path ℓ_u = 1/σ_t′ per channel.
    #[inline]
    pub fn mean_free_path(&self) -> Vec3 {
        each_model!(self, c => Vec3::from(c.map(|d| d.mean_free_path())))
    }
    /// The slowest exponential decay rate of R per channel (σ_tr for the dipoles, 1/(3d) for
    /// Burley): beyond a few times its reciprocal a cluster's contribution can be bounded.
    pub fn decay_rate(&self) -> Vec3 {
        each_model!(self, c => Vec3::from(c.map(|d| d.decay_rate())))
    }
    /// The decay length 1/[`Profile::decay_rate`] per channel: the diffuse mean free path
    /// ℓ_d = 1/σ_tr for the dipoles, 3d for Burley.
    pub fn diffuse_mean_free_path(&self) -> Vec3 {
        Vec3::ONE / self.decay_rate()
    }
    /// Absorption σ_a per channel: (1 − α′)/ℓ_u for the dipoles; for Burley, of the classical
    /// dipole with the same total reflectance and ℓ_u.
    pub fn sigma_a(&self) -> Vec3 {
        let albedo = self.dipole_albedo();
        let ell = self.mean_free_path();
        Vec3::new(
            ((1.0 - albedo[0]) / ell.x as f64) as f32,
            ((1.0 - albedo[1]) / ell.y as f64) as f32,
            ((1.0 - albedo[2]) / ell.z as f64) as f32,
        )
    }
    /// Reduced scattering σ_s′ per channel (α′/ℓ_u; for Burley as [`Profile::sigma_a`]).
    pub fn sigma_s_prime(&self) -> Vec3 {
        let albedo = self.dipole_albedo();
        let ell = self.mean_free_path();
        Vec3::new(
            (albedo[0] / ell.x as f64) as f32,
            (albedo[1] / ell.y as f64) as f32,
            (albedo[2] / ell.z as f64) as f32,
        )
    }
    /// α′ of the dipoles; for Burley, of the classical dipole with its total reflectance.
    fn dipole_albedo(&self) -> [f64; 3] {
        match &self.channels {
            Channels::Burley(ch, _) => ch.map(|b| {
                let kd = b.albedo().clamp(KD_MIN as f64, KD_MAX as f64);
                dipole::albedo_from_total_reflectance(kd, self.eta as f64)
            }),
            _ => self.albedo_parameters(),
        }
    }

    /// Outgoing radiance from radiant exitance M_o, the project's convention
    /// (`docs/physics.md` §17): L_o = F_t(η, cos θ_o) / (π (1 − F_dr,ext(η))) · M_o. Integrating L_o cos θ over the
    /// hemisphere gives back M_o exactly, so a flat uniformly lit surface of albedo K_d has
    /// radiant exitance E·K_d.
    pub fn radiance(&self, exitance: Vec3, cos_out: f32) -> Vec3 {
        exitance * (fresnel::transmittance(self.eta, cos_out) * self.radiance_scale)
    }

    /// The factor 1 / (π (1 − F_dr,ext(η))) of [`Profile::radiance`].
    pub fn radiance_scale(&self) -> f32 {
        self.radiance_scale
    }
}

fn check_extinction(sigma_t: f64) -> Result<(), ParamError> {
    if sigma_t.is_finite() && sigma_t > 0.0 {
        Ok(())
    } else {
        Err(ParamError::NotPositive {
            name: "sigma_t",
            value: sigma_t as f32,
        })
    }
}

// The models other than the classical dipole are evaluated out of line: inlined at every call
// site of the traversal (three per mode, and the AVX2 build inlines all modes into one
// function) they tripled its machine code and compile time for a model most scenes do not use.

#[inline(never)]
fn better_dipole_lanes<L: Lanes>(c: &[BetterDipole; 3], r2: L) -> [L; 3] {
    [c[0].rd_lanes(r2), c[1].rd_lanes(r2), c[2].rd_lanes(r2)]
}

#[inline(never)]
fn better_dipole_lanes_corrected<L: Lanes>(
    c: &[BetterDipole; 3],
    r2: L,
    m: &NodeMoments<L>,
) -> [L; 3] {
    [
        c[0].rd_lanes_corrected(r2, m),
        c[1].rd_lanes_corrected(r2, m),
        c[2].rd_lanes_corrected(r2, m),
    ]
}

#[inline(never)]
fn burley_lanes<L: Lanes>(c: &[Burley; 3], r2: L) -> [L; 3] {
    [c[0].rd_lanes(r2), c[1].rd_lanes(r2), c[2].rd_lanes(r2)]
}

#[inline(never)]
fn burley_lanes_corrected<L: Lanes>(c: &[Burley; 3], r2: L, m: &NodeMoments<L>) -> [L; 3] {
    [
        c[0].rd_lanes_corrected(r2, m),
        c[1].rd_lanes_corrected(r2, m),
        c[2].rd_lanes_corrected(r2, m),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets;
    use crate::quadrature::GaussLegendre;

    #[test]
    fn reflectance_parameters_round_trip() {
        for eta in [1.0, 1.3, 1.5, 2.5] {
            let kd = Vec3::new(0.001, 0.5, 0.999);
            for distance in [
                Distance::MeanFreePath(Vec3::new(0.1, 1.0, 10.0)),
                Distance::DiffuseMeanFreePath(Vec3::splat(2.0)),
            ] {
                let p = Profile::from_reflectance(kd, distance, eta).unwrap();
                let back = p.total_reflectance();
                for c in 0..3 {
                    assert!(((back[c] - kd[c]) / kd[c]).abs() < 1e-5, "{back} vs {kd}");
                }
                match distance {
                    Distance::MeanFreePath(l) => {
                        assert!((p.mean_free_path() - l).abs().max_element() < 1e-6 * 10.0)
                    }
                    Distance::DiffuseMeanFreePath(l) => {
                        assert!(((p.diffuse_mean_free_path() - l) / l).abs().max_element() < 1e-5)
                    }
                }
                // Coefficients → profile gives the same channels back.
                let q = Profile::from_coefficients(p.sigma_a(), p.sigma_s_prime(), eta).unwrap();
                assert!(((q.total_reflectance() - back) / back).abs().max_element() < 1e-4);
            }
        }
    }

    #[test]
    fn artist_parameter_errors_are_typed() {
        let l = Distance::MeanFreePath(Vec3::ONE);
        assert!(matches!(
            Profile::from_reflectance(Vec3::new(0.0, 0.5, 0.5), l, 1.3),
            Err(ParamError::ReflectanceOutOfRange { .. })
        ));
        assert!(matches!(
            Profile::from_reflectance(Vec3::new(0.5, 1.0, 0.5), l, 1.3),
            Err(ParamError::ReflectanceOutOfRange { .. })
        ));
        assert!(matches!(
            Profile::from_reflectance(Vec3::new(0.5, f32::NAN, 0.5), l, 1.3),
            Err(ParamError::NotFinite { .. })
        ));
        assert!(matches!(
            Profile::from_reflectance(
                Vec3::splat(0.5),
                Distance::MeanFreePath(Vec3::new(1.0, -1.0, 1.0)),
                1.3
            ),
            Err(ParamError::NotPositive { .. })
        ));
        assert!(matches!(
            Profile::from_reflectance(
                Vec3::splat(0.5),
                Distance::DiffuseMeanFreePath(Vec3::splat(f32::INFINITY)),
                1.3
            ),
            Err(ParamError::NotFinite { .. })
        ));
        assert!(matches!(
            Profile::from_reflectance(Vec3::splat(0.5), l, 0.5),
            Err(ParamError::EtaBelowOne { .. })
        ));
        let marble = presets::find("marble").unwrap();
        assert!(matches!(
            Profile::from_preset(marble, 0.0),
            Err(ParamError::NotPositive { .. })
        ));
    }

    #[test]
    fn presets_scale_with_units() {
        let marble = presets::find("Marble").unwrap();
        let mm = Profile::from_preset(marble, 1.0).unwrap();
        let cm = Profile::from_preset(marble, 10.0).unwrap();
        // Same albedo, lengths ten times shorter in centimetre units.
        assert!(
            (mm.total_reflectance() - cm.total_reflectance())
                .abs()
                .max_element()
                < 1e-6
        );
        assert!(
            ((mm.mean_free_path() / cm.mean_free_path()) - Vec3::splat(10.0))
                .abs()
                .max_element()
                < 1e-4
        );
    }

    /// ∫ L_o cos θ dω over the hemisphere equals M_o (numerically, in μ = cos θ).
    #[test]
    fn radiance_convention_integrates_back_to_exitance() {
        let rule = GaussLegendre::<48>::new();
        for eta in [1.0_f32, 1.3, 1.5, 2.0] {
            let p =
                Profile::from_reflectance(Vec3::splat(0.5), Distance::MeanFreePath(Vec3::ONE), eta)
                    .unwrap();
            let m = Vec3::new(1.0, 2.0, 3.0);
            let lo = rule.integrate(0.0, 1.0, |mu| {
                2.0 * core::f64::consts::PI * mu * p.radiance(m, mu as f32).x as f64
            });
            assert!((lo - 1.0).abs() < 1e-4, "eta {eta}: {lo}");
        }
    }

    #[test]
    fn textured_mean_free_path_keeps_albedo() {
        let p = Profile::from_reflectance(
            Vec3::new(0.8, 0.5, 0.2),
            Distance::MeanFreePath(Vec3::ONE),
            1.3,
        )
        .unwrap();
        let q = p.with_mean_free_path(Vec3::splat(0.25)).unwrap();
        assert!((p.albedo() - q.albedo()).abs().max_element() < 1e-7);
        assert!((q.mean_free_path() - Vec3::splat(0.25)).abs().max_element() < 1e-7);
        // Scaling law: Rd_ℓ(r) = Rd_1(r/ℓ)/ℓ².
        let r = 0.3_f32;
        let lhs = q.rd(r * r);
        let rhs = p.rd((r / 0.25) * (r / 0.25)) / (0.25 * 0.25);
        assert!(((lhs - rhs) / rhs).abs().max_element() < 1e-5);
        assert!(p.with_mean_free_path(Vec3::new(1.0, 0.0, 1.0)).is_err());
    }

    /// Re-made in place, into a profile that held another model's channels, a profile is the
    /// one `with_albedo_and_extinction` and `with_reflectance_albedo_and_extinction` give, bit
    /// for bit; on an error the target is a copy of the base.
    #[test]
    fn rebuilt_in_place_equals_rebuilt_anew() {
        let kd = Vec3::new(0.6, 0.35, 0.8);
        let albedo = [0.93, 0.71, 0.98];
        let sigma_t = [2.0, 13.0, 0.7];
        let mut out = Profile::from_reflectance_with(
            ProfileModel::Burley(BurleyFit::Searchlight),
            Vec3::splat(0.5),
            Distance::MeanFreePath(Vec3::ONE),
            1.5,
        )
        .unwrap();
        for model in ProfileModel::ALL {
            let base = Profile::from_reflectance_with(
                model,
                Vec3::new(0.5, 0.4, 0.3),
                Distance::MeanFreePath(Vec3::splat(0.1)),
                1.3,
            )
            .unwrap();
            base.rebuild_into(&mut out, None, albedo, sigma_t).unwrap();
            assert_eq!(
                out,
                base.with_albedo_and_extinction(albedo, sigma_t).unwrap()
            );
            base.rebuild_into(&mut out, Some(kd), albedo, sigma_t)
                .unwrap();
            let want = base
                .with_reflectance_albedo_and_extinction(kd, albedo, sigma_t)
                .unwrap();
            assert_eq!(out, want, "{model:?}");
            let bad = [2.0, f64::NAN, 0.7];
            let err = base
                .rebuild_into(&mut out, Some(kd), albedo, bad)
                .unwrap_err();
            assert!(
                matches!(
                    err,
                    ParamError::NotPositive {
                        name: "sigma_t",
                        ..
                    }
                ),
                "{err:?}"
            );
            assert_eq!(out, base, "{model:?}");
        }
    }
}
