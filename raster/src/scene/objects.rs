//! `[[object]]` tables → world-space [`Object`]s: a mesh file (OBJ, PLY, glTF) or a built-in shape, placed by
//! its transform, checked against the invariants of [`super::Mesh`].

use std::collections::HashMap;
use std::path::Path;

use toml::Spanned;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::RawObject;
use super::mesh::{Transform, validate_mesh};
use super::mesh_file::{MESH_EXTENSIONS, MeshFormat, parse_mesh_file};
use super::model::{Mesh, Object};
use super::origin::SceneOrigin;
use super::shapes::{self, DEFAULT_SEGMENTS, MAX_SEGMENTS, MIN_SEGMENTS};

/// Values accepted by `shape`.
pub const SHAPES: [&str; 4] = ["plane", "sphere", "box", "disk"];

/// What a material needs from the meshes that use it.
pub(crate) struct MaterialRef<'n> {
    /// Material index in the scene.
    pub index: usize,
    /// The key of a textured parameter, if the material has one (the mesh then needs UVs).
    pub texture_key: Option<&'n str>,
}

/// Builds object `index`. `materials` maps names to indices and texture needs.
pub(crate) fn build_object(
    c: &Check,
    index: usize,
    raw: &Spanned<RawObject>,
    origin: &SceneOrigin,
    materials: &HashMap<&str, MaterialRef>,
) -> Checked<Object> {
    let o = raw.get_ref();
    let key = |k: &str| format!("object[{index}].{k}");
    // The material first: a typo there is the cheapest thing to report.
    let material = materials
        .get(o.material.get_ref().as_str())
        .ok_or_else(|| {
            let mut names: Vec<_> = materials.keys().copied().collect();
            names.sort_unstable();
            c.at(
                SceneErrorKind::UnknownName,
                &key("material"),
                &o.material,
                if names.is_empty() {
                    format!(
                        "unknown material `{}` (the scene defines no [material.NAME] tables)",
                        o.material.get_ref()
                    )
                } else {
                    format!(
                        "unknown material `{}` (defined: {})",
                        o.material.get_ref(),
                        names.join(", ")
                    )
                },
            )
        })?;
    let transform = Transform {
        translate: match &o.translate {
            Some(v) => c.vec3(&key("translate"), v)?,
            None => glam::Vec3::ZERO,
        },
        rotate_degrees: match &o.rotate {
            Some(v) => c.vec3(&key("rotate"), v)?,
            None => glam::Vec3::ZERO,
        },
        scale: match &o.scale {
            Some(v) => c.positive(&key("scale"), v)?,
            None => 1.0,
        },
    };
    // `obj` is the older name of `mesh`.
    let file = match (&o.mesh, &o.obj) {
        (Some(_), Some(obj)) => {
            return Err(c.at(
                SceneErrorKind::Conflict,
                &key("obj"),
                obj,
                "cannot be combined with `mesh` (`obj` is an older name for `mesh`)",
            ));
        }
        (Some(file), None) => Some(("mesh", file)),
        (None, Some(file)) => Some(("obj", file)),
        (None, None) => None,
    };
    let (mut mesh, default_name, source) = match (file, &o.shape) {
        (Some((name, _)), Some(shape)) => {
            return Err(c.at(
                SceneErrorKind::Conflict,
                &key("shape"),
                shape,
                format!(
                    "cannot be combined with `{name}`: an object is a mesh file or a built-in \
                     shape"
                ),
            ));
        }
        (None, None) => {
            return Err(c.at(
                SceneErrorKind::MissingKey,
                &key("mesh"),
                raw,
                format!(
                    "an object needs `mesh = \"file.obj\"` (.obj, .ply, .gltf or .glb) or \
                     `shape = ...` ({})",
                    SHAPES.join(", ")
                ),
            ));
        }
        (Some((name, file)), None) => {
            let what = "a mesh file";
            c.forbid(&key("size"), &o.size, what)?;
            c.forbid(&key("radius"), &o.radius, what)?;
            c.forbid(&key("segments"), &o.segments, what)?;
            let mesh = load_mesh(c, &key(name), file, origin)?;
            let stem = Path::new(file.get_ref())
                .file_stem()
                .map_or_else(|| "mesh".to_string(), |s| s.to_string_lossy().into_owned());
            (mesh, stem, (key(name), file.span(), file.get_ref().clone()))
        }
        (None, Some(shape)) => {
            let mesh = build_shape(c, index, raw)?;
            let name = shape.get_ref().clone();
            (mesh, name.clone(), (key("shape"), shape.span(), name))
        }
    };
    if let (Some(texture_key), None) = (material.texture_key, &mesh.uvs) {
        return Err(c.src.error(
            SceneErrorKind::Mesh,
            source.1,
            source.0,
            format!(
                "`{}` has no texture coordinates, but material `{}` uses a texture for `{texture_key}`",
                source.2,
                o.material.get_ref()
            ),
        ));
    }
    transform.apply(&mut mesh);
    validate_mesh(&mesh).map_err(|why| {
        c.src.error(
            SceneErrorKind::Mesh,
            source.1.clone(),
            source.0.clone(),
            format!("`{}` after its transform: {why}", source.2),
        )
    })?;
    let name = match &o.name {
        Some(n) if n.get_ref().trim().is_empty() => {
            return Err(c.range(&key("name"), n, "must not be empty"));
        }
        Some(n) => n.get_ref().clone(),
        None => default_name,
    };
    Ok(Object {
        name,
        mesh,
        material: material.index,
    })
}

