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

use std::collections::HashMap;

use crate::geom::{cross, dihedral_angles_deg, dot, lerp, norm, orient6, sub, V3};

/// Input edges sharper than this (angle between the normals) are features.
pub const FEATURE_ANGLE_DEG: f64 = 35.0;
/// Boundary nodes closer than this fraction of h to a feature are snapped.
pub const SNAP_FRACTION: f64 = 0.5;
/// Dihedral range every tet around a moved node must keep (degrees).
pub const GUARD_DEG: (f64, f64) = (10.0, 165.0);

/// Feature edges (as segments) and corners of an oriented triangle surface.
pub(crate) fn features(vertices: &[V3], triangles: &[[usize; 3]]) -> (Vec<[V3; 2]>, Vec<V3>) {
    let normal = |t: &[usize; 3]| {
        let n = cross(sub(vertices[t[1]], vertices[t[0]]), sub(vertices[t[2]], vertices[t[0]]));
        let l = norm(n);
        n.map(|c| c / l)
    };
    let mut edges: Vec<(usize, usize, usize)> = Vec::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), i));
        }
    }
    edges.sort_unstable();
    let cos_limit = FEATURE_ANGLE_DEG.to_radians().cos();
    let mut segments = Vec::new();
    let mut degree: HashMap<usize, usize> = HashMap::new();
    for pair in edges.windows(2) {
        let (x, y) = (pair[0], pair[1]);
        if (x.0, x.1) != (y.0, y.1) {
            continue;
        }
        if dot(normal(&triangles[x.2]), normal(&triangles[y.2])) < cos_limit {
            segments.push([vertices[x.0], vertices[x.1]]);
            *degree.entry(x.0).or_default() += 1;
            *degree.entry(x.1).or_default() += 1;
        }
    }
    let corners = degree.into_iter().filter(|&(_, d)| d >= 3).map(|(v, _)| vertices[v]).collect();
    (segments, corners)
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
        if let Some((d, q)) = best {
            if d > 0.0 && try_move(nodes, tets, &around[v], v, q) {
                moved += 1;
            }
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
