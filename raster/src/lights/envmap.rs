//! A latitude–longitude environment map and its luminance-importance distribution
//! (`docs/physics.md` §5.2).
//!
//! **Convention.** World +z is up. In the map's own frame, the direction of polar angle θ
//! (from +z) and azimuth φ (from +x towards +y) is ω = (sin θ cos φ, sin θ sin φ, cos θ). Texel
//! column `i` of a `W × H` image covers φ ∈ [2π i/W, 2π (i+1)/W) and row `j` (from the top)
//! covers θ ∈ [π j/H, π (j+1)/H): the top row is the zenith, the bottom row the nadir, the
//! left edge looks along +x and a quarter of the way across looks along +y. The light's
//! `rotation` turns the map by that angle about +z (counter-clockwise seen from above), so a
//! world direction is looked up at azimuth φ − rotation.
//!
//! The radiance is piecewise constant: each texel holds one value over its cell of the sphere
//! (no filtering), which is the function the sampling density below matches exactly.
//!
//! **Distribution.** Texel (i, j) is chosen with probability P_ij = ℓ_ij ΔΩ_j / Σ ℓ ΔΩ, where
//! ℓ is the texel's luminance (Rec. 709 weights) and ΔΩ_j = (2π/W)(cos θ_j − cos θ_{j+1}) the
//! exact solid angle of a texel of row j (the integral of sin θ over the row), and a direction
//! is then uniform in solid angle within the texel: its density is p(ω) = P_ij / ΔΩ_j. A row is
//! picked from the marginal CDF and a column from that row's conditional CDF; the fraction of
//! each uniform variate left over inside the chosen row or column places the point within the
//! texel, so stratified variates stay stratified.
//!
//! ```text
//! texels:      [ W × H linear RGB, row-major, top row first ]   (the texture's own)
//! row_cdf:     [ 0, c_1, …, c_H = 1 ]               H + 1   marginal over rows
//! column_cdf:  [ row 0: 0, …, 1 | row 1: 0, …, 1 | … ]   H × (W + 1)   conditional per row
//! row_solid_angle: [ ΔΩ_0, …, ΔΩ_{H−1} ]            H       solid angle of one texel per row
//! row_cos:     [ cos θ_0 = 1, cos θ_1, …, cos θ_H = −1 ]   H + 1   the rows' boundaries
//! ```
//!
//! 4 (W + 4) bytes per row beyond the texture (about 4 bytes per texel). A row with no light
//! keeps a flat conditional CDF (never chosen, since its marginal step is 0).

use std::f64::consts::PI as PI64;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::texture::Texture;

/// Rec. 709 luminance weights, the importance of a texel's colour.
const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// The luminance of a linear RGB colour.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(LUMINANCE)
}

/// A lat-long radiance map with its sampling distribution (layout in the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    texture: Arc<Texture>,
    row_cdf: Vec<f32>,
    column_cdf: Vec<f32>,
    row_solid_angle: Vec<f32>,
    row_cos: Vec<f32>,
    /// Σ ℓ ΔΩ over all texels: the map's luminance integrated over the sphere.
    total: f64,
}

/// A direction drawn from an [`EnvironmentMap`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSample {
    /// Unit direction in the map's frame.
    pub direction: Vec3,
    /// The texel's radiance there.
    pub radiance: Vec3,
    /// The density in solid angle, p(ω) > 0.
    pub pdf: f32,
}

