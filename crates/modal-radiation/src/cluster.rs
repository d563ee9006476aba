//! Wavelength-driven coarsening of the pressure unknowns: clusters of
//! panels that share one pressure value.
//!
//! The surface pressure of a mode varies on the scale of the shorter of
//! the acoustic wavelength `2π/k` and the mode's own surface wavelength
//! `2π/k_s` (subsonic bending waves drag a near field of their own
//! wavelength), not on the scale of the FEM mesh. So the solve keeps every
//! panel for the geometry and for the normal velocity (nothing of the
//! mode's cancellation is averaged away) but represents the pressure as
//! piecewise constant on clusters of diameter about `κ / max(k, k_s)`:
//!
//! - Clusters grow breadth-first over shared edges from a seed panel,
//!   taking unassigned panels whose centroid lies within half the target
//!   diameter of the seed's and whose normal is within
//!   [`MAX_NORMAL_ANGLE_DEG`] of the seed's (so a cluster never wraps a
//!   bar's edge or the rim of a thin wall). Seeds are taken in
//!   breadth-first order of the whole surface, so clusters tile it front by
//!   front. Deterministic: no hashing order, no threads.
//! - A cluster's collocation point is the centroid of its member panel
//!   nearest to the cluster's area-weighted centroid.
//!
//! The surface wavenumber of a velocity field `v` on the panels is the
//! discrete Rayleigh quotient `k_s² = 2 Σ_i A_i ⟨|v_i − v_j|²/|c_i − c_j|²⟩_j
//! / Σ_i A_i |v_i|²` over edge neighbours `j` on the same smooth patch (the
//! mean of `(∇v·ê)²` over edge directions is `|∇v|²/2`; a plane wave
//! `cos(k_s x)` gives `k_s`).

use std::collections::VecDeque;

use faer::c64;

use crate::geometry::{dot, norm, sub, BoundaryMesh};

/// Largest angle between a cluster's seed normal and a member's normal.
pub const MAX_NORMAL_ANGLE_DEG: f64 = 25.0;

/// A partition of the panels into clusters sharing one pressure unknown.
#[derive(Clone, Debug, PartialEq)]
pub struct Clusters {
    /// Cluster of each panel.
    pub of_panel: Vec<usize>,
    /// Per cluster, the panel whose centroid is its collocation point.
    pub collocation: Vec<usize>,
}

impl Clusters {
    /// Every panel its own cluster (the plain panel solve).
    pub fn identity(panels: usize) -> Clusters {
        Clusters { of_panel: (0..panels).collect(), collocation: (0..panels).collect() }
    }

    /// Number of clusters (unknowns of the solve).
    pub fn len(&self) -> usize {
        self.collocation.len()
    }

    /// True when there is no cluster.
    pub fn is_empty(&self) -> bool {
        self.collocation.is_empty()
    }

    /// True when every cluster is one panel.
    pub fn is_identity(&self) -> bool {
        self.collocation.len() == self.of_panel.len()
    }

    /// Clusters of diameter `wanted` [m], grown by 1.25× at a time until at
    /// most `max` remain, and the diameter they took; `None` when even
    /// clusters reaching across the body (`largest` [m]) are too many.
    /// Growth stops there because a cluster never spans panels whose normals
    /// turn by more than [`MAX_NORMAL_ANGLE_DEG`] from its seed's: on a rough
    /// or spiky surface that, not the diameter, bounds the clusters, and
    /// growing for ever would hang the run.
    pub fn fit(
        mesh: &BoundaryMesh,
        adjacency: &Adjacency,
        wanted: f64,
        largest: f64,
        max: usize,
    ) -> Option<(Clusters, f64)> {
        let mut diameter = wanted;
        loop {
            let clusters = Clusters::grow(mesh, adjacency, diameter);
            if clusters.len() <= max {
                return Some((clusters, diameter));
            }
            if diameter >= largest {
                return None;
            }
            diameter = (1.25 * diameter).min(largest);
        }
    }

