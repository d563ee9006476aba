//! Sharp edges that a mesh of cell h can follow, told from surface noise.
//!
//! A feature edge is one whose faces' normals differ by more than
//! [`crate::FEATURE_ANGLE_DEG`]. On a dense, noisy scan most edges are: a
//! 1.3 M-triangle scan with 0.2 % radial noise had 42 % of its edges "sharp"
//! (median dihedral 29°). Snapping onto them moved boundary nodes onto noise:
//! the mesh lost 0.24 % of its volume, its worst dihedral sat on the snap
//! guard (10.0° against 20.3° for the same scan without noise), and testing
//! the 826 k edges took more than half of the run (36 s against 15 s).
//!
//! Sharp edges are walked into chains, which run through vertices where
//! exactly two sharp edges meet, both convex or both concave, and end at
//! junctions (three or more), free ends, where convex turns concave (a
//! CAD edge is one or the other along its length; noise alternates), or
//! where the path turns by more than [`MAX_TURN_DEG`]. A chain is *long* when it spans at least [`MIN_CHAIN_FRACTION`] · h
//! (the diagonal of its vertices' bounding box: a noise chain zigzags, so
//! its length says little); a CAD edge is one long chain however finely it
//! is tessellated. A short
//! chain is kept when one of its ends is a junction of a long chain (the
//! 2 mm edge across a plate's thickness, between two corners of long
//! edges); noise makes short chains that meet only each other, and those
//! are dropped.

use crate::geom::{bounds, dot, norm, sub, V3};

/// Chains spanning at least this fraction of the cell h are followed.
pub const MIN_CHAIN_FRACTION: f64 = 0.5;

/// The sharp edges `(a, b, mean normal)` worth following at cell `h`
/// (module doc), in their input order.
pub(crate) fn followable(
    sharp: Vec<(usize, usize, V3)>,
    convex: &[bool],
    vertices: &[V3],
    h: f64,
) -> Vec<(usize, usize, V3)> {
    debug_assert_eq!(sharp.len(), convex.len());
    // Per vertex, the sharp edges at it: (vertex, edge) sorted by vertex.
    let mut incidence: Vec<(usize, usize)> =
        sharp.iter().enumerate().flat_map(|(e, &(a, b, _))| [(a, e), (b, e)]).collect();
    incidence.sort_unstable();
    let at = |v: usize| {
        let start = incidence.partition_point(|&(u, _)| u < v);
        let end = incidence.partition_point(|&(u, _)| u <= v);
        incidence[start..end].iter().map(|&(_, e)| e)
    };
    let degree = |v: usize| at(v).count();
    let mut chain_of = vec![usize::MAX; sharp.len()];
    // Per chain: its extent and its ends (junctions or free ends).
    let mut chains: Vec<(f64, Vec<usize>)> = Vec::new();
    for first in 0..sharp.len() {
        if chain_of[first] != usize::MAX {
            continue;
        }
        let id = chains.len();
        let mut members = Vec::new();
        let mut ends = Vec::new();
        let mut stack = vec![first];
        chain_of[first] = id;
        while let Some(e) = stack.pop() {
            let (a, b, _) = sharp[e];
            for v in [a, b] {
                members.push(v);
                if degree(v) != 2 {
                    ends.push(v);
                    continue;
                }
                for next in at(v) {
                    if next != e && (convex[next] != convex[e] || turns(&sharp, vertices, e, next, v)) {
                        ends.push(v);
                    } else if chain_of[next] == usize::MAX {
                        chain_of[next] = id;
                        stack.push(next);
                    }
                }
            }
        }
        let (lo, hi) = bounds(members.into_iter().map(|v| vertices[v]));
        chains.push((norm(sub(hi, lo)), ends));
    }
    let long: Vec<bool> = chains.iter().map(|(extent, _)| *extent >= MIN_CHAIN_FRACTION * h).collect();
    // Junctions where a long chain ends, sorted for the search below.
    let mut anchored: Vec<usize> = chains
        .iter()
        .zip(&long)
        .filter(|(_, &l)| l)
        .flat_map(|((_, ends), _)| ends.iter().copied())
        .collect();
    anchored.sort_unstable();
    anchored.dedup();
    let keep: Vec<bool> = chains
        .iter()
        .zip(&long)
        .map(|((_, ends), &l)| l || ends.iter().any(|v| degree(*v) >= 3 && anchored.binary_search(v).is_ok()))
        .collect();
    sharp.into_iter().zip(chain_of).filter(|(_, c)| keep[*c]).map(|(s, _)| s).collect()
}

