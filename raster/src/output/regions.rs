//! Pixel regions for error statistics: the translucent pixels, and the band around shadow
//! edges where the methods differ most (Neulander 2010, Figure 1).
//!
//! Both are found from a reference render's layers, so `lucent compare` and `lucent bench`
//! select the same pixels:
//!
//! - **Translucent**: the `exitance` layer has a positive channel (pixels that show no
//!   translucent surface have exitance exactly 0; lit or not, a translucent surface receives
//!   some light through the dipole's tail, far above the f32 underflow at bench scales).
//! - **Shadow-edge band**: a translucent pixel is an *edge* pixel when a 4-neighbour, also
//!   translucent, differs from it in irradiance luminance by more than
//!   [`EDGE_CONTRAST`] × the 99th percentile of the translucent pixels' irradiance luminance.
//!   A cast shadow's edge jumps by the full lit level within a pixel or two; the smooth
//!   fall-off of N·L towards the terminator does not. The band is every translucent pixel
//!   within `radius` pixels (Euclidean) of an edge pixel.
//!
//! ```text
//!   irradiance      edge pixels      band (radius 2)
//!   ████░░░░        ...##...         .######.
//!   ████░░░░        ...##...         .######.
//! ```

use glam::Vec3;

use super::OutputError;

/// Fraction of the bright irradiance level a jump between neighbours must exceed to mark a
/// shadow edge.
pub const EDGE_CONTRAST: f32 = 0.2;

/// The band half-width used by `lucent compare` and `lucent bench`: 3 pixels at 512², scaled
/// with the image (at least 2).
pub fn default_band_radius(width: u32, height: u32) -> u32 {
    (width.max(height) as f32 / 170.0).round().max(2.0) as u32
}

/// Pixels showing a translucent surface: any channel of the exitance layer positive.
pub fn translucent_mask(exitance: &[Vec3]) -> Vec<bool> {
    exitance
        .iter()
        .map(|e| (0..3).any(|c| e[c] > 0.0 && e[c].is_finite()))
        .collect()
}

fn luminance(v: Vec3) -> f32 {
    let l = (v.x + v.y + v.z) / 3.0;
    if l.is_finite() { l.max(0.0) } else { 0.0 }
}

