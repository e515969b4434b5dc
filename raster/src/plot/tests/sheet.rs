//! Tests of [`sheet`](crate::plot::sheet): layout, tile placement, labels and errors.

use crate::plot::font::{ADVANCE, GLYPH_HEIGHT, SPACING, text_width};
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

fn row(label: &str, tiles: Vec<Option<Tile>>) -> SheetRow {
    SheetRow {
        label: label.into(),
        tiles,
    }
}

/// Two columns, two rows, one empty cell, small tiles (text scale 1).
fn small_sheet() -> Sheet {
    Sheet {
        title: "T".into(),
        column_labels: vec!["ref".into(), "a".into()],
        rows: vec![
            row("r1", vec![Some(tile(30, 20, 1)), None]),
            row("row 2", vec![Some(tile(10, 40, 2)), Some(tile(24, 8, 3))]),
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
    assert_eq!(layout.text_scale, 1);
    let chars = |n: u32| n * ADVANCE - SPACING; // text width at scale 1
    // Left margin: "row 2" plus the gap. Columns: 30 wide, then 24 wide.
    let x0 = MARGIN + chars(5) + LABEL_GAP;
    assert_eq!(layout.column_x, [x0, x0 + 30 + GUTTER]);
    assert_eq!(layout.column_widths, [30, 24]);
    // Title at scale 2 with its gaps, then the column labels, then rows 20 and 40 tall.
    let title = 2 * GLYPH_HEIGHT + 2 * LABEL_GAP;
    assert_eq!(layout.column_label_y, MARGIN + title);
    let y0 = MARGIN + title + GLYPH_HEIGHT + LABEL_GAP;
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
fn labels_are_light_and_in_the_margins() {
    let sheet = small_sheet();
    let layout = sheet_layout(&sheet).unwrap();
    let canvas = render_sheet(&sheet).unwrap();
    let text_in = |x0: u32, y0: u32, w: u32, h: u32| {
        (y0..y0 + h)
            .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
            .filter(|&(x, y)| canvas.pixel(x, y) == Some(TEXT))
            .count()
    };
    // Row label "r1", column labels, title.
    assert!(text_in(MARGIN, layout.row_y[0], layout.column_x[0] - MARGIN, 20) > 10);
    let (cx, cw) = (layout.column_x[0], layout.column_widths[0]);
    assert!(text_in(cx, layout.column_label_y, cw, GLYPH_HEIGHT) > 10);
    assert!(text_in(0, MARGIN, layout.width, 2 * GLYPH_HEIGHT) > 10);
    // A column label wider than its tiles widens the column.
    let mut wide = sheet.clone();
    wide.column_labels[1] = "a much longer label".into();
    let layout = sheet_layout(&wide).unwrap();
    assert_eq!(layout.column_widths[1], 19 * ADVANCE - SPACING);
}

#[test]
fn bad_tiles_are_reported() {
    let mut sheet = small_sheet();
    sheet.rows[1].tiles[1] = Some(Tile {
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
    sheet.rows[1].tiles[1] = Some(Tile {
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
        rows: vec![row(
            "",
            vec![Some(wide.clone()), Some(wide.clone()), Some(wide)],
        )],
        ..Sheet::default()
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
        title: "a title much wider than the grid".into(),
        column_labels: vec!["one".into(), String::new(), "three".into(), "four".into()],
        rows: vec![
            row("", vec![]),
            row("x", vec![None, Some(tile(3, 3, 9))]),
            row("", vec![None]),
        ],
    };
    let layout = sheet_layout(&ragged).unwrap();
    assert_eq!(layout.column_x.len(), 4);
    assert_eq!(layout.row_heights, [0, GLYPH_HEIGHT, 0]);
    let canvas = render_sheet(&ragged).unwrap();
    assert_eq!(canvas.width(), text_width(&ragged.title, 2) + 2 * MARGIN);
    let (x, y) = layout.tile_origin(1, 1, 3, 3).unwrap();
    assert_tile_at(&canvas, &tile(3, 3, 9), x, y);
    assert_eq!(canvas.to_rgb8(), render_sheet(&ragged).unwrap().to_rgb8());
}

#[test]
fn large_tiles_get_larger_text() {
    let sheet = Sheet {
        title: "big".into(),
        column_labels: vec!["m".into()],
        rows: vec![row("r", vec![Some(tile(160, 100, 0))])],
    };
    let layout = sheet_layout(&sheet).unwrap();
    assert_eq!(layout.text_scale, 2);
    let canvas = Canvas::new(1, 1, BACKGROUND).unwrap();
    assert_eq!(
        Tile::from_canvas(&canvas),
        Tile::new(BACKGROUND.to_vec(), 1, 1).unwrap()
    );
}