/// Largest turn (degrees) of a chain at a vertex where two sharp edges
/// meet: a tessellated CAD edge bends a little at each vertex (a circle of
/// 32 segments by 11.25°); a path of noise follows the mesh's edges and
/// zigzags.
pub const MAX_TURN_DEG: f64 = 45.0;

/// True when the path along sharp edge `e` then `next`, through their
/// shared vertex `v`, turns by more than [`MAX_TURN_DEG`].
fn turns(sharp: &[(usize, usize, V3)], vertices: &[V3], e: usize, next: usize, v: usize) -> bool {
    let other = |k: usize| if sharp[k].0 == v { sharp[k].1 } else { sharp[k].0 };
    let (before, after) = (sub(vertices[v], vertices[other(e)]), sub(vertices[other(next)], vertices[v]));
    dot(before, after) < MAX_TURN_DEG.to_radians().cos() * norm(before) * norm(after)
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: V3 = [0.0, 0.0, 1.0];

    #[test]
    fn a_long_chain_and_the_short_edge_between_its_corners_are_kept() {
        // The end of a 2 mm plate: two 10 mm edges joined by 2 mm edges, and
        // a 10 mm edge down from each corner, so every corner is a junction and
        // each 2 mm edge a chain of its own, short, between junctions of long ones.
        let p = [[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.01, 0.002, 0.0], [0.0, 0.002, 0.0]];
        let v: Vec<V3> = p.iter().copied().chain(p.iter().map(|q| [q[0], q[1], -0.01])).collect();
        let outline = [(0, 1, N), (1, 2, N), (2, 3, N), (3, 0, N)];
        let sharp: Vec<(usize, usize, V3)> =
            outline.into_iter().chain((0..4).map(|k| (k, k + 4, N))).collect();
        assert_eq!(followable(sharp.clone(), &vec![true; sharp.len()], &v, 0.005).len(), 8);
    }

    #[test]
    fn short_chains_meeting_only_each_other_are_noise() {
        // A star of three 1 mm edges, and a lone 1 mm edge, at h = 5 mm.
        let v = [
            [0.0; 3],
            [0.001, 0.0, 0.0],
            [0.0, 0.001, 0.0],
            [0.0, 0.0, 0.001],
            [0.1, 0.0, 0.0],
            [0.101, 0.0, 0.0],
        ];
        let sharp = vec![(0, 1, N), (0, 2, N), (0, 3, N), (4, 5, N)];
        assert!(followable(sharp.clone(), &vec![true; sharp.len()], &v, 0.005).is_empty());
    }

    #[test]
    fn a_tessellated_circle_is_followed_and_a_zigzag_is_not() {
        // A 10 mm circle in 32 segments (turning 11.25° at each vertex), and a
        // 10 mm zigzag of 1 mm edges turning 90° at each.
        let mut v: Vec<V3> = (0..32)
            .map(|k| (k as f64 * std::f64::consts::TAU / 32.0).sin_cos())
            .map(|(s, c)| [0.005 * c, 0.005 * s, 0.0])
            .collect();
        let mut sharp: Vec<(usize, usize, V3)> = (0..32).map(|k| (k, (k + 1) % 32, N)).collect();
        assert_eq!(followable(sharp.clone(), &vec![true; sharp.len()], &v, 0.005).len(), 32);
        v.extend((0..=10).map(|k| [0.1 + 0.001 * (k / 2 + k % 2) as f64, 0.001 * (k / 2) as f64, 0.0]));
        sharp = (0..10).map(|k| (32 + k, 33 + k, N)).collect();
        assert!(followable(sharp.clone(), &vec![true; sharp.len()], &v, 0.005).is_empty());
    }

    #[test]
    fn a_finely_tessellated_edge_is_one_long_chain() {
        // A 10 mm edge in 100 segments of 0.1 mm.
        let v: Vec<V3> = (0..=100).map(|i| [1e-4 * i as f64, 0.0, 0.0]).collect();
        let sharp: Vec<(usize, usize, V3)> = (0..100).map(|i| (i, i + 1, N)).collect();
        assert_eq!(followable(sharp.clone(), &vec![true; sharp.len()], &v, 0.005).len(), 100);
    }
}