/// The shadow-edge band (module doc) over `width × height` pixels, row-major. `translucent`
/// restricts both the edge test and the band. An image without an edge gives an all-`false`
/// band.
pub fn shadow_edge_band(
    irradiance: &[Vec3],
    translucent: &[bool],
    width: u32,
    height: u32,
    radius: u32,
) -> Result<Vec<bool>, OutputError> {
    let (w, h) = (width as usize, height as usize);
    let n = w.saturating_mul(h);
    if irradiance.len() != n || translucent.len() != n {
        return Err(OutputError::Mask {
            message: format!(
                "edge band: {} irradiance values and {} mask entries for {width}×{height} pixels",
                irradiance.len(),
                translucent.len()
            ),
        });
    }
    let lum: Vec<f32> = irradiance.iter().map(|&e| luminance(e)).collect();
    let mut lit: Vec<f32> = lum
        .iter()
        .zip(translucent)
        .filter(|&(_, &t)| t)
        .map(|(&l, _)| l)
        .collect();
    if lit.is_empty() {
        return Ok(vec![false; n]);
    }
    lit.sort_by(f32::total_cmp);
    let level = lit[((lit.len() - 1) as f64 * 0.99) as usize];
    let jump = EDGE_CONTRAST * level;
    if !(jump > 0.0) {
        return Ok(vec![false; n]);
    }

    let mut edge = vec![false; n];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if !translucent[i] {
                continue;
            }
            let neighbours = [
                (x > 0).then(|| i - 1),
                (x + 1 < w).then(|| i + 1),
                (y > 0).then(|| i - w),
                (y + 1 < h).then(|| i + w),
            ];
            edge[i] = neighbours
                .into_iter()
                .flatten()
                .any(|j| translucent[j] && (lum[i] - lum[j]).abs() > jump);
        }
    }

    // Dilate by a disc of the radius; separable would be faster but this runs once per image.
    let r = radius as isize;
    let offsets: Vec<(isize, isize)> = (-r..=r)
        .flat_map(|dy| (-r..=r).map(move |dx| (dx, dy)))
        .filter(|(dx, dy)| dx * dx + dy * dy <= r * r)
        .collect();
    let mut band = vec![false; n];
    for y in 0..h as isize {
        for x in 0..w as isize {
            if !edge[y as usize * w + x as usize] {
                continue;
            }
            for &(dx, dy) in &offsets {
                let (u, v) = (x + dx, y + dy);
                if u >= 0 && v >= 0 && (u as usize) < w && (v as usize) < h {
                    let j = v as usize * w + u as usize;
                    band[j] = translucent[j];
                }
            }
        }
    }
    Ok(band)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 20×10 image: translucent everywhere but the two leftmost columns; lit (E = 1) for
    /// x ≥ 10, shadowed (E = 0.05) left of it.
    fn half_lit() -> (Vec<Vec3>, Vec<bool>) {
        let (w, h) = (20, 10);
        let mut e = Vec::new();
        let mut t = Vec::new();
        for _y in 0..h {
            for x in 0..w {
                e.push(Vec3::splat(if x >= 10 { 1.0 } else { 0.05 }));
                t.push(x >= 2);
            }
        }
        (e, t)
    }

    #[test]
    fn band_is_the_disc_dilation_of_the_edge() {
        let (e, t) = half_lit();
        let band = shadow_edge_band(&e, &t, 20, 10, 2).unwrap();
        for y in 0..10 {
            for x in 0..20 {
                // Edge pixels are x = 9 and x = 10; radius 2 reaches x = 7..=12.
                let expected = (7..=12).contains(&x);
                assert_eq!(band[y * 20 + x], expected, "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn smooth_ramps_and_uniform_images_have_no_edge() {
        // N·L-like ramp: 0 to 1 over 20 pixels, steps of 0.05 < 0.2.
        let e: Vec<Vec3> = (0..200)
            .map(|i| Vec3::splat((i % 20) as f32 / 19.0))
            .collect();
        let t = vec![true; 200];
        assert!(!shadow_edge_band(&e, &t, 20, 10, 3).unwrap().contains(&true));
        let flat = vec![Vec3::ONE; 200];
        assert!(
            !shadow_edge_band(&flat, &t, 20, 10, 3)
                .unwrap()
                .contains(&true)
        );
        let dark = vec![Vec3::ZERO; 200];
        assert!(
            !shadow_edge_band(&dark, &t, 20, 10, 3)
                .unwrap()
                .contains(&true)
        );
    }

    #[test]
    fn opaque_neighbours_do_not_make_edges_and_band_stays_translucent() {
        // The jump between x = 1 (opaque) and x = 2 is ignored; the band never covers x < 2.
        let (mut e, t) = half_lit();
        for y in 0..10 {
            e[y * 20] = Vec3::splat(100.0);
            e[y * 20 + 1] = Vec3::splat(100.0);
        }
        let band = shadow_edge_band(&e, &t, 20, 10, 9).unwrap();
        for y in 0..10 {
            assert!(!band[y * 20] && !band[y * 20 + 1]);
            assert!(band[y * 20 + 2], "radius 9 from x = 9 reaches x = 2");
        }
    }

    #[test]
    fn masks_reject_wrong_sizes_and_survive_non_finite_values() {
        let (e, t) = half_lit();
        assert!(shadow_edge_band(&e, &t[1..], 20, 10, 2).is_err());
        assert!(shadow_edge_band(&e, &t, 21, 10, 2).is_err());
        let mut bad = e.clone();
        bad[50] = Vec3::NAN;
        bad[51] = Vec3::INFINITY;
        assert!(shadow_edge_band(&bad, &t, 20, 10, 2).is_ok());
        let m = translucent_mask(&[Vec3::ZERO, Vec3::new(0.0, 1e-30, 0.0), Vec3::NAN]);
        assert_eq!(m, vec![false, true, false]);
    }

    #[test]
    fn default_radius_scales_with_the_image() {
        assert_eq!(default_band_radius(512, 512), 3);
        assert_eq!(default_band_radius(128, 128), 2);
        assert_eq!(default_band_radius(2048, 1024), 12);
    }
}
