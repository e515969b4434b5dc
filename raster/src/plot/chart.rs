//! Line charts of error against time, as SVG: one coloured line per method, linear or
//! logarithmic axes.
//!
//! [`render_chart`] writes a [`Chart`] as an SVG document of `width × height` user units
//! (pixels): the title on top, a framed plot area with light grid lines, ticks and tick
//! labels, the axis labels, each [`Series`] as a polyline through its points (sorted by x)
//! with a marker on every point, and a legend in the corner of the plot area that hides the
//! least data (top-right when that is free, as it is for falling error curves). Colours come
//! from [`PALETTE`], cycling. Text is SVG `<text>` in a sans-serif font: the viewer draws it.
//!
//! ```text
//! <svg width=W height=H viewBox="0 0 W H">
//!   <rect/> background     <text/> title
//!   <g class="grid">…      <g class="ticks">… tick marks and labels
//!   <g class="series" data-label="…"><title>…</title><polyline/><circle/>…</g>  per series
//!   <rect/> frame          <text/> axis labels     <g class="legend">…
//! </svg>
//! ```
//!
//! A point is drawable when both coordinates are finite and, on a logarithmic axis,
//! positive; the rest are skipped, so every number in the document is finite. The axes span
//! the drawable points with a little room (see [`Axis`]). With no drawable point at all, the
//! chart shows its frame and "no data".
//!
//! [`chart_layout`] exposes the geometry — the plot rectangle and [`ChartLayout::data_to_pixel`]
//! — so callers and tests can find where a data point is drawn. Text widths in the layout are
//! estimates ([`TEXT_ADVANCE`] em per character): the margins leave room for the labels in
//! any common sans-serif font.

use std::fmt::Write as _;

use super::axis::Axis;
use super::xml::escape;
use super::{MAX_SIDE, PlotError};

/// The estimated advance of one character, in em: a little wider than the average of the
/// common sans-serif fonts for digits and lower case, so that labels fit their margins.
pub const TEXT_ADVANCE: f32 = 0.6;

/// The font size of tick labels, axis labels and legend at text scale 1 (the title is 1.5×).
pub const FONT_SIZE: f32 = 12.0;

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
    /// The drawing's width in pixels (SVG user units).
    pub width: u32,
    /// The drawing's height in pixels.
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
    /// The text scale: tick labels, axis labels and legend are [`FONT_SIZE`] × this, the
    /// title 1.5 times that.
    pub text_scale: u32,
}

impl ChartLayout {
    /// The drawing position of the data point (`x`, `y`): the left edge of the plot area is
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

/// The estimated width of `text` at font size `size` (see [`TEXT_ADVANCE`]).
pub fn text_width(text: &str, size: f32) -> f32 {
    text.chars().count() as f32 * TEXT_ADVANCE * size
}

/// Computes the layout of `chart` on a `width × height` drawing. Fails with
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
    let sf = s as f32;
    let size = FONT_SIZE * sf;
    let line = size * 1.2;
    let y_tick_width = if has_data {
        y.ticks()
            .iter()
            .map(|(_, l)| text_width(l, size))
            .fold(0.0, f32::max)
    } else {
        0.0
    };
    let last_x_tick = x.ticks().last().map_or(0.0, |(_, l)| text_width(l, size));
    let title = if chart.title.is_empty() {
        0.0
    } else {
        1.5 * line + 8.0 * sf
    };
    let y_label = if chart.y_label.is_empty() {
        0.0
    } else {
        line + 8.0 * sf
    };
    let x_label = if chart.x_label.is_empty() {
        0.0
    } else {
        line + 6.0 * sf
    };
    let left = (10.0 * sf + y_label + y_tick_width + 9.0 * sf).ceil();
    let right = (12.0 * sf).max(last_x_tick / 2.0 + 6.0 * sf).ceil();
    let top = (10.0 * sf + title).ceil();
    let bottom = (9.0 * sf + line + x_label + 10.0 * sf).ceil();
    Ok(ChartLayout {
        width,
        height,
        plot_left: left,
        plot_top: top,
        plot_width: (width as f32 - left - right).max(1.0),
        plot_height: (height as f32 - top - bottom).max(1.0),
        x,
        y,
        has_data,
        text_scale: s,
    })
}

fn drawable(chart: &Chart, x: f64, y: f64) -> bool {
    x.is_finite() && y.is_finite() && (!chart.log_x || x > 0.0) && (!chart.log_y || y > 0.0)
}

/// `#rrggbb`.
fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

