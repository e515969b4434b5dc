//! `[camera]`, `[render]` and `[output]` → [`Camera`], [`RenderSettings`], [`OutputSettings`].

use std::path::PathBuf;

use glam::Vec3;
use lucent_core::error::ParseMethodError;
use toml::Spanned;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::{RawCamera, RawOutput, RawRender, RawSamples};
use super::model::{
    ExrLayers, MAX_INTERPOLATION_STEP, OutputSettings, RenderSettings, SampleDensity, SampleRequest,
};
use crate::camera::Camera;

/// Default image width and height.
pub const DEFAULT_RESOLUTION: u32 = 512;

/// Largest image width or height.
pub const MAX_SIDE: i64 = 16_384;

/// Largest number of pixels (2^26, e.g. 8192 × 8192).
pub const MAX_PIXELS: i64 = 1 << 26;

/// Largest number of irradiance samples a scene may ask for (directly or through `spacing`).
pub const MAX_SAMPLES: i64 = 1 << 25;

/// Most worker threads a render may ask for (`threads`, `--threads`).
pub const MAX_THREADS: i64 = 1024;

/// The word that asks for an automatic sample count (`samples = "auto"`, `--samples auto`).
pub const AUTO: &str = "auto";

/// Values accepted in `output.layers`.
pub const LAYERS: [&str; 5] = ["exitance", "local", "global", "irradiance", "depth"];

/// Builds the camera.
pub(crate) fn build_camera(c: &Check, raw: &Spanned<RawCamera>) -> Checked<Camera> {
    let r = raw.get_ref();
    let position = c.vec3("camera.position", &r.position)?;
    let target = c.vec3("camera.target", &r.target)?;
    let up = match &r.up {
        Some(v) => c.vec3("camera.up", v)?,
        None => Vec3::Z,
    };
    let forward = target - position;
    let scale = position.abs().max(target.abs()).max_element().max(1.0);
    if forward.length() <= 1e-6 * scale {
        return Err(c.range(
            "camera.target",
            &r.target,
            "must differ from camera.position (the view direction is undefined)",
        ));
    }
    let fits = up
        .try_normalize()
        .is_some_and(|u| u.cross(forward.normalize()).length() > 1e-3);
    if !fits {
        let span = r.up.as_ref().map_or(raw.span(), |v| v.span());
        let key = if r.up.is_some() {
            "camera.up"
        } else {
            "camera"
        };
        return Err(c.src.error(
            SceneErrorKind::OutOfRange,
            span,
            key,
            format!(
                "up {:?} is zero or parallel to the view direction {:?}",
                up.to_array(),
                forward.normalize().to_array()
            ),
        ));
    }
    let vfov_degrees = c.num_where(
        "camera.fov",
        &r.fov,
        |x| x > 0.0 && x < 180.0,
        "must be in (0, 180) degrees (vertical field of view)",
    )?;
    let side = |k: &str, v: &Option<Spanned<i64>>| -> Checked<u32> {
        match v {
            Some(v) => Ok(c.int(k, v, 1, MAX_SIDE)? as u32),
            None => Ok(DEFAULT_RESOLUTION),
        }
    };
    let width = side("camera.width", &r.width)?;
    let height = side("camera.height", &r.height)?;
    if i64::from(width) * i64::from(height) > MAX_PIXELS {
        let (key, span) = match (&r.height, &r.width) {
            (Some(h), _) => ("camera.height", h.span()),
            (None, Some(w)) => ("camera.width", w.span()),
            (None, None) => ("camera", raw.span()),
        };
        return Err(c.src.error(
            SceneErrorKind::OutOfRange,
            span,
            key,
            format!("{width} × {height} is more than {MAX_PIXELS} pixels"),
        ));
    }
    Ok(Camera {
        position,
        target,
        up,
        vfov_degrees,
        width,
        height,
    })
}

