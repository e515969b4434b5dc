//! Tests of [`canvas`](crate::plot::canvas): every drawing operation, clipping, degenerate
//! and extreme input, PNG output, and cropping.

use crate::output::atomic::tests::TestDir;
use crate::plot::canvas::*;
use crate::plot::{PlotError, font};

const WHITE: [u8; 3] = [255, 255, 255];
const RED: [u8; 3] = [200, 30, 10];

/// The pixels that differ from `background`, as (x, y).
fn changed(canvas: &Canvas, background: [u8; 3]) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    for y in 0..canvas.height() {
        for x in 0..canvas.width() {
            if canvas.pixel(x, y) != Some(background) {
                v.push((x, y));
            }
        }
    }
    v
}

#[test]
fn sizes_are_checked() {
    for (w, h) in [(0, 5), (5, 0), (MAX_SIDE + 1, 1), (1, u32::MAX)] {
        let err = Canvas::new(w, h, WHITE).unwrap_err();
        assert_eq!(
            err,
            PlotError::Size {
                width: w.into(),
                height: h.into()
            }
        );
    }
    let c = Canvas::new(MAX_SIDE, 1, [1, 2, 3]).unwrap();
    assert_eq!((c.width(), c.height()), (MAX_SIDE, 1));
    assert_eq!(c.pixel(MAX_SIDE - 1, 0), Some([1, 2, 3]));
    assert_eq!(c.pixel(MAX_SIDE, 0), None);
    assert_eq!(c.to_rgb8().len(), 3 * MAX_SIDE as usize);
}

#[test]
fn rectangles_cover_whole_pixels() {
    let mut c = Canvas::new(10, 8, WHITE).unwrap();
    c.fill_rect(2.0, 1.0, 3.0, 2.0, RED);
    let expected: Vec<(u32, u32)> = (1..3).flat_map(|y| (2..5).map(move |x| (x, y))).collect();
    assert_eq!(changed(&c, WHITE), expected);
    assert_eq!(c.pixel(3, 2), Some(RED));

    let mut c = Canvas::new(6, 6, WHITE).unwrap();
    c.stroke_rect(1.0, 1.0, 4.0, 4.0, RED, 1.0);
    let outline = changed(&c, WHITE);
    assert_eq!(outline.len(), 12);
    assert!(
        outline
            .iter()
            .all(|&(x, y)| x == 1 || x == 4 || y == 1 || y == 4)
    );
}

#[test]
fn degenerate_shapes_draw_nothing() {
    let mut c = Canvas::new(12, 12, WHITE).unwrap();
    let nan = f32::NAN;
    c.fill_rect(nan, 0.0, 5.0, 5.0, RED);
    c.fill_rect(0.0, 0.0, -5.0, 5.0, RED);
    c.fill_rect(0.0, 0.0, 5.0, f32::INFINITY, RED);
    c.fill_rect(20.0, 20.0, 5.0, 5.0, RED);
    c.stroke_rect(1.0, 1.0, 5.0, 5.0, RED, nan);
    c.stroke_rect(1.0, 1.0, 0.0, 5.0, RED, 1.0);
    c.stroke_polyline(&[(0.0, 0.0), (10.0, 10.0)], RED, 0.0);
    c.stroke_polyline(&[(0.0, 0.0), (10.0, 10.0)], RED, nan);
    c.stroke_polyline(&[(5.0, 5.0)], RED, 2.0);
    c.stroke_polyline(&[], RED, 2.0);
    c.stroke_polyline(&[(0.0, nan), (10.0, 10.0), (nan, 0.0)], RED, 2.0);
    c.stroke_polyline(&[(-50.0, -50.0), (-40.0, 100.0)], RED, 2.0);
    c.circle(5.0, 5.0, 0.0, RED);
    c.circle(5.0, 5.0, -1.0, RED);
    c.circle(nan, 5.0, 3.0, RED);
    c.circle(-10.0, 5.0, 3.0, RED);
    c.text(0, 0, "", 2, RED);
    c.text(0, 0, "abc", 0, RED);
    c.text(-100, 0, "abc", 1, RED);
    c.text(0, i32::MAX, "abc", 1, RED);
    c.text_vertical(i32::MIN, 0, "abc", 3, RED);
    c.text_vertical(0, 0, "abc", 0, RED);
    assert!(changed(&c, WHITE).is_empty());
}

