//! Exact mesh volume, including curved 10-node tets.
//!
//! `V = ∫ det J dξ` over the reference tet (volume 1/6). For 4-node tets
//! det J is constant; for 10-node tets it is a cubic polynomial, integrated
//! exactly by the degree-3 Keast rule: the centroid with weight −4/5 and the
//! four points with barycentrics (1/2, 1/6, 1/6, 1/6) with weight 9/20 each
//! (weights relative to the reference volume).

use crate::validate::{cross, dot, volume6};
use crate::{tet10_shape_gradients, Cells, TetMesh};

const KEAST3: [([f64; 3], f64); 5] = {
    const A: f64 = 1.0 / 6.0;
    [
        ([0.25, 0.25, 0.25], -0.8),
        ([A, A, A], 0.45),
        ([0.5, A, A], 0.45),
        ([A, 0.5, A], 0.45),
        ([A, A, 0.5], 0.45),
    ]
};

/// Signed volume (m³) of tet `element`, exact for straight and curved
/// (10-node) tets. Node indices must be in range.
pub fn tet_volume(mesh: &TetMesh, element: usize) -> f64 {
    match &mesh.cells {
        Cells::Tet4(t) => volume6(&mesh.nodes, t[element]) / 6.0,
        Cells::Tet10(t) => {
            let nodes = t[element].map(|n| mesh.nodes[n]);
            KEAST3
                .iter()
                .map(|&(point, weight)| {
                    let grads = tet10_shape_gradients(point);
                    let mut jac = [[0.0; 3]; 3];
                    for (x, g) in nodes.iter().zip(&grads) {
                        for r in 0..3 {
                            for c in 0..3 {
                                jac[r][c] += x[r] * g[c];
                            }
                        }
                    }
                    weight * dot(jac[0], cross(jac[1], jac[2]))
                })
                .sum::<f64>()
                / 6.0
        }
    }
}

/// Total volume (m³) of the mesh (exact for curved 10-node tets).
pub fn mesh_volume(mesh: &TetMesh) -> f64 {
    (0..mesh.cells.len()).map(|e| tet_volume(mesh, e)).sum()
}
