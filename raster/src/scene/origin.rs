//! Where a scene comes from, and how the files it names (OBJ meshes, PNG textures) are found.
//!
//! A scene on disk resolves relative paths against its own directory. The built-in default
//! scene is compiled into the binary (`include_str!`), together with the files it names, so
//! that `lucent` renders it from any working directory; [`SceneOrigin::Embedded`] serves those
//! files from memory through the same interface.

use std::borrow::Cow;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::memory;
use crate::texture::{UDIM_TOKEN, tile_of};

/// Largest file the loader reads (scene, material library, texture, baked samples): 1 GiB.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// Largest mesh file (OBJ, PLY, glTF and its buffers) the loader reads: 64 GiB. OBJ text takes
/// about 40 bytes a triangle, so a scanned mesh of 25 M triangles is already 1 GiB, and a
/// binary glTF with normals and texture coordinates about 30 bytes; a render needs about 250
/// bytes a triangle besides, so memory, checked before the file is read and again before its
/// contents are parsed, is what bounds the size in practice.
pub const MAX_MESH_FILE_BYTES: u64 = 1 << 36;

/// Where a scene's text came from, which decides how the paths inside it are resolved.
#[derive(Clone, Debug)]
pub enum SceneOrigin {
    /// A scene file on disk (its path as given): relative paths resolve against its directory.
    File(PathBuf),
    /// A scene built into the program, with the files it refers to held in memory.
    Embedded {
        /// Display name used in messages (e.g. `<built-in>/default.toml`).
        name: String,
        /// The referenced files: (path exactly as written in the scene, contents).
        files: Vec<(String, Cow<'static, [u8]>)>,
    },
}

impl SceneOrigin {
    /// The name used in error messages.
    pub fn display_name(&self) -> String {
        match self {
            SceneOrigin::File(path) => path.display().to_string(),
            SceneOrigin::Embedded { name, .. } => name.clone(),
        }
    }

    /// The scene file on disk, if there is one (what [`super::Scene::source`] records).
    pub fn source_path(&self) -> Option<PathBuf> {
        match self {
            SceneOrigin::File(path) => Some(path.clone()),
            SceneOrigin::Embedded { .. } => None,
        }
    }

    /// The file stem of the scene (`sphere-shadow` for `scenes/sphere-shadow.toml`).
    pub fn stem(&self) -> String {
        let name = match self {
            SceneOrigin::File(path) => path.clone(),
            SceneOrigin::Embedded { name, .. } => PathBuf::from(name),
        };
        name.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".to_string())
    }

    /// The path a scene-relative reference stands for (for messages and [`crate::texture::Texture::path`]).
    pub fn resolve(&self, relative: &str) -> PathBuf {
        match self {
            SceneOrigin::File(path) => path
                .parent()
                .unwrap_or_else(|| Path::new(""))
                .join(relative),
            SceneOrigin::Embedded { name, .. } => Path::new(name)
                .parent()
                .unwrap_or_else(|| Path::new(""))
                .join(relative),
        }
    }

    /// Reads a file referenced by the scene, of at most [`MAX_FILE_BYTES`]. The error is a
    /// human-readable reason.
    pub fn read(&self, relative: &str) -> Result<Cow<'_, [u8]>, std::io::Error> {
        self.read_up_to(relative, MAX_FILE_BYTES)
    }

    /// [`SceneOrigin::read`] with a limit of its own (a mesh and its glTF buffers:
    /// [`MAX_MESH_FILE_BYTES`]).
    pub fn read_up_to(&self, relative: &str, limit: u64) -> Result<Cow<'_, [u8]>, std::io::Error> {
        match self {
            SceneOrigin::File(_) => read_limited(&self.resolve(relative), limit).map(Cow::Owned),
            SceneOrigin::Embedded { files, .. } => {
                let wanted = normalise(relative);
                files
                    .iter()
                    .find(|(name, _)| normalise(name) == wanted)
                    .map(|(_, bytes)| Cow::Borrowed(bytes.as_ref()))
                    .ok_or_else(|| {
                        std::io::Error::new(
                            std::io::ErrorKind::NotFound,
                            "no such file among the built-in files",
                        )
                    })
            }
        }
    }

    /// The files of the UDIM set `pattern` (a scene-relative path whose file name holds
    /// [`UDIM_TOKEN`]): each tile number with the file's scene-relative path, in increasing
    /// tile number. Errors if the token is not in the file name or the folder cannot be listed.
    pub fn udim_tiles(&self, pattern: &str) -> Result<Vec<(u32, String)>, std::io::Error> {
        let (folder, name) = match pattern.rsplit_once('/') {
            Some((folder, name)) => (Some(folder), name),
            None => (None, pattern),
        };
        if !name.contains(UDIM_TOKEN) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("{UDIM_TOKEN} must be in the file name, not in a folder"),
            ));
        }
        let relative = |file: &str| match folder {
            Some(folder) => format!("{folder}/{file}"),
            None => file.to_string(),
        };
        let names: Vec<String> = match self {
            SceneOrigin::File(_) => {
                let dir = self.resolve(folder.unwrap_or("."));
                let mut names = Vec::new();
                for entry in std::fs::read_dir(&dir)? {
                    let entry = entry?;
                    if let Some(file) = entry.file_name().to_str() {
                        names.push(file.to_string());
                    }
                }
                names
            }
            SceneOrigin::Embedded { files, .. } => {
                let folder = folder.map(normalise);
                files
                    .iter()
                    .filter_map(|(file, _)| {
                        let file = normalise(file);
                        match (file.rsplit_once('/'), folder) {
                            (Some((f, n)), Some(wanted)) if f == wanted => Some(n.to_string()),
                            (None, None) => Some(file.to_string()),
                            _ => None,
                        }
                    })
                    .collect()
            }
        };
        let mut tiles: Vec<(u32, String)> = names
            .iter()
            .filter_map(|file| Some((tile_of(name, file)?, relative(file))))
            .collect();
        tiles.sort();
        Ok(tiles)
    }
}

