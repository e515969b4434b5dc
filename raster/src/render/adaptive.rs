//! Shading antialiasing: more than one shading point in a pixel where its coverage
//! sub-samples see different light, surface orientation or material; one elsewhere.
//!
//! The visibility buffer resolves a pixel into one [`Fragment`] per visible object, shaded once
//! at its representative sub-sample (the covered one nearest the pixel centre) and weighted by
//! its coverage. That antialiases silhouettes between objects, but not what changes *within*
//! an object's part of a pixel: a hard shadow edge, a crease, a texture edge. Those stayed
//! stair-stepped at any `aa`. In the pixels the second pass picks ([`super::antialias`]: those
//! whose first-pass radiance differs from a neighbour's), each fragment of coverage ≥ 2 is
//! checked, and split where needed:
//!
//! 1. **Probe the hull.** Each covered sub-sample's *signature* is: which lights reach it (one
//!    shadow ray per light, [`Lighting::reach_mask`]), its shading normal, and for a textured
//!    translucent material its K_d and ℓ_u. Two signatures *match* when the light masks are
//!    equal, the normals are within [`NORMAL_COS`] (about 10°) and every channel's K_d and ℓ_u
//!    within [`MATERIAL_TOLERANCE`] relative. Only the vertices of the convex hull of the
//!    fragment's sub-sample positions are probed first (the four corners of a fully covered
//!    pixel). A straight edge splits the plane into two half-planes, and a half-plane that
//!    holds a covered sub-sample holds a hull vertex, so if every hull vertex matches the
//!    first one, no straight edge crosses the fragment: it keeps its one shading point.
//! 2. **Group.** Otherwise every covered sub-sample is probed, and leaders are chosen by
//!    farthest points: the representative first, then, while some sub-sample matches no
//!    leader and there are fewer than [`MAX_GROUPS`], the one the nearest leader stands for
//!    worst (other lights first, then [`Signature::distance`]; the first in centre order on
//!    ties). Every sub-sample then joins the leader that stands for it best. Each group is
//!    shaded once at its leader and weighted by its share of the pixel's sub-samples; on a
//!    shadow edge (two light masks) that is the sub-sample nearest the pixel centre on each
//!    side. Choosing the extremes matters where K_d or ℓ_u ramps within a pixel (a
//!    bilinear texture step): leaders taken in centre order spent the groups on the ramp's
//!    middle and put the far side in with them. The first group is led by the fragment's
//!    representative, with the fragment's seed, so that point is the first pass's, and the
//!    depth layer is unchanged.
//!
//! Every layer (radiance, exitance, local, global, irradiance) is the same coverage-weighted
//! sum over the shading points, so the layers stay consistent with one another: each is the
//! box filter over the sub-samples of a function that is constant on each group. The depth
//! layer stays the distance at the nearest fragment's representative.
//!
//! What it misses: a feature that touches no hull vertex (a shadow thinner than the sub-sample
//! spacing, a curved edge that cuts a side between two corners and turns back), and a sphere
//! light's penumbra, whose probe is the ray to the light's centre (a soft shadow varies
//! smoothly, so one point per side of that ray's edge is what it needs). Everything is a
//! function of the pixel's own sub-samples, so the image is the same for any thread count.
//!
//! Cost: four probes (attributes and one shadow ray per light) per fully covered fragment of a
//! probed pixel, every sub-sample's probe where it is split, and the points of a split pixel
//! (measured in the README, "Shading antialiasing").

use glam::{Vec2, Vec3};

use super::shading::{PixelScratch, Shading};
use crate::lights::{Lighting, ShadowHints};
use crate::material::Shader;
use crate::raster::Fragment;

/// Most shading points one fragment is split into.
pub const MAX_GROUPS: usize = 4;

/// Two shading normals match when their cosine is at least this (about 10°): a smooth mesh
/// turns less than that within a pixel except near silhouettes, a crease more.
pub const NORMAL_COS: f32 = 0.985;

/// Two textured materials match when every channel's K_d and ℓ_u differ by at most this
/// fraction.
pub const MATERIAL_TOLERANCE: f32 = 0.1;

/// One shading point of a pixel: a fragment, or one part of a split fragment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadeGroup {
    /// The point: its key (object), leader triangle, coverage (sub-samples of the group),
    /// leader position and depth.
    pub fragment: Fragment,
    /// Index of the fragment (in the resolved order) it was split from.
    pub source: usize,
    /// 0 for the group led by the fragment's representative, 1.. for the others.
    pub part: u32,
}

