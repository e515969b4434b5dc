//! The pinhole camera: where it is, what it looks at, and how world points map to pixels.
//!
//! Conventions (see the README): right-handed world, **z up** by default; pixel (0, 0) is the
//! top-left corner of the image, x grows to the right and y grows downwards; pixel centres are at
//! half-integer coordinates.

use glam::{Mat4, Vec3, Vec4};

/// A perspective camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (scene units).
    pub position: Vec3,
    /// Point the camera looks at.
    pub target: Vec3,
    /// Up direction (need not be orthogonal to the view direction, must not be parallel to it).
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub vfov_degrees: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// Width / height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// World → camera (right-handed, camera looks down −z).
    pub fn view_matrix(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, self.up)
    }

    /// Camera → clip space (OpenGL-style depth range [−1, 1] is *not* used: glam's
    /// `perspective_rh` maps depth to [0, 1]).
    pub fn projection_matrix(&self, near: f32, far: f32) -> Mat4 {
        Mat4::perspective_rh(self.vfov_degrees.to_radians(), self.aspect(), near, far)
    }

    /// World → clip space.
    pub fn view_projection(&self, near: f32, far: f32) -> Mat4 {
        self.projection_matrix(near, far) * self.view_matrix()
    }

    /// Clip-space position → continuous pixel coordinates (x right, y down) and NDC depth.
    /// Only meaningful for `clip.w > 0` (points in front of the camera).
    pub fn clip_to_pixel(&self, clip: Vec4) -> Vec3 {
        let ndc = clip.truncate() / clip.w;
        Vec3::new(
            (ndc.x * 0.5 + 0.5) * self.width as f32,
            (0.5 - ndc.y * 0.5) * self.height as f32,
            ndc.z,
        )
    }

    /// The world-space ray through continuous pixel coordinates `(px, py)`:
    /// `(origin, unit direction)`.
    pub fn ray(&self, px: f32, py: f32) -> (Vec3, Vec3) {
        let forward = (self.target - self.position).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        let half_h = (self.vfov_degrees.to_radians() * 0.5).tan();
        let half_w = half_h * self.aspect();
        let sx = (px / self.width as f32) * 2.0 - 1.0;
        let sy = 1.0 - (py / self.height as f32) * 2.0;
        let dir = (forward + right * (sx * half_w) + up * (sy * half_h)).normalize();
        (self.position, dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.0, -7.0, 1.3),
            target: Vec3::new(0.0, 0.0, 0.9),
            up: Vec3::Z,
            vfov_degrees: 30.0,
            width: 512,
            height: 256,
        }
    }

    #[test]
    fn target_projects_to_image_centre() {
        let cam = camera();
        let clip = cam.view_projection(0.1, 100.0) * cam.target.extend(1.0);
        let p = cam.clip_to_pixel(clip);
        assert!(
            (p.x - 256.0).abs() < 1e-3 && (p.y - 128.0).abs() < 1e-3,
            "{p}"
        );
    }

    #[test]
    fn ray_through_projected_point_hits_it() {
        let cam = camera();
        let world = Vec3::new(0.4, 0.3, 1.2);
        let p = cam.clip_to_pixel(cam.view_projection(0.1, 100.0) * world.extend(1.0));
        let (o, d) = cam.ray(p.x, p.y);
        let to = (world - o).normalize();
        assert!(d.dot(to) > 1.0 - 1e-6, "{d} vs {to}");
    }
}
