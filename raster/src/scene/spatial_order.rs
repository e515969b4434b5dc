//! Large meshes whose triangles come in no particular order are put in the Z-order (Morton
//! order) of their centroids when the scene is loaded.
//!
//! Scanners and modellers list a mesh's triangles strip by strip, so consecutive triangles
//! share corners, and the renderer's work on a large mesh leans on that: the shadow-ray tree
//! is built over runs of consecutive triangles (`geometry/cluster.rs`), and the samples'
//! Voronoi cells register runs of them with their grid cells (`sampling/voronoi/cells.rs`). A
//! mesh in random order (written by a tool that shuffles or sorts by something else) defeats
//! both: a 2 M-triangle sphere with its triangles shuffled took 4.7 s to render against 1.5 s.
//! Reordered along the Z-curve, consecutive triangles lie together again.
//!
//! The reorder changes no geometry, and the image is the same up to the rounding of sums
//! taken in another order; it is a pure function of the mesh, so a scene still renders to the
//! same bytes every time. Meshes below [`ORDERED_FROM`] triangles, and meshes already in
//! strip order, keep the file's order.

use glam::Vec3;
use lucent_core::internals::Grid;
use rayon::prelude::*;

use super::model::Mesh;
use crate::geometry::{self, Aabb};
use crate::parallel::sorted_by_key;

/// Meshes of fewer triangles keep the file's order: their work is small whatever the order.
pub const ORDERED_FROM: usize = 1 << 16;

/// Puts `mesh`'s triangles in the Morton order of their centroids (ties by index) when it has
/// at least [`ORDERED_FROM`] triangles and fewer than half of them touch the one before
/// (their boxes share no point). Returns whether it reordered them.
pub(crate) fn order_spatially(mesh: &mut Mesh) -> bool {
    if mesh.triangles.len() < ORDERED_FROM || in_strips(mesh) {
        return false;
    }
    let corners = |t: &[u32; 3]| t.map(|i| mesh.positions[i as usize]);
    let grid = grid_over(&mesh.positions);
    let keys = sorted_by_key(mesh.triangles.len(), |i| {
        let [a, b, c] = corners(&mesh.triangles[i]);
        grid.code((a + b + c) / 3.0)
    });
    mesh.triangles = keys
        .par_iter()
        .map(|&(_, i)| mesh.triangles[i as usize])
        .collect();
    true
}

/// The Morton grid over the box of `positions`.
fn grid_over(positions: &[Vec3]) -> Grid {
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    Grid::new(lo, hi)
}

