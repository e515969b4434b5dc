//! glTF 2.0 meshes (`.gltf` JSON with external or embedded `data:` buffers, and binary `.glb`),
//! merged into one [`Mesh`] in the file's world space.
//!
//! The `gltf` crate parses and validates the document (every index reference resolved, required
//! extensions refused) and splits GLB containers; what it trusts unchecked (a `POSITION`
//! accessor index, a GLB's declared length) is checked here first. Buffers and accessors are read here, every
//! offset, stride and count checked in overflow-free arithmetic against the bytes actually
//! present, so a malformed file is an error and never a panic.
//!
//! What is read: the node hierarchy of the default scene (or the first scene when none is
//! marked), each node's matrix or translation·rotation·scale composed with its parents' (in
//! f64); for every mesh instance, every primitive of mode `TRIANGLES` with `POSITION` (float
//! VEC3), indices (unsigned byte, short or int scalars; none = consecutive triples),
//! `NORMAL` (float VEC3) and `TEXCOORD_0` (float, or normalised unsigned byte or short, VEC2).
//! Positions go through the node's world matrix, normals through the inverse transpose of its
//! linear part; a mirroring matrix (negative determinant) reverses the winding, as the glTF
//! specification asks. Normals and UVs are kept only when every primitive has them, and
//! finished as for OBJ files ([`finish_loaded_mesh`]). Each primitive's material name is
//! recorded as a [`MaterialGroup`] (the scene still assigns one material per object).
//!
//! Rejected with an error naming the mesh and primitive: other primitive modes (points, lines,
//! strips, fans), sparse accessors, accessors without a buffer view, remote (`http:` …) URIs, a
//! node hierarchy that is not a tree. Ignored: cameras, lights, skins, morph targets,
//! animations, textures and every other attribute.

use std::borrow::Cow;
use std::fmt;
use std::ops::Range;

use base64::Engine;
use glam::{DMat3, DMat4, DQuat, DVec3, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::mesh::finish_loaded_mesh;
use super::model::Mesh;
use crate::memory::{self, OutOfMemory};

/// Why a glTF file could not be used.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfError {
    /// What is wrong, with the part of the document it concerns.
    pub message: String,
}

impl fmt::Display for GltfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for GltfError {}

fn fail(message: impl Into<String>) -> GltfError {
    GltfError {
        message: message.into(),
    }
}

/// Consecutive triangles that share a glTF material.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MaterialGroup {
    /// The material's name (`None` for the default material or an unnamed one).
    pub material: Option<String>,
    /// Their indices in [`Mesh::triangles`].
    pub triangles: Range<usize>,
}

/// A glTF file's mesh and its material groups.
#[derive(Clone, Debug)]
pub struct GltfMesh {
    /// Every triangle of the default scene, in world space.
    pub mesh: Mesh,
    /// Material groups, covering every triangle in order.
    pub groups: Vec<MaterialGroup>,
}

