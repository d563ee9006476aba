//! The normal velocity of a panel: the exact mean, over the panel, of the
//! bank triangle's interpolant of `φ·n`.
//!
//! A panel lies on one bank triangle (its corner triangle, one of the four
//! flat panels a quadratic triangle is split into, or a quarter of one of
//! those). With barycentric coordinates `λ` on that triangle,
//! `v_n(λ) = Σ_j N_j(λ) (φ_j · n_j)` (`N_j` the linear or 6-node quadratic
//! shape functions, `n_j` the normal the panel takes at node `j`), and the
//! panel's constant velocity is its mean
//!
//! `v̄ = (1/A) ∫_panel v_n dA = (1/3) Σ_{m ∈ edge midpoints} v_n(λ_m)`,
//!
//! the three-point edge-midpoint rule, exact for quadratics on a flat
//! panel. So the panels of a triangle carry exactly the triangle's volume
//! flux `∫ v_n dA` (a quadratic triangle's corner shape functions integrate
//! to zero: the flux is `(A/3) Σ` of its mid-edge values). The former rule,
//! the mean of the panel's corner values, did not: on a free thin disc
//! (20 cm × 2 mm) it gave mode 3's net broadside flux `Σ v_n n_z A` as
//! 1.36× the interpolant's, and along the axis of such an `n`-diameter
//! mode that small flux is all that is heard (BENCHMARKS.md, "The thin
//! disc again").

use faer::c64;
use modal_bank::ModeBank;

use crate::error::RadiationError;
use crate::geometry::{dot, BoundaryMesh};
use crate::modes::{corner_normals_of, smooth_or_panel, split_of, triangle_node};
use crate::normals::SurfaceNormals;

/// Barycentric coordinates of a triangle's nodes: corners 0–2, then the
/// mid-edge nodes of edges 01, 12, 20.
pub(crate) const NODE_BARYCENTRIC: [[f64; 3]; 6] =
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]];

/// Where a panel's normal velocity comes from: its bank triangle's nodes
/// and where on that triangle the panel lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PanelSource {
    /// The triangle's nodes (corners, then for a quadratic triangle the
    /// mid-edge nodes of edges 01, 12, 20), each with the unit normal this
    /// panel takes there.
    pub nodes: [(usize, [f64; 3]); 6],
    /// Whether the triangle is quadratic (6 nodes) or linear (the first 3).
    pub quadratic: bool,
    /// The panel's corners in the triangle's barycentric coordinates.
    pub corners: [[f64; 3]; 3],
}

impl PanelSource {
    /// A panel that is its whole (linear) triangle, or any panel whose
    /// velocity is linear between its corner nodes.
    pub fn linear(nodes: [(usize, [f64; 3]); 3]) -> PanelSource {
        let mut all = [(0, [0.0; 3]); 6];
        all[..3].copy_from_slice(&nodes);
        PanelSource { nodes: all, quadratic: false, corners: [0, 1, 2].map(|k| NODE_BARYCENTRIC[k]) }
    }

    /// Weight of each of [`PanelSource::nodes`] in the panel's mean
    /// velocity (module doc): `(1/3) Σ_m N_j(λ_m)`. They sum to 1.
    pub fn weights(&self) -> [f64; 6] {
        let mut w = [0.0; 6];
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let midpoint = [0, 1, 2].map(|k| 0.5 * (self.corners[a][k] + self.corners[b][k]));
            let n = shape_functions(midpoint, self.quadratic);
            for (w, n) in w.iter_mut().zip(n) {
                *w += n / 3.0;
            }
        }
        debug_assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        w
    }

    /// The four panels of this one split at its edge midpoints, in the
    /// order `[a, ab, ca]`, `[ab, b, bc]`, `[ca, bc, c]`, `[ab, bc, ca]`
    /// (as [`crate::geometry::BoundaryMesh::quadratic`] splits a triangle).
    /// Each keeps the triangle and its normals: a flat panel's quarters lie
    /// in its plane.
    pub fn quarters(&self) -> [PanelSource; 4] {
        let [a, b, c] = self.corners;
        let mid = |p: [f64; 3], q: [f64; 3]| [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]));
        let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
        [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]].map(|corners| PanelSource { corners, ..*self })
    }
}