/// Every file [`read_limited`] has read in this process (scenes, meshes, material libraries,
/// textures, glTF buffers), as canonical paths: a command refuses to write its outputs over
/// any of them.
static FILES_READ: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The files the scene loader has read so far in this process, as canonical paths (see
/// `read_limited`): what a command must not overwrite.
pub fn files_read() -> Vec<PathBuf> {
    FILES_READ.lock().map(|f| f.clone()).unwrap_or_default()
}

/// Reads a whole file, refusing files larger than `limit` bytes and anything that is not a
/// regular file: a device such as `/dev/zero` would be read to the limit, a pipe would block.
/// The buffer is allocated fallibly: a file larger than memory is an error of kind
/// `OutOfMemory` naming its size. Records the file in [`files_read`].
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, std::io::Error> {
    let too_large =
        |message: String| std::io::Error::new(std::io::ErrorKind::FileTooLarge, message);
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a directory, device, pipe or socket)",
        ));
    }
    let file = std::fs::File::open(path)?;
    if let (Ok(canonical), Ok(mut read)) = (std::fs::canonicalize(path), FILES_READ.lock())
        && !read.contains(&canonical)
    {
        read.push(canonical);
    }
    let len = file.metadata()?.len();
    if len > limit {
        return Err(too_large(format!(
            "file is {len} bytes, larger than the {limit}-byte limit"
        )));
    }
    let out_of_memory = |e: memory::OutOfMemory| {
        std::io::Error::new(std::io::ErrorKind::OutOfMemory, e.to_string())
    };
    let capacity = usize::try_from(len).map_err(|_| {
        out_of_memory(memory::OutOfMemory {
            bytes: len,
            buffer: memory::FILE,
        })
    })?;
    let mut bytes = memory::with_capacity(capacity, memory::FILE).map_err(out_of_memory)?;
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(format!(
            "file is larger than the {limit}-byte limit"
        )));
    }
    Ok(bytes)
}

/// Drops `./` prefixes so that `"./a.obj"` and `"a.obj"` name the same embedded file.
fn normalise(path: &str) -> &str {
    let mut p = path;
    while let Some(rest) = p.strip_prefix("./") {
        p = rest;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Only regular files are read (a device would be read to the limit, a pipe would block),
    /// and each file read is recorded once, canonically.
    #[cfg(unix)]
    #[test]
    fn only_regular_files_are_read_and_each_is_recorded() {
        let dir = std::env::temp_dir().join(format!("lucent-origin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pipe = dir.join("pipe.obj");
        let made = std::process::Command::new("mkfifo")
            .arg(&pipe)
            .status()
            .unwrap();
        assert!(made.success());
        for special in [pipe.as_path(), dir.as_path(), Path::new("/dev/zero")] {
            let err = read_limited(special, 1 << 20).expect_err("not a regular file");
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
        let file = dir.join("m.obj");
        std::fs::write(&file, b"v 0 0 0").unwrap();
        let relative = dir.join(".").join("m.obj");
        assert_eq!(read_limited(&file, 100).unwrap(), b"v 0 0 0");
        assert_eq!(read_limited(&relative, 100).unwrap(), b"v 0 0 0");
        let canonical = std::fs::canonicalize(&file).unwrap();
        let read = files_read();
        assert_eq!(read.iter().filter(|p| **p == canonical).count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn file_origin_resolves_next_to_the_scene() {
        let o = SceneOrigin::File(PathBuf::from("scenes/a.toml"));
        assert_eq!(o.resolve("m/b.obj"), PathBuf::from("scenes/m/b.obj"));
        assert_eq!(o.stem(), "a");
        assert_eq!(o.source_path(), Some(PathBuf::from("scenes/a.toml")));
        let err = o.read("definitely-missing.obj").expect_err("missing");
        assert_eq!(err.kind(), std::io::ErrorKind::NotFound);
    }

    #[test]
    fn embedded_origin_serves_its_files() {
        let o = SceneOrigin::Embedded {
            name: "<built-in>/default.toml".into(),
            files: vec![("bunny.obj".into(), Cow::Borrowed(b"v 0 0 0".as_slice()))],
        };
        assert_eq!(o.read("./bunny.obj").expect("present").as_ref(), b"v 0 0 0");
        assert!(o.read("other.obj").is_err());
        assert_eq!(o.source_path(), None);
        assert_eq!(o.stem(), "default");
        assert_eq!(
            o.resolve("bunny.obj"),
            PathBuf::from("<built-in>/bunny.obj")
        );
    }
}
