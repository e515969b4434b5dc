//! The RGB diffusion profile of a material: three [`Dipole`] channels sharing one η, built from
//! coefficients, from artist parameters (K_d with a distance, JB02 §4) or from a measured
//! preset; plus the conversion from exitance to radiance (the project's convention,
//! `docs/physics.md` §17).

use glam::Vec3;

use crate::dipole::{self, Dipole, NodeMoments};
use crate::error::ParamError;
use crate::fresnel;
use crate::lanes::Lanes;
use crate::math;
use crate::presets::Preset;

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
    /// ℓ_d = 1/σ_tr, the diffuse mean free path: JB02's and pbrt-v2's `meanfreepath`.
    DiffuseMeanFreePath(Vec3),
}

/// A material's dipole profile, per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    channels: [Dipole; 3],
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

impl Profile {
    /// Largest accepted relative index of refraction η (the constructors reject larger ones).
    pub const MAX_ETA: f32 = dipole::MAX_ETA;

    /// Assembles a profile from three channels with the same η.
    fn from_channels(channels: [Dipole; 3], eta: f32) -> Self {
        let fdr_ext = fresnel::diffuse_reflectance_exact(eta as f64);
        let radiance_scale = (1.0 / (core::f64::consts::PI * (1.0 - fdr_ext))) as f32;
        Profile {
            channels,
            eta,
            radiance_scale,
        }
    }

    /// From absorption σ_a and reduced scattering σ_s′ per channel (per scene unit) and η.
    pub fn from_coefficients(
        sigma_a: Vec3,
        sigma_s_prime: Vec3,
        eta: f32,
    ) -> Result<Self, ParamError> {
        let mut ch = [None; 3];
        for (c, slot) in ch.iter_mut().enumerate() {
            *slot = Some(Dipole::from_coefficients(
                sigma_a[c],
                sigma_s_prime[c],
                eta,
            )?);
        }
        Ok(Self::from_channels(
            ch.map(|d| d.expect("filled above")),
            eta,
        ))
    }

    /// From artist parameters (JB02 §4 reparameterisation, `docs/physics.md` §4): the total
    /// diffuse reflectance K_d per channel (in (0, 1), clamped to [`KD_MIN`, `KD_MAX`]) and a
    /// distance. α′ = Rd_total⁻¹(K_d); then σ_t′ = 1/ℓ_u, or σ_t′ = σ_tr/√(3(1−α′)) with
    /// σ_tr = 1/ℓ_d.
    pub fn from_reflectance(kd: Vec3, distance: Distance, eta: f32) -> Result<Self, ParamError> {
        dipole::check_eta(eta)?;
        let mut ch = [None; 3];
        for (c, slot) in ch.iter_mut().enumerate() {
            let kd = check_kd(kd[c])? as f64;
            let albedo = dipole::albedo_from_total_reflectance(kd, eta as f64);
            let sigma_t = match distance {
                Distance::MeanFreePath(l) => {
                    check_distance("mean_free_path", l[c])?;
                    1.0 / l[c] as f64
                }
                Distance::DiffuseMeanFreePath(l) => {
                    check_distance("diffuse_mean_free_path", l[c])?;
                    let sigma_tr = 1.0 / l[c] as f64;
                    sigma_tr / math::sqrt64(3.0 * (1.0 - albedo))
                }
            };
            *slot = Some(Dipole::from_albedo_and_extinction(albedo, sigma_t, eta)?);
        }
        Ok(Self::from_channels(
            ch.map(|d| d.expect("filled above")),
            eta,
        ))
    }

    /// From the reduced albedo α′ (in (0, 1]) and reduced extinction σ_t′ = 1/ℓ_u (per scene
    /// unit) per channel, and η: the form texture-mapped parameters arrive in (see
    /// [`crate::dipole::AlbedoInverter`]).
    pub fn from_albedo_and_extinction(
        albedo: [f64; 3],
        sigma_t: [f64; 3],
        eta: f32,
    ) -> Result<Self, ParamError> {
        let mut ch = [None; 3];
        for (c, slot) in ch.iter_mut().enumerate() {
            *slot = Some(Dipole::from_albedo_and_extinction(
                albedo[c], sigma_t[c], eta,
            )?);
        }
        Ok(Self::from_channels(
            ch.map(|d| d.expect("filled above")),
            eta,
        ))
    }