impl EnvironmentMap {
    /// The map of `texture` and its distribution. Errors (as a message) if a texel is negative
    /// or not finite, or if the map is empty; an all-black map is valid and delivers no light.
    pub fn new(texture: Arc<Texture>) -> Result<EnvironmentMap, String> {
        if texture.is_udim() {
            return Err("a UDIM set is not a latitude-longitude map: give one image".to_string());
        }
        let (w, h) = (texture.width as usize, texture.height as usize);
        if w == 0 || h == 0 || texture.texel_count() != w * h {
            return Err(format!(
                "the map has no texels ({} × {})",
                texture.width, texture.height
            ));
        }
        if let Some(k) = texture
            .texels()
            .position(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(format!(
                "map texel (column {}, row {}) is {} (radiance must be finite and at least 0)",
                k % w,
                k / w,
                texture.texel(k)
            ));
        }
        let row_solid_angle: Vec<f64> = (0..h)
            .map(|j| {
                let (top, bottom) = (PI64 * j as f64 / h as f64, PI64 * (j + 1) as f64 / h as f64);
                2.0 * PI64 / w as f64 * (top.cos() - bottom.cos())
            })
            .collect();
        let mut column_cdf = Vec::with_capacity(h * (w + 1));
        let mut row_mass = Vec::with_capacity(h);
        for j in 0..h {
            let start = column_cdf.len();
            let mut sum = 0.0f64;
            column_cdf.push(0.0);
            for i in 0..w {
                sum += luminance(texture.texel(j * w + i)) as f64;
                column_cdf.push(sum as f32);
            }
            normalise(&mut column_cdf[start..], sum);
            row_mass.push(sum * row_solid_angle[j]);
        }
        let total: f64 = row_mass.iter().sum();
        let mut row_cdf = Vec::with_capacity(h + 1);
        let mut sum = 0.0f64;
        row_cdf.push(0.0);
        for m in &row_mass {
            sum += m;
            row_cdf.push(sum as f32);
        }
        normalise(&mut row_cdf, sum);
        let map = EnvironmentMap {
            texture,
            row_cdf,
            column_cdf,
            row_solid_angle: row_solid_angle.iter().map(|&a| a as f32).collect(),
            row_cos: (0..=h)
                .map(|j| (PI64 * j as f64 / h as f64).cos() as f32)
                .collect(),
            total,
        };
        debug_assert_eq!(map.validate(), Ok(()));
        Ok(map)
    }

    /// The texture behind the map.
    pub fn texture(&self) -> &Texture {
        &self.texture
    }

    /// True if no texel has any luminance (the map delivers no light).
    pub fn is_black(&self) -> bool {
        !(self.total > 0.0)
    }

    /// Checks every invariant of the layout: sizes, CDFs non-decreasing from 0 to 1 (a flat 0
    /// for a black row or map), positive solid angles summing to 4π.
    pub fn validate(&self) -> Result<(), String> {
        let (w, h) = (self.texture.width as usize, self.texture.height as usize);
        if self.row_cdf.len() != h + 1
            || self.column_cdf.len() != h * (w + 1)
            || self.row_solid_angle.len() != h
            || self.row_cos.len() != h + 1
        {
            return Err("column sizes do not match the texture".into());
        }
        let cdf_ok = |c: &[f32]| {
            c[0] == 0.0
                && c.windows(2).all(|p| p[0] <= p[1])
                && (c[c.len() - 1] == 1.0 || c.iter().all(|&x| x == 0.0))
        };
        if !cdf_ok(&self.row_cdf) {
            return Err("the row CDF is not a CDF".into());
        }
        if let Some(j) = self.column_cdf.chunks_exact(w + 1).position(|c| !cdf_ok(c)) {
            return Err(format!("the column CDF of row {j} is not a CDF"));
        }
        let sphere: f64 = self.row_solid_angle.iter().map(|&a| a as f64).sum::<f64>() * w as f64;
        if self.row_solid_angle.iter().any(|&a| !(a > 0.0))
            || (sphere - 4.0 * PI64).abs() > 1e-4 * 4.0 * PI64
        {
            return Err(format!("texel solid angles sum to {sphere}, not 4π"));
        }
        if self.row_cos[0] != 1.0
            || self.row_cos[h] != -1.0
            || self.row_cos.windows(2).any(|c| !(c[0] > c[1]))
        {
            return Err("the rows' cos θ boundaries do not fall from 1 to −1".into());
        }
        if !(self.total >= 0.0) || !self.total.is_finite() {
            return Err(format!("total luminance {} is not finite", self.total));
        }
        Ok(())
    }

