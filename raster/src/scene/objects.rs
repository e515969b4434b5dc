//! `[[object]]` tables → world-space [`Object`]s: a mesh file (OBJ, PLY, glTF) or a built-in
//! shape, placed by its transform, checked against the invariants of [`super::Mesh`]. An OBJ
//! with several materials becomes several objects (`object_materials.rs`).

use std::path::Path;

use toml::Spanned;

use crate::memory;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::RawObject;
use super::gltf::{GltfMesh, parse_gltf};
use super::mesh::{Transform, retain_flagged, validate_mesh};
use super::mesh_file::{MESH_EXTENSIONS, MeshFileError, MeshFormat, parse_mesh_file};
use super::model::{Mesh, Object};
use super::obj::{ObjMesh, load_obj};
use super::object_materials::{MaterialRef, MaterialTable, ObjGroups, split_by_material};
use super::origin::{MAX_MESH_FILE_BYTES, SceneOrigin};
use super::sanity::{
    PositionIds, drop_coincident_triangles, normals_against_winding, orient_outward,
};
use super::shapes::{self, DEFAULT_SEGMENTS, MAX_SEGMENTS, MIN_SEGMENTS};
use super::spatial_order::order_spatially;
use super::weld::{MAX_CREASE_DEGREES, weld_normals};

/// Values accepted by `shape`.
pub const SHAPES: [&str; 4] = ["plane", "sphere", "box", "disk"];

