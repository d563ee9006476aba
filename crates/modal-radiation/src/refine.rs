//! Splitting flat panels in four at their edge midpoints: every panel (a
//! finer level), or, round after round, only the panels with a corner on a
//! crease (local refinement at a thin wall's rim).
//!
//! Why the rim: on a thin wall the two faces carry nearly opposite
//! pressures, and what radiates is their difference, the pressure jump
//! `μ = p₊ − p₋`. Towards a free edge it behaves like the jump across a
//! screen's edge, `μ ∝ √d` at distances `d` from the edge larger than the
//! wall thickness `t`, and the pressure wraps around the rim within `t`.
//! Constant panels wider than `t` there mis-state the edge's radiation.
//! Halving the panels that touch a crease, `N` times, grades the mesh
//! towards the rim (band widths `h, h/2, …`) for a fraction of a uniform
//! split's unknowns. A panel's quarters lie in its plane, so a split
//! panel next to an unsplit one leaves the surface exactly where it was
//! (a hanging midpoint, harmless to collocation with constant panels).

use std::collections::{HashMap, HashSet};

use crate::error::RadiationError;
use crate::geometry::{dot, BoundaryMesh};

/// `mesh`'s panels split in four (`[a, ab, ca]`, `[ab, b, bc]`,
/// `[ca, bc, c]`, `[ab, bc, ca]`) where `split(i)` holds, with each
/// split panel's `payload` replaced by `quarters(payload)` and the others'
/// kept. Midpoints are shared between the panels of an edge.
pub fn split_panels<T: Copy>(
    mesh: &BoundaryMesh,
    payload: &[T],
    split: impl Fn(usize) -> bool,
    quarters: impl Fn(&T) -> [T; 4],
) -> Result<(BoundaryMesh, Vec<T>), RadiationError> {
    let (mesh, payload, _) = split_with_midpoints(mesh, payload, split, quarters)?;
    Ok((mesh, payload))
}

/// Each new midpoint by its edge (the edge's two ends, smaller first).
type Midpoints = HashMap<(usize, usize), usize>;

/// [`split_panels`], also returning the new midpoints.
fn split_with_midpoints<T: Copy>(
    mesh: &BoundaryMesh,
    payload: &[T],
    split: impl Fn(usize) -> bool,
    quarters: impl Fn(&T) -> [T; 4],
) -> Result<(BoundaryMesh, Vec<T>, Midpoints), RadiationError> {
    debug_assert_eq!(mesh.len(), payload.len());
    let mut vertices = mesh.vertices.clone();
    let mut midpoints = Midpoints::new();
    let (mut triangles, mut out) = (Vec::with_capacity(mesh.len()), Vec::with_capacity(mesh.len()));
    for (i, (panel, p)) in mesh.panels.iter().zip(payload).enumerate() {
        if !split(i) {
            triangles.push(panel.corners);
            out.push(*p);
            continue;
        }
        let [a, b, c] = panel.corners;
        let [ab, bc, ca] = [(a, b), (b, c), (c, a)].map(|(u, v)| {
            *midpoints.entry((u.min(v), u.max(v))).or_insert_with(|| {
                let (pu, pv) = (vertices[u], vertices[v]);
                vertices.push([0, 1, 2].map(|k| 0.5 * (pu[k] + pv[k])));
                vertices.len() - 1
            })
        });
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        out.extend(quarters(p));
    }
    Ok((BoundaryMesh::new(vertices, &triangles)?, out, midpoints))
}

/// The edges (vertex pairs, smaller index first) where two panels meet at
/// more than `crease_deg` between their normals.
pub fn crease_edges(mesh: &BoundaryMesh, crease_deg: f64) -> HashSet<(usize, usize)> {
    let cos_crease = crease_deg.to_radians().cos();
    mesh.edge_panels()
        .into_iter()
        .filter(|(_, ps)| {
            ps.iter()
                .any(|&i| ps.iter().any(|&j| dot(mesh.panels[i].normal, mesh.panels[j].normal) < cos_crease))
        })
        .map(|(e, _)| e)
        .collect()
}