/// Where each panel of `mesh` takes its velocity from: on the bank's
/// [`crate::modes::boundary_mesh`], its place on its bank triangle, each of
/// the triangle's nodes with its smooth normal where that is within
/// [`crate::modes::CREASE_ANGLE_DEG`] of the panel's; on any other panel
/// mesh over the bank's nodes, its corners with their
/// [`crate::modes::corner_normals`], the velocity linear between them.
pub(crate) fn panel_sources(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    smooth: &SurfaceNormals,
) -> Vec<PanelSource> {
    let Some(split) = split_of(bank, mesh) else {
        let normals = corner_normals_of(bank, mesh, smooth);
        return mesh
            .panels
            .iter()
            .zip(normals)
            .map(|(p, n)| PanelSource::linear([0, 1, 2].map(|k| (p.corners[k], n[k]))))
            .collect();
    };
    let quadratic = bank.surface.triangle_edge_nodes.is_some();
    mesh.panels
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let t = i / split.len();
            let source = triangle_source(bank, t, &smooth.per_triangle[t], p.normal, quadratic);
            PanelSource { corners: split[i % split.len()].map(|k| NODE_BARYCENTRIC[k]), ..source }
        })
        .collect()
}

/// Bank triangle `t` as a whole panel with normal `panel_normal`: its
/// nodes with the smooth normals `smooth` (per local node) where they are
/// within [`crate::modes::CREASE_ANGLE_DEG`] of the panel's.
pub(crate) fn triangle_source(
    bank: &ModeBank,
    t: usize,
    smooth: &[[f64; 3]; 6],
    panel_normal: [f64; 3],
    quadratic: bool,
) -> PanelSource {
    let count = if quadratic { 6 } else { 3 };
    let mut nodes = [(0, [0.0; 3]); 6];
    for (k, node) in nodes.iter_mut().enumerate().take(count) {
        *node = (triangle_node(bank, t, k), smooth_or_panel(smooth[k], panel_normal));
    }
    PanelSource { nodes, quadratic, corners: [0, 1, 2].map(|k| NODE_BARYCENTRIC[k]) }
}

/// Mode `mode`'s normal velocity on panels with `sources` and their
/// [`PanelSource::weights`] `weights`.
pub(crate) fn velocity_of(
    bank: &ModeBank,
    sources: &[PanelSource],
    weights: &[[f64; 6]],
    mode: usize,
) -> Result<Vec<c64>, RadiationError> {
    if mode >= bank.mode_count() {
        return Err(RadiationError::NoSuchMode { mode, count: bank.mode_count() });
    }
    Ok(sources
        .iter()
        .zip(weights)
        .map(|(source, weights)| {
            let count = if source.quadratic { 6 } else { 3 };
            let v: f64 = source.nodes[..count]
                .iter()
                .zip(weights)
                .map(|(&(node, n), w)| {
                    let s = bank.shape_at(mode, node);
                    w * dot([s[0] as f64, s[1] as f64, s[2] as f64], n)
                })
                .sum();
            c64::new(v, 0.0)
        })
        .collect())
}

