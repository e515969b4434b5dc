//! What texture-mapped K_d and radius cost and how exact their local term is, on the textured
//! slab (the bench's `textured` scene with its material's parameters replaced).
//!
//! Three versions of the slab's material, rendered from one baked sample set in interleaved
//! rounds (the order rotates, as in the overhead measurement):
//!
//! ```text
//!   constant   kd = K_d             radius = ℓ            one K table, one profile
//!   uniform    kd = texture of K_d  radius = texture of ℓ the textured path (texture lookups,
//!                                                         K_d inverted per point, K from the
//!                                                         tables over K_d) with the same values
//!   varying    kd = kd-checker.jpg  radius = mfp-ramp.png the textured path with values that vary
//! ```
//!
//! *uniform / constant − 1* is the textured path's cost per lookup with the traversal's work
//! held equal (same profiles, same samples); *varying* adds what the values themselves change
//! (longer ℓ opens more nodes), reported with its profile evaluations for that reason. The
//! varying slab is also rendered with K by quadrature at every shading point: the exitance of the
//! table render against it is the interpolation error of K over the textures' range, on
//! translucent pixels.

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;

use super::BenchError;
use super::overhead::Spread;
use super::runner::{MethodSetting, configure};
use crate::render::{ObjectSamples, Render, RenderOptions, bake, render};
use crate::scene::{
    ColorParam, Distance, Material, Medium, ScalarParam, Scene, TranslucentMaterial,
};
use crate::texture::{Texture, TextureEncoding};

/// The checker albedo of `scenes/skin-textured.toml`.
const KD_CHECKER_JPG: &[u8] = include_bytes!("../../../scenes/textures/kd-checker.jpg");

/// K_d of the constant and uniform versions (the textured scene's own).
const KD: Vec3 = Vec3::new(0.85, 0.8, 0.75);

/// The three versions, in the order of [`TextureCost::lookup_us`].
pub const VERSIONS: [&str; 3] = ["constant", "uniform texture", "varying texture"];

/// The measurement on the textured slab.
#[derive(Clone, Debug)]
pub struct TextureCost {
    /// Samples placed.
    pub samples: usize,
    /// Rounds rendered.
    pub rounds: usize,
    /// Median CPU per lookup (translucent shading points, µs) of each of [`VERSIONS`].
    pub lookup_us: [f64; 3],
    /// Profile evaluations per lookup of each version.
    pub evaluations: [f64; 3],
    /// The uniform texture against the constant, CPU per lookup, over rounds.
    pub uniform_vs_constant: Spread,
    /// The varying textures against the constant, CPU per lookup, over rounds.
    pub varying_vs_constant: Spread,
    /// The varying slab, K from the tables against K by quadrature: mean relative exitance
    /// difference over translucent pixels.
    pub table_mean_relative: f64,
    /// The same, the largest relative difference of any translucent pixel and channel.
    pub table_max_relative: f64,
}

/// Measures the slab at `samples` samples (seed `seed`) with `method` at ε `epsilon`, over
/// `rounds` interleaved rounds, on one thread.
pub fn measure(
    base: &Scene,
    setting: MethodSetting,
    samples: u32,
    seed: u64,
    rounds: usize,
) -> Result<TextureCost, BenchError> {
    if rounds == 0 {
        return Err(BenchError::new("the texture cost needs at least one round"));
    }
    let mut single = configure(base, setting, samples, seed);
    single.render.threads = Some(1);
    let versions = versions(&single)?;
    let baked = bake(&versions[0], false)?;
    let mut lookup: [Vec<f64>; 3] = Default::default();
    let mut evaluations = [0.0; 3];
    let mut placed = 0;
    for round in 0..rounds {
        for k in 0..versions.len() {
            let v = (round + k) % versions.len();
            let r = render_version(&versions[v], &baked, false)?;
            if r.stats.queries == 0 {
                return Err(BenchError::new(
                    "the textured slab shows no translucent pixel",
                ));
            }
            let time = r.stats.translucent_time.unwrap_or_default().as_secs_f64();
            lookup[v].push(time / r.stats.queries as f64 * 1e6);
            let traversal = r.stats.traversal.unwrap_or_default();
            evaluations[v] =
                traversal.profile_evaluations() as f64 / traversal.queries.max(1) as f64;
            placed = r.stats.samples;
        }
    }
    let ratio = |this: usize| {
        Spread::of(
            (0..rounds)
                .map(|r| lookup[this][r] / lookup[0][r] - 1.0)
                .collect(),
        )
    };
    let table = render_version(&versions[2], &baked, false)?;
    let exact = render_version(&versions[2], &baked, true)?;
    let (table_mean_relative, table_max_relative) = relative_difference(&table, &exact);
    Ok(TextureCost {
        samples: placed,
        rounds,
        uniform_vs_constant: ratio(1),
        varying_vs_constant: ratio(2),
        lookup_us: lookup.map(|us| Spread::of(us).median),
        evaluations,
        table_mean_relative,
        table_max_relative,
    })
}