impl ShadeGroup {
    /// The seed of this point from its fragment's seed: unchanged for part 0, so a fragment
    /// that is not split shades exactly as before.
    pub fn seed(&self, fragment_seed: u64) -> u64 {
        if self.part == 0 {
            fragment_seed
        } else {
            crate::sampling::rng::splitmix64(fragment_seed ^ u64::from(self.part))
        }
    }
}

/// What a sub-sample looks like to the shading (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Signature {
    /// Lights that reach the point.
    mask: u32,
    /// Shading normal.
    normal: Vec3,
    /// K_d (Rd_total, what the eye sees: the reduced albedo α′ bunches up near 1) and ℓ_u per
    /// channel, for textured translucent materials.
    material: Option<[Vec3; 2]>,
}

impl Signature {
    /// Stands in for a sub-sample not probed (never the case once probed; matches nothing).
    const UNKNOWN: Signature = Signature {
        mask: u32::MAX,
        normal: Vec3::ZERO,
        material: None,
    };

    /// How far apart two signatures are in what shading sees, for a sub-sample that matches
    /// no group once there are [`MAX_GROUPS`]: the largest relative difference of K_d and
    /// ℓ_u, plus the normals' 1 − cos scaled so that [`NORMAL_COS`] counts as much as
    /// [`MATERIAL_TOLERANCE`].
    fn distance(&self, other: &Signature) -> f32 {
        let relative = |a: Vec3, b: Vec3| {
            ((a - b).abs() / a.abs().max(b.abs()).max(Vec3::splat(f32::MIN_POSITIVE))).max_element()
        };
        let material = match (&self.material, &other.material) {
            (Some(a), Some(b)) => relative(a[0], b[0]).max(relative(a[1], b[1])),
            (None, None) => 0.0,
            _ => f32::INFINITY,
        };
        let turn = (1.0 - self.normal.dot(other.normal)) / (1.0 - NORMAL_COS) * MATERIAL_TOLERANCE;
        material + turn
    }

    fn matches(&self, other: &Signature) -> bool {
        let close = |a: Vec3, b: Vec3| {
            ((a - b)
                .abs()
                .cmple(a.abs().max(b.abs()) * MATERIAL_TOLERANCE))
            .all()
        };
        self.mask == other.mask
            && self.normal.dot(other.normal) >= NORMAL_COS
            && match (&self.material, &other.material) {
                (Some(a), Some(b)) => close(a[0], b[0]) && close(a[1], b[1]),
                (None, None) => true,
                _ => false,
            }
    }
}

/// A covered sub-sample of the fragment being checked.
#[derive(Clone, Copy, Debug)]
struct Covered {
    /// Column and row within the pixel.
    i: u32,
    j: u32,
    triangle: u32,
    depth: f32,
    /// Probed signature, once known.
    signature: Option<Signature>,
}

/// One thread's working memory for [`Shading::split_pixel`] (allocation-free once warm).
#[derive(Clone, Debug, Default)]
pub struct GroupScratch {
    /// The pixel's shading points, in order: its fragments' groups, fragment by fragment.
    pub groups: Vec<ShadeGroup>,
    /// Sub-samples probed so far, summed over every pixel shaded with this scratch.
    pub probes: u64,
    covered: Vec<Covered>,
    hull: Vec<usize>,
    order: Vec<usize>,
    /// Per group: leader (index into `covered`) and coverage.
    leaders: Vec<(usize, u32)>,
}

impl GroupScratch {
    /// One shading point per fragment, each unsplit.
    pub fn whole(&mut self, fragments: &[Fragment]) {
        self.groups.clear();
        self.groups
            .extend(fragments.iter().enumerate().map(|(source, f)| ShadeGroup {
                fragment: *f,
                source,
                part: 0,
            }));
    }
}

