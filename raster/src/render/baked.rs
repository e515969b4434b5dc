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

use std::path::Path;

use super::irradiance::ObjectSamples;
use super::{Prepared, RenderError};
use crate::material::Shader;
use crate::output::{OutputError, SampleSet, read_ply_with_comments, write_ply};
use crate::scene::Scene;

/// The comment keyword that starts an object group.
pub const OBJECT_COMMENT: &str = "lucent object";

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
pub fn read_baked(path: &Path) -> Result<Vec<(ObjectSamples, String)>, RenderError> {
    let (all, comments) = read_ply_with_comments(path).map_err(RenderError::BakedFile)?;
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
    Ok(groups)
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
