//! Contact sheets: a labelled grid of images, like a photographer's proof sheet or the
//! first figure of a rendering paper (one row per scene, one column per method, crops
//! magnified alongside).
//!
//! [`render_sheet`] lays a [`Sheet`] out on a dark grey [`Canvas`]: the title centred on
//! top, the column labels above the columns, the row labels in a left margin wide enough for
//! the longest, light text throughout. Each column is as wide as its widest tile (or its
//! label, if that is wider), each row as tall as its tallest tile (or its label); tiles are
//! centred in their cells, [`GUTTER`] pixels apart. An empty cell (`None`, or a row with
//! fewer tiles than there are columns) shows a faint outline.
//!
//! Labels are drawn at text scale 1, or 2 once some tile is at least 160 pixels wide or tall;
//! the title at one scale more. [`sheet_layout`] exposes the geometry.

use super::canvas::Canvas;
use super::font::{text_height, text_width};
use super::{MAX_SIDE, PlotError, check_rgb_len};

/// Pixels between neighbouring cells.
pub const GUTTER: u32 = 4;

/// Pixels between the sheet's edges and its content.
pub const MARGIN: u32 = 12;

/// Pixels between a label and the cells it names.
pub const LABEL_GAP: u32 = 6;

pub(super) const BACKGROUND: [u8; 3] = [38, 38, 38];
pub(super) const TEXT: [u8; 3] = [232, 232, 232];
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

/// One row of a contact sheet.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SheetRow {
    /// The label in the left margin (may be empty).
    pub label: String,
    /// The cells from left to right; `None` leaves a cell empty.
    pub tiles: Vec<Option<Tile>>,
}

/// A contact sheet: what [`render_sheet`] draws.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Sheet {
    /// The title on top (may be empty).
    pub title: String,
    /// The labels above the columns, from left to right. There may be fewer labels than
    /// columns (the rest are unlabelled) or more (the extra columns are empty).
    pub column_labels: Vec<String>,
    /// The rows from top to bottom.
    pub rows: Vec<SheetRow>,
}

/// Where everything of a contact sheet goes, computed by [`sheet_layout`]. All positions are
/// canvas pixels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SheetLayout {
    /// The canvas width.
    pub width: u32,
    /// The canvas height.
    pub height: u32,
    /// The font scale of the row and column labels (the title uses one more).
    pub text_scale: u32,
    /// The left edge of every column.
    pub column_x: Vec<u32>,
    /// The width of every column.
    pub column_widths: Vec<u32>,
    /// The top edge of every row.
    pub row_y: Vec<u32>,
    /// The height of every row.
    pub row_heights: Vec<u32>,
    /// The top edge of the column labels.
    pub column_label_y: u32,
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
    let columns = sheet
        .rows
        .iter()
        .map(|row| row.tiles.len())
        .max()
        .unwrap_or(0)
        .max(sheet.column_labels.len());
    let mut column_widths = vec![0u32; columns];
    let mut row_heights = vec![0u32; sheet.rows.len()];
    let mut largest = 0;
    for (r, row) in sheet.rows.iter().enumerate() {
        for (c, tile) in row.tiles.iter().enumerate() {
            let Some(tile) = tile else { continue };
            check_tile(tile, r, c)?;
            column_widths[c] = column_widths[c].max(tile.width);
            row_heights[r] = row_heights[r].max(tile.height);
            largest = largest.max(tile.width).max(tile.height);
        }
    }
    let s = if largest >= 160 { 2 } else { 1 };
    let line = text_height(s);
    for (width, label) in column_widths.iter_mut().zip(&sheet.column_labels) {
        *width = (*width).max(text_width(label, s));
    }
    for (height, row) in row_heights.iter_mut().zip(&sheet.rows) {
        if !row.label.is_empty() {
            *height = (*height).max(line);
        }
    }

    // Sums in u64: a few thousand u32 sizes cannot overflow them.
    let label_margin = sheet
        .rows
        .iter()
        .map(|row| u64::from(text_width(&row.label, s)))
        .max()
        .unwrap_or(0);
    let label_margin = if label_margin > 0 {
        label_margin + u64::from(LABEL_GAP)
    } else {
        0
    };
    let title_height = if sheet.title.is_empty() {
        0
    } else {
        u64::from(text_height(s + 1)) + u64::from(2 * LABEL_GAP)
    };
    let column_label_y = u64::from(MARGIN) + title_height;
    let labelled = sheet.column_labels.iter().any(|l| !l.is_empty());
    let column_label_height = if labelled {
        u64::from(line + LABEL_GAP)
    } else {
        0
    };

    let mut column_x = Vec::with_capacity(columns);
    let mut x = u64::from(MARGIN) + label_margin;
    for &w in &column_widths {
        column_x.push(x);
        x += u64::from(w) + u64::from(GUTTER);
    }
    let grid_right = x - if columns > 0 { u64::from(GUTTER) } else { 0 };
    let mut row_y = Vec::with_capacity(sheet.rows.len());
    let mut y = column_label_y + column_label_height;
    for &h in &row_heights {
        row_y.push(y);
        y += u64::from(h) + u64::from(GUTTER);
    }
    let grid_bottom = y - if sheet.rows.is_empty() {
        0
    } else {
        u64::from(GUTTER)
    };

    let title_width = u64::from(text_width(&sheet.title, s + 1));
    let width = (grid_right + u64::from(MARGIN)).max(title_width + u64::from(2 * MARGIN));
    let height = grid_bottom + u64::from(MARGIN);
    if width > u64::from(MAX_SIDE) || height > u64::from(MAX_SIDE) {
        return Err(PlotError::Size { width, height });
    }
    // Everything is at most MAX_SIDE now, so the conversions below are exact.
    Ok(SheetLayout {
        width: width as u32,
        height: height as u32,
        text_scale: s,
        column_x: column_x.into_iter().map(|x| x as u32).collect(),
        column_widths,
        row_y: row_y.into_iter().map(|y| y as u32).collect(),
        row_heights,
        column_label_y: column_label_y as u32,
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
    let s = layout.text_scale;

    let title_width = text_width(&sheet.title, s + 1);
    canvas.text(
        (layout.width.saturating_sub(title_width) / 2) as i32,
        MARGIN as i32,
        &sheet.title,
        s + 1,
        TEXT,
    );
    for (c, label) in sheet.column_labels.iter().enumerate() {
        let free = layout.column_widths[c].saturating_sub(text_width(label, s));
        let x = layout.column_x[c] + free / 2;
        canvas.text(x as i32, layout.column_label_y as i32, label, s, TEXT);
    }
    for (r, row) in sheet.rows.iter().enumerate() {
        let free = layout.row_heights[r].saturating_sub(text_height(s));
        canvas.text(
            MARGIN as i32,
            (layout.row_y[r] + free / 2) as i32,
            &row.label,
            s,
            TEXT,
        );
        for c in 0..layout.column_x.len() {
            let (x, y) = (layout.column_x[c], layout.row_y[r]);
            match row.tiles.get(c) {
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
