//! Several materials on one OBJ: `usemtl` groups → scene materials (`materials = { … }`),
//! K_d from the `.mtl` (`kd = "mtl"`), and the split into one [`Object`] per material.
//!
//! The renderer keeps one material per object: irradiance samples, caches, convexity and the
//! shadow BVH are all per object. An OBJ whose groups resolve to several scene materials is
//! therefore split at load time into one object per *scene material* (not per group: groups
//! sharing a material stay one object, so light scatters across their seam). Parts are ordered
//! by their first triangle in the file and named `NAME/MATERIAL`, which keeps the result
//! deterministic. Light does not scatter between parts of different materials, which is the
//! physics of two media meeting; a part is no longer closed, so it is conservatively treated
//! as able to shadow itself.
//!
//! An OBJ group the mapping does not name takes the object's `material` with a warning (the
//! scene gave a mapping, so a forgotten group is likely a mistake); a mapping entry naming a
//! group the file does not have is an error (a typo would otherwise silently do nothing).

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use toml::Spanned;

use super::check::{Check, Checked};
use super::error::SceneErrorKind;
use super::format::RawObject;
use super::materials::{TextureCache, with_kd_texture};
use super::mesh::{drop_unused_vertices, validate_mesh};
use super::model::{Material, Mesh, Object};
use super::mtl::{MtlMaterial, parse_mtl};
use super::obj::ObjMesh;
use super::origin::SceneOrigin;
use crate::texture::TextureEncoding;

/// What a material needs from the meshes that use it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MaterialRef<'n> {
    /// Material index in the scene.
    pub index: usize,
    /// The key of a textured parameter, if the material has one (the mesh then needs UVs).
    pub texture_key: Option<&'n str>,
    /// `kd = "mtl"`: K_d comes from the OBJ's `map_Kd`.
    pub kd_from_mtl: bool,
}

/// The scene's materials while objects are built: the named ones, plus a copy of each
/// `kd = "mtl"` material per `map_Kd` texture it is given.
pub(crate) struct MaterialTable<'n, 'o> {
    /// The `[material.NAME]` tables by name.
    pub by_name: HashMap<&'n str, MaterialRef<'n>>,
    /// Every material; indices are [`Object::material`].
    pub materials: Vec<Material>,
    /// Shared texture loading.
    pub textures: TextureCache<'o>,
    /// Warnings so far, located.
    pub warnings: Vec<String>,
    /// (material, texture path relative to the scene) → index of its textured copy.
    instances: HashMap<(usize, String), usize>,
}

impl<'n, 'o> MaterialTable<'n, 'o> {
    /// A table of the named materials.
    pub fn new(
        by_name: HashMap<&'n str, MaterialRef<'n>>,
        materials: Vec<Material>,
        textures: TextureCache<'o>,
    ) -> Self {
        MaterialTable {
            by_name,
            materials,
            textures,
            warnings: Vec::new(),
            instances: HashMap::new(),
        }
    }

    fn name_of(&self, index: usize) -> &str {
        match &self.materials[index] {
            Material::Translucent(t) => &t.name,
            Material::Lambert { name, .. } => name,
        }
    }
}

/// An OBJ's material information, without its mesh.
pub(crate) struct ObjGroups {
    /// `usemtl` names in first-use order.
    pub groups: Vec<String>,
    /// Per triangle, its group.
    pub triangle_groups: Vec<Option<u32>>,
    /// `mtllib` statements: (OBJ line, path relative to the OBJ).
    pub mtllibs: Vec<(usize, String)>,
}

impl From<&ObjMesh> for ObjGroups {
    fn from(obj: &ObjMesh) -> Self {
        ObjGroups {
            groups: obj.groups.clone(),
            triangle_groups: obj.triangle_groups.clone(),
            mtllibs: obj.mtllibs.clone(),
        }
    }
}

impl ObjGroups {
    /// A glTF file's primitives as groups: each material name is a group (in first-use order),
    /// primitives without a name take the default material; there is no `.mtl`.
    pub fn from_gltf(primitives: &[super::gltf::MaterialGroup], triangles: usize) -> Self {
        let mut groups: Vec<String> = Vec::new();
        let mut triangle_groups = vec![None; triangles];
        for primitive in primitives {
            let Some(name) = &primitive.material else {
                continue;
            };
            let g = match groups.iter().position(|n| n == name) {
                Some(g) => g,
                None => {
                    groups.push(name.clone());
                    groups.len() - 1
                }
            };
            for t in primitive.triangles.clone() {
                if let Some(slot) = triangle_groups.get_mut(t) {
                    *slot = Some(g as u32);
                }
            }
        }
        ObjGroups {
            groups,
            triangle_groups,
            mtllibs: Vec::new(),
        }
    }
}

/// Where the object's mesh came from: the key, its span and the file (or shape) name.
pub(crate) type SourceKey = (String, std::ops::Range<usize>, String);