impl Shading<'_> {
    /// Resolves pixel `(x, y)` and splits its fragments where their sub-samples' signatures
    /// differ (see the module docs), into `scratch.groups`; true if any fragment was split
    /// (otherwise the points are those of [`Shading::pixel`]).
    pub fn split_pixel(&self, x: u32, y: u32, scratch: &mut PixelScratch) -> bool {
        let PixelScratch {
            fragments,
            shadows,
            groups,
            ..
        } = scratch;
        self.resolve(x, y, fragments);
        groups.groups.clear();
        let mut split = false;
        for (source, fragment) in fragments.iter().enumerate() {
            let whole = ShadeGroup {
                fragment: *fragment,
                source,
                part: 0,
            };
            if fragment.coverage < 2 {
                groups.groups.push(whole);
                continue;
            }
            self.collect_covered(x, y, fragment, groups);
            if self.hull_matches(x, y, fragment, groups, shadows) {
                groups.groups.push(whole);
                continue;
            }
            split |= self.split(x, y, source, fragment, groups, shadows);
        }
        split
    }

    /// The fragment's covered sub-samples, in centre order (the representative first).
    fn collect_covered(&self, x: u32, y: u32, fragment: &Fragment, scratch: &mut GroupScratch) {
        let vb = self.visibility;
        let aa = vb.aa();
        let object_of = &self.prep.object_of;
        scratch.covered.clear();
        for &s in vb.centre_order() {
            let (i, j) = (u32::from(s) % aa, u32::from(s) / aa);
            if let Some((triangle, depth)) = vb.sample(x, y, i, j)
                && object_of[triangle as usize] == fragment.key
            {
                scratch.covered.push(Covered {
                    i,
                    j,
                    triangle,
                    depth,
                    signature: None,
                });
            }
        }
    }

    /// Probes the hull vertices of the covered sub-samples; true when they all match.
    fn hull_matches(
        &self,
        x: u32,
        y: u32,
        fragment: &Fragment,
        scratch: &mut GroupScratch,
        shadows: &mut ShadowHints,
    ) -> bool {
        let GroupScratch {
            covered,
            hull,
            order,
            probes,
            ..
        } = scratch;
        convex_hull(covered, order, hull);
        let lighting = self.object_lighting(fragment.key as usize);
        let mut first: Option<Signature> = None;
        for &h in hull.iter() {
            let s = self.probe(
                x,
                y,
                fragment.key,
                &mut covered[h],
                &lighting,
                shadows,
                probes,
            );
            match &first {
                None => first = Some(s),
                Some(f) if !f.matches(&s) => return false,
                Some(_) => {}
            }
        }
        true
    }

    /// Probes every covered sub-sample, groups them, and pushes one shading point per group;
    /// true if there is more than one.
    fn split(
        &self,
        x: u32,
        y: u32,
        source: usize,
        fragment: &Fragment,
        scratch: &mut GroupScratch,
        shadows: &mut ShadowHints,
    ) -> bool {
        let lighting = self.object_lighting(fragment.key as usize);
        let GroupScratch {
            groups,
            probes,
            covered,
            leaders,
            ..
        } = scratch;
        for c in covered.iter_mut() {
            self.probe(x, y, fragment.key, c, &lighting, shadows, probes);
        }
        let sig = |c: &Covered| c.signature.unwrap_or(Signature::UNKNOWN);
        // How badly leader `l` stands for sub-sample `c`: other lights first, then distance.
        let rank = |l: usize, c: usize| {
            let (a, b) = (sig(&covered[l]), sig(&covered[c]));
            (a.mask != b.mask, a.distance(&b))
        };
        let worse = |a: (bool, f32), b: (bool, f32)| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1));
        // Farthest-point leaders: the representative, then repeatedly the sub-sample that no
        // leader matches and the nearest leader stands for worst (the first such in centre
        // order), while there is one and room for it.
        leaders.clear();
        leaders.push((0, 0));
        while leaders.len() < MAX_GROUPS {
            let mut worst: Option<(usize, (bool, f32))> = None;
            for c in 0..covered.len() {
                if leaders
                    .iter()
                    .any(|&(l, _)| sig(&covered[l]).matches(&sig(&covered[c])))
                {
                    continue;
                }
                let best = leaders
                    .iter()
                    .map(|&(l, _)| rank(l, c))
                    .min_by(|&a, &b| worse(a, b))
                    .unwrap_or((true, f32::INFINITY));
                if worst.is_none_or(|(_, w)| worse(best, w).is_gt()) {
                    worst = Some((c, best));
                }
            }
            match worst {
                Some((c, _)) => leaders.push((c, 0)),
                None => break,
            }
        }
        // Each sub-sample joins the leader that stands for it best (the first on ties).
        for c in 0..covered.len() {
            let mut g = 0;
            for k in 1..leaders.len() {
                if worse(rank(leaders[k].0, c), rank(leaders[g].0, c)).is_lt() {
                    g = k;
                }
            }
            leaders[g].1 += 1;
        }
        let aa = self.visibility.aa() as f32;
        for (part, &(leader, coverage)) in leaders.iter().enumerate() {
            let c = covered[leader];
            let point = if part == 0 {
                // The representative: the fragment's own point, bit for bit.
                Fragment {
                    coverage,
                    ..*fragment
                }
            } else {
                Fragment {
                    key: fragment.key,
                    triangle: c.triangle,
                    coverage,
                    sample: Vec2::new(
                        x as f32 + (c.i as f32 + 0.5) / aa,
                        y as f32 + (c.j as f32 + 0.5) / aa,
                    ),
                    depth: c.depth,
                }
            };
            groups.push(ShadeGroup {
                fragment: point,
                source,
                part: part as u32,
            });
        }
        leaders.len() > 1
    }

    /// The lights with the occluders the object's shading uses.
    fn object_lighting(&self, object: usize) -> Lighting<'_> {
        self.lighting
            .with_occluders(self.prep.occluders_for(object))
    }

    /// The signature of a covered sub-sample (computed once, then kept).
    fn probe(
        &self,
        x: u32,
        y: u32,
        key: u32,
        c: &mut Covered,
        lighting: &Lighting<'_>,
        shadows: &mut ShadowHints,
        probes: &mut u64,
    ) -> Signature {
        if let Some(s) = c.signature {
            return s;
        }
        *probes += 1;
        let aa = self.visibility.aa() as f32;
        let sample = Vec2::new(
            x as f32 + (c.i as f32 + 0.5) / aa,
            y as f32 + (c.j as f32 + 0.5) / aa,
        );
        let object = key as usize;
        let a = self.attributes(object, c.triangle, sample);
        let material = match self.prep.shader_of(object) {
            Shader::Translucent(shader) if shader.is_textured() => Some(shader.parameters_at(a.uv)),
            _ => None,
        };
        let s = Signature {
            mask: lighting.reach_mask(a.position, a.normal, shadows),
            normal: a.normal,
            material,
        };
        c.signature = Some(s);
        s
    }
}

