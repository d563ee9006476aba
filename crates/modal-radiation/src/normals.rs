//! Smooth-surface normals at the nodes of a triangulated surface, fitted
//! to the local surface and never across a crease.
//!
//! **Sectors.** The triangles around a node `p` fall into smooth sectors:
//! two of them that share an edge at `p` are in one sector when their
//! normals at `p` (of the curved 6-node triangle, `∂x/∂ξ × ∂x/∂η`, or of
//! the flat triangle) differ by less than the crease angle. A bar's edge
//! node has two sectors, its corner three, a node of a smooth surface one.
//! Every (triangle, node) pair gets the normal of the node's sector that
//! holds the triangle.
//!
//! **Fit.** For node `p` and sector `S`, the neighbourhood `Q` is the nodes
//! of `S`'s triangles; for a mid-edge node of edge `ab`, of the sectors of
//! `a` and `b` that hold `S`'s triangles (a patch centred on the node). In
//! an orthonormal frame `(t₁, t₂, n)` at `p`, a neighbour `q` has local
//! coordinates `(u, v, w) = ((q−p)·t₁, (q−p)·t₂, (q−p)·n)`, and the surface
//! is taken as the height field through `p`
//!
//! ```text
//! w(u, v) = a u + b v + Σ_{2 ≤ i+j ≤ 3} c_ij uⁱ vʲ,
//! ```
//!
//! fitted to `Q` in weighted least squares (weights `e^{−r²/r̄²}`,
//! `r² = u² + v²`, `r̄²` its mean over `Q`; Householder QR). The normal is
//! `(n − a t₁ − b t₂) / √(1 + a² + b²)`. The frame starts at the sector's
//! area-weighted mean normal and is re-centred on the fitted normal
//! [`ITERATIONS`] times. The slope is exact for a cubic height field, so
//! its error is O(h³) in the patch size `h` (the quartic terms, through the
//! patch's asymmetry), against O(h²) for the mean of the triangles'
//! normals, whose error does not cancel on an irregular triangulation.
//! A patch with fewer than [`MIN_POINTS_PER_TERM`] points per cubic term
//! is fitted without the cubic terms (O(h²)); one too small even for that,
//! a rank-deficient system, or a fitted normal beyond the crease angle
//! from the mean keeps the mean normal. On a flat face the fit returns the
//! face's normal.
//!
//! Measured on the FEM sphere of `tests/radiation_cli.rs` (h = 15 mm): see
//! the tests below and docs/radiation.md, "Torsional sphere modes".

use crate::geometry::{cross, dot, norm, sub};

/// Re-centrings of the fit frame on the fitted normal.
pub const ITERATIONS: usize = 3;

/// Fewest neighbours per fitted coefficient; below it the sector keeps its
/// mean normal.
pub const MIN_POINTS_PER_TERM: f64 = 1.5;

/// Exponents `(i, j)` of the fitted terms `uⁱ vʲ`; the first two are the slope.
const TERMS: [(i32, i32); 9] = [(1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3)];

/// The first this many [`TERMS`] make the quadratic fit, for patches too
/// small for the cubic.
const QUADRATIC_TERMS: usize = 5;

/// Smooth-surface unit normals of a triangulated surface (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceNormals {
    /// Per triangle, the normal at each of its nodes (corners, then the
    /// mid-edge nodes of edges 01, 12, 20 for a quadratic surface; the last
    /// three are zero for a linear one), from the node's sector that holds
    /// the triangle.
    pub per_triangle: Vec<[[f64; 3]; 6]>,
    /// Per node, the normal of its first sector (zero for a node no
    /// triangle touches).
    pub per_node: Vec<[f64; 3]>,
}

/// The fitted normals of a surface of `triangles` (corner indices,
/// counter-clockwise seen from outside) over `positions`, with the mid-edge
/// nodes `edge_nodes` (edges 01, 12, 20) of a quadratic surface. Triangles
/// whose normal at a shared node differs by more than `crease_deg` are on
/// different sides of a crease there. Indices must be in range.
pub fn fit_normals(
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    edge_nodes: Option<&[[usize; 3]]>,
    crease_deg: f64,
) -> SurfaceNormals {
    let surface = Triangles::new(positions, triangles, edge_nodes);
    let cos_crease = crease_deg.to_radians().cos();
    let sectors = Sectors::new(&surface, cos_crease);
    let normals: Vec<[f64; 3]> = (0..sectors.members.len())
        .map(|s| {
            let mean = sectors.mean_normal(&surface, s);
            let patch = sectors.patch(&surface, s);
            fit_normal(positions, sectors.node[s], &patch, mean)
                .filter(|n| dot(*n, mean) >= cos_crease)
                .unwrap_or(mean)
        })
        .collect();
    let mut per_triangle = vec![[[0.0; 3]; 6]; triangles.len()];
    for (t, ids) in sectors.of.iter().enumerate() {
        for (k, &s) in ids.iter().enumerate().take(surface.nodes_per_triangle) {
            per_triangle[t][k] = normals[s];
        }
    }
    let mut per_node = vec![[0.0; 3]; positions.len()];
    for (s, &p) in sectors.node.iter().enumerate().rev() {
        per_node[p] = normals[s];
    }
    SurfaceNormals { per_triangle, per_node }
}