fn render_version(
    scene: &Scene,
    baked: &[ObjectSamples],
    exact_local_integral: bool,
) -> Result<Render, BenchError> {
    let options = RenderOptions {
        collect_stats: true,
        exact_local_integral,
        baked: Some(baked),
        ..RenderOptions::default()
    };
    Ok(render(scene, &options)?)
}

/// The constant, uniform and varying versions of `scene` (the textured bench scene): its one
/// translucent material's K_d and mean free path replaced.
fn versions(scene: &Scene) -> Result<[Scene; 3], BenchError> {
    let index = scene
        .materials
        .iter()
        .position(|m| matches!(m, Material::Translucent(_)))
        .ok_or_else(|| BenchError::new("the textured scene has no translucent material"))?;
    let Material::Translucent(material) = &scene.materials[index] else {
        unreachable!("found above");
    };
    let Medium::Reflectance {
        distance: Distance::MeanFreePath(ramp @ ScalarParam::Texture { min, max, .. }),
        eta,
        ..
    } = &material.medium
    else {
        return Err(BenchError::new(
            "the textured scene's material is not K_d with a mean free path texture",
        ));
    };
    // t = ½ on the ramp's logarithmic scale: ℓ = √(min·max), the ramp's geometric middle.
    let ell = (min * max).sqrt();
    let uniform_t = texture("uniform-radius.png", Vec3::splat(0.5));
    let with = |kd: ColorParam, distance: ScalarParam| {
        let mut s = scene.clone();
        s.materials[index] = Material::Translucent(TranslucentMaterial {
            medium: Medium::Reflectance {
                kd,
                distance: Distance::MeanFreePath(distance),
                eta: *eta,
            },
            ..material.clone()
        });
        s
    };
    let checker = Texture::from_bytes(
        KD_CHECKER_JPG,
        Path::new("textures/kd-checker.jpg"),
        TextureEncoding::Srgb,
    )
    .map_err(|e| BenchError::new(e.to_string()))?;
    Ok([
        with(
            ColorParam::Constant(KD),
            ScalarParam::Constant(Vec3::splat(ell)),
        ),
        with(
            ColorParam::Texture(texture("uniform-kd.png", KD)),
            ScalarParam::Texture {
                texture: uniform_t,
                min: *min,
                max: *max,
            },
        ),
        with(ColorParam::Texture(Arc::new(checker)), ramp.clone()),
    ])
}

/// A 2 × 2 texture of one linear value.
fn texture(name: &str, value: Vec3) -> Arc<Texture> {
    Arc::new(Texture::from_linear(name, 2, 2, vec![value; 4]))
}

/// Mean and largest relative difference of `a`'s exitance against `b`'s over the pixels where
/// `b` is translucent, per channel.
fn relative_difference(a: &Render, b: &Render) -> (f64, f64) {
    let (mut sum, mut n, mut max) = (0.0f64, 0usize, 0.0f64);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let want = f64::from(q.exitance[c]);
            if want > 0.0 {
                let rel = (f64::from(p.exitance[c]) - want).abs() / want;
                sum += rel;
                n += 1;
                max = max.max(rel);
            }
        }
    }
    (if n == 0 { 0.0 } else { sum / n as f64 }, max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::BenchScene;
    use lucent_core::Method;

    /// The textured path with the constant's values renders the constant's image (up to the
    /// tables' interpolation in K_d) and the measurement is complete.
    #[test]
    fn the_uniform_texture_renders_the_constant_and_the_table_tracks_quadrature() {
        let base = BenchScene::Textured.load(32).unwrap();
        let setting = MethodSetting {
            method: Method::EdgeRefined,
            epsilon: 0.5,
        };
        let mut single = configure(&base, setting, 1500, 3);
        single.render.threads = Some(1);
        let v = versions(&single).unwrap();
        let baked = bake(&v[0], false).unwrap();
        let constant = render_version(&v[0], &baked, false).unwrap();
        let uniform = render_version(&v[1], &baked, false).unwrap();
        let varying = render_version(&v[2], &baked, false).unwrap();
        let (mean, max) = relative_difference(&uniform, &constant);
        assert!(mean < 1e-3 && max < 5e-3, "{mean} {max}");
        let (mean, _) = relative_difference(&varying, &constant);
        assert!(mean > 0.05, "the varying textures change the image: {mean}");

        let cost = measure(&base, setting, 1500, 3, 2).unwrap();
        assert_eq!(cost.rounds, 2);
        assert!(cost.samples > 1000);
        assert!(cost.lookup_us.iter().all(|&t| t > 0.0), "{cost:?}");
        assert!(cost.evaluations.iter().all(|&e| e >= 1.0), "{cost:?}");
        for s in [cost.uniform_vs_constant, cost.varying_vs_constant] {
            assert!(
                s.min <= s.median && s.median <= s.max && s.min > -1.0,
                "{s:?}"
            );
        }
        assert!(
            cost.table_mean_relative < 1e-3 && cost.table_max_relative < 5e-3,
            "{cost:?}"
        );
        assert!(measure(&base, setting, 1500, 3, 0).is_err());
    }
}
