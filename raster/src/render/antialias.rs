//! The second shading pass: pixels next to a visible change are checked, and re-shaded at
//! more than one point where their sub-samples differ ([`super::adaptive`]).
//!
//! The first pass shades every pixel once per visible object. A straight edge (a shadow's, a
//! crease's, a texture's) that crosses a pixel separates its representative sub-sample from
//! another of its sub-samples, and the 3 × 3 block of representatives around it spans the
//! pixel, so the edge also separates the pixel's representative from a neighbour's: the two
//! first-pass values differ. Only pixels whose first-pass radiance differs from a neighbour's
//! by more than [`CONTRAST`] (relative, with a floor at [`FLOOR`] of the radiance the PNG shows
//! as white) are probed; elsewhere the first pass stands, bit for bit. An edge of lower
//! contrast is not refined (its stair-steps are at most that contrast).
//!
//! Every pixel's second-pass value depends only on its own and its eight neighbours'
//! first-pass values (read-only), its own sub-samples and the scene, so the image is the same
//! for any thread count, and a tile of the image (`RenderOptions::crop`) whose first pass
//! covers a one-pixel margin around it is the same as that part of the whole image.

use glam::Vec3;
use lucent_core::stats::NoStats;
use rayon::prelude::*;

use super::RenderError;
use super::shading::{PixelScratch, PixelValue, Shading, ShadingCounters};
use crate::output::Region;

/// A pixel is probed when, in some channel, its first-pass radiance `a` and a neighbour's `b`
/// have `|a − b| / (a + b + FLOOR · white)` above this (a ratio above 1.22 where the pixels are
/// bright), `white` being the radiance the PNG shows as white, `2^−exposure`.
pub const CONTRAST: f32 = 0.1;

/// The floor in [`CONTRAST`]'s denominator, in units of the radiance the PNG shows as white:
/// steps between dark pixels are not probed unless they are large against that. It is a
/// property of the scene (its exposure), not of the pixels, so that a tile of the image knows
/// it: a floor at a tenth of the image's mean radiance, which it replaces, needed the whole
/// first pass. The shipped scenes' mean radiance is 0.04–0.18 of white (0.56 in the blue of
/// the environment map), so this is about the floor of that rule.
pub const FLOOR: f32 = 0.01;

/// What the second pass did, summed over the image.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Refined {
    /// Pixels probed (above [`CONTRAST`]).
    pub flagged: u64,
    /// Pixels re-shaded (a fragment split).
    pub reshaded: u64,
    /// Points shaded in the re-shaded pixels.
    pub points: u64,
    /// Translucent points among them.
    pub queries: u64,
    /// Sub-samples probed.
    pub probes: u64,
    /// Traversal counters and translucent time, when collected.
    pub stats: ShadingCounters,
}

/// The largest channel of `|a − b| / (a + b + floor)` (0 where the denominator is 0).
fn contrast(a: Vec3, b: Vec3, floor: Vec3) -> f32 {
    let (d, s) = ((a - b).abs(), a + b + floor);
    (0..3)
        .map(|c| if s[c] > 0.0 { d[c] / s[c] } else { 0.0 })
        .fold(0.0, f32::max)
}

/// True if pixel `(x, y)` of the `width × height` radiance `colors` differs from one of its
/// eight neighbours (those inside `colors`) by more than [`CONTRAST`].
fn near_a_change(
    colors: &[Vec3],
    floor: Vec3,
    width: usize,
    height: usize,
    x: usize,
    y: usize,
) -> bool {
    let c = colors[y * width + x];
    (y.saturating_sub(1)..(y + 2).min(height)).any(|ny| {
        (x.saturating_sub(1)..(x + 2).min(width))
            .any(|nx| contrast(c, colors[ny * width + nx], floor) > CONTRAST)
    })
}

