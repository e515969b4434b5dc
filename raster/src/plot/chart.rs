//! Line charts of error against time: one coloured line per method, linear or logarithmic
//! axes.
//!
//! [`render_chart`] draws a [`Chart`] on a white [`Canvas`]: the title on top, a framed plot
//! area with light grid lines, ticks and tick labels, the axis labels, each [`Series`] as a
//! line through its points (sorted by x) with a marker on every point, and a legend in the
//! corner of the plot area that hides the least data (top-right when that is free, as it is
//! for falling error curves). Colours come from [`PALETTE`], cycling.
//!
//! A point is drawable when both coordinates are finite and, on a logarithmic axis,
//! positive; the rest are skipped. The axes span the drawable points with a little room
//! (see [`Axis`]). With no drawable point at all, the chart shows its frame and "no data".
//!
//! The axes, their ranges and ticks are in [`axis`](super::axis).
//!
//! [`chart_layout`] exposes the geometry — the plot rectangle and [`ChartLayout::data_to_pixel`]
//! — so callers and tests can find where a data point is drawn.

use super::axis::Axis;
use super::canvas::Canvas;
use super::font::{self, text_width};
use super::{MAX_SIDE, PlotError};

/// The series colours, used in order and then repeated: ten hues that stay distinguishable
/// on white (and for the common forms of colour blindness, for the first six).
pub const PALETTE: [[u8; 3]; 10] = [
    [0, 114, 178],   // blue
    [213, 94, 0],    // vermilion
    [0, 158, 115],   // bluish green
    [204, 121, 167], // reddish purple
    [230, 159, 0],   // orange
    [86, 180, 233],  // sky blue
    [0, 0, 0],       // black
    [140, 86, 75],   // brown
    [148, 103, 189], // violet
    [127, 127, 127], // grey
];

pub(super) const BACKGROUND: [u8; 3] = [255, 255, 255];
pub(super) const INK: [u8; 3] = [25, 25, 25];
pub(super) const TICK_INK: [u8; 3] = [70, 70, 70];
pub(super) const GRID: [u8; 3] = [226, 226, 226];
pub(super) const FRAME: [u8; 3] = [60, 60, 60];
pub(super) const LEGEND_FRAME: [u8; 3] = [170, 170, 170];

/// One line of a chart.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// The name shown in the legend.
    pub label: String,
    /// The data points `(x, y)`, in any order.
    pub points: Vec<(f64, f64)>,
}

/// A line chart: what [`render_chart`] draws.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Chart {
    /// The title above the plot (may be empty).
    pub title: String,
    /// The label below the x axis (may be empty).
    pub x_label: String,
    /// The label left of the y axis, drawn reading upwards (may be empty).
    pub y_label: String,
    /// The lines, drawn in order (later ones on top), coloured from [`PALETTE`].
    pub series: Vec<Series>,
    /// Whether the x axis is logarithmic.
    pub log_x: bool,
    /// Whether the y axis is logarithmic.
    pub log_y: bool,
}

/// Where everything of a chart goes, computed by [`chart_layout`].
#[derive(Debug, Clone, PartialEq)]
pub struct ChartLayout {
    /// The canvas width in pixels.
    pub width: u32,
    /// The canvas height in pixels.
    pub height: u32,
    /// The left edge of the plot area in pixels (the frame is drawn just outside it).
    pub plot_left: f32,
    /// The top edge of the plot area in pixels.
    pub plot_top: f32,
    /// The width of the plot area in pixels.
    pub plot_width: f32,
    /// The height of the plot area in pixels.
    pub plot_height: f32,
    /// The horizontal axis.
    pub x: Axis,
    /// The vertical axis.
    pub y: Axis,
    /// Whether any point is drawable; if not, the chart says "no data".
    pub has_data: bool,
    /// The font scale of tick labels, axis labels and legend (the title uses twice this).
    pub text_scale: u32,
}

