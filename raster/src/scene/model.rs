//! The in-memory scene: what the TOML format (see `docs/scene-format.md`) loads into and what the
//! renderer consumes. Everything here is already resolved: meshes are loaded and transformed to
//! world space, textures are decoded, every number has been validated.

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use lucent_core::{Method, ProfileModel};

use crate::camera::Camera;
use crate::lights::EnvironmentMap;
use crate::texture::Texture;

/// A complete, validated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// Every object, each a world-space triangle mesh with one material (an OBJ file whose
    /// `usemtl` groups map to several materials becomes one object per material).
    pub objects: Vec<Object>,
    /// Materials, referenced by [`Object::material`].
    pub materials: Vec<Material>,
    /// Light sources.
    pub lights: Vec<Light>,
    /// How to render.
    pub render: RenderSettings,
    /// Where to write results.
    pub output: OutputSettings,
    /// The file the scene came from (`None` for the built-in default scene).
    pub source: Option<PathBuf>,
    /// What loading repaired or doubted without failing (a mesh flipped outside out, an OBJ
    /// material group the scene does not map, ...), each located like a
    /// [`SceneError`](super::SceneError). The command line prints them on stderr.
    pub warnings: Vec<String>,
}

/// One mesh with one material.
#[derive(Clone, Debug)]
pub struct Object {
    /// The name given in the scene file (or derived from the mesh file name).
    pub name: String,
    /// World-space geometry.
    pub mesh: Mesh,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// An indexed triangle mesh in world space.
///
/// Invariants (checked by the loader): every index is in range, every position, normal and UV
/// is finite, every coordinate is within ±[`MAX_COORDINATE`](super::mesh::MAX_COORDINATE), normals have unit length, `uvs` (when present) has one entry per vertex, and the
/// total area is positive.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals (computed area-weighted from the faces when the file has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per vertex, if the mesh has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Counter-clockwise triangles (seen from outside), as vertex indices: in the file's order,
    /// except that the loader puts a large mesh listed in no particular order in Z-order
    /// (`docs/scene-format.md`, "Mesh files").
    pub triangles: Vec<[u32; 3]>,
}

/// A surface material.
#[derive(Clone, Debug)]
pub enum Material {
    /// Subsurface scattering through a diffusion profile (shaded by `lucent-core`).
    Translucent(TranslucentMaterial),
    /// An opaque Lambertian reflector.
    Lambert {
        /// Material name from the scene file.
        name: String,
        /// Diffuse reflectance (linear RGB, each in [0, 1]).
        albedo: Vec3,
    },
}

/// A translucent material: how its scattering coefficients are given, plus an optional
/// specular highlight.
#[derive(Clone, Debug)]
pub struct TranslucentMaterial {
    /// Material name from the scene file.
    pub name: String,
    /// The scattering parameters.
    pub medium: Medium,
    /// The diffusion model every profile of the material is built with (`profile = …`; the
    /// classical dipole by default).
    pub model: ProfileModel,
    /// Fresnel-weighted specular highlight, if enabled.
    pub specular: Option<Specular>,
}

/// The three ways a scene can specify a scattering medium.
#[derive(Clone, Debug)]
pub enum Medium {
    /// A measured material of Jensen et al. 2001 (`lucent presets` lists them).
    Preset {
        /// Preset name, matched case-insensitively (e.g. "marble", "skin1").
        name: String,
        /// Millimetres per scene unit: the preset's per-mm coefficients are multiplied by it
        /// (pbrt's `scale`; 10 for a scene modelled in centimetres).
        mm_per_unit: f32,
    },
    /// Explicit coefficients, per RGB channel, in inverse scene units.
    Coefficients {
        /// Absorption σ_a.
        sigma_a: Vec3,
        /// Reduced scattering σ_s′.
        sigma_s_prime: Vec3,
        /// Relative index of refraction (inside / outside), ≥ 1.
        eta: f32,
    },
    /// Artist parameters: diffuse reflectance K_d and a distance (JB02 reparameterisation).
    Reflectance {
        /// Total diffuse reflectance K_d per channel, in (0, 1).
        kd: ColorParam,
        /// The distance, which says which mean free path it is.
        distance: Distance,
        /// Relative index of refraction (inside / outside), ≥ 1.
        eta: f32,
    },
}

