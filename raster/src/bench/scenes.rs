//! The benchmark's scenes, compiled into the binary so that `lucent bench` runs anywhere.
//!
//! | name | what | shadow edge |
//! |---|---|---|
//! | `default` | the built-in default scene: marble bunny, plate, key and fill light | across the bunny |
//! | `sphere` | `scenes/sphere-shadow.toml`: a marble sphere (radius 1 cm at (0, 0, 1), plate edge in x = 0) | the great circle x = 0 |
//! | `textured` | `scenes/textured-mfp.toml`: a slab whose ℓ_u spans two decades (texture) | the line y = 0, across the ramp |

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
}

impl BenchScene {
    /// Every scene, in report order.
    pub const ALL: [BenchScene; 3] = [
        BenchScene::Default,
        BenchScene::Sphere,
        BenchScene::Textured,
    ];

    /// The name used in file names, tables and `--scenes`.
    pub fn name(self) -> &'static str {
        match self {
            BenchScene::Default => "default",
            BenchScene::Sphere => "sphere",
            BenchScene::Textured => "textured",
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
}