/// Turns a world-space mesh into objects: one when every triangle has the same material,
/// else one per material (see the module docs).
#[allow(clippy::too_many_arguments)]
pub(crate) fn split_by_material(
    c: &Check,
    index: usize,
    raw: &RawObject,
    name: String,
    mesh: Mesh,
    default: MaterialRef,
    obj: Option<&ObjGroups>,
    table: &mut MaterialTable,
    origin: &SceneOrigin,
    source: &SourceKey,
) -> Checked<Vec<Object>> {
    let key = |k: &str| format!("object[{index}].{k}");
    let at_source = |message: String| {
        c.src.error(
            SceneErrorKind::Mesh,
            source.1.clone(),
            source.0.clone(),
            message,
        )
    };
    let Some(obj) = obj else {
        if default.kd_from_mtl {
            return Err(c.at(
                SceneErrorKind::Conflict,
                &key("material"),
                &raw.material,
                format!(
                    "material `{}` takes kd from an OBJ's .mtl (kd = \"mtl\"), but this object \
                     is not an OBJ mesh",
                    raw.material.get_ref()
                ),
            ));
        }
        if let (Some(texture_key), None) = (default.texture_key, &mesh.uvs) {
            return Err(at_source(format!(
                "`{}` has no texture coordinates, but material `{}` uses a texture for \
                 `{texture_key}`",
                source.2,
                raw.material.get_ref()
            )));
        }
        return Ok(vec![Object {
            name,
            mesh,
            material: default.index,
        }]);
    };

    // Each group's material: the mapping's, else the default.
    let mut group_refs = vec![default; obj.groups.len()];
    if let Some(map) = &raw.materials {
        for (group, scene_name) in map.get_ref() {
            let entry_key = key(&format!("materials.{group}"));
            let Some(r) = table.by_name.get(scene_name.get_ref().as_str()) else {
                let mut names: Vec<_> = table.by_name.keys().copied().collect();
                names.sort_unstable();
                return Err(c.at(
                    SceneErrorKind::UnknownName,
                    &entry_key,
                    scene_name,
                    format!(
                        "unknown material `{}` (defined: {})",
                        scene_name.get_ref(),
                        names.join(", ")
                    ),
                ));
            };
            let Some(g) = obj.groups.iter().position(|n| n == group) else {
                return Err(c.at(
                    SceneErrorKind::UnknownName,
                    &entry_key,
                    scene_name,
                    format!(
                        "`{}` has no `usemtl {group}` ({})",
                        source.2,
                        if obj.groups.is_empty() {
                            "it has no usemtl groups".to_string()
                        } else {
                            format!("its groups: {}", obj.groups.join(", "))
                        }
                    ),
                ));
            };
            group_refs[g] = *r;
        }
        for group in obj
            .groups
            .iter()
            .filter(|g| !map.get_ref().contains_key(*g))
        {
            table.warnings.push(
                c.src
                    .error(
                        SceneErrorKind::Mesh,
                        map.span(),
                        key("materials"),
                        format!(
                            "`{}` group `usemtl {group}` is not mapped: it takes the object's \
                             material `{}`",
                            source.2,
                            raw.material.get_ref()
                        ),
                    )
                    .to_string(),
            );
        }
    }

    // Material indices per group (`kd = "mtl"` ones become textured copies), and for the
    // faces before any `usemtl`.
    let mut libraries: Option<Vec<(String, MtlMaterial)>> = None;
    let mut group_material = Vec::with_capacity(obj.groups.len());
    for (g, r) in group_refs.iter().enumerate() {
        let m = if r.kd_from_mtl {
            let libs = match &mut libraries {
                Some(libs) => libs,
                None => libraries.insert(read_libraries(c, obj, origin, source)?),
            };
            let group = &obj.groups[g];
            let Some((lib, found)) = libs.iter().rev().find(|(_, m)| m.name == *group) else {
                return Err(at_source(format!(
                    "material `{}` takes kd from the .mtl (kd = \"mtl\"), but no material \
                     library of `{}` defines `newmtl {group}` (libraries: {})",
                    table.name_of(r.index),
                    source.2,
                    library_list(obj, &source.2)
                )));
            };
            let Some(map_kd) = &found.map_kd else {
                return Err(at_source(format!(
                    "material `{}` takes kd from the .mtl (kd = \"mtl\"), but `newmtl {group}` \
                     in {lib} has no map_Kd",
                    table.name_of(r.index)
                )));
            };
            let texture_path = sibling(lib, map_kd);
            let spanned = Spanned::new(source.1.clone(), texture_path.clone());
            let texture = table
                .textures
                .get(c, &source.0, &spanned, TextureEncoding::Srgb)
                .map_err(|mut e| {
                    e.message = format!("{} (map_Kd of `newmtl {group}` in {lib})", e.message);
                    e
                })?;
            instance(table, r.index, texture, &texture_path)
        } else {
            r.index
        };
        group_material.push(m);
    }
    let ungrouped = obj.triangle_groups.iter().any(Option::is_none);
    if ungrouped && default.kd_from_mtl {
        return Err(at_source(format!(
            "material `{}` takes kd from the .mtl (kd = \"mtl\"), but some faces of `{}` come \
             before any usemtl and have no .mtl material",
            raw.material.get_ref(),
            source.2
        )));
    }
    let per_triangle: Vec<usize> = obj
        .triangle_groups
        .iter()
        .map(|g| g.map_or(default.index, |g| group_material[g as usize]))
        .collect();

    // Used materials in order of first triangle.
    let mut used: Vec<usize> = Vec::new();
    for &m in &per_triangle {
        if !used.contains(&m) {
            used.push(m);
        }
    }
    let texture_key = |m: usize| {
        table
            .by_name
            .values()
            .find(|r| r.index == m)
            .map_or(Some("kd"), |r| r.texture_key)
    };
    if mesh.uvs.is_none()
        && let Some(&m) = used.iter().find(|&&m| texture_key(m).is_some())
    {
        return Err(at_source(format!(
            "`{}` has no texture coordinates, but material `{}` uses a texture for `{}`",
            source.2,
            table.name_of(m),
            texture_key(m).unwrap_or("kd")
        )));
    }
    if let [only] = used.as_slice() {
        return Ok(vec![Object {
            name,
            mesh,
            material: *only,
        }]);
    }
    used.iter()
        .map(|&m| {
            let mut part = Mesh {
                positions: mesh.positions.clone(),
                normals: mesh.normals.clone(),
                uvs: mesh.uvs.clone(),
                triangles: mesh
                    .triangles
                    .iter()
                    .zip(&per_triangle)
                    .filter(|&(_, &pm)| pm == m)
                    .map(|(t, _)| *t)
                    .collect(),
            };
            drop_unused_vertices(&mut part);
            let part_name = format!("{name}/{}", table.name_of(m));
            validate_mesh(&part).map_err(|why| {
                at_source(format!(
                    "`{}`, the part with material `{}`: {why}",
                    source.2,
                    table.name_of(m)
                ))
            })?;
            Ok(Object {
                name: part_name,
                mesh: part,
                material: m,
            })
        })
        .collect()
}

