//! Scene materials resolved for shading: the diffusion profile at a surface point (constant,
//! or from texture-mapped K_d and mean free path) and the local integral K of the split
//! methods at that point.
//!
//! Texture-mapped ℓ with constant K_d is N10's case: α′ is fixed, so one
//! [`LocalIntegralTable`] (cached at powers of two of ℓ) serves every point. A texture-mapped
//! K_d also varies α′; K then comes from the core's [`LocalIntegralByKd`], tables at evenly
//! spaced K_d interpolated linearly in K_d per channel.

use std::fmt;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use lucent_core::error::ParamError;
use lucent_core::internals::AlbedoInverter;
use lucent_core::{
    Distance as CoreDistance, LocalIntegralByKd, LocalIntegralTable, LocalTerm, Profile, presets,
};

use crate::scene::{ColorParam, Distance, Material, Medium, ScalarParam, Specular};
use crate::texture::Texture;

/// Why a material cannot be shaded.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum MaterialError {
    /// The material names a preset that does not exist.
    UnknownPreset {
        /// The material's name.
        material: String,
        /// The preset it names.
        preset: String,
    },
    /// The core rejected the material's parameters (at a surface point, for a textured one).
    Params {
        /// The material's name.
        material: String,
        /// What the core found wrong.
        source: ParamError,
    },
}

impl MaterialError {
    fn params(material: &str, source: ParamError) -> Self {
        MaterialError::Params {
            material: material.to_string(),
            source,
        }
    }
}

impl fmt::Display for MaterialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MaterialError::UnknownPreset { material, preset } => {
                write!(f, "material '{material}': unknown preset '{preset}'")
            }
            MaterialError::Params { material, source } => {
                write!(f, "material '{material}': {source}")
            }
        }
    }
}

impl std::error::Error for MaterialError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            MaterialError::UnknownPreset { .. } => None,
            MaterialError::Params { source, .. } => Some(source),
        }
    }
}

/// A material ready for shading.
#[derive(Debug)]
pub enum Shader {
    /// Subsurface scattering through the core.
    Translucent(Box<TranslucentShader>),
    /// Opaque Lambert.
    Lambert {
        /// Diffuse reflectance.
        albedo: Vec3,
    },
}

impl Shader {
    /// Resolves a scene material (validating its parameters).
    pub fn new(material: &Material) -> Result<Shader, MaterialError> {
        match material {
            Material::Lambert { albedo, .. } => Ok(Shader::Lambert { albedo: *albedo }),
            Material::Translucent(t) => {
                let err = |e: ParamError| MaterialError::params(&t.name, e);
                let params = match &t.medium {
                    Medium::Preset { name, mm_per_unit } => {
                        let preset =
                            presets::find(name).ok_or_else(|| MaterialError::UnknownPreset {
                                material: t.name.clone(),
                                preset: name.clone(),
                            })?;
                        Params::Fixed(Profile::from_preset(preset, *mm_per_unit).map_err(err)?)
                    }
                    Medium::Coefficients {
                        sigma_a,
                        sigma_s_prime,
                        eta,
                    } => Params::Fixed(
                        Profile::from_coefficients(*sigma_a, *sigma_s_prime, *eta).map_err(err)?,
                    ),
                    Medium::Reflectance { kd, distance, eta } => {
                        reflectance_params(kd, distance, *eta).map_err(err)?
                    }
                };
                Ok(Shader::Translucent(Box::new(TranslucentShader {
                    name: t.name.clone(),
                    params,
                    specular: t.specular,
                })))
            }
        }
    }
}

/// How the translucent parameters vary over the surface.
#[derive(Debug)]
pub(crate) enum Params {
    /// The same profile everywhere.
    Fixed(Profile),
    /// K_d and a distance, either of which may be a texture.
    Reflectance {
        base: Profile,
        kd: KdSource,
        distance: Distance,
    },
}

#[derive(Debug)]
pub(crate) enum KdSource {
    Constant([f64; 3]),
    Texture(Arc<Texture>, AlbedoInverter),
}

