//! `[material.NAME]` tables → [`Material`]: which keys go together, their ranges, and texture
//! loading (shared between materials that name the same file).
//!
//! A translucent material is given in exactly one of three ways (see `docs/scene-format.md`
//! and `docs/physics.md` §4): a measured preset of Jensen et al. 2001 with the
//! scene's scale, explicit coefficients, or the artist parameters of Jensen & Buhler 2002
//! (diffuse reflectance K_d and one distance: a named mean free path, or Standard Surface's
//! `radius` × `radius_scale`, which is ℓ_u). Whichever way, `profile` names the diffusion
//! model (`lucent_core::ProfileModel`).

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec3;
use lucent_core::ProfileModel;
use toml::Spanned;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::{RawMaterial, RawParam, RawTextureRef};
use super::model::{
    ColorParam, Distance, Material, Medium, ScalarParam, Specular, TranslucentMaterial,
};
use super::origin::SceneOrigin;
use crate::texture::{
    FIRST_TILE, LAST_TILE, MAX_UDIM_TEXELS, Texture, TextureEncoding, UDIM_TOKEN,
};

/// The names accepted by `preset` (matched case-insensitively): the measured materials of
/// Jensen et al. 2001 in `lucent_core::presets`, the one list.
pub fn preset_names() -> impl Iterator<Item = &'static str> {
    lucent_core::presets::PRESETS.iter().map(|p| p.name)
}

/// The names accepted by `profile`, in [`ProfileModel::ALL`]'s order.
pub fn profile_names() -> impl Iterator<Item = &'static str> {
    ProfileModel::ALL.iter().map(|m| m.name())
}

/// Material types accepted by `type`.
const MATERIAL_TYPES: [&str; 2] = ["translucent", "lambert"];

/// Loads each texture once per (file, encoding).
pub(crate) struct TextureCache<'o> {
    origin: &'o SceneOrigin,
    loaded: HashMap<(String, TextureEncoding), Arc<Texture>>,
    /// Most texels in all the tiles of a UDIM set ([`MAX_UDIM_TEXELS`]).
    udim_texel_cap: u64,
}

impl<'o> TextureCache<'o> {
    /// An empty cache reading through `origin`.
    pub fn new(origin: &'o SceneOrigin) -> Self {
        TextureCache {
            origin,
            loaded: HashMap::new(),
            udim_texel_cap: MAX_UDIM_TEXELS,
        }
    }

    /// The texture in `file` (relative to the scene), decoded with `encoding`; errors are
    /// located at `file`'s span under `key`.
    pub fn get(
        &mut self,
        c: &Check,
        key: &str,
        file: &Spanned<String>,
        encoding: TextureEncoding,
    ) -> Checked<Arc<Texture>> {
        let name = file.get_ref().clone();
        if let Some(t) = self.loaded.get(&(name.clone(), encoding)) {
            return Ok(Arc::clone(t));
        }
        let texture = if name.contains(UDIM_TOKEN) {
            self.udim(c, key, file, encoding)?
        } else {
            self.one(c, key, file, &name, encoding)?
        };
        let texture = Arc::new(texture);
        self.loaded.insert((name, encoding), Arc::clone(&texture));
        Ok(texture)
    }

    /// The image in the scene-relative file `name`, decoded with `encoding`; errors located at
    /// `file` under `key`.
    fn one(
        &self,
        c: &Check,
        key: &str,
        file: &Spanned<String>,
        name: &str,
        encoding: TextureEncoding,
    ) -> Checked<Texture> {
        let path = self.origin.resolve(name);
        let bytes = self.origin.read(name).map_err(|why| {
            c.at(
                SceneErrorKind::Io,
                key,
                file,
                format!("cannot read texture {}: {why}", path.display()),
            )
            .with_source(why)
        })?;
        Texture::from_bytes(&bytes, &path, encoding).map_err(|e| {
            c.at(SceneErrorKind::Texture, key, file, e.to_string())
                .with_source(e)
        })
    }

