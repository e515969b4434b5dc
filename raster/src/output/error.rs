//! The one error type of the output module.
//!
//! Every variant that concerns a file carries its path, and every message says what was wrong
//! with which value, so that `lucent` can print the error as is.

use std::fmt;
use std::io;
use std::path::PathBuf;

/// Everything that can go wrong while writing, reading or comparing output files.
#[derive(Debug)]
#[non_exhaustive]
pub enum OutputError {
    /// An operating-system I/O call failed.
    Io {
        /// The file being written or read (the target, not the temporary file).
        path: PathBuf,
        /// What was being done, e.g. "creating a temporary file in 'out/'".
        action: String,
        /// The underlying error.
        source: io::Error,
    },
    /// The output file exists and is read-only: lucent does not replace it.
    ReadOnly {
        /// The file.
        path: PathBuf,
    },
    /// The data handed to a writer (or decoded by a reader) does not describe a valid image or
    /// sample set, e.g. a pixel buffer of the wrong length or an invalid layer name.
    Invalid {
        /// The file being written or read (empty when there is none).
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The PNG decoder reported an error (malformed or unsupported file).
    Png {
        /// The file.
        path: PathBuf,
        /// The codec's error.
        source: png::DecodingError,
    },
    /// The PNG encoder reported an error.
    PngEncode {
        /// The file.
        path: PathBuf,
        /// The codec's error.
        source: png::EncodingError,
    },
    /// The OpenEXR encoder or decoder reported an error (malformed or unsupported file).
    Exr {
        /// The file.
        path: PathBuf,
        /// The codec's error.
        source: exr::error::Error,
    },
    /// The pixels of an image being read do not fit in the memory granted.
    Memory {
        /// The file.
        path: PathBuf,
        /// What was refused.
        source: crate::memory::OutOfMemory,
    },
    /// A required channel is not in the file.
    MissingChannel {
        /// The file.
        path: PathBuf,
        /// The channel that was looked for.
        channel: String,
        /// The channels the file does have (possibly abbreviated).
        available: String,
    },
    /// The PLY header is malformed or describes something lucent does not read.
    PlyHeader {
        /// The file.
        path: PathBuf,
        /// 1-based header line number (0 when the problem is not on one line).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The PLY body does not have the size the header promises.
    PlySize {
        /// The file.
        path: PathBuf,
        /// Header length plus vertex count times vertex size.
        expected: u64,
        /// The actual file size.
        actual: u64,
    },
    /// A sample has an invalid value (non-finite, negative area or irradiance, non-unit normal).
    SampleValue {
        /// The file being written or read.
        path: PathBuf,
        /// Index of the offending sample (PLY vertex).
        vertex: usize,
        /// What is wrong, with the value.
        message: String,
    },
    /// Two images that must have the same size do not.
    SizeMismatch {
        /// Which comparison or buffer this is about.
        what: &'static str,
        /// The size required (width, height).
        expected: (u32, u32),
        /// The size found (width, height).
        actual: (u32, u32),
    },
    /// A comparison mask does not have one entry per pixel, or selects no pixel.
    Mask {
        /// What is wrong.
        message: String,
    },
    /// An image taking part in a comparison contains NaN or infinity.
    NonFinite {
        /// Which image ("test" or "reference").
        image: &'static str,
        /// Pixel column.
        x: u32,
        /// Pixel row.
        y: u32,
        /// Channel (0 = R, 1 = G, 2 = B).
        channel: usize,
        /// The value.
        value: f32,
    },
}

impl OutputError {
    /// Shorthand for [`OutputError::Io`].
    pub(crate) fn io(
        path: impl Into<PathBuf>,
        action: impl Into<String>,
        source: io::Error,
    ) -> Self {
        OutputError::Io {
            path: path.into(),
            action: action.into(),
            source,
        }
    }

    /// Shorthand for [`OutputError::Invalid`].
    pub(crate) fn invalid(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        OutputError::Invalid {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OutputError::Io {
                path,
                action,
                source,
            } => {
                write!(f, "{}: {action}: {source}", path.display())
            }
            OutputError::Memory { path, source } => write!(f, "{}: {source}", path.display()),
            OutputError::ReadOnly { path } => write!(
                f,
                "{}: the file is read-only; lucent does not replace it (make it writable or \
                 write elsewhere)",
                path.display()
            ),
            OutputError::Invalid { path, message } => {
                if path.as_os_str().is_empty() {
                    write!(f, "{message}")
                } else {
                    write!(f, "{}: {message}", path.display())
                }
            }
            OutputError::Png { path, source } => {
                write!(f, "{}: PNG error: {source}", path.display())
            }
            OutputError::PngEncode { path, source } => {
                write!(f, "{}: PNG error: {source}", path.display())
            }
            OutputError::Exr { path, source } => {
                write!(f, "{}: OpenEXR error: {source}", path.display())
            }
            OutputError::MissingChannel {
                path,
                channel,
                available,
            } => write!(
                f,
                "{}: no channel '{channel}' in the file (channels: {available})",
                path.display()
            ),
            OutputError::PlyHeader {
                path,
                line,
                message,
            } => {
                if *line == 0 {
                    write!(f, "{}: PLY header: {message}", path.display())
                } else {
                    write!(f, "{}: PLY header line {line}: {message}", path.display())
                }
            }
            OutputError::PlySize {
                path,
                expected,
                actual,
            } => write!(
                f,
                "{}: PLY file is {actual} bytes but its header promises {expected} bytes{}",
                path.display(),
                if actual < expected {
                    " (truncated)"
                } else {
                    " (trailing data)"
                }
            ),
            OutputError::SampleValue {
                path,
                vertex,
                message,
            } => {
                write!(f, "{}: sample {vertex}: {message}", path.display())
            }
            OutputError::SizeMismatch {
                what,
                expected,
                actual,
            } => write!(
                f,
                "{what}: expected {}x{} pixels, got {}x{}",
                expected.0, expected.1, actual.0, actual.1
            ),
            OutputError::Mask { message } => write!(f, "comparison mask: {message}"),
            OutputError::NonFinite {
                image,
                x,
                y,
                channel,
                value,
            } => write!(
                f,
                "{image} image: pixel ({x}, {y}) channel {} is {value}",
                ["R", "G", "B"].get(*channel).copied().unwrap_or("?")
            ),
        }
    }
}

impl std::error::Error for OutputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            OutputError::Io { source, .. } => Some(source),
            OutputError::Png { source, .. } => Some(source),
            OutputError::PngEncode { source, .. } => Some(source),
            OutputError::Exr { source, .. } => Some(source),
            _ => None,
        }
    }
}
