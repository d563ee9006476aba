//! Rigid-body mass properties of a tet mesh (exact integrals).
//!
//! With density ρ and the isoparametric map `x(ξ)` of each element:
//! `V = ∫ dV`, `m = ρV`, centre of mass `c = (1/V) ∫ x dV`, and the inertia
//! tensor about `c`: `I = ρ ∫ (|r|² 𝟙 − r rᵀ) dV`, `r = x − c`.
//!
//! The integrands are polynomials in reference coordinates: for 4-node and
//! straight-sided 10-node tets the map is affine and `r rᵀ det J` has degree
//! 2 (4-point rule, exact); for curved 10-node tets `det J` has degree 3 and
//! `r rᵀ det J` degree 7, integrated exactly by the degree-7
//! Grundmann–Möller rule. Moments are accumulated about the mean node
//! position and shifted to `c` at the end (parallel-axis theorem), which
//! keeps round-off relative to the body's size rather than its distance
//! from the origin. Elements with `det J ≤ 0` contribute their signed
//! integral (meshes are expected to be checked by `modal-mesh` first).

use modal_mesh::TetMesh;
use serde::{Deserialize, Serialize};

use crate::element::{is_straight, point_data};
use crate::quadrature::QuadratureRule;

/// Volume, mass, centre of mass and inertia of a solid, SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MassProperties {
    /// Volume \[m³\].
    pub volume_m3: f64,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Centre of mass \[m\].
    pub center_of_mass_m: [f64; 3],
    /// Inertia tensor about the centre of mass \[kg·m²\], symmetric.
    pub inertia_kg_m2: [[f64; 3]; 3],
}

/// Mass properties of `mesh` (4- or 10-node tets) with uniform density
/// `density_kg_m3`. An empty mesh gives all zeros.
///
/// # Panics
/// If an element refers to a node index out of range (check the mesh with
/// `modal-mesh` first; [`crate::assemble`] reports this as an error).
pub fn mass_properties(mesh: &TetMesh, density_kg_m3: f64) -> MassProperties {
    let n = mesh.node_count().max(1) as f64;
    let mut origin = [0.0; 3];
    for p in &mesh.nodes {
        (0..3).for_each(|c| origin[c] += p[c] / n);
    }
    let affine = QuadratureRule::exact_to(2);
    let curved = QuadratureRule::exact_to(7);
    let mut volume = 0.0;
    let mut first = [0.0; 3];
    let mut second = [[0.0; 3]; 3];
    let mut x = [[0.0; 3]; 10];
    for e in 0..mesh.cells.len() {
        let ids = mesh.cells.nodes_of(e);
        for (xi, &id) in x.iter_mut().zip(ids) {
            let p = mesh.nodes[id];
            *xi = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        }
        let x = &x[..ids.len()];
        let rule = if is_straight(x) { &affine } else { &curved };
        for (p, w) in rule.points.iter().zip(&rule.weights) {
            let d = point_data(x, *p);
            let dv = w * d.det;
            let mut r = [0.0; 3];
            for (na, xa) in d.n.iter().zip(x) {
                (0..3).for_each(|c| r[c] += na * xa[c]);
            }
            volume += dv;
            for a in 0..3 {
                first[a] += dv * r[a];
                for b in 0..3 {
                    second[a][b] += dv * r[a] * r[b];
                }
            }
        }
    }
    if volume == 0.0 {
        return MassProperties {
            volume_m3: 0.0,
            mass_kg: 0.0,
            center_of_mass_m: origin,
            inertia_kg_m2: [[0.0; 3]; 3],
        };
    }
    let shift = first.map(|f| f / volume);
    let mut cov = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            cov[a][b] = density_kg_m3 * (second[a][b] - volume * shift[a] * shift[b]);
        }
    }
    let trace = cov[0][0] + cov[1][1] + cov[2][2];
    let mut inertia = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            inertia[a][b] = if a == b { trace - cov[a][b] } else { -cov[a][b] };
        }
    }
    // Exact symmetry.
    for a in 0..3 {
        for b in 0..a {
            inertia[a][b] = inertia[b][a];
        }
    }
    MassProperties {
        volume_m3: volume,
        mass_kg: density_kg_m3 * volume,
        center_of_mass_m: [0, 1, 2].map(|c| origin[c] + shift[c]),
        inertia_kg_m2: inertia,
    }
}
