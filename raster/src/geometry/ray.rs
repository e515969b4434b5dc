//! Rays, the watertight ray/triangle test, and how to start a shadow ray on a surface.
//!
//! The triangle test is the watertight test of Woop, Benthin & Wald 2013 ("Watertight
//! Ray/Triangle Intersection", JCGT 2(1)): the ray is turned into the +z axis by a permutation
//! and a shear, the triangle's vertices are transformed into that frame, and the hit is decided
//! by the signs of three 2-D edge functions. Each edge function depends only on the two vertices
//! of its edge (and the ray), so two triangles sharing an edge compute exactly opposite values
//! for it: a ray through the edge is claimed by at least one of them and can never slip between.
//! When an edge function rounds to exactly zero it is recomputed in `f64`, where the products of
//! two `f32` are exact, as the paper prescribes. Departure from the paper: backfaces are not
//! culled, and the hit distance is divided out rather than compared in scaled form (clearer,
//! and the division only happens for triangles that pass the edge tests).

use glam::{Vec3, Vec3A};

use super::aabb::safe_inverse;

/// The closest intersection found by [`Bvh::intersect`](super::Bvh::intersect).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray in units of the direction's length (`origin + t·dir` is the
    /// hit point).
    pub t: f32,
    /// Index of the triangle in the slice given to [`Bvh::build`](super::Bvh::build).
    pub triangle: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex (the first has `1 − u − v`).
    pub v: f32,
}

/// Ray origins are pushed off the surface by `OFFSET_RELATIVE · scale` (2⁻¹⁵ ≈ 3.05·10⁻⁵).
///
/// Why relative: the error of a point computed on a surface (from barycentrics, or by the
/// rasteriser) and of the intersection test itself grows with the magnitude of the coordinates,
/// about a few ulps, i.e. a few times 6·10⁻⁸ of the largest coordinate. 2⁻¹⁵ is 256 ulps of
/// it: far above the rounding error, yet far below any feature size a scene for subsurface
/// scattering models (a 10-unit scene offsets by 0.3 thousandths of a unit).
pub const OFFSET_RELATIVE: f32 = 1.0 / 32768.0;

/// Pushes a ray origin `p` off a surface along `n` by `OFFSET_RELATIVE · scale`, so that a
/// shadow ray leaving `p` does not hit the triangle `p` lies on.
///
/// `n` is the unit geometric normal on the side the ray leaves towards (flip it when
/// `n · dir < 0`). `scale` is the size of the scene: pass [`Bvh::scale`](super::Bvh::scale)
/// (the largest absolute coordinate of the scene's bounds), which covers both the extent of the
/// scene and its distance from the origin, the two things floating-point error grows with.
pub fn offset_origin(p: Vec3, n: Vec3, scale: f32) -> Vec3 {
    p + n * (scale * OFFSET_RELATIVE)
}

/// A ray prepared for many triangle tests: the reciprocal direction for box tests, and the
/// permutation and shear of the watertight test.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (any non-zero length; distances are in units of it).
    pub dir: Vec3,
    /// The origin again, in SIMD form for the slab test.
    pub(crate) origin_a: Vec3A,
    /// Finite reciprocal of the direction, for the slab test.
    pub(crate) inv_dir: Vec3A,
    /// Rows of the shear: the transformed vertex `(x, y, z)` of a vertex `a` (relative to the
    /// origin) is `(a·shear_x, a·shear_y, a·shear_z)`. `shear_x = e_kx − (d_kx/d_kz)·e_kz`,
    /// `shear_y = e_ky − (d_ky/d_kz)·e_kz`, `shear_z = e_kz / d_kz`, where `kz` is the axis of
    /// the largest direction component and `kx, ky` the other two, swapped when `d_kz < 0` so
    /// the winding is preserved.
    shear_x: Vec3,
    shear_y: Vec3,
    shear_z: Vec3,
}

