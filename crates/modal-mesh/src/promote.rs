//! Order elevation: 4-node tets → 10-node tets with straight edges.

use crate::{Cells, TetMesh, TET10_EDGES};

/// Returns the mesh with 10-node tets. A 4-node mesh gains one node at the
/// midpoint of every edge, shared by all tets around that edge (so the
/// quadratic field stays conforming); a 10-node mesh is returned unchanged,
/// keeping its own (possibly curved) mid-edge nodes.
pub fn to_quadratic(mesh: &TetMesh) -> TetMesh {
    to_quadratic_with(mesh, |a, b| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0])
}

/// Like [`to_quadratic`], but the new node of the edge between nodes at
/// `a` and `b` is placed at `midpoint(a, b)` (generators use it to put
/// mid-edge nodes on curved surfaces). Called once per unique edge.
pub fn to_quadratic_with(
    mesh: &TetMesh,
    mut midpoint: impl FnMut([f64; 3], [f64; 3]) -> [f64; 3],
) -> TetMesh {
    let Cells::Tet4(tets) = &mesh.cells else {
        return mesh.clone();
    };
    // Sort all (edge, slot) pairs so each unique edge gets one new node,
    // numbered in order of the edge's first appearance (tet order).
    let mut edges: Vec<((usize, usize), usize)> = Vec::with_capacity(6 * tets.len());
    for (t, tet) in tets.iter().enumerate() {
        for (e, [a, b]) in TET10_EDGES.iter().enumerate() {
            let (p, q) = (tet[*a], tet[*b]);
            edges.push(((p.min(q), p.max(q)), 6 * t + e));
        }
    }
    edges.sort_unstable();
    let mut first_slot = vec![0usize; edges.len()];
    for run in edges.chunk_by(|x, y| x.0 == y.0) {
        let first = run[0].1; // smallest slot: sorted by (edge, slot)
        run.iter().for_each(|&(_, slot)| first_slot[slot] = first);
    }
    let mut nodes = mesh.nodes.clone();
    let mut node_of_slot = vec![usize::MAX; edges.len()];
    let quadratic = tets
        .iter()
        .enumerate()
        .map(|(t, tet)| {
            let mut t10 = [0usize; 10];
            t10[..4].copy_from_slice(tet);
            for (e, [a, b]) in TET10_EDGES.iter().enumerate() {
                let first = first_slot[6 * t + e];
                if node_of_slot[first] == usize::MAX {
                    let m = midpoint(nodes[tet[*a]], nodes[tet[*b]]);
                    nodes.push(m);
                    node_of_slot[first] = nodes.len() - 1;
                }
                t10[4 + e] = node_of_slot[first];
            }
            t10
        })
        .collect();
    TetMesh { nodes, cells: Cells::Tet10(quadratic), groups: mesh.groups.clone() }
}

/// Returns the mesh with 4-node tets: a 10-node mesh keeps only its corner
/// nodes (mid-edge nodes that no longer belong to any tet are dropped and
/// the rest renumbered); a 4-node mesh is returned unchanged.
pub fn to_linear(mesh: &TetMesh) -> TetMesh {
    let Cells::Tet10(tets) = &mesh.cells else {
        return mesh.clone();
    };
    // Keep corner nodes in their original relative order.
    let mut is_corner = vec![false; mesh.nodes.len()];
    tets.iter().flat_map(|t| &t[..4]).for_each(|&n| is_corner[n] = true);
    let mut new_index = vec![usize::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    for (n, _) in is_corner.iter().enumerate().filter(|(_, &c)| c) {
        new_index[n] = nodes.len();
        nodes.push(mesh.nodes[n]);
    }
    let linear = tets.iter().map(|t| [t[0], t[1], t[2], t[3]].map(|n| new_index[n])).collect();
    TetMesh { nodes, cells: Cells::Tet4(linear), groups: mesh.groups.clone() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::box_mesh;

    #[test]
    fn promotion_shares_edge_nodes_and_round_trips() {
        let linear = box_mesh([1.0, 1.0, 1.0], [2, 2, 2]);
        let quadratic = to_quadratic(&linear);
        // A grid of 3x3x3 nodes split into Kuhn tets has these unique edges:
        // axis edges 3*2*3*3 = 54, face diagonals 3*2*2*3 = 36, body diagonals 8.
        assert_eq!(quadratic.nodes.len(), 27 + 54 + 36 + 8);
        assert_eq!(to_linear(&quadratic), linear);
    }
}