/// Validates every constant and both ends of every texture range by building profiles there.
pub(crate) fn reflectance_params(
    kd: &ColorParam,
    distance: &Distance,
    eta: f32,
) -> Result<Params, ParamError> {
    let representative_kd = match kd {
        ColorParam::Constant(v) => *v,
        ColorParam::Texture(_) => Vec3::splat(0.5),
    };
    let ends = |p: &ScalarParam| match p {
        ScalarParam::Constant(v) => (*v, *v),
        ScalarParam::Texture { min, max, .. } => (Vec3::splat(*min), Vec3::splat(*max)),
    };
    let (lo, hi, make): (Vec3, Vec3, fn(Vec3) -> CoreDistance) = match distance {
        Distance::MeanFreePath(p) => {
            let (lo, hi) = ends(p);
            (lo, hi, CoreDistance::MeanFreePath)
        }
        Distance::DiffuseMeanFreePath(p) => {
            let (lo, hi) = ends(p);
            (lo, hi, CoreDistance::DiffuseMeanFreePath)
        }
    };
    let base = Profile::from_reflectance(representative_kd, make(lo), eta)?;
    Profile::from_reflectance(representative_kd, make(hi), eta)?;
    let kd = match kd {
        ColorParam::Constant(_) => KdSource::Constant(base.albedo_parameters()),
        ColorParam::Texture(t) => {
            // Both ends of the reflectance range must make valid profiles too.
            for v in [0.001, 0.999] {
                Profile::from_reflectance(Vec3::splat(v), make(lo), eta)?;
            }
            KdSource::Texture(t.clone(), AlbedoInverter::new(eta))
        }
    };
    Ok(Params::Reflectance {
        base,
        kd,
        distance: distance.clone(),
    })
}

/// A translucent material.
#[derive(Debug)]
pub struct TranslucentShader {
    /// Name from the scene file.
    pub name: String,
    params: Params,
    /// The optional highlight.
    pub specular: Option<Specular>,
}

/// The material at one surface point.
#[derive(Clone, Copy, Debug)]
pub struct PointMaterial {
    /// The diffusion profile there.
    pub profile: Profile,
    /// K_d there, when it comes from a texture (selects the local-integral tables).
    pub kd: Option<Vec3>,
}

fn scalar_at(p: &ScalarParam, uv: Vec2) -> Vec3 {
    match p {
        ScalarParam::Constant(v) => *v,
        ScalarParam::Texture { texture, .. } => scalar_at_value(p, texture.sample(uv)),
    }
}

/// A distance parameter at texture value `t` (clamped to [0, 1]).
fn scalar_at_value(p: &ScalarParam, t: Vec3) -> Vec3 {
    match p {
        ScalarParam::Constant(v) => *v,
        ScalarParam::Texture { min, max, .. } => {
            let t = t.clamp(Vec3::ZERO, Vec3::ONE);
            let ratio = (max / min).ln();
            Vec3::new(
                min * (ratio * t.x).exp(),
                min * (ratio * t.y).exp(),
                min * (ratio * t.z).exp(),
            )
        }
    }
}