impl ChartLayout {
    /// The canvas position of the data point (`x`, `y`): the left edge of the plot area is
    /// `x.min`, the right edge `x.max`, the bottom edge `y.min`, the top edge `y.max`.
    /// `None` for a point that is not drawable, or when the chart has no data.
    pub fn data_to_pixel(&self, x: f64, y: f64) -> Option<(f32, f32)> {
        if !self.has_data {
            return None;
        }
        let fx = self.x.fraction(x)?;
        let fy = self.y.fraction(y)?;
        let px = f64::from(self.plot_left) + fx * f64::from(self.plot_width);
        let py = f64::from(self.plot_top) + (1.0 - fy) * f64::from(self.plot_height);
        Some((px as f32, py as f32))
    }
}

/// Computes the layout of `chart` on a `width × height` canvas. Fails with
/// [`PlotError::Size`] when a side is 0 or larger than [`MAX_SIDE`].
pub fn chart_layout(chart: &Chart, width: u32, height: u32) -> Result<ChartLayout, PlotError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(PlotError::Size {
            width: width.into(),
            height: height.into(),
        });
    }
    let mut bounds: Option<[f64; 4]> = None;
    for s in &chart.series {
        for &(x, y) in &s.points {
            if drawable(chart, x, y) {
                let b = bounds.get_or_insert([x, x, y, y]);
                *b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
            }
        }
    }
    let has_data = bounds.is_some();
    let [x0, x1, y0, y1] = bounds.unwrap_or([1.0, 10.0, 1.0, 10.0]);
    let x = Axis::fit(x0, x1, chart.log_x);
    let y = Axis::fit(y0, y1, chart.log_y);

    let s = (width.min(height) / 400).max(1);
    let line = font::text_height(s);
    let y_tick_width = if has_data {
        y.ticks()
            .iter()
            .map(|(_, l)| text_width(l, s))
            .max()
            .unwrap_or(0)
    } else {
        0
    };
    let last_x_tick = x.ticks().last().map_or(0, |(_, l)| text_width(l, s));
    let title = if chart.title.is_empty() {
        0
    } else {
        font::text_height(2 * s) + 8 * s
    };
    let y_label = if chart.y_label.is_empty() {
        0
    } else {
        line + 8 * s
    };
    let x_label = if chart.x_label.is_empty() {
        0
    } else {
        line + 6 * s
    };
    let left = 10 * s + y_label + y_tick_width + 9 * s;
    let right = (12 * s).max(last_x_tick / 2 + 6 * s);
    let top = 10 * s + title;
    let bottom = 9 * s + line + x_label + 10 * s;
    Ok(ChartLayout {
        width,
        height,
        plot_left: left as f32,
        plot_top: top as f32,
        plot_width: width.saturating_sub(left + right).max(1) as f32,
        plot_height: height.saturating_sub(top + bottom).max(1) as f32,
        x,
        y,
        has_data,
        text_scale: s,
    })
}

fn drawable(chart: &Chart, x: f64, y: f64) -> bool {
    x.is_finite() && y.is_finite() && (!chart.log_x || x > 0.0) && (!chart.log_y || y > 0.0)
}