/// True when the mesh's triangles come in strips ([`geometry::in_strips`]): at least half of
/// them touch the one before them.
fn in_strips(mesh: &Mesh) -> bool {
    let bounds = |t: &[u32; 3]| Aabb::from_triangle(&t.map(|i| mesh.positions[i as usize]));
    geometry::in_strips(&mesh.triangles, |a, b| bounds(a).touches(&bounds(b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;
    use crate::scene::shapes::sphere;

    /// A UV sphere of at least [`ORDERED_FROM`] triangles.
    fn large_sphere() -> Mesh {
        let mesh = sphere(1.0, 260);
        assert!(mesh.triangles.len() >= ORDERED_FROM);
        mesh
    }

    fn shuffled(mut mesh: Mesh, seed: u64) -> Mesh {
        let mut rng = Pcg32::new(seed, 1);
        for i in (1..mesh.triangles.len()).rev() {
            let j = rng.next_below(i as u32 + 1) as usize;
            mesh.triangles.swap(i, j);
        }
        mesh
    }

    #[test]
    fn a_shuffled_large_mesh_is_put_in_z_order() {
        let ordered = large_sphere();
        let mut mesh = shuffled(ordered.clone(), 3);
        assert!(!in_strips(&mesh));
        assert!(order_spatially(&mut mesh));
        // The same triangles (each exactly once, corners in their order), now mostly touching
        // the one before, in Morton order of their centroids.
        let mut a = mesh.triangles.clone();
        let mut b = ordered.triangles.clone();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
        assert!(in_strips(&mesh));
        let grid = grid_over(&ordered.positions);
        let positions = ordered.positions.clone();
        let code = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            grid.code((a + b + c) / 3.0)
        };
        assert!(
            mesh.triangles
                .windows(2)
                .all(|w| code(&w[0]) <= code(&w[1]))
        );
        // A pure function of the triangles: another shuffle gives the same order up to ties
        // (triangles of one Morton code keep their input order), and the order is stable.
        let again = mesh.clone();
        assert!(
            !order_spatially(&mut mesh),
            "an ordered mesh stays as it is"
        );
        assert_eq!(mesh.triangles, again.triangles);
        let mut other = shuffled(ordered, 4);
        assert!(order_spatially(&mut other));
        let codes = |m: &Mesh| m.triangles.iter().map(code).collect::<Vec<_>>();
        assert_eq!(codes(&other), codes(&mesh));
    }

    #[test]
    fn the_loader_puts_a_shuffled_mesh_file_in_z_order() {
        // A grid of 256 × 130 quads (66 560 triangles) as an OBJ file in row order and
        // shuffled: both load as the same triangles, and both in strips.
        let (n, m) = (256u32, 130u32);
        let mut obj = String::new();
        for j in 0..=m {
            for i in 0..=n {
                obj += &format!("v {i} {j} 0\n");
            }
        }
        let v = |i: u32, j: u32| 1 + j * (n + 1) + i;
        let mut faces = Vec::new();
        for j in 0..m {
            for i in 0..n {
                faces.push(format!(
                    "f {} {} {}\n",
                    v(i, j),
                    v(i + 1, j),
                    v(i + 1, j + 1)
                ));
                faces.push(format!(
                    "f {} {} {}\n",
                    v(i, j),
                    v(i + 1, j + 1),
                    v(i, j + 1)
                ));
            }
        }
        let rows = obj.clone() + &faces.concat();
        let mut rng = Pcg32::new(11, 2);
        for i in (1..faces.len()).rev() {
            faces.swap(i, rng.next_below(i as u32 + 1) as usize);
        }
        let shuffled = obj + &faces.concat();
        let scene = "[camera]\nposition = [128, -200, 300]\ntarget = [128, 65, 0]\nfov = 60\n\n\
                     [[object]]\nmesh = \"rows.obj\"\nmaterial = \"m\"\n\n\
                     [[object]]\nmesh = \"shuffled.obj\"\nmaterial = \"m\"\n\n\
                     [material.m]\ntype = \"translucent\"\npreset = \"marble\"\n\
                     mm_per_unit = 10\n\n\
                     [[light]]\ntype = \"point\"\nposition = [0, 0, 50]\nintensity = 20\n";
        let origin = crate::scene::SceneOrigin::Embedded {
            name: "t.toml".into(),
            files: [("rows.obj", rows), ("shuffled.obj", shuffled)]
                .into_iter()
                .map(|(name, text)| (name.to_string(), text.into_bytes().into()))
                .collect(),
        };
        let scene = crate::scene::parse_scene(scene, &origin).unwrap();
        let [rows, shuffled] = [0, 1].map(|o| &scene.objects[o].mesh);
        assert_eq!(rows.triangles.len(), 2 * (n * m) as usize);
        assert!(in_strips(rows) && in_strips(shuffled));
        let corners = |mesh: &Mesh| {
            let mut all: Vec<[[u32; 3]; 3]> = mesh
                .triangles
                .iter()
                .map(|t| t.map(|i| mesh.positions[i as usize].to_array().map(f32::to_bits)))
                .collect();
            all.sort_unstable();
            all
        };
        assert_eq!(corners(rows), corners(shuffled));
    }

    #[test]
    fn meshes_in_strips_or_small_keep_their_order() {
        let mut mesh = large_sphere();
        let before = mesh.triangles.clone();
        assert!(!order_spatially(&mut mesh));
        assert_eq!(mesh.triangles, before);
        let mut small = shuffled(sphere(1.0, 64), 5);
        assert!(small.triangles.len() < ORDERED_FROM && !in_strips(&small));
        let before = small.triangles.clone();
        assert!(!order_spatially(&mut small));
        assert_eq!(small.triangles, before);
    }
}
