//! `convexity_is_sound`: `cannot_shadow_itself` accepts only meshes that are flat or convex.
//!
//! # Input layout
//!
//! ```text
//! b0         bit 0: 0 an arbitrary mesh, 1 a perturbed built-in shape
//! arbitrary  b: vertex count 3 + b mod 14; b: coordinate mode, bit 0: 0 scaled (then a scale
//!            2^i8, each coordinate i8·scale), 1 raw f32 bits (non-finite ones read as 0, so
//!            the mesh stays valid); the coordinates; b: triangle count b mod 25, each 3 bytes
//!            of vertex indices (b mod vertex count)
//! shape      b: kind b mod 3: sphere (radius 1, 3 + (b / 3) mod 14 segments), cuboid (size
//!            3 × (1 + u8)/16), plane (size 2 × (1 + u8)/16)
//!            b: perturbation count b mod 8, each: u16 vertex (mod vertex count), e (b mod 32),
//!            i8 a, i8 c: every copy of that position (all positions within 10⁻⁶ of the mesh's
//!            diagonal of it, as the welding does) becomes p·(1 + a·2^−e) + (0, 0, c·2^−e)
//!            b: edit count b mod 4, each: u16 triangle (mod count), b: bit 0 set flips it
//!            (swaps two corners), clear removes it
//! then       b: transform flags (both modes), bit 0: rotation by Euler angles 3 × u8·2π/256,
//!            bit 1: translation 3 × i8 · 2^(i8 mod 32), bit 2: uniform scale 2^(i8 mod 64);
//!            the bytes of each step only when its bit is set
//! ```
//!
//! # What is checked
//!
//! `cannot_shadow_itself` never panics. When it returns true, an independent exhaustive test in
//! f64 must confirm that the mesh is flat or convex. It looks at the *solid* faces: triangles
//! whose corners are pairwise farther apart than 4·10⁻⁶ of the bounding-box diagonal of all
//! positions and whose f64 normal is non-zero, and at the corners of those faces. With `TOL` =
//! 2·10⁻⁵ of the diagonal (twice the implementation's documented relative tolerance of 10⁻⁵):
//!
//! - *flat*: every corner lies within `TOL` of the plane of some solid face (or there is no
//!   solid face);
//! - *convex*: every corner lies behind or within `TOL` in front of the plane of every solid
//!   face (outward normals by the counter-clockwise convention).
//!
//! Closedness is not asked for: a mesh on the back of all its faces cannot shadow itself
//! whether or not it is closed (a box with a face removed is accepted, and rightly).

use std::f64::consts::TAU;

use glam::{DVec3, EulerRot, Mat4, Quat, Vec2, Vec3};
use lucent_raster::render::cannot_shadow_itself;
use lucent_raster::scene::{Mesh, shapes};

use super::input::{Input, pow2};

/// The check's tolerance, relative to the diagonal: twice the implementation's 10⁻⁵.
const TOL: f64 = 2e-5;
/// Corners closer than this (relative to the diagonal) make a face not solid.
const WELD: f64 = 4e-6;

fn decode_arbitrary(r: &mut Input) -> Mesh {
    let nv = 3 + usize::from(r.u8() % 14);
    let raw = r.u8() & 1 == 1;
    let scale = if raw { 1.0 } else { r.pow2_i8() };
    let coord = |r: &mut Input| {
        if raw {
            let v = r.f32_bits();
            if v.is_finite() { v } else { 0.0 }
        } else {
            f32::from(r.i8()) * scale
        }
    };
    let positions: Vec<Vec3> = (0..nv)
        .map(|_| Vec3::new(coord(r), coord(r), coord(r)))
        .collect();
    let nt = usize::from(r.u8() % 25);
    let triangles = (0..nt)
        .map(|_| [0; 3].map(|_| u32::from(r.u8()) % nv as u32))
        .collect();
    Mesh {
        normals: vec![Vec3::Z; nv],
        positions,
        uvs: None,
        triangles,
    }
}

fn diagonal(positions: &[Vec3]) -> f64 {
    let (lo, hi) = positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.as_dvec3()), hi.max(v.as_dvec3()))
        });
    if positions.is_empty() {
        0.0
    } else {
        (hi - lo).length()
    }
}

/// Decodes a perturbed built-in shape.
fn decode_shape(r: &mut Input) -> Mesh {
    let b = r.u8();
    let size = |r: &mut Input| (1.0 + f32::from(r.u8())) / 16.0;
    let mut mesh = match b % 3 {
        0 => shapes::sphere(1.0, 3 + u32::from(b / 3) % 14),
        1 => shapes::cuboid(Vec3::new(size(r), size(r), size(r))),
        _ => shapes::plane(Vec2::new(size(r), size(r))),
    };
    for _ in 0..r.u8() % 8 {
        let target = mesh.positions[usize::from(r.u16()) % mesh.positions.len()];
        let e = -i32::from(r.u8() % 32);
        let (a, c) = (f32::from(r.i8()), f32::from(r.i8()));
        let weld = (1e-6 * diagonal(&mesh.positions)) as f32;
        for p in &mut mesh.positions {
            if p.distance(target) <= weld {
                *p = *p * (1.0 + a * pow2(e)) + Vec3::Z * (c * pow2(e));
            }
        }
    }
    for _ in 0..r.u8() % 4 {
        let k = usize::from(r.u16());
        let flip = r.u8() & 1 == 1;
        if mesh.triangles.is_empty() {
            continue;
        }
        let k = k % mesh.triangles.len();
        if flip {
            mesh.triangles[k].swap(1, 2);
        } else {
            mesh.triangles.remove(k);
        }
    }
    mesh
}

