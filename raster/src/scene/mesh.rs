//! Mesh preparation shared by OBJ files and built-in shapes: placement in the world
//! (scale, rotate, translate), smooth vertex normals, and the invariants of [`Mesh`].

use glam::{Mat3, Mat4, Quat, Vec3};
use rayon::prelude::*;

use super::model::Mesh;
use crate::parallel::first_where;

/// Placement of an object: `world = translate + R · (scale · local)`, with the rotation made of
/// `rotate_degrees.x` about the x axis first, then `.y` about y, then `.z` about z (fixed world
/// axes; counter-clockwise looking down the axis, right-handed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Translation (scene units).
    pub translate: Vec3,
    /// Rotations about x, then y, then z, in degrees.
    pub rotate_degrees: Vec3,
    /// Uniform scale factor (> 0).
    pub scale: f32,
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            translate: Vec3::ZERO,
            rotate_degrees: Vec3::ZERO,
            scale: 1.0,
        }
    }
}

impl Transform {
    /// The rotation part, `Rz · Ry · Rx`.
    pub fn rotation(&self) -> Mat3 {
        let r = self.rotate_degrees;
        Mat3::from_quat(
            Quat::from_rotation_z(r.z.to_radians())
                * Quat::from_rotation_y(r.y.to_radians())
                * Quat::from_rotation_x(r.x.to_radians()),
        )
    }

    /// The full affine matrix (local → world).
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_translation(self.translate)
            * Mat4::from_mat3(self.rotation())
            * Mat4::from_scale(Vec3::splat(self.scale))
    }

    /// Moves a mesh to world space: positions through the affine matrix, normals through the
    /// inverse transpose of its linear part (renormalised). The linear part is first divided
    /// by its largest entry, which leaves normal directions unchanged and keeps the inverse
    /// finite for extreme scales.
    pub fn apply(&self, mesh: &mut Mesh) {
        let m = self.matrix();
        let linear = Mat3::from_mat4(m);
        let largest = linear
            .abs()
            .to_cols_array()
            .into_iter()
            .fold(0.0f32, f32::max);
        let normal_matrix = (linear * (1.0 / largest)).inverse().transpose();
        mesh.positions
            .par_iter_mut()
            .for_each(|p| *p = m.transform_point3(*p));
        mesh.normals
            .par_iter_mut()
            .for_each(|n| *n = (normal_matrix * *n).normalize_or_zero());
    }
}

/// Area-weighted vertex normals: each vertex gets the normalised sum of the (unnormalised)
/// cross products of the triangles around it, i.e. of their normals weighted by twice their
/// area. A vertex whose triangles cancel or have no area gets +z (it then lies in a
/// degenerate region that contributes no area to anything).
pub fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            sum[i as usize] += n;
        }
    }
    sum.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Z))
        .collect()
}

/// Total surface area.
pub fn mesh_area(mesh: &Mesh) -> f64 {
    mesh.triangles.iter().map(|t| triangle_area(mesh, t)).sum()
}

/// One triangle's area, in f64.
fn triangle_area(mesh: &Mesh, t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
    0.5 * (b - a).cross(c - a).length()
}

/// Drops vertices that no triangle uses (OBJ files often carry some), renumbering indices.
/// Indices must already be in range.
pub fn drop_unused_vertices(mesh: &mut Mesh) {
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut remap = vec![u32::MAX; used.len()];
    let mut next = 0u32;
    for (i, &u) in used.iter().enumerate() {
        if u {
            remap[i] = next;
            next += 1;
        }
    }
    retain_flagged(&mut mesh.positions, &used);
    if mesh.normals.len() == used.len() {
        retain_flagged(&mut mesh.normals, &used);
    }
    if let Some(uvs) = &mut mesh.uvs
        && uvs.len() == used.len()
    {
        retain_flagged(uvs, &used);
    }
    for t in &mut mesh.triangles {
        *t = t.map(|i| remap[i as usize]);
    }
}

/// Keeps the elements of `v` whose flag in `keep` is set (and any beyond `keep`'s end): per
/// vertex or per triangle data, kept aligned with the vertices or triangles a repair keeps.
pub fn retain_flagged<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut i = 0;
    v.retain(|_| {
        i += 1;
        keep.get(i - 1).copied().unwrap_or(true)
    });
}