/// The per-channel smallest and largest texel of a texture.
fn texel_range(t: &Texture) -> (Vec3, Vec3) {
    t.texels
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// The smallest value of a distance parameter over the surface, per channel.
fn smallest_scalar(p: &ScalarParam) -> Vec3 {
    match p {
        ScalarParam::Constant(v) => *v,
        ScalarParam::Texture { texture, .. } => {
            let (lo, hi) = texel_range(texture);
            // min·(max/min)^t is monotone in t: the extreme is at one end of the texel range.
            let at = |t: Vec3| scalar_at_value(p, t);
            at(lo).min(at(hi))
        }
    }
}

impl TranslucentShader {
    /// True if the profile varies over the surface (needs UVs and per-point profiles).
    pub fn is_textured(&self) -> bool {
        match &self.params {
            Params::Fixed(_) => false,
            Params::Reflectance { kd, distance, .. } => {
                matches!(kd, KdSource::Texture(..))
                    || matches!(
                        distance,
                        Distance::MeanFreePath(ScalarParam::Texture { .. })
                            | Distance::DiffuseMeanFreePath(ScalarParam::Texture { .. })
                    )
            }
        }
    }

    /// The profile used where nothing varies (and for sample spacing decisions).
    pub fn base_profile(&self) -> &Profile {
        match &self.params {
            Params::Fixed(p) | Params::Reflectance { base: p, .. } => p,
        }
    }

    /// The smallest diffuse mean free path ℓ_d = 1/σ_tr anywhere on the surface, per channel:
    /// what the irradiance sample spacing must resolve. Textures are bilinear, so their
    /// extremes are texels: ℓ_u (or ℓ_d) is taken at the texel that makes it smallest, and a
    /// textured K_d at its smallest texel (ℓ_d = ℓ_u / √(3(1 − α′)) grows with α′, which grows
    /// with K_d). With both textured the two extremes need not meet at one point, so the value is
    /// a lower bound there; otherwise it is the minimum.
    pub fn smallest_diffuse_mean_free_path(&self) -> Vec3 {
        let (kd, distance) = match &self.params {
            Params::Fixed(p) => return p.diffuse_mean_free_path(),
            Params::Reflectance { kd, distance, .. } => (kd, distance),
        };
        let albedo: [f64; 3] = match kd {
            KdSource::Constant(a) => *a,
            KdSource::Texture(t, inverter) => {
                let lo = texel_range(t)
                    .0
                    .clamp(Vec3::splat(0.001), Vec3::splat(0.999));
                [
                    inverter.albedo(lo.x),
                    inverter.albedo(lo.y),
                    inverter.albedo(lo.z),
                ]
            }
        };
        match distance {
            Distance::DiffuseMeanFreePath(p) => smallest_scalar(p),
            Distance::MeanFreePath(p) => {
                let ell_u = smallest_scalar(p);
                Vec3::from_array(std::array::from_fn(|c| {
                    (f64::from(ell_u[c]) / (3.0 * (1.0 - albedo[c])).sqrt()) as f32
                }))
            }
        }
    }

    /// The material at texture coordinate `uv` (ignored when nothing is textured).
    pub fn at(&self, uv: Vec2) -> Result<PointMaterial, ParamError> {
        let (base, kd, distance) = match &self.params {
            Params::Fixed(p) => {
                return Ok(PointMaterial {
                    profile: *p,
                    kd: None,
                });
            }
            Params::Reflectance { base, kd, distance } => (base, kd, distance),
        };
        let (albedo, kd_value) = match kd {
            KdSource::Constant(a) => (*a, None),
            KdSource::Texture(t, inverter) => {
                let v = t.sample(uv).clamp(Vec3::splat(0.001), Vec3::splat(0.999));
                (
                    [
                        inverter.albedo(v.x),
                        inverter.albedo(v.y),
                        inverter.albedo(v.z),
                    ],
                    Some(v),
                )
            }
        };
        let sigma_t = match distance {
            Distance::MeanFreePath(p) => {
                let l = scalar_at(p, uv);
                [1.0 / l.x as f64, 1.0 / l.y as f64, 1.0 / l.z as f64]
            }
            Distance::DiffuseMeanFreePath(p) => {
                let l = scalar_at(p, uv);
                let st = |c: usize| (1.0 / l[c] as f64) / (3.0 * (1.0 - albedo[c])).sqrt();
                [st(0), st(1), st(2)]
            }
        };
        Ok(PointMaterial {
            profile: base.with_albedo_and_extinction(albedo, sigma_t)?,
            kd: kd_value,
        })
    }

    /// The local-integral source for smoothing radius `alpha` and threshold `ell_min`.
    pub fn local_term(&self, alpha: f32, ell_min: f32) -> Result<LocalIntegral, ParamError> {
        let textured_kd = matches!(
            &self.params,
            Params::Reflectance {
                kd: KdSource::Texture(..),
                ..
            }
        );
        if textured_kd {
            let eta = self.base_profile().eta();
            Ok(LocalIntegral::ByKd(LocalIntegralByKd::new(
                eta, alpha, ell_min,
            )?))
        } else {
            Ok(LocalIntegral::Single(LocalIntegralTable::new(
                self.base_profile(),
                alpha,
                ell_min,
            )?))
        }
    }
}

/// Where K comes from for one material.
#[derive(Debug)]
pub enum LocalIntegral {
    /// Constant K_d: one table over ℓ.
    Single(LocalIntegralTable),
    /// Texture-mapped K_d: tables at evenly spaced K_d.
    ByKd(LocalIntegralByKd),
}

impl LocalIntegral {
    /// The local term at a surface point of a material that does not vary over the surface,
    /// by quadrature (no interpolation error: one quadrature per channel, so once per object,
    /// not per point). As [`LocalIntegral::lookup`], ℓ_u ≤ ℓ_min gives the limit Rd_total.
    pub fn exact(&self, point: &PointMaterial) -> LocalTerm {
        match self {
            LocalIntegral::Single(table) => table.exact_local_term(point.profile.mean_free_path()),
            LocalIntegral::ByKd(tables) => {
                LocalIntegralTable::new(&point.profile, tables.alpha(), tables.ell_min())
                    .map(|t| t.exact_local_term(point.profile.mean_free_path()))
                    .unwrap_or_else(|_| self.lookup(point))
            }
        }
    }

    /// The local term at a surface point.
    pub fn lookup(&self, point: &PointMaterial) -> LocalTerm {
        let ell = point.profile.mean_free_path();
        match self {
            LocalIntegral::Single(table) => table.local_term(ell),
            LocalIntegral::ByKd(tables) => {
                tables.local_term(point.kd.unwrap_or(Vec3::splat(0.5)), ell)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::TranslucentMaterial;
    use std::path::PathBuf;

    fn texture(values: &[Vec3], width: u32) -> Arc<Texture> {
        Arc::new(Texture {
            path: PathBuf::from("test.png"),
            width,
            height: values.len() as u32 / width,
            texels: values.to_vec(),
        })
    }

    fn translucent(medium: Medium) -> TranslucentShader {
        match Shader::new(&Material::Translucent(TranslucentMaterial {
            name: "m".into(),
            medium,
            specular: None,
        }))
        .unwrap()
        {
            Shader::Translucent(t) => *t,
            Shader::Lambert { .. } => unreachable!(),
        }
    }

    #[test]
    fn constant_reflectance_matches_the_core() {
        let kd = Vec3::new(0.8, 0.5, 0.3);
        let shader = translucent(Medium::Reflectance {
            kd: ColorParam::Constant(kd),
            distance: Distance::MeanFreePath(ScalarParam::Constant(Vec3::splat(0.2))),
            eta: 1.3,
        });
        let p = shader.at(Vec2::ZERO).unwrap().profile;
        assert!((p.total_reflectance() - kd).abs().max_element() < 1e-5);
        assert!((p.mean_free_path() - Vec3::splat(0.2)).abs().max_element() < 1e-6);
        assert!(!shader.is_textured());
    }

    #[test]
    fn textured_mean_free_path_maps_logarithmically() {
        // A 2×1 texture: t = 0 on the left, t = 1 on the right; clamp-free lookups at texel
        // centres.
        let tex = texture(&[Vec3::ZERO, Vec3::ONE], 2);
        let shader = translucent(Medium::Reflectance {
            kd: ColorParam::Constant(Vec3::splat(0.6)),
            distance: Distance::MeanFreePath(ScalarParam::Texture {
                texture: tex,
                min: 0.01,
                max: 1.0,
            }),
            eta: 1.3,
        });
        assert!(shader.is_textured());
        let left = shader
            .at(Vec2::new(0.25, 0.5))
            .unwrap()
            .profile
            .mean_free_path();
        let right = shader
            .at(Vec2::new(0.75, 0.5))
            .unwrap()
            .profile
            .mean_free_path();
        assert!(
            (left.x - 0.01).abs() < 1e-6 && (right.x - 1.0).abs() < 1e-5,
            "{left} {right}"
        );
        // K from the single table equals the table's own lookup at that ℓ.
        let term = shader.local_term(0.1, 1e-4).unwrap();
        let point = shader.at(Vec2::new(0.75, 0.5)).unwrap();
        let LocalIntegral::Single(table) = &term else {
            panic!("expected a single table")
        };
        assert_eq!(
            term.lookup(&point),
            table.local_term(point.profile.mean_free_path())
        );
    }

    /// A texture-mapped K_d takes K from the core's tables over K_d at the texel's K_d (their
    /// interpolation error is tested in the core, `kd_tables.rs`).
    #[test]
    fn textured_reflectance_takes_k_from_the_tables_over_kd() {
        let kd = Vec3::new(0.3, 0.55, 0.9);
        let tex = texture(&[kd], 1);
        let shader = translucent(Medium::Reflectance {
            kd: ColorParam::Texture(tex),
            distance: Distance::MeanFreePath(ScalarParam::Constant(Vec3::splat(0.05))),
            eta: 1.4,
        });
        let point = shader.at(Vec2::splat(0.5)).unwrap();
        assert!((point.profile.total_reflectance() - kd).abs().max_element() < 1e-4);
        let alpha = 0.07;
        let term = shader
            .local_term(alpha, alpha / 1024.0)
            .unwrap()
            .lookup(&point);
        let want = LocalIntegralByKd::new(1.4, alpha, alpha / 1024.0)
            .unwrap()
            .local_term(kd, point.profile.mean_free_path());
        assert_eq!(term, want);
        assert_eq!(term.alpha(), alpha);
    }

    #[test]
    fn invalid_parameters_name_the_material() {
        let m = Material::Translucent(TranslucentMaterial {
            name: "wax".into(),
            medium: Medium::Coefficients {
                sigma_a: Vec3::new(1.0, -1.0, 1.0),
                sigma_s_prime: Vec3::ONE,
                eta: 1.3,
            },
            specular: None,
        });
        let err = Shader::new(&m).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("wax") && message.contains("sigma_a"),
            "{err}"
        );
        // The core's error is kept as the source.
        let source = std::error::Error::source(&err).expect("a source");
        assert!(source.downcast_ref::<ParamError>().is_some(), "{source:?}");
        let m = Material::Translucent(TranslucentMaterial {
            name: "stone".into(),
            medium: Medium::Preset {
                name: "granite".into(),
                mm_per_unit: 1.0,
            },
            specular: None,
        });
        let err = Shader::new(&m).unwrap_err();
        assert_eq!(
            err.to_string(),
            "material 'stone': unknown preset 'granite'"
        );
    }
}
