//! Built-in shapes, in object coordinates (centred on the origin, z up), with UVs, exact
//! normals and counter-clockwise triangles seen from outside (for the flat shapes: from +z).
//!
//! | shape | geometry | UVs |
//! |---|---|---|
//! | [`plane`] | `size.x × size.y` rectangle in z = 0, normal +z | (0, 0) at (−x, −y), (1, 1) at (+x, +y) |
//! | [`sphere`] | UV sphere, `segments` around, `segments / 2` (≥ 2) from pole to pole | u = longitude / 2π, v = 0 at the south pole, 1 at the north pole |
//! | [`cuboid`] | axis-aligned box of the given size, flat faces | [0, 1]² on every face |
//! | [`disk`] | disc of the given radius in z = 0, normal +z, a fan of `segments` | planar: (0.5, 0.5) at the centre |

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};

use super::model::Mesh;

/// Default number of segments around a sphere or a disk.
pub const DEFAULT_SEGMENTS: u32 = 64;

/// Smallest accepted segment count.
pub const MIN_SEGMENTS: u32 = 3;

/// Largest accepted segment count (a 4096-segment sphere has 8.4 M vertices).
pub const MAX_SEGMENTS: u32 = 4096;

/// Triangles of [`sphere`] with `segments`: two per quad of the `segments × rings` grid, less
/// the degenerate halves at the two poles.
pub fn sphere_triangles(segments: u32) -> u64 {
    let segments = u64::from(segments.clamp(MIN_SEGMENTS, MAX_SEGMENTS));
    let rings = (segments / 2).max(2);
    2 * segments * (rings - 1)
}

/// Triangles of [`disk`] with `segments`: one per segment.
pub fn disk_triangles(segments: u32) -> u64 {
    u64::from(segments.clamp(MIN_SEGMENTS, MAX_SEGMENTS))
}