/// Which mean free path a distance parameter means (both are common; see the README).
#[derive(Clone, Debug)]
pub enum Distance {
    /// ℓ_u = 1/σ_t′, the mean free path (N10, pbrt-v3); the one N10 varies by texture. Also
    /// what `radius × radius_scale` (Standard Surface's `subsurface_radius`,
    /// `subsurface_scale`) gives, already multiplied.
    MeanFreePath(ScalarParam),
    /// ℓ_d = 1/σ_tr, the diffuse mean free path (JB02, pbrt-v2's `meanfreepath`).
    DiffuseMeanFreePath(ScalarParam),
}

impl Distance {
    /// The value, whichever mean free path it is.
    pub fn param(&self) -> &ScalarParam {
        match self {
            Distance::MeanFreePath(p) | Distance::DiffuseMeanFreePath(p) => p,
        }
    }
}

/// An RGB parameter: a constant or a texture over the mesh UVs.
#[derive(Clone, Debug)]
pub enum ColorParam {
    /// The same value everywhere.
    Constant(Vec3),
    /// Looked up at the shading point's UV (textures store linear values; sRGB PNGs are
    /// decoded to linear on load).
    Texture(Arc<Texture>),
}

/// A positive per-channel distance parameter: a constant, or a texture mapped to a range.
#[derive(Clone, Debug)]
pub enum ScalarParam {
    /// The same value everywhere, per RGB channel (scene units).
    Constant(Vec3),
    /// A texture whose value t ∈ [0, 1] (per channel) maps logarithmically to
    /// `min · (max / min)^t` scene units, so that an 8-bit texture spans decades smoothly.
    Texture {
        /// The texture (linear values, not sRGB-decoded).
        texture: Arc<Texture>,
        /// Distance at t = 0.
        min: f32,
        /// Distance at t = 1.
        max: f32,
    },
}

/// A Fresnel-weighted Blinn–Phong highlight on a translucent surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Specular {
    /// Blinn–Phong exponent (larger = sharper).
    pub exponent: f32,
    /// Multiplier on the highlight (1 = physically normalised lobe).
    pub strength: f32,
}

/// A light source. Intensities are radiant intensities (W/sr) for the local lights and an
/// irradiance (W/m², perpendicular to the direction) for the directional light; `color`
/// multiplies either.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// A point light: E = I cos θ / d².
    Point {
        /// Position.
        position: Vec3,
        /// Linear RGB colour.
        color: Vec3,
        /// Radiant intensity.
        intensity: f32,
    },
    /// A spot light: a point light with a smooth falloff between the inner and outer cone.
    Spot {
        /// Position.
        position: Vec3,
        /// Unit direction the spot points to.
        direction: Vec3,
        /// Half-angle (degrees) inside which the spot is at full intensity.
        inner_angle_degrees: f32,
        /// Half-angle (degrees) outside which the spot is dark.
        outer_angle_degrees: f32,
        /// Linear RGB colour.
        color: Vec3,
        /// Radiant intensity on the axis.
        intensity: f32,
    },
    /// A distant light.
    Directional {
        /// Unit direction in which the light travels (from the light towards the scene).
        direction: Vec3,
        /// Linear RGB colour.
        color: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: f32,
    },
    /// A spherical area light: soft shadows from `samples` stratified points on the sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius (> 0).
        radius: f32,
        /// Linear RGB colour.
        color: Vec3,
        /// Total radiant intensity (as if it were a point light at the centre).
        intensity: f32,
        /// Shadow samples per shading point (≥ 1).
        samples: u32,
    },
    /// A one-sided rectangular Lambertian emitter: soft shadows from `samples` stratified
    /// points on the rectangle (`docs/physics.md` §5.1).
    Rect {
        /// Centre.
        center: Vec3,
        /// Unit normal of the emitting face (the light shines where `(p − center)·normal > 0`).
        normal: Vec3,
        /// Unit vector along the width, `up_axis × normal` (to the right, seen from the lit side).
        right: Vec3,
        /// Unit vector along the height: the scene's `up` made perpendicular to `normal`.
        up_axis: Vec3,
        /// Width and height (> 0).
        size: Vec2,
        /// Linear RGB colour.
        color: Vec3,
        /// Radiant intensity along the normal, I = L · width · height.
        intensity: f32,
        /// Shadow samples per shading point (≥ 1).
        samples: u32,
    },
    /// Light from every direction at infinity: a constant radiance, or a lat-long map
    /// (`docs/physics.md` §5.2).
    Environment {
        /// Linear RGB colour: the radiance of a constant environment, a tint on a map.
        color: Vec3,
        /// Radiance scale.
        intensity: f32,
        /// The lat-long map, if any (`None`: constant radiance `color × intensity`).
        map: Option<Arc<EnvironmentMap>>,
        /// Turn of the map about +z, degrees (counter-clockwise seen from above).
        rotation_degrees: f32,
        /// Shadow rays per shading point (≥ 1).
        samples: u32,
    },
}

