//! The scene flattened for rendering: every triangle in world space with its object, the
//! materials resolved into shaders, and the shadow-ray BVH — only when something can occlude.

use glam::Vec3;

use super::RenderError;
use crate::geometry::Bvh;
use crate::material::Shader;
use crate::scene::{Object, Scene};

/// Largest vertex × face product for which convexity is checked exactly (beyond it a lone
/// mesh is assumed able to shadow itself, which only costs shadow rays).
const CONVEXITY_WORK: usize = 50_000_000;

/// A scene ready to render.
pub struct Prepared<'s> {
    /// The scene.
    pub scene: &'s Scene,
    /// One shader per scene material.
    pub shaders: Vec<Shader>,
    /// All triangles, object after object, in world space.
    pub triangles: Vec<[Vec3; 3]>,
    /// Index of each object's first triangle in `triangles`, plus the total at the end.
    pub first_triangle: Vec<u32>,
    /// The object of each triangle.
    pub object_of: Vec<u32>,
    /// Shadow-ray acceleration, `None` when nothing can cast a shadow.
    pub occluders: Option<Bvh>,
    /// The scene's bounding-box diagonal (for ray offsets).
    pub scale: f32,
}

impl<'s> Prepared<'s> {
    /// Resolves materials, flattens geometry and builds the BVH if shadows are possible.
    pub fn new(scene: &'s Scene) -> Result<Self, RenderError> {
        let shaders = scene
            .materials
            .iter()
            .map(Shader::new)
            .collect::<Result<Vec<_>, _>>()
            .map_err(RenderError::Material)?;
        let total: usize = scene.objects.iter().map(|o| o.mesh.triangles.len()).sum();
        if total >= u32::MAX as usize {
            return Err(RenderError::Limit(format!(
                "{total} triangles exceed the renderer's limit of {}",
                u32::MAX - 1
            )));
        }
        let mut triangles = Vec::with_capacity(total);
        let mut object_of = Vec::with_capacity(total);
        let mut first_triangle = Vec::with_capacity(scene.objects.len() + 1);
        for (i, object) in scene.objects.iter().enumerate() {
            first_triangle.push(triangles.len() as u32);
            let p = &object.mesh.positions;
            for t in &object.mesh.triangles {
                triangles.push([p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]]);
                object_of.push(i as u32);
            }
        }
        first_triangle.push(triangles.len() as u32);
        let (lo, hi) = triangles
            .iter()
            .flatten()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let scale = if triangles.is_empty() {
            1.0
        } else {
            (hi - lo).length().max(f32::MIN_POSITIVE)
        };
        let occluders = (!scene.lights.is_empty() && can_occlude(&scene.objects))
            .then(|| Bvh::build(&triangles));
        Ok(Prepared {
            scene,
            shaders,
            triangles,
            first_triangle,
            object_of,
            occluders,
            scale,
        })
    }

    /// The shader of object `object`.
    pub fn shader_of(&self, object: usize) -> &Shader {
        &self.shaders[self.scene.objects[object].material]
    }

    /// Indices of the objects with a translucent material.
    pub fn translucent_objects(&self) -> Vec<usize> {
        (0..self.scene.objects.len())
            .filter(|&i| matches!(self.shader_of(i), Shader::Translucent(_)))
            .collect()
    }
}

/// Whether any triangle can shadow another point of the scene. A single convex mesh cannot
/// (its back faces receive no light anyway, by the cosine); anything else is assumed to.
pub fn can_occlude(objects: &[Object]) -> bool {
    match objects {
        [] => false,
        [only] => !is_convex(only),
        _ => true,
    }
}

/// True if every vertex lies behind (or on) every face's plane, within a tolerance relative to
/// the mesh size.
fn is_convex(object: &Object) -> bool {
    let m = &object.mesh;
    if m.positions.len().saturating_mul(m.triangles.len()) > CONVEXITY_WORK {
        return false;
    }
    let (lo, hi) = m
        .positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let tolerance = 1e-5 * (hi - lo).length();
    m.triangles.iter().all(|t| {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let n = (b - a).cross(c - a);
        let len = n.length();
        if !(len > 0.0) {
            return true;
        }
        let n = n / len;
        m.positions.iter().all(|&v| n.dot(v - a) <= tolerance)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Mesh, shapes};

    fn object(mesh: Mesh) -> Object {
        Object {
            name: "o".into(),
            mesh,
            material: 0,
        }
    }

    #[test]
    fn convex_shapes_cannot_shadow_themselves() {
        assert!(!can_occlude(&[object(shapes::sphere(1.0, 32))]));
        assert!(!can_occlude(&[object(shapes::cuboid(Vec3::new(
            1.0, 2.0, 3.0
        )))]));
        assert!(!can_occlude(&[]));
        // Two objects, or a non-convex one, can.
        assert!(can_occlude(&[
            object(shapes::sphere(1.0, 16)),
            object(shapes::plane(glam::Vec2::ONE))
        ]));
        let bunny =
            crate::scene::obj::parse_obj(include_bytes!("../../../assets/bunny.obj")).unwrap();
        assert!(can_occlude(&[object(bunny)]));
    }
}
