//! The scene file as written: serde structures mirroring the TOML tables one to one
//! (documented in `docs/scene-format.md`).
//!
//! Everything here is *unchecked*: numbers may be NaN, names may refer to nothing, keys may
//! conflict. Unknown keys and wrong types are already rejected by serde
//! (`deny_unknown_fields`). Values that are checked afterwards are wrapped in
//! [`toml::Spanned`] so that their errors can name a line; `build` turns this into a validated
//! [`super::Scene`].

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use toml::Spanned;

/// A number with its position in the file.
pub(crate) type Num = Spanned<f64>;
/// An integer with its position in the file.
pub(crate) type Int = Spanned<i64>;
/// A string with its position in the file.
pub(crate) type Str = Spanned<String>;
/// A 3-vector `[x, y, z]` with its position in the file (the length is checked when
/// building: serde's fixed-size arrays silently ignore extra elements).
pub(crate) type Vec3Raw = Spanned<Components>;

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawScene {
    pub camera: Option<Spanned<RawCamera>>,
    #[serde(default)]
    pub object: Vec<Spanned<RawObject>>,
    #[serde(default)]
    pub material: BTreeMap<String, Spanned<RawMaterial>>,
    #[serde(default)]
    pub light: Vec<Spanned<RawLight>>,
    pub render: Option<Spanned<RawRender>>,
    pub output: Option<Spanned<RawOutput>>,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCamera {
    pub position: Vec3Raw,
    pub target: Vec3Raw,
    pub up: Option<Vec3Raw>,
    pub fov: Num,
    pub width: Option<Int>,
    pub height: Option<Int>,
}

/// One `[[object]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawObject {
    pub name: Option<Str>,
    pub mesh: Option<Str>,
    pub obj: Option<Str>,
    pub shape: Option<Str>,
    pub size: Option<Spanned<Components>>,
    pub radius: Option<Num>,
    pub segments: Option<Int>,
    pub translate: Option<Vec3Raw>,
    pub rotate: Option<Vec3Raw>,
    pub scale: Option<Num>,
    pub material: Str,
    pub materials: Option<Spanned<BTreeMap<String, Str>>>,
    pub weld: Option<Spanned<bool>>,
    pub crease_angle: Option<Num>,
}

/// One `[material.NAME]`: the union of the keys of every material type; which keys apply is
/// checked when building.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMaterial {
    #[serde(rename = "type")]
    pub kind: Str,
    pub preset: Option<Str>,
    pub mm_per_unit: Option<Num>,
    pub sigma_a: Option<Spanned<Components>>,
    pub sigma_s_prime: Option<Spanned<Components>>,
    pub eta: Option<Num>,
    pub kd: Option<Spanned<RawParam>>,
    pub mean_free_path: Option<Spanned<RawParam>>,
    pub diffuse_mean_free_path: Option<Spanned<RawParam>>,
    pub radius: Option<Spanned<RawParam>>,
    pub radius_scale: Option<Num>,
    pub profile: Option<Str>,
    pub specular: Option<Spanned<RawSpecular>>,
    pub albedo: Option<Spanned<Components>>,
}

/// `specular = { exponent, strength }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSpecular {
    pub exponent: Num,
    pub strength: Option<Num>,
}

/// One `[[light]]`: the union of the keys of every light type.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawLight {
    #[serde(rename = "type")]
    pub kind: Str,
    pub position: Option<Vec3Raw>,
    pub direction: Option<Vec3Raw>,
    pub center: Option<Vec3Raw>,
    pub radius: Option<Num>,
    pub color: Option<Spanned<Components>>,
    pub intensity: Option<Num>,
    pub irradiance: Option<Num>,
    pub inner_angle: Option<Num>,
    pub outer_angle: Option<Num>,
    pub samples: Option<Int>,
    pub size: Option<Spanned<Components>>,
    pub up: Option<Vec3Raw>,
    pub map: Option<Str>,
    pub rotation: Option<Num>,
}