/// A concrete irradiance sample density: what the sample placement is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleDensity {
    /// About this many samples over all translucent surfaces.
    Count(u32),
    /// Poisson-disk spacing in scene units.
    Spacing(f32),
}

/// How many irradiance samples a scene asks for (`render.samples`, `render.spacing`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum SampleRequest {
    /// `samples = "auto"` (the default): a spacing of a fixed fraction of the smallest diffuse
    /// mean free path ℓ_d of the translucent materials, capped by
    /// [`RenderSettings::max_samples`] (see `raster/src/render/density.rs`).
    #[default]
    Auto,
    /// An explicit count or spacing.
    Density(SampleDensity),
}

impl From<SampleDensity> for SampleRequest {
    fn from(d: SampleDensity) -> Self {
        SampleRequest::Density(d)
    }
}

/// The largest `render.interpolation` step: beyond 16 pixels a block spans more of the
/// surface than the corners' alikeness test can vouch for.
pub const MAX_INTERPOLATION_STEP: u32 = 16;

/// Render settings (the `[render]` table).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Subsurface method.
    pub method: Method,
    /// Irradiance sample density: automatic, or a count or spacing.
    pub samples: SampleRequest,
    /// The most samples `Auto` may place; `None` = sized to the machine's available memory
    /// (`render::density::default_max_samples`). Explicit counts and spacings ignore it.
    pub max_samples: Option<u32>,
    /// JB02 solid-angle threshold ε (aggregate a node when max(A, 2π tr C)/d² < ε).
    pub epsilon: f32,
    /// Smoothing radius factor k: α = k · √(mean sample area).
    pub smoothing: f32,
    /// Below this ℓ_u (scene units) the local-integral table uses the ℓ → 0 (Lambertian)
    /// limit; `None` = automatic (α / 1024).
    pub ell_min: Option<f32>,
    /// Relative tolerance below which whole subtrees are skipped (0 = never skip).
    pub cull_tolerance: f32,
    /// Exitance interpolation: query the cache only at every `interpolation`-th pixel in x and
    /// y, and interpolate between those where they are alike (1 = query every pixel; see
    /// `raster/src/render/interpolation.rs`).
    pub interpolation: u32,
    /// How alike the four corners of an interpolated block must be: per channel, the largest
    /// exitance at most `1 + interpolation_tolerance` times the smallest.
    pub interpolation_tolerance: f32,
    /// Anti-aliasing: `aa × aa` sub-samples per pixel for coverage.
    pub aa: u32,
    /// Exposure in stops applied before the PNG's sRGB encoding.
    pub exposure: f32,
    /// Worker threads (`None` = all cores). The image does not depend on it.
    pub threads: Option<usize>,
    /// Seed of the irradiance sample placement.
    pub seed: u64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            method: Method::EdgeRefined,
            samples: SampleRequest::Auto,
            max_samples: None,
            epsilon: 0.5,
            smoothing: 1.5,
            ell_min: None,
            cull_tolerance: 1e-4,
            interpolation: 1,
            interpolation_tolerance: 0.25,
            aa: 2,
            exposure: 0.0,
            threads: None,
            seed: 1,
        }
    }
}

/// Optional EXR layers besides the final RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ExrLayers {
    /// Translucent exitance M_o.
    pub exitance: bool,
    /// The local term of the split (LM07 / N10).
    pub local: bool,
    /// The global term of the split.
    pub global: bool,
    /// Irradiance at the shading point.
    pub irradiance: bool,
    /// Camera-space depth.
    pub depth: bool,
}

/// Where to write results (the `[output]` table). Relative paths are relative to the current
/// directory.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct OutputSettings {
    /// 8-bit sRGB PNG, if any.
    pub png: Option<PathBuf>,
    /// Linear float OpenEXR, if any.
    pub exr: Option<PathBuf>,
    /// Extra EXR layers.
    pub layers: ExrLayers,
}
