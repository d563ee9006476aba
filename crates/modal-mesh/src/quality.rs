//! Element quality: dihedral angles of the corner tets.
//!
//! The dihedral angle at edge (i, j) of a tet is the angle between its two
//! faces meeting there: with `e` the unit edge direction and `u`, `v` the
//! components of `p_k − p_i`, `p_l − p_i` normal to `e`, it is
//! `acos(u·v / (|u| |v|))`. A regular tet has 70.53° everywhere; slivers
//! approach 0° (and 180°).

use crate::validate::{dot, sub};
use crate::{TetMesh, TET10_EDGES};

/// The six dihedral angles (degrees) of the tet with corners `p`, in
/// [`TET10_EDGES`] order.
pub fn dihedral_angles_deg(p: [[f64; 3]; 4]) -> [f64; 6] {
    TET10_EDGES.map(|[i, j]| {
        let others: Vec<usize> = (0..4).filter(|&c| c != i && c != j).collect();
        let e = sub(p[j], p[i]);
        let e_len2 = dot(e, e);
        let normal_part = |k: usize| {
            let w = sub(p[k], p[i]);
            let s = dot(w, e) / e_len2;
            [w[0] - s * e[0], w[1] - s * e[1], w[2] - s * e[2]]
        };
        let (u, v) = (normal_part(others[0]), normal_part(others[1]));
        let cos = dot(u, v) / (dot(u, u) * dot(v, v)).sqrt();
        cos.clamp(-1.0, 1.0).acos().to_degrees()
    })
}

/// Smallest dihedral angle (degrees) over all (corner) tets of the mesh;
/// 180 for an empty mesh. Node indices must be in range.
pub fn min_dihedral_angle_deg(mesh: &TetMesh) -> f64 {
    (0..mesh.cells.len())
        .flat_map(|e| dihedral_angles_deg(mesh.cells.corners(e).map(|n| mesh.nodes[n])))
        .fold(180.0, f64::min)
}