    /// Clusters of diameter about `diameter` [m] (see the module doc); a
    /// diameter below the panels' gives one panel per cluster.
    pub fn grow(mesh: &BoundaryMesh, adjacency: &Adjacency, diameter: f64) -> Clusters {
        let n = mesh.len();
        let cos_max = MAX_NORMAL_ANGLE_DEG.to_radians().cos();
        let reach2 = 0.25 * diameter * diameter;
        let mut of_panel = vec![usize::MAX; n];
        let mut collocation = Vec::new();
        let mut queue = VecDeque::new();
        for &seed in &adjacency.order {
            if of_panel[seed] != usize::MAX {
                continue;
            }
            let id = collocation.len();
            let (c0, n0) = (mesh.panels[seed].centroid, mesh.panels[seed].normal);
            let mut members = vec![seed];
            of_panel[seed] = id;
            queue.clear();
            queue.push_back(seed);
            while let Some(p) = queue.pop_front() {
                for &q in adjacency.neighbours(p) {
                    let pq = &mesh.panels[q];
                    let d = sub(pq.centroid, c0);
                    if of_panel[q] == usize::MAX && dot(d, d) <= reach2 && dot(pq.normal, n0) >= cos_max {
                        of_panel[q] = id;
                        members.push(q);
                        queue.push_back(q);
                    }
                }
            }
            let area: f64 = members.iter().map(|&m| mesh.panels[m].area).sum();
            let centre = [0, 1, 2].map(|k| {
                members.iter().map(|&m| mesh.panels[m].area * mesh.panels[m].centroid[k]).sum::<f64>() / area
            });
            let best = members
                .iter()
                .copied()
                .min_by(|&a, &b| {
                    let da = norm(sub(mesh.panels[a].centroid, centre));
                    let db = norm(sub(mesh.panels[b].centroid, centre));
                    da.total_cmp(&db).then(a.cmp(&b))
                })
                .unwrap_or(seed);
            collocation.push(best);
        }
        Clusters { of_panel, collocation }
    }
}

/// Edge neighbours of every panel and a breadth-first order of the surface.
#[derive(Clone, Debug)]
pub struct Adjacency {
    start: Vec<usize>,
    list: Vec<usize>,
    /// Panels in breadth-first order (component by component, each from
    /// its lowest-numbered panel).
    pub order: Vec<usize>,
}

