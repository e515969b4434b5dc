//! `shadow_rays_match_brute_force`: the BVH's shadow-ray and closest-hit queries against a
//! brute-force loop over the triangles.
//!
//! # Input layout
//!
//! ```text
//! header     b0: mode (b0 mod 4); b1: triangle count n = b1 mod 33 (modes 0–2)
//! mode 0 grid    n triangles of 9 bytes, each coordinate (b mod 9) − 4: small integers, so
//!                that rays meet edges and vertices exactly;
//!                rays: origin 3 × ((b mod 17) − 8)/2 (half-integers), direction
//!                3 × ((b mod 9) − 4), t_max code (below)
//! mode 1 scaled  n triangles of 1 + 9 bytes: scale 2^i8 (2^−128 … 2^127), 9 × i8·scale;
//!                rays: scale 2^i8, origin 3 × i8·scale, scale 2^i8, direction 3 × i8·scale,
//!                t_max code
//! mode 2 raw     n triangles of 9 raw f32 (NaN, ±∞, subnormal: anything);
//!                rays: origin and direction 6 raw f32, t_max raw f32
//! mode 3 coherent  b1: icosphere subdivisions (bit 0: 20 or 80 triangles), cube divisions
//!                (bits 1–2: none, 1, 2 or 3), plate cells per side 1 + (bits 3–5); then
//!                light 3 bytes (x, y = i8/16, z = 2 + u8/16), scene scale 2^(i8 mod 24):
//!                a tessellated sphere and box standing on a plate, every triangle of which is
//!                input in order; then one byte per ray: bit 7 set: from the centroid of
//!                object triangle (ray index mod count) (sphere and box, in order), else from
//!                plate point (ray index mod 8, ray index / 8 mod 8) of an 8 × 8 scanline
//!                raster, jittered by (b & 127)/128 of a step; each leaves its triangle through
//!                `offset_origin` on the light's side towards the light, t_max = 1: a
//!                renderer's shadow rays in scanline order
//! rays       until the input ends, at most 64
//! t_max code u8: 0 → +∞, 1 → 0, 2 → −1, 3 → NaN, 4 → −∞, 5 → the smallest subnormal,
//!            else (b − 6)/16
//! ```
//!
//! # What is checked
//!
//! - `Bvh::build` never panics, `validate()` holds, exactly the triangles with a non-finite
//!   coordinate are `skipped()`, and `len()` counts the rest;
//! - for every ray, `occluded`, `occluded_hinted` with one hint carried across the whole
//!   sequence (as a renderer keeps one per light), and `occluded_hinted` with a fresh hint all
//!   equal the brute force: some finite input triangle is hit by the same watertight test
//!   (`Ray::new` and `Ray::intersect_triangle`) in `(0, t_max)` (an invalid ray or range: none);
//! - when occluded, both hints name (through `Bvh::triangle_index`) a triangle that really
//!   blocks the ray; when not, the carried hint is unchanged and the fresh one names none;
//! - `intersect` returns a hit exactly when the ray is occluded, and then exactly the brute
//!   force's closest hit: the smallest t, the lowest input index among equal t (the documented
//!   tie-break), with the same barycentrics, bit for bit.
//!
//! Two stated exceptions, where only soundness is checked (what the BVH reports — occluded,
//! the hints' triangles, the closest hit — must be hits of the brute force, never closer than
//! its closest), because the BVH may legitimately miss:
//!
//! - a non-zero direction component of magnitude at most [`TINY_DIR`]: the slab test counts
//!   its axis as parallel and ignores the ray's drift along it (see `TINY_DIR` in
//!   `raster/src/geometry/aabb.rs`), which matters at distances beyond `δ / TINY_DIR`;
//! - a *phantom* hit: the brute force reports a triangle at a `t` before the exact ray (an
//!   f64 slab test over `[0, t_max]`) enters the triangle's bounding box (by more than
//!   [`PHANTOM_SLACK`]), or whose box the exact ray does not touch at all. The watertight test
//!   decides in a sheared f32 frame and can claim a hit within its rounding error outside the
//!   triangle, and its `t` can be far off when the ray's length is tiny against the triangle's
//!   distance from the origin, while the box tests are conservative only for the exact ray
//!   (`regress-phantom-hit-outside-box`: a ray in the plane z = 8·10⁻²⁹ "hits" a triangle whose
//!   box ends at z = 0; `regress-phantom-hit-wrong-t`: a ray of length 8·10⁻²⁹ hits a triangle
//!   of size 40 at t = 0.003, but crosses its plane at t ≈ 11). See "Known limitations" in
//!   `docs/fuzzing.md`.

