//! Baked irradiance samples: `lucent bake` writes the lit samples of every translucent object
//! to one PLY file (see [`crate::output::ply`] for the binary layout), grouped by object, with
//! one header comment per group:
//!
//! ```text
//! comment lucent object <index> <count> <name>
//! ```
//!
//! `lucent render --samples-from FILE` reads them back instead of placing and lighting new
//! samples, after checking that every group names a translucent object of the scene with the
//! same index and name.
//!
//! The samples' positions and irradiance depend on the objects (their meshes and which of
//! them are translucent) and on the lights, not on the camera, the output or the shading
//! settings — that is why a bake can be reused. `lucent bake` writes a digest of what they
//! depend on ([`lighting_digest`]) as the comment `lucent lighting <hex>`; a render from the
//! file whose scene gives another digest warns that the baked light is stale.

use std::path::Path;

use super::irradiance::ObjectSamples;
use super::{Prepared, RenderError};
use crate::material::Shader;
use crate::output::{OutputError, SampleSet, read_ply_with_comments, write_ply};
use crate::scene::{Light, Material, Scene};
use lucent_core::Method;

/// The comment keyword that starts an object group.
pub const OBJECT_COMMENT: &str = "lucent object";

/// The comment keyword of the method the samples were baked for.
pub const METHOD_COMMENT: &str = "method ";

/// Sample groups as read from a file, each with the name of the object it was baked for.
pub type BakedGroups = Vec<(ObjectSamples, String)>;

/// The comment keyword of the [`lighting_digest`] the samples were baked with.
pub const LIGHTING_COMMENT: &str = "lucent lighting";

/// A 64-bit FNV-1a hash fed 32-bit words: a fingerprint to notice a change, not a
/// cryptographic one.
struct Digest(u64);

