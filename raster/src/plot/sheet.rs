//! Contact sheets: a grid of images, like a photographer's proof sheet or the first figure
//! of a rendering paper (one row per scene, one column per method, crops magnified
//! alongside).
//!
//! [`render_sheet`] lays a [`Sheet`] out on a dark grey [`Canvas`]. Each column is as wide as
//! its widest tile, each row as tall as its tallest tile; tiles are centred in their cells,
//! [`GUTTER`] pixels apart, [`MARGIN`] pixels from the edges. An empty cell (`None`, or a row
//! with fewer tiles than there are columns) shows a faint outline. The sheet carries no text:
//! its caption (what the rows and columns are) goes next to it, in the report that shows it.
//! [`sheet_layout`] exposes the geometry.
//!
//! ```text
//!  MARGIN
//!  ┌──────┐ GUTTER ┌────┐        ┌──────┐
//!  │ tile │        │tile│        │      │ ← empty cell: outline
//!  └──────┘        └────┘        └──────┘
//!  ┌──────┐        ┌────┐
//!  │      │        │    │    (a column is as wide as its widest tile)
//!  └──────┘        └────┘
//! ```

use super::canvas::Canvas;
use super::{MAX_SIDE, PlotError, check_rgb_len};

/// Pixels between neighbouring cells.
pub const GUTTER: u32 = 4;

/// Pixels between the sheet's edges and its content.
pub const MARGIN: u32 = 12;

pub(super) const BACKGROUND: [u8; 3] = [38, 38, 38];
pub(super) const EMPTY_CELL: [u8; 3] = [72, 72, 72];

/// An 8-bit RGB image placed in a cell.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tile {
    /// The pixels, row-major, top row first, `R G B` per pixel: `3 · width · height` bytes.
    pub rgb: Vec<u8>,
    /// The width in pixels.
    pub width: u32,
    /// The height in pixels.
    pub height: u32,
}

impl Tile {
    /// A tile of `width × height` pixels, checking that `rgb` holds `3 · width · height`
    /// bytes ([`PlotError::BufferLength`] if not).
    pub fn new(rgb: Vec<u8>, width: u32, height: u32) -> Result<Tile, PlotError> {
        check_rgb_len(width, height, &rgb)?;
        Ok(Tile { rgb, width, height })
    }

    /// A tile holding the contents of `canvas`.
    pub fn from_canvas(canvas: &Canvas) -> Tile {
        Tile {
            rgb: canvas.to_rgb8(),
            width: canvas.width(),
            height: canvas.height(),
        }
    }
}

/// A contact sheet: what [`render_sheet`] draws.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Sheet {
    /// The rows from top to bottom, each its cells from left to right; `None` leaves a cell
    /// empty. The sheet has as many columns as its longest row.
    pub rows: Vec<Vec<Option<Tile>>>,
}

/// Where everything of a contact sheet goes, computed by [`sheet_layout`]. All positions are
/// canvas pixels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SheetLayout {
    /// The canvas width.
    pub width: u32,
    /// The canvas height.
    pub height: u32,
    /// The left edge of every column.
    pub column_x: Vec<u32>,
    /// The width of every column.
    pub column_widths: Vec<u32>,
    /// The top edge of every row.
    pub row_y: Vec<u32>,
    /// The height of every row.
    pub row_heights: Vec<u32>,
}

impl SheetLayout {
    /// The top-left corner of a `width × height` tile centred in the cell at `row`, `column`
    /// (rounded down when the free space is odd); `None` for a cell that does not exist.
    pub fn tile_origin(
        &self,
        row: usize,
        column: usize,
        width: u32,
        height: u32,
    ) -> Option<(u32, u32)> {
        let x = self.column_x.get(column)? + self.column_widths[column].saturating_sub(width) / 2;
        let y = self.row_y.get(row)? + self.row_heights[row].saturating_sub(height) / 2;
        Some((x, y))
    }
}

