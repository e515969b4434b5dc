//! Tests of [`canvas`](crate::plot::canvas): every drawing operation, clipping, degenerate
//! and extreme input, PNG output, and cropping.

use crate::output::atomic::tests::TestDir;
use crate::plot::PlotError;
use crate::plot::canvas::*;

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
    assert!(changed(&c, WHITE).is_empty());
}

#[test]
fn extreme_values_do_not_panic() {
    let mut c = Canvas::new(16, 16, WHITE).unwrap();
    let big = f32::MAX;
    c.fill_rect(-big, -big, big, big, RED);
    c.stroke_rect(-1e30, -1e30, 2e30, 2e30, RED, 1e30);
    c.blit_rgb8(i32::MIN, i32::MAX, 1, 1, &[0, 0, 0]).unwrap();
    // The huge frame covers everything.
    assert_eq!(c.pixel(0, 0), Some(RED));
    assert_eq!(c.pixel(15, 15), Some(RED));
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
    c.fill_rect(2.0, 1.0, 3.0, 2.0, RED);
    c.fill_rect(0.0, 0.0, 1.0, 1.0, [250, 251, 252]);
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
