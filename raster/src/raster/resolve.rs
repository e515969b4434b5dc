//! Resolving a pixel: its covered sub-samples grouped by surface, one shading point per group.
//!
//! The renderer shades each [`Fragment`] once, at the position of its representative sub-sample,
//! and weights the result by `coverage / aa²`. Grouping by a caller-given key (typically the
//! object a triangle belongs to) lets a smooth surface be shaded once per pixel even where
//! several of its triangles meet, while silhouettes against another object still get one
//! fragment per object and an antialiased edge.

use glam::Vec2;

use super::visibility::{EMPTY, VisibilityBuffer};

/// The part of a pixel covered by one surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fragment {
    /// The group key (`key(triangle)`) shared by every sub-sample of this fragment.
    pub key: u32,
    /// Triangle seen at the representative sub-sample.
    pub triangle: u32,
    /// Number of sub-samples in the group (1..=aa²).
    pub coverage: u32,
    /// Pixel-space position of the representative sub-sample: the covered one nearest the
    /// pixel centre, ties broken by sub-sample order (row `j` first, then column `i`).
    pub sample: Vec2,
    /// NDC depth at the representative sub-sample.
    pub depth: f32,
}

impl VisibilityBuffer {
    /// Collects the fragments of pixel `(x, y)` into `out` (cleared first), one per distinct
    /// `key(triangle id)` among its covered sub-samples, sorted by depth (nearest first), then
    /// by key. `out` is left empty for pixels outside the image or with nothing drawn (and for
    /// pixels outside the window, which the caller must not ask for: debug builds assert).
    ///
    /// Allocation-free once `out` has capacity for the fragments (at most aa², usually 1–3).
    pub fn resolve(&self, x: u32, y: u32, key: impl Fn(u32) -> u32, out: &mut Vec<Fragment>) {
        out.clear();
        if !self.holds(x, y) {
            return;
        }
        let aa = self.aa();
        let (depths, ids) = (self.depths(), self.triangles());
        // Visit sub-samples nearest-to-centre first, so the first one seen of each group is its
        // representative.
        for &s in &self.centre_order {
            let (i, j) = (u32::from(s) % aa, u32::from(s) / aa);
            let idx = self.index(x, y, i, j);
            let id = ids[idx];
            if id == EMPTY {
                continue;
            }
            let k = key(id);
            match out.iter_mut().find(|f| f.key == k) {
                Some(f) => f.coverage += 1,
                None => out.push(Fragment {
                    key: k,
                    triangle: id,
                    coverage: 1,
                    sample: Vec2::new(
                        x as f32 + (i as f32 + 0.5) / aa as f32,
                        y as f32 + (j as f32 + 0.5) / aa as f32,
                    ),
                    depth: depths[idx],
                }),
            }
        }
        // Keys are distinct, so this order is total and the unstable sort deterministic.
        out.sort_unstable_by(|a, b| a.depth.total_cmp(&b.depth).then(a.key.cmp(&b.key)));
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::super::testutil::Rng;
    use super::*;
    use glam::Vec4;

    /// Draws a tiny axis-aligned quad (two triangles) covering exactly sub-sample `(c, r)` of the
    /// grid, at constant depth `z`, so tests can set individual sub-samples through the public
    /// API.
    fn set(buf: &mut VisibilityBuffer, c: u32, r: u32, id: u32, z: f32) {
        let (cols, rows) = buf.grid_size();
        let p = |sx: f32, sy: f32| {
            Vec4::new(
                2.0 * sx / cols as f32 - 1.0,
                1.0 - 2.0 * sy / rows as f32,
                z,
                1.0,
            )
        };
        let (x0, y0, x1, y1) = (
            c as f32 + 0.25,
            r as f32 + 0.25,
            c as f32 + 0.75,
            r as f32 + 0.75,
        );
        buf.rasterize_triangle(id, [p(x0, y0), p(x1, y0), p(x0, y1)]);
        buf.rasterize_triangle(id, [p(x1, y0), p(x1, y1), p(x0, y1)]);
    }

    #[test]
    fn groups_by_key_and_picks_sample_nearest_centre() {
        let aa = 4;
        let mut buf = VisibilityBuffer::new(3, 2, aa).unwrap();
        // Pixel (1, 1): sub-samples (i, j) → id, depth. Key = id / 10.
        let px = (1, 1);
        let samples = [
            ((0, 0), 11, 0.5), // key 1, corner
            ((3, 3), 12, 0.4), // key 1, corner (same distance as (0,0), later in order)
            ((2, 1), 13, 0.6), // key 1, one of the four central sub-samples
            ((0, 1), 20, 0.2), // key 2
            ((3, 0), 21, 0.3), // key 2, farther from the centre than (0, 1)
            ((1, 3), 30, 0.9), // key 3
        ];
        for ((i, j), id, z) in samples {
            set(&mut buf, px.0 * aa + i, px.1 * aa + j, id, z);
        }
        let mut out = Vec::new();
        buf.resolve(px.0, px.1, |t| t / 10, &mut out);
        let s = |i: f32, j: f32| Vec2::new(1.0 + (i + 0.5) / 4.0, 1.0 + (j + 0.5) / 4.0);
        assert_eq!(
            out,
            vec![
                Fragment {
                    key: 2,
                    triangle: 20,
                    coverage: 2,
                    sample: s(0.0, 1.0),
                    depth: 0.2
                },
                Fragment {
                    key: 1,
                    triangle: 13,
                    coverage: 3,
                    sample: s(2.0, 1.0),
                    depth: 0.6
                },
                Fragment {
                    key: 3,
                    triangle: 30,
                    coverage: 1,
                    sample: s(1.0, 3.0),
                    depth: 0.9
                },
            ]
        );
        // Tie between two corners: the earlier sub-sample (0, 0) is the representative.
        let mut buf = VisibilityBuffer::new(3, 2, aa).unwrap();
        set(&mut buf, 4 + 3, 4 + 3, 12, 0.4);
        set(&mut buf, 4, 4, 11, 0.5);
        buf.resolve(1, 1, |t| t / 10, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(
            (out[0].triangle, out[0].coverage, out[0].sample),
            (11, 2, s(0.0, 0.0))
        );
        // Empty pixel and out-of-range pixel give nothing.
        buf.resolve(0, 0, |t| t, &mut out);
        assert!(out.is_empty());
        buf.resolve(3, 0, |t| t, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn resolve_matches_brute_force_on_random_buffers() {
        let mut rng = Rng::new(21);
        for aa in 1..=8u32 {
            let mut buf = VisibilityBuffer::new(4, 3, aa).unwrap();
            let (cols, rows) = buf.grid_size();
            for _ in 0..(cols * rows / 2) {
                let (c, r) = (
                    rng.range_i64(0, cols.into()) as u32,
                    rng.range_i64(0, rows.into()) as u32,
                );
                let id = rng.range_i64(0, 9) as u32;
                set(&mut buf, c, r, id, rng.f32_in(0.0, 1.0));
            }
            let key = |t: u32| t % 3;
            let mut out = Vec::new();
            for y in 0..3 {
                for x in 0..4 {
                    buf.resolve(x, y, key, &mut out);
                    // Brute force: scan all sub-samples, keep per key the count and the
                    // (distance², order) minimum.
                    let mut groups: BTreeMap<u32, ((i32, u32), Fragment)> = BTreeMap::new();
                    for j in 0..aa {
                        for i in 0..aa {
                            let Some((id, z)) = buf.sample(x, y, i, j) else {
                                continue;
                            };
                            let fragment = Fragment {
                                key: key(id),
                                triangle: id,
                                coverage: 0,
                                sample: Vec2::new(
                                    x as f32 + (i as f32 + 0.5) / aa as f32,
                                    y as f32 + (j as f32 + 0.5) / aa as f32,
                                ),
                                depth: z,
                            };
                            // Squared distance to the centre in units of 1/(2aa), exact.
                            let off = |k: u32| (2 * k as i32 + 1 - aa as i32).pow(2);
                            let rank = (off(i) + off(j), j * aa + i);
                            let g = groups.entry(key(id)).or_insert((rank, fragment));
                            if rank < g.0 {
                                *g = (
                                    rank,
                                    Fragment {
                                        coverage: g.1.coverage,
                                        ..fragment
                                    },
                                );
                            }
                            g.1.coverage += 1;
                        }
                    }
                    let mut want: Vec<Fragment> = groups.into_values().map(|(_, f)| f).collect();
                    want.sort_by(|a, b| a.depth.total_cmp(&b.depth).then(a.key.cmp(&b.key)));
                    assert_eq!(out, want, "aa {aa} pixel ({x}, {y})");
                    let total: u32 = out.iter().map(|f| f.coverage).sum();
                    assert!(total <= aa * aa);
                }
            }
        }
    }
}
