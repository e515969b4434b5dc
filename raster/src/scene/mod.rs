//! Scenes: the TOML format, OBJ, PLY and glTF meshes and built-in shapes, and the default scene.
//!
//! The format is documented in `docs/scene-format.md`. Loading goes text → serde structures
//! mirroring the tables (`format.rs`; unknown keys and wrong types rejected) → value checks,
//! name resolution and file loading (`settings.rs`, `objects.rs`, `object_materials.rs`,
//! `materials.rs`, `lights.rs`) → [`Scene`] (the shared, validated data model of `model.rs`). Every failure is a
//! [`SceneError`] naming the file, line, column and key. Files are read through a
//! [`SceneOrigin`], so the built-in [`default_scene`] loads from memory.
//!
//! ```no_run
//! use std::path::Path;
//! let scene = lucent_raster::scene::load_scene(Path::new("scenes/sphere-shadow.toml"))?;
//! println!("{} objects", scene.objects.len());
//! # Ok::<(), lucent_raster::scene::SceneError>(())
//! ```

mod check;
mod default;
mod error;
mod format;
pub mod gltf;
mod lights;
mod load;
mod materials;
pub mod mesh;
pub mod mesh_file;
mod model;
pub mod mtl;
pub mod obj;
mod obj_reader;
mod object_materials;
mod objects;
mod origin;
pub mod ply;
pub mod sanity;
mod settings;
pub mod shapes;
mod spatial_order;
mod tables;
pub mod weld;

#[cfg(test)]
mod tests;

pub use default::{DEFAULT_SCENE_NAME, DEFAULT_SCENE_TOML, default_scene, default_scene_origin};
pub use error::{SceneError, SceneErrorKind};
pub use lights::LIGHT_TYPES;
pub use load::{MAX_SCENE_BYTES, load_scene, parse_scene};
pub use materials::preset_names;
pub use model::*;
pub use objects::SHAPES;
pub use origin::{MAX_FILE_BYTES, MAX_MESH_FILE_BYTES, SceneOrigin, files_read};
pub use settings::{
    AUTO, DEFAULT_RESOLUTION, LAYERS, MAX_PIXELS, MAX_SAMPLES, MAX_SIDE, MAX_THREADS,
};