#[test]
fn extreme_values_do_not_panic() {
    let mut c = Canvas::new(16, 16, WHITE).unwrap();
    let big = f32::MAX;
    c.fill_rect(-big, -big, big, big, RED);
    c.stroke_rect(-1e30, -1e30, 2e30, 2e30, RED, 1e30);
    c.stroke_polyline(&[(-big, -big), (big, big)], RED, big);
    c.stroke_polyline(&[(0.0, 0.0), (1e30, 3.0), (-1e30, -1e30)], RED, 1.0);
    c.circle(8.0, 8.0, big, RED);
    c.circle(-1e30, 8.0, 1e30, RED);
    c.text(i32::MIN, i32::MIN, "xyz", u32::MAX, RED);
    c.text(3, 3, "xyz", u32::MAX, RED);
    c.text_vertical(3, 3, "xyz", u32::MAX, RED);
    c.text_vertical(i32::MAX, i32::MIN, "xyz", 7, RED);
    c.blit_rgb8(i32::MIN, i32::MAX, 1, 1, &[0, 0, 0]).unwrap();
    // The huge disc covers everything.
    assert_eq!(c.pixel(0, 0), Some(RED));
    assert_eq!(c.pixel(15, 15), Some(RED));
}

#[test]
fn polylines_are_anti_aliased_and_clipped_far_away() {
    let mut c = Canvas::new(40, 20, WHITE).unwrap();
    // A horizontal line 2 px wide centred on y = 10 covers rows 9 and 10 exactly.
    c.stroke_polyline(&[(-1e20, 10.0), (1e20, 10.0)], RED, 2.0);
    for x in 0..40 {
        assert_eq!(c.pixel(x, 9), Some(RED), "x = {x}");
        assert_eq!(c.pixel(x, 10), Some(RED), "x = {x}");
        assert_eq!(c.pixel(x, 8), Some(WHITE));
        assert_eq!(c.pixel(x, 11), Some(WHITE));
    }
    // A diagonal line has partially covered (blended) pixels along its edges.
    let mut c = Canvas::new(30, 30, WHITE).unwrap();
    c.stroke_polyline(&[(3.0, 5.0), (25.0, 20.0)], [0, 0, 0], 1.5);
    let grey = (0..30)
        .flat_map(|y| (0..30).map(move |x| (x, y)))
        .filter_map(|(x, y)| c.pixel(x, y))
        .filter(|p| p[0] > 0 && p[0] < 255 && p[0] == p[1] && p[1] == p[2])
        .count();
    assert!(grey > 10, "only {grey} blended pixels");
    assert!(c.pixel(14, 12).is_some_and(|p| p[0] < 128), "on the line");
    assert_eq!(c.pixel(3, 25), Some(WHITE));
}

#[test]
fn non_finite_points_split_a_polyline() {
    let mut c = Canvas::new(30, 10, WHITE).unwrap();
    let points = [
        (0.0, 5.0),
        (10.0, 5.0),
        (f32::NAN, 5.0),
        (20.0, 5.0),
        (30.0, 5.0),
    ];
    c.stroke_polyline(&points, RED, 2.0);
    // The gap between x = 10 and x = 20 (the segments through the NaN) stays empty.
    assert_eq!(c.pixel(5, 4), Some(RED));
    assert_eq!(c.pixel(25, 4), Some(RED));
    assert_eq!(c.pixel(15, 4), Some(WHITE));
}

