//! Isoparametric TET4 and TET10 elements for isotropic linear elasticity.
//!
//! Shape functions in barycentric coordinates of the reference tet (see
//! [`crate::quadrature`]): TET4 `Nᵢ = Lᵢ`; TET10 (VTK order, node `4 + e`
//! on edge `modal_mesh::TET10_EDGES[e]` = `(a, b)`) corner `Nᵢ = Lᵢ(2Lᵢ − 1)`,
//! mid-edge `N₄₊ₑ = 4 Lₐ L_b`. Geometry is interpolated with the same
//! functions (isoparametric), so curved 10-node tets are supported.
//!
//! Element matrices, DOF `3a + i` = node `a`, component `i`:
//! - stiffness `Kₑ = ∫ Bᵀ D B dV`, written per node pair with gradients
//!   `gₐ = ∇Nₐ` as `K[3a+i, 3b+j] = ∫ λ gₐᵢ g_bⱼ + μ gₐⱼ g_bᵢ + μ δᵢⱼ gₐ·g_b dV`
//!   (isotropic `D` with Lamé λ, μ);
//! - consistent mass `Mₑ = ρ ∫ Nᵀ N dV`, `M[3a+i, 3b+j] = δᵢⱼ ρ ∫ Nₐ N_b dV`.
//!
//! Quadrature (rules of [`crate::quadrature`]): straight-sided elements are
//! integrated exactly — TET4 stiffness degree 1 (integrand constant), TET4
//! mass degree 2, TET10 stiffness degree 2, TET10 mass degree 4 (the
//! 14-point degree-5 rule). A 10-node tet whose mid-edge nodes are off the
//! straight edge midpoints (relative distance > 1e-10 of the edge length) is
//! "curved": its stiffness (a rational integrand) and mass (polynomial of
//! degree 7) both use the degree-5 rule, an approximation whose error
//! vanishes as the curvature does.
//!
//! Every matrix is written row-major into a caller-owned slice of length
//! `(3n)²`, `n` = nodes per element; no allocation per element.

use crate::{quadrature::QuadratureRule, FemError, Lame};

/// Maximum nodes per element.
pub const MAX_NODES: usize = 10;

/// Corner pairs of the 6 mid-edge nodes (VTK order, as in `modal_mesh`).
const EDGES: [[usize; 2]; 6] = modal_mesh::TET10_EDGES;

