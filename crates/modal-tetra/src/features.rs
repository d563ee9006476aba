//! Sharp-feature recovery after stuffing.
//!
//! Isosurface stuffing puts every boundary node on the surface but rounds
//! sharp edges and corners off by up to about half a cell. Here boundary
//! nodes near an input *feature* are moved onto it: first the nearest node
//! to each corner (a vertex where three or more feature edges meet), then
//! every boundary node within [`SNAP_FRACTION`] · h of a feature edge
//! (an edge whose two triangles' normals differ by more than
//! [`FEATURE_ANGLE_DEG`]) onto its closest point. A move is kept only if all
//! tets around the node stay positively oriented with dihedral angles inside
//! [`GUARD_DEG`], so the quality bound of the stuffing survives.
//!
//! Only features on the boundary of the solid count. Where closed parts
//! overlap (a gusset welded into a bracket, a handle pushed into a cup), the
//! edges and corners of one part that lie inside another are buried: snapping
//! onto them would dig a groove into the flat face above them (measured on
//! the corpus bracket: a 2.3 mm groove along the gusset's foot, all of its
//! first 10 frequencies 0.4–3.2 % low). Each feature edge is cut into pieces
//! of at most [`PIECE_FRACTION`] · h; a piece (or a corner) is kept when the
//! generalized winding number w is below ½ just outside it and at least ½
//! just inside it, along the mean of its faces' normals n̄:
//!
//! ```text
//!   exposed(m)  ⇔  w(m + δ n̄) < ½ ≤ w(m − δ n̄),   δ = PROBE_FRACTION · h.
//! ```

use std::collections::HashMap;

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::chains::followable;
use crate::geom::{
    add, cross, dihedral_angles_deg, dot, lerp, norm, orient6, scale, segment_triangle, sub, V3,
};

/// Input edges sharper than this (angle between the normals) are features.
pub const FEATURE_ANGLE_DEG: f64 = 35.0;
/// Boundary nodes closer than this fraction of h to a feature are snapped.
pub const SNAP_FRACTION: f64 = 0.75;
/// Dihedral range every tet around a moved node must keep (degrees).
pub const GUARD_DEG: (f64, f64) = (10.0, 165.0);
/// Feature edges are tested for exposure in pieces of at most this fraction of h.
pub const PIECE_FRACTION: f64 = 0.25;
/// Distance of the exposure probes from the feature, as a fraction of h.
pub const PROBE_FRACTION: f64 = 0.02;
/// At most this many pieces are tested per feature edge (very long edges
/// relative to h are cut into this many).
const MAX_PIECES: usize = 64;