/// Parses a `.gltf` or `.glb` file held in memory. `read_file` reads an external buffer given
/// its URI (percent-decoded, relative to the glTF file); its error is a human-readable reason.
pub fn parse_gltf(
    bytes: &[u8],
    read_file: &mut dyn FnMut(&str) -> Result<Vec<u8>, String>,
) -> Result<GltfMesh, GltfError> {
    let malformed = |e: gltf::Error| fail(format!("malformed glTF: {e}"));
    // The `gltf` crate (1.4) subtracts the header size from a GLB's declared length unchecked.
    if let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
        && length < 12
    {
        return Err(fail(format!(
            "malformed GLB: its declared length {length} is shorter than its 12-byte header"
        )));
    }
    // A GLB's chunks are borrowed from `bytes`, not copied: the binary chunk of a scanned
    // mesh can be gigabytes.
    let (json, mut blob): (Cow<[u8]>, Option<Cow<[u8]>>) = if bytes.starts_with(b"glTF") {
        let glb = gltf::Glb::from_slice(bytes).map_err(malformed)?;
        (glb.json, glb.bin)
    } else {
        (Cow::Borrowed(bytes), None)
    };
    // The parsed document holds a copy of every string, data URIs included, and their decoded
    // buffers come on top: about twice the JSON, asked for at once before parsing, where the
    // parser's own allocations would abort.
    memory::probe(2 * json.len() as u64, memory::GLTF_JSON).map_err(|e| fail(e.to_string()))?;
    let gltf::Gltf { document, .. } =
        gltf::Gltf::from_slice_without_validation(&json).map_err(malformed)?;
    check_position_accessors(document.as_json())?;
    let document = gltf::Document::from_json(document.into_json()).map_err(malformed)?;
    // The bytes behind the buffers, each read once: exporters may name one file in several
    // buffers (a mesh's attributes and its indices, say), and a scanned mesh's file is large.
    let mut contents: Vec<Cow<[u8]>> = Vec::new();
    let mut read_uris: Vec<(&str, usize)> = Vec::new();
    // Per buffer: its index in `contents` and its declared length.
    let mut sources = Vec::new();
    for buffer in document.buffers() {
        let what = format!("buffer {}", buffer.index());
        let content = match buffer.source() {
            gltf::buffer::Source::Bin => {
                let bin = blob.take().ok_or_else(|| {
                    fail(format!("{what} is the GLB binary chunk, which is missing"))
                })?;
                contents.push(bin);
                contents.len() - 1
            }
            gltf::buffer::Source::Uri(uri) => {
                match read_uris.iter().find(|(known, _)| *known == uri) {
                    Some(&(_, content)) => content,
                    None => {
                        let data = load_uri(uri, read_file)
                            .map_err(|why| fail(format!("{what} ({}): {why}", short(uri))))?;
                        contents.push(Cow::Owned(data));
                        read_uris.push((uri, contents.len() - 1));
                        contents.len() - 1
                    }
                }
            }
        };
        let available = contents[content].len();
        if available < buffer.length() {
            return Err(fail(format!(
                "{what} declares {} bytes but has only {available}",
                buffer.length(),
            )));
        }
        sources.push((content, buffer.length()));
    }
    // Each buffer is its declared length: a view beyond it is an error even where the file
    // holds more bytes (a GLB chunk's padding, or a URI's longer file).
    let buffers: Vec<&[u8]> = sources
        .iter()
        .map(|&(content, len)| &contents[content][..len])
        .collect();
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| fail("the file has no scene"))?;

    let mut out = Builder::default();
    // Depth-first over the hierarchy with an explicit stack; each node may be reached once.
    let mut reached = vec![false; document.nodes().len()];
    let mut stack: Vec<(gltf::Node, DMat4)> = scene.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let seen = reached
            .get_mut(node.index())
            .ok_or_else(|| fail(format!("node {} does not exist", node.index())))?;
        if std::mem::replace(seen, true) {
            return Err(fail(format!(
                "node {} is reached twice (the node hierarchy must be a tree)",
                node.index()
            )));
        }
        let world = parent * local_matrix(&node);
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                out.add(&buffers, &primitive, &world).map_err(|why| {
                    fail(format!(
                        "mesh {} primitive {} (node {}): {why}",
                        name_of(mesh.index(), mesh.name()),
                        primitive.index(),
                        name_of(node.index(), node.name())
                    ))
                })?;
            }
        }
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    out.finish()
}

/// Checks that every `POSITION` attribute names an existing accessor. The `gltf` crate's
/// validation (1.4) indexes the accessor list with it unchecked, which panics.
fn check_position_accessors(root: &gltf::json::Root) -> Result<(), GltfError> {
    let semantic = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&semantic)
                && index.value() >= root.accessors.len()
            {
                return Err(fail(format!(
                    "malformed glTF: mesh {m} primitive {p}: POSITION names accessor {}, but \
                     there are {}",
                    index.value(),
                    root.accessors.len()
                )));
            }
        }
    }
    Ok(())
}

/// `3` or `3 'name'`, for messages.
fn name_of(index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) => format!("{index} '{}'", short(n)),
        None => index.to_string(),
    }
}

/// The first 60 characters of `s` (a data URI can be megabytes long).
fn short(s: &str) -> String {
    match s.char_indices().nth(60) {
        Some((end, _)) => format!("{}…", &s[..end]),
        None => s.to_string(),
    }
}

/// A node's own transform, in f64.
fn local_matrix(node: &gltf::Node) -> DMat4 {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let [x, y, z, w] = rotation.map(f64::from);
            DMat4::from_scale_rotation_translation(
                DVec3::from(scale.map(f64::from)),
                // Unit in the file up to f32 rounding; renormalised in f64.
                DQuat::from_xyzw(x, y, z, w).normalize(),
                DVec3::from(translation.map(f64::from)),
            )
        }
    }
}

/// A buffer's bytes from its URI: a base64 `data:` URI or a relative file.
fn load_uri(
    uri: &str,
    read_file: &mut dyn FnMut(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or("a data URI must be base64 (`data:...;base64,...`)")?;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("bad base64 in the data URI: {e}"));
    }
    if uri.contains("://") || uri.starts_with('/') {
        return Err("only relative file names and data URIs are read".to_string());
    }
    read_file(&percent_decode(uri)?)
}