/// A `<text>` element at (`x`, `y`) (the baseline), anchored `start`, `middle` or `end`.
fn text(svg: &mut String, x: f32, y: f32, anchor: &str, size: f32, rgb: [u8; 3], body: &str) {
    if body.is_empty() {
        return;
    }
    let _ = writeln!(
        svg,
        r#"<text x="{x:.1}" y="{y:.1}" text-anchor="{anchor}" font-size="{size:.1}" fill="{}">{}</text>"#,
        hex(rgb),
        escape(body)
    );
}

/// Writes `chart` as an SVG document of `width × height` (see the [module
/// documentation](self)).
///
/// Fails only with [`PlotError::Size`] for a side of 0 or more than [`MAX_SIDE`]; any data,
/// including NaN, infinities and non-positive values on logarithmic axes, makes a chart.
pub fn render_chart(chart: &Chart, width: u32, height: u32) -> Result<String, PlotError> {
    let layout = chart_layout(chart, width, height)?;
    let s = layout.text_scale as f32;
    let size = FONT_SIZE * s;
    let (left, top) = (layout.plot_left, layout.plot_top);
    let (pw, ph) = (layout.plot_width, layout.plot_height);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">
<rect width="{width}" height="{height}" fill="{}"/>"#,
        hex(BACKGROUND)
    );
    text(
        &mut svg,
        width as f32 / 2.0,
        10.0 * s + 1.5 * size,
        "middle",
        1.5 * size,
        INK,
        &chart.title,
    );

    // Each series as drawing positions, sorted by x.
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
        draw_ticks(&mut svg, &layout);
        for (index, (series, pixels)) in chart.series.iter().zip(&lines).enumerate() {
            let colour = hex(PALETTE[index % PALETTE.len()]);
            let label = escape(&series.label);
            let _ = writeln!(
                svg,
                r#"<g class="series" data-label="{label}" stroke="{colour}" fill="{colour}"><title>{label}</title>"#
            );
            if pixels.len() > 1 {
                let points: Vec<String> = pixels
                    .iter()
                    .map(|(x, y)| format!("{x:.2},{y:.2}"))
                    .collect();
                let _ = writeln!(
                    svg,
                    r#"<polyline fill="none" stroke-width="{:.1}" stroke-linejoin="round" points="{}"/>"#,
                    1.5 * s,
                    points.join(" ")
                );
            }
            for &(px, py) in pixels {
                let _ = writeln!(
                    svg,
                    r#"<circle cx="{px:.2}" cy="{py:.2}" r="{:.1}" stroke="none"/>"#,
                    marker_radius(layout.text_scale)
                );
            }
            svg.push_str("</g>\n");
        }
    }
    let _ = writeln!(
        svg,
        r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="{}" stroke-width="1"/>"#,
        left - 0.5,
        top - 0.5,
        pw + 1.0,
        ph + 1.0,
        hex(FRAME)
    );

    let x_label_y = top + ph + 9.0 * s + 1.2 * size + 6.0 * s + size;
    text(
        &mut svg,
        left + pw / 2.0,
        x_label_y,
        "middle",
        size,
        INK,
        &chart.x_label,
    );
    if !chart.y_label.is_empty() {
        let (x, y) = (10.0 * s + size, top + ph / 2.0);
        let _ = writeln!(
            svg,
            r#"<text x="{x:.1}" y="{y:.1}" text-anchor="middle" font-size="{size:.1}" fill="{}" transform="rotate(-90 {x:.1} {y:.1})">{}</text>"#,
            hex(INK),
            escape(&chart.y_label)
        );
    }

    if layout.has_data {
        draw_legend(&mut svg, chart, &layout, &lines);
    } else {
        text(
            &mut svg,
            left + pw / 2.0,
            top + ph / 2.0 + size,
            "middle",
            2.0 * size,
            TICK_INK,
            "no data",
        );
    }
    svg.push_str("</svg>\n");
    Ok(svg)
}

