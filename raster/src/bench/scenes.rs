//! The benchmark's scenes, compiled into the binary so that `lucent bench` runs anywhere.
//!
//! | name | what | shadow edge |
//! |---|---|---|
//! | `default` | the built-in default scene: marble bunny, plate, key and fill light | across the bunny |
//! | `sphere` | `scenes/sphere-shadow.toml`: a marble sphere (radius 1 cm at (0, 0, 1), plate edge in x = 0) | the great circle x = 0 |
//! | `textured` | `scenes/textured-mfp.toml`: a slab whose ℓ_u spans two decades (texture) | the line y = 0, across the ramp |
//! | `sphere-burley` | `sphere` with the marble under normalised diffusion (`profile = "burley"`) | as `sphere` |

use std::borrow::Cow;

use crate::scene::{Scene, SceneError, SceneOrigin, default_scene, parse_scene};

const SPHERE_TOML: &str = include_str!("../../../scenes/sphere-shadow.toml");
const TEXTURED_TOML: &str = include_str!("../../../scenes/textured-mfp.toml");
const MFP_RAMP_PNG: &[u8] = include_bytes!("../../../scenes/textures/mfp-ramp.png");

/// One of the benchmark's scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BenchScene {
    /// The built-in default scene (bunny with a shadow edge).
    Default,
    /// The marble sphere half in a plate's shadow.
    Sphere,
    /// The slab with texture-mapped mean free path.
    Textured,
    /// The sphere with its marble under Christensen & Burley's normalised diffusion.
    SphereBurley,
}

impl BenchScene {
    /// Every scene, in report order.
    pub const ALL: [BenchScene; 4] = [
        BenchScene::Default,
        BenchScene::Sphere,
        BenchScene::Textured,
        BenchScene::SphereBurley,
    ];

    /// The name used in file names, tables and `--scenes`.
    pub fn name(self) -> &'static str {
        match self {
            BenchScene::Default => "default",
            BenchScene::Sphere => "sphere",
            BenchScene::Textured => "textured",
            BenchScene::SphereBurley => "sphere-burley",
        }
    }

    /// The scene of a name (see [`BenchScene::name`]).
    pub fn from_name(name: &str) -> Option<BenchScene> {
        BenchScene::ALL.into_iter().find(|s| s.name() == name)
    }

    /// Loads the scene at `resolution²` pixels, with its outputs and layers cleared (the
    /// benchmark writes its own files).
    pub fn load(self, resolution: u32) -> Result<Scene, SceneError> {
        let mut scene = match self {
            BenchScene::Default => default_scene(),
            BenchScene::Sphere => parse_scene(
                SPHERE_TOML,
                &SceneOrigin::Embedded {
                    name: "<built-in>/sphere-shadow.toml".to_string(),
                    files: Vec::new(),
                },
            )?,
            BenchScene::SphereBurley => parse_scene(
                &with_burley_marble(SPHERE_TOML),
                &SceneOrigin::Embedded {
                    name: "<built-in>/sphere-shadow.toml, profile = \"burley\"".to_string(),
                    files: Vec::new(),
                },
            )?,
            BenchScene::Textured => parse_scene(
                TEXTURED_TOML,
                &SceneOrigin::Embedded {
                    name: "<built-in>/textured-mfp.toml".to_string(),
                    files: vec![(
                        "textures/mfp-ramp.png".to_string(),
                        Cow::Borrowed(MFP_RAMP_PNG),
                    )],
                },
            )?,
        };
        scene.camera.width = resolution;
        scene.camera.height = resolution;
        scene.output = Default::default();
        Ok(scene)
    }
}

/// The sphere scene's TOML with its marble under normalised diffusion (the searchlight fit):
/// the same coefficients, so Burley's A is the better dipole's total reflectance of them and
/// ℓ = 1/σ_t′ (`docs/physics.md` §18).
fn with_burley_marble(toml: &str) -> String {
    let table = "[material.marble]\n";
    let at = toml
        .find(table)
        .expect("the sphere scene has [material.marble]")
        + table.len();
    format!("{}profile = \"burley\"\n{}", &toml[..at], &toml[at..])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Material;

    #[test]
    fn every_scene_loads_with_a_translucent_object_and_the_asked_size() {
        for s in BenchScene::ALL {
            let scene = s.load(64).unwrap_or_else(|e| panic!("{}: {e}", s.name()));
            assert_eq!((scene.camera.width, scene.camera.height), (64, 64));
            assert!(scene.output.png.is_none() && scene.output.exr.is_none());
            assert!(
                scene
                    .objects
                    .iter()
                    .any(|o| matches!(scene.materials[o.material], Material::Translucent(_))),
                "{}",
                s.name()
            );
            assert_eq!(BenchScene::from_name(s.name()), Some(s));
        }
        assert_eq!(BenchScene::from_name("teapot"), None);
    }

    #[test]
    fn the_burley_sphere_is_the_sphere_under_burley() {
        use lucent_core::{BurleyFit, ProfileModel};
        let profile_of = |s: BenchScene| {
            let scene = s.load(16).unwrap();
            scene
                .materials
                .iter()
                .find_map(|m| match m {
                    Material::Translucent(t) => Some(t.clone()),
                    _ => None,
                })
                .unwrap()
        };
        let plain = profile_of(BenchScene::Sphere);
        let burley = profile_of(BenchScene::SphereBurley);
        assert_eq!(plain.model, ProfileModel::Dipole);
        assert_eq!(burley.model, ProfileModel::Burley(BurleyFit::Searchlight));
    }
}