    /// The UDIM set `file` names (its file name holds `<UDIM>`): every tile file found,
    /// decoded with `encoding`, at most [`MAX_UDIM_TEXELS`] texels in all (each tile within
    /// its own cap first).
    fn udim(
        &self,
        c: &Check,
        key: &str,
        file: &Spanned<String>,
        encoding: TextureEncoding,
    ) -> Checked<Texture> {
        let pattern = file.get_ref();
        let path = self.origin.resolve(pattern);
        let fail = |kind, message: String| c.at(kind, key, file, message);
        let names = self.origin.udim_tiles(pattern).map_err(|why| {
            fail(
                SceneErrorKind::Io,
                format!("cannot list the UDIM tiles {}: {why}", path.display()),
            )
            .with_source(why)
        })?;
        if names.is_empty() {
            return Err(fail(
                SceneErrorKind::Io,
                format!(
                    "no file matches the UDIM set {} (tiles {FIRST_TILE} to {LAST_TILE})",
                    path.display(),
                ),
            ));
        }
        let mut tiles = Vec::with_capacity(names.len());
        let mut texels = 0u64;
        for (tile, name) in names {
            let texture = self.one(c, key, file, &name, encoding)?;
            texels += texture.texel_count() as u64;
            if texels > self.udim_texel_cap {
                return Err(fail(
                    SceneErrorKind::Texture,
                    format!(
                        "UDIM set {}: more than {} texels in all (up to tile {tile})",
                        path.display(),
                        self.udim_texel_cap
                    ),
                ));
            }
            tiles.push((tile, texture));
        }
        // The tile numbers come from the file names, each once: they are valid.
        Texture::udim(path.clone(), tiles).ok_or_else(|| {
            fail(
                SceneErrorKind::Texture,
                format!("UDIM set {}: invalid tile numbers", path.display()),
            )
        })
    }
}

/// A built material and, if it uses a texture, the key of the first textured parameter (the
/// objects that use it must have UVs).
pub(crate) struct BuiltMaterial {
    pub material: Material,
    pub texture_key: Option<&'static str>,
    /// `kd = "mtl"`: each object using it supplies K_d from its OBJ's `map_Kd` (the material
    /// holds a placeholder constant until [`with_kd_texture`] replaces it).
    pub kd_from_mtl: bool,
}

/// The K_d every `kd = "mtl"` material holds until an object supplies its `map_Kd`.
const MTL_PLACEHOLDER_KD: f32 = 0.5;

/// A copy of a `kd = "mtl"` material with K_d from `texture`, named after both.
pub(crate) fn with_kd_texture(material: &Material, texture: Arc<Texture>, file: &str) -> Material {
    let mut m = material.clone();
    if let Material::Translucent(t) = &mut m {
        t.name = format!("{} (map_Kd {file})", t.name);
        if let Medium::Reflectance { kd, .. } = &mut t.medium {
            *kd = ColorParam::Texture(texture);
        }
    }
    m
}

/// Builds one material from its table.
pub(crate) fn build_material(
    c: &Check,
    name: &str,
    raw: &Spanned<RawMaterial>,
    textures: &mut TextureCache,
) -> Checked<BuiltMaterial> {
    let m = raw.get_ref();
    let key = |k: &str| format!("material.{name}.{k}");
    match m.kind.get_ref().as_str() {
        "lambert" => {
            let what = "a lambert material";
            c.forbid(&key("preset"), &m.preset, what)?;
            c.forbid(&key("mm_per_unit"), &m.mm_per_unit, what)?;
            c.forbid(&key("sigma_a"), &m.sigma_a, what)?;
            c.forbid(&key("sigma_s_prime"), &m.sigma_s_prime, what)?;
            c.forbid(&key("eta"), &m.eta, what)?;
            c.forbid(&key("kd"), &m.kd, what)?;
            c.forbid(&key("mean_free_path"), &m.mean_free_path, what)?;
            c.forbid(
                &key("diffuse_mean_free_path"),
                &m.diffuse_mean_free_path,
                what,
            )?;
            c.forbid(&key("radius"), &m.radius, what)?;
            c.forbid(&key("radius_scale"), &m.radius_scale, what)?;
            c.forbid(&key("profile"), &m.profile, what)?;
            c.forbid(&key("specular"), &m.specular, what)?;
            let albedo = c.require(&key("albedo"), &m.albedo, raw, what)?;
            let albedo = c.rgb(
                &key("albedo"),
                albedo,
                |x| (0.0..=1.0).contains(&x),
                "must be in [0, 1]",
            )?;
            Ok(BuiltMaterial {
                material: Material::Lambert {
                    name: name.to_string(),
                    albedo,
                },
                texture_key: None,
                kd_from_mtl: false,
            })
        }
        "translucent" => {
            c.forbid(&key("albedo"), &m.albedo, "a translucent material (use kd)")?;
            let model = profile_model(c, &key("profile"), &m.profile)?;
            let (medium, texture_key, kd_from_mtl) = build_medium(c, name, raw, model, textures)?;
            let specular = match &m.specular {
                None => None,
                Some(s) => {
                    let s = s.get_ref();
                    Some(Specular {
                        exponent: c.positive(&key("specular.exponent"), &s.exponent)?,
                        strength: match &s.strength {
                            Some(v) => c.non_negative(&key("specular.strength"), v)?,
                            None => 1.0,
                        },
                    })
                }
            };
            Ok(BuiltMaterial {
                material: Material::Translucent(TranslucentMaterial {
                    name: name.to_string(),
                    medium,
                    model,
                    specular,
                }),
                texture_key,
                kd_from_mtl,
            })
        }
        other => Err(c.at(
            SceneErrorKind::UnknownName,
            &key("type"),
            &m.kind,
            format!(
                "unknown material type `{other}` (expected one of: {})",
                MATERIAL_TYPES.join(", ")
            ),
        )),
    }
}