impl Ray {
    /// Prepares a ray. `None` if the origin or direction is not finite or the direction is
    /// zero.
    pub fn new(origin: Vec3, dir: Vec3) -> Option<Ray> {
        if !origin.is_finite() || !dir.is_finite() || dir == Vec3::ZERO {
            return None;
        }
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            core::mem::swap(&mut kx, &mut ky);
        }
        let axis = |k: usize| Vec3::AXES[k];
        let sz = 1.0 / dir[kz];
        let sx = dir[kx] * sz;
        let sy = dir[ky] * sz;
        Some(Ray {
            origin,
            dir,
            origin_a: origin.into(),
            inv_dir: safe_inverse(dir),
            shear_x: axis(kx) - sx * axis(kz),
            shear_y: axis(ky) - sy * axis(kz),
            shear_z: sz * axis(kz),
        })
    }

    /// The watertight test against one triangle: `Some((t, u, v))` if the ray hits it at a
    /// distance `t ∈ (0, t_max)`, with `u`, `v` the barycentric weights of the second and third
    /// vertex. Degenerate (zero-area) triangles and rays in the triangle's plane never hit.
    #[inline]
    pub fn intersect_triangle(&self, tri: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32)> {
        let a = tri[0] - self.origin;
        let b = tri[1] - self.origin;
        let c = tri[2] - self.origin;
        let (ax, ay) = (a.dot(self.shear_x), a.dot(self.shear_y));
        let (bx, by) = (b.dot(self.shear_x), b.dot(self.shear_y));
        let (cx, cy) = (c.dot(self.shear_x), c.dot(self.shear_y));
        // Edge functions: e0 for edge bc (weight of a), e1 for ca, e2 for ab.
        let mut e0 = cx * by - cy * bx;
        let mut e1 = ax * cy - ay * cx;
        let mut e2 = bx * ay - by * ax;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            let f =
                |p: f32, q: f32, r: f32, s: f32| (p as f64 * q as f64 - r as f64 * s as f64) as f32;
            e0 = f(cx, by, cy, bx);
            e1 = f(ax, cy, ay, cx);
            e2 = f(bx, ay, by, ax);
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 {
            return None;
        }
        let scaled = e0 * a.dot(self.shear_z) + e1 * b.dot(self.shear_z) + e2 * c.dot(self.shear_z);
        let inv_det = 1.0 / det;
        let t = scaled * inv_det;
        // Written so that NaN (from overflow in huge scenes) is a miss.
        if t > 0.0 && t < t_max {
            Some((t, e1 * inv_det, e2 * inv_det))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// Möller–Trumbore in f64: an independent reference for rays that are not near an edge.
    fn reference(o: Vec3, d: Vec3, t: &[Vec3; 3]) -> Option<(f64, f64, f64)> {
        let (o, d) = (o.as_dvec3(), d.as_dvec3());
        let (v0, v1, v2) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
        let (e1, e2) = (v1 - v0, v2 - v0);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return None;
        }
        let s = o - v0;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let t = e2.dot(q) / det;
        (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some((t, u, v))
    }

    fn random_vec(rng: &mut Pcg32, r: f32) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * (2.0 * r) - Vec3::splat(r)
    }

    #[test]
    fn matches_f64_moller_trumbore_away_from_edges() {
        let mut rng = Pcg32::new(7, 0);
        let (mut hits, mut checked) = (0, 0);
        for _ in 0..20_000 {
            let tri = [
                random_vec(&mut rng, 1.0),
                random_vec(&mut rng, 1.0),
                random_vec(&mut rng, 1.0),
            ];
            let o = random_vec(&mut rng, 3.0);
            let aim = (tri[0] + tri[1] + tri[2]) / 3.0 + random_vec(&mut rng, 0.5);
            let d = (aim - o) * (0.5 + rng.next_f32());
            let Some(ray) = Ray::new(o, d) else { continue };
            let want = reference(o, d, &tri);
            // Skip rays within 1e-4 of an edge, where rounding may legitimately decide.
            if let Some((_, u, v)) = want
                && (u < 1e-4 || v < 1e-4 || u + v > 1.0 - 1e-4)
            {
                continue;
            }
            let got = ray.intersect_triangle(&tri, f32::INFINITY);
            checked += 1;
            match (got, want) {
                (None, None) => {}
                (Some((t, u, v)), Some((rt, ru, rv))) => {
                    hits += 1;
                    assert!(((t as f64 - rt) / rt).abs() < 1e-4, "t {t} vs {rt}");
                    assert!((u as f64 - ru).abs() < 1e-4 && (v as f64 - rv).abs() < 1e-4);
                }
                _ => panic!("ray {o} {d} tri {tri:?}: got {got:?}, want {want:?}"),
            }
        }
        assert!(
            checked > 15_000 && hits > 5_000,
            "{checked} checked, {hits} hits"
        );
    }

    #[test]
    fn respects_the_open_distance_interval() {
        let tri = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let ray = Ray::new(Vec3::new(0.25, 0.25, 0.0), Vec3::Z * 2.0).unwrap();
        let (t, u, v) = ray.intersect_triangle(&tri, 1.0).unwrap();
        assert_eq!((t, u, v), (0.5, 0.25, 0.25));
        assert_eq!(
            ray.intersect_triangle(&tri, 0.5),
            None,
            "t_max is exclusive"
        );
        let behind = Ray::new(Vec3::new(0.25, 0.25, 2.0), Vec3::Z).unwrap();
        assert_eq!(behind.intersect_triangle(&tri, f32::INFINITY), None);
        // Both windings hit (no backface culling).
        let flipped = [tri[0], tri[2], tri[1]];
        assert!(ray.intersect_triangle(&flipped, 1.0).is_some());
    }

    #[test]
    fn degenerate_triangles_and_bad_rays_never_hit() {
        let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        let point = [Vec3::ONE; 3];
        let ray = Ray::new(Vec3::new(1.0, 0.0, -1.0), Vec3::Z).unwrap();
        assert_eq!(ray.intersect_triangle(&line, f32::INFINITY), None);
        let ray = Ray::new(Vec3::new(1.0, 1.0, 0.0), Vec3::Z).unwrap();
        assert_eq!(ray.intersect_triangle(&point, f32::INFINITY), None);
        assert!(Ray::new(Vec3::ZERO, Vec3::ZERO).is_none());
        assert!(Ray::new(Vec3::NAN, Vec3::Z).is_none());
        assert!(Ray::new(Vec3::ZERO, Vec3::new(0.0, f32::INFINITY, 0.0)).is_none());
    }

    #[test]
    fn shared_edge_and_vertex_are_claimed() {
        // A fan of 7 triangles around a shared vertex c, with irrational-looking coordinates so
        // that rounding is not trivially exact. Rays aimed exactly at c, and at points of the
        // shared edges, from many directions, must hit at least one triangle of the fan.
        let c = Vec3::new(0.3127, -0.1733, 0.4519);
        let ring: Vec<Vec3> = (0..7)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / 7.0 + 0.1;
                c + Vec3::new(a.cos(), a.sin(), 0.05 * (3.0 * a).sin())
            })
            .collect();
        let fan: Vec<[Vec3; 3]> = (0..7).map(|k| [c, ring[k], ring[(k + 1) % 7]]).collect();
        let mut rng = Pcg32::new(3, 1);
        for _ in 0..2_000 {
            let from = Vec3::new(
                rng.next_f32() * 2.0 - 1.0,
                rng.next_f32() * 2.0 - 1.0,
                1.0 + rng.next_f32(),
            );
            let k = (rng.next_u32() % 7) as usize;
            let s = 0.05 + 0.9 * rng.next_f32();
            for target in [c, c + (ring[k] - c) * s] {
                let ray = Ray::new(target + from, -from).unwrap();
                let n = fan
                    .iter()
                    .filter(|t| ray.intersect_triangle(t, 2.0).is_some())
                    .count();
                assert!(n >= 1, "ray {ray:?} slipped through the fan at {target}");
            }
        }
    }

    #[test]
    fn offset_moves_along_normal_by_relative_amount() {
        let p = offset_origin(Vec3::new(1.0, 2.0, 3.0), Vec3::Z, 32768.0);
        assert_eq!(p, Vec3::new(1.0, 2.0, 4.0));
    }
}