/// Builds the render settings; `translucent_area` (scene units²) bounds what `spacing` may ask.
pub(crate) fn build_render(
    c: &Check,
    raw: Option<&Spanned<RawRender>>,
    translucent_area: f64,
) -> Checked<RenderSettings> {
    let mut s = RenderSettings::default();
    let Some(raw) = raw else {
        return Ok(s);
    };
    let r = raw.get_ref();
    if let Some(m) = &r.method {
        s.method = m.get_ref().parse().map_err(|e: ParseMethodError| {
            c.at(
                SceneErrorKind::UnknownName,
                "render.method",
                m,
                e.to_string(),
            )
        })?;
    }
    match (&r.samples, &r.spacing) {
        (Some(_), Some(spacing)) => {
            return Err(c.at(
                SceneErrorKind::Conflict,
                "render.spacing",
                spacing,
                "cannot be combined with `samples`: give a count or a spacing",
            ));
        }
        (Some(n), None) => s.samples = samples(c, n)?,
        (None, Some(d)) => {
            let spacing = c.positive("render.spacing", d)?;
            // Poisson-disk samples at least `spacing` apart cover at most one hexagon of area
            // (√3/2)·spacing² each: an upper bound on the count.
            let bound = translucent_area / (0.866 * f64::from(spacing).powi(2));
            if bound > MAX_SAMPLES as f64 {
                return Err(c.range(
                    "render.spacing",
                    d,
                    format!(
                        "spacing {spacing} over {translucent_area:.4} square units of translucent \
                         surface allows up to {bound:.3e} samples, more than {MAX_SAMPLES} (check \
                         the scene's units and mm_per_unit)"
                    ),
                ));
            }
            s.samples = SampleDensity::Spacing(spacing).into();
        }
        (None, None) => {}
    }
    if let Some(m) = &r.max_samples {
        if s.samples != SampleRequest::Auto {
            let given = if r.samples.is_some() {
                "samples"
            } else {
                "spacing"
            };
            return Err(c.at(
                SceneErrorKind::Conflict,
                "render.max_samples",
                m,
                format!(
                    "caps the automatic count only (samples = \"auto\"), but the scene gives \
                     `{given}`: remove one of the two"
                ),
            ));
        }
        s.max_samples = Some(c.int("render.max_samples", m, 1, MAX_SAMPLES)? as u32);
    }
    if let Some(v) = &r.epsilon {
        s.epsilon = c.non_negative("render.epsilon", v)?;
    }
    if let Some(v) = &r.smoothing {
        s.smoothing = c.non_negative("render.smoothing", v)?;
    }
    if let Some(v) = &r.ell_min {
        s.ell_min = Some(c.positive("render.ell_min", v)?);
    }
    if let Some(v) = &r.cull_tolerance {
        s.cull_tolerance = c.num_where(
            "render.cull_tolerance",
            v,
            |x| (0.0..1.0).contains(&x),
            "must be in [0, 1)",
        )?;
    }
    if let Some(v) = &r.interpolation {
        s.interpolation = c.int(
            "render.interpolation",
            v,
            1,
            i64::from(MAX_INTERPOLATION_STEP),
        )? as u32;
    }
    if let Some(v) = &r.interpolation_tolerance {
        s.interpolation_tolerance = c.non_negative("render.interpolation_tolerance", v)?;
    }
    if let Some(v) = &r.aa {
        s.aa = c.int("render.aa", v, 1, 8)? as u32;
    }
    if let Some(v) = &r.exposure {
        s.exposure = c.num_where(
            "render.exposure",
            v,
            |x| (-64.0..=64.0).contains(&x),
            "must be in [-64, 64] stops",
        )?;
    }
    if let Some(v) = &r.threads {
        s.threads = Some(c.int("render.threads", v, 1, MAX_THREADS)? as usize);
    }
    if let Some(v) = &r.seed {
        s.seed = c.int("render.seed", v, 0, i64::MAX)? as u64;
    }
    Ok(s)
}

/// `render.samples`: `"auto"` or a count in `1..=MAX_SAMPLES`.
fn samples(c: &Check, n: &Spanned<RawSamples>) -> Checked<SampleRequest> {
    match n.get_ref() {
        RawSamples::Word(w) if w == AUTO => Ok(SampleRequest::Auto),
        RawSamples::Word(w) => Err(c.range(
            "render.samples",
            n,
            format!("`{w}` is not a sample count (expected an integer in 1..={MAX_SAMPLES} or \"{AUTO}\")"),
        )),
        RawSamples::Count(k) if (1..=MAX_SAMPLES).contains(k) => {
            Ok(SampleDensity::Count(*k as u32).into())
        }
        RawSamples::Count(k) => Err(c.range(
            "render.samples",
            n,
            format!("must be in 1..={MAX_SAMPLES} or \"{AUTO}\" (got {k})"),
        )),
    }
}

/// Builds the output settings. Without `png` and `exr`, the PNG goes to `<stem>.png`.
pub(crate) fn build_output(
    c: &Check,
    raw: Option<&Spanned<RawOutput>>,
    stem: &str,
) -> Checked<OutputSettings> {
    let mut out = OutputSettings::default();
    if let Some(raw) = raw {
        let r = raw.get_ref();
        let path = |k: &str, v: &Spanned<String>| -> Checked<PathBuf> {
            if v.get_ref().trim().is_empty() {
                Err(c.range(k, v, "must be a file name, not empty"))
            } else {
                Ok(PathBuf::from(v.get_ref()))
            }
        };
        out.png = r.png.as_ref().map(|v| path("output.png", v)).transpose()?;
        out.exr = r.exr.as_ref().map(|v| path("output.exr", v)).transpose()?;
        if let Some(layers) = &r.layers {
            if out.exr.is_none() {
                return Err(c.at(
                    SceneErrorKind::Conflict,
                    "output.layers",
                    layers,
                    "layers are written to the EXR file: set `exr` too",
                ));
            }
            for layer in layers.get_ref() {
                let flag = match layer.get_ref().as_str() {
                    "exitance" => &mut out.layers.exitance,
                    "local" => &mut out.layers.local,
                    "global" => &mut out.layers.global,
                    "irradiance" => &mut out.layers.irradiance,
                    "depth" => &mut out.layers.depth,
                    other => {
                        return Err(c.at(
                            SceneErrorKind::UnknownName,
                            "output.layers",
                            layer,
                            format!(
                                "unknown layer `{other}` (expected any of: {})",
                                LAYERS.join(", ")
                            ),
                        ));
                    }
                };
                *flag = true;
            }
        }
    }
    if out.png.is_none() && out.exr.is_none() {
        out.png = Some(PathBuf::from(format!("{stem}.png")));
        out.layers = ExrLayers::default();
    }
    Ok(out)
}
