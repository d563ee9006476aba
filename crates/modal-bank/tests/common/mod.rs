//! Small synthetic banks for tests (no eigen solve): a cube surface (TET4
//! style) and a tetrahedron surface with mid-edge nodes (TET10 style).
#![allow(dead_code)]

use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;

/// Steel with the preset damping of `shared/reference/materials.md`.
pub fn steel() -> Material {
    Material {
        name: Some("steel".into()),
        youngs_pa: 2.0e11,
        poisson: 0.29,
        density_kg_m3: 7850.0,
        alpha: 5.0,
        beta: 3e-8,
    }
}

/// Deterministic values in [-1, 1) (64-bit LCG).
pub fn pseudo_random(seed: u64, count: usize) -> Vec<f64> {
    let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (0..count)
        .map(|_| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// Frequencies for `n` modes, ascending, with one exactly repeated pair.
pub fn frequencies(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 440.0 * (1.0 + (i / 2 * 2) as f64 * 0.731) + if i % 2 == 1 && i > 2 { 13.7 } else { 0.0 })
        .collect()
}

/// Solid cube of side `a` [m] with density `rho`: exact mass properties.
pub fn cube_mass(a: f64, rho: f64) -> MassProperties {
    let v = a * a * a;
    let m = rho * v;
    let i = m * a * a / 6.0;
    MassProperties {
        volume_m3: v,
        mass_kg: m,
        center_of_mass_m: [a / 2.0; 3],
        inertia_kg_m2: [[i, 0.0, 0.0], [0.0, i, 0.0], [0.0, 0.0, i]],
    }
}

fn bank_on(surface: Surface, n_modes: usize, mass: MassProperties) -> ModeBank {
    let s = surface.positions.len();
    let shapes =
        pseudo_random(7 + n_modes as u64, n_modes * s * 3).iter().map(|&v| (v * 0.3) as f32).collect();
    let mut bank = ModeBank {
        frequencies_hz: frequencies(n_modes),
        damping_ratios: vec![],
        decay_rates: vec![],
        residuals: (0..n_modes).map(|i| 1e-12 * (i + 1) as f64).collect(),
        shapes,
        surface,
        material: steel(),
        mass,
        info: SolveInfo {
            order: 1,
            dofs: 3 * 27,
            rigid_modes_removed: 6,
            inertia_expected: n_modes + 6,
            inertia_found: n_modes + 6,
            assemble_s: 0.1 + 0.2,
            factor_s: 0.012345678901234567,
            solve_s: 1e-300,
            input_hash: "ab".repeat(32),
            ..Default::default()
        },
    };
    bank.recompute_damping();
    bank
}

/// Cube of side 0.1 m: 8 corner nodes, 12 outward triangles.
pub fn cube_surface(a: f64) -> Surface {
    let positions: Vec<[f64; 3]> =
        (0..8).map(|k| [(k & 1) as f64 * a, ((k >> 1) & 1) as f64 * a, ((k >> 2) & 1) as f64 * a]).collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3], // z = 0
        [4, 5, 6],
        [5, 7, 6], // z = a
        [0, 1, 4],
        [1, 5, 4], // y = 0
        [2, 6, 3],
        [3, 6, 7], // y = a
        [0, 4, 2],
        [2, 4, 6], // x = 0
        [1, 3, 5],
        [3, 7, 5], // x = a
    ];
    Surface {
        node_ids: (0..8).map(|k| 100 + 3 * k).collect(),
        positions,
        triangles,
        triangle_edge_nodes: None,
    }
}

/// A TET4-style bank on a 0.1 m cube surface.
pub fn linear_bank(n_modes: usize) -> ModeBank {
    bank_on(cube_surface(0.1), n_modes, cube_mass(0.1, 7850.0))
}

/// A TET10-style bank: one tetrahedron's surface, 4 corners + 6 mid-edge nodes.
pub fn quadratic_bank(n_modes: usize) -> ModeBank {
    let corners = [[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.2]];
    let edges = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
    let mut positions: Vec<[f64; 3]> = corners.to_vec();
    for [a, b] in edges {
        positions.push([0, 1, 2].map(|c| 0.5 * (corners[a][c] + corners[b][c])));
    }
    let edge_node =
        |a: usize, b: usize| 4 + edges.iter().position(|e| *e == [a, b] || *e == [b, a]).unwrap_or(0);
    let triangles = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    let triangle_edge_nodes = triangles
        .iter()
        .map(|t: &[usize; 3]| [edge_node(t[0], t[1]), edge_node(t[1], t[2]), edge_node(t[2], t[0])])
        .collect();
    let surface = Surface {
        node_ids: (0..10).collect(),
        positions,
        triangles,
        triangle_edge_nodes: Some(triangle_edge_nodes),
    };
    let mut bank = bank_on(surface, n_modes, cube_mass(0.1, 7850.0));
    bank.info.order = 2;
    bank
}
