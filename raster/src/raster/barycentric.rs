//! Perspective-correct barycentric coordinates of the point of a triangle seen at a pixel.
//!
//! A point on the triangle is `P = b0·V0 + b1·V1 + b2·V2` with `b0 + b1 + b2 = 1`; because the
//! projection matrix is linear in homogeneous coordinates, the same combination holds for the
//! clip-space corners. The pixel at NDC `(nx, ny)` sees `P` exactly when `P.x = nx·P.w` and
//! `P.y = ny·P.w`, i.e.
//!
//! ```text
//!   Σ bᵢ (xᵢ − nx·wᵢ) = 0,   Σ bᵢ (yᵢ − ny·wᵢ) = 0,   Σ bᵢ = 1.
//! ```
//!
//! The first two equations say `b` is orthogonal to two known 3-vectors, so `b` is their cross
//! product, normalised to sum to one. This is the 2D homogeneous formulation of
//! Olano & Greer, "Triangle Scan Conversion using 2D Homogeneous Coordinates" (1997); it works
//! for the unclipped triangle even when some corners are behind the camera, which is why the
//! renderer interpolates attributes with it instead of with the clipped screen-space vertices.

use glam::{DVec3, Vec2, Vec3, Vec4};

/// Barycentric coordinates `(b0, b1, b2)` (summing to 1) of the point of the clip-space
/// triangle `clip` seen at pixel-space position `pixel` of a `width × height` image (x right,
/// y down, pixel centres at half-integers, as in `Camera::clip_to_pixel`).
///
/// The point may lie outside the triangle (coordinates outside [0, 1]) when `pixel` is outside
/// its projection. Returns `None` when the view ray is parallel to the triangle's plane (or
/// the triangle is degenerate), when the point is behind the eye (`w <= 0`), for an empty image
/// size, or for non-finite input.
pub fn perspective_barycentrics(
    clip: [Vec4; 3],
    pixel: Vec2,
    width: u32,
    height: u32,
) -> Option<Vec3> {
    if width == 0 || height == 0 || !pixel.is_finite() || !clip.iter().all(|v| v.is_finite()) {
        return None;
    }
    let nx = 2.0 * f64::from(pixel.x) / f64::from(width) - 1.0;
    let ny = 1.0 - 2.0 * f64::from(pixel.y) / f64::from(height);
    let c = clip.map(|v| v.as_dvec4());
    let ex = DVec3::new(
        c[0].x - nx * c[0].w,
        c[1].x - nx * c[1].w,
        c[2].x - nx * c[2].w,
    );
    let ey = DVec3::new(
        c[0].y - ny * c[0].w,
        c[1].y - ny * c[1].w,
        c[2].y - ny * c[2].w,
    );
    let l = ex.cross(ey);
    let sum = l.x + l.y + l.z;
    // |l| / |sum| is the size of the barycentrics: beyond 1e9 the ray is parallel for all
    // practical purposes (and exactly zero for a degenerate triangle). Finite input keeps every
    // product below 10^117, so nothing here is NaN.
    if sum.abs() <= 1e-9 * (l.x.abs() + l.y.abs() + l.z.abs()) {
        return None;
    }
    let b = l / sum;
    let w = b.x * c[0].w + b.y * c[1].w + b.z * c[2].w;
    if w <= 0.0 || !b.is_finite() {
        return None;
    }
    Some(b.as_vec3())
}

