//! Mesh files named by an object's `mesh = "PATH"` (or `obj = "PATH"`): the loader is chosen
//! by the file's extension.

use std::fmt;
use std::path::Path;

use super::gltf::{GltfError, parse_gltf};
use super::model::Mesh;
use super::obj::{ObjError, parse_obj};
use super::ply::{PlyError, parse_ply};

/// The mesh file formats lucent reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`), see [`parse_obj`].
    Obj,
    /// Stanford PLY (`.ply`), see [`parse_ply`].
    Ply,
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`), see [`parse_gltf`].
    Gltf,
}

/// The extensions recognised, lower case.
pub const MESH_EXTENSIONS: [&str; 4] = ["obj", "ply", "gltf", "glb"];

impl MeshFormat {
    /// The format of the file at `path`, from its extension (any case).
    pub fn from_path(path: &str) -> Option<MeshFormat> {
        let ext = Path::new(path).extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => MeshFormat::Obj,
            "ply" => MeshFormat::Ply,
            "gltf" | "glb" => MeshFormat::Gltf,
            _ => return None,
        })
    }
}

/// Why a mesh file could not be used: the error of its format's loader.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshFileError {
    /// From [`parse_obj`].
    Obj(ObjError),
    /// From [`parse_ply`].
    Ply(PlyError),
    /// From [`parse_gltf`].
    Gltf(GltfError),
}

impl fmt::Display for MeshFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshFileError::Obj(e) => e.fmt(f),
            MeshFileError::Ply(e) => e.fmt(f),
            MeshFileError::Gltf(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for MeshFileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            MeshFileError::Obj(e) => std::error::Error::source(e),
            MeshFileError::Ply(_) | MeshFileError::Gltf(_) => None,
        }
    }
}

/// Parses a mesh file of `format` held in memory. `read_file` reads files the mesh file
/// refers to (a glTF's external buffers) by their path relative to it.
pub fn parse_mesh_file(
    format: MeshFormat,
    bytes: &[u8],
    read_file: &mut dyn FnMut(&str) -> Result<Vec<u8>, String>,
) -> Result<Mesh, MeshFileError> {
    match format {
        MeshFormat::Obj => parse_obj(bytes).map_err(MeshFileError::Obj),
        MeshFormat::Ply => parse_ply(bytes).map_err(MeshFileError::Ply),
        MeshFormat::Gltf => parse_gltf(bytes, read_file)
            .map(|g| g.mesh)
            .map_err(MeshFileError::Gltf),
    }
}