/// Re-shades, in place, the pixels of `region` that need more than one point per object.
/// `pixels` is the first pass over `shaded` (row-major), which must hold `region` and, of its
/// pixels' neighbours, those inside the image; `collect_stats` as for the first pass.
pub(super) fn refine(
    shading: &Shading<'_>,
    pixels: &mut [PixelValue],
    shaded: Region,
    region: Region,
    collect_stats: bool,
) -> Result<Refined, RenderError> {
    let (w, h) = (shaded.width() as usize, shaded.height() as usize);
    let colors: Vec<Vec3> = pixels.iter().map(|p| p.color).collect();
    let white = (-f64::from(shading.prep.scene.render.exposure)).exp2() as f32;
    let floor = Vec3::splat(FLOOR * white);
    let rows: Vec<Result<Refined, RenderError>> = pixels
        .par_chunks_mut(w.max(1))
        .zip(shaded.y0..shaded.y1)
        .filter(|(_, y)| (region.y0..region.y1).contains(y))
        .map(|(out, y)| {
            let mut scratch = PixelScratch::default();
            let mut row = Refined::default();
            for (x, slot) in (shaded.x0..shaded.x1).zip(out.iter_mut()) {
                if !region.contains(x, y) {
                    continue;
                }
                let (local_x, local_y) = ((x - shaded.x0) as usize, (y - shaded.y0) as usize);
                if !near_a_change(&colors, floor, w, h, local_x, local_y) {
                    continue;
                }
                row.flagged += 1;
                if !shading.split_pixel(x, y, &mut scratch) {
                    continue;
                }
                *slot = if collect_stats {
                    shading.shade(x, y, &mut scratch, &mut row.stats)?
                } else {
                    shading.shade(x, y, &mut scratch, &mut NoStats)?
                };
                let groups = &scratch.groups.groups;
                row.reshaded += 1;
                row.points += groups.len() as u64;
                row.queries += groups
                    .iter()
                    .filter(|g| shading.caches[g.fragment.key as usize].is_some())
                    .count() as u64;
            }
            row.probes = scratch.groups.probes;
            Ok(row)
        })
        .collect();
    let mut total = Refined::default();
    for row in rows {
        let row = row?;
        total.flagged += row.flagged;
        total.reshaded += row.reshaded;
        total.points += row.points;
        total.queries += row.queries;
        total.probes += row.probes;
        total.stats.add(&row.stats);
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contrast_is_the_largest_channel_ratio() {
        let none = Vec3::ZERO;
        assert_eq!(contrast(Vec3::ZERO, Vec3::ZERO, none), 0.0);
        assert_eq!(contrast(Vec3::ONE, Vec3::ZERO, none), 1.0);
        let c = contrast(Vec3::new(1.0, 1.0, 1.0), Vec3::new(1.0, 1.5, 0.9), none);
        assert!((c - 0.2).abs() < 1e-6, "{c}");
        // The floor adds to the denominator: 0.5 / (2.5 + 2.5).
        let c = contrast(Vec3::ONE, Vec3::new(1.0, 1.5, 1.0), Vec3::splat(2.5));
        assert!((c - 0.1).abs() < 1e-6, "{c}");
    }

    #[test]
    fn only_pixels_next_to_a_change_are_flagged() {
        // A 5 × 4 image, uniform but for a step between columns 2 and 3 in rows 0–1.
        let (w, h) = (5, 4);
        let mut colors = vec![Vec3::ONE; w * h];
        colors[3] = Vec3::splat(1.3);
        colors[4] = Vec3::splat(1.3);
        colors[w + 3] = Vec3::splat(1.3);
        colors[w + 4] = Vec3::splat(1.3);
        let flagged: Vec<(usize, usize)> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| near_a_change(&colors, Vec3::ZERO, w, h, x, y))
            .collect();
        // Columns 2 and 3 of rows 0–2, and column 4 of row 2 (diagonal to row 1's step).
        assert_eq!(
            flagged,
            vec![
                (2, 0),
                (3, 0),
                (2, 1),
                (3, 1),
                (4, 1),
                (2, 2),
                (3, 2),
                (4, 2)
            ]
        );
        // A change below the threshold flags nothing.
        let mut soft = vec![Vec3::ONE; w * h];
        soft[3] = Vec3::splat(1.2);
        let quiet = |colors: &[Vec3], floor: Vec3| {
            (0..h).all(|y| (0..w).all(|x| !near_a_change(colors, floor, w, h, x, y)))
        };
        assert!(quiet(&soft, Vec3::ZERO));
        // The step above, in a dark corner of an image shown at white = 100: under the floor.
        assert!(!quiet(&colors, Vec3::ZERO));
        assert!(quiet(&colors, Vec3::splat(100.0 * FLOOR)));
    }
}
