//! A thin wall as one open screen: the pressure jump across its
//! mid-surface by a Galerkin solve of the hypersingular equation.
//!
//! Time convention `e^{−iωt}`, `G(x, y) = e^{ikr}/(4πr)`. A wall much
//! thinner than the wavelength radiates as a surface `Γ` carrying the jump
//! `μ = p⁺ − p⁻` of the pressure across it (`+` the side its normal `n`
//! points to). Outside, `p(x) = ∫_Γ μ ∂G/∂n_y dS_y`; the normal derivative,
//! continuous across `Γ`, equals `q = iωρ₀ v_n` on it:
//!
//! `N μ = q`,  `N μ(x) = ∂/∂n_x ∫_Γ μ ∂G/∂n_y dS_y`.
//!
//! `N` is hypersingular. In weak form (Maue's identity; Nédélec,
//! *Acoustic and Electromagnetic Equations* §3.4), for `μ`, `ψ` vanishing on
//! the free edge `∂Γ` and `curl_Γ u = n × ∇_Γ u`:
//!
//! `⟨N μ, ψ⟩ = −∫∫ G(x, y) [curl_Γ μ(y)·curl_Γ ψ(x) − k² (n_x·n_y) μ(y) ψ(x)] dS_y dS_x`,
//!
//! whose kernel is only weakly singular. Discretization: `μ` and `ψ`
//! continuous and linear on each flat panel, zero at the free edge (the
//! interior nodes are the unknowns: near a free edge the jump falls like
//! `√d`), Galerkin: `Σ_b A_ab μ_b = ∫ q φ_a dS`, dense complex LU (faer, one
//! thread: the same bits for any thread count). Piecewise-constant
//! collocation, the closed-surface solver's scheme, does not converge on a
//! screen (a flat disc's dipole at 168 / 720 / 2 976 / 12 096 panels:
//! 1.085 / 0.973 / 0.896 / 0.859 of Lamb's): constants are not in the
//! hypersingular operator's energy space `H^{1/2}`.
//!
//! Quadrature of a pair of panels `(T, S)`: the inner integrals
//! `∫_S G (1, λ_j) dS_y` seen from an outer point `x` are, for `S = T` and
//! for `S` within [`NEAR_RATIO`] diameters, split as `1/(4πr)` in closed
//! form ([`static_potentials`]) plus the bounded rest `(e^{ikr} − 1)/(4πr)`
//! by the 7-point rule, and else taken by the 3-point rule. The outer
//! integral takes the 7-point rule (`S = T` and near pairs; on `T` split in
//! four when the two panels touch) or the 3-point rule.
//!
//! Checked (tests below): a flat disc translating broadside has Lamb's
//! dipole (0.984 of it on 2 976 panels, converging); on a closed sphere the
//! jump radiates the oscillating sphere's closed form within 0.08 dB at
//! `ka` = 0.5, 1.5, 3; bempp-cl's Galerkin screen (tools/screen_ref.py)
//! agrees to 0.02 % (docs/radiation.md, "Thin walls").
//!
//! Not used by `modal radiation`: a wall solved as its mid-surface drops the
//! wall's thickness, and for subsonic bending patterns (the quiet modes of
//! thin plates) that changes the far field at first order in the thickness:
//! by 2–5 dB at `t/a` = 0.04–0.08 (docs/radiation.md, "Thin walls").

use faer::c64;
use faer::Mat;
use rayon::prelude::*;

use crate::bem::Air;
use crate::error::RadiationError;
use crate::geometry::{cross, dot, norm, sub, BoundaryMesh};
use crate::quadrature::{on_triangle, quarters, TRIANGLE_3, TRIANGLE_7};

/// A pair of panels is near (inner integral in closed form, outer by the
/// 7-point rule) when their centroids are closer than this many times the
/// larger diameter; farther pairs take the 3-point rule on both panels.
/// Measured: 4 instead of 2 moved the disc probe's levels by < 10⁻⁴.
pub const NEAR_RATIO: f64 = 2.0;

/// Most unknowns (interior nodes) of one dense screen solve (16 B × n²:
/// 6 000 ≈ 0.58 GB, the closed-surface solver's dense limit).
pub const MAX_SCREEN_UNKNOWNS: usize = 6000;

const FOUR_PI: f64 = 4.0 * std::f64::consts::PI;

