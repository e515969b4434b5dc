//! The rectangular area light (`docs/physics.md` §5.1): a one-sided Lambertian emitter of
//! radiance L = I / (w h), sampled at stratified points of its area.
//!
//! **Orientation.** The rectangle lies in the plane through `center` perpendicular to its unit
//! normal `d` (the scene's `direction`, where it shines). Its height runs along `up` made
//! perpendicular to `d` (`up` defaults to +z, or +y when `d` is within 0.06° of ±z), and its
//! width along `up_axis × d`, which is to the right for an observer the light faces:
//!
//! ```text
//!            up_axis (height h)
//!               ▲
//!      ┌────────┼────────┐
//!      │        │        │
//!      │        ●────────┼──▶ right = up_axis × d (width w)
//!      │      center     │
//!      └─────────────────┘      d points out of the page, towards the lit side
//! ```
//!
//! **Estimator.** With N stratified points qₖ = c + (u − ½) w r̂ + (v − ½) h û, each traced,
//!
//! E = L · (w h / N) Σₖ Vₖ max(0, n·ωₖ) max(0, −d·ωₖ) / |qₖ − p|², ωₖ = (qₖ − p)/|qₖ − p|,
//!
//! an unbiased area-sampling estimate of E = ∫_A L cos θ cos θ′ / r² dA that converges as the
//! strata shrink (tested against Lambert's closed form, [`tests`](self)).

use glam::{Vec2, Vec3};

use super::{Incident, Lighting, SHORTEN, strata};
use crate::geometry::ShadowHint;

/// Where a rect light is and which way it is turned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RectFrame {
    /// Centre.
    pub center: Vec3,
    /// Unit normal of the emitting face.
    pub normal: Vec3,
    /// Unit vector along the width.
    pub right: Vec3,
    /// Unit vector along the height.
    pub up: Vec3,
    /// Width and height.
    pub size: Vec2,
}

impl RectFrame {
    /// The four corners, counter-clockwise seen from the lit side.
    pub fn corners(&self) -> [Vec3; 4] {
        let (x, y) = (
            self.right * (0.5 * self.size.x),
            self.up * (0.5 * self.size.y),
        );
        let c = self.center;
        [c - x - y, c + x - y, c + x + y, c - x + y]
    }
}

/// The width and height axes `(right, up_axis)` of a rect light facing `direction` (unit),
/// from the scene's `up` (`None`: +z, or +y when `direction` is within 0.06° of ±z). `None`
/// when the given `up` is (nearly) parallel to `direction` or zero.
pub fn rect_frame(direction: Vec3, up: Option<Vec3>) -> Option<(Vec3, Vec3)> {
    /// sin² of the smallest angle between `up` and `direction`: 1e-6 rad².
    const MIN_SIN2: f32 = 1e-6;
    let up = match up {
        Some(u) => u.try_normalize()?,
        None if direction.cross(Vec3::Z).length_squared() > MIN_SIN2 => Vec3::Z,
        None => Vec3::Y,
    };
    if direction.cross(up).length_squared() <= MIN_SIN2 {
        return None;
    }
    let up_axis = (up - direction * up.dot(direction)).normalize();
    let right = up_axis.cross(direction).normalize();
    Some((right, up_axis))
}

