//! Procedural triangle meshes (sphere, cube, grid) for tests, benchmarks and placeholder
//! scenes. Vertices shared by neighbouring triangles are bit-identical, so the meshes are
//! closed (sphere, cube) in the exact sense the watertight ray test relies on.

use std::collections::HashMap;

use glam::Vec3;

/// Most subdivisions [`icosphere`] performs (20·4¹⁰ ≈ 21 million triangles).
pub const MAX_ICOSPHERE_SUBDIVISIONS: u32 = 10;

/// A sphere made by subdividing an icosahedron `subdivisions` times (clamped to
/// [`MAX_ICOSPHERE_SUBDIVISIONS`]): 20·4^`subdivisions` triangles, counter-clockwise seen from
/// outside, vertices on the sphere.
pub fn icosphere(subdivisions: u32, center: Vec3, radius: f32) -> Vec<[Vec3; 3]> {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions.min(MAX_ICOSPHERE_SUBDIVISIONS) {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, verts: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (verts[a.min(b) as usize], verts[a.max(b) as usize]);
                verts.push((p + q).normalize());
                verts.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for &[a, b, c] in &faces {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let world: Vec<Vec3> = verts.iter().map(|&v| center + v * radius).collect();
    faces.iter().map(|f| f.map(|i| world[i as usize])).collect()
}

/// An axis-aligned cube with each face split into `divisions × divisions` quads of two
/// triangles (`divisions` is at least 1): 12·`divisions`² triangles, counter-clockwise seen
/// from outside.
pub fn cube(center: Vec3, half_size: f32, divisions: u32) -> Vec<[Vec3; 3]> {
    let n = divisions.max(1);
    // Every vertex is computed from integer lattice coordinates by this one function, so
    // vertices shared between faces are bit-identical.
    let coord = |i: u32| half_size * (2.0 * i as f32 / n as f32 - 1.0);
    let point = |l: [u32; 3]| center + Vec3::new(coord(l[0]), coord(l[1]), coord(l[2]));
    let mut tris = Vec::with_capacity(12 * (n * n) as usize);
    // For each face: the fixed axis, its lattice value, and the two in-face axes ordered so
    // (u × v) points outwards.
    let faces = [
        (0, n, 1, 2),
        (0, 0, 2, 1),
        (1, n, 2, 0),
        (1, 0, 0, 2),
        (2, n, 0, 1),
        (2, 0, 1, 0),
    ];
    for (axis, value, ua, va) in faces {
        let lattice = |i: u32, j: u32| {
            let mut l = [0u32; 3];
            l[axis] = value;
            l[ua] = i;
            l[va] = j;
            point(l)
        };
        for i in 0..n {
            for j in 0..n {
                let (p00, p10) = (lattice(i, j), lattice(i + 1, j));
                let (p01, p11) = (lattice(i, j + 1), lattice(i + 1, j + 1));
                tris.push([p00, p10, p11]);
                tris.push([p00, p11, p01]);
            }
        }
    }
    tris
}

/// A planar grid `corner + s·edge_u + t·edge_v`, `s, t ∈ [0, 1]`, of `nu × nv` quads (each at
/// least 1) split into two triangles each, counter-clockwise seen from `edge_u × edge_v`.
pub fn grid(corner: Vec3, edge_u: Vec3, edge_v: Vec3, nu: u32, nv: u32) -> Vec<[Vec3; 3]> {
    let (nu, nv) = (nu.max(1), nv.max(1));
    let p =
        |i: u32, j: u32| corner + edge_u * (i as f32 / nu as f32) + edge_v * (j as f32 / nv as f32);
    let mut tris = Vec::with_capacity(2 * (nu * nv) as usize);
    for j in 0..nv {
        for i in 0..nu {
            tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum of the signed volumes of the tetrahedra (origin, triangle): the enclosed volume
    /// for a closed, consistently outward-wound mesh.
    fn volume(tris: &[[Vec3; 3]]) -> f64 {
        tris.iter()
            .map(|t| t[0].as_dvec3().dot(t[1].as_dvec3().cross(t[2].as_dvec3())) / 6.0)
            .sum()
    }

    /// Every directed edge appears once and its reverse once: closed and consistently wound.
    fn is_closed(tris: &[[Vec3; 3]]) -> bool {
        let key = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut edges = HashMap::new();
        for t in tris {
            for k in 0..3 {
                *edges.entry((key(t[k]), key(t[(k + 1) % 3]))).or_insert(0) += 1;
            }
        }
        edges
            .iter()
            .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
    }

    #[test]
    fn icosphere_is_closed_outward_and_close_to_the_sphere() {
        let s = icosphere(3, Vec3::new(1.0, 2.0, 3.0), 2.0);
        assert_eq!(s.len(), 20 * 64);
        assert!(is_closed(&s));
        let centred: Vec<[Vec3; 3]> = s
            .iter()
            .map(|t| t.map(|v| v - Vec3::new(1.0, 2.0, 3.0)))
            .collect();
        let v = volume(&centred);
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
        assert!(v > 0.98 * exact && v < exact, "volume {v} vs {exact}");
    }

    #[test]
    fn cube_is_closed_outward_with_exact_volume() {
        let c = cube(Vec3::ZERO, 0.5, 3);
        assert_eq!(c.len(), 12 * 9);
        assert!(is_closed(&c));
        assert!((volume(&c) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn grid_faces_along_u_cross_v() {
        let g = grid(Vec3::ZERO, Vec3::X * 2.0, Vec3::Y, 4, 3);
        assert_eq!(g.len(), 24);
        let area: f32 = g
            .iter()
            .map(|t| {
                let n = (t[1] - t[0]).cross(t[2] - t[0]);
                assert!(n.z > 0.0);
                0.5 * n.length()
            })
            .sum();
        assert!((area - 2.0).abs() < 1e-5);
    }
}