/// The triangles' nodes and their unnormalized normals at each node.
struct Triangles {
    /// Per triangle, its nodes (corners, then mid-edge nodes).
    nodes: Vec<[usize; 6]>,
    /// 3 (linear) or 6 (quadratic).
    nodes_per_triangle: usize,
    /// Per triangle and node, `∂x/∂ξ × ∂x/∂η` there (twice the area element).
    raw: Vec<[[f64; 3]; 6]>,
    /// Per node, the (triangle, local index) pairs that hold it, by triangle.
    incident: Vec<Vec<(usize, usize)>>,
}

impl Triangles {
    fn new(positions: &[[f64; 3]], triangles: &[[usize; 3]], edge_nodes: Option<&[[usize; 3]]>) -> Self {
        let nodes_per_triangle = if edge_nodes.is_some() { 6 } else { 3 };
        let nodes: Vec<[usize; 6]> = triangles
            .iter()
            .enumerate()
            .map(|(t, c)| match edge_nodes {
                Some(e) => [c[0], c[1], c[2], e[t][0], e[t][1], e[t][2]],
                None => [c[0], c[1], c[2], c[0], c[1], c[2]],
            })
            .collect();
        let raw = nodes
            .iter()
            .map(|n| {
                let x = n.map(|i| positions[i]);
                if edge_nodes.is_some() {
                    REFERENCE_NODES.map(|(xi, eta)| modal_mesh::quadratic_triangle_normal(&x, xi, eta))
                } else {
                    [cross(sub(x[1], x[0]), sub(x[2], x[0])); 6]
                }
            })
            .collect();
        let mut incident = vec![Vec::new(); positions.len()];
        for (t, n) in nodes.iter().enumerate() {
            for (k, &p) in n.iter().enumerate().take(nodes_per_triangle) {
                incident[p].push((t, k));
            }
        }
        Triangles { nodes, nodes_per_triangle, raw, incident }
    }

    /// The corners of triangle `t`.
    fn corners(&self, t: usize) -> &[usize] {
        &self.nodes[t][..3]
    }
}

/// Reference coordinates `(ξ, η)` of the six nodes of a quadratic triangle.
const REFERENCE_NODES: [(f64, f64); 6] =
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)];

/// The smooth sectors around every node.
struct Sectors {
    /// Per sector, its node.
    node: Vec<usize>,
    /// Per sector, its (triangle, local index) pairs.
    members: Vec<Vec<(usize, usize)>>,
    /// Per triangle and local node, the sector.
    of: Vec<[usize; 6]>,
}

impl Sectors {
    fn new(surface: &Triangles, cos_crease: f64) -> Sectors {
        let mut sectors =
            Sectors { node: Vec::new(), members: Vec::new(), of: vec![[0; 6]; surface.nodes.len()] };
        for (p, around) in surface.incident.iter().enumerate() {
            // Union-find over the triangles around p.
            let mut root: Vec<usize> = (0..around.len()).collect();
            fn find(root: &mut [usize], mut i: usize) -> usize {
                while root[i] != i {
                    root[i] = root[root[i]];
                    i = root[i];
                }
                i
            }
            for i in 0..around.len() {
                for j in i + 1..around.len() {
                    let ((ti, ki), (tj, kj)) = (around[i], around[j]);
                    let shared =
                        surface.corners(ti).iter().filter(|c| surface.corners(tj).contains(c)).count();
                    // An edge at p: two shared corners (p a corner and one
                    // more, or the edge whose mid-node p is).
                    let (ni, nj) = (surface.raw[ti][ki], surface.raw[tj][kj]);
                    let smooth = dot(ni, nj) >= cos_crease * norm(ni) * norm(nj);
                    if shared >= 2 && smooth {
                        let (ri, rj) = (find(&mut root, i), find(&mut root, j));
                        root[ri.max(rj)] = ri.min(rj);
                    }
                }
            }
            let mut ids = vec![usize::MAX; around.len()];
            for (i, &(t, k)) in around.iter().enumerate() {
                let r = find(&mut root, i);
                if ids[r] == usize::MAX {
                    ids[r] = sectors.node.len();
                    sectors.node.push(p);
                    sectors.members.push(Vec::new());
                }
                sectors.members[ids[r]].push((t, k));
                sectors.of[t][k] = ids[r];
            }
        }
        sectors
    }