/// Feature edges (as segments) and corners of an oriented triangle surface
/// that lie on the boundary of the solid `bvh` bounds (see the module doc);
/// `h` is the cell size.
pub(crate) fn features(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    bvh: &Bvh,
    h: f64,
) -> (Vec<[V3; 2]>, Vec<V3>) {
    let normals: Vec<V3> = triangles
        .iter()
        .map(|t| {
            unit(cross(sub(vertices[t[1]], vertices[t[0]]), sub(vertices[t[2]], vertices[t[0]])))
                .unwrap_or([0.0; 3])
        })
        .collect();
    let mut edges: Vec<(usize, usize, usize)> = Vec::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), i));
        }
    }
    edges.sort_unstable();
    let cos_limit = FEATURE_ANGLE_DEG.to_radians().cos();
    // (a, b, mean normal) of every sharp input edge; per vertex the sum of the
    // mean normals of its sharp edges and their count.
    let mut sharp: Vec<(usize, usize, V3)> = Vec::new();
    let mut convex: Vec<bool> = Vec::new();
    for pair in edges.windows(2) {
        let (x, y) = (pair[0], pair[1]);
        if (x.0, x.1) != (y.0, y.1) {
            continue;
        }
        let (n1, n2) = (normals[x.2], normals[y.2]);
        if dot(n1, n2) < cos_limit {
            let mean = unit(add(n1, n2)).unwrap_or(n1);
            sharp.push((x.0, x.1, mean));
            // Convex when the far corner of one face lies below the other's plane.
            let far = triangles[y.2].into_iter().find(|&v| v != x.0 && v != x.1).unwrap_or(x.0);
            convex.push(dot(n1, sub(vertices[far], vertices[x.0])) < 0.0);
        }
    }
    // Not the noise of a scan (module `chains`).
    let sharp = followable(sharp, &convex, vertices, h);
    let mut at_vertex: HashMap<usize, (usize, V3)> = HashMap::new();
    for &(a, b, mean) in &sharp {
        for v in [a, b] {
            let e = at_vertex.entry(v).or_insert((0, [0.0; 3]));
            e.0 += 1;
            e.1 = add(e.1, mean);
        }
    }
    let mut lines: Vec<([V3; 2], V3)> =
        sharp.iter().map(|&(a, b, n)| ([vertices[a], vertices[b]], n)).collect();
    lines.extend(intersection_lines(vertices, triangles, &normals, bvh, cos_limit));
    let mut candidates: Vec<(V3, Option<V3>)> = at_vertex
        .into_iter()
        .filter(|(_, (d, _))| *d >= 3)
        .map(|(v, (_, n))| (vertices[v], unit(n)))
        .collect();
    candidates.extend(edge_crossings(vertices, triangles, &normals, bvh, &sharp));
    let delta = PROBE_FRACTION * h;
    let exposed = |m: V3, n: V3| {
        bvh.winding(add(m, scale(n, delta))) < 0.5 && bvh.winding(sub(m, scale(n, delta))) >= 0.5
    };
    let segments: Vec<[V3; 2]> = lines
        .par_iter()
        .flat_map_iter(|&([p, q], n)| {
            let pieces = ((norm(sub(q, p)) / (PIECE_FRACTION * h)).ceil() as usize).clamp(1, MAX_PIECES);
            (0..pieces).filter_map(move |k| {
                let (s, t) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
                let piece = [lerp(p, q, s), lerp(p, q, t)];
                exposed(lerp(p, q, 0.5 * (s + t)), n).then_some(piece)
            })
        })
        .collect();
    let mut corners: Vec<V3> = candidates
        .into_par_iter()
        .filter_map(|(c, n)| n.is_none_or(|n| exposed(c, n)).then_some(c))
        .collect();
    // A crossing on a shared triangle edge is found from both triangles.
    corners.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    corners.dedup_by(|a, b| norm(sub(*a, *b)) <= 1e-9 * h);
    (merge(segments), corners)
}

/// The points where `a` and `b` cross each other's edges (up to duplicates).
fn crossing_points(a: [V3; 3], b: [V3; 3]) -> Vec<V3> {
    let mut out = Vec::new();
    for (x, y) in [(a, b), (b, a)] {
        for k in 0..3 {
            let (p, q) = (x[k], x[(k + 1) % 3]);
            if let Some(t) = segment_triangle(p, q, y[0], y[1], y[2]) {
                out.push(lerp(p, q, t));
            }
        }
    }
    out
}

/// Where two input triangles that share no vertex cross at more than
/// [`FEATURE_ANGLE_DEG`] (overlapping parts, self-intersections), the solid
/// has a crease that is no input edge: the segment of the crossing, with the
/// mean of the two normals.
fn intersection_lines(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    normals: &[V3],
    bvh: &Bvh,
    cos_limit: f64,
) -> Vec<([V3; 2], V3)> {
    (0..triangles.len())
        .into_par_iter()
        .flat_map_iter(|a| {
            let ta = triangles[a];
            let pa = ta.map(|v| vertices[v]);
            let lo = std::array::from_fn(|c| pa[0][c].min(pa[1][c]).min(pa[2][c]));
            let hi = std::array::from_fn(|c| pa[0][c].max(pa[1][c]).max(pa[2][c]));
            bvh.in_box(lo, hi).into_iter().filter_map(move |b| {
                let tb = triangles[b];
                if b <= a || tb.iter().any(|v| ta.contains(v)) || dot(normals[a], normals[b]) >= cos_limit {
                    return None;
                }
                let points = crossing_points(pa, tb.map(|v| vertices[v]));
                let p = *points.first()?;
                let q =
                    points.iter().copied().max_by(|x, y| norm(sub(*x, p)).total_cmp(&norm(sub(*y, p))))?;
                let n = unit(add(normals[a], normals[b]))?;
                (norm(sub(q, p)) > 0.0).then_some(([p, q], n))
            })
        })
        .collect()
}

