//! Cavities: closed components nested inside other closed components.
//!
//! The solid is `{w ≥ ½}` with `w` the winding number of the oriented
//! surface. Orienting every component outward on its own makes a hollow
//! object solid: inside the inner skin of a hollow ball `w = 1 + 1 = 2`. A
//! nested closed surface bounds a cavity when it faces the other way than
//! the surface around it, `w = 1 − 1 = 0` in the cavity (the even–odd rule
//! of nesting depth, which a consistently oriented export follows). So the
//! input's own orientation decides, relative to its container's:
//! - it faces the other way than its container (as given, by the majority
//!   of its triangles): a cavity, oriented against the container;
//! - it faces the same way (an assembly's inner part, or a sloppy export of
//!   a hollow part): a solid inside a solid, oriented like the container,
//!   with a warning that says how to mark a cavity.
//!
//! The outermost components are oriented outward, whatever the input says
//! (a whole surface exported inside out is the common error). A component
//! is nested in a closed one when its bounding box lies inside the other's
//! and sampled vertices of it have `|w| > ¾` of that one alone; its
//! container is the smallest such, among the [`MAX_CONTAINERS`] largest.

use crate::bvh::Bvh;
use crate::geom::{bounds, V3};

/// Vertices of a component tested against a container.
const SAMPLES: usize = 16;

/// Only the largest this many closed components are tried as containers: each is
/// compared with every component, and an export of 100 k voxel cubes must not take
/// 10¹⁰ comparisons (minutes).
pub const MAX_CONTAINERS: usize = 256;

/// One edge-connected component of a surface, oriented outward.
#[derive(Clone, Debug)]
pub(crate) struct Component {
    /// Its triangles (indices into the surface's triangles).
    pub triangles: Vec<usize>,
    /// Every edge of it belongs to exactly two of its triangles.
    pub closed: bool,
    /// Enclosed volume (m³), ≥ 0 (the component is oriented outward).
    pub volume: f64,
    /// The input faced outward (most of its triangles were not flipped).
    pub given_outward: bool,
}

/// What the nesting makes of each component.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Nesting {
    /// Per component: true when it bounds a cavity (to be oriented inward).
    pub inward: Vec<bool>,
    /// Closed components inside another that face the same way (kept solid).
    pub same_facing: Vec<usize>,
}

/// Decides which components of the outward-oriented `triangles` are cavities.
pub(crate) fn nest(vertices: &[V3], triangles: &[[usize; 3]], components: &[Component]) -> Nesting {
    let boxes: Vec<(V3, V3)> =
        components.iter().map(|c| bounding_box(vertices, triangles, &c.triangles)).collect();
    let mut parent: Vec<Option<usize>> = vec![None; components.len()];
    let mut closed: Vec<usize> = (0..components.len()).filter(|&c| components[c].closed).collect();
    closed.sort_by(|&a, &b| components[b].volume.total_cmp(&components[a].volume).then(a.cmp(&b)));
    closed.truncate(MAX_CONTAINERS);
    for &outer in &closed {
        let candidates: Vec<usize> = (0..components.len())
            .filter(|&c| c != outer && components[c].volume < components[outer].volume)
            .filter(|&c| box_inside(boxes[c], boxes[outer]))
            .collect();
        if candidates.is_empty() {
            continue;
        }
        let bvh = Bvh::new(
            components[outer].triangles.iter().map(|&t| triangles[t].map(|v| vertices[v])).collect(),
        );
        for c in candidates {
            let smaller = parent[c].is_none_or(|p| components[outer].volume < components[p].volume);
            if smaller && samples(vertices, triangles, &components[c]).all(|q| bvh.winding(q).abs() > 0.75) {
                parent[c] = Some(outer);
            }
        }
    }
    // Containers first: a container encloses more volume than what it holds.
    let mut order: Vec<usize> = (0..components.len()).collect();
    order.sort_by(|&a, &b| components[b].volume.total_cmp(&components[a].volume).then(a.cmp(&b)));
    let mut nesting = Nesting { inward: vec![false; components.len()], same_facing: Vec::new() };
    for c in order {
        let Some(p) = parent[c] else { continue };
        let same = components[c].given_outward == components[p].given_outward;
        nesting.inward[c] = nesting.inward[p] ^ !same;
        if same {
            nesting.same_facing.push(c);
        }
    }
    nesting.same_facing.sort_unstable();
    nesting
}

/// Up to [`SAMPLES`] of the component's distinct vertices, spread over
/// their (canonical, by position) numbering: all of them for a small part.
/// First corners of every few triangles depended on how each triangle was
/// written, and a box crossing the side of an L-bracket was taken as nested
/// when the one corner outside was never a first corner.
fn samples<'a>(
    vertices: &'a [V3],
    triangles: &'a [[usize; 3]],
    c: &'a Component,
) -> impl Iterator<Item = V3> + 'a {
    let mut corners: Vec<usize> = c.triangles.iter().flat_map(|&t| triangles[t]).collect();
    corners.sort_unstable();
    corners.dedup();
    let step = corners.len().div_ceil(SAMPLES).max(1);
    corners.into_iter().step_by(step).map(move |v| vertices[v])
}

