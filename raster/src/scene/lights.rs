//! `[[light]]` tables → [`Light`]: each type's required keys, defaults and ranges.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use toml::Spanned;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::{Components, RawLight};
use super::materials::TextureCache;
use super::model::Light;
use crate::lights::{EnvironmentMap, rect_frame};
use crate::texture::TextureEncoding;

/// Light types accepted by `type`.
pub const LIGHT_TYPES: [&str; 6] = [
    "point",
    "spot",
    "directional",
    "sphere",
    "rect",
    "environment",
];

/// Default shadow samples of a sphere light.
pub const DEFAULT_SPHERE_SAMPLES: u32 = 16;

/// Largest number of shadow samples of a sphere light (and of a rect or environment light).
pub const MAX_SPHERE_SAMPLES: i64 = 4096;

/// Default shadow samples of a rect light (as for a sphere light).
pub const DEFAULT_RECT_SAMPLES: u32 = DEFAULT_SPHERE_SAMPLES;

/// Default shadow rays of an environment light (`docs/physics.md` §5.2 measures their noise).
pub const DEFAULT_ENVIRONMENT_SAMPLES: u32 = 64;

/// Builds the light `index` (its key prefix is `light[index]`); an environment's `map` is read
/// through `textures`.
pub(crate) fn build_light(
    c: &Check,
    index: usize,
    raw: &Spanned<RawLight>,
    textures: &mut TextureCache,
) -> Checked<Light> {
    let l = raw.get_ref();
    let key = |k: &str| format!("light[{index}].{k}");
    let color = match &l.color {
        Some(v) => c.rgb(&key("color"), v, |x| x >= 0.0, "must be at least 0")?,
        None => Vec3::ONE,
    };
    let kind = l.kind.get_ref().as_str();
    let what = match kind {
        "point" => "a point light",
        "spot" => "a spot light",
        "directional" => "a directional light",
        "sphere" => "a sphere light",
        "rect" => "a rect light",
        "environment" => "an environment light",
        other => {
            return Err(c.at(
                SceneErrorKind::UnknownName,
                &key("type"),
                &l.kind,
                format!(
                    "unknown light type `{other}` (expected one of: {})",
                    LIGHT_TYPES.join(", ")
                ),
            ));
        }
    };
    // Keys each type does not take.
    let takes = |k: &str| -> bool {
        match kind {
            "point" => matches!(k, "position" | "intensity"),
            "spot" => matches!(
                k,
                "position" | "direction" | "intensity" | "inner_angle" | "outer_angle"
            ),
            "directional" => matches!(k, "direction" | "irradiance"),
            "sphere" => matches!(k, "center" | "radius" | "intensity" | "samples"),
            "rect" => matches!(
                k,
                "position" | "direction" | "size" | "up" | "intensity" | "samples"
            ),
            _ => matches!(k, "map" | "rotation" | "intensity" | "samples"),
        }
    };
    let spans = [
        ("position", l.position.as_ref().map(|v| v.span())),
        ("direction", l.direction.as_ref().map(|v| v.span())),
        ("center", l.center.as_ref().map(|v| v.span())),
        ("radius", l.radius.as_ref().map(|v| v.span())),
        ("intensity", l.intensity.as_ref().map(|v| v.span())),
        ("irradiance", l.irradiance.as_ref().map(|v| v.span())),
        ("inner_angle", l.inner_angle.as_ref().map(|v| v.span())),
        ("outer_angle", l.outer_angle.as_ref().map(|v| v.span())),
        ("samples", l.samples.as_ref().map(|v| v.span())),
        ("size", l.size.as_ref().map(|v| v.span())),
        ("up", l.up.as_ref().map(|v| v.span())),
        ("map", l.map.as_ref().map(|v| v.span())),
        ("rotation", l.rotation.as_ref().map(|v| v.span())),
    ];
    for (k, span) in spans {
        if let Some(span) = span
            && !takes(k)
        {
            return Err(c.src.error(
                SceneErrorKind::Conflict,
                span,
                key(k),
                format!("does not apply to {what}"),
            ));
        }
    }
    let intensity = |c: &Check| -> Checked<f32> {
        let v = c.require(&key("intensity"), &l.intensity, raw, what)?;
        c.non_negative(&key("intensity"), v)
    };
    let direction = |c: &Check| -> Checked<Vec3> {
        let v = c.require(&key("direction"), &l.direction, raw, what)?;
        let d = c.vec3(&key("direction"), v)?;
        d.try_normalize()
            .ok_or_else(|| c.range(&key("direction"), v, "must not be the zero vector"))
    };
    let position = |c: &Check, k: &str, v: &Option<Spanned<Components>>| -> Checked<Vec3> {
        let v = c.require(&key(k), v, raw, what)?;
        c.vec3(&key(k), v)
    };
    let samples = |c: &Check, default: u32| -> Checked<u32> {
        match &l.samples {
            Some(v) => Ok(c.int(&key("samples"), v, 1, MAX_SPHERE_SAMPLES)? as u32),
            None => Ok(default),
        }
    };
    Ok(match kind {
        "point" => Light::Point {
            position: position(c, "position", &l.position)?,
            color,
            intensity: intensity(c)?,
        },
        "spot" => {
            let position = position(c, "position", &l.position)?;
            let direction = direction(c)?;
            let inner = c.require(&key("inner_angle"), &l.inner_angle, raw, what)?;
            let outer = c.require(&key("outer_angle"), &l.outer_angle, raw, what)?;
            let outer_angle_degrees = c.num_where(
                &key("outer_angle"),
                outer,
                |x| x > 0.0 && x < 180.0,
                "must be in (0, 180) degrees (a half-angle)",
            )?;
            let inner_angle_degrees = c.num_where(
                &key("inner_angle"),
                inner,
                |x| (0.0..=outer_angle_degrees).contains(&x),
                &format!("must be in [0, outer_angle = {outer_angle_degrees}] degrees"),
            )?;
            Light::Spot {
                position,
                direction,
                inner_angle_degrees,
                outer_angle_degrees,
                color,
                intensity: intensity(c)?,
            }
        }
        "directional" => {
            let direction = direction(c)?;
            let v = c.require(&key("irradiance"), &l.irradiance, raw, what)?;
            Light::Directional {
                direction,
                color,
                irradiance: c.non_negative(&key("irradiance"), v)?,
            }
        }
        "sphere" => {
            let center = position(c, "center", &l.center)?;
            let r = c.require(&key("radius"), &l.radius, raw, what)?;
            let radius = c.positive(&key("radius"), r)?;
            Light::Sphere {
                center,
                radius,
                color,
                intensity: intensity(c)?,
                samples: samples(c, DEFAULT_SPHERE_SAMPLES)?,
            }
        }
        "rect" => {
            let center = position(c, "position", &l.position)?;
            let normal = direction(c)?;
            let v = c.require(&key("size"), &l.size, raw, what)?;
            let s = c.components(&key("size"), v, 2)?;
            let size = Vec2::new(s[0], s[1]);
            if !(size.x > 0.0 && size.y > 0.0 && (size.x * size.y).is_normal()) {
                return Err(c.range(
                    &key("size"),
                    v,
                    format!(
                        "width and height must be greater than 0, with an area that fits a \
                         float (got [{}, {}])",
                        s[0], s[1]
                    ),
                ));
            }
            let up = match &l.up {
                Some(v) => Some((c.vec3(&key("up"), v)?, v)),
                None => None,
            };
            let (right, up_axis) = rect_frame(normal, up.map(|(u, _)| u)).ok_or_else(|| {
                let (_, v) = up.expect("the default up always has a frame");
                c.range(
                    &key("up"),
                    v,
                    "must not be zero or parallel to `direction` (the rectangle's height \
                     runs along up made perpendicular to direction)",
                )
            })?;
            Light::Rect {
                center,
                normal,
                right,
                up_axis,
                size,
                color,
                intensity: intensity(c)?,
                samples: samples(c, DEFAULT_RECT_SAMPLES)?,
            }
        }
        _ => {
            let map = match &l.map {
                Some(file) => {
                    let texture = textures.get(c, &key("map"), file, TextureEncoding::Srgb)?;
                    let map = EnvironmentMap::new(texture).map_err(|why| {
                        c.at(
                            SceneErrorKind::Texture,
                            &key("map"),
                            file,
                            format!("environment map {}: {why}", file.get_ref()),
                        )
                    })?;
                    Some(Arc::new(map))
                }
                None => None,
            };
            let rotation_degrees = match &l.rotation {
                Some(v) => c.num_where(
                    &key("rotation"),
                    v,
                    |x| x.abs() <= 360.0,
                    "must be in [-360, 360] degrees",
                )?,
                None => 0.0,
            };
            Light::Environment {
                color,
                intensity: intensity(c)?,
                map,
                rotation_degrees,
                samples: samples(c, DEFAULT_ENVIRONMENT_SAMPLES)?,
            }
        }
    })
}
