//! T-junctions: a corner of one triangle lying on an edge of another.
//!
//! CAD and level-editor exports split a face where a neighbour has a corner
//! without splitting the neighbour, so the edge `(a, b)` of one triangle
//! meets the edges `(a, p)` and `(p, b)` of two others. The surface is closed
//! in space but open in its connectivity: each such edge counted as a hole,
//! the sharp edge along it was not found as a feature, and the mesh missed
//! the corner (a 10 × 6 × 4 cm box with one T-junction on its top edge:
//! 1.0 mm off, and a false "thinner than the cells" warning).
//!
//! Each open edge is split at every open-edge corner that lies on it, within
//! [`ON_EDGE`] of the bounding-box diagonal, and its triangle is fanned anew:
//! from the opposite corner when one edge is split, from a new centre vertex
//! when more are. The seam then closes. A face written twice (a
//! double-sided export) counts as one face on its edges, and both copies are
//! split alike: otherwise each T-junction edge, used by the face and its
//! copy, looked closed, and the side left open was taken for a sheet.

use std::collections::{HashMap, HashSet};

use crate::geom::{add, dot, norm, scale, sub, V3};

/// Distance from an edge, as a fraction of the bounding-box diagonal, within
/// which a corner counts as lying on it: about ten f32 roundings of a
/// coordinate, far below any gap a mesh could resolve.
pub(crate) const ON_EDGE: f64 = 1e-6;

/// Splits the open edges of `triangles` at the corners lying on them (module
/// doc); returns how many corners were inserted into edges. New centre
/// vertices are appended to `vertices`.
pub(crate) fn split_t_junctions(
    vertices: &mut Vec<V3>,
    triangles: &mut Vec<[usize; 3]>,
    diagonal: f64,
) -> usize {
    let open = open_edges(triangles);
    if open.is_empty() {
        return 0;
    }
    let tol = ON_EDGE * diagonal;
    let corners = OpenCorners::new(vertices, &open, triangles);
    // (triangle, its edge k from corner k to k + 1) -> corners on it, by position along it.
    let mut splits: HashMap<(usize, usize), Vec<(f64, usize)>> = HashMap::new();
    for &(t, k) in &open {
        let (a, b) = (triangles[t][k], triangles[t][(k + 1) % 3]);
        // The triangle's own third corner never splits it (a sliver whose
        // corner lies on its opposite edge stays as it is).
        let third = triangles[t][(k + 2) % 3];
        let on_it: Vec<(f64, usize)> =
            corners.on_segment(vertices, a, b, tol).into_iter().filter(|&(_, v)| v != third).collect();
        if !on_it.is_empty() {
            splits.insert((t, k), on_it);
        }
    }
    let mut split_triangles: Vec<usize> = splits.keys().map(|&(t, _)| t).collect();
    split_triangles.sort_unstable();
    split_triangles.dedup();
    let mut added = Vec::new();
    let mut inserted = 0;
    // Copies of one face (same corners, either winding) count their inserted
    // corners once and share their centre vertex.
    let mut counted: HashSet<[usize; 3]> = HashSet::new();
    let mut centres: HashMap<[usize; 3], usize> = HashMap::new();
    for t in split_triangles {
        let tri = triangles[t];
        let mut face = tri;
        face.sort_unstable();
        let mut outline = Vec::new();
        for (k, &corner) in tri.iter().enumerate() {
            outline.push(corner);
            outline.extend(splits.get(&(t, k)).into_iter().flatten().map(|&(_, v)| v));
        }
        let mut distinct = outline.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < outline.len() {
            // One corner on two of its edges: a sliver beyond repair here.
            continue;
        }
        if counted.insert(face) {
            inserted += outline.len() - 3;
        }
        let split_edges = (0..3).filter(|&k| splits.contains_key(&(t, k))).count();
        let fan = if split_edges == 1 {
            let k = (0..3).find(|&k| splits.contains_key(&(t, k))).unwrap_or(0);
            Fan::FromCorner(tri[(k + 2) % 3])
        } else {
            let centre = *centres.entry(face).or_insert_with(|| {
                vertices.push(scale(tri.iter().fold([0.0; 3], |s, &v| add(s, vertices[v])), 1.0 / 3.0));
                vertices.len() - 1
            });
            Fan::FromCentre(centre)
        };
        let pieces = fan.triangles(&outline);
        debug_assert!(pieces.len() >= 2, "a split triangle gives at least two");
        triangles[t] = pieces[0];
        added.extend_from_slice(&pieces[1..]);
    }
    triangles.extend(added);
    inserted
}

/// How a split triangle is filled again from its outline.
enum Fan {
    /// From the corner opposite the one split edge (the outline starts at
    /// the next corner, so that corner closes it).
    FromCorner(usize),
    /// From a vertex at the triangle's centre.
    FromCentre(usize),
}