/// Points where a sharp input edge crosses a triangle that does not hold it
/// (a feature line of one part entering another): corners of the solid,
/// with the mean of the edge's and the triangle's normals.
fn edge_crossings(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    normals: &[V3],
    bvh: &Bvh,
    sharp: &[(usize, usize, V3)],
) -> Vec<(V3, Option<V3>)> {
    sharp
        .par_iter()
        .flat_map_iter(|&(a, b, n)| {
            let (p, q) = (vertices[a], vertices[b]);
            let lo = std::array::from_fn(|c| p[c].min(q[c]));
            let hi = std::array::from_fn(|c| p[c].max(q[c]));
            bvh.in_box(lo, hi).into_iter().filter_map(move |t| {
                let tri = triangles[t];
                if tri.contains(&a) || tri.contains(&b) {
                    return None;
                }
                let x = tri.map(|v| vertices[v]);
                let s = segment_triangle(p, q, x[0], x[1], x[2])?;
                (s > 1e-9 && s < 1.0 - 1e-9).then(|| (lerp(p, q, s), unit(add(n, normals[t]))))
            })
        })
        .collect()
}

/// `v / |v|`, or `None` for a (near-)zero vector.
fn unit(v: V3) -> Option<V3> {
    let l = norm(v);
    (l > 1e-12).then(|| scale(v, 1.0 / l))
}

/// Joins consecutive collinear pieces of one edge back into one segment.
fn merge(pieces: Vec<[V3; 2]>) -> Vec<[V3; 2]> {
    let mut out: Vec<[V3; 2]> = Vec::with_capacity(pieces.len());
    for piece in pieces {
        match out.last_mut() {
            Some(last) if last[1] == piece[0] && collinear(*last, piece[1]) => last[1] = piece[1],
            _ => out.push(piece),
        }
    }
    out
}

fn collinear([a, b]: [V3; 2], c: V3) -> bool {
    let (ab, ac) = (sub(b, a), sub(c, a));
    norm(cross(ab, ac)) <= 1e-9 * dot(ab, ab).max(dot(ac, ac))
}

/// Moves boundary nodes of (`nodes`, `tets`) onto the features; returns how
/// many nodes moved.
pub(crate) fn snap(
    nodes: &mut [V3],
    tets: &[[usize; 4]],
    boundary: &[usize],
    segments: &[[V3; 2]],
    corners: &[V3],
    h: f64,
) -> usize {
    if segments.is_empty() {
        return 0;
    }
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    for (e, t) in tets.iter().enumerate() {
        for &v in t {
            around[v].push(e);
        }
    }
    let key = |p: V3| p.map(|c| (c / h).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for &v in boundary {
        grid.entry(key(nodes[v])).or_default().push(v);
    }
    let near = |p: V3, nodes: &[V3], grid: &HashMap<[i64; 3], Vec<usize>>| {
        let k = key(p);
        let mut out = Vec::new();
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        out.extend(list.iter().copied().filter(|&v| norm(sub(nodes[v], p)) < h));
                    }
                }
            }
        }
        out
    };
    let mut locked = vec![false; nodes.len()];
    let mut moved = 0;
    for &c in corners {
        let mut candidates = near(c, nodes, &grid);
        candidates.sort_by(|&a, &b| norm(sub(nodes[a], c)).total_cmp(&norm(sub(nodes[b], c))));
        for v in candidates {
            if !locked[v] && try_move(nodes, tets, &around[v], v, c) {
                locked[v] = true;
                moved += 1;
                break;
            }
        }
    }
    // Segments bucketed on the grid (each into the cells its box touches).
    let mut seg_grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (s, [a, b]) in segments.iter().enumerate() {
        let kl = key(std::array::from_fn(|i| a[i].min(b[i])));
        let kh = key(std::array::from_fn(|i| a[i].max(b[i])));
        let cells = (0..3).map(|i| (kh[i] - kl[i] + 1) as u64).product::<u64>();
        if cells > 1_000_000 {
            continue; // absurdly long segment relative to h: skip rather than allocate
        }
        for z in kl[2]..=kh[2] {
            for y in kl[1]..=kh[1] {
                for x in kl[0]..=kh[0] {
                    seg_grid.entry([x, y, z]).or_default().push(s);
                }
            }
        }
    }
    // Each free boundary node's closest feature point within reach; the
    // nearest nodes move first, so a farther node cannot take an edge spot
    // (and spoil the quality around it) before the node that belongs there.
    let mut wanted: Vec<(f64, usize, V3)> = Vec::new();
    for &v in boundary {
        if locked[v] {
            continue;
        }
        let p = nodes[v];
        let k = key(p);
        let mut best: Option<(f64, V3)> = None;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    for &s in seg_grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]).into_iter().flatten() {
                        let q = closest_on_segment(p, segments[s]);
                        let d = norm(sub(q, p));
                        if d < SNAP_FRACTION * h && best.is_none_or(|(bd, _)| d < bd) {
                            best = Some((d, q));
                        }
                    }
                }
            }
        }
        if let Some((d, q)) = best.filter(|&(d, _)| d > 0.0) {
            wanted.push((d, v, q));
        }
    }
    wanted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (_, v, q) in wanted {
        if try_move(nodes, tets, &around[v], v, q) {
            moved += 1;
        }
    }
    moved
}

