//! Each group's vertices: one per distinct (`v`, `vt`, `vn`) triple of its corners, numbered in
//! order of first use, with the attributes the triple names.

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::{Corner, MISSING, ObjGroup};

/// The file's vertex attributes, which every group's corners index.
pub(super) struct Attributes {
    pub positions: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub normals: Vec<Vec3>,
}

/// Which vertex each (`v`, `vt`, `vn`) triple became in the current group.
///
/// Most positions appear with one (`vt`, `vn`) pair, so each has one slot, stamped with the
/// group that filled it; other pairs go to a map keyed by group as well. Nothing is cleared
/// between groups: clearing a map costs its capacity, and a file may have a group with
/// millions of seams followed by thousands of small groups.
pub(super) struct FirstUse {
    slots: Vec<Slot>,
    others: HashMap<(u32, Corner), u32>,
}

/// The first (`vt`, `vn`) pair seen with a position in group `group`, and its vertex.
///
/// ```text
///   0        4     8     12       16
///   | group  | vt  | vn  | vertex |    one per position: 16 bytes
/// ```
#[derive(Clone, Copy)]
struct Slot {
    group: u32,
    vt: u32,
    vn: u32,
    vertex: u32,
}
const _: () = assert!(size_of::<Slot>() == 16);

impl FirstUse {
    pub fn new(positions: usize) -> FirstUse {
        let empty = Slot {
            group: u32::MAX,
            vt: 0,
            vn: 0,
            vertex: 0,
        };
        FirstUse {
            slots: vec![empty; positions],
            others: HashMap::new(),
        }
    }

    /// The vertex of `corner` in `group`, or `None` after recording `next` as its vertex.
    fn find_or_insert(&mut self, group: u32, corner: Corner, next: u32) -> Option<u32> {
        let [v, vt, vn] = corner;
        let slot = &mut self.slots[v as usize];
        if slot.group != group {
            *slot = Slot {
                group,
                vt,
                vn,
                vertex: next,
            };
            return None;
        }
        if slot.vt == vt && slot.vn == vn {
            return Some(slot.vertex);
        }
        match self.others.entry((group, corner)) {
            std::collections::hash_map::Entry::Occupied(e) => Some(*e.get()),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(next);
                None
            }
        }
    }
}

impl Attributes {
    /// One group's vertices and triangles from its corners (three per triangle).
    pub fn group(
        &self,
        usemtl: Option<u32>,
        corners: &[Corner],
        number: u32,
        first_use: &mut FirstUse,
    ) -> ObjGroup {
        let mut out = ObjGroup {
            usemtl,
            triangles: Vec::with_capacity(corners.len() / 3),
            ..ObjGroup::default()
        };
        for triangle in corners.chunks_exact(3) {
            let mut indices = [0u32; 3];
            for (index, &corner) in indices.iter_mut().zip(triangle) {
                let next = out.positions.len() as u32;
                *index = first_use
                    .find_or_insert(number, corner, next)
                    .unwrap_or_else(|| {
                        let [v, vt, vn] = corner;
                        out.positions.push(self.positions[v as usize]);
                        if vt != MISSING && !self.uvs.is_empty() {
                            out.uvs.push(self.uvs[vt as usize]);
                        }
                        if vn != MISSING && !self.normals.is_empty() {
                            out.normals.push(self.normals[vn as usize]);
                        }
                        next
                    });
            }
            out.triangles.push(indices);
        }
        out
    }
}