/// Decodes `%XX` escapes of a URI.
fn percent_decode(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or("bad %-escape in the URI")?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "the URI is not UTF-8 after %-decoding".to_string())
}

/// The merged mesh under construction.
#[derive(Default)]
struct Builder {
    mesh: Mesh,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    all_normals: bool,
    all_uvs: bool,
    primitives: usize,
    groups: Vec<MaterialGroup>,
}

impl Builder {
    fn add(
        &mut self,
        buffers: &[&[u8]],
        primitive: &gltf::Primitive,
        world: &DMat4,
    ) -> Result<(), String> {
        if primitive.mode() != Mode::Triangles {
            return Err(format!(
                "mode {:?} is not supported (only triangles)",
                primitive.mode()
            ));
        }
        let position = primitive
            .get(&gltf::Semantic::Positions)
            .ok_or("no POSITION attribute")?;
        let positions = read_floats::<3>(buffers, &position, "POSITION")?;
        let n = positions.len();
        let base = self.mesh.positions.len();
        if base + n > u32::MAX as usize {
            return Err("too many vertices".to_string());
        }
        let normals = match primitive.get(&gltf::Semantic::Normals) {
            Some(a) => Some(read_floats::<3>(buffers, &a, "NORMAL")?),
            None => None,
        };
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) => Some(read_floats::<2>(buffers, &a, "TEXCOORD_0")?),
            None => None,
        };
        for (what, len) in [
            ("NORMAL", normals.as_ref().map(Vec::len)),
            ("TEXCOORD_0", uvs.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len
                && len != n
            {
                return Err(format!("{what} has {len} entries but POSITION has {n}"));
            }
        }
        let indices = match primitive.indices() {
            Some(a) => read_indices(buffers, &a)?,
            None => memory::collect(n, 0..n as u32, memory::GLTF_ACCESSORS)
                .map_err(|e| e.to_string())?,
        };
        if indices.len() % 3 != 0 {
            return Err(format!(
                "{} indices do not make whole triangles",
                indices.len()
            ));
        }
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!("index {bad} out of range ({n} vertices)"));
        }

        reserve(&mut self.mesh.positions, n)?;
        reserve(&mut self.mesh.triangles, indices.len() / 3)?;
        if normals.is_some() {
            reserve(&mut self.normals, n)?;
        }
        if uvs.is_some() {
            reserve(&mut self.uvs, n)?;
        }
        let linear = DMat3::from_mat4(*world);
        let mirrored = linear.determinant() < 0.0;
        let normal_matrix = linear.inverse().transpose();
        self.mesh.positions.extend(positions.iter().map(|p| {
            world
                .transform_point3(DVec3::from(p.map(f64::from)))
                .as_vec3()
        }));
        let first = self.primitives == 0;
        self.primitives += 1;
        self.all_normals = (first || self.all_normals) && normals.is_some();
        self.all_uvs = (first || self.all_uvs) && uvs.is_some();
        if let Some(normals) = normals {
            self.normals.extend(normals.iter().map(|v| {
                (normal_matrix * DVec3::from(v.map(f64::from)))
                    .normalize_or_zero()
                    .as_vec3()
            }));
        }
        if let Some(uvs) = uvs {
            self.uvs.extend(uvs.iter().map(|&t| Vec2::from(t)));
        }
        let start = self.mesh.triangles.len();
        self.mesh.triangles.extend(indices.chunks_exact(3).map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i + base as u32);
            if mirrored { [a, c, b] } else { [a, b, c] }
        }));
        let end = self.mesh.triangles.len();
        let material = primitive.material().name().map(str::to_string);
        match self.groups.last_mut() {
            Some(g) if g.material == material && g.triangles.end == start => g.triangles.end = end,
            _ => self.groups.push(MaterialGroup {
                material,
                triangles: start..end,
            }),
        }
        Ok(())
    }

    fn finish(self) -> Result<GltfMesh, GltfError> {
        if self.mesh.triangles.is_empty() {
            return Err(fail(
                "the default scene has no triangles (a mesh needs at least one)",
            ));
        }
        // Finishing copies the vertex lists (unused vertices dropped, normals made unit):
        // asked for at once, so that a mesh that only just fitted is refused here rather
        // than aborting there.
        let vertex_bytes = 32 * self.mesh.positions.len() as u64;
        memory::probe(vertex_bytes, memory::GLTF_ACCESSORS).map_err(|e| fail(e.to_string()))?;
        let mut mesh = self.mesh;
        mesh.uvs = self.all_uvs.then_some(self.uvs);
        let mesh =
            finish_loaded_mesh(mesh, self.all_normals.then_some(self.normals)).map_err(fail)?;
        Ok(GltfMesh {
            mesh,
            groups: self.groups,
        })
    }
}