    /// The texel (column, row) that contains the map-frame direction `d` (unit).
    fn texel_of(&self, d: Vec3) -> (usize, usize) {
        let (w, h) = (self.texture.width as usize, self.texture.height as usize);
        let theta = d.z.clamp(-1.0, 1.0).acos();
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += std::f32::consts::TAU;
        }
        let column = ((phi / std::f32::consts::TAU * w as f32) as usize).min(w - 1);
        let row = ((theta / std::f32::consts::PI * h as f32) as usize).min(h - 1);
        (column, row)
    }

    /// Radiance arriving from the map-frame direction `d` (unit).
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.radiance_and_pdf(d).0
    }

    /// The sampling density in solid angle at the map-frame direction `d` (unit); 0 for a
    /// black map.
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.radiance_and_pdf(d).1
    }

    /// [`EnvironmentMap::radiance`] and [`EnvironmentMap::pdf`] from one texel lookup.
    pub fn radiance_and_pdf(&self, d: Vec3) -> (Vec3, f32) {
        let (i, j) = self.texel_of(d);
        let w = self.texture.width as usize;
        let radiance = self.texture.texel(j * w + i);
        if self.is_black() {
            return (radiance, 0.0);
        }
        let row = self.row_cdf[j + 1] - self.row_cdf[j];
        let cdf = &self.column_cdf[j * (w + 1)..];
        let column = cdf[i + 1] - cdf[i];
        (radiance, row * column / self.row_solid_angle[j])
    }

    /// The direction for the uniform variates `u ∈ [0, 1)²` (`u.y` picks the row, `u.x` the
    /// column), or `None` for a black map.
    pub fn sample(&self, u: Vec2) -> Option<MapSample> {
        if self.is_black() {
            return None;
        }
        let w = self.texture.width as usize;
        let (j, fy) = pick(&self.row_cdf, u.y);
        let cdf = &self.column_cdf[j * (w + 1)..(j + 1) * (w + 1)];
        let (i, fx) = pick(cdf, u.x);
        let row_p = self.row_cdf[j + 1] - self.row_cdf[j];
        let column_p = cdf[i + 1] - cdf[i];
        // Uniform in solid angle within the texel: uniform in φ and in cos θ.
        let (cos_top, cos_bottom) = (self.row_cos[j], self.row_cos[j + 1]);
        let cos_theta = (cos_top + fy * (cos_bottom - cos_top)).clamp(-1.0, 1.0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * (i as f32 + fx) / w as f32;
        let (sin_phi, cos_phi) = phi.sin_cos();
        Some(MapSample {
            direction: Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta),
            radiance: self.texture.texel(j * w + i),
            pdf: row_p * column_p / self.row_solid_angle[j],
        })
    }
}

/// Divides a running sum by its total (a zero total leaves the zeros), and pins the last
/// entry to exactly 1.
fn normalise(cdf: &mut [f32], total: f64) {
    if !(total > 0.0) {
        cdf.fill(0.0);
        return;
    }
    let mut running = 0.0f64;
    let n = cdf.len();
    for (k, c) in cdf.iter_mut().enumerate() {
        running = (*c as f64).max(running);
        *c = if k + 1 == n {
            1.0
        } else {
            ((running / total) as f32).min(1.0)
        };
    }
}

/// The bin `k` of a CDF (`cdf[k] ≤ u < cdf[k + 1]`, a bin of positive mass) and the fraction
/// of `u` within it.
fn pick(cdf: &[f32], u: f32) -> (usize, f32) {
    let bins = cdf.len() - 1;
    let k = cdf[1..].partition_point(|&c| c <= u).min(bins - 1);
    let width = cdf[k + 1] - cdf[k];
    let f = if width > 0.0 {
        ((u - cdf[k]) / width).clamp(0.0, 1.0 - f32::EPSILON / 2.0)
    } else {
        0.5
    };
    (k, f)
}