/// `[render]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRender {
    pub method: Option<Str>,
    pub samples: Option<Spanned<RawSamples>>,
    pub max_samples: Option<Int>,
    pub spacing: Option<Num>,
    pub epsilon: Option<Num>,
    pub smoothing: Option<Num>,
    pub ell_min: Option<Num>,
    pub cull_tolerance: Option<Num>,
    pub interpolation: Option<Int>,
    pub interpolation_tolerance: Option<Num>,
    pub aa: Option<Int>,
    pub exposure: Option<Num>,
    pub threads: Option<Int>,
    pub seed: Option<Int>,
}

/// `render.samples`: an integer, or a word (only `"auto"` is valid; checked when building, so
/// that a wrong word gets a located message naming the key).
#[derive(Debug)]
pub(crate) enum RawSamples {
    /// An integer (any sign; the range is checked when building).
    Count(i64),
    /// A string.
    Word(String),
}

impl<'de> Deserialize<'de> for RawSamples {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(SamplesVisitor)
    }
}

struct SamplesVisitor;

impl<'de> Visitor<'de> for SamplesVisitor {
    type Value = RawSamples;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a sample count (an integer) or \"auto\"")
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawSamples, E> {
        Ok(RawSamples::Count(v))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawSamples, E> {
        Ok(RawSamples::Count(i64::try_from(v).unwrap_or(i64::MAX)))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<RawSamples, E> {
        Ok(RawSamples::Word(v.to_string()))
    }
}

/// `[output]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawOutput {
    pub png: Option<Str>,
    pub exr: Option<Str>,
    pub layers: Option<Spanned<Vec<Str>>>,
}

/// A number or an array of numbers (`1.5` or `[1, 2, 3]`); the expected length is checked
/// when building, so that the error can say which key wanted how many.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Components {
    /// A single number (applies to every component).
    Scalar(f64),
    /// An explicit list.
    List(Vec<f64>),
}

impl<'de> Deserialize<'de> for Components {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ComponentsVisitor)
    }
}

struct ComponentsVisitor;

impl<'de> Visitor<'de> for ComponentsVisitor {
    type Value = Components;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a number or an array of numbers")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Components, E> {
        Ok(Components::Scalar(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Components, E> {
        Ok(Components::Scalar(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Components, E> {
        Ok(Components::Scalar(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Components, A::Error> {
        let mut values = Vec::new();
        while let Some(v) = seq.next_element::<f64>()? {
            values.push(v);
            if values.len() > 16 {
                return Err(de::Error::custom(
                    "array too long (expected at most 3 numbers)",
                ));
            }
        }
        Ok(Components::List(values))
    }
}

/// A reference to a texture: `{ texture = "file.png", min = …, max = … }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTextureRef {
    pub texture: Str,
    pub min: Option<Num>,
    pub max: Option<Num>,
}

/// A material parameter: a constant (number or `[r, g, b]`) or a texture table.
#[derive(Debug)]
pub(crate) enum RawParam {
    /// A constant.
    Constant(Components),
    /// A texture lookup.
    Texture(RawTextureRef),
    /// A word (only `kd = "mtl"` is valid; checked when building).
    Word(String),
}

impl<'de> Deserialize<'de> for RawParam {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ParamVisitor)
    }
}

struct ParamVisitor;

impl<'de> Visitor<'de> for ParamVisitor {
    type Value = RawParam;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a number, an array [r, g, b] or a table { texture = \"file.png\" }")
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<RawParam, E> {
        Ok(RawParam::Word(v.to_string()))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawParam, E> {
        Ok(RawParam::Constant(Components::Scalar(v)))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawParam, E> {
        Ok(RawParam::Constant(Components::Scalar(v as f64)))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawParam, E> {
        Ok(RawParam::Constant(Components::Scalar(v as f64)))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<RawParam, A::Error> {
        ComponentsVisitor.visit_seq(seq).map(RawParam::Constant)
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<RawParam, A::Error> {
        RawTextureRef::deserialize(de::value::MapAccessDeserializer::new(map))
            .map(RawParam::Texture)
    }
}
