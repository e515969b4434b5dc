//! Scenes: the TOML format, OBJ meshes and built-in shapes, and the default scene.

mod model;

pub use model::*;