use glam::Vec3;
use lucent_raster::geometry::{Bvh, Hit, Ray, ShadowHint, offset_origin, shapes};

use super::input::{Input, pow2};

/// Most rays per input.
const MAX_RAYS: usize = 64;

/// The slab test's smallest direction component (`TINY_DIR` in `raster/src/geometry/aabb.rs`).
pub const TINY_DIR: f32 = 1e-30;

fn t_code(b: u8) -> f32 {
    match b {
        0 => f32::INFINITY,
        1 => 0.0,
        2 => -1.0,
        3 => f32::NAN,
        4 => f32::NEG_INFINITY,
        5 => f32::from_bits(1),
        _ => f32::from(b - 6) / 16.0,
    }
}

/// One shadow ray: origin, direction, t_max.
type Query = (Vec3, Vec3, f32);

fn grid_coord(r: &mut Input, m: u8) -> f32 {
    f32::from(r.u8() % m) - f32::from(m / 2)
}

/// Decodes the triangles and rays of modes 0–2.
fn decode_free(r: &mut Input, mode: u8, n: usize) -> (Vec<[Vec3; 3]>, Vec<Query>) {
    let mut tris = Vec::with_capacity(n);
    for _ in 0..n {
        let tri = match mode {
            0 => {
                let mut v = || Vec3::new(grid_coord(r, 9), grid_coord(r, 9), grid_coord(r, 9));
                [v(), v(), v()]
            }
            1 => {
                let s = r.pow2_i8();
                let mut v = || {
                    let mut c = || f32::from(r.i8()) * s;
                    Vec3::new(c(), c(), c())
                };
                [v(), v(), v()]
            }
            _ => {
                let mut v = || Vec3::new(r.f32_bits(), r.f32_bits(), r.f32_bits());
                [v(), v(), v()]
            }
        };
        tris.push(tri);
    }
    let mut rays = Vec::new();
    while !r.is_empty() && rays.len() < MAX_RAYS {
        let ray = match mode {
            0 => {
                let mut o = || grid_coord(r, 17) * 0.5;
                let origin = Vec3::new(o(), o(), o());
                let dir = Vec3::new(grid_coord(r, 9), grid_coord(r, 9), grid_coord(r, 9));
                (origin, dir, t_code(r.u8()))
            }
            1 => {
                let s = r.pow2_i8();
                let origin = Vec3::new(
                    f32::from(r.i8()) * s,
                    f32::from(r.i8()) * s,
                    f32::from(r.i8()) * s,
                );
                let s = r.pow2_i8();
                let dir = Vec3::new(
                    f32::from(r.i8()) * s,
                    f32::from(r.i8()) * s,
                    f32::from(r.i8()) * s,
                );
                (origin, dir, t_code(r.u8()))
            }
            _ => {
                let origin = Vec3::new(r.f32_bits(), r.f32_bits(), r.f32_bits());
                let dir = Vec3::new(r.f32_bits(), r.f32_bits(), r.f32_bits());
                (origin, dir, r.f32_bits())
            }
        };
        rays.push(ray);
    }
    (tris, rays)
}

/// Mode 3: a sphere and a box on a plate, shadow rays from their surfaces in scanline order.
fn decode_coherent(r: &mut Input) -> (Vec<[Vec3; 3]>, Vec<Query>) {
    let b = r.u8();
    let mut objects = shapes::icosphere(u32::from(b & 1), Vec3::new(-1.0, 0.0, 1.0), 1.0);
    let cube_divisions = u32::from((b >> 1) & 3);
    if cube_divisions > 0 {
        objects.extend(shapes::cube(
            Vec3::new(1.5, 0.5, 0.75),
            0.75,
            cube_divisions,
        ));
    }
    let cells = 1 + u32::from((b >> 3) & 7);
    let plate = shapes::grid(
        Vec3::new(-4.0, -4.0, 0.0),
        Vec3::X * 8.0,
        Vec3::Y * 8.0,
        cells,
        cells,
    );
    let light = Vec3::new(
        f32::from(r.i8()) / 16.0,
        f32::from(r.i8()) / 16.0,
        2.0 + f32::from(r.u8()) / 16.0,
    );
    let scale = pow2(i32::from(r.i8() % 24));
    let light = light * scale;
    let tris: Vec<[Vec3; 3]> = objects
        .iter()
        .chain(&plate)
        .map(|t| t.map(|v| v * scale))
        .collect();
    let n_objects = objects.len();
    // The scene scale a renderer would pass to `offset_origin`: that of the BVH's bounds.
    let scene_scale = tris
        .iter()
        .flatten()
        .fold(0.0f32, |m, v| m.max(v.abs().max_element()));
    let mut rays = Vec::new();
    while !r.is_empty() && rays.len() < MAX_RAYS {
        let k = rays.len();
        let b = r.u8();
        let (p, normal) = if b & 128 != 0 {
            let t = &tris[k % n_objects];
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            ((t[0] + t[1] + t[2]) / 3.0, n)
        } else {
            let jitter = f32::from(b & 127) / 128.0;
            let (i, j) = ((k % 8) as f32, ((k / 8) % 8) as f32);
            let p = Vec3::new(-4.0 + (i + jitter) * 1.0, -4.0 + (j + 0.5) * 1.0, 0.0) * scale;
            (p, Vec3::Z)
        };
        let towards = light - p;
        let n = if normal.dot(towards) < 0.0 {
            -normal
        } else {
            normal
        };
        let origin = offset_origin(p, n, scene_scale);
        rays.push((origin, light - origin, 1.0));
    }
    (tris, rays)
}