impl Fan {
    /// The outline's consecutive corners joined to the fan's apex, in the
    /// outline's (the triangle's) orientation; degenerate pieces at the apex
    /// are left out.
    fn triangles(&self, outline: &[usize]) -> Vec<[usize; 3]> {
        let apex = match *self {
            Fan::FromCorner(v) | Fan::FromCentre(v) => v,
        };
        (0..outline.len())
            .map(|i| [outline[i], outline[(i + 1) % outline.len()], apex])
            .filter(|t| t[0] != apex && t[1] != apex)
            .collect()
    }
}

/// Edges of one face only, as (triangle, local edge k), sorted. A face
/// written more than once (a double-sided or duplicated export) counts once,
/// and each of its copies is listed: they are split alike, so the copies stay
/// coincident for module `coincident`. The faces on an edge are told apart by
/// their third corner. A sort of packed keys, not a hash map: this runs on
/// every input, scans of a million triangles included.
fn open_edges(triangles: &[[usize; 3]]) -> Vec<(usize, usize)> {
    // (edge's two corners, 3 · triangle + k); corner indices fit in 32 bits
    // for any surface that fits in memory, as do the triangle slots.
    let mut edges: Vec<(u64, u64)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k] as u64, tri[(k + 1) % 3] as u64);
            edges.push(((a.min(b) << 32) | a.max(b), (3 * t + k) as u64));
        }
    }
    edges.sort_unstable();
    let slot = |s: u64| (s as usize / 3, s as usize % 3);
    let third = |s: u64| {
        let (t, k) = slot(s);
        triangles[t][(k + 2) % 3]
    };
    let mut open: Vec<(usize, usize)> = edges
        .chunk_by(|x, y| x.0 == y.0)
        .filter(|group| group.iter().all(|e| third(e.1) == third(group[0].1)))
        .flat_map(|group| group.iter().map(|e| slot(e.1)))
        .collect();
    open.sort_unstable();
    open
}

/// The corners of open edges, sorted along each axis for slab queries.
struct OpenCorners {
    by_axis: [Vec<usize>; 3],
}

impl OpenCorners {
    fn new(vertices: &[V3], open: &[(usize, usize)], triangles: &[[usize; 3]]) -> Self {
        let mut ids: Vec<usize> =
            open.iter().flat_map(|&(t, k)| [triangles[t][k], triangles[t][(k + 1) % 3]]).collect();
        ids.sort_unstable();
        ids.dedup();
        let by_axis = std::array::from_fn(|c| {
            let mut sorted = ids.clone();
            sorted.sort_by(|&p, &q| vertices[p][c].total_cmp(&vertices[q][c]).then(p.cmp(&q)));
            sorted
        });
        Self { by_axis }
    }

    /// Corners strictly inside segment `a b` within `tol` of it, as
    /// (distance from `a`, corner), nearest to `a` first. Searched in the
    /// slab of the axis along which the segment extends least.
    fn on_segment(&self, vertices: &[V3], a: usize, b: usize, tol: f64) -> Vec<(f64, usize)> {
        let (pa, pb) = (vertices[a], vertices[b]);
        let d = sub(pb, pa);
        let length = norm(d);
        if length <= 2.0 * tol {
            return Vec::new();
        }
        let axis = (0..3).min_by(|&i, &j| d[i].abs().total_cmp(&d[j].abs())).unwrap_or(0);
        let (lo, hi) = (pa[axis].min(pb[axis]) - tol, pa[axis].max(pb[axis]) + tol);
        let sorted = &self.by_axis[axis];
        let start = sorted.partition_point(|&v| vertices[v][axis] < lo);
        let mut found: Vec<(f64, usize)> = sorted[start..]
            .iter()
            .take_while(|&&v| vertices[v][axis] <= hi)
            .filter(|&&v| v != a && v != b)
            .filter_map(|&v| inside_segment(vertices[v], pa, pb, tol).map(|along| (along, v)))
            .collect();
        found.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        found
    }
}