/// Indices into `points` of the vertices of their convex hull in the (i, j) plane (Andrew's
/// monotone chain; collinear points are not vertices). One point gives itself, two or more
/// collinear ones their two ends.
fn convex_hull(points: &[Covered], order: &mut Vec<usize>, hull: &mut Vec<usize>) {
    order.clear();
    order.extend(0..points.len());
    order.sort_unstable_by_key(|&k| (points[k].j, points[k].i));
    hull.clear();
    if order.len() <= 2 {
        hull.extend_from_slice(order);
        return;
    }
    let at = |k: usize| (points[k].i as i64, points[k].j as i64);
    let turns_left = |o: usize, a: usize, b: usize| {
        let (o, a, b) = (at(o), at(a), at(b));
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0) > 0
    };
    // Lower chain forwards, then upper chain backwards; each chain drops its last point,
    // which starts the other.
    let extend = |hull: &mut Vec<usize>, start: usize, k: usize| {
        while hull.len() >= start + 2 && !turns_left(hull[hull.len() - 2], hull[hull.len() - 1], k)
        {
            hull.pop();
        }
        hull.push(k);
    };
    for &k in order.iter() {
        extend(hull, 0, k);
    }
    hull.pop();
    let start = hull.len();
    for &k in order.iter().rev() {
        extend(hull, start, k);
    }
    hull.pop();
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covered(points: &[(u32, u32)]) -> Vec<Covered> {
        points
            .iter()
            .map(|&(i, j)| Covered {
                i,
                j,
                triangle: 0,
                depth: 0.0,
                signature: None,
            })
            .collect()
    }

    fn hull_of(points: &[(u32, u32)]) -> Vec<(u32, u32)> {
        let c = covered(points);
        let (mut order, mut hull) = (Vec::new(), Vec::new());
        convex_hull(&c, &mut order, &mut hull);
        let mut v: Vec<(u32, u32)> = hull.iter().map(|&k| (c[k].i, c[k].j)).collect();
        v.sort_unstable();
        v
    }

    /// Brute force: a point is a hull vertex iff some direction makes it the unique maximum
    /// of the projection; on integer grids of side ≤ 8, directions (a, b) with |a|, |b| ≤ 16
    /// suffice (every hull edge's normal is such a direction, and a vertex's normal cone
    /// contains the sum of its two edges' normals).
    fn hull_brute(points: &[(u32, u32)]) -> Vec<(u32, u32)> {
        let mut v: Vec<(u32, u32)> = points.to_vec();
        v.sort_unstable();
        v.dedup();
        if v.len() <= 1 {
            return v;
        }
        let mut out = Vec::new();
        for &p in &v {
            let extreme = (-16i64..=16).any(|a| {
                (-16i64..=16).any(|b| {
                    let f = |q: (u32, u32)| a * q.0 as i64 + b * q.1 as i64;
                    (a, b) != (0, 0) && v.iter().all(|&q| q == p || f(q) < f(p))
                })
            });
            if extreme {
                out.push(p);
            }
        }
        out
    }

    #[test]
    fn the_hull_of_a_full_pixel_is_its_corners() {
        for aa in 2..=8u32 {
            let all: Vec<(u32, u32)> = (0..aa).flat_map(|j| (0..aa).map(move |i| (i, j))).collect();
            let want = vec![(0, 0), (0, aa - 1), (aa - 1, 0), (aa - 1, aa - 1)];
            assert_eq!(hull_of(&all), want, "aa {aa}");
        }
        assert_eq!(hull_of(&[(2, 1)]), vec![(2, 1)]);
        assert_eq!(hull_of(&[(0, 0), (1, 1), (3, 3)]), vec![(0, 0), (3, 3)]);
        assert_eq!(hull_of(&[(0, 2), (1, 2), (3, 2)]), vec![(0, 2), (3, 2)]);
    }

    #[test]
    fn hull_matches_brute_force_on_random_subsets() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state = crate::sampling::rng::splitmix64(state);
            state
        };
        for trial in 0..2000 {
            let aa = 2 + (trial % 7) as u32;
            let bits = next();
            let points: Vec<(u32, u32)> = (0..aa * aa)
                .filter(|&s| (bits >> (s % 64)) & 1 == 1 || (next() % 5 == 0))
                .map(|s| (s % aa, s / aa))
                .collect();
            if points.is_empty() {
                continue;
            }
            assert_eq!(hull_of(&points), hull_brute(&points), "aa {aa}: {points:?}");
        }
    }

    /// The property the hull test relies on: whenever a half-plane holds a covered sub-sample
    /// and its complement another, it or its complement holds a hull vertex of each kind, so
    /// the hull vertices do not all match.
    #[test]
    fn a_straight_edge_through_a_fragment_separates_two_hull_vertices() {
        let mut state = 7u64;
        let mut next = || {
            state = crate::sampling::rng::splitmix64(state);
            state
        };
        let unit = |r: u64| (r >> 11) as f64 / (1u64 << 53) as f64;
        for trial in 0..3000 {
            let aa = 2 + (trial % 7) as u32;
            let bits = next();
            let points: Vec<(u32, u32)> = (0..aa * aa)
                .filter(|&s| (bits >> (s % 64)) & 1 == 1)
                .map(|s| (s % aa, s / aa))
                .collect();
            let angle = unit(next()) * std::f64::consts::TAU;
            let offset = unit(next()) * aa as f64;
            let side = |p: (u32, u32)| {
                let (px, py) = (p.0 as f64 + 0.5, p.1 as f64 + 0.5);
                px * angle.cos() + py * angle.sin() > offset
            };
            let split = points.iter().any(|&p| side(p)) && points.iter().any(|&p| !side(p));
            let hull = hull_of(&points);
            let hull_split = hull.iter().any(|&p| side(p)) && hull.iter().any(|&p| !side(p));
            assert_eq!(split, hull_split, "aa {aa}: {points:?}, hull {hull:?}");
        }
    }

    #[test]
    fn signatures_match_within_the_tolerances_only() {
        let base = Signature {
            mask: 0b101,
            normal: Vec3::Z,
            material: Some([Vec3::splat(0.5), Vec3::new(0.1, 0.2, 0.3)]),
        };
        assert!(base.matches(&base));
        let tilt = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        assert!(base.matches(&Signature {
            normal: tilt(9.0),
            ..base
        }));
        assert!(!base.matches(&Signature {
            normal: tilt(11.0),
            ..base
        }));
        assert!(!base.matches(&Signature {
            mask: 0b100,
            ..base
        }));
        let ell = |l: Vec3| Signature {
            material: Some([Vec3::splat(0.5), l]),
            ..base
        };
        assert!(base.matches(&ell(Vec3::new(0.108, 0.2, 0.3))));
        assert!(!base.matches(&ell(Vec3::new(0.1, 0.2, 0.34))));
        assert!(!base.matches(&Signature {
            material: None,
            ..base
        }));
    }
}