/// `rounds` rounds of [`split_panels`] on the panels with a corner on a
/// crease edge ([`crease_edges`] at `crease_deg`); the halves of a split
/// crease edge are crease edges of the next round.
pub fn refine_near_creases<T: Copy>(
    mesh: &BoundaryMesh,
    payload: &[T],
    rounds: usize,
    crease_deg: f64,
    quarters: impl Fn(&T) -> [T; 4],
) -> Result<(BoundaryMesh, Vec<T>), RadiationError> {
    let mut creases = crease_edges(mesh, crease_deg);
    let (mut mesh, mut payload) = (mesh.clone(), payload.to_vec());
    for _ in 0..rounds {
        let on_crease: HashSet<usize> = creases.iter().flat_map(|&(u, v)| [u, v]).collect();
        let touches = |i: usize| mesh.panels[i].corners.iter().any(|c| on_crease.contains(c));
        let (next, next_payload, midpoints) = split_with_midpoints(&mesh, &payload, touches, &quarters)?;
        creases = creases
            .into_iter()
            .flat_map(|(u, v)| match midpoints.get(&(u, v)) {
                Some(&m) => vec![(u.min(m), u.max(m)), (v.min(m), v.max(m))],
                None => vec![(u, v)],
            })
            .collect();
        (mesh, payload) = (next, next_payload);
    }
    Ok((mesh, payload))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box `[0, 2] × [0, 1] × [0, 0.1]` of 12 triangles.
    fn slab() -> BoundaryMesh {
        crate::geometry::tests::box_surface([2.0, 1.0, 0.1], |x| x)
    }

    /// Every edge of a box is a crease and its face diagonals are not; each
    /// round keeps the area and the enclosed volume, splits only panels
    /// touching a crease, and every panel of the result that touches a
    /// crease is at most half as wide as before (graded towards the edges).
    #[test]
    fn refining_near_creases_grades_towards_the_edges_and_keeps_the_surface() {
        let mesh = slab();
        let creases = crease_edges(&mesh, 25.0);
        assert_eq!(creases.len(), 12, "a box has 12 edges");
        let area = mesh.area();
        let ids: Vec<usize> = (0..mesh.len()).collect();
        let (one, parent1) = refine_near_creases(&mesh, &ids, 1, 25.0, |&p| [p; 4]).unwrap();
        assert_eq!(one.len(), 4 * mesh.len(), "every panel of a box touches an edge");
        let (three, parent3) = refine_near_creases(&mesh, &ids, 3, 25.0, |&p| [p; 4]).unwrap();
        for refined in [&one, &three] {
            assert!((refined.area() - area).abs() < 1e-12 * area);
            assert!(refined.contains([1.0, 0.5, 0.05]) && !refined.contains([1.0, 0.5, 0.2]));
        }
        assert!(three.len() < 64 * mesh.len(), "the third round splits only panels at an edge");
        assert!(three.len() > one.len());
        // Each child lies in its parent panel's plane.
        for (q, &p) in three.panels.iter().zip(&parent3) {
            assert!(dot(q.normal, mesh.panels[p].normal) > 1.0 - 1e-12);
        }
        assert_eq!(parent1.len(), one.len());
        // Panels touching an edge after three rounds are 1/8 of the originals.
        let edge_panels = three.panels.iter().filter(|p| {
            p.corners.iter().any(|&c| {
                let v = three.vertices[c];
                let on = |x: f64, hi: f64| x.abs() < 1e-12 || (x - hi).abs() < 1e-12;
                [on(v[0], 2.0), on(v[1], 1.0), on(v[2], 0.1)].iter().filter(|&&b| b).count() >= 2
            })
        });
        let widest = edge_panels.map(|p| p.diameter).fold(0.0, f64::max);
        let original = mesh.panels.iter().map(|p| p.diameter).fold(0.0, f64::max);
        assert!(widest <= original / 8.0 + 1e-12, "{widest} vs {original}");
    }
}