/// `profile`: one of [`profile_names`]; the classical dipole when absent.
fn profile_model(c: &Check, key: &str, v: &Option<Spanned<String>>) -> Checked<ProfileModel> {
    let Some(v) = v else {
        return Ok(ProfileModel::default());
    };
    ProfileModel::ALL
        .into_iter()
        .find(|m| m.name() == v.get_ref())
        .ok_or_else(|| {
            c.at(
                SceneErrorKind::UnknownName,
                key,
                v,
                format!(
                    "unknown profile `{}` (expected one of: {})",
                    v.get_ref(),
                    profile_names().collect::<Vec<_>>().join(", ")
                ),
            )
        })
}

/// The three ways of giving a medium; exactly one must be used. Also returns the first
/// textured key and whether K_d comes from the OBJ's `.mtl` (`kd = "mtl"`). Every range check
/// builds the profiles of `model`.
fn build_medium(
    c: &Check,
    name: &str,
    raw: &Spanned<RawMaterial>,
    model: ProfileModel,
    textures: &mut TextureCache,
) -> Checked<(Medium, Option<&'static str>, bool)> {
    let m = raw.get_ref();
    let key = |k: &str| format!("material.{name}.{k}");
    const FORMS: &str = "a translucent material takes exactly one of: `preset` + `mm_per_unit`; \
                         `sigma_a` + `sigma_s_prime` + `eta`; `kd` + (`mean_free_path`, \
                         `diffuse_mean_free_path` or `radius` [+ `radius_scale`]) + `eta`";
    // The first key of each form that is present, with its span.
    let preset_form = m.preset.as_ref().map(|v| ("preset", v.span()));
    let coeff_form = m
        .sigma_a
        .as_ref()
        .map(|v| ("sigma_a", v.span()))
        .or_else(|| {
            m.sigma_s_prime
                .as_ref()
                .map(|v| ("sigma_s_prime", v.span()))
        });
    let artist_form =
        m.kd.as_ref()
            .map(|v| ("kd", v.span()))
            .or_else(|| {
                m.mean_free_path
                    .as_ref()
                    .map(|v| ("mean_free_path", v.span()))
            })
            .or_else(|| {
                m.diffuse_mean_free_path
                    .as_ref()
                    .map(|v| ("diffuse_mean_free_path", v.span()))
            })
            .or_else(|| m.radius.as_ref().map(|v| ("radius", v.span())))
            .or_else(|| m.radius_scale.as_ref().map(|v| ("radius_scale", v.span())));
    let present: Vec<_> = [preset_form, coeff_form, artist_form]
        .into_iter()
        .flatten()
        .collect();
    match present.as_slice() {
        [] => {
            return Err(c.at(
                SceneErrorKind::MissingKey,
                &format!("material.{name}"),
                raw,
                format!("no scattering parameters: {FORMS}"),
            ));
        }
        [(first, _), (second, span), ..] => {
            return Err(c.src.error(
                SceneErrorKind::Conflict,
                span.clone(),
                key(second),
                format!("cannot be combined with `{first}`: {FORMS}"),
            ));
        }
        [_] => {}
    }
    if let Some(preset) = &m.preset {
        c.forbid(&key("eta"), &m.eta, "a preset (it has its own)")?;
        if lucent_core::presets::find(preset.get_ref()).is_none() {
            return Err(c.at(
                SceneErrorKind::UnknownName,
                &key("preset"),
                preset,
                format!(
                    "unknown preset `{}` (expected one of: {})",
                    preset.get_ref(),
                    preset_names()
                        .map(str::to_ascii_lowercase)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        let scale = c.require(&key("mm_per_unit"), &m.mm_per_unit, raw, "a preset")?;
        let mm_per_unit = c.positive(&key("mm_per_unit"), scale)?;
        if let Some(found) = lucent_core::presets::find(preset.get_ref())
            && let Err(e) = lucent_core::Profile::from_preset_with(model, found, mm_per_unit)
        {
            return Err(c.range(
                &key("mm_per_unit"),
                scale,
                format!(
                    "{} is out of range for preset `{}`: {e}",
                    c.written(scale),
                    preset.get_ref()
                ),
            ));
        }
        let medium = Medium::Preset {
            name: preset.get_ref().to_ascii_lowercase(),
            mm_per_unit,
        };
        return Ok((medium, None, false));
    }
    if m.sigma_a.is_some() || m.sigma_s_prime.is_some() {
        let what = "explicit coefficients";
        c.forbid(&key("mm_per_unit"), &m.mm_per_unit, what)?;
        let sa = c.require(&key("sigma_a"), &m.sigma_a, raw, what)?;
        let ss = c.require(&key("sigma_s_prime"), &m.sigma_s_prime, raw, what)?;
        let positive = |x: f32| x > 0.0;
        let sigma_a = c.rgb(&key("sigma_a"), sa, positive, "must be greater than 0")?;
        let sigma_s_prime = c.rgb(
            &key("sigma_s_prime"),
            ss,
            positive,
            "must be greater than 0",
        )?;
        let eta = eta(c, &key("eta"), &m.eta, raw, what)?;
        if let Err(e) =
            lucent_core::Profile::from_coefficients_with(model, sigma_a, sigma_s_prime, eta)
        {
            return Err(c.range(
                &key("sigma_a"),
                sa,
                format!(
                    "{} (with sigma_s_prime = {}) is out of range: {e}",
                    c.written(sa),
                    c.written(ss)
                ),
            ));
        }
        let medium = Medium::Coefficients {
            sigma_a,
            sigma_s_prime,
            eta,
        };
        return Ok((medium, None, false));
    }
    let what = "kd and a mean free path";
    c.forbid(&key("mm_per_unit"), &m.mm_per_unit, what)?;
    let kd_raw = c.require(&key("kd"), &m.kd, raw, what)?;
    let kd_from_mtl = matches!(kd_raw.get_ref(), RawParam::Word(w) if w == "mtl");
    let kd = if kd_from_mtl {
        ColorParam::Constant(glam::Vec3::splat(MTL_PLACEHOLDER_KD))
    } else {
        color_param(c, &key("kd"), kd_raw, textures)?
    };
    let (distance, given_distance) = distance(c, name, raw, textures)?;
    let eta = eta(c, &key("eta"), &m.eta, raw, what)?;
    if let Err(e) = crate::material::reflectance_params(&kd, &distance, eta, model) {
        let (name, v) = given_distance;
        return Err(c.at(
            SceneErrorKind::OutOfRange,
            &key(name),
            v,
            format!(
                "{} is out of range with kd = {}: {e}",
                c.written(v),
                c.written(kd_raw)
            ),
        ));
    }
    let textured = [
        (kd_from_mtl || matches!(kd, ColorParam::Texture(_))).then_some("kd"),
        matches!(distance.param(), ScalarParam::Texture { .. }).then_some(given_distance.0),
    ];
    Ok((
        Medium::Reflectance { kd, distance, eta },
        textured.into_iter().flatten().next(),
        kd_from_mtl,
    ))
}

/// The distance of the artist form: exactly one of `mean_free_path`, `diffuse_mean_free_path`
/// and `radius` (ℓ_u = `radius` × `radius_scale`, the scale only with `radius`). Also returns
/// the key it was given by and its value (where a range error on it points).
fn distance<'r>(
    c: &Check,
    name: &str,
    raw: &'r Spanned<RawMaterial>,
    textures: &mut TextureCache,
) -> Checked<(Distance, (&'static str, &'r Spanned<RawParam>))> {
    let m = raw.get_ref();
    let key = |k: &str| format!("material.{name}.{k}");
    let given: Vec<(&'static str, &Spanned<RawParam>)> = [
        ("mean_free_path", &m.mean_free_path),
        ("diffuse_mean_free_path", &m.diffuse_mean_free_path),
        ("radius", &m.radius),
    ]
    .into_iter()
    .filter_map(|(k, v)| v.as_ref().map(|v| (k, v)))
    .collect();
    let (which, v) = match given.as_slice() {
        [] => {
            return Err(match &m.radius_scale {
                Some(scale) => c.at(
                    SceneErrorKind::MissingKey,
                    &key("radius"),
                    scale,
                    "missing required key: `radius_scale` scales `radius`",
                ),
                None => c.at(
                    SceneErrorKind::MissingKey,
                    &key("mean_free_path"),
                    raw,
                    "missing required key: `kd` needs `mean_free_path` (ℓ_u = 1/σ_t′), \
                     `diffuse_mean_free_path` (ℓ_d = 1/σ_tr) or `radius` (ℓ_u, with \
                     `radius_scale`)",
                ),
            });
        }
        [(first, _), (second, v), ..] => {
            return Err(c.at(
                SceneErrorKind::Conflict,
                &key(second),
                v,
                format!("cannot be combined with `{first}`: give one distance"),
            ));
        }
        [one] => *one,
    };
    if which != "radius"
        && let Some(scale) = &m.radius_scale
    {
        return Err(c.at(
            SceneErrorKind::Conflict,
            &key("radius_scale"),
            scale,
            format!("cannot be combined with `{which}`: it scales `radius`"),
        ));
    }
    let param = distance_param(c, &key(which), v, textures)?;
    let distance = match which {
        "diffuse_mean_free_path" => Distance::DiffuseMeanFreePath(param),
        "radius" => Distance::MeanFreePath(match &m.radius_scale {
            None => param,
            Some(scale) => scaled_radius(c, &key("radius_scale"), scale, param)?,
        }),
        _ => Distance::MeanFreePath(param),
    };
    Ok((distance, (which, v)))
}

/// `radius` × `radius_scale` (a positive number), per channel in single precision; the products
/// must stay positive and finite.
fn scaled_radius(
    c: &Check,
    key: &str,
    scale: &Spanned<f64>,
    radius: ScalarParam,
) -> Checked<ScalarParam> {
    let s = c.positive(key, scale)?;
    let product = |r: Vec3| {
        let l = r * s;
        if l.is_finite() && l.min_element() > 0.0 {
            Ok(l)
        } else {
            Err(c.range(
                key,
                scale,
                format!(
                    "{} times radius {r} is not a positive single-precision distance",
                    c.written(scale)
                ),
            ))
        }
    };
    Ok(match radius {
        ScalarParam::Constant(r) => ScalarParam::Constant(product(r)?),
        ScalarParam::Texture { texture, min, max } => ScalarParam::Texture {
            texture,
            min: product(Vec3::splat(min))?.x,
            max: product(Vec3::splat(max))?.x,
        },
    })
}

/// The relative index of refraction: required, in [1, `lucent_core::Profile::MAX_ETA`] (the
/// J01 Fresnel fit behind the dipole's boundary term is only sound there).
fn eta(
    c: &Check,
    key: &str,
    v: &Option<Spanned<f64>>,
    table: &Spanned<RawMaterial>,
    what: &str,
) -> Checked<f32> {
    let v = c.require(key, v, table, what)?;
    let max = lucent_core::Profile::MAX_ETA;
    c.num_where(
        key,
        v,
        |x| (1.0..=max).contains(&x),
        &format!("must be between 1 and {max} (relative index of refraction, inside / outside)"),
    )
}

/// K_d: `[r, g, b]` / a number in (0, 1), or `{ texture = "file.png" }` (sRGB-decoded);
/// `"mtl"` is handled by the caller.
fn color_param(
    c: &Check,
    key: &str,
    v: &Spanned<RawParam>,
    textures: &mut TextureCache,
) -> Checked<ColorParam> {
    match v.get_ref() {
        RawParam::Constant(components) => {
            let spanned = Spanned::new(v.span(), components.clone());
            let kd = c.rgb(
                key,
                &spanned,
                |x| x > 0.0 && x < 1.0,
                "must be strictly between 0 and 1",
            )?;
            Ok(ColorParam::Constant(kd))
        }
        RawParam::Texture(t) => {
            forbid_range(c, key, t, "a colour texture")?;
            let texture = textures.get(
                c,
                &format!("{key}.texture"),
                &t.texture,
                TextureEncoding::Srgb,
            )?;
            Ok(ColorParam::Texture(texture))
        }
        RawParam::Word(w) => Err(c.at(
            SceneErrorKind::WrongType,
            key,
            v,
            format!(
                "invalid value `{w}`: expected a number, an array [r, g, b], a table \
                 {{ texture = \"file.png\" }} or \"mtl\" (the OBJ's map_Kd)"
            ),
        )),
    }
}

/// A distance: a positive number / `[r, g, b]`, or `{ texture, min, max }` (linear data).
fn distance_param(
    c: &Check,
    key: &str,
    v: &Spanned<RawParam>,
    textures: &mut TextureCache,
) -> Checked<ScalarParam> {
    match v.get_ref() {
        RawParam::Constant(components) => {
            let spanned = Spanned::new(v.span(), components.clone());
            let d = c.rgb(key, &spanned, |x| x > 0.0, "must be greater than 0")?;
            Ok(ScalarParam::Constant(d))
        }
        RawParam::Texture(t) => {
            let missing = |k: &str| {
                c.at(
                    SceneErrorKind::MissingKey,
                    &format!("{key}.{k}"),
                    v,
                    "a distance texture needs `min` and `max` (distance at 0 and at 1)",
                )
            };
            let min = t.min.as_ref().ok_or_else(|| missing("min"))?;
            let max = t.max.as_ref().ok_or_else(|| missing("max"))?;
            let min = c.positive(&format!("{key}.min"), min)?;
            let max = c.positive(&format!("{key}.max"), max)?;
            let texture = textures.get(
                c,
                &format!("{key}.texture"),
                &t.texture,
                TextureEncoding::Linear,
            )?;
            Ok(ScalarParam::Texture { texture, min, max })
        }
        RawParam::Word(w) => Err(c.at(
            SceneErrorKind::WrongType,
            key,
            v,
            format!(
                "invalid value `{w}`: expected a number, an array [r, g, b] or a table \
                 {{ texture, min, max }} (only `kd` may be \"mtl\")"
            ),
        )),
    }
}

fn forbid_range(c: &Check, key: &str, t: &RawTextureRef, what: &str) -> Checked<()> {
    c.forbid(&format!("{key}.min"), &t.min, what)?;
    c.forbid(&format!("{key}.max"), &t.max, what)
}

#[cfg(test)]
mod tests {
    use super::super::error::Source;
    use super::*;
    use crate::texture::tests::encode_png;

    /// A UDIM set among a built-in scene's files (listed like a folder's): its tiles load,
    /// other files beside them are not tiles, and tiles holding more texels together than the
    /// cap are refused, naming the tile that crossed it.
    #[test]
    fn udim_sets_load_their_tiles_within_the_cap() {
        let tile = |grey: u8| {
            let png = encode_png(
                2,
                2,
                png::ColorType::Grayscale,
                png::BitDepth::Eight,
                &[grey; 4],
                None,
            );
            std::borrow::Cow::Owned(png)
        };
        let origin = SceneOrigin::Embedded {
            name: "<test>/scene.toml".to_string(),
            files: vec![
                ("t/kd.1002.png".to_string(), tile(200)),
                ("t/kd.1001.png".to_string(), tile(100)),
                ("t/kd.png".to_string(), tile(0)),
                ("kd.1003.png".to_string(), tile(0)),
            ],
        };
        let c = Check {
            src: Source {
                file: "scene.toml",
                text: "kd",
            },
        };
        let file = Spanned::new(0..2, "t/kd.<UDIM>.png".to_string());
        let mut cache = TextureCache::new(&origin);
        cache.udim_texel_cap = 7;
        let e = cache
            .get(&c, "k", &file, TextureEncoding::Linear)
            .expect_err("8 texels > 7");
        assert!(
            e.message
                .ends_with("kd.<UDIM>.png: more than 7 texels in all (up to tile 1002)"),
            "{}",
            e.message
        );
        cache.udim_texel_cap = 8;
        let set = cache
            .get(&c, "k", &file, TextureEncoding::Linear)
            .expect("8 texels");
        assert!(set.is_udim());
        let grey = |code: f32| Vec3::splat(code / 255.0);
        let want = [[grey(100.0); 4], [grey(200.0); 4]].concat();
        assert_eq!(set.texels().collect::<Vec<_>>(), want);
    }
}
