//! [`TextureError`]: a texture that cannot be used, naming the file and the reason.

use std::fmt;
use std::path::PathBuf;

/// Why a file could not be turned into a [`Texture`](super::Texture).
///
/// Displayed as `texture <path>: <message>`, e.g. `texture kd.jpg: JPEG decoding failed: …`.
#[derive(Debug)]
pub struct TextureError {
    /// The file concerned.
    pub path: PathBuf,
    /// What went wrong (it includes the source's message, if there is a source).
    pub message: String,
    /// The error behind it, if one: returned by [`source`](std::error::Error::source).
    pub source: Option<TextureSource>,
}

/// The error behind a [`TextureError`].
#[derive(Debug)]
#[non_exhaustive]
pub enum TextureSource {
    /// Reading the file failed.
    Io(std::io::Error),
    /// The PNG, JPEG, TGA, BMP or Radiance HDR decoder (the `image` crate) failed.
    Image(image::ImageError),
    /// The OpenEXR decoder failed.
    Exr(exr::error::Error),
}

impl TextureError {
    /// An error without a source: a check of lucent's own.
    pub(crate) fn new(path: &std::path::Path, message: impl Into<String>) -> TextureError {
        TextureError {
            path: path.to_path_buf(),
            message: message.into(),
            source: None,
        }
    }
}

impl fmt::Display for TextureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "texture {}: {}", self.path.display(), self.message)
    }
}

impl std::error::Error for TextureError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.source {
            Some(TextureSource::Io(e)) => Some(e),
            Some(TextureSource::Image(e)) => Some(e),
            Some(TextureSource::Exr(e)) => Some(e),
            None => None,
        }
    }
}