/// Room for `n` more items in `v`, or the out-of-memory error as a message.
fn reserve<T>(v: &mut Vec<T>, n: usize) -> Result<(), String> {
    v.try_reserve(n).map_err(|_| {
        OutOfMemory {
            bytes: (n as u64).saturating_mul(size_of::<T>() as u64),
            buffer: memory::GLTF_ACCESSORS,
        }
        .to_string()
    })
}

/// The bytes of each element of `accessor`: checks the buffer view, stride, offset and count
/// against the buffer, then returns the element slices (`size` bytes each, `count` of them).
fn elements<'b>(
    buffers: &[&'b [u8]],
    accessor: &gltf::Accessor,
    size: usize,
) -> Result<impl ExactSizeIterator<Item = &'b [u8]>, String> {
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not supported".to_string());
    }
    let view = accessor
        .view()
        .ok_or("an accessor without a buffer view is not supported")?;
    let buffer: &'b [u8] = buffers
        .get(view.buffer().index())
        .ok_or("the buffer view's buffer is missing")?;
    let view_bytes = view
        .offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "buffer view {} (bytes {}..+{}) lies outside its buffer of {} bytes",
                view.index(),
                view.offset(),
                view.length(),
                buffer.len()
            )
        })?;
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "byte stride {stride} is smaller than an element ({size} bytes)"
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err("an accessor with no elements".to_string());
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(accessor.offset()))
        .and_then(|x| x.checked_add(size))
        .filter(|&end| end <= view_bytes.len())
        .ok_or_else(|| {
            format!(
                "accessor {} ({count} elements of {size} bytes, stride {stride}, offset {}) \
                 overruns its buffer view of {} bytes",
                accessor.index(),
                accessor.offset(),
                view_bytes.len()
            )
        })?;
    // `count − 1` strides and one element: `count` chunks, each at least `size` long.
    let data = &view_bytes[accessor.offset()..end];
    Ok(data.chunks(stride).map(move |e| &e[..size]))
}

/// An accessor of `N`-component floats (or, for `TEXCOORD_0`, normalised unsigned integers).
fn read_floats<const N: usize>(
    buffers: &[&[u8]],
    accessor: &gltf::Accessor,
    what: &str,
) -> Result<Vec<[f32; N]>, String> {
    let dims = match N {
        2 => Dimensions::Vec2,
        _ => Dimensions::Vec3,
    };
    let component = match accessor.data_type() {
        DataType::F32 => 4,
        DataType::U8 | DataType::U16 if N == 2 && accessor.normalized() => {
            accessor.data_type().size()
        }
        other => {
            return Err(format!(
                "{what} has component type {other:?} (expected float{})",
                if N == 2 {
                    " or normalised unsigned byte/short"
                } else {
                    ""
                }
            ));
        }
    };
    if accessor.dimensions() != dims {
        return Err(format!(
            "{what} is {:?} (expected {dims:?})",
            accessor.dimensions()
        ));
    }
    let data_type = accessor.data_type();
    let values = elements(buffers, accessor, N * component)?.map(|e| {
        std::array::from_fn(|k| {
            let c = &e[k * component..(k + 1) * component];
            match data_type {
                DataType::U8 => f32::from(c[0]) / 255.0,
                DataType::U16 => f32::from(u16::from_le_bytes([c[0], c[1]])) / 65535.0,
                _ => f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
            }
        })
    });
    memory::collect(values.len(), values, memory::GLTF_ACCESSORS).map_err(|e| e.to_string())
}

/// An index accessor (unsigned byte, short or int scalars).
fn read_indices(buffers: &[&[u8]], accessor: &gltf::Accessor) -> Result<Vec<u32>, String> {
    let data_type = accessor.data_type();
    if accessor.dimensions() != Dimensions::Scalar
        || !matches!(data_type, DataType::U8 | DataType::U16 | DataType::U32)
    {
        return Err(format!(
            "indices are {:?} {data_type:?} (expected unsigned scalars)",
            accessor.dimensions()
        ));
    }
    let indices = elements(buffers, accessor, data_type.size())?.map(|c| match c.len() {
        1 => u32::from(c[0]),
        2 => u32::from(u16::from_le_bytes([c[0], c[1]])),
        _ => u32::from_le_bytes([c[0], c[1], c[2], c[3]]),
    });
    memory::collect(indices.len(), indices, memory::GLTF_ACCESSORS).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests;