/// The jump across a screen for each velocity field.
#[derive(Clone, Debug, PartialEq)]
pub struct ScreenJump {
    /// Per field, the jump `μ = p⁺ − p⁻` [Pa] at each vertex of the mesh
    /// (zero on the free edge and at vertices no panel uses).
    pub nodal: Vec<Vec<c64>>,
    /// Per field, the mean of `μ` over each panel [Pa].
    pub panel_mean: Vec<Vec<c64>>,
}

/// One flat panel with what the Galerkin integrals need.
struct Element {
    corners: [[f64; 3]; 3],
    nodes: [usize; 3],
    normal: [f64; 3],
    area: f64,
    diameter: f64,
    centroid: [f64; 3],
    /// `∇λ_i`, constant on the panel.
    grads: [[f64; 3]; 3],
    /// `curl_Γ λ_i = n × ∇λ_i`.
    curls: [[f64; 3]; 3],
}

impl Element {
    fn new(mesh: &BoundaryMesh, j: usize) -> Element {
        let p = &mesh.panels[j];
        let corners = p.corners.map(|c| mesh.vertices[c]);
        // ∇λ_i = n × (x_{i+2} − x_{i+1}) / 2A: towards corner i, of length 1/height.
        let grads = [0, 1, 2].map(|i| {
            let e = sub(corners[(i + 2) % 3], corners[(i + 1) % 3]);
            cross(p.normal, e).map(|x| x / (2.0 * p.area))
        });
        Element {
            corners,
            nodes: p.corners,
            normal: p.normal,
            area: p.area,
            diameter: p.diameter,
            centroid: p.centroid,
            grads,
            curls: grads.map(|g| cross(p.normal, g)),
        }
    }
}

/// The jump across the open screen `mesh` (flat panels, normals on the `+`
/// side) for each normal-velocity field (one value per panel [m/s]) at
/// `frequency_hz`. Errors: a bad frequency, air or velocity field; more
/// than [`MAX_SCREEN_UNKNOWNS`] interior nodes; a singular system.
pub fn solve_screen(
    mesh: &BoundaryMesh,
    air: Air,
    frequency_hz: f64,
    velocities: &[Vec<c64>],
) -> Result<ScreenJump, RadiationError> {
    crate::bem::check_problem(air, frequency_hz, mesh.len(), velocities)?;
    let unknown = interior_nodes(mesh);
    let n = unknown.iter().filter(|u| u.is_some()).count();
    if n > MAX_SCREEN_UNKNOWNS {
        return Err(RadiationError::ScreenTooLarge { unknowns: n, max: MAX_SCREEN_UNKNOWNS });
    }
    let omega = std::f64::consts::TAU * frequency_hz;
    let k = omega / air.sound_speed_m_s;
    let iwr = c64::new(0.0, omega * air.density_kg_m3);
    let elements: Vec<Element> = (0..mesh.len()).map(|j| Element::new(mesh, j)).collect();
    let a = assemble(&elements, &unknown, n, k);
    let nf = velocities.len();
    let mut rhs = Mat::<c64>::zeros(n, nf);
    for (f, v) in velocities.iter().enumerate() {
        for (e, vj) in elements.iter().zip(v) {
            for &node in &e.nodes {
                if let Some(row) = unknown[node] {
                    rhs[(row, f)] += vj * iwr * (e.area / 3.0);
                }
            }
        }
    }
    let x = lu_solve(a, rhs).ok_or(RadiationError::Singular { frequency_hz })?;
    let zero = c64::new(0.0, 0.0);
    let nodal: Vec<Vec<c64>> =
        (0..nf).map(|f| unknown.iter().map(|u| u.map_or(zero, |row| x[(row, f)])).collect()).collect();
    let panel_mean = nodal
        .iter()
        .map(|mu| elements.iter().map(|e| e.nodes.iter().map(|&c| mu[c]).sum::<c64>() / 3.0).collect())
        .collect();
    Ok(ScreenJump { nodal, panel_mean })
}

