//! Scene materials resolved for shading: the diffusion profile at a surface point (constant,
//! or from texture-mapped K_d and mean free path) and the local integral K of the split
//! methods at that point.
//!
//! Every profile of a material is of the material's [`ProfileModel`]: the constant one, the
//! per-point ones of texture-mapped parameters (K_d inverted by that model's
//! [`AlbedoInverter`]) and the local-integral tables.
//!
//! Texture-mapped ℓ with constant K_d is N10's case: the albedo parameter (α′ for the dipoles,
//! A for Burley) is fixed, so one [`LocalIntegralTable`] (cached at powers of two of ℓ) serves
//! every point. A texture-mapped K_d also varies the albedo parameter; K then comes from the
//! core's [`LocalIntegralByKd`], tables at evenly spaced K_d whose K / K_d is interpolated in
//! K_d per channel.
//!
//! A diffuse mean free path ℓ_d is converted to ℓ_u with the classical dipole's relation
//! ℓ_u = ℓ_d √(3(1 − α′)) whatever the model (as the core's `Distance::DiffuseMeanFreePath`),
//! so a model other than the dipole also keeps the dipole's α′ of K_d for that conversion.

use std::fmt;
use std::sync::{Arc, Mutex};

use glam::{Vec2, Vec3};
use lucent_core::error::ParamError;
use lucent_core::internals::{AlbedoInverter, KD_MAX, KD_MIN, albedo_from_total_reflectance};
use lucent_core::{
    Distance as CoreDistance, LocalIntegralByKd, LocalIntegralTable, LocalTerm, Profile,
    ProfileModel, presets,
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
                let model = t.model;
                let params = match &t.medium {
                    Medium::Preset { name, mm_per_unit } => {
                        let preset =
                            presets::find(name).ok_or_else(|| MaterialError::UnknownPreset {
                                material: t.name.clone(),
                                preset: name.clone(),
                            })?;
                        Params::Fixed(
                            Profile::from_preset_with(model, preset, *mm_per_unit).map_err(err)?,
                        )
                    }
                    Medium::Coefficients {
                        sigma_a,
                        sigma_s_prime,
                        eta,
                    } => Params::Fixed(
                        Profile::from_coefficients_with(model, *sigma_a, *sigma_s_prime, *eta)
                            .map_err(err)?,
                    ),
                    Medium::Reflectance { kd, distance, eta } => {
                        reflectance_params(kd, distance, *eta, model).map_err(err)?
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

/// How the translucent parameters vary over the surface. The model is the profiles' own
/// (`base.model()`), kept by every per-point profile derived from `base`.
#[derive(Debug)]
pub(crate) enum Params {
    /// The same profile everywhere.
    Fixed(Profile),
    /// K_d and a distance, either of which may be a texture.
    Reflectance {
        base: Profile,
        kd: KdSource,
        distance: Distance,
        /// [`log_span`] of the distance parameter.
        log_span: f32,
    },
}

/// Where K_d comes from, with what turns it into albedo parameters.
#[derive(Debug)]
pub(crate) enum KdSource {
    /// A constant K_d: the model's albedo parameters, and the classical dipole's α′ (for the
    /// ℓ_d → ℓ_u conversion; the same numbers when the model is the dipole).
    Constant {
        albedo: [f64; 3],
        dipole_albedo: [f64; 3],
    },
    /// A texture-mapped K_d, inverted per point by the model's table; `dipole` is the classical
    /// dipole's table when the model is another one (`None`: the model's α′ is the dipole's).
    Texture {
        texture: Arc<Texture>,
        inverter: Arc<AlbedoInverter>,
        dipole: Option<Arc<AlbedoInverter>>,
    },
}

impl KdSource {
    /// The model's albedo parameters and the dipole's α′ at K_d = `kd` (a texture's value,
    /// already clamped; ignored for a constant).
    fn albedos(&self, kd: Vec3) -> ([f64; 3], [f64; 3]) {
        match self {
            KdSource::Constant {
                albedo,
                dipole_albedo,
            } => (*albedo, *dipole_albedo),
            KdSource::Texture {
                inverter, dipole, ..
            } => {
                let invert =
                    |t: &Arc<AlbedoInverter>| [t.albedo(kd.x), t.albedo(kd.y), t.albedo(kd.z)];
                let albedo = invert(inverter);
                (albedo, dipole.as_ref().map_or(albedo, invert))
            }
        }
    }
}

/// K_d at `uv` from a texture (clamped), `None` for a constant K_d.
fn kd_at(kd: &KdSource, uv: Vec2) -> Option<Vec3> {
    match kd {
        KdSource::Constant { .. } => None,
        KdSource::Texture { texture, .. } => Some(clamp_kd(texture.sample(uv))),
    }
}

/// A texture's K_d clamped into [0.001, 0.999], where every model's inversion is defined.
fn clamp_kd(kd: Vec3) -> Vec3 {
    kd.clamp(Vec3::splat(0.001), Vec3::splat(0.999))
}

/// What a textured point's profile is built from at `uv`: the texture's K_d (clamped; `None`
/// for a constant K_d), the model's albedo parameters and σ_t′ per channel.
#[inline]
fn inputs_at(
    kd: &KdSource,
    distance: &Distance,
    log_span: f32,
    uv: Vec2,
) -> (Option<Vec3>, [f64; 3], [f64; 3]) {
    let p = distance.param();
    let (kd_value, l) = match (kd, p) {
        // Both textured: one footprint where they have the same size.
        (KdSource::Texture { texture: a, .. }, ScalarParam::Texture { texture: b, .. }) => {
            let (kd, t) = Texture::sample_pair(a, b, uv);
            (Some(clamp_kd(kd)), scalar_at_value(p, log_span, t))
        }
        _ => (kd_at(kd, uv), scalar_at(p, log_span, uv)),
    };
    let (albedo, dipole_albedo) = kd.albedos(kd_value.unwrap_or(Vec3::ZERO));
    (kd_value, albedo, extinction(distance, l, dipole_albedo))
}

/// σ_t′ per channel from a distance value `l` (ℓ_u, or ℓ_d with the dipole's α′).
fn extinction(distance: &Distance, l: Vec3, dipole_albedo: [f64; 3]) -> [f64; 3] {
    match distance {
        Distance::MeanFreePath(_) => [1.0 / l.x as f64, 1.0 / l.y as f64, 1.0 / l.z as f64],
        Distance::DiffuseMeanFreePath(_) => {
            std::array::from_fn(|c| (1.0 / l[c] as f64) / (3.0 * (1.0 - dipole_albedo[c])).sqrt())
        }
    }
}

/// The albedo inverter of `model` at `eta`, built once per process: a table costs about 10 ms,
/// and a scene's materials are resolved when it is checked and again when it renders.
fn shared_inverter(model: ProfileModel, eta: f32) -> Arc<AlbedoInverter> {
    type Inverters = Vec<((ProfileModel, u32), Arc<AlbedoInverter>)>;
    static INVERTERS: Mutex<Inverters> = Mutex::new(Vec::new());
    let key = (model, eta.to_bits());
    // A poisoned lock only means another thread panicked while pushing: the list is intact.
    let mut built = INVERTERS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, inverter)) = built.iter().find(|(k, _)| *k == key) {
        return inverter.clone();
    }
    let inverter = Arc::new(AlbedoInverter::for_model(model, eta));
    built.push((key, inverter.clone()));
    inverter
}

/// Validates every constant and both ends of every texture range by building profiles of
/// `model` there.
pub(crate) fn reflectance_params(
    kd: &ColorParam,
    distance: &Distance,
    eta: f32,
    model: ProfileModel,
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
    let base = Profile::from_reflectance_with(model, representative_kd, make(lo), eta)?;
    Profile::from_reflectance_with(model, representative_kd, make(hi), eta)?;
    let kd = match kd {
        ColorParam::Constant(v) => {
            let albedo = base.albedo_parameters();
            let dipole_albedo = if model == ProfileModel::Dipole {
                albedo
            } else {
                // As the core's conversion of ℓ_d: the dipole's α′ of the clamped K_d.
                let kd = v.clamp(Vec3::splat(KD_MIN), Vec3::splat(KD_MAX));
                kd.to_array()
                    .map(|k| albedo_from_total_reflectance(k as f64, eta as f64))
            };
            KdSource::Constant {
                albedo,
                dipole_albedo,
            }
        }
        ColorParam::Texture(t) => {
            // Both ends of the reflectance range must make valid profiles too.
            for v in [0.001, 0.999] {
                Profile::from_reflectance_with(model, Vec3::splat(v), make(lo), eta)?;
            }
            KdSource::Texture {
                texture: t.clone(),
                inverter: shared_inverter(model, eta),
                dipole: (model != ProfileModel::Dipole)
                    .then(|| shared_inverter(ProfileModel::Dipole, eta)),
            }
        }
    };
    Ok(Params::Reflectance {
        base,
        kd,
        distance: distance.clone(),
        log_span: log_span(distance.param()),
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

/// ln(max / min) of a texture-mapped distance (0 for a constant): the scale of the exponent
/// in `min · (max / min)^t`, computed once per material rather than at every point.
fn log_span(p: &ScalarParam) -> f32 {
    match p {
        ScalarParam::Constant(_) => 0.0,
        ScalarParam::Texture { min, max, .. } => (max / min).ln(),
    }
}

/// A distance parameter at `uv`; `log_span` is [`log_span`]`(p)`.
fn scalar_at(p: &ScalarParam, log_span: f32, uv: Vec2) -> Vec3 {
    match p {
        ScalarParam::Constant(v) => *v,
        ScalarParam::Texture { texture, .. } => scalar_at_value(p, log_span, texture.sample(uv)),
    }
}

/// A distance parameter at texture value `t` (clamped to [0, 1]); `log_span` is
/// [`log_span`]`(p)`.
fn scalar_at_value(p: &ScalarParam, log_span: f32, t: Vec3) -> Vec3 {
    match p {
        ScalarParam::Constant(v) => *v,
        ScalarParam::Texture { min, .. } => {
            let t = t.clamp(Vec3::ZERO, Vec3::ONE);
            let at = |t: f32| min * (log_span * t).exp();
            // A grey texture (the usual radius map): one exponential for the three channels.
            if t.x == t.y && t.y == t.z {
                Vec3::splat(at(t.x))
            } else {
                Vec3::new(at(t.x), at(t.y), at(t.z))
            }
        }
    }
}

/// The per-channel smallest and largest texel of a texture.
fn texel_range(t: &Texture) -> (Vec3, Vec3) {
    t.texels()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// The smallest and largest value of a distance parameter over the surface, per channel.
fn scalar_range(p: &ScalarParam) -> (Vec3, Vec3) {
    match p {
        ScalarParam::Constant(v) => (*v, *v),
        ScalarParam::Texture { texture, .. } => {
            let (lo, hi) = texel_range(texture);
            // min·(max/min)^t is monotone in t: the extremes are the ends of the texel range.
            let (a, b) = (
                scalar_at_value(p, log_span(p), lo),
                scalar_at_value(p, log_span(p), hi),
            );
            (a.min(b), a.max(b))
        }
    }
}

/// The smallest value of a distance parameter over the surface, per channel.
fn smallest_scalar(p: &ScalarParam) -> Vec3 {
    scalar_range(p).0
}

/// The range of a K_d texture over all channels, clamped as [`clamp_kd`] clamps its samples
/// (bilinear samples lie between the texels).
fn kd_range(texture: &Texture) -> (f32, f32) {
    let (lo, hi) = texel_range(texture);
    (clamp_kd(lo).min_element(), clamp_kd(hi).max_element())
}

/// The range of ℓ_u over the surface, all channels, for K_d ∈ `kd`: the distance parameter's
/// range, converted from ℓ_d at each corner where the distance is ℓ_d (ℓ_u = ℓ_d·√(3(1 − α′))
/// is monotone in ℓ_d and in K_d, so its extremes are corners).
fn mean_free_path_range(kd: (f32, f32), source: &KdSource, distance: &Distance) -> (f32, f32) {
    let (lo, hi) = scalar_range(distance.param());
    let ends = [lo.min_element(), hi.max_element()];
    match distance {
        Distance::MeanFreePath(_) => (ends[0], ends[1]),
        Distance::DiffuseMeanFreePath(_) => {
            let mut range = (f32::INFINITY, f32::NEG_INFINITY);
            for k in [kd.0, kd.1] {
                let (_, dipole_albedo) = source.albedos(Vec3::splat(k));
                for l in ends {
                    let ell = (1.0 / extinction(distance, Vec3::splat(l), dipole_albedo)[0]) as f32;
                    range = (range.0.min(ell), range.1.max(ell));
                }
            }
            range
        }
    }
}

impl TranslucentShader {
    /// True if the profile varies over the surface (needs UVs and per-point profiles).
    pub fn is_textured(&self) -> bool {
        match &self.params {
            Params::Fixed(_) => false,
            Params::Reflectance { kd, distance, .. } => {
                matches!(kd, KdSource::Texture { .. })
                    || matches!(distance.param(), ScalarParam::Texture { .. })
            }
        }
    }

    /// The profile used where nothing varies (and for sample spacing decisions).
    pub fn base_profile(&self) -> &Profile {
        match &self.params {
            Params::Fixed(p) | Params::Reflectance { base: p, .. } => p,
        }
    }

    /// The base profile, K_d source, distance and [`log_span`] of a material given by K_d and a
    /// distance; `None` for fixed coefficients.
    fn reflectance(&self) -> Option<(&Profile, &KdSource, &Distance, f32)> {
        match &self.params {
            Params::Fixed(_) => None,
            Params::Reflectance {
                base,
                kd,
                distance,
                log_span,
            } => Some((base, kd, distance, *log_span)),
        }
    }

    /// The smallest decay length of the profile anywhere on the surface, per channel
    /// ([`Profile::diffuse_mean_free_path`]: ℓ_d = 1/σ_tr for the dipoles, 3d for Burley): what
    /// the irradiance sample spacing must resolve.
    ///
    /// Textures are bilinear, so their extremes are texels, and at a fixed K_d the decay length
    /// is proportional to the distance parameter: ℓ_u (or ℓ_d) is taken at the texel that makes
    /// it smallest. Over a textured K_d: for the classical dipole, at its smallest texel
    /// (ℓ_d = ℓ_u / √(3(1 − α′)) grows with α′, which grows with K_d); for the other models the
    /// profile is built at 65 evenly spaced K_d from the smallest to the largest texel, both
    /// included, and the shortest decay length kept — the minimum whenever it lies at an end,
    /// which it does from ℓ_u (the better dipole's decay length grows with K_d; Burley's
    /// 3ℓ_u/s(A) is smallest where the convex s(A) is largest), and within that grid's
    /// resolution from ℓ_d. With both textured the two extremes need not meet at one point, so
    /// the value is a lower bound there; otherwise it is the minimum.
    pub fn smallest_diffuse_mean_free_path(&self) -> Vec3 {
        let (base, kd, distance) = match &self.params {
            Params::Fixed(p) => return p.diffuse_mean_free_path(),
            Params::Reflectance {
                base, kd, distance, ..
            } => (base, kd, distance),
        };
        let smallest_distance = smallest_scalar(distance.param());
        if base.model() != ProfileModel::Dipole {
            if !self.is_textured() {
                return base.diffuse_mean_free_path();
            }
            let kd_values: Vec<Vec3> = match kd {
                KdSource::Constant { .. } => vec![Vec3::splat(0.5)],
                KdSource::Texture { texture, .. } => {
                    let (lo, hi) = texel_range(texture);
                    let (lo, hi) = (clamp_kd(lo), clamp_kd(hi));
                    (0..=64).map(|i| lo.lerp(hi, i as f32 / 64.0)).collect()
                }
            };
            // The decay length per unit distance at each K_d, scaled by the smallest distance.
            let per_unit = kd_values
                .iter()
                .filter_map(|&v| {
                    let (albedo, dipole_albedo) = kd.albedos(v);
                    let sigma_t = extinction(distance, Vec3::ONE, dipole_albedo);
                    base.with_albedo_and_extinction(albedo, sigma_t).ok()
                })
                .fold(Vec3::INFINITY, |m, p| m.min(p.diffuse_mean_free_path()));
            return if per_unit.is_finite() {
                per_unit * smallest_distance
            } else {
                base.diffuse_mean_free_path()
            };
        }
        let albedo: [f64; 3] = match kd {
            KdSource::Constant { albedo, .. } => *albedo,
            KdSource::Texture { texture, .. } => {
                let lo = clamp_kd(texel_range(texture).0);
                kd.albedos(lo).0
            }
        };
        match distance {
            Distance::DiffuseMeanFreePath(_) => smallest_distance,
            Distance::MeanFreePath(_) => Vec3::from_array(std::array::from_fn(|c| {
                (f64::from(smallest_distance[c]) / (3.0 * (1.0 - albedo[c])).sqrt()) as f32
            })),
        }
    }

    /// The total reflectance K_d and mean free path ℓ_u at texture coordinate `uv`, without
    /// building the profile there (what [`TranslucentShader::at`] would give as
    /// `total_reflectance()` and `mean_free_path()`, to the albedo inversion's accuracy): the
    /// second pass compares them between a pixel's sub-samples.
    pub fn parameters_at(&self, uv: Vec2) -> [Vec3; 2] {
        let Some((base, kd, distance, log_span)) = self.reflectance() else {
            let p = self.base_profile();
            return [p.total_reflectance(), p.mean_free_path()];
        };
        let kd_value = kd_at(kd, uv);
        let total = kd_value.unwrap_or_else(|| base.total_reflectance());
        let ell = match distance {
            // ℓ_u is the parameter itself: no albedo inversion.
            Distance::MeanFreePath(p) => scalar_at(p, log_span, uv),
            Distance::DiffuseMeanFreePath(_) => {
                let (_, _, sigma_t) = inputs_at(kd, distance, log_span, uv);
                Vec3::from_array(sigma_t.map(|s| (1.0 / s) as f32))
            }
        };
        [total, ell]
    }

    /// The material at texture coordinate `uv` (ignored when nothing is textured).
    #[inline]
    pub fn at(&self, uv: Vec2) -> Result<PointMaterial, ParamError> {
        let mut out = PointMaterial {
            profile: *self.base_profile(),
            kd: None,
        };
        self.at_into(uv, &mut out)?;
        Ok(out)
    }

    /// [`TranslucentShader::at`] written into `out`, the same bits: for a caller that keeps
    /// one point's material per thread rather than moving a new one at every point. On an
    /// error `out` holds the base profile.
    #[inline]
    pub fn at_into(&self, uv: Vec2, out: &mut PointMaterial) -> Result<(), ParamError> {
        let Some((base, kd, distance, log_span)) = self.reflectance() else {
            *out = PointMaterial {
                profile: *self.base_profile(),
                kd: None,
            };
            return Ok(());
        };
        let (kd_value, albedo, sigma_t) = inputs_at(kd, distance, log_span, uv);
        out.kd = None;
        base.rebuild_into(&mut out.profile, kd_value, albedo, sigma_t)?;
        out.kd = kd_value;
        Ok(())
    }

    /// The local-integral source for smoothing radius `alpha` and threshold `ell_min`: for a
    /// texture-mapped K_d, the tables over K_d of the material's model.
    pub fn local_term(&self, alpha: f32, ell_min: f32) -> Result<LocalIntegral, ParamError> {
        let base = self.base_profile();
        if let Some((_, source @ KdSource::Texture { texture, .. }, distance, _)) =
            self.reflectance()
        {
            let tables = LocalIntegralByKd::for_model(base.model(), base.eta(), alpha, ell_min)?;
            let kd = kd_range(texture);
            let ell = mean_free_path_range(kd, source, distance);
            Ok(LocalIntegral::ByKd(tables.with_range(kd, ell)))
        } else {
            Ok(LocalIntegral::Single(Box::new(LocalIntegralTable::new(
                base, alpha, ell_min,
            )?)))
        }
    }
}

/// Where K comes from for one material.
#[derive(Debug)]
pub enum LocalIntegral {
    /// Constant K_d: one table over ℓ.
    Single(Box<LocalIntegralTable>),
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
    #[inline]
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
mod tests;
