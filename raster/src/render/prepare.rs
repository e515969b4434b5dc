//! The scene flattened for rendering: every triangle in world space with its object, the
//! materials resolved into shaders, and the shadow-ray BVH — only when something can occlude.

use glam::Vec3;
use rayon::prelude::*;

use super::RenderError;
use super::convexity::cannot_shadow_itself;
use crate::geometry::{Bvh, vertex_bounds};
use crate::material::Shader;
use crate::memory;
use crate::scene::{Object, Scene};

/// An object that cannot shadow itself gets a BVH without its own triangles when it holds at
/// least this share of the scene's triangles (so at most this many extra BVHs, each smaller
/// than the scene's).
const OWN_BVH_SHARE: usize = 4;

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
    /// Per object, the BVH of every *other* object's triangles, for the large objects that
    /// cannot shadow themselves (closed convex or flat, see `convexity`): shadow rays leaving
    /// them skip their own triangles, which are the ones near the ray's origin. On the
    /// benchmark's sphere that is 16k of 16k triangles.
    pub others: Vec<Option<Bvh>>,
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
        // What the triangles will need up to the placed samples, asked for at once: a scene
        // too large for the memory granted stops here rather than aborting midway.
        memory::probe(
            (total as u64).saturating_mul(memory::PEAK_BYTES_PER_TRIANGLE),
            memory::TRIANGLES,
        )?;
        let mut triangles = memory::with_capacity(total, memory::TRIANGLES)?;
        let mut object_of = memory::with_capacity(total, memory::TRIANGLES)?;
        let mut first_triangle = Vec::with_capacity(scene.objects.len() + 1);
        for (i, object) in scene.objects.iter().enumerate() {
            first_triangle.push(triangles.len() as u32);
            let p = &object.mesh.positions;
            // In the capacity reserved above: on every thread, in place.
            triangles.par_extend(
                object
                    .mesh
                    .triangles
                    .par_iter()
                    .map(|t| [p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]]),
            );
            object_of.resize(triangles.len(), i as u32);
        }
        first_triangle.push(triangles.len() as u32);
        let (lo, hi) = vertex_bounds(&triangles);
        let scale = if triangles.is_empty() {
            1.0
        } else {
            (hi - lo).length().max(f32::MIN_POSITIVE)
        };
        let shadows = !scene.lights.is_empty() && can_occlude(&scene.objects);
        // Which large objects cannot shadow themselves, checked while the tree is built: on a
        // scanned mesh of millions of triangles each takes a second or more, and the tree's
        // build keeps a thread idle while it makes its first splits.
        let large = |object: &Object| {
            let own = object.mesh.triangles.len();
            shadows && own > 0 && own.saturating_mul(OWN_BVH_SHARE) >= total
        };
        let (occluders, convex) = rayon::join(
            || shadows.then(|| Bvh::try_build(&triangles)).transpose(),
            || {
                let convex = |o: &Object| large(o) && cannot_shadow_itself(&o.mesh);
                scene.objects.iter().map(convex).collect::<Vec<bool>>()
            },
        );
        let occluders = occluders?;
        let others = convex
            .iter()
            .enumerate()
            .map(|(i, &convex)| {
                convex
                    .then(|| {
                        let (a, b) = (first_triangle[i] as usize, first_triangle[i + 1] as usize);
                        let rest = memory::collect(
                            total - (b - a),
                            triangles[..a].iter().chain(&triangles[b..]).copied(),
                            memory::TRIANGLES,
                        )?;
                        Bvh::try_build(&rest)
                    })
                    .transpose()
            })
            .collect::<Result<_, _>>()?;
        Ok(Prepared {
            scene,
            shaders,
            triangles,
            first_triangle,
            object_of,
            occluders,
            others,
            scale,
        })
    }

    /// The BVH for shadow rays leaving object `object`: the other objects' when it cannot
    /// shadow itself and has its own (`None` if that holds nothing), else the scene's.
    pub fn occluders_for(&self, object: usize) -> Option<&Bvh> {
        match self.others.get(object) {
            Some(Some(bvh)) => (!bvh.is_empty()).then_some(bvh),
            _ => self.occluders.as_ref(),
        }
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

/// Whether any triangle can shadow another point of the scene. A single mesh behind all its
/// faces' planes (convex or flat) cannot (its back faces receive no light anyway, by the cosine); anything else is
/// assumed to.
pub fn can_occlude(objects: &[Object]) -> bool {
    match objects {
        [] => false,
        [only] => !cannot_shadow_itself(&only.mesh),
        _ => true,
    }
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

    fn scene(objects: &str) -> Scene {
        let text = format!(
            "[camera]\nposition = [0.0, -6.0, 2.0]\ntarget = [0.0, 0.0, 1.0]\nfov = 30.0\n{objects}\n\
             [material.m]\ntype = \"lambert\"\nalbedo = 0.5\n\
             [[light]]\ntype = \"point\"\nposition = [0.0, 0.0, 5.0]\nintensity = 1.0\n"
        );
        crate::scene::parse_scene(
            &text,
            &crate::scene::SceneOrigin::Embedded {
                name: "test.toml".into(),
                files: Vec::new(),
            },
        )
        .unwrap()
    }

    const SPHERE: &str =
        "[[object]]\nshape = \"sphere\"\nradius = 1.0\nsegments = 32\nmaterial = \"m\"\n";
    const BOX: &str = "[[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\ntranslate = [3.0, 0.0, 0.0]\nmaterial = \"m\"\n";
    const PLANE: &str = "[[object]]\nshape = \"plane\"\nsize = [9.0, 9.0]\ntranslate = [0.0, 0.0, -1.0]\nmaterial = \"m\"\n";

    #[test]
    fn large_objects_that_cannot_shadow_themselves_get_the_other_objects_bvh() {
        let s = scene(&format!("{SPHERE}{BOX}{PLANE}"));
        let prep = Prepared::new(&s).unwrap();
        let all = prep
            .occluders
            .as_ref()
            .expect("three objects can occlude")
            .len();
        let own = |o: usize| (prep.first_triangle[o + 1] - prep.first_triangle[o]) as usize;
        // The sphere holds most triangles: its rays see only the box and the plane.
        assert!(own(0) * 4 >= all);
        assert_eq!(prep.occluders_for(0).map(Bvh::len), Some(all - own(0)));
        // The box and the plane are convex and flat but small: the scene's BVH.
        for o in [1, 2] {
            assert!(prep.others[o].is_none());
            assert_eq!(prep.occluders_for(o).map(Bvh::len), Some(all));
        }
        // Alone, the sphere casts no shadow at all; with only a plane beside it, the plane's
        // rays use everything and the sphere's only the plane.
        let alone = scene(SPHERE);
        assert!(Prepared::new(&alone).unwrap().occluders_for(0).is_none());
        let two = scene(&format!("{SPHERE}{PLANE}"));
        let prep = Prepared::new(&two).unwrap();
        assert_eq!(prep.occluders_for(0).map(Bvh::len), Some(2));
    }
}