fn bounding_box(vertices: &[V3], triangles: &[[usize; 3]], members: &[usize]) -> (V3, V3) {
    bounds(members.iter().flat_map(|&t| triangles[t]).map(|v| vertices[v]))
}

fn box_inside(inner: (V3, V3), outer: (V3, V3)) -> bool {
    (0..3).all(|a| inner.0[a] >= outer.0[a] && inner.1[a] <= outer.1[a])
}

#[cfg(test)]
mod tests {
    use crate::diagnose::repair;
    use crate::shapes::icosphere;
    use crate::TriSurface;

    /// Spheres of the given radii about the origin; `inward` reverses one.
    fn spheres(radii: &[(f64, bool)]) -> TriSurface {
        let mut s = TriSurface { vertices: Vec::new(), triangles: Vec::new(), parts: Vec::new() };
        for &(r, inward) in radii {
            let one = icosphere(r, 2);
            let offset = s.vertices.len();
            s.vertices.extend(one.vertices);
            s.triangles.extend(one.triangles.iter().map(|t| {
                let t = t.map(|v| v + offset);
                if inward {
                    [t[0], t[2], t[1]]
                } else {
                    t
                }
            }));
        }
        let n = s.triangles.len();
        s.parts = vec![("spheres".into(), 0..n)];
        s
    }

    /// Volume enclosed by the icosphere of radius `r` (m³).
    fn ball(r: f64) -> f64 {
        crate::diagnose(&icosphere(r, 2)).enclosed_volume_m3
    }

    fn assert_volume(report: &crate::SurfaceReport, expected: f64) {
        assert!(
            (report.enclosed_volume_m3 / expected - 1.0).abs() < 1e-12,
            "{} m³",
            report.enclosed_volume_m3
        );
    }

    #[test]
    fn an_inward_inner_skin_is_a_cavity() {
        let r = repair(&spheres(&[(0.05, false), (0.04, true)])).report;
        assert_eq!((r.cavities, r.flipped_faces), (1, 0));
        assert_volume(&r, ball(0.05) - ball(0.04));
    }

    #[test]
    fn an_inside_out_hollow_ball_is_turned_and_keeps_its_cavity() {
        let r = repair(&spheres(&[(0.05, true), (0.04, false)])).report;
        assert_eq!(r.cavities, 1);
        assert_eq!(r.flipped_faces, r.triangles, "both skins turned");
        assert_volume(&r, ball(0.05) - ball(0.04));
    }

    #[test]
    fn a_same_facing_inner_part_stays_solid_with_a_warning() {
        let r = repair(&spheres(&[(0.05, false), (0.04, false)])).report;
        assert_eq!(r.cavities, 0);
        assert!(r.warnings.iter().any(|w| w.contains("face the same way")), "{:?}", r.warnings);
    }

    #[test]
    fn a_bead_in_a_hollow_ball_is_solid_and_nesting_alternates() {
        // Outer skin out, cavity in, a bead in the cavity out: three levels.
        let r = repair(&spheres(&[(0.05, false), (0.04, true), (0.01, false)])).report;
        assert_eq!((r.cavities, r.flipped_faces), (1, 0));
        assert_volume(&r, ball(0.05) - ball(0.04) + ball(0.01));
    }

    #[test]
    fn many_small_closed_parts_side_by_side_are_no_cavities() {
        // 20 000 closed tetrahedra in a grid (a voxel-like export): only the
        // MAX_CONTAINERS largest are tried as containers, so this takes a
        // fraction of a second instead of 4·10⁸ box comparisons.
        let mut s = TriSurface::default();
        for i in 0..20_000 {
            let o = s.vertices.len();
            let x = (i % 200) as f64 * 0.01;
            let y = (i / 200) as f64 * 0.01;
            s.vertices.extend([[x, y, 0.0], [x + 0.005, y, 0.0], [x, y + 0.005, 0.0], [x, y, 0.005]]);
            s.triangles.extend([
                [o, o + 2, o + 1],
                [o, o + 1, o + 3],
                [o, o + 3, o + 2],
                [o + 1, o + 2, o + 3],
            ]);
        }
        let r = repair(&s).report;
        assert_eq!((r.components, r.cavities, r.flipped_faces), (20_000, 0, 0));
    }

    #[test]
    fn side_by_side_and_overlapping_parts_are_not_nested() {
        let mut s = spheres(&[(0.05, false), (0.04, true)]);
        // Shift the second sphere so it pokes out of the first.
        let half = s.vertices.len() / 2;
        s.vertices[half..].iter_mut().for_each(|p| p[0] += 0.03);
        let r = repair(&s).report;
        assert_eq!(r.cavities, 0);
        assert_eq!(r.flipped_faces, s.triangles.len() / 2, "the reversed one is turned outward");
    }
}