/// The linear (corner) or 6-node quadratic shape functions at barycentric
/// `l` (unused entries 0).
fn shape_functions(l: [f64; 3], quadratic: bool) -> [f64; 6] {
    if quadratic {
        [
            l[0] * (2.0 * l[0] - 1.0),
            l[1] * (2.0 * l[1] - 1.0),
            l[2] * (2.0 * l[2] - 1.0),
            4.0 * l[0] * l[1],
            4.0 * l[1] * l[2],
            4.0 * l[2] * l[0],
        ]
    } else {
        [l[0], l[1], l[2], 0.0, 0.0, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quadratic polynomial on a flat triangle, as the 6 nodal values of
    /// its interpolant (which it equals).
    fn field(l: [f64; 3]) -> f64 {
        0.3 + 2.0 * l[0] - 1.5 * l[1] + 4.0 * l[0] * l[1] - 3.0 * l[2] * l[2] + 0.7 * l[1] * l[1]
    }

    /// The mean of `field` over the sub-triangle `corners` by a 64×64
    /// midpoint rule in its own coordinates.
    fn brute_mean(corners: [[f64; 3]; 3]) -> f64 {
        let n = 64;
        let (mut sum, mut count) = (0.0, 0.0);
        for i in 0..n {
            for j in 0..n - i {
                // Both triangles of the grid cell (i, j) by their centroids.
                let cells = [
                    [(i as f64 + 1.0 / 3.0), (j as f64 + 1.0 / 3.0)],
                    [(i as f64 + 2.0 / 3.0), (j as f64 + 2.0 / 3.0)],
                ];
                for (ci, [s, t]) in cells.into_iter().enumerate() {
                    if ci == 1 && i + j + 1 >= n {
                        continue;
                    }
                    let (s, t) = (s / n as f64, t / n as f64);
                    let l = [0, 1, 2]
                        .map(|k| (1.0 - s - t) * corners[0][k] + s * corners[1][k] + t * corners[2][k]);
                    sum += field(l);
                    count += 1.0;
                }
            }
        }
        sum / count
    }

    fn mean_by_weights(source: &PanelSource) -> f64 {
        let values = NODE_BARYCENTRIC.map(field);
        source.weights().iter().zip(values).map(|(w, v)| w * v).sum()
    }

    /// Each of the four split panels, and each quarter of those, gets the
    /// exact mean of a quadratic field (against a brute-force rule), and the
    /// four panels' area-weighted sum is the triangle's exact integral: the
    /// mid-edge values' mean, corners weighted 0.
    #[test]
    fn split_panels_carry_the_exact_mean_of_a_quadratic_field() {
        let whole = PanelSource { quadratic: true, ..PanelSource::linear([(0, [0.0, 0.0, 1.0]); 3]) };
        let values = NODE_BARYCENTRIC.map(field);
        let exact_mean = (values[3] + values[4] + values[5]) / 3.0;
        assert!((mean_by_weights(&whole) - exact_mean).abs() < 1e-14);
        assert!((brute_mean(whole.corners) - exact_mean).abs() < 1e-3);
        let quarters = whole.quarters();
        let sum: f64 = quarters.iter().map(|q| 0.25 * mean_by_weights(q)).sum();
        assert!((sum - exact_mean).abs() < 1e-14, "{sum} vs {exact_mean}");
        for q in quarters.iter().flat_map(|q| q.quarters().into_iter().chain([*q])) {
            let (ours, brute) = (mean_by_weights(&q), brute_mean(q.corners));
            assert!((ours - brute).abs() < 1e-3 * brute.abs().max(1.0), "{ours} vs {brute}");
        }
        // The former rule (the mean of each panel's corner values) misses
        // the flux of this field: the check above can fail.
        let corner_rule: f64 =
            quarters.iter().map(|q| 0.25 * q.corners.iter().map(|&c| field(c)).sum::<f64>() / 3.0).sum();
        assert!((corner_rule - exact_mean).abs() > 1e-2);
    }

    /// On a linear triangle every panel's weights are its corners' mean.
    #[test]
    fn a_linear_panel_is_the_mean_of_its_corners() {
        let whole = PanelSource::linear([(4, [1.0, 0.0, 0.0]), (9, [1.0, 0.0, 0.0]), (2, [1.0, 0.0, 0.0])]);
        let w = whole.weights();
        for (k, w) in w.iter().enumerate() {
            let expected = if k < 3 { 1.0 / 3.0 } else { 0.0 };
            assert!((w - expected).abs() < 1e-15);
        }
        let [_, _, _, centre] = whole.quarters();
        let lin = |l: [f64; 3]| 2.0 * l[0] - l[1] + 0.5 * l[2];
        let by_weights: f64 =
            centre.weights()[..3].iter().zip(NODE_BARYCENTRIC).map(|(w, l)| w * lin(l)).sum();
        let by_corners: f64 = centre.corners.iter().map(|&c| lin(c)).sum::<f64>() / 3.0;
        assert!((by_weights - by_corners).abs() < 1e-15);
    }
}