impl Digest {
    fn word(&mut self, w: u32) {
        self.0 = (self.0 ^ u64::from(w)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    fn floats(&mut self, values: impl IntoIterator<Item = f32>) {
        for v in values {
            self.word(v.to_bits());
        }
    }
    fn text(&mut self, s: &str) {
        self.word(s.len() as u32);
        for chunk in s.as_bytes().chunks(4) {
            let mut b = [0u8; 4];
            b[..chunk.len()].copy_from_slice(chunk);
            self.word(u32::from_le_bytes(b));
        }
    }
}

/// A fingerprint of what baked samples depend on: every object's name, mesh and whether its
/// material is translucent, and every light with its map's texels. Changing the camera, the
/// outputs, the shading settings or a translucent material's coefficients leaves it as is.
pub fn lighting_digest(scene: &Scene) -> u64 {
    let mut d = Digest(0xcbf2_9ce4_8422_2325);
    d.word(scene.objects.len() as u32);
    for o in &scene.objects {
        d.text(&o.name);
        let translucent = matches!(
            scene.materials.get(o.material),
            Some(Material::Translucent(_))
        );
        d.word(u32::from(translucent));
        let m = &o.mesh;
        d.word(m.positions.len() as u32);
        d.floats(m.positions.iter().flat_map(|p| p.to_array()));
        d.floats(m.normals.iter().flat_map(|n| n.to_array()));
        d.word(m.triangles.len() as u32);
        for t in &m.triangles {
            t.iter().for_each(|&i| d.word(i));
        }
    }
    d.word(scene.lights.len() as u32);
    for light in &scene.lights {
        match light {
            Light::Environment {
                color,
                intensity,
                map: Some(map),
                rotation_degrees,
                samples,
            } => {
                d.text("environment map");
                d.floats(color.to_array());
                d.floats([*intensity, *rotation_degrees]);
                d.word(*samples);
                let t = map.texture();
                d.word(t.width);
                d.word(t.height);
                d.floats(t.texels().flat_map(|c| c.to_array()));
            }
            // Every other light is a few numbers; its debug form lists them all.
            other => d.text(&format!("{other:?}")),
        }
    }
    d.0
}

/// Writes the sample groups (atomically), with `provenance` comments first.
pub fn write_baked(
    path: &Path,
    sets: &[ObjectSamples],
    names: &[String],
    provenance: &[String],
) -> Result<(), OutputError> {
    let mut all = SampleSet::default();
    let mut comments: Vec<String> = provenance.to_vec();
    for set in sets {
        comments.push(format!(
            "{OBJECT_COMMENT} {} {} {}",
            set.object,
            set.len(),
            names[set.object]
        ));
        all.positions.extend(&set.positions);
        all.normals.extend(&set.normals);
        all.areas.extend(&set.areas);
        all.irradiance.extend(&set.irradiance);
    }
    let refs: Vec<&str> = comments.iter().map(String::as_str).collect();
    write_ply(path, &all, &refs)
}

/// Reads sample groups written by [`write_baked`]. Returns the groups and, per group, the
/// object name it was baked for.
pub fn read_baked(path: &Path) -> Result<BakedGroups, RenderError> {
    read_baked_with_provenance(path).map(|(groups, _)| groups)
}

/// What a baked file says about how its samples were made, from its comments; `None` for
/// what it does not record (files of earlier versions have no digest).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Provenance {
    /// The [`lighting_digest`] of the scene it was baked from.
    pub lighting: Option<u64>,
    /// The method it was baked for, which chooses how the samples are lit.
    pub method: Option<Method>,
}

impl Provenance {
    /// Warnings for rendering `scene` from samples of this provenance read from `path`: the
    /// objects or lights changed since the bake, or the samples were lit for a method that
    /// lights them otherwise than the scene's.
    pub fn warnings(&self, scene: &Scene, path: &Path) -> Vec<String> {
        let mut warnings = Vec::new();
        if let Some(baked) = self.lighting
            && baked != lighting_digest(scene)
        {
            warnings.push(format!(
                "{}: baked for other objects or lights than this scene has (a mesh, a \
                 transform, a material's kind or a light changed since `lucent bake`); its \
                 irradiance is used as baked",
                path.display()
            ));
        }
        let now = scene.render.method;
        if let Some(baked) = self.method
            && baked.averages_edge_cells() != now.averages_edge_cells()
        {
            let how = |m: Method| {
                if m.averages_edge_cells() {
                    "as means over their cells"
                } else {
                    "at their positions"
                }
            };
            warnings.push(format!(
                "{}: baked for {baked}, whose samples are lit {}; {now} lights its own {} \
                 (bake with --method {now})",
                path.display(),
                how(baked),
                how(now)
            ));
        }
        warnings
    }
}

/// [`read_baked`], with the file's [`Provenance`].
pub fn read_baked_with_provenance(path: &Path) -> Result<(BakedGroups, Provenance), RenderError> {
    let (all, comments) = read_ply_with_comments(path).map_err(RenderError::BakedFile)?;
    let provenance = Provenance {
        lighting: comments.iter().find_map(|c| {
            let hex = c.strip_prefix(LIGHTING_COMMENT)?.trim();
            u64::from_str_radix(hex, 16).ok()
        }),
        method: comments
            .iter()
            .find_map(|c| c.strip_prefix(METHOD_COMMENT)?.trim().parse().ok()),
    };
    let bad = |m: String| RenderError::Baked(format!("{}: {m}", path.display()));
    let mut groups = Vec::new();
    let mut next = 0usize;
    for c in &comments {
        let Some(rest) = c.strip_prefix(OBJECT_COMMENT) else {
            continue;
        };
        let mut words = rest.trim().splitn(3, ' ');
        let object: usize = words
            .next()
            .and_then(|w| w.parse().ok())
            .ok_or_else(|| bad(format!("malformed comment '{c}'")))?;
        let count: usize = words
            .next()
            .and_then(|w| w.parse().ok())
            .ok_or_else(|| bad(format!("malformed comment '{c}'")))?;
        let name = words.next().unwrap_or("").to_string();
        let end = next
            .checked_add(count)
            .filter(|&e| e <= all.len())
            .ok_or_else(|| {
                bad(format!(
                    "object groups claim more than the file's {} samples",
                    all.len()
                ))
            })?;
        groups.push((
            ObjectSamples {
                object,
                positions: all.positions[next..end].to_vec(),
                normals: all.normals[next..end].to_vec(),
                areas: all.areas[next..end].to_vec(),
                irradiance: all.irradiance[next..end].to_vec(),
            },
            name,
        ));
        next = end;
    }
    if next != all.len() {
        return Err(bad(format!(
            "{} of {} samples belong to no object (missing '{OBJECT_COMMENT}' comments?)",
            all.len() - next,
            all.len()
        )));
    }
    Ok((groups, provenance))
}

/// Checks that baked groups fit the scene: each names a translucent object by index and name,
/// and no object appears twice.
pub fn check_fits(prep: &Prepared, sets: &[ObjectSamples]) -> Result<(), RenderError> {
    let mut seen = vec![false; prep.scene.objects.len()];
    for s in sets {
        let Some(object) = prep.scene.objects.get(s.object) else {
            return Err(RenderError::Baked(format!(
                "samples for object {} but the scene has {}",
                s.object,
                prep.scene.objects.len()
            )));
        };
        if !matches!(prep.shader_of(s.object), Shader::Translucent(_)) {
            return Err(RenderError::Baked(format!(
                "samples for object {} ('{}'), which is not translucent",
                s.object, object.name
            )));
        }
        if std::mem::replace(&mut seen[s.object], true) {
            return Err(RenderError::Baked(format!(
                "two sample groups for object {} ('{}')",
                s.object, object.name
            )));
        }
    }
    Ok(())
}

/// Matches groups read by [`read_baked`] to the scene by object index and name.
pub fn match_baked(
    scene: &Scene,
    groups: Vec<(ObjectSamples, String)>,
) -> Result<Vec<ObjectSamples>, RenderError> {
    groups
        .into_iter()
        .map(|(set, name)| match scene.objects.get(set.object) {
            Some(o) if o.name == name => Ok(set),
            Some(o) => Err(RenderError::Baked(format!(
                "group for object {} was baked for '{name}', but that object is '{}' in this scene",
                set.object, o.name
            ))),
            None => Err(RenderError::Baked(format!(
                "samples for object {} but the scene has {}",
                set.object,
                scene.objects.len()
            ))),
        })
        .collect()
}