/// Draws `chart` on a new `width × height` canvas (see the [module documentation](self)).
///
/// Fails only with [`PlotError::Size`] for a side of 0 or more than [`MAX_SIDE`]; any data,
/// including NaN, infinities and non-positive values on logarithmic axes, draws a chart.
pub fn render_chart(chart: &Chart, width: u32, height: u32) -> Result<Canvas, PlotError> {
    let layout = chart_layout(chart, width, height)?;
    let mut canvas = Canvas::new(width, height, BACKGROUND)?;
    let s = layout.text_scale;
    let sf = s as f32;
    let (left, top) = (layout.plot_left, layout.plot_top);
    let (pw, ph) = (layout.plot_width, layout.plot_height);
    let line = font::text_height(s) as i32;

    let title_x = centred(0.0, width as f32, text_width(&chart.title, 2 * s));
    canvas.text(title_x, 10 * s as i32, &chart.title, 2 * s, INK);

    // Each series as canvas positions, sorted by x.
    let lines: Vec<Vec<(f32, f32)>> = chart
        .series
        .iter()
        .map(|series| {
            let mut points: Vec<(f64, f64)> = series
                .points
                .iter()
                .copied()
                .filter(|&(x, y)| drawable(chart, x, y))
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            points
                .iter()
                .filter_map(|&(x, y)| layout.data_to_pixel(x, y))
                .collect()
        })
        .collect();
    if layout.has_data {
        draw_ticks(&mut canvas, &layout);
        for (index, pixels) in lines.iter().enumerate() {
            let colour = PALETTE[index % PALETTE.len()];
            canvas.stroke_polyline(pixels, colour, 1.5 * sf);
            for &(px, py) in pixels {
                canvas.circle(px, py, marker_radius(s), colour);
            }
        }
    }
    canvas.stroke_rect(left - 1.0, top - 1.0, pw + 2.0, ph + 2.0, FRAME, 1.0);

    let x_label_x = centred(left, pw, text_width(&chart.x_label, s));
    let x_label_y = (top + ph) as i32 + 9 * s as i32 + line + 6 * s as i32;
    canvas.text(x_label_x, x_label_y, &chart.x_label, s, INK);
    let y_label_y = centred(top, ph, text_width(&chart.y_label, s));
    canvas.text_vertical(10 * s as i32, y_label_y, &chart.y_label, s, INK);

    if layout.has_data {
        draw_legend(&mut canvas, chart, &layout, &lines);
    } else {
        let message = "no data";
        let x = centred(left, pw, text_width(message, 2 * s));
        let y = centred(top, ph, font::text_height(2 * s));
        canvas.text(x, y, message, 2 * s, TICK_INK);
    }
    Ok(canvas)
}

/// The start of something `size` pixels long centred in `space` pixels from `start`
/// (saturating at the ends of the `i32` range, however long the text).
fn centred(start: f32, space: f32, size: u32) -> i32 {
    (f64::from(start) + (f64::from(space) - f64::from(size)) / 2.0).floor() as i32
}

/// Grid lines, tick marks and tick labels of both axes.
fn draw_ticks(canvas: &mut Canvas, layout: &ChartLayout) {
    let s = layout.text_scale;
    let tick = 5.0 * s as f32;
    let (left, top) = (layout.plot_left, layout.plot_top);
    let bottom = top + layout.plot_height;
    let to_px = |axis: &Axis, a: f64, start: f32, length: f32| start + axis.unit(a) as f32 * length;
    let mut label_end = i32::MIN;
    for (a, label) in layout.x.ticks() {
        let px = to_px(&layout.x, a, left, layout.plot_width).round();
        canvas.fill_rect(px, top, 1.0, layout.plot_height, GRID);
        canvas.fill_rect(px, bottom + 1.0, 1.0, tick, FRAME);
        let w = text_width(&label, s) as i32;
        let label_left = px as i32 - w / 2;
        // Skip a label that would run into the previous one.
        if label_left > label_end {
            canvas.text(
                label_left,
                (bottom + 1.0 + tick) as i32 + 3 * s as i32,
                &label,
                s,
                TICK_INK,
            );
            label_end = label_left + w + 2 * font::ADVANCE as i32 * s as i32;
        }
    }
    for a in layout.x.minor_ticks() {
        let px = to_px(&layout.x, a, left, layout.plot_width).round();
        canvas.fill_rect(px, bottom + 1.0, 1.0, tick / 2.0, FRAME);
    }
    let line = font::text_height(s) as i32;
    let mut label_top = i32::MAX;
    for (a, label) in layout.y.ticks() {
        let py = to_px(&layout.y, a, bottom, -layout.plot_height).round();
        canvas.fill_rect(left, py, layout.plot_width, 1.0, GRID);
        canvas.fill_rect(left - 1.0 - tick, py, tick, 1.0, FRAME);
        let w = text_width(&label, s) as i32;
        let y = py as i32 - line / 2;
        // Skip a label that would run into the one below.
        if y + line + s as i32 <= label_top {
            canvas.text(
                (left - 1.0 - tick) as i32 - 3 * s as i32 - w,
                y,
                &label,
                s,
                TICK_INK,
            );
            label_top = y;
        }
    }
    for a in layout.y.minor_ticks() {
        let py = to_px(&layout.y, a, bottom, -layout.plot_height).round();
        canvas.fill_rect(left - 1.0 - tick / 2.0, py, tick / 2.0, 1.0, FRAME);
    }
}

