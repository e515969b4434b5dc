//! Tests of [`sheet`](crate::plot::sheet): layout, tile placement and errors.

use crate::plot::sheet::*;
use crate::plot::{Canvas, PlotError};

/// A tile whose every pixel is different: (x, y, seed).
fn tile(width: u32, height: u32, seed: u8) -> Tile {
    let mut rgb = Vec::new();
    for y in 0..height {
        for x in 0..width {
            rgb.extend_from_slice(&[x as u8, y as u8, seed]);
        }
    }
    Tile::new(rgb, width, height).unwrap()
}

/// Two columns, two rows, one empty cell, small tiles.
fn small_sheet() -> Sheet {
    Sheet {
        rows: vec![
            vec![Some(tile(30, 20, 1)), None],
            vec![Some(tile(10, 40, 2)), Some(tile(24, 8, 3))],
        ],
    }
}

fn assert_tile_at(canvas: &Canvas, tile: &Tile, x0: u32, y0: u32) {
    for y in 0..tile.height {
        for x in 0..tile.width {
            let i = 3 * (y * tile.width + x) as usize;
            let expected = [tile.rgb[i], tile.rgb[i + 1], tile.rgb[i + 2]];
            assert_eq!(canvas.pixel(x0 + x, y0 + y), Some(expected), "({x}, {y})");
        }
    }
}

#[test]
fn layout_matches_the_hand_computed_one() {
    let layout = sheet_layout(&small_sheet()).unwrap();
    // Columns 30 and 24 wide, rows 20 and 40 tall, from the margin, a gutter apart.
    let (x0, y0) = (MARGIN, MARGIN);
    assert_eq!(layout.column_x, [x0, x0 + 30 + GUTTER]);
    assert_eq!(layout.column_widths, [30, 24]);
    assert_eq!(layout.row_y, [y0, y0 + 20 + GUTTER]);
    assert_eq!(layout.row_heights, [20, 40]);
    assert_eq!(layout.width, x0 + 30 + GUTTER + 24 + MARGIN);
    assert_eq!(layout.height, y0 + 20 + GUTTER + 40 + MARGIN);
    let canvas = render_sheet(&small_sheet()).unwrap();
    assert_eq!(
        (canvas.width(), canvas.height()),
        (layout.width, layout.height)
    );
}

#[test]
fn tiles_appear_centred_in_their_cells() {
    let sheet = small_sheet();
    let layout = sheet_layout(&sheet).unwrap();
    let canvas = render_sheet(&sheet).unwrap();
    let (x0, y0) = (layout.column_x[0], layout.row_y[0]);
    // The 30x20 tile fills its cell exactly.
    assert_tile_at(&canvas, &tile(30, 20, 1), x0, y0);
    // The 10x40 tile is centred in a 30-wide cell: 10 pixels free on each side.
    assert_tile_at(&canvas, &tile(10, 40, 2), x0 + 10, layout.row_y[1]);
    assert_eq!(canvas.pixel(x0 + 9, layout.row_y[1]), Some(BACKGROUND));
    // The 24x8 tile is centred in a 40-tall row.
    let (x, y) = layout.tile_origin(1, 1, 24, 8).unwrap();
    assert_eq!((x, y), (layout.column_x[1], layout.row_y[1] + 16));
    assert_tile_at(&canvas, &tile(24, 8, 3), x, y);
    // The empty cell is outlined.
    assert_eq!(canvas.pixel(layout.column_x[1], y0), Some(EMPTY_CELL));
    assert_eq!(
        canvas.pixel(layout.column_x[1] + 5, y0 + 5),
        Some(BACKGROUND)
    );
    assert_eq!(layout.tile_origin(2, 0, 1, 1), None);
    assert_eq!(layout.tile_origin(0, 2, 1, 1), None);
}

#[test]
fn bad_tiles_are_reported() {
    let mut sheet = small_sheet();
    sheet.rows[1][1] = Some(Tile {
        rgb: vec![0; 10],
        width: 2,
        height: 2,
    });
    let err = render_sheet(&sheet).unwrap_err();
    assert!(
        matches!(
            err,
            PlotError::Tile {
                row: 1,
                column: 1,
                ..
            }
        ),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        "contact-sheet tile at row 1, column 1: an 8-bit RGB image of 2x2 pixels needs 12 \
         bytes, got 10"
    );
    sheet.rows[1][1] = Some(Tile {
        rgb: Vec::new(),
        width: 0,
        height: 5,
    });
    let err = sheet_layout(&sheet).unwrap_err();
    assert!(err.to_string().contains("no pixels (0x5)"), "{err}");
    assert!(Tile::new(vec![0; 5], 1, 2).is_err());
}

#[test]
fn oversized_sheets_are_errors() {
    let wide = Tile::new(vec![0; 3 * 6000], 6000, 1).unwrap();
    let sheet = Sheet {
        rows: vec![vec![Some(wide.clone()), Some(wide.clone()), Some(wide)]],
    };
    assert!(matches!(
        render_sheet(&sheet),
        Err(PlotError::Size { height: 25, .. })
    ));
}

#[test]
fn degenerate_sheets_still_render() {
    let empty = render_sheet(&Sheet::default()).unwrap();
    assert_eq!((empty.width(), empty.height()), (2 * MARGIN, 2 * MARGIN));
    let ragged = Sheet {
        rows: vec![vec![], vec![None, Some(tile(3, 3, 9))], vec![None]],
    };
    let layout = sheet_layout(&ragged).unwrap();
    assert_eq!(layout.column_x.len(), 2);
    assert_eq!(layout.row_heights, [0, 3, 0]);
    assert_eq!(layout.column_widths, [0, 3]);
    let canvas = render_sheet(&ragged).unwrap();
    assert_eq!(
        (canvas.width(), canvas.height()),
        (
            MARGIN + GUTTER + 3 + MARGIN,
            MARGIN + 3 + 2 * GUTTER + MARGIN
        )
    );
    let (x, y) = layout.tile_origin(1, 1, 3, 3).unwrap();
    assert_tile_at(&canvas, &tile(3, 3, 9), x, y);
    assert_eq!(canvas.to_rgb8(), render_sheet(&ragged).unwrap().to_rgb8());
}

#[test]
fn a_canvas_becomes_a_tile() {
    let canvas = Canvas::new(1, 1, BACKGROUND).unwrap();
    assert_eq!(
        Tile::from_canvas(&canvas),
        Tile::new(BACKGROUND.to_vec(), 1, 1).unwrap()
    );
}