/// Reads and parses a mesh file named by the scene, choosing the loader by its extension.
fn load_mesh(c: &Check, key: &str, file: &Spanned<String>, origin: &SceneOrigin) -> Checked<Mesh> {
    let name = file.get_ref();
    let Some(format) = MeshFormat::from_path(name) else {
        return Err(c.at(
            SceneErrorKind::Mesh,
            key,
            file,
            format!(
                "`{name}` is not a known mesh format (the extension must be one of: .{})",
                MESH_EXTENSIONS.join(", .")
            ),
        ));
    };
    let path = origin.resolve(name);
    let bytes = origin.read(name).map_err(|why| {
        c.at(
            SceneErrorKind::Io,
            key,
            file,
            format!("cannot read mesh {}: {why}", path.display()),
        )
        .with_source(why)
    })?;
    // Files a mesh refers to (glTF buffers) are relative to the mesh file.
    let dir = Path::new(name).parent().unwrap_or(Path::new(""));
    let mut read_file = |relative: &str| -> Result<Vec<u8>, String> {
        let scene_relative = dir.join(relative).to_string_lossy().into_owned();
        origin
            .read(&scene_relative)
            .map(|b| b.into_owned())
            .map_err(|why| {
                format!(
                    "cannot read {}: {why}",
                    origin.resolve(&scene_relative).display()
                )
            })
    };
    parse_mesh_file(format, &bytes, &mut read_file).map_err(|e| {
        c.at(
            SceneErrorKind::Mesh,
            key,
            file,
            format!("in {}: {e}", path.display()),
        )
        .with_source(e)
    })
}

/// Builds a built-in shape from its keys.
fn build_shape(c: &Check, index: usize, raw: &Spanned<RawObject>) -> Checked<Mesh> {
    let o = raw.get_ref();
    let key = |k: &str| format!("object[{index}].{k}");
    let Some(shape) = &o.shape else {
        return Err(c.at(SceneErrorKind::MissingKey, &key("shape"), raw, "missing"));
    };
    let name = shape.get_ref().as_str();
    let what = format!("shape `{name}`");
    let segments = |c: &Check| -> Checked<u32> {
        match &o.segments {
            Some(v) => Ok(c.int(
                &key("segments"),
                v,
                i64::from(MIN_SEGMENTS),
                i64::from(MAX_SEGMENTS),
            )? as u32),
            None => Ok(DEFAULT_SEGMENTS),
        }
    };
    let radius = |c: &Check| -> Checked<f32> {
        let v = c.require(&key("radius"), &o.radius, raw, &what)?;
        c.positive(&key("radius"), v)
    };
    let positive_size = |c: &Check, n: usize| -> Checked<Vec<f32>> {
        let v = c.require(&key("size"), &o.size, raw, &what)?;
        let s = c.components(&key("size"), v, n)?;
        if s.iter().all(|&x| x > 0.0) {
            Ok(s)
        } else {
            Err(c.range(
                &key("size"),
                v,
                format!("must be greater than 0 (got {s:?})"),
            ))
        }
    };
    match name {
        "plane" => {
            c.forbid(&key("radius"), &o.radius, &what)?;
            c.forbid(&key("segments"), &o.segments, &what)?;
            let s = positive_size(c, 2)?;
            Ok(shapes::plane(glam::Vec2::new(s[0], s[1])))
        }
        "box" => {
            c.forbid(&key("radius"), &o.radius, &what)?;
            c.forbid(&key("segments"), &o.segments, &what)?;
            let s = positive_size(c, 3)?;
            Ok(shapes::cuboid(glam::Vec3::new(s[0], s[1], s[2])))
        }
        "sphere" => {
            c.forbid(&key("size"), &o.size, &what)?;
            Ok(shapes::sphere(radius(c)?, segments(c)?))
        }
        "disk" => {
            c.forbid(&key("size"), &o.size, &what)?;
            Ok(shapes::disk(radius(c)?, segments(c)?))
        }
        other => Err(c.at(
            SceneErrorKind::UnknownName,
            &key("shape"),
            shape,
            format!(
                "unknown shape `{other}` (expected one of: {})",
                SHAPES.join(", ")
            ),
        )),
    }
}