/// Builds object `index` (several objects when an OBJ's groups map to several materials).
/// `table` resolves material names, and collects new materials and warnings.
pub(crate) fn build_object(
    c: &Check,
    index: usize,
    raw: &Spanned<RawObject>,
    origin: &SceneOrigin,
    table: &mut MaterialTable,
) -> Checked<Vec<Object>> {
    let o = raw.get_ref();
    let key = |k: &str| format!("object[{index}].{k}");
    // The material first: a typo there is the cheapest thing to report.
    let material = *table
        .by_name
        .get(o.material.get_ref().as_str())
        .ok_or_else(|| {
            let mut names: Vec<_> = table.by_name.keys().copied().collect();
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
    let mut groups: Option<ObjGroups> = None;
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
            let loaded = load_mesh(c, &key(name), file, origin)?;
            let (mesh, warnings) = match loaded {
                // The OBJ loader has dropped coincident copies and oriented the mesh itself.
                Loaded::Obj(obj) => {
                    groups = Some(ObjGroups::from(&obj));
                    (obj.mesh, obj.warnings)
                }
                Loaded::Gltf(gltf) => {
                    let mtl = |r: &MaterialRef| r.kd_from_mtl;
                    let mapped_mtl = o
                        .materials
                        .iter()
                        .flat_map(|m| m.get_ref().values())
                        .any(|name| table.by_name.get(name.get_ref().as_str()).is_some_and(mtl));
                    if mtl(&material) || mapped_mtl {
                        return Err(c.at(
                            SceneErrorKind::Conflict,
                            &key(name),
                            file,
                            "a material with kd = \"mtl\" reads an OBJ's .mtl; glTF materials \
                             give no map_Kd to lucent",
                        ));
                    }
                    groups = Some(ObjGroups::from_gltf(
                        &gltf.groups,
                        gltf.mesh.triangles.len(),
                    ));
                    let mut mesh = gltf.mesh;
                    let mut ids = PositionIds::default();
                    let copies = drop_coincident_triangles(&mut mesh, &mut ids, |keep| {
                        if let Some(g) = groups.as_mut() {
                            retain_flagged(&mut g.triangle_groups, keep);
                        }
                    });
                    let flipped = orient_outward(&mut mesh, true, &mut ids);
                    let against = normals_against_winding(&mesh);
                    (
                        mesh,
                        copies.into_iter().chain(flipped).chain(against).collect(),
                    )
                }
                Loaded::Other(mut mesh) => {
                    c.forbid(&key("materials"), &o.materials, "a PLY mesh")?;
                    // The same repairs as for OBJ files. The normals are the file's or were
                    // computed from the winding: either way they follow the flip when they
                    // agreed with the inverted winding. Copies go first: they make a closed
                    // surface look open.
                    let mut ids = PositionIds::default();
                    let copies = drop_coincident_triangles(&mut mesh, &mut ids, |_| {});
                    let flipped = orient_outward(&mut mesh, true, &mut ids);
                    let against = normals_against_winding(&mesh);
                    (
                        mesh,
                        copies.into_iter().chain(flipped).chain(against).collect(),
                    )
                }
            };
            for warning in &warnings {
                let at = c.at(
                    SceneErrorKind::Mesh,
                    &key(name),
                    file,
                    format!("`{}`: {warning}", file.get_ref()),
                );
                table.warnings.push(at.to_string());
            }
            let stem = Path::new(file.get_ref())
                .file_stem()
                .map_or_else(|| "mesh".to_string(), |s| s.to_string_lossy().into_owned());
            (mesh, stem, (key(name), file.span(), file.get_ref().clone()))
        }
        (None, Some(shape)) => {
            let what = "a built-in shape";
            c.forbid(&key("materials"), &o.materials, what)?;
            c.forbid(&key("weld"), &o.weld, what)?;
            c.forbid(&key("crease_angle"), &o.crease_angle, what)?;
            let mesh = build_shape(c, index, raw)?;
            let name = shape.get_ref().clone();
            (mesh, name.clone(), (key("shape"), shape.span(), name))
        }
    };
    if let Some(crease) = crease_angle(c, index, o)? {
        weld_normals(&mut mesh, crease);
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
    let mut objects = split_by_material(
        c,
        index,
        o,
        name,
        mesh,
        material,
        groups.as_ref(),
        table,
        origin,
        &source,
    )?;
    for object in &mut objects {
        order_spatially(&mut object.mesh);
    }
    Ok(objects)
}

/// The crease angle to weld with, if `weld = true` or `crease_angle` ask for smooth normals
/// (`weld = true` alone smooths across every edge: 180°).
fn crease_angle(c: &Check, index: usize, o: &RawObject) -> Checked<Option<f32>> {
    let key = |k: &str| format!("object[{index}].{k}");
    let angle = match &o.crease_angle {
        Some(v) => Some(c.num_where(
            &key("crease_angle"),
            v,
            |x| (0.0..=MAX_CREASE_DEGREES).contains(&x),
            &format!("must be between 0 and {MAX_CREASE_DEGREES} (degrees)"),
        )?),
        None => None,
    };
    match (&o.weld, angle) {
        (Some(w), Some(_)) if !*w.get_ref() => Err(c.at(
            SceneErrorKind::Conflict,
            &key("crease_angle"),
            o.crease_angle.as_ref().unwrap_or_else(|| unreachable!()),
            "cannot be combined with `weld = false`: a crease angle welds the mesh",
        )),
        (Some(w), None) => Ok(w.get_ref().then_some(MAX_CREASE_DEGREES)),
        (_, angle) => Ok(angle),
    }
}

/// A mesh file as read: an OBJ keeps its `usemtl` groups and repair warnings, a glTF its
/// primitives' material names.
enum Loaded {
    Obj(ObjMesh),
    Gltf(GltfMesh),
    Other(Mesh),
}

/// Reads and parses a mesh file named by the scene, choosing the loader by its extension.
fn load_mesh(
    c: &Check,
    key: &str,
    file: &Spanned<String>,
    origin: &SceneOrigin,
) -> Checked<Loaded> {
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
    let bytes = origin
        .read_up_to(name, MAX_MESH_FILE_BYTES)
        .map_err(|why| {
            c.at(
                SceneErrorKind::Io,
                key,
                file,
                format!("cannot read mesh {}: {why}", path.display()),
            )
            .with_source(why)
        })?;
    let located = |e: MeshFileError| {
        c.at(
            SceneErrorKind::Mesh,
            key,
            file,
            format!("in {}: {e}", path.display()),
        )
        .with_source(e)
    };
    if format == MeshFormat::Obj {
        return load_obj(&bytes)
            .map(Loaded::Obj)
            .map_err(|e| located(MeshFileError::Obj(e)));
    }
    // Files a mesh refers to (glTF buffers, as large as the mesh) are relative to the mesh
    // file.
    let dir = Path::new(name).parent().unwrap_or(Path::new(""));
    let mut read_file = |relative: &str| -> Result<Vec<u8>, String> {
        let scene_relative = dir.join(relative).to_string_lossy().into_owned();
        origin
            .read_up_to(&scene_relative, MAX_MESH_FILE_BYTES)
            .map(|b| b.into_owned())
            .map_err(|why| {
                format!(
                    "cannot read {}: {why}",
                    origin.resolve(&scene_relative).display()
                )
            })
    };
    if format == MeshFormat::Gltf {
        return parse_gltf(&bytes, &mut read_file)
            .map(Loaded::Gltf)
            .map_err(|e| located(MeshFileError::Gltf(e)));
    }
    parse_mesh_file(format, &bytes, &mut read_file)
        .map(Loaded::Other)
        .map_err(located)
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
    // What the shape's triangles will need up to the placed samples, asked for before the mesh
    // is built: a mesh that does not fit would otherwise abort while it is generated.
    let fits = |triangles: u64| -> Checked<()> {
        let bytes = triangles.saturating_mul(memory::PEAK_BYTES_PER_TRIANGLE);
        memory::probe(bytes, memory::TRIANGLES).map_err(|e| match &o.segments {
            Some(v) => c.at(
                SceneErrorKind::OutOfRange,
                &key("segments"),
                v,
                e.to_string(),
            ),
            None => c.at(
                SceneErrorKind::OutOfRange,
                &key("shape"),
                shape,
                e.to_string(),
            ),
        })
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
            let (radius, segments) = (radius(c)?, segments(c)?);
            fits(shapes::sphere_triangles(segments))?;
            Ok(shapes::sphere(radius, segments))
        }
        "disk" => {
            c.forbid(&key("size"), &o.size, &what)?;
            let (radius, segments) = (radius(c)?, segments(c)?);
            fits(shapes::disk_triangles(segments))?;
            Ok(shapes::disk(radius, segments))
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
