//! 2-D drawing for benchmark reports.
//!
//! The report of `lucent bench` needs pictures: error-against-time curves for every method
//! (log–log line charts, SVG text: the viewer draws lines and text at any size) and the
//! Figure-1-style contact sheet that puts the renders of several methods side by side, with
//! magnified crops of the interesting regions (PNG, drawn with `tiny-skia` and written by the
//! crate's own PNG writer).
//!
//! | file | what |
//! |---|---|
//! | [`canvas`] | [`Canvas`]: an opaque RGB drawing surface; [`crop_magnify`] |
//! | [`axis`] | [`Axis`]: data ranges, ticks and tick labels, linear or logarithmic |
//! | [`chart`] | [`render_chart`]: line charts of error against time, as SVG |
//! | [`sheet`] | [`render_sheet`]: a grid of image tiles (a contact sheet) |
//! | [`xml`] | escaping chart text; [`check_well_formed`](xml::check_well_formed) |
//!
//! The tests are in `plot/tests/`, one file per module.
//!
//! Everything is deterministic (the same input draws the same pixels, or the same SVG text)
//! and nothing panics on bad input: sizes, buffer lengths and crop rectangles are checked and
//! reported as a [`PlotError`]; non-finite coordinates are skipped.

pub mod axis;
pub mod canvas;
pub mod chart;
pub mod sheet;
pub mod xml;

#[cfg(test)]
mod tests;

use std::fmt;

pub use axis::Axis;
pub use canvas::{Canvas, MAX_SIDE, crop_magnify};
pub use chart::{Chart, ChartLayout, PALETTE, Series, chart_layout, render_chart};
pub use sheet::{Sheet, SheetLayout, Tile, render_sheet, sheet_layout};

/// What went wrong while drawing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PlotError {
    /// An image or canvas would have a side of zero pixels or more than [`MAX_SIDE`].
    Size {
        /// The requested width in pixels.
        width: u64,
        /// The requested height in pixels.
        height: u64,
    },
    /// An 8-bit RGB pixel buffer does not hold `3 · width · height` bytes.
    BufferLength {
        /// The width the buffer was said to have.
        width: u32,
        /// The height the buffer was said to have.
        height: u32,
        /// The number of bytes the buffer holds.
        actual: usize,
    },
    /// A crop rectangle, clamped to its image, contains no pixels.
    EmptyCrop {
        /// The crop's left edge.
        x0: u32,
        /// The crop's top edge.
        y0: u32,
        /// The crop's requested width.
        w: u32,
        /// The crop's requested height.
        h: u32,
        /// The width of the image being cropped.
        width: u32,
        /// The height of the image being cropped.
        height: u32,
    },
    /// A magnification factor of zero.
    ZeroFactor,
    /// A contact-sheet tile is unusable (zero-sized, or its buffer has the wrong length).
    Tile {
        /// The tile's row, counted from 0.
        row: usize,
        /// The tile's column, counted from 0.
        column: usize,
        /// What is wrong with it.
        message: String,
    },
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlotError::Size { width, height } => write!(
                f,
                "an image of {width}x{height} pixels is not allowed: each side must be between \
                 1 and {MAX_SIDE} pixels"
            ),
            PlotError::BufferLength {
                width,
                height,
                actual,
            } => write!(
                f,
                "an 8-bit RGB image of {width}x{height} pixels needs {} bytes, got {actual}",
                rgb_len(*width, *height)
            ),
            PlotError::EmptyCrop {
                x0,
                y0,
                w,
                h,
                width,
                height,
            } => write!(
                f,
                "the crop of {w}x{h} pixels at ({x0}, {y0}) has no pixels inside the \
                 {width}x{height} image"
            ),
            PlotError::ZeroFactor => write!(f, "the magnification factor must be at least 1"),
            PlotError::Tile {
                row,
                column,
                message,
            } => write!(
                f,
                "contact-sheet tile at row {row}, column {column}: {message}"
            ),
        }
    }
}

impl std::error::Error for PlotError {}

/// The length of an 8-bit RGB buffer of `width × height` pixels (no overflow: at most
/// `3 · (2³² − 1)²`, which fits in a `u64`).
pub(crate) fn rgb_len(width: u32, height: u32) -> u64 {
    3 * u64::from(width) * u64::from(height)
}

/// Checks that an 8-bit RGB buffer holds exactly `3 · width · height` bytes.
pub(crate) fn check_rgb_len(width: u32, height: u32, rgb: &[u8]) -> Result<(), PlotError> {
    if rgb.len() as u64 == rgb_len(width, height) {
        Ok(())
    } else {
        Err(PlotError::BufferLength {
            width,
            height,
            actual: rgb.len(),
        })
    }
}