#[test]
fn clipping_keeps_direction() {
    let bounds = (0.0, 0.0, 10.0, 10.0);
    let (a, b) = clip_segment((-10.0, -10.0), (20.0, 20.0), bounds).unwrap();
    assert_eq!((a, b), ((0.0, 0.0), (10.0, 10.0)));
    let (a, b) = clip_segment((2.0, 3.0), (4.0, 5.0), bounds).unwrap();
    assert_eq!((a, b), ((2.0, 3.0), (4.0, 5.0)));
    assert_eq!(clip_segment((-5.0, 1.0), (-1.0, 9.0), bounds), None);
    assert_eq!(clip_segment((20.0, 5.0), (20.0, 5.0), bounds), None);
    let (a, b) = clip_segment((5.0, -1e30), (5.0, 1e30), bounds).unwrap();
    assert_eq!((a, b), ((5.0, 0.0), (5.0, 10.0)));
    let (a, b) = clip_segment((-1e7, 2.0), (1e7, 8.0), bounds).unwrap();
    assert_eq!((a.0, b.0), (0.0, 10.0));
    assert!(
        (a.1 - 5.0).abs() < 1e-5 && (b.1 - 5.0).abs() < 1e-5,
        "{a:?} {b:?}"
    );
}

#[test]
fn circles_are_round_and_centred() {
    let mut c = Canvas::new(21, 21, WHITE).unwrap();
    c.circle(10.5, 10.5, 4.0, RED);
    assert_eq!(c.pixel(10, 10), Some(RED));
    assert_eq!(c.pixel(10, 7), Some(RED));
    assert_eq!(c.pixel(10, 5), Some(WHITE));
    assert_eq!(c.pixel(6, 6), Some(WHITE));
    // Symmetric under mirroring and transposition, up to rounding in the coverage.
    let close = |p: Option<[u8; 3]>, q: Option<[u8; 3]>| {
        let (p, q) = (p.unwrap(), q.unwrap());
        (0..3).all(|i| p[i].abs_diff(q[i]) <= 2)
    };
    for y in 0..21 {
        for x in 0..21 {
            let p = c.pixel(x, y);
            assert!(close(p, c.pixel(20 - x, y)), "({x}, {y})");
            assert!(close(p, c.pixel(x, 20 - y)), "({x}, {y})");
            assert!(close(p, c.pixel(y, x)), "({x}, {y})");
        }
    }
}

#[test]
fn text_is_clipped_at_the_edges() {
    let mut full = Canvas::new(40, 20, WHITE).unwrap();
    full.text(10, 5, "Hi", 2, RED);
    let mut clipped = Canvas::new(40, 20, WHITE).unwrap();
    clipped.text(10 - 40, 5 - 20, "Hi", 2, RED);
    clipped.text(10 + 24, 5 + 8, "Hi", 2, RED);
    // The shifted copies show exactly the parts of the full text that stay inside.
    for y in 0..20 {
        for x in 0..40 {
            let from_full = |dx: i32, dy: i32| {
                let (sx, sy) = (x as i32 - dx, y as i32 - dy);
                (0..40).contains(&sx)
                    && (0..20).contains(&sy)
                    && full.pixel(sx as u32, sy as u32) == Some(RED)
            };
            let expected = from_full(-40, -20) || from_full(24, 8);
            assert_eq!(clipped.pixel(x, y) == Some(RED), expected, "({x}, {y})");
        }
    }
    assert_eq!(changed(&full, WHITE).len(), 4 * font::ink("Hi").count());
}

#[test]
fn vertical_text_reads_bottom_to_top() {
    let mut c = Canvas::new(16, 16, WHITE).unwrap();
    c.text_vertical(2, 3, "L", 1, RED);
    for y in 0..16 {
        for x in 0..16 {
            let (col, row) = (x as i32 - 2, y as i32 - 3);
            // Box pixel (col, row) shows text pixel (4 − row, col).
            let ink = (0..5).contains(&row)
                && col >= 0
                && font::is_ink('L', (4 - row) as u32, col as u32);
            let expected = if ink { RED } else { WHITE };
            assert_eq!(c.pixel(x, y), Some(expected), "({x}, {y})");
        }
    }
    // "ab": 'a' at the bottom, 'b' above it, the box 11 px tall.
    let mut c = Canvas::new(20, 20, WHITE).unwrap();
    c.text_vertical(0, 0, "ab", 1, RED);
    let ink = changed(&c, WHITE);
    assert!(ink.iter().all(|&(x, y)| x < font::GLYPH_HEIGHT && y < 11));
    // The top of 'b' (its ascender, text row 0) ends up in column 0, rows 0..=4.
    assert!(ink.contains(&(0, 4)) && !ink.iter().any(|&(x, y)| x == 0 && y >= 6));
}