/// A rectangle in the z = 0 plane, centred on the origin, facing +z (two triangles).
pub fn plane(size: Vec2) -> Mesh {
    let (hx, hy) = (0.5 * size.x, 0.5 * size.y);
    Mesh {
        positions: vec![
            Vec3::new(-hx, -hy, 0.0),
            Vec3::new(hx, -hy, 0.0),
            Vec3::new(hx, hy, 0.0),
            Vec3::new(-hx, hy, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// A UV sphere centred on the origin: `segments` meridians and `max(segments / 2, 2)` bands.
/// The seam vertices are duplicated (u = 0 and u = 1) and each pole is one vertex per segment,
/// so that UVs are continuous; normals are exactly `position / radius`.
pub fn sphere(radius: f32, segments: u32) -> Mesh {
    let segments = segments.clamp(MIN_SEGMENTS, MAX_SEGMENTS);
    let rings = (segments / 2).max(2);
    let mut mesh = Mesh {
        uvs: Some(Vec::new()),
        ..Mesh::default()
    };
    let uvs = mesh.uvs.get_or_insert_with(Vec::new);
    // Vertex (i, j): i = 0..=segments around, j = 0..=rings from the south pole up.
    for j in 0..=rings {
        let v = j as f32 / rings as f32;
        let theta = std::f32::consts::PI * (1.0 - v); // polar angle from +z
        let (sin_t, cos_t) = theta.sin_cos();
        for i in 0..=segments {
            let u = i as f32 / segments as f32;
            let phi = TAU * u;
            let (sin_p, cos_p) = phi.sin_cos();
            let n = match j {
                0 => -Vec3::Z,
                j if j == rings => Vec3::Z,
                _ => Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t),
            };
            mesh.positions.push(n * radius);
            mesh.normals.push(n);
            uvs.push(Vec2::new(u, v));
        }
    }
    let row = segments + 1;
    for j in 0..rings {
        for i in 0..segments {
            let a = j * row + i; // lower left
            let b = a + 1; // lower right
            let c = a + row + 1; // upper right
            let d = a + row; // upper left
            // Seen from outside with u growing eastwards and v northwards, (a, b, c) is
            // counter-clockwise. Skip the degenerate halves at the poles (a = b at the south
            // pole, c = d at the north pole).
            if j != 0 {
                mesh.triangles.push([a, b, c]);
            }
            if j != rings - 1 {
                mesh.triangles.push([a, c, d]);
            }
        }
    }
    mesh
}

/// An axis-aligned box centred on the origin with edge lengths `size`: 24 vertices (flat
/// normals per face), 12 triangles.
pub fn cuboid(size: Vec3) -> Mesh {
    let h = 0.5 * size;
    let mut mesh = Mesh {
        uvs: Some(Vec::new()),
        ..Mesh::default()
    };
    // For each face: outward normal n and two in-face axes (s, t) with s × t = n, so that
    // corners −s−t, +s−t, +s+t, −s+t run counter-clockwise seen from outside.
    let faces = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (-Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (-Vec3::Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (-Vec3::Z, Vec3::Y, Vec3::X),
    ];
    let uvs = mesh.uvs.get_or_insert_with(Vec::new);
    for (n, s, t) in faces {
        let base = mesh.positions.len() as u32;
        for (cs, ct) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            mesh.positions.push((n + s * cs + t * ct) * h);
            mesh.normals.push(n);
            uvs.push(Vec2::new(0.5 * (cs + 1.0), 0.5 * (ct + 1.0)));
        }
        mesh.triangles.push([base, base + 1, base + 2]);
        mesh.triangles.push([base, base + 2, base + 3]);
    }
    mesh
}

/// A disc of the given radius in the z = 0 plane, centred on the origin, facing +z: a fan of
/// `segments` triangles around a centre vertex.
pub fn disk(radius: f32, segments: u32) -> Mesh {
    let segments = segments.clamp(MIN_SEGMENTS, MAX_SEGMENTS);
    let mut mesh = Mesh {
        positions: vec![Vec3::ZERO],
        normals: vec![Vec3::Z],
        uvs: Some(vec![Vec2::splat(0.5)]),
        triangles: Vec::new(),
    };
    let uvs = mesh.uvs.get_or_insert_with(Vec::new);
    for i in 0..segments {
        let (s, c) = (TAU * i as f32 / segments as f32).sin_cos();
        mesh.positions.push(Vec3::new(c, s, 0.0) * radius);
        mesh.normals.push(Vec3::Z);
        uvs.push(Vec2::new(0.5 + 0.5 * c, 0.5 + 0.5 * s));
    }
    for i in 0..segments {
        mesh.triangles.push([0, 1 + i, 1 + (i + 1) % segments]);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::super::mesh::{mesh_area, smooth_normals, validate_mesh};
    use super::*;

    /// Every triangle's geometric normal agrees with its vertices' normals (counter-clockwise
    /// seen from the side the normals point to).
    fn assert_ccw_from_outside(m: &Mesh) {
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let g = (b - a).cross(c - a);
            assert!(g.length() > 0.0, "degenerate triangle {t:?}");
            for &i in t {
                assert!(
                    g.dot(m.normals[i as usize]) > 0.0,
                    "triangle {t:?} is clockwise"
                );
            }
        }
    }

    #[test]
    fn triangle_counts_are_those_the_shapes_build() {
        for segments in [0, 3, 4, 5, 17, 64, 5000] {
            assert_eq!(
                sphere(1.0, segments).triangles.len() as u64,
                sphere_triangles(segments),
                "sphere, {segments} segments"
            );
            assert_eq!(
                disk(1.0, segments).triangles.len() as u64,
                disk_triangles(segments),
                "disk, {segments} segments"
            );
        }
        assert_eq!(sphere_triangles(MAX_SEGMENTS), 2 * 4096 * 2047);
    }

    #[test]
    fn plane_has_the_requested_size_and_faces_up() {
        let m = plane(Vec2::new(4.0, 2.0));
        validate_mesh(&m).expect("valid");
        assert_ccw_from_outside(&m);
        assert!((mesh_area(&m) - 8.0).abs() < 1e-9);
        assert_eq!(m.uvs.as_ref().map(|u| u[2]), Some(Vec2::ONE));
    }

    #[test]
    fn sphere_normals_are_analytic_and_area_converges() {
        let r = 2.0;
        let m = sphere(r, 64);
        validate_mesh(&m).expect("valid");
        assert_ccw_from_outside(&m);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((*p / r - *n).length() < 1e-6);
            assert!((p.length() - r).abs() < 1e-5);
        }
        // Computed (area-weighted) normals of the same triangles converge to the analytic ones:
        // within a quarter of the angular step. The seam and the poles are split vertices, so
        // compare away from them.
        for segments in [64, 256] {
            let m = sphere(r, segments);
            let computed = smooth_normals(&m.positions, &m.triangles);
            let uvs = m.uvs.as_ref().expect("uvs");
            let mut worst = 0.0f32;
            for ((c, n), uv) in computed.iter().zip(&m.normals).zip(uvs) {
                if uv.x > 0.0 && uv.x < 1.0 && uv.y > 0.0 && uv.y < 1.0 {
                    worst = worst.max(c.angle_between(*n));
                }
            }
            let step = 360.0 / segments as f32;
            assert!(
                worst.to_degrees() < 0.25 * step,
                "{segments} segments: worst angle {} deg",
                worst.to_degrees()
            );
        }
        // Inscribed polyhedron: area slightly below 4πr², within 0.5 % at 64 segments.
        let exact = 4.0 * std::f64::consts::PI * (r as f64).powi(2);
        let area = mesh_area(&m);
        assert!(
            area < exact && area > 0.995 * exact,
            "area {area} vs {exact}"
        );
    }

    #[test]
    fn sphere_is_closed() {
        // Every edge (between distinct positions) is shared by exactly two triangles, once in
        // each direction: count directed edges keyed by rounded positions.
        use std::collections::HashMap;
        let m = sphere(1.0, 12);
        let key = |i: u32| {
            let p = m.positions[i as usize] * 1e4;
            (p.x.round() as i64, p.y.round() as i64, p.z.round() as i64)
        };
        let mut edges: HashMap<_, i32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
                *edges.entry((a, b)).or_default() += 1;
                *edges.entry((b, a)).or_default() -= 1;
            }
        }
        assert!(
            edges.values().all(|&v| v == 0),
            "open or inconsistent edges"
        );
    }

    #[test]
    fn cuboid_is_outward_and_has_the_right_area() {
        let m = cuboid(Vec3::new(1.0, 2.0, 3.0));
        validate_mesh(&m).expect("valid");
        assert_ccw_from_outside(&m);
        assert!((mesh_area(&m) - 2.0 * (2.0 + 3.0 + 6.0)).abs() < 1e-9);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            // Each vertex lies on the face its normal points out of.
            let half = Vec3::new(0.5, 1.0, 1.5);
            assert!((p.dot(*n) - half.dot(n.abs())).abs() < 1e-6);
        }
    }

    #[test]
    fn disk_area_and_orientation() {
        let m = disk(1.5, 256);
        validate_mesh(&m).expect("valid");
        assert_ccw_from_outside(&m);
        let exact = std::f64::consts::PI * 1.5f64.powi(2);
        assert!((mesh_area(&m) - exact).abs() < 1e-3 * exact);
    }
}
