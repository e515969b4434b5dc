//! Where a scene comes from, and how the files it names (OBJ meshes, PNG textures) are found.
//!
//! A scene on disk resolves relative paths against its own directory. The built-in default
//! scene is compiled into the binary (`include_str!`), together with the files it names, so
//! that `lucent` renders it from any working directory; [`SceneOrigin::Embedded`] serves those
//! files from memory through the same interface.

use std::borrow::Cow;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest file the loader reads (scene, mesh or texture): 1 GiB.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

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

    /// Reads a file referenced by the scene. The error is a human-readable reason.
    pub fn read(&self, relative: &str) -> Result<Cow<'_, [u8]>, std::io::Error> {
        match self {
            SceneOrigin::File(_) => {
                read_limited(&self.resolve(relative), MAX_FILE_BYTES).map(Cow::Owned)
            }
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
}

/// Reads a whole file, refusing files larger than `limit` bytes.
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, std::io::Error> {
    let too_large =
        |message: String| std::io::Error::new(std::io::ErrorKind::FileTooLarge, message);
    let file = std::fs::File::open(path)?;
    let len = file.metadata()?.len();
    if len > limit {
        return Err(too_large(format!(
            "file is {len} bytes, larger than the {limit}-byte limit"
        )));
    }
    let mut bytes = Vec::with_capacity(len as usize);
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