#[test]
fn blit_copies_and_clips() {
    let image: Vec<u8> = (0..4 * 3 * 3).map(|i| i as u8).collect(); // 4×3 pixels
    let pixel = |x: u32, y: u32| {
        let i = ((y * 4 + x) * 3) as usize;
        [image[i], image[i + 1], image[i + 2]]
    };
    let mut c = Canvas::new(5, 5, WHITE).unwrap();
    c.blit_rgb8(-1, 3, 4, 3, &image).unwrap();
    for y in 0..5 {
        for x in 0..5 {
            let expected = if x < 3 && y >= 3 {
                pixel(x + 1, y - 3)
            } else {
                WHITE
            };
            assert_eq!(c.pixel(x, y), Some(expected), "({x}, {y})");
        }
    }
    let before = c.to_rgb8();
    let err = c.blit_rgb8(0, 0, 4, 4, &image).unwrap_err();
    assert!(matches!(err, PlotError::BufferLength { actual: 36, .. }));
    assert_eq!(c.to_rgb8(), before);
    c.blit_rgb8(0, 0, 0, 0, &[]).unwrap();
    c.blit_rgb8(5, 0, 4, 3, &image).unwrap();
    assert_eq!(c.to_rgb8(), before);
}

#[test]
fn png_round_trip_is_exact() {
    let mut c = Canvas::new(7, 5, [12, 34, 56]).unwrap();
    c.circle(3.0, 2.5, 2.0, RED);
    c.text(0, 0, "x", 1, [250, 251, 252]);
    let dir = TestDir::new("plot-canvas");
    let path = dir.path("c.png");
    c.write_png(&path).unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (7, 5));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(&buf[..info.buffer_size()], &c.to_rgb8()[..]);
}

#[test]
fn crop_magnify_replicates_pixels() {
    let image: Vec<u8> = (0..3 * 2 * 3).map(|i| i as u8).collect(); // 3×2 pixels
    let (crop, w, h) = crop_magnify(&image, 3, 2, 1, 0, 2, 2, 2).unwrap();
    assert_eq!((w, h), (4, 4));
    let source = |x: usize, y: usize| &image[(y * 3 + x) * 3..(y * 3 + x) * 3 + 3];
    for y in 0..4 {
        for x in 0..4 {
            let got = &crop[(y * 4 + x) * 3..(y * 4 + x) * 3 + 3];
            assert_eq!(got, source(1 + x / 2, y / 2), "({x}, {y})");
        }
    }
    // Clamped to the image: only the bottom-right pixel remains.
    let (crop, w, h) = crop_magnify(&image, 3, 2, 2, 1, 100, u32::MAX, 3).unwrap();
    assert_eq!((w, h), (3, 3));
    assert!(crop.chunks_exact(3).all(|p| p == source(2, 1)));
    // Factor 1 of the whole image is the image.
    assert_eq!(crop_magnify(&image, 3, 2, 0, 0, 3, 2, 1).unwrap().0, image);
}

#[test]
fn crop_magnify_errors() {
    let image = vec![0u8; 3 * 2 * 3];
    let empty = |x0, y0, w, h| crop_magnify(&image, 3, 2, x0, y0, w, h, 2).unwrap_err();
    for (x0, y0, w, h) in [
        (3, 0, 1, 1),
        (0, 2, 1, 1),
        (0, 0, 0, 1),
        (u32::MAX, 0, 9, 9),
    ] {
        assert!(matches!(empty(x0, y0, w, h), PlotError::EmptyCrop { .. }));
    }
    assert_eq!(
        crop_magnify(&image, 3, 2, 0, 0, 1, 1, 0).unwrap_err(),
        PlotError::ZeroFactor
    );
    assert!(matches!(
        crop_magnify(&image, 3, 3, 0, 0, 1, 1, 1).unwrap_err(),
        PlotError::BufferLength { .. }
    ));
    assert!(matches!(
        crop_magnify(&image, 3, 2, 0, 0, 3, 2, MAX_SIDE).unwrap_err(),
        PlotError::Size { width: 49152, .. }
    ));
}
