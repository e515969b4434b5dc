//! The error-against-time charts of `lucent bench`: per scene, mean relative error against
//! render time for every method setting, over the translucent pixels
//! (`<scene>-error-vs-time.svg`) and in the shadow-edge band
//! (`<scene>-edge-error-vs-time.svg`), log–log, SVG.
//!
//! They are drawn from [`ChartPoint`]s: during a run from its results, and again later from a
//! report's `results.csv` ([`replot`]) without running anything. The CSV keeps every number
//! exactly, so a replot gives the same bytes.

use std::path::{Path, PathBuf};

use super::BenchError;
use crate::output::write_text_atomically;
use crate::plot::{Chart, Series, render_chart};

/// One run as a chart point: its series label, render time, and errors.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartPoint {
    /// The series (a method setting's label).
    pub label: String,
    /// Render time in seconds.
    pub time: f64,
    /// Mean relative error over the translucent pixels.
    pub error: f64,
    /// Mean relative error in the shadow-edge band, if the scene has one.
    pub edge_error: Option<f64>,
}

/// The chart files of a scene, without the directory: `<scene>-error-vs-time.svg` and
/// `<scene>-edge-error-vs-time.svg`.
pub fn chart_files(scene: &str) -> [String; 2] {
    [
        format!("{scene}-error-vs-time.svg"),
        format!("{scene}-edge-error-vs-time.svg"),
    ]
}

/// Width and height of the charts.
const CHART_SIZE: (u32, u32) = (800, 560);

/// Writes a scene's two error-against-time charts ([`chart_files`]) into `out`: one series
/// per label, in the order the labels first appear in `points`.
pub fn write_charts(scene: &str, points: &[ChartPoint], out: &Path) -> Result<(), BenchError> {
    let mut labels: Vec<&str> = Vec::new();
    for p in points {
        if !labels.contains(&p.label.as_str()) {
            labels.push(&p.label);
        }
    }
    for (edge, file, what) in [
        (false, &chart_files(scene)[0], "translucent pixels"),
        (true, &chart_files(scene)[1], "shadow-edge band"),
    ] {
        let series = labels
            .iter()
            .map(|&label| Series {
                label: label.to_string(),
                points: points
                    .iter()
                    .filter(|p| p.label == label)
                    .filter_map(|p| Some((p.time, if edge { p.edge_error? } else { p.error })))
                    .collect(),
            })
            .collect();
        let chart = Chart {
            title: format!("{scene}: error against time ({what})"),
            x_label: "render time (s)".to_string(),
            y_label: "mean relative error".to_string(),
            series,
            log_x: true,
            log_y: true,
        };
        let svg = render_chart(&chart, CHART_SIZE.0, CHART_SIZE.1)?;
        write_text_atomically(&out.join(file), &svg)?;
    }
    Ok(())
}

/// Draws the error-against-time charts again from `dir/results.csv` (as [`write_csv`]
/// wrote it) into `dir`, for every scene in it; returns the files written. Only the runs at
/// each scene's own smoothing factor (its first row's) are drawn, like the charts of the run
/// itself; the smoothing sweep's other rows are left out.
///
/// [`write_csv`]: super::write_csv
pub fn replot(dir: &Path) -> Result<Vec<PathBuf>, BenchError> {
    let path = dir.join("results.csv");
    let text = std::fs::read_to_string(&path).map_err(|e| BenchError::Read {
        path: path.clone(),
        source: e,
    })?;
    let bad = |line: usize, message: String| BenchError::Csv {
        path: path.clone(),
        line,
        message,
    };
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| bad(1, format!("no column '{name}'")))
    };
    let [scene, method, epsilon, smoothing, total, error, edge] = [
        "scene",
        "method",
        "epsilon",
        "smoothing",
        "total_s",
        "error_mean_rel",
        "edge_mean_rel",
    ]
    .map(column);
    let (scene, method, epsilon, smoothing, total, error, edge) =
        (scene?, method?, epsilon?, smoothing?, total?, error?, edge?);
    // Per scene, in the order of the file: its own smoothing factor and its points.
    let mut scenes: Vec<(String, String, Vec<ChartPoint>)> = Vec::new();
    for (index, line) in lines.enumerate().filter(|(_, l)| !l.is_empty()) {
        let number = index + 2;
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            return Err(bad(
                number,
                format!("{} cells, the header has {}", cells.len(), header.len()),
            ));
        }
        let number_at = |c: usize| -> Result<f64, BenchError> {
            cells[c]
                .parse::<f64>()
                .map_err(|_| bad(number, format!("'{}' is not a number", cells[c])))
        };
        let label = if cells[method] == "hierarchical" {
            format!("hierarchical eps={}", cells[epsilon])
        } else {
            cells[method].to_string()
        };
        let point = ChartPoint {
            label,
            time: number_at(total)?,
            error: number_at(error)?,
            edge_error: if cells[edge].is_empty() {
                None
            } else {
                Some(number_at(edge)?)
            },
        };
        let name = cells[scene];
        if !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
            || name.is_empty()
        {
            return Err(bad(number, format!("'{name}' is not a scene name")));
        }
        match scenes.iter_mut().find(|(s, _, _)| s == name) {
            Some((_, k, points)) => {
                if *k == cells[smoothing] {
                    points.push(point);
                }
            }
            None => scenes.push((name.to_string(), cells[smoothing].to_string(), vec![point])),
        }
    }
    let mut written = Vec::new();
    for (name, _, points) in &scenes {
        write_charts(name, points, dir)?;
        written.extend(chart_files(name).iter().map(|f| dir.join(f)));
    }
    Ok(written)
}