/// The largest accepted coordinate magnitude (scene units), in object and world space.
///
/// The renderer works in f32 and sums squared lengths and areas: with every coordinate within
/// ±10¹², a squared distance across the scene is at most 1.2·10²⁵ and a sum of 2³² such terms
/// stays below 10³⁵, well under f32's 3.4·10³⁸. Beyond it areas and densities overflow (a
/// tetrahedron at ±6·10³⁷ used to reach the sampler with an infinite area and a sample cap
/// of millions), and no sensible unit needs it: 10¹² m is seven times the Earth–Sun distance.
pub const MAX_COORDINATE: f32 = 1e12;

/// The common end of every mesh-file loader (OBJ, PLY, glTF): rejects non-finite positions and
/// UVs, drops unused vertices, keeps the file's `normals` (one per vertex, in `positions`
/// order) only when every used vertex has a usable one and otherwise computes
/// [`smooth_normals`], then checks [`validate_mesh`]. Vertex numbers in messages are 1-based.
pub fn finish_loaded_mesh(mut mesh: Mesh, normals: Option<Vec<Vec3>>) -> Result<Mesh, String> {
    reject_non_finite(&mesh)?;
    mesh.normals = normals.unwrap_or_default();
    drop_unused_vertices(&mut mesh);
    // File normals are only trusted when every vertex has a usable one.
    let units: Option<Vec<Vec3>> = (mesh.normals.len() == mesh.positions.len())
        .then(|| mesh.normals.iter().map(|&n| unit_normal(n)).collect())
        .flatten();
    mesh.normals = match units {
        Some(units) => units,
        None => smooth_normals(&mesh.positions, &mesh.triangles),
    };
    validate_mesh(&mesh)?;
    Ok(mesh)
}

/// A file's normal as a unit vector, or `None` when it has no direction (length below 10⁻¹²,
/// or not finite). A length beyond f32 (`vn 3e38 3e38 0`) is scaled by the largest component
/// first: normalised directly, it gave the zero vector.
pub fn unit_normal(n: Vec3) -> Option<Vec3> {
    if !n.is_finite() {
        return None;
    }
    let length = n.length();
    if length.is_finite() {
        (length > 1e-12).then(|| n.normalize())
    } else {
        Some((n / n.abs().max_element()).normalize())
    }
}

/// A loaded mesh's positions and UVs must be finite (vertex numbers 1-based, as in files).
pub fn reject_non_finite(mesh: &Mesh) -> Result<(), String> {
    if let Some(i) = first_where(&mesh.positions, |p| !p.is_finite()) {
        return Err(format!(
            "vertex {} is not finite: {:?}",
            i + 1,
            mesh.positions[i]
        ));
    }
    if let Some(uvs) = &mesh.uvs
        && let Some(i) = first_where(uvs, |t| !t.is_finite())
    {
        return Err(format!(
            "texture coordinate of vertex {} is not finite: {:?}",
            i + 1,
            uvs[i]
        ));
    }
    Ok(())
}