    /// Unit area-weighted mean normal of sector `s` at its node.
    fn mean_normal(&self, surface: &Triangles, s: usize) -> [f64; 3] {
        let mut n = [0.0; 3];
        for &(t, k) in &self.members[s] {
            n = [0, 1, 2].map(|q| n[q] + surface.raw[t][k][q]);
        }
        let len = norm(n);
        n.map(|x| x / len)
    }

    /// The nodes the fit of sector `s` uses (without its own node), sorted.
    fn patch(&self, surface: &Triangles, s: usize) -> Vec<usize> {
        let p = self.node[s];
        let mut triangles: Vec<usize> = Vec::new();
        for &(t, k) in &self.members[s] {
            if k < 3 {
                triangles.push(t);
            } else {
                // Mid-edge node of the edge (k−3, k−2 mod 3): both ends' sectors holding t.
                for c in [k - 3, (k - 2) % 3] {
                    triangles.extend(self.members[self.of[t][c]].iter().map(|&(u, _)| u));
                }
            }
        }
        let mut nodes: Vec<usize> = triangles
            .iter()
            .flat_map(|&t| surface.nodes[t][..surface.nodes_per_triangle].iter().copied())
            .filter(|&q| q != p)
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes
    }
}

/// The fitted unit normal at node `p` from its neighbours `patch`, starting
/// from `start`: the cubic fit where the patch allows, else the quadratic;
/// `None` when neither is determined.
fn fit_normal(positions: &[[f64; 3]], p: usize, patch: &[usize], start: [f64; 3]) -> Option<[f64; 3]> {
    [TERMS.len(), QUADRATIC_TERMS]
        .into_iter()
        .filter(|&terms| patch.len() as f64 >= MIN_POINTS_PER_TERM * terms as f64)
        .find_map(|terms| fit_with(positions, p, patch, start, &TERMS[..terms]))
}

/// The normal of the height field of `terms` through node `p` fitted to `patch`.
fn fit_with(
    positions: &[[f64; 3]],
    p: usize,
    patch: &[usize],
    start: [f64; 3],
    terms: &[(i32, i32)],
) -> Option<[f64; 3]> {
    let cols = terms.len();
    let mut n = start;
    let mut design = vec![0.0; patch.len() * cols];
    let mut rhs = vec![0.0; patch.len()];
    for _ in 0..ITERATIONS {
        let (t1, t2) = tangents(n);
        let local: Vec<[f64; 3]> = patch
            .iter()
            .map(|&q| {
                let d = sub(positions[q], positions[p]);
                [dot(d, t1), dot(d, t2), dot(d, n)]
            })
            .collect();
        // Lengths in units of the patch's RMS radius (conditioning); the
        // slope is dimensionless either way.
        let r2_mean = local.iter().map(|l| l[0] * l[0] + l[1] * l[1]).sum::<f64>() / local.len() as f64;
        let scale = r2_mean.sqrt();
        if scale.is_nan() || scale <= 0.0 {
            return None;
        }
        for (row, l) in local.iter().enumerate() {
            let (u, v, w) = (l[0] / scale, l[1] / scale, l[2] / scale);
            let weight = (-(u * u + v * v)).exp();
            for (col, &(i, j)) in terms.iter().enumerate() {
                design[row * cols + col] = weight * u.powi(i) * v.powi(j);
            }
            rhs[row] = weight * w;
        }
        let c = least_squares(&mut design, &mut rhs, patch.len(), cols)?;
        let tilted = [0, 1, 2].map(|q| n[q] - c[0] * t1[q] - c[1] * t2[q]);
        let len = norm(tilted);
        n = tilted.map(|x| x / len);
    }
    Some(n)
}

/// Two unit tangents completing `n` to a right-handed frame.
fn tangents(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let axis = if n[0].abs() < 0.6 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let t1 = cross(n, axis);
    let t1 = t1.map(|x| x / norm(t1));
    (t1, cross(n, t1))
}