/// The unknown (row) of each vertex: the vertices of the panels that are
/// not on the free edge (an edge of one panel), in vertex order.
fn interior_nodes(mesh: &BoundaryMesh) -> Vec<Option<usize>> {
    let mut used = vec![false; mesh.vertices.len()];
    let mut free = vec![false; mesh.vertices.len()];
    for p in &mesh.panels {
        p.corners.iter().for_each(|&c| used[c] = true);
    }
    for ((a, b), panels) in mesh.edge_panels() {
        if panels.len() == 1 {
            free[a] = true;
            free[b] = true;
        }
    }
    let mut next = 0;
    (0..mesh.vertices.len())
        .map(|v| {
            (used[v] && !free[v]).then(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

/// Panels assembled together: their rows are summed into the matrix in
/// panel order, so the bits do not depend on the thread count.
const CHUNK: usize = 32;

/// The Galerkin matrix `A_ab = ⟨N φ_b, φ_a⟩` (module doc), `n × n`.
fn assemble(elements: &[Element], unknown: &[Option<usize>], n: usize, k: f64) -> Mat<c64> {
    let mut a = Mat::<c64>::zeros(n, n);
    let starts: Vec<usize> = (0..elements.len()).step_by(CHUNK).collect();
    for block in starts.chunks(4 * rayon::current_num_threads().max(1)) {
        let rows: Vec<Vec<(usize, Vec<c64>)>> = block
            .par_iter()
            .map(|&start| {
                let end = (start + CHUNK).min(elements.len());
                let mut out: Vec<(usize, Vec<c64>)> = Vec::new();
                for t in start..end {
                    let mut local = [
                        vec![c64::new(0.0, 0.0); n],
                        vec![c64::new(0.0, 0.0); n],
                        vec![c64::new(0.0, 0.0); n],
                    ];
                    let et = &elements[t];
                    for (s, es) in elements.iter().enumerate() {
                        let (i0, i1) = pair_integrals(et, es, t == s, k);
                        let nn = dot(et.normal, es.normal);
                        for i in 0..3 {
                            if unknown[et.nodes[i]].is_none() {
                                continue;
                            }
                            for j in 0..3 {
                                if let Some(col) = unknown[es.nodes[j]] {
                                    let curls = dot(et.curls[i], es.curls[j]);
                                    local[i][col] -= i0 * curls - i1[i][j] * (k * k * nn);
                                }
                            }
                        }
                    }
                    for (i, row) in local.into_iter().enumerate() {
                        if let Some(r) = unknown[et.nodes[i]] {
                            out.push((r, row));
                        }
                    }
                }
                out
            })
            .collect();
        for (r, row) in rows.into_iter().flatten() {
            for (c, v) in row.into_iter().enumerate() {
                a[(r, c)] += v;
            }
        }
    }
    a
}

/// `(∫_T∫_S G, ∫_T∫_S G λ_i(x) λ_j(y))` of one pair of panels.
fn pair_integrals(t: &Element, s: &Element, same: bool, k: f64) -> (c64, [[c64; 3]; 3]) {
    let mut i0 = c64::new(0.0, 0.0);
    let mut i1 = [[c64::new(0.0, 0.0); 3]; 3];
    let mut add = |b: [f64; 3], w: f64, (g0, g1): (c64, [c64; 3])| {
        i0 += g0 * w;
        for i in 0..3 {
            for j in 0..3 {
                i1[i][j] += g1[j] * (w * b[i]);
            }
        }
    };
    let near = norm(sub(t.centroid, s.centroid)) < NEAR_RATIO * t.diameter.max(s.diameter);
    let touching = t.nodes.iter().any(|c| s.nodes.contains(c));
    if same {
        for (b, w) in TRIANGLE_7 {
            let x = on_triangle(b, t.corners);
            add(b, w * t.area, near_inner(x, s, k));
        }
    } else if touching {
        for child in quarters([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) {
            for (b, w) in TRIANGLE_7 {
                let bt = on_triangle(b, child);
                let x = on_triangle(bt, t.corners);
                add(bt, 0.25 * w * t.area, near_inner(x, s, k));
            }
        }
    } else if near {
        for (b, w) in TRIANGLE_7 {
            let x = on_triangle(b, t.corners);
            add(b, w * t.area, near_inner(x, s, k));
        }
    } else {
        for (b, w) in TRIANGLE_3 {
            let x = on_triangle(b, t.corners);
            let mut g1 = [c64::new(0.0, 0.0); 3];
            let mut g0 = c64::new(0.0, 0.0);
            for (by, wy) in TRIANGLE_3 {
                let g = green(k, x, on_triangle(by, s.corners)) * (wy * s.area);
                g0 += g;
                for j in 0..3 {
                    g1[j] += g * by[j];
                }
            }
            add(b, w * t.area, (g0, g1));
        }
    }
    (i0, i1)
}

/// `G(x, y)`.
#[inline]
fn green(k: f64, x: [f64; 3], y: [f64; 3]) -> c64 {
    let r = norm(sub(y, x));
    let (sn, cs) = (k * r).sin_cos();
    c64::new(cs, sn) / (FOUR_PI * r)
}

/// `(∫_S G(x, ·), ∫_S G(x, ·) λ_j)` for `x` near or on `S`, split as
/// `G = 1/(4πr) + (e^{ikr} − 1)/(4πr)`: the static part in closed form
/// ([`static_potentials`]), the rest (bounded, `ik/4π` at `r = 0`) by the
/// 7-point rule.
fn near_inner(x: [f64; 3], s: &Element, k: f64) -> (c64, [c64; 3]) {
    let (i0, iv, x0) = static_potentials(x, s);
    let l0 = barycentric(x0, s);
    let mut g0 = c64::new(i0 / FOUR_PI, 0.0);
    let mut g1 = [0, 1, 2].map(|j| c64::new((l0[j] * i0 + dot(s.grads[j], iv)) / FOUR_PI, 0.0));
    for (b, w) in TRIANGLE_7 {
        let r = norm(sub(on_triangle(b, s.corners), x));
        let kr = k * r;
        // (e^{ikr} − 1)/r, by series below kr = 10⁻³ (its rounding is then ≈ 10⁻¹³ k).
        let rest = if kr < 1e-3 {
            c64::new(-0.5 * k * kr, k * (1.0 - kr * kr / 6.0))
        } else {
            let (sn, cs) = kr.sin_cos();
            c64::new(cs - 1.0, sn) / r
        };
        let g = rest * (w * s.area / FOUR_PI);
        g0 += g;
        for j in 0..3 {
            g1[j] += g * b[j];
        }
    }
    (g0, g1)
}

/// The static potentials of the flat triangle `s` at `x` (Wilton, Rao,
/// Glisson, Schaubert & Butler 1984, IEEE Trans. AP-32): `∫_S dS/R`,
/// `∫_S (ρ − ρ₀)/R dS` (in the plane) and `ρ₀`, the foot of `x` on the
/// plane. With `d` the height of `x` over the plane, per edge `i` its unit
/// direction `l̂`, outward in-plane normal `û = l̂ × n`, signed distance
/// `P⁰ = (a − ρ₀)·û` of its line, `l^± = (end^± − ρ₀)·l̂`, `R^±` the
/// distances of its ends from `x`, `R⁰² = P⁰² + d²` and
/// `f = ln((R⁺ + l⁺)/(R⁻ + l⁻))`:
/// `∫ dS/R = Σ [P⁰ f − d (atan(P⁰l⁺/(R⁰² + dR⁺)) − atan(P⁰l⁻/(R⁰² + dR⁻)))]`,
/// `∫ (ρ − ρ₀)/R dS = ½ Σ û [R⁰² f + l⁺R⁺ − l⁻R⁻]`.
fn static_potentials(x: [f64; 3], s: &Element) -> (f64, [f64; 3], [f64; 3]) {
    let n = s.normal;
    let height = dot(sub(x, s.corners[0]), n);
    let x0 = [0, 1, 2].map(|c| x[c] - height * n[c]);
    let d = height.abs();
    let tiny = 1e-12 * s.diameter;
    let (mut scalar, mut vector) = (0.0, [0.0; 3]);
    for e in 0..3 {
        let (a, b) = (s.corners[e], s.corners[(e + 1) % 3]);
        let edge = sub(b, a);
        let lhat = edge.map(|c| c / norm(edge));
        let u = cross(lhat, n);
        let p0 = dot(sub(a, x0), u);
        let (lp, lm) = (dot(sub(b, x0), lhat), dot(sub(a, x0), lhat));
        let (rp, rm) = (norm(sub(b, x)), norm(sub(a, x)));
        let r02 = p0 * p0 + d * d;
        // The two forms of f are equal ((R + l)(R − l) = R⁰²); each avoids the
        // other's cancellation.
        let f = if lp + lm >= 0.0 { ((rp + lp) / (rm + lm)).ln() } else { ((rm - lm) / (rp - lp)).ln() };
        let f = if f.is_finite() { f } else { 0.0 };
        let beta = if p0.abs() < tiny {
            0.0
        } else {
            (p0 * lp / (r02 + d * rp)).atan() - (p0 * lm / (r02 + d * rm)).atan()
        };
        scalar += p0 * f - d * beta;
        let along = 0.5 * (r02 * f + lp * rp - lm * rm);
        for c in 0..3 {
            vector[c] += u[c] * along;
        }
    }
    (scalar, vector, x0)
}

/// Barycentric coordinates of `x` (in `s`'s plane) on `s`.
fn barycentric(x: [f64; 3], s: &Element) -> [f64; 3] {
    [0, 1, 2].map(|i| {
        let c = s.corners[i];
        // λ_i(x) = 1 + ∇λ_i·(x − x_i).
        1.0 + dot(s.grads[i], sub(x, c))
    })
}

/// `A X = B` by dense LU with partial pivoting (faer, one thread); `None`
/// when a factor or the solution is not finite.
fn lu_solve(a: Mat<c64>, b: Mat<c64>) -> Option<Mat<c64>> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::lu::partial_pivoting::solve;
    use faer::Par;
    let mut lu = a;
    let perm = crate::bem::lu_in_place(lu.as_mut())?;
    let mut x = b;
    let (n, nrhs) = (x.nrows(), x.ncols());
    let mut buf = MemBuffer::new(solve::solve_in_place_scratch::<usize, c64>(n, nrhs, Par::Seq));
    solve::solve_in_place(
        lu.as_ref(),
        lu.as_ref(),
        perm.as_ref(),
        x.as_mut(),
        Par::Seq,
        MemStack::new(&mut buf),
    );
    let finite = (0..nrhs).all(|f| x.col(f).iter().all(|z| z.re.is_finite() && z.im.is_finite()));
    finite.then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat disc of radius `a` in the plane `z = 0`, normal `+z`: `rings`
    /// rings of `6·rings` nodes about a centre node.
    fn flat_disc(a: f64, rings: usize) -> BoundaryMesh {
        let (v, t) = modal_mesh::disc_surface(a, 0.0, rings);
        BoundaryMesh::new(v, &t).unwrap()
    }

    /// `|∫ μ dS|` of a flat disc translating broadside at unit speed, over
    /// Lamb's `ωρ₀ (8/3) a³` (the jump of the potential across a disc of
    /// no thickness is `(4U/π)√(a² − r²)`, Lamb, *Hydrodynamics* §108).
    fn dipole_ratio(rings: usize) -> f64 {
        let (a, f) = (0.1, 100.0);
        let mesh = flat_disc(a, rings);
        let air = Air::default();
        let v = vec![c64::new(1.0, 0.0); mesh.len()];
        let jump = solve_screen(&mesh, air, f, &[v]).unwrap();
        let d: c64 = jump.panel_mean[0].iter().zip(&mesh.panels).map(|(m, p)| m * p.area).sum();
        d.norm() / (std::f64::consts::TAU * f * air.density_kg_m3 * 8.0 / 3.0 * a * a * a)
    }

    /// The closed forms against the polar form inside the triangle, and
    /// against the 7-point rule on 4⁶ leaves over it, beside it in its plane
    /// and on an edge's line.
    #[test]
    fn static_potentials_match_brute_force_quadrature() {
        let mesh =
            BoundaryMesh::new(vec![[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.3, 0.8, 0.2]], &[[0, 1, 2]]).unwrap();
        let s = Element::new(&mesh, 0);
        let mut leaves = vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]];
        for _ in 0..6 {
            leaves = leaves.iter().flat_map(|&t| quarters(t)).collect();
        }
        let inside = on_triangle([0.2, 0.5, 0.3], s.corners);
        let beside = on_triangle([1.4, -0.2, -0.2], s.corners);
        let on_line = on_triangle([1.5, -0.5, 0.0], s.corners);
        let over = [0, 1, 2].map(|c| inside[c] + 0.05 * s.normal[c]);
        // Inside, in the plane, the polar form is exact: R dθ = h ℓ ds / R along each edge.
        let (gx, gw) = crate::quadrature::gauss_legendre(64);
        let (mut polar0, mut polarv) = (0.0, [0.0; 3]);
        for e in 0..3 {
            let (a, b) = (s.corners[e], s.corners[(e + 1) % 3]);
            let edge = sub(b, a);
            let h = norm(cross(sub(a, inside), edge)) / norm(edge);
            for (t, w) in gx.iter().zip(&gw) {
                let y = [0, 1, 2].map(|c| a[c] + 0.5 * (t + 1.0) * edge[c]);
                let r = norm(sub(y, inside));
                let ds = 0.5 * w * h * norm(edge);
                polar0 += ds / r;
                for c in 0..3 {
                    polarv[c] += 0.5 * ds * (y[c] - inside[c]) / r;
                }
            }
        }
        let (i0, iv, _) = static_potentials(inside, &s);
        assert!((i0 - polar0).abs() < 1e-12 * polar0, "{i0} vs {polar0}");
        assert!(norm(sub(iv, polarv)) < 1e-12 * norm(polarv), "{iv:?} vs {polarv:?}");
        for x in [beside, on_line, over, [0.4, 0.3, 0.9]] {
            let (i0, iv, x0) = static_potentials(x, &s);
            let (mut want0, mut wantv) = (0.0, [0.0; 3]);
            for leaf in &leaves {
                for (b, wb) in TRIANGLE_7 {
                    let y = on_triangle(on_triangle(b, *leaf), s.corners);
                    let w = wb * s.area / leaves.len() as f64 / norm(sub(y, x));
                    want0 += w;
                    for c in 0..3 {
                        wantv[c] += w * (y[c] - x0[c]);
                    }
                }
            }
            assert!((i0 - want0).abs() < 1e-4 * want0, "{x:?}: {i0} vs {want0}");
            assert!(norm(sub(iv, wantv)) < 1e-4 * norm(wantv), "{x:?}: {iv:?} vs {wantv:?}");
        }
    }

    /// On a closed surface the jump's double layer is the exterior field
    /// (the interior Neumann field's double layer outside equals its single
    /// layer, which cancels the exterior one's): an oscillating sphere
    /// (`v_n = cos θ`) must give `ρ₀c |h₁(kr)/h₁'(ka)| cos θ` away from the
    /// interior Neumann eigenvalues (`j₁'(ka) = 0` at 2.08, 5.94).
    #[test]
    fn on_a_sphere_the_jump_radiates_the_oscillating_sphere() {
        use crate::special::{spherical_hankel, spherical_hankel_derivative};
        let a = 0.1;
        let mesh = crate::geometry::tests::icosphere(a, [0.0; 3], 3);
        let air = Air::default();
        for ka in [0.5, 1.5, 3.0] {
            let k = ka / a;
            let f = k * air.sound_speed_m_s / std::f64::consts::TAU;
            let v: Vec<c64> = mesh.panels.iter().map(|p| c64::new(p.normal[2], 0.0)).collect();
            let jump = solve_screen(&mesh, air, f, &[v]).unwrap();
            let field = crate::SurfaceField {
                frequency_hz: f,
                wavenumber: k,
                air,
                pressure: jump.panel_mean[0].clone(),
                normal_velocity: vec![c64::new(0.0, 0.0); mesh.len()],
            };
            let r = 3.0 * a;
            let want = air.impedance()
                * (spherical_hankel(1, k * r)[1] / spherical_hankel_derivative(1, ka)[1]).norm();
            for theta in [0.0f64, 0.7] {
                let got = field.pressure_at(&mesh, [r * theta.sin(), 0.0, r * theta.cos()]).unwrap().norm();
                let db = 20.0 * (got / (want * theta.cos())).log10();
                eprintln!("ka {ka} θ {theta}: {db:.3} dB");
                assert!(db.abs() < 0.3, "ka {ka} θ {theta}: {db:.3} dB");
            }
        }
    }

    #[test]
    fn a_translating_disc_has_lambs_dipole() {
        // Measured: 0.907, 0.960, 0.984 (the jump falls like √d at the rim,
        // which the linear elements take one ring at a time).
        let ratios: Vec<f64> = [4, 8, 16].iter().map(|&r| dipole_ratio(r)).collect();
        assert!((ratios[2] - 1.0).abs() < 0.02, "{ratios:?}");
        assert!(
            ratios.windows(2).all(|w| (w[1] - 1.0).abs() < 0.6 * (w[0] - 1.0).abs()),
            "not converging: {ratios:?}"
        );
    }
}
