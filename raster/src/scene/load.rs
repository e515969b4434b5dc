//! The scene loader: TOML text → validated [`Scene`].
//!
//! Three stages, each with located errors: TOML syntax (the `toml` parser); structure (serde,
//! with unknown keys and wrong types rejected); meaning (every number checked, every name
//! resolved, every referenced file loaded and checked). Nothing here panics on any input.

use std::collections::HashMap;
use std::path::Path;

use serde::Deserialize;

use super::check::Check;
use super::error::{SceneError, SceneErrorKind, Source};
use super::format::RawScene;
use super::lights::build_light;
use super::materials::{TextureCache, build_material};
use super::mesh::mesh_area;
use super::model::{Material, Scene};
use super::object_materials::{MaterialRef, MaterialTable};
use super::objects::build_object;
use super::origin::{SceneOrigin, read_limited};
use super::settings::{build_camera, build_output, build_render};

/// Largest scene file accepted (16 MiB; scenes are hand-written).
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Reads a scene file from disk. Relative paths inside it (meshes, textures) are resolved
/// against the file's directory.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let origin = SceneOrigin::File(path.to_path_buf());
    let file_error = |kind, message: String| SceneError {
        kind,
        file: origin.display_name(),
        position: None,
        key: None,
        message,
        source: None,
    };
    let bytes = read_limited(path, MAX_SCENE_BYTES).map_err(|why| {
        file_error(SceneErrorKind::Io, format!("cannot read scene: {why}")).with_source(why)
    })?;
    let text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let valid = e.utf8_error().valid_up_to();
            let bytes = e.into_bytes();
            let prefix = String::from_utf8_lossy(&bytes[..valid]);
            let src = Source {
                file: &origin.display_name(),
                text: &prefix,
            };
            let mut err = file_error(SceneErrorKind::Syntax, "the file is not UTF-8 text".into());
            err.position = Some(src.line_column(valid));
            return Err(err);
        }
    };
    parse_scene(&text, &origin)
}

/// Parses scene text. `origin` says where relative paths lead (and names the file in errors).
pub fn parse_scene(text: &str, origin: &SceneOrigin) -> Result<Scene, SceneError> {
    let name = origin.display_name();
    let src = Source { file: &name, text };
    let root = toml::de::DeTable::parse(text).map_err(|e| src.syntax_error(&e))?;
    super::tables::check_tables(root.get_ref(), &src)?;
    let raw = RawScene::deserialize(toml::de::Deserializer::from(root)).map_err(|mut e| {
        // The document was parsed above: give the error its text back, as a parse from the
        // text would have.
        e.set_input(Some(text));
        src.data_error(&e, &["object", "light"])
    })?;
    build(&raw, Check { src }, origin)
}

/// Resolves and checks everything.
fn build(raw: &RawScene, c: Check, origin: &SceneOrigin) -> Result<Scene, SceneError> {
    let camera = match &raw.camera {
        Some(cam) => build_camera(&c, cam)?,
        None => {
            return Err(c.src.file_error(
                SceneErrorKind::MissingKey,
                Some("camera".into()),
                "missing required table [camera]",
            ));
        }
    };

    // Materials, in name order (the file's tables are a map).
    let mut textures = TextureCache::new(origin);
    let mut materials = Vec::with_capacity(raw.material.len());
    let mut refs = Vec::with_capacity(raw.material.len());
    for (name, table) in &raw.material {
        let built = build_material(&c, name, table, &mut textures)?;
        materials.push(built.material);
        refs.push((built.texture_key, built.kd_from_mtl));
    }
    let by_name: HashMap<&str, MaterialRef> = raw
        .material
        .keys()
        .enumerate()
        .map(|(index, name)| {
            (
                name.as_str(),
                MaterialRef {
                    index,
                    texture_key: refs[index].0,
                    kd_from_mtl: refs[index].1,
                },
            )
        })
        .collect();

    if raw.object.is_empty() {
        return Err(c.src.file_error(
            SceneErrorKind::MissingKey,
            Some("object".into()),
            "the scene has no [[object]]",
        ));
    }
    let mut table = MaterialTable::new(by_name, materials, textures);
    let mut objects = Vec::with_capacity(raw.object.len());
    for (i, o) in raw.object.iter().enumerate() {
        objects.extend(build_object(&c, i, o, origin, &mut table)?);
    }
    let MaterialTable {
        materials,
        warnings,
        mut textures,
        ..
    } = table;

    if raw.light.is_empty() {
        return Err(c.src.file_error(
            SceneErrorKind::MissingKey,
            Some("light".into()),
            "the scene has no [[light]]",
        ));
    }
    let lights = raw
        .light
        .iter()
        .enumerate()
        .map(|(i, l)| build_light(&c, i, l, &mut textures))
        .collect::<Result<Vec<_>, _>>()?;

    let translucent_area: f64 = objects
        .iter()
        .filter(|o| matches!(materials[o.material], Material::Translucent(_)))
        .map(|o| mesh_area(&o.mesh))
        .sum();
    let render = build_render(&c, raw.render.as_ref(), translucent_area)?;
    let output = build_output(&c, raw.output.as_ref(), &origin.stem())?;

    Ok(Scene {
        camera,
        objects,
        materials,
        lights,
        render,
        output,
        source: origin.source_path(),
        warnings,
    })
}
