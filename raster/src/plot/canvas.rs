//! [`Canvas`]: an opaque 8-bit RGB drawing surface over a `tiny_skia::Pixmap`.
//!
//! Rectangles are filled without anti-aliasing so that frames stay crisp; images are copied
//! pixel for pixel. All colours are opaque sRGB bytes, so the canvas stays opaque and
//! [`Canvas::to_rgb8`] is exact. (Text and charts are SVG: [`chart`](super::chart).)
//!
//! Drawing never fails and never panics: shapes are clipped to the canvas, and non-finite
//! coordinates or non-positive sizes draw nothing. Only construction and image copies, which
//! can be handed inconsistent sizes, return a [`PlotError`].
//!
//! [`crop_magnify`] cuts a rectangle out of an RGB image and enlarges it by pixel
//! replication, for the magnified insets of a contact sheet.

use std::path::Path;

use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

use super::{PlotError, check_rgb_len};
use crate::output::OutputError;
use crate::output::png::write_png_rgb8;

/// The largest width or height, in pixels, of a canvas or of an image made by this module.
pub const MAX_SIDE: u32 = 16384;

/// An opaque RGB image to draw on. See the [module documentation](self).
#[derive(Debug, Clone)]
pub struct Canvas {
    pixmap: Pixmap,
}

impl Canvas {
    /// A `width × height` canvas filled with `background`.
    ///
    /// Fails with [`PlotError::Size`] when a side is 0 or larger than [`MAX_SIDE`].
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Result<Self, PlotError> {
        let size_error = PlotError::Size {
            width: width.into(),
            height: height.into(),
        };
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(size_error);
        }
        let mut pixmap = Pixmap::new(width, height).ok_or(size_error)?;
        pixmap.fill(color(background));
        Ok(Canvas { pixmap })
    }

    /// The width in pixels.
    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    /// The height in pixels.
    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// The colour of the pixel at (`x`, `y`), or `None` outside the canvas.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        let p = self.pixmap.pixel(x, y)?.demultiply();
        Some([p.red(), p.green(), p.blue()])
    }

    /// Fills the rectangle with corners (`x`, `y`) and (`x + w`, `y + h`) with `rgb`.
    ///
    /// Not anti-aliased: a pixel is covered when its centre is inside, so rectangles on whole
    /// pixel coordinates are exact. Draws nothing for non-finite values or `w, h ≤ 0`; the
    /// corners may otherwise be anywhere.
    pub fn fill_rect(&mut self, x: f32, y: f32, w: f32, h: f32, rgb: [u8; 3]) {
        let finite = x.is_finite() && y.is_finite() && w.is_finite() && h.is_finite();
        if !(finite && w > 0.0 && h > 0.0) {
            return;
        }
        // Clip to a little more than the canvas first, so that huge rectangles stay in the
        // range where tiny-skia's fixed-point arithmetic is exact.
        let limit_x = self.width() as f32 + 1.0;
        let limit_y = self.height() as f32 + 1.0;
        let (left, right) = (x.max(-1.0), (x + w).min(limit_x));
        let (top, bottom) = (y.max(-1.0), (y + h).min(limit_y));
        let Some(rect) = Rect::from_ltrb(left, top, right, bottom) else {
            return;
        };
        let mut paint = paint(rgb);
        paint.anti_alias = false;
        self.pixmap
            .fill_rect(rect, &paint, Transform::identity(), None);
    }

    /// Draws the outline of a rectangle, `line_width` pixels thick, inside the rectangle
    /// with corners (`x`, `y`) and (`x + w`, `y + h`). Like [`fill_rect`](Self::fill_rect),
    /// not anti-aliased.
    pub fn stroke_rect(&mut self, x: f32, y: f32, w: f32, h: f32, rgb: [u8; 3], line_width: f32) {
        if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0 && line_width > 0.0) {
            return;
        }
        let t = line_width.min(w / 2.0).min(h / 2.0);
        self.fill_rect(x, y, w, t, rgb);
        self.fill_rect(x, y + h - t, w, t, rgb);
        self.fill_rect(x, y + t, t, h - 2.0 * t, rgb);
        self.fill_rect(x + w - t, y + t, t, h - 2.0 * t, rgb);
    }

    /// Copies an 8-bit RGB image (`width × height` pixels, row-major, 3 bytes per pixel)
    /// with its top-left corner at (`x`, `y`), clipped to the canvas.
    ///
    /// Fails with [`PlotError::BufferLength`] when `rgb` does not hold `3 · width · height`
    /// bytes; nothing is drawn then.
    pub fn blit_rgb8(
        &mut self,
        x: i32,
        y: i32,
        width: u32,
        height: u32,
        rgb: &[u8],
    ) -> Result<(), PlotError> {
        check_rgb_len(width, height, rgb)?;
        let (canvas_w, canvas_h) = (i64::from(self.width()), i64::from(self.height()));
        let (x, y) = (i64::from(x), i64::from(y));
        // Source columns and rows that land on the canvas.
        let col0 = (-x).clamp(0, i64::from(width));
        let col1 = (canvas_w - x).clamp(col0, i64::from(width));
        let row0 = (-y).clamp(0, i64::from(height));
        let row1 = (canvas_h - y).clamp(row0, i64::from(height));
        let run = (col1 - col0) as usize * 3;
        let data = self.pixmap.data_mut();
        for row in row0..row1 {
            let src = (row as usize * width as usize + col0 as usize) * 3;
            let dst = (((y + row) * canvas_w + x + col0) * 4) as usize;
            let source = rgb[src..src + run].chunks_exact(3);
            let target = data[dst..dst + run / 3 * 4].chunks_exact_mut(4);
            for (out, pixel) in target.zip(source) {
                out.copy_from_slice(&[pixel[0], pixel[1], pixel[2], 255]);
            }
        }
        Ok(())
    }

    /// The canvas as 8-bit RGB bytes, row-major, top row first.
    pub fn to_rgb8(&self) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(self.pixmap.pixels().len() * 3);
        for p in self.pixmap.pixels() {
            let c = p.demultiply();
            bytes.extend_from_slice(&[c.red(), c.green(), c.blue()]);
        }
        bytes
    }

    /// Writes the canvas as an 8-bit RGB PNG, atomically (see
    /// [`write_png_rgb8`]).
    pub fn write_png(&self, path: &Path) -> Result<(), OutputError> {
        write_png_rgb8(path, self.width(), self.height(), &self.to_rgb8())
    }
}