/// Least-squares solution of the `rows × cols` system `a x = b` (row-major
/// `a`, overwritten) by Householder QR; `None` when a pivot is below 1e-8
/// of the largest (rank-deficient patch).
fn least_squares(a: &mut [f64], b: &mut [f64], rows: usize, cols: usize) -> Option<Vec<f64>> {
    let mut diag = vec![0.0; cols];
    for j in 0..cols {
        let alpha = (j..rows).map(|i| a[i * cols + j].powi(2)).sum::<f64>().sqrt();
        if alpha == 0.0 {
            return None;
        }
        let akk = a[j * cols + j];
        let beta = if akk > 0.0 { -alpha } else { alpha };
        // v = x − beta e₁, stored in place; H = I − 2 v vᵀ / vᵀv.
        a[j * cols + j] = akk - beta;
        let vtv = (j..rows).map(|i| a[i * cols + j].powi(2)).sum::<f64>();
        for k in j + 1..cols {
            let s = (j..rows).map(|i| a[i * cols + j] * a[i * cols + k]).sum::<f64>() * 2.0 / vtv;
            for i in j..rows {
                a[i * cols + k] -= s * a[i * cols + j];
            }
        }
        let s = (j..rows).map(|i| a[i * cols + j] * b[i]).sum::<f64>() * 2.0 / vtv;
        for i in j..rows {
            b[i] -= s * a[i * cols + j];
        }
        diag[j] = beta;
    }
    let largest = diag.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    if diag.iter().any(|d| d.abs() < 1e-8 * largest) {
        return None;
    }
    let mut x = vec![0.0; cols];
    for j in (0..cols).rev() {
        let s = b[j] - (j + 1..cols).map(|k| a[j * cols + k] * x[k]).sum::<f64>();
        x[j] = s / diag[j];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use modal_mesh::generate::{generate, Shape};
    use modal_mesh::{boundary_surface, Surface};

    const CREASE: f64 = 25.0;

    fn surface(shape: Shape, h: f64, order: u8) -> Surface {
        boundary_surface(&generate(&shape, h, order).unwrap())
    }

    fn fitted(s: &Surface) -> SurfaceNormals {
        fit_normals(&s.positions, &s.triangles, s.triangle_edge_nodes.as_deref(), CREASE)
    }

    /// Per (triangle, local node): node index, fitted normal, and the mean
    /// of the curved triangles' normals at the node over all its triangles
    /// (the previous smooth normal).
    fn pairs(s: &Surface, n: &SurfaceNormals) -> Vec<(usize, [f64; 3], [f64; 3])> {
        let surf = Triangles::new(&s.positions, &s.triangles, s.triangle_edge_nodes.as_deref());
        let mut mean = vec![[0.0; 3]; s.positions.len()];
        for (raw, nodes) in surf.raw.iter().zip(&surf.nodes) {
            for (r, &p) in raw.iter().zip(nodes).take(surf.nodes_per_triangle) {
                mean[p] = [0, 1, 2].map(|q| mean[p][q] + r[q]);
            }
        }
        let mut out = Vec::new();
        for (t, nodes) in surf.nodes.iter().enumerate() {
            for k in 0..surf.nodes_per_triangle {
                let m = mean[nodes[k]];
                out.push((nodes[k], n.per_triangle[t][k], m.map(|x| x / norm(m))));
            }
        }
        out
    }

    fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
        norm(cross(a, b)).atan2(dot(a, b)).to_degrees()
    }

    fn mean_max(errors: &[f64]) -> (f64, f64) {
        (errors.iter().sum::<f64>() / errors.len() as f64, errors.iter().fold(0.0, |m: f64, &e| m.max(e)))
    }

    /// The FEM sphere's nodes lie on the sphere, so the exact normal is
    /// radial. The fit must beat the mean of the triangles' normals by far.
    #[test]
    fn fitted_normals_of_the_fem_sphere_are_radial_to_a_small_fraction_of_the_mean_normals_error() {
        let s = surface(Shape::Sphere { radius: 0.05 }, 0.015, 2);
        let n = fitted(&s);
        let (mut fit, mut mean) = (Vec::new(), Vec::new());
        for (p, f, m) in pairs(&s, &n) {
            let radial = s.positions[p].map(|x| x / norm(s.positions[p]));
            fit.push(angle_deg(f, radial));
            mean.push(angle_deg(m, radial));
        }
        let (fit, mean) = (mean_max(&fit), mean_max(&mean));
        eprintln!("sphere h = 15 mm, error vs radial [deg]: fitted mean {:.4} max {:.4}; mean normals mean {:.4} max {:.4}", fit.0, fit.1, mean.0, mean.1);
        assert!(fit.0 < 0.1 * mean.0 && fit.1 < 0.1 * mean.1, "fitted {fit:?}, mean normals {mean:?}");
    }

    /// An ellipsoid (the sphere's nodes scaled, so they lie on it exactly)
    /// has no symmetry to help the fit: its exact normal is ∝ (x/a², y/b², z/c²).
    #[test]
    fn fitted_normals_of_an_ellipsoid_beat_the_mean_normals() {
        let mut s = surface(Shape::Sphere { radius: 1.0 }, 0.3, 2);
        let axes = [0.06, 0.04, 0.025];
        for x in &mut s.positions {
            *x = [0, 1, 2].map(|q| x[q] * axes[q]);
        }
        let n = fitted(&s);
        let (mut fit, mut mean) = (Vec::new(), Vec::new());
        for (p, f, m) in pairs(&s, &n) {
            let x = s.positions[p];
            let g = [0, 1, 2].map(|q| x[q] / (axes[q] * axes[q]));
            let exact = g.map(|c| c / norm(g));
            fit.push(angle_deg(f, exact));
            mean.push(angle_deg(m, exact));
        }
        let (fit, mean) = (mean_max(&fit), mean_max(&mean));
        eprintln!(
            "ellipsoid, error vs exact [deg]: fitted mean {:.4} max {:.4}; mean normals mean {:.4} max {:.4}",
            fit.0, fit.1, mean.0, mean.1
        );
        assert!(fit.0 < 0.5 * mean.0 && fit.1 < mean.1, "fitted {fit:?}, mean normals {mean:?}");
    }

    /// Flat faces and creases: every node of a box, its edges and corners
    /// included, gets exactly its face's normal on each face.
    #[test]
    fn every_node_of_a_box_keeps_its_faces_normal_across_edges_and_corners() {
        for order in [1, 2] {
            let s = surface(Shape::Box { size: [0.2, 0.04, 0.03] }, 0.01, order);
            let n = fitted(&s);
            for (t, tri) in s.triangles.iter().enumerate() {
                let [a, b, c] = tri.map(|i| s.positions[i]);
                let face = cross(sub(b, a), sub(c, a));
                let face = face.map(|x| x / norm(face));
                for k in 0..if order == 2 { 6 } else { 3 } {
                    let err = angle_deg(n.per_triangle[t][k], face);
                    assert!(err < 1e-9, "order {order}, triangle {t}, node {k}: {err:e} deg off its face");
                }
            }
        }
    }

    /// A cylinder's rim is a crease between a flat cap and the curved side:
    /// cap sectors keep ±z exactly, side sectors are radial, never tilted
    /// towards the cap.
    #[test]
    fn cylinder_rim_nodes_get_the_cap_normal_on_the_cap_and_a_radial_one_on_the_side() {
        let (radius, length) = (0.04, 0.1);
        let s = surface(Shape::Cylinder { radius, length }, 0.01, 2);
        let n = fitted(&s);
        let nodes = s.triangle_edge_nodes.as_ref().unwrap();
        let mut side = Vec::new();
        for (t, tri) in s.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| s.positions[i]);
            let face = cross(sub(b, a), sub(c, a));
            let on_cap = face[2].abs() > 0.99 * norm(face);
            for k in 0..6 {
                let p = if k < 3 { tri[k] } else { nodes[t][k - 3] };
                let x = s.positions[p];
                let normal = n.per_triangle[t][k];
                if on_cap {
                    let want = [0.0, 0.0, face[2].signum()];
                    assert!(angle_deg(normal, want) < 1e-9, "cap triangle {t} node {k}: {normal:?}");
                } else {
                    let r = x[0].hypot(x[1]);
                    side.push(angle_deg(normal, [x[0] / r, x[1] / r, 0.0]));
                }
            }
        }
        let (mean, max) = mean_max(&side);
        eprintln!("cylinder side, error vs radial [deg]: mean {mean:.4} max {max:.4}");
        assert!(max < 0.5, "side normals off radial by up to {max:.3} deg");
    }

    #[test]
    fn least_squares_recovers_an_exact_fit_and_refuses_a_rank_deficient_system() {
        // 4 × 2: rows (1, i), b = 2 + 3 i.
        let mut a: Vec<f64> = (0..4).flat_map(|i| [1.0, i as f64]).collect();
        let mut b: Vec<f64> = (0..4).map(|i| 2.0 + 3.0 * i as f64).collect();
        let x = least_squares(&mut a, &mut b, 4, 2).unwrap();
        assert!((x[0] - 2.0).abs() < 1e-12 && (x[1] - 3.0).abs() < 1e-12, "{x:?}");
        let mut a = vec![1.0, 2.0, 2.0, 4.0, 3.0, 6.0];
        let mut b = vec![1.0, 2.0, 3.0];
        assert!(least_squares(&mut a, &mut b, 3, 2).is_none());
    }
}