#[cfg(test)]
mod tests {
    use super::super::testutil::Rng;
    use super::*;
    use crate::camera::Camera;
    use glam::DVec3;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.3, -6.0, 1.1),
            target: Vec3::new(0.0, 0.0, 0.8),
            up: Vec3::Z,
            vfov_degrees: 40.0,
            width: 320,
            height: 200,
        }
    }

    /// Exact reference: intersect the camera ray with the triangle's plane (Cramer's rule in
    /// f64) and return the barycentrics and the ray parameter.
    fn ray_barycentrics(o: DVec3, d: DVec3, v: [DVec3; 3]) -> Option<(DVec3, f64)> {
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return None;
        }
        let s = o - v[0];
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let w = d.dot(q) / det;
        let t = e2.dot(q) / det;
        Some((DVec3::new(1.0 - u - w, u, w), t))
    }

    #[test]
    fn matches_ray_plane_intersection() {
        let cam = camera();
        let vp = cam.view_projection(0.1, 100.0);
        let mut rng = Rng::new(9);
        let mut checked = 0;
        for _ in 0..2000 {
            let mut p = || {
                Vec3::new(
                    rng.f32_in(-3.0, 3.0),
                    rng.f32_in(-4.0, 8.0),
                    rng.f32_in(-2.0, 4.0),
                )
            };
            let world = [p(), p(), p()];
            let clip = world.map(|w| vp * w.extend(1.0));
            let pixel = Vec2::new(rng.f32_in(0.0, 320.0), rng.f32_in(0.0, 200.0));
            let (o, d) = cam.ray(pixel.x, pixel.y);
            let reference =
                ray_barycentrics(o.as_dvec3(), d.as_dvec3(), world.map(|w| w.as_dvec3()));
            let got = perspective_barycentrics(clip, pixel, 320, 200);
            match (reference, got) {
                (Some((want, t)), Some(b)) if t > 0.0 && want.abs().max_element() < 20.0 => {
                    let err = (b.as_dvec3() - want).abs().max_element();
                    assert!(
                        err < 2e-3 * want.abs().max_element().max(1.0),
                        "{b} vs {want}"
                    );
                    assert!((f64::from(b.x + b.y + b.z) - 1.0).abs() < 1e-5);
                    checked += 1;
                }
                // Behind the eye: the camera does not see the plane along this ray.
                (Some((_, t)), got) if t < -1e-3 => assert_eq!(got, None, "t = {t}"),
                _ => {}
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn vertices_get_unit_coordinates_even_when_triangle_crosses_the_eye_plane() {
        let cam = camera();
        let vp = cam.view_projection(0.1, 100.0);
        // The third corner is behind the camera; the visible part still interpolates correctly.
        let world = [
            Vec3::new(-1.0, 0.0, 0.5),
            Vec3::new(1.0, 0.5, 1.0),
            Vec3::new(0.5, -9.0, 1.0),
        ];
        let clip = world.map(|w| vp * w.extend(1.0));
        for (k, w) in world.iter().take(2).enumerate() {
            let px = cam.clip_to_pixel(clip[k]);
            let b = perspective_barycentrics(clip, Vec2::new(px.x, px.y), 320, 200).unwrap();
            assert!((b[k] - 1.0).abs() < 1e-4, "{w}: {b}");
        }
        // 30 % of the way from corner 0 towards the hidden corner 2 (still in front of the camera).
        let target = world[0].lerp(world[2], 0.3);
        let px = cam.clip_to_pixel(vp * target.extend(1.0));
        let b = perspective_barycentrics(clip, Vec2::new(px.x, px.y), 320, 200).unwrap();
        assert!(
            (b - Vec3::new(0.7, 0.0, 0.3)).abs().max_element() < 1e-4,
            "{b}"
        );
    }

    #[test]
    fn degenerate_and_invalid_input_give_none() {
        let tri = [
            Vec4::new(0.0, 0.0, 0.5, 1.0),
            Vec4::new(1.0, 0.0, 0.5, 1.0),
            Vec4::new(0.0, 1.0, 0.5, 1.0),
        ];
        let px = Vec2::new(60.0, 40.0);
        assert!(perspective_barycentrics(tri, px, 100, 100).is_some());
        assert_eq!(perspective_barycentrics(tri, px, 0, 100), None);
        let collinear = [tri[0], tri[1], Vec4::new(2.0, 0.0, 0.5, 1.0)];
        assert_eq!(perspective_barycentrics(collinear, px, 100, 100), None);
        let mut nan = tri;
        nan[1].x = f32::NAN;
        assert_eq!(perspective_barycentrics(nan, px, 100, 100), None);
        // All corners behind the eye (w < 0): never seen.
        let behind = tri.map(|v| -v);
        assert_eq!(perspective_barycentrics(behind, px, 100, 100), None);
    }
}
