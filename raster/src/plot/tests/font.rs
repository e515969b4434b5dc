//! Tests of [`font`](crate::plot::font): coverage of the glyph table, widths, and drawing
//! through the canvas.

use crate::plot::Canvas;
use crate::plot::font::*;

fn printable() -> impl Iterator<Item = char> {
    (0x20u8..=0x7E).map(char::from)
}

#[test]
fn every_printable_character_has_its_own_glyph() {
    for c in printable() {
        let g = glyph(c);
        assert!(
            g.iter().all(|row| row & !0x1F == 0),
            "{c:?} has bits beyond 5 columns"
        );
        let pixels: u32 = g.iter().map(|row| row.count_ones()).sum();
        if c == ' ' {
            assert_eq!(pixels, 0);
        } else {
            assert!(pixels > 0, "{c:?} has no ink");
            assert_ne!(g, &BOX_GLYPH, "{c:?} is drawn as the unknown-character box");
        }
        for other in printable().filter(|&o| o < c) {
            assert_ne!(glyph(other), g, "{other:?} and {c:?} look the same");
        }
    }
}

#[test]
fn descenders_only_where_expected() {
    for c in printable() {
        let descends = glyph(c)[7..].iter().any(|&row| row != 0);
        assert_eq!(descends, "gjpqy,;_".contains(c), "{c:?}");
    }
}

#[test]
fn unknown_characters_are_boxes() {
    for c in ['\n', '\t', '\u{7F}', 'é', '→', '\u{0}'] {
        assert_eq!(glyph(c), &BOX_GLYPH, "{c:?}");
    }
    assert!(is_ink('é', 0, 0) && !is_ink('é', 1, 1));
    assert!(!is_ink('A', GLYPH_WIDTH, 0) && !is_ink('A', 0, GLYPH_HEIGHT));
}

#[test]
fn widths_add_up() {
    assert_eq!(text_width("", 3), 0);
    assert_eq!(text_width("abc", 0), 0);
    assert_eq!(text_width("A", 1), GLYPH_WIDTH);
    assert_eq!(text_width("AB", 1), 2 * GLYPH_WIDTH + SPACING);
    assert_eq!(text_width("1e-3", 2), 2 * (4 * ADVANCE - SPACING));
    // One cell per char, not per byte.
    assert_eq!(text_width("é", 1), text_width("e", 1));
    for (a, b) in [("x", "y"), ("error", " vs time"), ("0.01", "e-5")] {
        for scale in [1, 2, 5] {
            let joined = format!("{a}{b}");
            assert_eq!(
                text_width(&joined, scale),
                text_width(a, scale) + SPACING * scale + text_width(b, scale)
            );
        }
    }
    assert_eq!(text_width("ab", u32::MAX), u32::MAX);
    assert_eq!(text_height(2), 18);
    assert_eq!(text_height(u32::MAX), u32::MAX);
}

#[test]
fn ink_stays_inside_the_text_box() {
    let text = "Quick gray fox; 1e-3 {~}";
    let width = u64::from(text_width(text, 1));
    let mut count = 0;
    for (x, y) in ink(text) {
        assert!(x < width && y < GLYPH_HEIGHT, "({x}, {y})");
        count += 1;
    }
    let expected: u32 = text
        .chars()
        .map(|c| glyph(c).iter().map(|r| r.count_ones()).sum::<u32>())
        .sum();
    assert_eq!(count, expected);
}

#[test]
fn canvas_draws_glyphs_at_integer_scale() {
    let mut canvas = Canvas::new(20, 24, [255, 255, 255]).unwrap();
    canvas.text(1, 2, "L", 2, [10, 20, 30]);
    // 'L' is the left column plus the bottom row (row 6) of the 5x7 box.
    for y in 0..24 {
        for x in 0..20 {
            let (u, v) = (x as i32 - 1, y as i32 - 2);
            let ink = u >= 0 && v >= 0 && is_ink('L', u as u32 / 2, v as u32 / 2);
            let expected = if ink { [10, 20, 30] } else { [255, 255, 255] };
            assert_eq!(canvas.pixel(x, y), Some(expected), "({x}, {y})");
        }
    }
}