/// The radius of the marker on every data point at text scale `s`.
fn marker_radius(s: u32) -> f32 {
    1.5 + 1.5 * s as f32
}

/// The legend: a box listing every series' colour and label, in the corner of the plot area
/// (top-right, top-left, bottom-left or bottom-right, preferred in that order) that hides the
/// least of the lines.
fn draw_legend(
    canvas: &mut Canvas,
    chart: &Chart,
    layout: &ChartLayout,
    lines: &[Vec<(f32, f32)>],
) {
    if chart.series.is_empty() {
        return;
    }
    let scale = layout.text_scale;
    let s = scale as f32;
    let label_width = chart
        .series
        .iter()
        .map(|series| text_width(&series.label, scale))
        .max()
        .unwrap_or(0) as f32;
    let (pad, swatch, row) = (6.0 * s, 20.0 * s, font::text_height(scale) as f32 + 5.0 * s);
    let box_w = pad + swatch + pad + label_width + pad;
    let box_h = pad + row * chart.series.len() as f32 - 5.0 * s + pad;
    let inset = 8.0 * s;
    let (left, top) = (layout.plot_left + inset, layout.plot_top + inset);
    let right = layout.plot_left + layout.plot_width - inset - box_w;
    let bottom = layout.plot_top + layout.plot_height - inset - box_h;
    let corners = [(right, top), (left, top), (left, bottom), (right, bottom)];
    let margin = marker_radius(scale) + 2.0;
    let hidden = |&(x, y): &(f32, f32)| {
        let inside = |(px, py): (f32, f32)| {
            px >= x - margin
                && px <= x + box_w + margin
                && py >= y - margin
                && py <= y + box_h + margin
        };
        lines
            .iter()
            .map(|line| covered_samples(line, &inside))
            .sum::<usize>()
    };
    let mut best = corners[0];
    let mut least = hidden(&best);
    for corner in &corners[1..] {
        let count = hidden(corner);
        if count < least {
            (best, least) = (*corner, count);
        }
    }
    let (box_x, box_y) = (best.0.round(), best.1.round());
    canvas.fill_rect(box_x, box_y, box_w, box_h, BACKGROUND);
    canvas.stroke_rect(box_x, box_y, box_w, box_h, LEGEND_FRAME, 1.0);
    for (index, series) in chart.series.iter().enumerate() {
        let colour = PALETTE[index % PALETTE.len()];
        let row_top = box_y + pad + row * index as f32;
        let mid = row_top + (font::CAP_HEIGHT as f32 * s) / 2.0;
        let x0 = box_x + pad;
        canvas.stroke_polyline(&[(x0, mid), (x0 + swatch, mid)], colour, 1.5 * s);
        canvas.circle(x0 + swatch / 2.0, mid, marker_radius(scale), colour);
        canvas.text(
            (x0 + swatch + pad) as i32,
            row_top as i32,
            &series.label,
            scale,
            INK,
        );
    }
}

/// How many samples of the polyline `line` — its points, and points every 4 pixels or so
/// along its segments — satisfy `inside`.
fn covered_samples(line: &[(f32, f32)], inside: &impl Fn((f32, f32)) -> bool) -> usize {
    let mut count = line.iter().filter(|&&p| inside(p)).count();
    for pair in line.windows(2) {
        let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
        let steps = ((x1 - x0).hypot(y1 - y0) / 4.0).clamp(1.0, 64.0) as usize;
        count += (1..steps)
            .map(|i| i as f32 / steps as f32)
            .filter(|t| inside((x0 + t * (x1 - x0), y0 + t * (y1 - y0))))
            .count();
    }
    count
}