impl Adjacency {
    /// Neighbours through shared corner pairs (edges).
    pub fn new(mesh: &BoundaryMesh) -> Adjacency {
        let n = mesh.len();
        let edges = mesh.edge_panels();
        let mut nbr: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (i, p) in mesh.panels.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (p.corners[k], p.corners[(k + 1) % 3]);
                for &j in &edges[&(a.min(b), a.max(b))] {
                    if j != i && !nbr[i].contains(&j) {
                        nbr[i].push(j);
                    }
                }
            }
            nbr[i].sort_unstable();
        }
        let mut start = Vec::with_capacity(n + 1);
        let mut list = Vec::new();
        for l in &nbr {
            start.push(list.len());
            list.extend_from_slice(l);
        }
        start.push(list.len());
        let mut seen = vec![false; n];
        let mut order = Vec::with_capacity(n);
        let mut queue = VecDeque::new();
        for root in 0..n {
            if seen[root] {
                continue;
            }
            seen[root] = true;
            queue.push_back(root);
            while let Some(p) = queue.pop_front() {
                order.push(p);
                for &q in &nbr[p] {
                    if !seen[q] {
                        seen[q] = true;
                        queue.push_back(q);
                    }
                }
            }
        }
        Adjacency { start, list, order }
    }

    /// Edge neighbours of panel `p`.
    pub fn neighbours(&self, p: usize) -> &[usize] {
        &self.list[self.start[p]..self.start[p + 1]]
    }

    /// Surface wavenumber `k_s` [1/m] of a velocity field on the panels
    /// (module doc); 0 for a uniform or zero field.
    pub fn surface_wavenumber(&self, mesh: &BoundaryMesh, v: &[c64]) -> f64 {
        let cos_max = MAX_NORMAL_ANGLE_DEG.to_radians().cos();
        let (mut num, mut den) = (0.0, 0.0);
        for (i, p) in mesh.panels.iter().enumerate() {
            den += p.area * v[i].norm_sqr();
            let (mut s, mut count) = (0.0, 0usize);
            for &j in self.neighbours(i) {
                let q = &mesh.panels[j];
                if dot(p.normal, q.normal) >= cos_max {
                    let d = sub(p.centroid, q.centroid);
                    s += (v[i] - v[j]).norm_sqr() / dot(d, d);
                    count += 1;
                }
            }
            if count > 0 {
                num += p.area * 2.0 * s / count as f64;
            }
        }
        if den > 0.0 {
            (num / den).sqrt()
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere(subdiv: u32) -> BoundaryMesh {
        let (v, t) = modal_mesh::icosphere(subdiv);
        BoundaryMesh::new(v, &t).unwrap()
    }

    #[test]
    fn clusters_partition_the_surface_within_the_target_size() {
        let mesh = sphere(4);
        let adj = Adjacency::new(&mesh);
        assert_eq!(adj.order.len(), mesh.len());
        assert!((0..mesh.len()).all(|p| adj.neighbours(p).len() == 3));
        let tiny = Clusters::grow(&mesh, &adj, 1e-6);
        assert!(tiny.is_identity());
        let c = Clusters::grow(&mesh, &adj, 0.4);
        assert!(c.len() > 20 && c.len() < mesh.len() / 4, "{} clusters", c.len());
        let mut area = vec![0.0; c.len()];
        for (p, &k) in c.of_panel.iter().enumerate() {
            assert!(k < c.len());
            area[k] += mesh.panels[p].area;
            // Every member lies within the target radius of its collocation point (seed
            // distance ≤ 0.2 on both sides).
            let d = norm(sub(mesh.panels[p].centroid, mesh.panels[c.collocation[k]].centroid));
            assert!(d <= 0.4 + 1e-12, "panel {p}: {d}");
        }
        assert!(c.collocation.iter().enumerate().all(|(k, &p)| c.of_panel[p] == k));
        let total: f64 = area.iter().sum();
        assert!((total - mesh.area()).abs() < 1e-12 * total);
        assert_eq!(c, Clusters::grow(&mesh, &adj, 0.4), "deterministic");
    }

    /// An icosahedron's neighbouring faces turn by 41.8°, more than a
    /// cluster spans: no diameter groups its 20 faces into fewer than 20
    /// clusters, so asking for 10 ends (`None`, the run's error) instead of
    /// growing for ever; a finer sphere's gentler faces group as asked, and
    /// a cap they already fit keeps the diameter asked for.
    #[test]
    fn clusters_stop_growing_where_the_normals_bound_them() {
        let ico = sphere(0);
        assert_eq!(ico.len(), 20);
        assert!(Clusters::fit(&ico, &Adjacency::new(&ico), 0.1, 4.0, 10).is_none());
        let fine = sphere(3);
        let adjacency = Adjacency::new(&fine);
        let (clusters, diameter) = Clusters::fit(&fine, &adjacency, 0.1, 4.0, 200).expect("it groups");
        assert!(clusters.len() <= 200 && diameter > 0.1 && diameter <= 4.0, "{} {diameter}", clusters.len());
        let (all, kept) = Clusters::fit(&fine, &adjacency, 0.1, 4.0, fine.len()).expect("it fits");
        assert_eq!((all.len() <= fine.len(), kept), (true, 0.1));
    }

    #[test]
    fn surface_wavenumber_of_a_plane_wave() {
        // v = cos(k_s z) on a unit sphere: |∇_S v|² = k_s² sin²(k_s z)(1 − z²); the
        // Rayleigh quotient is ∫|∇_S v|² / ∫ v², computed here by quadrature in z.
        let mesh = sphere(5);
        let adj = Adjacency::new(&mesh);
        for ks in [3.0, 8.0] {
            let v: Vec<c64> = mesh.panels.iter().map(|p| c64::new((ks * p.centroid[2]).cos(), 0.0)).collect();
            let (x, w) = crate::quadrature::gauss_legendre(200);
            let num: f64 =
                x.iter().zip(&w).map(|(z, w)| w * ks * ks * (ks * z).sin().powi(2) * (1.0 - z * z)).sum();
            let den: f64 = x.iter().zip(&w).map(|(z, w)| w * (ks * z).cos().powi(2)).sum();
            let want = (num / den).sqrt();
            let got = adj.surface_wavenumber(&mesh, &v);
            assert!((got / want - 1.0).abs() < 0.1, "k_s {ks}: {got} vs {want}");
        }
    }
}