impl Lighting<'_> {
    /// Stratified points on the rectangle, each traced (module docs); the incident direction
    /// reported is the irradiance-weighted mean of the visible samples' directions.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn rect(
        &self,
        p: Vec3,
        n: Vec3,
        frame: &RectFrame,
        intensity: Vec3,
        samples: u32,
        seed: u64,
        hint: &mut ShadowHint,
    ) -> Option<Incident> {
        // Behind the emitting face (or in its plane): nothing.
        if !((p - frame.center).dot(frame.normal) > 0.0) {
            return None;
        }
        let count = samples.max(1);
        let mut sum = 0.0f32;
        let mut toward = Vec3::ZERO;
        for u in strata(count, seed) {
            let q = frame.center
                + frame.right * ((u.x - 0.5) * frame.size.x)
                + frame.up * ((u.y - 0.5) * frame.size.y);
            let to = q - p;
            let d2 = to.length_squared();
            if !(d2 > 0.0) {
                continue;
            }
            let d = d2.sqrt();
            let dir = to / d;
            let cos = n.dot(dir);
            let cos_light = -frame.normal.dot(dir);
            if cos <= 0.0 || cos_light <= 0.0 {
                continue;
            }
            if self.visible(p, n, dir, d * SHORTEN, hint) {
                let g = cos * cos_light / d2;
                sum += g;
                toward += dir * g;
            }
        }
        if !(sum > 0.0) {
            return None;
        }
        // L · A / N · Σ G = (I / A) · A / N · Σ G.
        Some(Incident {
            direction: toward.normalize_or(-frame.normal),
            irradiance: intensity * (sum / count as f32),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Bvh;
    use crate::scene::Light;

    /// Lambert's closed form for a polygon of uniform radiance L entirely above the tangent
    /// plane of `p` (normal `n`): E = (L/2) |Σᵢ βᵢ (n·γ̂ᵢ)|, βᵢ the angle the edge i subtends
    /// at p and γ̂ᵢ the unit normal of the plane through p and the edge (`docs/physics.md`
    /// §5.1). Computed in f64.
    fn lambert_polygon(p: Vec3, n: Vec3, corners: &[Vec3], radiance: f64) -> f64 {
        let n = n.as_dvec3();
        let v: Vec<_> = corners
            .iter()
            .map(|c| (c.as_dvec3() - p.as_dvec3()).normalize())
            .collect();
        let mut sum = 0.0;
        for i in 0..v.len() {
            let (a, b) = (v[i], v[(i + 1) % v.len()]);
            let beta = a.dot(b).clamp(-1.0, 1.0).acos();
            sum += beta * n.dot(a.cross(b).normalize());
        }
        0.5 * radiance * sum.abs()
    }

    fn light(frame: &RectFrame, intensity: f32, samples: u32) -> Light {
        Light::Rect {
            center: frame.center,
            normal: frame.normal,
            right: frame.right,
            up_axis: frame.up,
            size: frame.size,
            color: Vec3::ONE,
            intensity,
            samples,
        }
    }

    fn facing_down(center: Vec3, size: Vec2) -> RectFrame {
        let normal = -Vec3::Z;
        let (right, up) = rect_frame(normal, None).unwrap();
        RectFrame {
            center,
            normal,
            right,
            up,
            size,
        }
    }

    #[test]
    fn the_frame_rule() {
        // Facing −y (towards a camera at −y): height along +z, width along +x.
        let (right, up) = rect_frame(-Vec3::Y, None).unwrap();
        assert!((up - Vec3::Z).length() < 1e-6 && (right - Vec3::X).length() < 1e-6);
        // Facing straight down: up falls back to +y, right = y × (−z) = −x.
        let (right, up) = rect_frame(-Vec3::Z, None).unwrap();
        assert!((up - Vec3::Y).length() < 1e-6 && (right + Vec3::X).length() < 1e-6);
        // A tilted direction: the axes are orthonormal and perpendicular to it.
        let d = Vec3::new(0.3, -0.5, -0.8).normalize();
        let (right, up) = rect_frame(d, Some(Vec3::new(0.0, 1.0, 1.0))).unwrap();
        for (a, b) in [(right, up), (right, d), (up, d)] {
            assert!(a.dot(b).abs() < 1e-6);
        }
        assert!((right.length() - 1.0).abs() < 1e-6 && (up.length() - 1.0).abs() < 1e-6);
        assert!(
            (right.cross(up) - d).length() < 1e-5,
            "right-handed: r × u = d"
        );
        // A given up parallel to the direction, or zero, has no frame.
        assert_eq!(rect_frame(Vec3::Z, Some(Vec3::new(0.0, 0.0, -3.0))), None);
        assert_eq!(rect_frame(Vec3::Z, Some(Vec3::ZERO)), None);
    }

    /// The estimator against Lambert's closed form, on the axis and off it (a tilted
    /// receiver, a point beside the light), its error shrinking as the rays increase.
    #[test]
    fn matches_lamberts_closed_form_and_converges() {
        let frame = facing_down(Vec3::new(0.0, 0.0, 2.0), Vec2::new(2.0, 1.0));
        let intensity = 6.0;
        let radiance = (intensity / (frame.size.x * frame.size.y)) as f64;
        let tilted = Vec3::new(0.5, -0.3, 1.0).normalize();
        let cases = [
            (Vec3::ZERO, Vec3::Z),
            (Vec3::new(0.4, -0.7, 0.3), Vec3::Z),
            (Vec3::new(2.5, 1.5, 0.0), tilted),
            (
                Vec3::new(-3.0, 0.5, 1.0),
                Vec3::new(0.6, 0.0, 1.0).normalize(),
            ),
        ];
        for (p, n) in cases {
            let corners = frame.corners();
            // The formula needs the whole rectangle above the receiver's horizon.
            assert!(corners.iter().all(|c| (*c - p).dot(n) > 0.0));
            let want = lambert_polygon(p, n, &corners, radiance);
            let mut errors = Vec::new();
            for samples in [4, 64, 1024] {
                let lights = [light(&frame, intensity, samples)];
                let l = Lighting::new(&lights, None, 4.0);
                // The mean |error| over many seeds (per-point rotations).
                let seeds = 32;
                let mut err = 0.0;
                for seed in 0..seeds {
                    let e = l.irradiance(p, n, seed) / radiance as f32;
                    assert!((e.x - e.y).abs() < 1e-6 && (e.x - e.z).abs() < 1e-6);
                    err += (e.x as f64 * radiance - want).abs() / want;
                }
                errors.push(err / seeds as f64);
            }
            eprintln!("{p} {n}: mean relative error at N = 4, 64, 1024: {errors:?}");
            assert!(errors[2] < 1e-2, "{p} {n}: errors {errors:?}");
            assert!(
                errors[0] > errors[1] && errors[1] > errors[2],
                "{p} {n}: no convergence: {errors:?}"
            );
        }
    }

    #[test]
    fn far_away_it_is_a_point_light_with_a_cosine_lobe() {
        // At distance 100 along a direction 60° off the light's normal: E ≈ I cos 60° / d².
        let frame = facing_down(Vec3::ZERO, Vec2::new(0.5, 0.25));
        let lights = [light(&frame, 8.0, 16)];
        let dir = Vec3::new(3f32.sqrt() / 2.0, 0.0, -0.5);
        let p = dir * 100.0;
        let e = Lighting::new(&lights, None, 100.0).irradiance(p, -dir, 5).x;
        let want = 8.0 * 0.5 / 100.0f32.powi(2);
        assert!((e - want).abs() / want < 5e-3, "{e} vs {want}");
        // Behind the emitting face, and in its plane: nothing.
        let l = Lighting::new(&lights, None, 100.0);
        assert_eq!(
            l.irradiance(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z, 5),
            Vec3::ZERO
        );
        assert_eq!(
            l.irradiance(Vec3::new(3.0, 0.0, 0.0), -Vec3::X, 5),
            Vec3::ZERO
        );
    }

    #[test]
    fn soft_shadow_under_an_occluders_edge() {
        let frame = facing_down(Vec3::new(0.0, 0.0, 4.0), Vec2::new(2.0, 2.0));
        let lights = [light(&frame, 16.0, 256)];
        // A half-plane x < 0 at height 2: under its edge, half of the light is hidden.
        let h = 2.0;
        let bvh = Bvh::build(&crate::lights::test_plate(-100.0, 0.0, 100.0, h));
        let l = Lighting::new(&lights, Some(&bvh), 10.0);
        let open = Lighting::new(&lights, None, 10.0);
        let frac = |x: f32| {
            let p = Vec3::new(x, 0.0, 0.0);
            l.irradiance(p, Vec3::Z, 3).x / open.irradiance(p, Vec3::Z, 3).x
        };
        assert_eq!(frac(-3.0), 0.0);
        assert_eq!(frac(3.0), 1.0);
        assert!((frac(0.0) - 0.5).abs() < 0.02, "edge {}", frac(0.0));
        // Graded: monotone across the penumbra (half-width 1 at the ground).
        let row: Vec<f32> = (-4..=4).map(|k| frac(k as f32 * 0.25)).collect();
        assert!(row.windows(2).all(|w| w[0] <= w[1]), "{row:?}");
        assert!(row[2] > 0.0 && row[6] < 1.0, "{row:?}");
    }
}