/// How far from `p` the point `x` lies along segment `p q` when it lies on
/// it strictly inside: within `tol` of it, and farther than `tol` from
/// either end; `None` otherwise (and for a segment of at most `2 tol`).
pub(crate) fn inside_segment(x: V3, p: V3, q: V3, tol: f64) -> Option<f64> {
    let d = sub(q, p);
    let length = norm(d);
    if length <= 2.0 * tol {
        return None;
    }
    let along = dot(sub(x, p), d) / length;
    let off = norm(sub(sub(x, p), scale(d, along / length)));
    (along > tol && along < length - tol && off <= tol).then_some(along)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 × 6 × 4 cm box whose top face has a corner (8) half-way along
    /// its front edge, while the front face does not.
    fn box_with_t_junction() -> (Vec<V3>, Vec<[usize; 3]>) {
        let v = vec![
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [0.1, 0.06, 0.0],
            [0.0, 0.06, 0.0],
            [0.0, 0.0, 0.04],
            [0.1, 0.0, 0.04],
            [0.1, 0.06, 0.04],
            [0.0, 0.06, 0.04],
            [0.05, 0.0, 0.04],
        ];
        let t = vec![
            [0, 2, 1],
            [0, 3, 2],
            [4, 8, 7],
            [8, 6, 7],
            [8, 5, 6],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ];
        (v, t)
    }

    #[test]
    fn a_t_junction_is_split_and_the_box_closes() {
        let (mut v, mut t) = box_with_t_junction();
        assert_eq!(open_edges(&t).len(), 3);
        let area_before: f64 =
            t.iter().map(|x| norm(crate::geom::area_vector(v[x[0]], v[x[1]], v[x[2]]))).sum();
        assert_eq!(split_t_junctions(&mut v, &mut t, 0.1237), 1);
        assert!(open_edges(&t).is_empty(), "{t:?}");
        assert_eq!((v.len(), t.len()), (9, 14));
        let area_after: f64 =
            t.iter().map(|x| norm(crate::geom::area_vector(v[x[0]], v[x[1]], v[x[2]]))).sum();
        assert!((area_after - area_before).abs() < 1e-15);
    }

    #[test]
    fn a_triangle_split_on_two_edges_is_fanned_from_its_centre() {
        // Triangle 0 1 2, with corners of open neighbours on edges 0-1 and 1-2.
        let mut v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.0, 0.0], [0.5, 0.5, 0.0]];
        let mut t = vec![[0, 1, 2], [3, 0, 9], [1, 3, 9], [4, 1, 9], [2, 4, 9]];
        v.resize(10, [0.3, 0.3, 1.0]);
        assert_eq!(split_t_junctions(&mut v, &mut t, 1.0), 2);
        assert_eq!(v.len(), 11, "one centre vertex");
        assert_eq!(t.len(), 4 + 5, "the triangle became five around its centre");
        // Left open: the neighbours' free edges to their apex 9, and edge 2-0.
        let mut open: Vec<(usize, usize)> = open_edges(&t)
            .iter()
            .map(|&(tri, k)| {
                let (a, b) = (t[tri][k], t[tri][(k + 1) % 3]);
                (a.min(b), a.max(b))
            })
            .collect();
        open.sort_unstable();
        assert_eq!(open, vec![(0, 2), (0, 9), (2, 9)], "{t:?}");
    }

    /// The same box written double-sided (every face again, reversed): the
    /// T-junction edge is used by the face and its copy, yet it is open, and
    /// both copies are split alike, so they stay opposite pairs.
    #[test]
    fn a_double_sided_t_junction_is_split_on_both_sides() {
        let (mut v, mut t) = box_with_t_junction();
        let back: Vec<[usize; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        t.extend(back);
        assert_eq!(open_edges(&t).len(), 6, "three edges, each on a face and its copy");
        assert_eq!(split_t_junctions(&mut v, &mut t, 0.1237), 1, "one corner inserted");
        assert!(open_edges(&t).is_empty(), "{t:?}");
        let mut faces: Vec<[usize; 3]> = t
            .iter()
            .map(|x| {
                let mut k = *x;
                k.sort_unstable();
                k
            })
            .collect();
        faces.sort_unstable();
        assert!(faces.chunks(2).all(|pair| pair[0] == pair[1]), "every face twice: {faces:?}");
    }

    /// Two edges split on a face written twice: the copies share one centre.
    #[test]
    fn copies_of_a_face_split_on_two_edges_share_its_centre() {
        let mut v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.0, 0.0], [0.5, 0.5, 0.0]];
        let mut t = vec![[0, 1, 2], [0, 2, 1], [3, 0, 9], [1, 3, 9], [4, 1, 9], [2, 4, 9]];
        v.resize(10, [0.3, 0.3, 1.0]);
        assert_eq!(split_t_junctions(&mut v, &mut t, 1.0), 2);
        assert_eq!(v.len(), 11, "one centre vertex for both copies");
        assert_eq!(t.len(), 4 + 2 * 5);
    }

    #[test]
    fn a_hole_stays_a_hole() {
        // An open square of two triangles: nothing lies on its rim.
        let mut v = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let mut t = vec![[0, 1, 2], [0, 2, 3]];
        assert_eq!(split_t_junctions(&mut v, &mut t, 1.5), 0);
        assert_eq!(t, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
