//! Why a visibility buffer could not be made.

use std::error::Error;
use std::fmt;

use super::fixed::MAX_GRID_AXIS;
use super::visibility::{MAX_AA, MAX_SUBSAMPLES};
use crate::memory::OutOfMemory;
use crate::output::Region;

/// Why a [`VisibilityBuffer`](super::VisibilityBuffer) could not be created.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RasterError {
    /// Width or height is zero.
    EmptyImage {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
    },
    /// `aa` is outside `1..=8`.
    InvalidAa {
        /// The requested value.
        aa: u32,
    },
    /// The window of a
    /// [`VisibilityBuffer::new_window`](super::VisibilityBuffer::new_window) is empty or not
    /// inside the image.
    WindowOutside {
        /// The requested window.
        window: Region,
        /// Image width in pixels.
        width: u32,
        /// Image height in pixels.
        height: u32,
    },
    /// The sub-sample grid is larger than supported (2^20 per axis of the image, 2^28 in the
    /// pixels held).
    TooLarge {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// Requested sub-samples per axis.
        aa: u32,
    },
    /// The allocator refused the buffer.
    OutOfMemory(OutOfMemory),
}

impl fmt::Display for RasterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::EmptyImage { width, height } => {
                write!(f, "visibility buffer of {width}×{height} pixels is empty")
            }
            Self::InvalidAa { aa } => {
                write!(f, "aa = {aa} sub-samples per axis is outside 1..={MAX_AA}")
            }
            Self::WindowOutside {
                window,
                width,
                height,
            } => write!(
                f,
                "visibility window {window} is empty or not inside the {width}×{height} image"
            ),
            Self::TooLarge { width, height, aa } => write!(
                f,
                "visibility buffer of {width}×{height} pixels with aa = {aa} exceeds \
                 {MAX_GRID_AXIS} sub-samples per axis or {MAX_SUBSAMPLES} in total (lower the \
                 resolution or the antialiasing: 'aa' in [render], or --aa; or render the image in \
                 tiles, --crop, and merge them)"
            ),
            Self::OutOfMemory(e) => write!(f, "{e}"),
        }
    }
}

impl Error for RasterError {}
