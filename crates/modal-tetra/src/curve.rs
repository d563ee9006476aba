//! Curved 10-node boundary: mid-edge nodes of boundary edges on the input surface.
//!
//! A 10-node tet maps the reference tet by x(ξ) = Σ_k N_k(ξ) x_k with the
//! quadratic shape functions N_k (corners L_i(2L_i − 1), edge nodes
//! 4 L_a L_b). With straight mid-edge nodes the mesh boundary is the
//! piecewise-flat stuffed surface, whose volume and stiffness error is
//! O(h²) and dominates the O(h⁴) eigenvalue error of quadratic elements on
//! curved bodies. Here the mid-edge node of every edge of a boundary face
//! is moved to the point of the input surface closest to the straight
//! midpoint (the corners are already on it), so the boundary follows the
//! surface to second order.
//!
//! Guards, per edge and per element:
//! - a projection that moves the node by more than [`MAX_BULGE`] × the edge
//!   length is not made (the nearest surface point is then another sheet, or
//!   a feature the edge cuts across);
//! - every element with a moved node must keep det J(ξ) ≥
//!   [`MIN_JACOBIAN_RATIO`] × det J_straight at the corners, mid-edges, face
//!   centroids, centroid and the degree-3 Keast points; an element that
//!   fails gets its boundary edges straight again (which changes its
//!   neighbours on those edges too, so the check repeats until none fails).
//!   Straight elements are valid, so this ends.

use modal_mesh::{Cells, TetMesh, TET10_EDGES};
use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::geom::{cross, dot, norm, orient6, sub, V3};

/// Largest move of a mid-edge node onto the surface, as a fraction of the edge length.
pub const MAX_BULGE: f64 = 0.25;
/// Smallest det J of a curved element, relative to its straight (corner) tet.
pub const MIN_JACOBIAN_RATIO: f64 = 0.2;

/// The curved mesh and what was done.
pub(crate) struct Curved {
    /// 10-node mesh: the stuffed nodes first (same indices), then mid-edge nodes.
    pub mesh: TetMesh,
    /// Boundary mid-edge nodes moved onto the surface.
    pub curved_edges: usize,
    /// Elements whose boundary edges were made straight again by the Jacobian check.
    pub straightened_elements: usize,
    /// Mid-edge nodes of boundary edges (curved or not), sorted.
    pub boundary_mids: Vec<usize>,
}

/// Reference points (ξ, η, ζ) where det J is checked.
fn check_points() -> Vec<[f64; 3]> {
    let mut p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let corner = p.clone();
    for [a, b] in TET10_EDGES {
        p.push(std::array::from_fn(|c| 0.5 * (corner[a][c] + corner[b][c])));
    }
    for skip in 0..4 {
        let f: Vec<usize> = (0..4).filter(|&k| k != skip).collect();
        p.push(std::array::from_fn(|c| f.iter().map(|&k| corner[k][c]).sum::<f64>() / 3.0));
    }
    p.push([0.25; 3]);
    let s = 1.0 / 6.0;
    p.extend([[s, s, s], [0.5, s, s], [s, 0.5, s], [s, s, 0.5]]);
    p
}

/// Smallest det J over `points`, divided by the straight tet's det J.
fn min_jacobian_ratio(x: &[V3; 10], points: &[[f64; 3]]) -> f64 {
    let straight = orient6(x[0], x[1], x[2], x[3]);
    points
        .iter()
        .map(|&p| {
            let g = modal_mesh::tet10_shape_gradients(p);
            // Columns d x / d ξ_c.
            let col: [V3; 3] = std::array::from_fn(|c| {
                std::array::from_fn(|r| (0..10).map(|k| x[k][r] * g[k][c]).sum::<f64>())
            });
            dot(col[0], cross(col[1], col[2])) / straight
        })
        .fold(f64::INFINITY, f64::min)
}