fn closest_on_segment(p: V3, [a, b]: [V3; 2]) -> V3 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    if l2 == 0.0 {
        return a;
    }
    lerp(a, b, (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0))
}

/// Moves node `v` to `target` if every tet around it stays valid and inside
/// the guard range; otherwise leaves it.
fn try_move(nodes: &mut [V3], tets: &[[usize; 4]], around: &[usize], v: usize, target: V3) -> bool {
    let old = nodes[v];
    nodes[v] = target;
    let ok = around.iter().all(|&e| {
        let p = tets[e].map(|i| nodes[i]);
        orient6(p[0], p[1], p[2], p[3]) > 0.0
            && dihedral_angles_deg(p).iter().all(|&a| (GUARD_DEG.0..=GUARD_DEG.1).contains(&a))
    });
    if !ok {
        nodes[v] = old;
    }
    ok
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::cuboid;

    /// A 4 cm cube with a 2 cm cube pushed halfway into its top face (off the
    /// top face's diagonals, so no crossing lies on a triangle edge).
    fn union_of_two_boxes() -> (Vec<V3>, Vec<[usize; 3]>) {
        let big = cuboid(0.04, 0.04, 0.04);
        let small = cuboid(0.02, 0.02, 0.02);
        let mut vertices = big.vertices.clone();
        let offset = vertices.len();
        vertices.extend(small.vertices.iter().map(|p| [p[0] + 0.011, p[1] + 0.007, p[2] + 0.03]));
        let mut triangles = big.triangles.clone();
        triangles.extend(small.triangles.iter().map(|t| t.map(|v| v + offset)));
        (vertices, triangles)
    }

    #[test]
    fn buried_edges_and_corners_of_overlapping_parts_are_not_features() {
        let (vertices, triangles) = union_of_two_boxes();
        let bvh = Bvh::new(triangles.iter().map(|t| t.map(|v| vertices[v])).collect());
        let h = 0.004;
        let (segments, corners) = features(&vertices, &triangles, &bvh, h);
        // Strictly inside the union: inside the big cube below z = 0.04 and inside the small one.
        let buried = |p: V3| {
            let inside = |lo: V3, hi: V3| (0..3).all(|c| p[c] > lo[c] + 1e-9 && p[c] < hi[c] - 1e-9);
            inside([0.0; 3], [0.04; 3]) || inside([0.011, 0.007, 0.03], [0.031, 0.027, 0.05])
        };
        for s in &segments {
            assert!(!buried(lerp(s[0], s[1], 0.5)), "buried feature piece {s:?}");
        }
        for c in &corners {
            assert!(!buried(*c), "buried corner {c:?}");
        }
        // Exposed: the big cube's 12 edges (48 cm), the small cube's 4 top edges (8 cm)
        // and its 4 vertical edges above z = 0.04 (4 cm), and the crease where its sides
        // cross the big top face (4 · 2 cm, no input edge): 68 cm. Its 4 bottom edges
        // and the lower halves of its vertical edges are buried.
        let length: f64 = segments.iter().map(|s| norm(sub(s[1], s[0]))).sum();
        // Each of the 4 edges that leave the big cube may lose the one piece that straddles it.
        assert!(length <= 0.68 + 1e-9 && length > 0.68 - 4.0 * PIECE_FRACTION * h, "feature length {length}");
        // The big cube's 8 corners, the small cube's 4 top corners, and the 4 points
        // where its vertical edges cross the big top face.
        assert_eq!(corners.len(), 16, "{corners:?}");
        let crossing = |c: &V3| (c[2] - 0.04).abs() < 1e-12 && c[0] > 0.0 && c[0] < 0.04;
        assert_eq!(corners.iter().filter(|c| crossing(c)).count(), 4, "{corners:?}");
    }
}