/// Grid lines, tick marks and tick labels of both axes.
fn draw_ticks(svg: &mut String, layout: &ChartLayout) {
    let s = layout.text_scale as f32;
    let size = FONT_SIZE * s;
    let tick = 5.0 * s;
    let (left, top) = (layout.plot_left, layout.plot_top);
    let bottom = top + layout.plot_height;
    let right = left + layout.plot_width;
    let to_px = |axis: &Axis, a: f64, start: f32, length: f32| start + axis.unit(a) as f32 * length;
    let mut grid = String::new();
    let mut marks = String::new();
    let mut labels = String::new();
    let mut label_end = f32::NEG_INFINITY;
    for (a, label) in layout.x.ticks() {
        let px = to_px(&layout.x, a, left, layout.plot_width).round() + 0.5;
        let _ = write!(grid, "M{px:.1} {top:.1}V{bottom:.1}");
        let _ = write!(marks, "M{px:.1} {:.1}v{tick:.1}", bottom + 0.5);
        let w = text_width(&label, size);
        // Skip a label that would run into the previous one.
        if px - w / 2.0 > label_end {
            text(
                &mut labels,
                px,
                bottom + tick + 3.0 * s + size,
                "middle",
                size,
                TICK_INK,
                &label,
            );
            label_end = px + w / 2.0 + TEXT_ADVANCE * size;
        }
    }
    for a in layout.x.minor_ticks() {
        let px = to_px(&layout.x, a, left, layout.plot_width).round() + 0.5;
        let _ = write!(marks, "M{px:.1} {:.1}v{:.1}", bottom + 0.5, tick / 2.0);
    }
    let mut label_top = f32::INFINITY;
    for (a, label) in layout.y.ticks() {
        let py = to_px(&layout.y, a, bottom, -layout.plot_height).round() + 0.5;
        let _ = write!(grid, "M{left:.1} {py:.1}H{right:.1}");
        let _ = write!(marks, "M{:.1} {py:.1}h{tick:.1}", left - 0.5 - tick);
        // Skip a label that would run into the one below.
        let baseline = py + 0.35 * size;
        if baseline + 0.2 * size <= label_top {
            text(
                &mut labels,
                left - tick - 3.0 * s,
                baseline,
                "end",
                size,
                TICK_INK,
                &label,
            );
            label_top = baseline - 1.2 * size;
        }
    }
    for a in layout.y.minor_ticks() {
        let py = to_px(&layout.y, a, bottom, -layout.plot_height).round() + 0.5;
        let _ = write!(
            marks,
            "M{:.1} {py:.1}h{:.1}",
            left - 0.5 - tick / 2.0,
            tick / 2.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<path class="grid" d="{grid}" stroke="{}" stroke-width="1" fill="none"/>
<path class="ticks" d="{marks}" stroke="{}" stroke-width="1" fill="none"/>
<g class="tick-labels">
{labels}</g>"#,
        hex(GRID),
        hex(FRAME)
    );
}

/// The radius of the marker on every data point at text scale `s`.
fn marker_radius(s: u32) -> f32 {
    1.5 + 1.5 * s as f32
}

/// The legend: a box listing every series' colour and label, in the corner of the plot area
/// (top-right, top-left, bottom-left or bottom-right, preferred in that order) that hides the
/// least of the lines.
fn draw_legend(svg: &mut String, chart: &Chart, layout: &ChartLayout, lines: &[Vec<(f32, f32)>]) {
    if chart.series.is_empty() {
        return;
    }
    let scale = layout.text_scale;
    let s = scale as f32;
    let size = FONT_SIZE * s;
    let label_width = chart
        .series
        .iter()
        .map(|series| text_width(&series.label, size))
        .fold(0.0, f32::max);
    let (pad, swatch, row) = (6.0 * s, 20.0 * s, 1.2 * size + 3.0 * s);
    let box_w = pad + swatch + pad + label_width + pad;
    let box_h = pad + row * chart.series.len() as f32 - 3.0 * s + pad;
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
    let (box_x, box_y) = (best.0.round() + 0.5, best.1.round() + 0.5);
    let _ = writeln!(
        svg,
        r#"<g class="legend">
<rect x="{box_x:.1}" y="{box_y:.1}" width="{box_w:.1}" height="{box_h:.1}" fill="{}" stroke="{}" stroke-width="1"/>"#,
        hex(BACKGROUND),
        hex(LEGEND_FRAME)
    );
    for (index, series) in chart.series.iter().enumerate() {
        let colour = hex(PALETTE[index % PALETTE.len()]);
        let row_top = box_y + pad + row * index as f32;
        let mid = row_top + 0.6 * size;
        let x0 = box_x + pad;
        let _ = writeln!(
            svg,
            r#"<path d="M{x0:.1} {mid:.1}h{swatch:.1}" stroke="{colour}" stroke-width="{:.1}"/><circle cx="{:.1}" cy="{mid:.1}" r="{:.1}" fill="{colour}"/>"#,
            1.5 * s,
            x0 + swatch / 2.0,
            marker_radius(scale)
        );
        text(
            svg,
            x0 + swatch + pad,
            mid + 0.35 * size,
            "start",
            size,
            INK,
            &series.label,
        );
    }
    svg.push_str("</g>\n");
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