/// The textured copy of material `index` for `texture` (one per material and file).
fn instance(
    table: &mut MaterialTable,
    index: usize,
    texture: Arc<crate::texture::Texture>,
    path: &str,
) -> usize {
    if let Some(&i) = table.instances.get(&(index, path.to_string())) {
        return i;
    }
    let m = with_kd_texture(&table.materials[index], texture, path);
    table.materials.push(m);
    let i = table.materials.len() - 1;
    table.instances.insert((index, path.to_string()), i);
    i
}

/// `relative` next to the file `beside` (both relative to the scene).
fn sibling(beside: &str, relative: &str) -> String {
    Path::new(beside)
        .parent()
        .unwrap_or_else(|| Path::new(""))
        .join(relative)
        .to_string_lossy()
        .into_owned()
}

fn library_list(obj: &ObjGroups, file: &str) -> String {
    if obj.mtllibs.is_empty() {
        return "none".to_string();
    }
    obj.mtllibs
        .iter()
        .map(|(line, path)| format!("{} ({file} line {line})", sibling(file, path)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Reads every `mtllib` of the OBJ, in file order: (library path relative to the scene, one of
/// its materials). Later definitions of a name win, as in `tobj`.
fn read_libraries(
    c: &Check,
    obj: &ObjGroups,
    origin: &SceneOrigin,
    source: &SourceKey,
) -> Checked<Vec<(String, MtlMaterial)>> {
    let fail = |kind, message: String| {
        c.src
            .error(kind, source.1.clone(), source.0.clone(), message)
    };
    if obj.mtllibs.is_empty() {
        return Err(fail(
            SceneErrorKind::Mesh,
            format!(
                "a material takes kd from the .mtl (kd = \"mtl\"), but `{}` has no mtllib",
                source.2
            ),
        ));
    }
    let mut all = Vec::new();
    for (line, path) in &obj.mtllibs {
        let lib = sibling(&source.2, path);
        let shown = origin.resolve(&lib);
        let bytes = origin.read(&lib).map_err(|why| {
            fail(
                SceneErrorKind::Io,
                format!(
                    "cannot read material library {} (mtllib at {} line {line}): {why}",
                    shown.display(),
                    source.2
                ),
            )
            .with_source(why)
        })?;
        let materials = parse_mtl(&bytes).map_err(|e| {
            fail(SceneErrorKind::Mesh, format!("in {}: {e}", shown.display())).with_source(e)
        })?;
        all.extend(materials.into_iter().map(|m| (lib.clone(), m)));
    }
    Ok(all)
}