    /// From a measured material of J01 (see [`crate::presets`]) and the number of millimetres
    /// per scene unit (the table is per mm; a scene modelled in centimetres passes 10).
    pub fn from_preset(preset: &Preset, mm_per_unit: f32) -> Result<Self, ParamError> {
        check_distance("mm_per_unit", mm_per_unit)?;
        let s = Vec3::splat(mm_per_unit);
        Self::from_coefficients(
            Vec3::from(preset.sigma_a) * s,
            Vec3::from(preset.sigma_s_prime) * s,
            preset.eta,
        )
    }

    /// The same material (same α′ and η per channel) with a different mean free path ℓ_u per
    /// channel: how a texture-mapped ℓ_u is applied at a shading point. Cheap (no inversion).
    pub fn with_mean_free_path(&self, ell_u: Vec3) -> Result<Self, ParamError> {
        let mut ch = self.channels;
        for (c, d) in ch.iter_mut().enumerate() {
            check_distance("mean_free_path", ell_u[c])?;
            *d = Dipole::from_albedo_and_extinction(d.albedo(), 1.0 / ell_u[c] as f64, self.eta)?;
        }
        Ok(Profile {
            channels: ch,
            ..*self
        })
    }

    /// The same η with new α′ and σ_t′ per channel: a texture-mapped material at one shading
    /// point. Cheaper than [`Profile::from_albedo_and_extinction`] (keeps the Fresnel
    /// normalisation computed for this η).
    pub fn with_albedo_and_extinction(
        &self,
        albedo: [f64; 3],
        sigma_t: [f64; 3],
    ) -> Result<Self, ParamError> {
        let mut ch = self.channels;
        for (c, d) in ch.iter_mut().enumerate() {
            // A constant K_d (only ℓ textured) keeps α′: reuse its Rd_total.
            *d = if albedo[c] == d.albedo() {
                d.with_extinction(sigma_t[c], self.eta)?
            } else {
                Dipole::from_albedo_and_extinction(albedo[c], sigma_t[c], self.eta)?
            };
        }
        Ok(Profile {
            channels: ch,
            ..*self
        })
    }

    /// The channel dipoles (R, G, B).
    pub fn channels(&self) -> &[Dipole; 3] {
        &self.channels
    }
    /// Relative index of refraction.
    pub fn eta(&self) -> f32 {
        self.eta
    }
    /// Rd(r) per channel from r².
    #[inline]
    pub fn rd(&self, r2: f32) -> Vec3 {
        Vec3::new(
            self.channels[0].rd(r2),
            self.channels[1].rd(r2),
            self.channels[2].rd(r2),
        )
    }
    /// Rd on eight squared distances, per channel.
    #[inline(always)]
    #[doc(hidden)]
    pub fn rd_lanes<L: Lanes>(&self, r2: L) -> [L; 3] {
        [
            self.channels[0].rd_lanes(r2),
            self.channels[1].rd_lanes(r2),
            self.channels[2].rd_lanes(r2),
        ]
    }
    /// Fourth-order corrected node aggregate per channel (see
    /// [`Dipole::rd_lanes_corrected`]).
    #[inline(always)]
    #[doc(hidden)]
    pub fn rd_lanes_corrected<L: Lanes>(&self, r2: L, m: &NodeMoments<L>) -> [L; 3] {
        [
            self.channels[0].rd_lanes_corrected(r2, m),
            self.channels[1].rd_lanes_corrected(r2, m),
            self.channels[2].rd_lanes_corrected(r2, m),
        ]
    }
    /// Rd(0) per channel.
    pub fn rd_zero(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.rd_zero()))
    }
    /// Rd_total(α′) per channel: the albedo of a flat, uniformly lit surface.
    pub fn total_reflectance(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.total_reflectance()))
    }
    /// Reduced albedo α′ per channel.
    pub fn albedo(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.albedo() as f32))
    }
    /// Mean free path ℓ_u = 1/σ_t′ per channel.
    pub fn mean_free_path(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.mean_free_path()))
    }
    /// Diffuse mean free path ℓ_d = 1/σ_tr per channel.
    pub fn diffuse_mean_free_path(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.diffuse_mean_free_path()))
    }
    /// Absorption σ_a per channel.
    pub fn sigma_a(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.sigma_a()))
    }
    /// Reduced scattering σ_s′ per channel.
    pub fn sigma_s_prime(&self) -> Vec3 {
        Vec3::from(self.channels.map(|d| d.sigma_s_prime()))
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
}