/// Checks every tile of `sheet` and computes its layout.
///
/// Fails with [`PlotError::Tile`] for a tile of zero width or height or whose buffer does not
/// hold `3 · width · height` bytes, and with [`PlotError::Size`] when the sheet would be
/// larger than [`MAX_SIDE`] on a side.
pub fn sheet_layout(sheet: &Sheet) -> Result<SheetLayout, PlotError> {
    let columns = sheet.rows.iter().map(Vec::len).max().unwrap_or(0);
    let mut column_widths = vec![0u32; columns];
    let mut row_heights = vec![0u32; sheet.rows.len()];
    for (r, row) in sheet.rows.iter().enumerate() {
        for (c, tile) in row.iter().enumerate() {
            let Some(tile) = tile else { continue };
            check_tile(tile, r, c)?;
            column_widths[c] = column_widths[c].max(tile.width);
            row_heights[r] = row_heights[r].max(tile.height);
        }
    }

    // Sums in u64: a few thousand u32 sizes cannot overflow them.
    let mut column_x = Vec::with_capacity(columns);
    let mut x = u64::from(MARGIN);
    for &w in &column_widths {
        column_x.push(x);
        x += u64::from(w) + u64::from(GUTTER);
    }
    let grid_right = x - if columns > 0 { u64::from(GUTTER) } else { 0 };
    let mut row_y = Vec::with_capacity(sheet.rows.len());
    let mut y = u64::from(MARGIN);
    for &h in &row_heights {
        row_y.push(y);
        y += u64::from(h) + u64::from(GUTTER);
    }
    let grid_bottom = y - if sheet.rows.is_empty() {
        0
    } else {
        u64::from(GUTTER)
    };

    let width = grid_right + u64::from(MARGIN);
    let height = grid_bottom + u64::from(MARGIN);
    if width > u64::from(MAX_SIDE) || height > u64::from(MAX_SIDE) {
        return Err(PlotError::Size { width, height });
    }
    // Everything is at most MAX_SIDE now, so the conversions below are exact.
    Ok(SheetLayout {
        width: width as u32,
        height: height as u32,
        column_x: column_x.into_iter().map(|x| x as u32).collect(),
        column_widths,
        row_y: row_y.into_iter().map(|y| y as u32).collect(),
        row_heights,
    })
}

fn check_tile(tile: &Tile, row: usize, column: usize) -> Result<(), PlotError> {
    let message = if tile.width == 0 || tile.height == 0 {
        format!("it has no pixels ({}x{})", tile.width, tile.height)
    } else if let Err(e) = check_rgb_len(tile.width, tile.height, &tile.rgb) {
        e.to_string()
    } else {
        return Ok(());
    };
    Err(PlotError::Tile {
        row,
        column,
        message,
    })
}

/// Draws `sheet` (see the [module documentation](self)) on a canvas of the size that
/// [`sheet_layout`] computes, failing as that does.
pub fn render_sheet(sheet: &Sheet) -> Result<Canvas, PlotError> {
    let layout = sheet_layout(sheet)?;
    let mut canvas = Canvas::new(layout.width, layout.height, BACKGROUND)?;
    for (r, row) in sheet.rows.iter().enumerate() {
        for c in 0..layout.column_x.len() {
            let (x, y) = (layout.column_x[c], layout.row_y[r]);
            match row.get(c) {
                Some(Some(tile)) => {
                    if let Some((tx, ty)) = layout.tile_origin(r, c, tile.width, tile.height) {
                        canvas.blit_rgb8(
                            tx as i32,
                            ty as i32,
                            tile.width,
                            tile.height,
                            &tile.rgb,
                        )?;
                    }
                }
                _ => canvas.stroke_rect(
                    x as f32,
                    y as f32,
                    layout.column_widths[c] as f32,
                    layout.row_heights[r] as f32,
                    EMPTY_CELL,
                    1.0,
                ),
            }
        }
    }
    Ok(canvas)
}
