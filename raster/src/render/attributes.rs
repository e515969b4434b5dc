//! The surface seen at one sub-sample: position, normals, texture coordinates and view
//! direction, interpolated over the visible triangle.
//!
//! Shared by the shading of a fragment and by the probes that decide whether a pixel's
//! sub-samples need more than one shading point ([`super::adaptive`]), so that both see the
//! same surface at the same sub-sample.

use glam::{Vec2, Vec3};

use super::shading::Shading;
use crate::raster::perspective_barycentrics;

/// What a shading point needs from the geometry.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfaceAttributes {
    /// World position.
    pub position: Vec3,
    /// Interpolated shading normal (unit), turned to the side the camera sees.
    pub normal: Vec3,
    /// The triangle's unit normal, turned to the side the camera sees (zero if degenerate).
    pub geometric: Vec3,
    /// Interpolated texture coordinates (zero without UVs).
    pub uv: Vec2,
    /// Unit direction from the position to the camera.
    pub view: Vec3,
}

impl Shading<'_> {
    /// The surface of `object` seen through triangle `triangle` (a global id, as in the
    /// visibility buffer) at pixel-space position `sample`, by perspective-correct
    /// barycentrics.
    pub(crate) fn attributes(
        &self,
        object: usize,
        triangle: u32,
        sample: Vec2,
    ) -> SurfaceAttributes {
        let prep = self.prep;
        let mesh = &prep.scene.objects[object].mesh;
        let tri = mesh.triangles[triangle as usize - prep.first_triangle[object] as usize];
        let v = tri.map(|i| mesh.positions[i as usize]);
        let clip = v.map(|p| self.view_proj * p.extend(1.0));
        let b = perspective_barycentrics(clip, sample, self.camera.width, self.camera.height)
            .unwrap_or(Vec3::splat(1.0 / 3.0));
        let position = v[0] * b.x + v[1] * b.y + v[2] * b.z;
        let mut normal = (0..3)
            .fold(Vec3::ZERO, |n, k| n + mesh.normals[tri[k] as usize] * b[k])
            .normalize_or(Vec3::Z);
        let uv = mesh.uvs.as_ref().map_or(Vec2::ZERO, |uv| {
            (0..3).fold(Vec2::ZERO, |t, k| t + uv[tri[k] as usize] * b[k])
        });
        let view = (self.camera.position - position).normalize_or(Vec3::Z);
        let mut geometric = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
        if geometric.dot(view) < 0.0 {
            // Seen from behind (open meshes): shade the side the camera sees.
            normal = -normal;
            geometric = -geometric;
        }
        SurfaceAttributes {
            position,
            normal,
            geometric,
            uv,
            view,
        }
    }
}
