//! The near field of a panel mesh: the (collocation point, panel) pairs
//! too close for a fixed quadrature rule, with the geometry-only part of
//! their integrals, computed once per mesh and reused at every frequency.
//!
//! A collocation point is a panel centroid `c_t` with that panel's normal.
//! Panel `j ≠ t` is *near* it when `|c_j − c_t| < ρ h_j`, `ρ` =
//! [`crate::bem::MID_POINT_RATIO`], `h_j` the panel's diameter: there the
//! kernels vary too fast over the panel for the 3-point rule, and the
//! adaptive rule subdivides it (neighbours, both faces of a thin wall).
//! Each kernel splits into static coefficients and a bounded remainder
//! (`∫ K = K₀ + k² K₂ + ∫ R_k`, [`crate::kernels`]): `K₀` and `K₂` are
//! integrated here once by the adaptive rule; each frequency adds only
//! `∫ R_k` by the 7-point rule ([`crate::kernels::Kernels::near`]).
//!
//! Storage: per point, its near panels in ascending order with their seven
//! coefficients (compressed rows): 60 bytes per pair. Rows are built in
//! parallel, each by one thread: bit-identical for any thread count.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::bem::MID_POINT_RATIO;
use crate::geometry::{dot, sub, BoundaryMesh};
use crate::kernels::StaticIntegrals;

/// Near pairs of a mesh and their static integrals (module doc).
#[derive(Clone, Debug, Default)]
pub struct NearField {
    start: Vec<usize>,
    panel: Vec<u32>,
    integrals: Vec<StaticIntegrals>,
}

impl NearField {
    /// Finds every near pair of `mesh` and integrates its static part.
    pub fn new(mesh: &BoundaryMesh) -> NearField {
        let grid = Grid::new(mesh);
        let rows: Vec<(Vec<u32>, Vec<StaticIntegrals>)> = (0..mesh.len())
            .into_par_iter()
            .map(|t| {
                let pt = &mesh.panels[t];
                let near = grid.near(mesh, t);
                let ints = near
                    .iter()
                    .map(|&j| StaticIntegrals::over(mesh, &mesh.panels[j as usize], pt.centroid, pt.normal))
                    .collect();
                (near, ints)
            })
            .collect();
        let mut out = NearField {
            start: Vec::with_capacity(mesh.len() + 1),
            panel: Vec::with_capacity(rows.iter().map(|r| r.0.len()).sum()),
            integrals: Vec::new(),
        };
        out.integrals.reserve(out.panel.capacity());
        for (near, ints) in rows {
            out.start.push(out.panel.len());
            out.panel.extend(near);
            out.integrals.extend(ints);
        }
        out.start.push(out.panel.len());
        out
    }

    /// The near panels of collocation point `t` (ascending) and their
    /// static integrals.
    pub fn row(&self, t: usize) -> (&[u32], &[StaticIntegrals]) {
        let r = self.start[t]..self.start[t + 1];
        (&self.panel[r.clone()], &self.integrals[r])
    }

    /// Number of near pairs.
    pub fn pairs(&self) -> usize {
        self.panel.len()
    }

    /// Memory held [bytes].
    pub fn bytes(&self) -> usize {
        self.start.len() * std::mem::size_of::<usize>()
            + self.panel.len() * std::mem::size_of::<u32>()
            + self.integrals.len() * std::mem::size_of::<StaticIntegrals>()
    }
}

/// Panel centroids bucketed in cubes of side `ρ·h_max`: every panel near a
/// point lies in the 27 cubes around it.
struct Grid {
    side: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl Grid {
    fn new(mesh: &BoundaryMesh) -> Grid {
        let h = mesh.panels.iter().map(|p| p.diameter).fold(0.0, f64::max);
        let side = MID_POINT_RATIO * h;
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (j, p) in mesh.panels.iter().enumerate() {
            cells.entry(Self::cell(side, p.centroid)).or_default().push(j as u32);
        }
        Grid { side, cells }
    }

    fn cell(side: f64, x: [f64; 3]) -> [i64; 3] {
        x.map(|c| (c / side).floor() as i64)
    }

    /// Panels near point `t`, ascending.
    fn near(&self, mesh: &BoundaryMesh, t: usize) -> Vec<u32> {
        let c = mesh.panels[t].centroid;
        let [a, b, e] = Self::cell(self.side, c);
        let mut out = Vec::new();
        for i in a - 1..=a + 1 {
            for j in b - 1..=b + 1 {
                for k in e - 1..=e + 1 {
                    for &p in self.cells.get(&[i, j, k]).map_or(&[][..], |v| v.as_slice()) {
                        let q = &mesh.panels[p as usize];
                        let d = sub(q.centroid, c);
                        let reach = MID_POINT_RATIO * q.diameter;
                        if p as usize != t && dot(d, d) < reach * reach {
                            out.push(p);
                        }
                    }
                }
            }
        }
        out.sort_unstable();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_pairs_are_exactly_those_within_the_ratio() {
        // A thin slab: both faces within reach of each other.
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.1, 0.004], 3);
        let near = NearField::new(&mesh);
        let mut pairs = 0;
        for t in 0..mesh.len() {
            let (panels, ints) = near.row(t);
            assert_eq!(panels.len(), ints.len());
            assert!(panels.windows(2).all(|w| w[0] < w[1]));
            let c = mesh.panels[t].centroid;
            for (j, q) in mesh.panels.iter().enumerate() {
                let d = sub(q.centroid, c);
                let want = j != t && dot(d, d).sqrt() < MID_POINT_RATIO * q.diameter;
                assert_eq!(panels.binary_search(&(j as u32)).is_ok(), want, "pair ({t}, {j})");
                pairs += usize::from(want);
            }
        }
        assert_eq!(near.pairs(), pairs);
        assert!(pairs > 4 * mesh.len(), "{pairs} pairs");
    }
}
