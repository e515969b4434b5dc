//! `[[light]]` tables → [`Light`]: each type's required keys, defaults and ranges.

use glam::Vec3;
use toml::Spanned;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::{Components, RawLight};
use super::model::Light;

/// Light types accepted by `type`.
pub const LIGHT_TYPES: [&str; 4] = ["point", "spot", "directional", "sphere"];

/// Default shadow samples of a sphere light.
pub const DEFAULT_SPHERE_SAMPLES: u32 = 16;

/// Largest number of shadow samples of a sphere light.
pub const MAX_SPHERE_SAMPLES: i64 = 4096;

/// Builds the light `index` (its key prefix is `light[index]`).
pub(crate) fn build_light(c: &Check, index: usize, raw: &Spanned<RawLight>) -> Checked<Light> {
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
            _ => matches!(k, "center" | "radius" | "intensity" | "samples"),
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
        _ => {
            let center = position(c, "center", &l.center)?;
            let r = c.require(&key("radius"), &l.radius, raw, what)?;
            let radius = c.positive(&key("radius"), r)?;
            let samples = match &l.samples {
                Some(v) => c.int(&key("samples"), v, 1, MAX_SPHERE_SAMPLES)? as u32,
                None => DEFAULT_SPHERE_SAMPLES,
            };
            Light::Sphere {
                center,
                radius,
                color,
                intensity: intensity(c)?,
                samples,
            }
        }
    })
}