/// Promotes the positively oriented 4-node `tets` to 10-node tets whose
/// boundary edges follow the surface of `bvh` (see the module doc).
pub(crate) fn curve(nodes: Vec<V3>, tets: Vec<[usize; 4]>, bvh: &Bvh) -> Curved {
    let linear = TetMesh { nodes, cells: Cells::Tet4(tets), groups: Vec::new() };
    let mut mesh = modal_mesh::to_quadratic(&linear);
    let Cells::Tet10(elements) = &mesh.cells else { unreachable!("to_quadratic gives 10-node tets") };
    let elements = elements.clone();
    // Boundary faces: sorted corner triples that occur once.
    let mut faces: Vec<([usize; 3], usize, usize)> = Vec::with_capacity(4 * elements.len());
    for (t, e) in elements.iter().enumerate() {
        for skip in 0..4 {
            let mut f = [e[(skip + 1) % 4], e[(skip + 2) % 4], e[(skip + 3) % 4]];
            f.sort_unstable();
            faces.push((f, t, skip));
        }
    }
    faces.par_sort_unstable();
    let mut boundary_mid: Vec<(usize, usize, usize)> = Vec::new(); // (mid node, corner a, corner b)
    for run in faces.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, t, skip)] = run {
            let e = &elements[*t];
            for (slot, [a, b]) in TET10_EDGES.iter().enumerate() {
                if *a != *skip && *b != *skip {
                    boundary_mid.push((e[4 + slot], e[*a], e[*b]));
                }
            }
        }
    }
    boundary_mid.sort_unstable();
    boundary_mid.dedup();
    let straight: Vec<V3> = boundary_mid.iter().map(|&(m, _, _)| mesh.nodes[m]).collect();
    let projected: Vec<Option<V3>> = boundary_mid
        .par_iter()
        .zip(&straight)
        .map(|(&(_, a, b), &s)| {
            let length = norm(sub(mesh.nodes[a], mesh.nodes[b]));
            let p = bvh.closest(s)?;
            let moved = norm(sub(p, s));
            (moved > 1e-12 * length && moved <= MAX_BULGE * length).then_some(p)
        })
        .collect();
    let mut is_moved = vec![false; mesh.nodes.len()];
    let mut curved_edges = 0;
    for (&(m, _, _), p) in boundary_mid.iter().zip(&projected) {
        if let Some(p) = p {
            mesh.nodes[m] = *p;
            is_moved[m] = true;
            curved_edges += 1;
        }
    }
    // Jacobian check with straight fallback, repeated until no element fails.
    let points = check_points();
    let mut suspects: Vec<usize> =
        (0..elements.len()).filter(|&t| elements[t][4..].iter().any(|&m| is_moved[m])).collect();
    let mut straightened = vec![false; elements.len()];
    let mut mid_of = vec![usize::MAX; mesh.nodes.len()];
    for (i, &(m, _, _)) in boundary_mid.iter().enumerate() {
        mid_of[m] = i;
    }
    let mut elements_of_mid: Vec<Vec<usize>> = Vec::new();
    while !suspects.is_empty() {
        let nodes = &mesh.nodes;
        let bad: Vec<usize> = suspects
            .par_iter()
            .copied()
            .filter(|&t| min_jacobian_ratio(&elements[t].map(|k| nodes[k]), &points) < MIN_JACOBIAN_RATIO)
            .collect();
        if bad.is_empty() {
            break;
        }
        if elements_of_mid.is_empty() {
            elements_of_mid = vec![Vec::new(); boundary_mid.len()];
            for (t, e) in elements.iter().enumerate() {
                for &m in &e[4..] {
                    if is_moved[m] {
                        elements_of_mid[mid_of[m]].push(t);
                    }
                }
            }
        }
        suspects.clear();
        for t in bad {
            straightened[t] = true;
            for &m in &elements[t][4..] {
                if is_moved[m] {
                    let i = mid_of[m];
                    mesh.nodes[m] = straight[i];
                    is_moved[m] = false;
                    curved_edges -= 1;
                    suspects.extend(&elements_of_mid[i]);
                }
            }
        }
        suspects.sort_unstable();
        suspects.dedup();
    }
    let straightened_elements = straightened.iter().filter(|&&s| s).count();
    let boundary_mids = boundary_mid.iter().map(|&(m, _, _)| m).collect();
    Curved { mesh, curved_edges, straightened_elements, boundary_mids }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_tet_has_unit_jacobian_ratio_and_a_pushed_mid_node_lowers_it() {
        let c = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut x = [[0.0; 3]; 10];
        x[..4].copy_from_slice(&c);
        for (e, [a, b]) in TET10_EDGES.iter().enumerate() {
            x[4 + e] = std::array::from_fn(|k| 0.5 * (c[*a][k] + c[*b][k]));
        }
        let points = check_points();
        assert!((min_jacobian_ratio(&x, &points) - 1.0).abs() < 1e-12);
        // Moving the (0,1) mid-edge node towards the opposite corners folds the element.
        x[4] = [0.5, 0.6, 0.6];
        assert!(min_jacobian_ratio(&x, &points) < 0.0);
    }
}
