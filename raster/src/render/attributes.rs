//! The surface seen at one sub-sample: position, normals, texture coordinates and view
//! direction, interpolated over the visible triangle.
//!
//! Shared by the shading of a fragment and by the probes that decide whether a pixel's
//! sub-samples need more than one shading point ([`super::adaptive`]), so that both see the
//! same surface at the same sub-sample.

use glam::{Vec2, Vec3, Vec4};

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

/// What every point on one triangle shares: its corners, their clip-space positions, normals
/// and texture coordinates, and its unit normal. Kept from pixel to pixel (neighbouring pixels
/// mostly see the same triangle), it spares the three matrix products and the cross product of
/// each point; a point's attributes are the same with or without it, bit for bit.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TriangleSetup {
    /// (object, global triangle id) it holds, if any.
    key: Option<(usize, u32)>,
    corners: [Vec3; 3],
    clip: [Vec4; 3],
    normals: [Vec3; 3],
    uvs: Option<[Vec2; 3]>,
    geometric: Vec3,
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
        self.attributes_on(object, triangle, sample, &mut TriangleSetup::default())
    }

    /// [`Shading::attributes`], reusing `setup` when it holds the same triangle (and filling it
    /// otherwise).
    pub(crate) fn attributes_on(
        &self,
        object: usize,
        triangle: u32,
        sample: Vec2,
        setup: &mut TriangleSetup,
    ) -> SurfaceAttributes {
        if setup.key != Some((object, triangle)) {
            *setup = self.triangle_setup(object, triangle);
        }
        let TriangleSetup {
            corners: v,
            clip,
            normals,
            uvs,
            geometric,
            ..
        } = *setup;
        let b = perspective_barycentrics(clip, sample, self.camera.width, self.camera.height)
            .unwrap_or(Vec3::splat(1.0 / 3.0));
        let position = v[0] * b.x + v[1] * b.y + v[2] * b.z;
        let mut normal = (0..3)
            .fold(Vec3::ZERO, |n, k| n + normals[k] * b[k])
            .normalize_or(Vec3::Z);
        let uv = uvs.map_or(Vec2::ZERO, |uv| {
            (0..3).fold(Vec2::ZERO, |t, k| t + uv[k] * b[k])
        });
        let view = (self.camera.position - position).normalize_or(Vec3::Z);
        let mut geometric = geometric;
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

    fn triangle_setup(&self, object: usize, triangle: u32) -> TriangleSetup {
        let prep = self.prep;
        let mesh = &prep.scene.objects[object].mesh;
        let tri = mesh.triangles[triangle as usize - prep.first_triangle[object] as usize];
        let corners = tri.map(|i| mesh.positions[i as usize]);
        let v = corners;
        TriangleSetup {
            key: Some((object, triangle)),
            corners,
            clip: corners.map(|p| self.view_proj * p.extend(1.0)),
            normals: tri.map(|i| mesh.normals[i as usize]),
            uvs: mesh.uvs.as_ref().map(|uv| tri.map(|i| uv[i as usize])),
            geometric: (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero(),
        }
    }
}