/// The opaque tiny-skia colour of `rgb`.
fn color(rgb: [u8; 3]) -> Color {
    Color::from_rgba8(rgb[0], rgb[1], rgb[2], 255)
}

/// An anti-aliased solid paint of `rgb`.
fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(color(rgb));
    paint.anti_alias = true;
    paint
}

/// Cuts the rectangle at (`x0`, `y0`) of `w × h` pixels out of an 8-bit RGB image of
/// `width × height` pixels and enlarges it `factor` times by pixel replication (nearest
/// neighbour). Returns the crop's bytes, width and height.
///
/// The rectangle is clamped to the image, so the crop may be smaller than `w × h`. Fails
/// when `rgb` has the wrong length ([`PlotError::BufferLength`]), `factor` is 0
/// ([`PlotError::ZeroFactor`]), the clamped rectangle is empty ([`PlotError::EmptyCrop`]), or
/// the enlarged crop would have a side longer than [`MAX_SIDE`] ([`PlotError::Size`]).
pub fn crop_magnify(
    rgb: &[u8],
    width: u32,
    height: u32,
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
    factor: u32,
) -> Result<(Vec<u8>, u32, u32), PlotError> {
    check_rgb_len(width, height, rgb)?;
    if factor == 0 {
        return Err(PlotError::ZeroFactor);
    }
    let crop_w = x0.saturating_add(w).min(width).saturating_sub(x0);
    let crop_h = y0.saturating_add(h).min(height).saturating_sub(y0);
    if crop_w == 0 || crop_h == 0 {
        return Err(PlotError::EmptyCrop {
            x0,
            y0,
            w,
            h,
            width,
            height,
        });
    }
    let out_w = u64::from(crop_w) * u64::from(factor);
    let out_h = u64::from(crop_h) * u64::from(factor);
    if out_w > u64::from(MAX_SIDE) || out_h > u64::from(MAX_SIDE) {
        return Err(PlotError::Size {
            width: out_w,
            height: out_h,
        });
    }
    let (out_w, out_h) = (out_w as usize, out_h as usize);
    let mut out = Vec::with_capacity(out_w * out_h * 3);
    let mut line = Vec::with_capacity(out_w * 3);
    for row in 0..crop_h as usize {
        line.clear();
        let start = ((y0 as usize + row) * width as usize + x0 as usize) * 3;
        for pixel in rgb[start..start + crop_w as usize * 3].chunks_exact(3) {
            for _ in 0..factor {
                line.extend_from_slice(pixel);
            }
        }
        for _ in 0..factor {
            out.extend_from_slice(&line);
        }
    }
    Ok((out, out_w as u32, out_h as u32))
}