fn decode_transform(r: &mut Input) -> Mat4 {
    let flags = r.u8();
    let mut m = Mat4::IDENTITY;
    if flags & 1 != 0 {
        let mut angle = || (f64::from(r.u8()) * TAU / 256.0) as f32;
        let q = Quat::from_euler(EulerRot::XYZ, angle(), angle(), angle());
        m = Mat4::from_quat(q) * m;
    }
    if flags & 2 != 0 {
        let (x, y, z) = (f32::from(r.i8()), f32::from(r.i8()), f32::from(r.i8()));
        let s = pow2(i32::from(r.i8() % 32));
        m = Mat4::from_translation(Vec3::new(x, y, z) * s) * m;
    }
    if flags & 4 != 0 {
        m = Mat4::from_scale(Vec3::splat(pow2(i32::from(r.i8() % 64)))) * m;
    }
    m
}

/// A face for the exhaustive check: a corner and the unit normal, in f64.
struct Plane {
    at: DVec3,
    normal: DVec3,
}

/// The solid face through `t`, if it is one (see the module docs).
fn solid(t: [Vec3; 3], diag: f64) -> Option<Plane> {
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let weld = WELD * diag;
    if a.distance(b) <= weld || b.distance(c) <= weld || a.distance(c) <= weld {
        return None;
    }
    let n = (b - a).cross(c - a);
    let len = n.length();
    (len > 0.0 && len.is_finite()).then(|| Plane {
        at: a,
        normal: n / len,
    })
}

/// The exhaustive check: how far from flat and from convex the mesh is, relative to the
/// diagonal: the smallest over solid faces of the largest |distance| of a corner from its plane,
/// and the largest distance of a corner in front of a solid face's plane (see the module docs).
fn exhaustive(mesh: &Mesh) -> (f64, f64) {
    let diag = diagonal(&mesh.positions);
    let mut planes = Vec::new();
    let mut corners = Vec::new();
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.positions[i as usize]);
        if let Some(plane) = solid(p, diag) {
            planes.push(plane);
            corners.extend(p.map(|v| v.as_dvec3()));
        }
    }
    let distance = |plane: &Plane, p: DVec3| plane.normal.dot(p - plane.at) / diag;
    let flat = planes
        .iter()
        .map(|plane| {
            corners
                .iter()
                .fold(0.0f64, |m, &p| m.max(distance(plane, p).abs()))
        })
        .fold(f64::INFINITY, f64::min);
    let convex = planes
        .iter()
        .flat_map(|plane| corners.iter().map(move |&p| distance(plane, p)))
        .fold(0.0f64, f64::max);
    if planes.is_empty() {
        (0.0, 0.0)
    } else {
        (flat, convex)
    }
}

/// The property of the fuzz target `convexity_is_sound` (see the module docs); panics when it
/// fails.
pub fn convexity_is_sound(data: &[u8]) {
    let mut r = Input::new(data);
    let mut mesh = if r.u8() & 1 == 0 {
        decode_arbitrary(&mut r)
    } else {
        decode_shape(&mut r)
    };
    let m = decode_transform(&mut r);
    for p in &mut mesh.positions {
        *p = m.transform_point3(*p);
    }
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        return; // the transform overflowed: not a mesh a scene can hold
    }

    let accepted = cannot_shadow_itself(&mesh);
    if !accepted {
        return;
    }
    let (off_flat, off_convex) = exhaustive(&mesh);
    assert!(
        off_flat <= TOL || off_convex <= TOL,
        "accepted a mesh that is neither flat ({off_flat:e} of the diagonal off its flattest \
         face's plane) nor convex ({off_convex:e} in front of a face): {mesh:?}"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exhaustive_check_tells_convex_from_dented() {
        let (flat, convex) = exhaustive(&shapes::cuboid(Vec3::ONE));
        assert!(flat > 0.5 && convex <= 1e-12);
        let (flat, convex) = exhaustive(&shapes::plane(Vec2::ONE));
        assert!(flat <= 1e-12 && convex <= 1e-12);
        let mut dented = shapes::cuboid(Vec3::ONE);
        let corner = dented.positions[0];
        for p in &mut dented.positions {
            if *p == corner {
                *p *= 0.2;
            }
        }
        let (flat, convex) = exhaustive(&dented);
        assert!(flat > 0.2 && convex > 0.05, "{flat} {convex}");
    }
}