/// Checks every invariant documented on [`Mesh`]; the error says which one failed.
pub fn validate_mesh(mesh: &Mesh) -> Result<(), String> {
    let n = mesh.positions.len();
    if mesh.triangles.is_empty() {
        return Err("the mesh has no triangles".to_string());
    }
    if n > u32::MAX as usize {
        return Err(format!("too many vertices ({n})"));
    }
    // Each check on every thread; the first offender in order is the one named.
    let out_of_range = |t: &[u32; 3]| t.iter().copied().find(|&i| i as usize >= n);
    if let Some(k) = first_where(&mesh.triangles, |t| out_of_range(t).is_some()) {
        let i = out_of_range(&mesh.triangles[k]).unwrap_or_default();
        return Err(format!(
            "triangle {k} uses vertex {i}, but there are only {n} vertices"
        ));
    }
    if let Some(i) = first_where(&mesh.positions, |p| !p.is_finite()) {
        return Err(format!(
            "vertex {} has a non-finite position {:?}",
            i + 1,
            mesh.positions[i]
        ));
    }
    if let Some(i) = first_where(&mesh.positions, |p| p.abs().max_element() > MAX_COORDINATE) {
        return Err(format!(
            "vertex {} at {:?} is farther than {MAX_COORDINATE:e} units from the origin on \
             some axis (check the file's units and the object's scale)",
            i + 1,
            mesh.positions[i]
        ));
    }
    // The total is positive when one triangle's area is, and finite with every coordinate
    // within the bound, so the first triangle with an area usually settles it.
    if !mesh.triangles.iter().any(|t| triangle_area(mesh, t) > 0.0) {
        let area = mesh_area(mesh);
        return Err(format!(
            "the mesh has no usable surface area (total area {area})"
        ));
    }
    if mesh.normals.len() != n {
        return Err(format!("{} normals for {n} vertices", mesh.normals.len()));
    }
    if let Some(i) = first_where(&mesh.normals, |v| {
        !v.is_finite() || (v.length() - 1.0).abs() > 1e-3
    }) {
        return Err(format!(
            "vertex {} has an invalid normal {:?}",
            i + 1,
            mesh.normals[i]
        ));
    }
    if let Some(uvs) = &mesh.uvs {
        if uvs.len() != n {
            return Err(format!(
                "{} texture coordinates for {n} vertices",
                uvs.len()
            ));
        }
        if let Some(i) = first_where(uvs, |v| !v.is_finite()) {
            return Err(format!(
                "vertex {} has non-finite texture coordinates {:?}",
                i + 1,
                uvs[i]
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4Swizzles;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    #[test]
    fn rotations_apply_x_then_y_then_z() {
        let t = Transform {
            rotate_degrees: Vec3::new(90.0, 0.0, 0.0),
            ..Transform::default()
        };
        // +90° about x takes y to z (right-handed).
        assert!(close(t.rotation() * Vec3::Y, Vec3::Z));
        // x then z: X stays under Rx, then Rz(90°) takes X to Y.
        let t = Transform {
            rotate_degrees: Vec3::new(90.0, 0.0, 90.0),
            ..Transform::default()
        };
        assert!(close(t.rotation() * Vec3::X, Vec3::Y));
        // Y → (Rx) Z → (Rz) Z.
        assert!(close(t.rotation() * Vec3::Y, Vec3::Z));
        // Order matters: x then y takes Y → Z → X (Ry(90°) takes z to x).
        let t = Transform {
            rotate_degrees: Vec3::new(90.0, 90.0, 0.0),
            ..Transform::default()
        };
        assert!(close(t.rotation() * Vec3::Y, Vec3::X));
    }

    #[test]
    fn transform_scales_rotates_then_translates() {
        let t = Transform {
            translate: Vec3::new(1.0, 2.0, 3.0),
            rotate_degrees: Vec3::new(0.0, 0.0, 90.0),
            scale: 2.0,
        };
        // (1, 0, 0) → scale (2, 0, 0) → rotate (0, 2, 0) → translate (1, 4, 3).
        let p = t.matrix() * glam::Vec4::new(1.0, 0.0, 0.0, 1.0);
        assert!(close(p.xyz(), Vec3::new(1.0, 4.0, 3.0)));
        let mut mesh = Mesh {
            positions: vec![Vec3::X],
            normals: vec![Vec3::X],
            uvs: None,
            triangles: vec![],
        };
        t.apply(&mut mesh);
        assert!(close(mesh.positions[0], Vec3::new(1.0, 4.0, 3.0)));
        assert!(close(mesh.normals[0], Vec3::Y));
    }

    #[test]
    fn normals_use_the_inverse_transpose() {
        // A tilted plane x + z = 0 under the (non-uniform, test-only) map scale x by 2: the
        // transformed plane is x/2 + z = 0 with normal ∝ (1/2, 0, 1), not (2, 0, 1).
        let n = Vec3::new(1.0, 0.0, 1.0).normalize();
        let m = Mat3::from_diagonal(Vec3::new(2.0, 1.0, 1.0));
        let got = (m.inverse().transpose() * n).normalize();
        assert!(close(got, Vec3::new(0.5, 0.0, 1.0).normalize()));
        // Under uniform scale and rotation it is the rotated normal.
        let t = Transform {
            translate: Vec3::ONE,
            rotate_degrees: Vec3::new(30.0, -20.0, 75.0),
            scale: 3.0,
        };
        let mut mesh = Mesh {
            positions: vec![Vec3::ZERO],
            normals: vec![n],
            uvs: None,
            triangles: vec![],
        };
        t.apply(&mut mesh);
        assert!(close(mesh.normals[0], t.rotation() * n));
    }

    #[test]
    fn smooth_normals_weight_by_area() {
        // Vertex 0 shared by a big triangle in the xy plane (normal +z, area 2) and a small one
        // in the xz plane (normal −y, area 0.5): the normal is (0, −0.5, 2)·2 normalised.
        let positions = vec![
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let triangles = vec![[0, 1, 2], [0, 3, 4]];
        let n = smooth_normals(&positions, &triangles);
        assert!(close(n[0], Vec3::new(0.0, -0.5, 2.0).normalize()));
        assert!(close(n[1], Vec3::Z));
        assert!(close(n[4], -Vec3::Y));
    }

    #[test]
    fn validation_catches_each_invariant() {
        let good = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            uvs: None,
            triangles: vec![[0, 1, 2]],
        };
        assert!(validate_mesh(&good).is_ok());
        assert!((mesh_area(&good) - 0.5).abs() < 1e-12);
        let mut m = good.clone();
        m.triangles[0][2] = 3;
        assert!(validate_mesh(&m).unwrap_err().contains("vertex 3"));
        let mut m = good.clone();
        m.positions[1].x = f32::NAN;
        assert!(validate_mesh(&m).unwrap_err().contains("non-finite"));
        let mut m = good.clone();
        m.positions[2] = Vec3::new(2.0, 0.0, 0.0);
        assert!(validate_mesh(&m).unwrap_err().contains("area"));
        let mut m = good.clone();
        m.triangles.clear();
        assert!(validate_mesh(&m).unwrap_err().contains("no triangles"));
        let mut m = good.clone();
        m.uvs = Some(vec![glam::Vec2::ZERO]);
        assert!(
            validate_mesh(&m)
                .unwrap_err()
                .contains("texture coordinates")
        );
        let mut m = good;
        m.normals[0] = Vec3::ZERO;
        assert!(validate_mesh(&m).unwrap_err().contains("normal"));
    }

    /// Checked on every thread, a mesh with several offenders of a kind names the first.
    #[test]
    fn validation_names_the_first_offender() {
        let grid = 300u32;
        let mut m = Mesh {
            positions: (0..grid * grid)
                .map(|k| Vec3::new((k % grid) as f32, (k / grid) as f32, 0.0))
                .collect(),
            normals: vec![Vec3::Z; (grid * grid) as usize],
            uvs: Some(vec![glam::Vec2::ZERO; (grid * grid) as usize]),
            triangles: (0..grid * (grid - 1))
                .filter(|k| k % grid != grid - 1)
                .map(|k| [k, k + 1, k + grid])
                .collect(),
        };
        assert!(validate_mesh(&m).is_ok());
        let far = grid * grid + 7;
        let mut bad = m.clone();
        for k in [60_000, 20_000, 80_000] {
            bad.triangles[k] = [0, far, far + k as u32];
        }
        assert_eq!(
            validate_mesh(&bad).unwrap_err(),
            format!("triangle 20000 uses vertex {far}, but there are only 90000 vertices")
        );
        let mut bad = m.clone();
        // The later one where a second thread would start.
        bad.positions[45_001].y = f32::INFINITY;
        bad.positions[44_000].x = f32::NAN;
        assert!(
            validate_mesh(&bad)
                .unwrap_err()
                .starts_with("vertex 44001 has a non-finite")
        );
        let mut bad = m.clone();
        bad.positions[50_000].z = 1e30;
        bad.positions[40_000].x = -1e30;
        assert!(
            validate_mesh(&bad)
                .unwrap_err()
                .starts_with("vertex 40001 at")
        );
        let mut bad = m.clone();
        bad.normals[80_000] = Vec3::X * 2.0;
        bad.normals[10_000] = Vec3::ZERO;
        assert!(
            validate_mesh(&bad)
                .unwrap_err()
                .starts_with("vertex 10001 has an invalid normal")
        );
        if let Some(uvs) = &mut m.uvs {
            uvs[60_000].x = f32::NAN;
            uvs[50_000].y = f32::NAN;
        }
        assert!(
            validate_mesh(&m)
                .unwrap_err()
                .starts_with("vertex 50001 has non-finite")
        );
    }

    #[test]
    fn unused_vertices_are_dropped() {
        let mut m = Mesh {
            positions: vec![Vec3::ONE, Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 4],
            uvs: Some(vec![glam::Vec2::ZERO; 4]),
            triangles: vec![[1, 2, 3]],
        };
        drop_unused_vertices(&mut m);
        assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(m.uvs.as_ref().map(Vec::len), Some(3));
    }
}