/// Reference gradients of the barycentric coordinates L₀..L₃.
const GRAD_L: [[f64; 3]; 4] = [[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Shape function values `n` and reference gradients `dn` (∂N/∂ξ) of an
/// `nodes`-node tet (4 or 10) at reference point `p`.
pub fn shape_functions(nodes: usize, p: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let l = [1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]];
    if nodes == 4 {
        n[..4].copy_from_slice(&l);
        dn[..4].copy_from_slice(&GRAD_L);
        return;
    }
    assert_eq!(nodes, 10, "tets have 4 or 10 nodes");
    for i in 0..4 {
        n[i] = l[i] * (2.0 * l[i] - 1.0);
        dn[i] = GRAD_L[i].map(|g| (4.0 * l[i] - 1.0) * g);
    }
    for (e, [a, b]) in EDGES.iter().enumerate() {
        n[4 + e] = 4.0 * l[*a] * l[*b];
        dn[4 + e] = [0, 1, 2].map(|c| 4.0 * (l[*b] * GRAD_L[*a][c] + l[*a] * GRAD_L[*b][c]));
    }
}

/// Physical-space data at one quadrature point: `det J` and `∇Nₐ`.
pub struct PointData {
    /// Shape function values.
    pub n: [f64; MAX_NODES],
    /// Physical gradients ∇Nₐ \[1/m\].
    pub grad: [[f64; 3]; MAX_NODES],
    /// Jacobian determinant `det(∂x/∂ξ)` (6 × volume for a straight tet).
    pub det: f64,
}

/// Evaluates shape functions, the Jacobian `J = ∂x/∂ξ` and physical
/// gradients `∇Nₐ = J⁻ᵀ ∂Nₐ/∂ξ` at `p` for an element with node
/// coordinates `x`. Returns `det J`; gradients are only valid if it is > 0.
pub fn point_data(x: &[[f64; 3]], p: [f64; 3]) -> PointData {
    let nodes = x.len();
    let mut out = PointData { n: [0.0; MAX_NODES], grad: [[0.0; 3]; MAX_NODES], det: 0.0 };
    let mut dn = [[0.0; 3]; MAX_NODES];
    shape_functions(nodes, p, &mut out.n, &mut dn);
    let mut j = [[0.0; 3]; 3];
    for (xa, da) in x.iter().zip(&dn) {
        for r in 0..3 {
            for c in 0..3 {
                j[r][c] += xa[r] * da[c];
            }
        }
    }
    let cof = [
        [
            j[1][1] * j[2][2] - j[1][2] * j[2][1],
            j[1][2] * j[2][0] - j[1][0] * j[2][2],
            j[1][0] * j[2][1] - j[1][1] * j[2][0],
        ],
        [
            j[0][2] * j[2][1] - j[0][1] * j[2][2],
            j[0][0] * j[2][2] - j[0][2] * j[2][0],
            j[0][1] * j[2][0] - j[0][0] * j[2][1],
        ],
        [
            j[0][1] * j[1][2] - j[0][2] * j[1][1],
            j[0][2] * j[1][0] - j[0][0] * j[1][2],
            j[0][0] * j[1][1] - j[0][1] * j[1][0],
        ],
    ];
    let det = j[0][0] * cof[0][0] + j[0][1] * cof[0][1] + j[0][2] * cof[0][2];
    out.det = det;
    // J⁻ᵀ = cof / det, so ∇Nₐ[r] = Σ_c cof[r][c] dNₐ[c] / det.
    for (g, da) in out.grad.iter_mut().zip(&dn).take(nodes) {
        for r in 0..3 {
            g[r] = (cof[r][0] * da[0] + cof[r][1] * da[1] + cof[r][2] * da[2]) / det;
        }
    }
    out
}

/// True when a 10-node tet's mid-edge nodes sit on the straight edge
/// midpoints (relative tolerance 1e-10 of the edge length). 4-node tets are
/// always straight.
pub fn is_straight(x: &[[f64; 3]]) -> bool {
    if x.len() == 4 {
        return true;
    }
    EDGES.iter().enumerate().all(|(e, [a, b])| {
        let (xa, xb, xm) = (x[*a], x[*b], x[4 + e]);
        let mut off = 0.0;
        let mut len = 0.0;
        for c in 0..3 {
            off += (xm[c] - 0.5 * (xa[c] + xb[c])).powi(2);
            len += (xb[c] - xa[c]).powi(2);
        }
        off <= 1e-20 * len
    })
}

/// The quadrature rules used for one assembly (see the module doc).
#[derive(Clone, Debug)]
pub struct ElementRules {
    tet4_stiffness: QuadratureRule,
    tet4_mass: QuadratureRule,
    tet10_stiffness: QuadratureRule,
    tet10_mass: QuadratureRule,
    curved: QuadratureRule,
}

impl Default for ElementRules {
    fn default() -> Self {
        ElementRules {
            tet4_stiffness: QuadratureRule::exact_to(1),
            tet4_mass: QuadratureRule::exact_to(2),
            tet10_stiffness: QuadratureRule::exact_to(2),
            tet10_mass: QuadratureRule::exact_to(4),
            curved: QuadratureRule::exact_to(5),
        }
    }
}

impl ElementRules {
    /// (stiffness rule, mass rule) for an element with coordinates `x`.
    pub fn select(&self, x: &[[f64; 3]]) -> (&QuadratureRule, &QuadratureRule) {
        match (x.len(), is_straight(x)) {
            (4, _) => (&self.tet4_stiffness, &self.tet4_mass),
            (_, true) => (&self.tet10_stiffness, &self.tet10_mass),
            (_, false) => (&self.curved, &self.curved),
        }
    }
}

/// Writes the element stiffness `k` and consistent mass `m` (row-major,
/// `(3n)²` each, overwritten) of element `element` with node coordinates
/// `x` (4 or 10 nodes, VTK order). Fails when `det J ≤ 0` (or is not finite)
/// at a quadrature point.
pub fn element_matrices_into(
    element: usize,
    x: &[[f64; 3]],
    lame: Lame,
    density: f64,
    rules: &ElementRules,
    k: &mut [f64],
    m: &mut [f64],
) -> Result<(), FemError> {
    let nodes = x.len();
    let size = 3 * nodes;
    assert!(k.len() == size * size && m.len() == size * size, "element buffers must be (3n)² long");
    k.fill(0.0);
    m.fill(0.0);
    let (k_rule, m_rule) = rules.select(x);
    for (p, w) in k_rule.points.iter().zip(&k_rule.weights) {
        let d = checked_point(element, x, *p)?;
        add_stiffness(&d, nodes, w * d.det, lame, k);
    }
    for (p, w) in m_rule.points.iter().zip(&m_rule.weights) {
        let d = checked_point(element, x, *p)?;
        add_mass(&d, nodes, w * d.det * density, m);
    }
    mirror_upper(k, size);
    mirror_upper(m, size);
    Ok(())
}

fn checked_point(element: usize, x: &[[f64; 3]], p: [f64; 3]) -> Result<PointData, FemError> {
    let d = point_data(x, p);
    if d.det > 0.0 && d.det.is_finite() {
        Ok(d)
    } else {
        Err(FemError::NonPositiveJacobian { element, det: d.det })
    }
}

/// Adds `scale · (λ gₐᵢ g_bⱼ + μ gₐⱼ g_bᵢ + μ δᵢⱼ gₐ·g_b)` to the upper triangle.
fn add_stiffness(d: &PointData, nodes: usize, scale: f64, lame: Lame, k: &mut [f64]) {
    let size = 3 * nodes;
    let (lam, mu) = (lame.lambda * scale, lame.mu * scale);
    for a in 0..nodes {
        let ga = d.grad[a];
        for b in a..nodes {
            let gb = d.grad[b];
            let dot = mu * (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]);
            for i in 0..3 {
                let row = &mut k[(3 * a + i) * size + 3 * b..(3 * a + i) * size + 3 * b + 3];
                for j in 0..3 {
                    row[j] += lam * ga[i] * gb[j] + mu * ga[j] * gb[i];
                }
                row[i] += dot;
            }
        }
    }
}

/// Adds `scale · Nₐ N_b` to the diagonal components of the upper triangle.
fn add_mass(d: &PointData, nodes: usize, scale: f64, m: &mut [f64]) {
    let size = 3 * nodes;
    for a in 0..nodes {
        for b in a..nodes {
            let v = scale * d.n[a] * d.n[b];
            for i in 0..3 {
                m[(3 * a + i) * size + 3 * b + i] += v;
            }
        }
    }
}

/// Copies the upper node-block triangle to the lower one, so the element
/// matrix is exactly symmetric. Within a diagonal node block the lower part
/// is taken from the upper too.
fn mirror_upper(a: &mut [f64], size: usize) {
    for r in 0..size {
        for c in 0..r {
            // Entry (r, c) with r > c: its transpose (c, r) was computed if
            // c's node ≤ r's node, which always holds when c < r.
            a[r * size + c] = a[c * size + r];
        }
    }
}
