//! Structured box meshes: a grid of hexahedra, each split into six tets.

use crate::{Cells, TetMesh};

/// The six Kuhn (Freudenthal) tets of the unit cube around its main diagonal
/// 0 → 7, as corner indices `i + 2j + 4k`. Every cube of the grid uses the
/// same split, so face diagonals of neighbours match and the mesh conforms.
pub(crate) const KUHN_TETS: [[usize; 4]; 6] =
    [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]];

/// A box `[0, size[0]] × [0, size[1]] × [0, size[2]]` (m) with
/// `cells[c]` hexahedra along axis `c`, each split into six 4-node tets,
/// all positively oriented.
///
/// # Panics
/// If a size is not finite and positive or a cell count is zero.
pub fn box_mesh(size: [f64; 3], cells: [usize; 3]) -> TetMesh {
    assert!(size.iter().all(|s| s.is_finite() && *s > 0.0), "box size must be positive");
    assert!(cells.iter().all(|&n| n > 0), "box needs at least one cell per axis");
    let [nx, ny, nz] = cells;
    let node_index = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push([
                    size[0] * i as f64 / nx as f64,
                    size[1] * j as f64 / ny as f64,
                    size[2] * k as f64 / nz as f64,
                ]);
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: usize| node_index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                for kuhn in KUHN_TETS {
                    let mut tet = kuhn.map(corner);
                    if signed_volume6(&nodes, tet) < 0.0 {
                        tet.swap(2, 3);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    TetMesh { nodes, cells: Cells::Tet4(tets), groups: Vec::new() }
}

/// Six times the signed volume of a tet: `(b − a) × (c − a) · (d − a)`.
pub(crate) fn signed_volume6(nodes: &[[f64; 3]], tet: [usize; 4]) -> f64 {
    let [a, b, c, d] = tet.map(|n| nodes[n]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_volume_is_exact_and_tets_positive() {
        let mesh = box_mesh([0.3, 0.02, 0.01], [6, 2, 1]);
        assert_eq!(mesh.cells.len(), 6 * 12);
        let Cells::Tet4(tets) = &mesh.cells else { unreachable!() };
        let volume: f64 = tets.iter().map(|&t| signed_volume6(&mesh.nodes, t) / 6.0).sum();
        assert!(tets.iter().all(|&t| signed_volume6(&mesh.nodes, t) > 0.0));
        assert!((volume - 0.3 * 0.02 * 0.01).abs() < 1e-15);
    }
}