/// Relative margin of the phantom test: below the BVH's own `BOX_T_SLACK` (2⁻¹²), which lets
/// box tests accept entries up to that factor beyond the best hit.
pub const PHANTOM_SLACK: f64 = 1.0 / 8192.0;

/// Whether the exact ray `origin + t·dir` enters the bounding box of `tri` within `[0, t_max]`
/// no later than `t·(1 + PHANTOM_SLACK)` (an f64 slab test: f32 inputs, differences exact,
/// one rounding per division).
fn exact_ray_reaches_box_by(origin: Vec3, dir: Vec3, t_max: f32, tri: &[Vec3; 3], t: f32) -> bool {
    let (lo, hi) = (
        tri[0].min(tri[1]).min(tri[2]),
        tri[0].max(tri[1]).max(tri[2]),
    );
    let (mut near, mut far) = (0.0f64, f64::from(t_max));
    for a in 0..3 {
        let (o, d) = (f64::from(origin[a]), f64::from(dir[a]));
        let (l, h) = (f64::from(lo[a]) - o, f64::from(hi[a]) - o);
        if d == 0.0 {
            if l > 0.0 || h < 0.0 {
                return false;
            }
        } else {
            let (t0, t1) = (l / d, h / d);
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
    }
    near <= far && near <= f64::from(t) * (1.0 + PHANTOM_SLACK)
}

/// Whether triangle `tri` blocks the ray by the watertight test (what the BVH uses).
fn blocks(ray: Option<&Ray>, tri: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32)> {
    ray.and_then(|ray| ray.intersect_triangle(tri, t_max))
}

/// The property of the fuzz target `shadow_rays_match_brute_force` (see the module docs);
/// panics when it fails.
pub fn shadow_rays_match_brute_force(data: &[u8]) {
    let mut r = Input::new(data);
    let mode = r.u8() % 4;
    let (tris, rays) = if mode == 3 {
        decode_coherent(&mut r)
    } else {
        let n = usize::from(r.u8() % 33);
        decode_free(&mut r, mode, n)
    };

    let bvh = Bvh::build(&tris);
    if let Err(e) = bvh.validate() {
        panic!("validate after building {tris:?}: {e}");
    }
    let finite = |t: &[Vec3; 3]| t.iter().all(|v| v.is_finite());
    let skipped: Vec<u32> = (0..tris.len() as u32)
        .filter(|&i| !finite(&tris[i as usize]))
        .collect();
    assert_eq!(bvh.skipped(), skipped.as_slice(), "skipped triangles");
    assert_eq!(bvh.len(), tris.len() - skipped.len(), "BVH size");

    let mut carried = ShadowHint::default();
    for (k, &(origin, dir, t_max)) in rays.iter().enumerate() {
        let what = format!("ray {k}: origin {origin:?} dir {dir:?} t_max {t_max:?}");
        let ray = Ray::new(origin, dir);
        // Brute force: every finite triangle, in input order; the first of equal t wins.
        let mut closest: Option<Hit> = None;
        for (i, tri) in tris.iter().enumerate() {
            if !finite(tri) {
                continue;
            }
            if let Some((t, u, v)) = blocks(ray.as_ref(), tri, t_max)
                && closest.is_none_or(|c| t < c.t)
            {
                closest = Some(Hit {
                    t,
                    triangle: i as u32,
                    u,
                    v,
                });
            }
        }
        let want = closest.is_some();
        // The stated exception (module docs): only soundness for tiny direction components.
        let tiny = dir
            .to_array()
            .iter()
            .any(|&d| d != 0.0 && d.abs() <= TINY_DIR);
        let phantom = tris.iter().any(|tri| {
            finite(tri)
                && blocks(ray.as_ref(), tri, t_max)
                    .is_some_and(|(t, _, _)| !exact_ray_reaches_box_by(origin, dir, t_max, tri, t))
        });
        let exact = !tiny && !phantom;
        let blocker = |hint: &ShadowHint, name: &str| {
            let slot = hint
                .slot()
                .unwrap_or_else(|| panic!("{what}: occluded, but the {name} hint is empty"));
            let id = bvh
                .triangle_index(slot)
                .unwrap_or_else(|| panic!("{what}: the {name} hint names slot {slot} of none"));
            assert!(
                blocks(ray.as_ref(), &tris[id as usize], t_max).is_some(),
                "{what}: the {name} hint names triangle {id} {:?}, which does not block",
                tris[id as usize]
            );
        };

        let plain = bvh.occluded(origin, dir, t_max);
        let before = carried;
        let with_carried = bvh.occluded_hinted(origin, dir, t_max, &mut carried);
        let mut fresh = ShadowHint::default();
        let with_fresh = bvh.occluded_hinted(origin, dir, t_max, &mut fresh);
        let hit = bvh.intersect(origin, dir, t_max);
        if !exact {
            assert!(!plain || want, "{what}: occluded, the brute force says not");
            for (occluded, hint, name) in [
                (with_carried, &carried, "carried"),
                (with_fresh, &fresh, "fresh"),
            ] {
                assert!(
                    !occluded || want,
                    "{what}: occluded ({name} hint), the brute force says not"
                );
                if occluded {
                    blocker(hint, name);
                } else if name == "fresh" {
                    assert_eq!(*hint, ShadowHint::NONE, "{what}: a miss set the fresh hint");
                }
            }
            if let Some(h) = hit {
                let tri = &tris[h.triangle as usize];
                assert_eq!(
                    blocks(ray.as_ref(), tri, t_max),
                    Some((h.t, h.u, h.v)),
                    "{what}: intersect gave {h:?}, not a hit of that triangle"
                );
                assert!(
                    closest.is_some_and(|c| c.t <= h.t),
                    "{what}: {h:?} before {closest:?}"
                );
            }
            continue;
        }
        assert_eq!(plain, want, "{what}: occluded");
        assert_eq!(
            with_carried, want,
            "{what}: occluded_hinted, hint carried from {before:?}"
        );
        assert_eq!(with_fresh, want, "{what}: occluded_hinted, fresh hint");
        if want {
            blocker(&carried, "carried");
            blocker(&fresh, "fresh");
        } else {
            assert_eq!(carried, before, "{what}: a miss changed the carried hint");
            assert_eq!(fresh, ShadowHint::NONE, "{what}: a miss set the fresh hint");
        }

        match (hit, closest) {
            (None, None) => {}
            (Some(h), Some(c)) => assert!(
                h.t.to_bits() == c.t.to_bits()
                    && h.triangle == c.triangle
                    && h.u.to_bits() == c.u.to_bits()
                    && h.v.to_bits() == c.v.to_bits(),
                "{what}: intersect gave {h:?}, the brute force {c:?}"
            ),
            _ => panic!("{what}: intersect gave {hit:?}, the brute force {closest:?}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_codes_cover_the_special_values() {
        assert_eq!(t_code(0), f32::INFINITY);
        assert!(t_code(3).is_nan());
        assert_eq!(t_code(6), 0.0);
        assert_eq!(t_code(22), 1.0);
    }

    #[test]
    fn coherent_scene_rays_start_off_the_surface_and_some_are_blocked() {
        // Sphere (80 triangles), a box of 1 division, a 4 × 4 plate; light above and to the
        // side; 64 plate rays in scanline order.
        let mut data = vec![3, 1 | (1 << 1) | (3 << 3), 40, 0, 32, 0];
        data.extend([0u8; 64]);
        let mut r = Input::new(&data[1..]);
        let (tris, rays) = decode_coherent(&mut r);
        assert_eq!(tris.len(), 80 + 12 + 32);
        assert_eq!(rays.len(), 64);
        let bvh = Bvh::build(&tris);
        let blocked = rays
            .iter()
            .filter(|&&(o, d, t)| bvh.occluded(o, d, t))
            .count();
        assert!(blocked > 0 && blocked < 64, "{blocked} of 64 rays blocked");
        shadow_rays_match_brute_force(&data);
    }
}
