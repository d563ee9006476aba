//! Collision shapes of bodies, built from a bank's surface (mesh frame).
//!
//! - fixed bodies: the surface triangle mesh;
//! - dynamic bodies, `collider = "hull"`: the convex hull of the surface nodes,
//!   reduced to at most [`MAX_HULL_VERTICES`] vertices by farthest-point
//!   sampling of the full hull's vertices (the hull of a subset lies inside
//!   the full hull; on a sphere the largest gap measured 1.2 % of the radius,
//!   0.7 mm for a 6 cm bowl — see the unit test). Rapier recomputes a hull's bounding box from
//!   every vertex at every step and searches its vertices for each contact,
//!   so a fine mesh's hull (the demo's TET10 bowl: 6 241 of 12 674 surface
//!   nodes) would dominate the
//!   physics cost;
//! - `collider = "decomposition"`: parry's approximate convex decomposition
//!   (V-HACD, Mamou & Ghorbel 2009; voxel resolution [`DECOMPOSITION_RESOLUTION`]
//!   along the longest extent, concavity [`DECOMPOSITION_CONCAVITY`]), each
//!   part being the exact convex hull of the surface points it covers — a
//!   compound that keeps cavities open (a bowl can hold a ball);
//! - `collider = "auto"`: the decomposition when the hull's volume exceeds the
//!   mesh's (mass / density) by more than
//!   [`crate::AUTO_DECOMPOSITION_RATIO`], else the hull.
//!
//! A decomposition costs set-up time (measured in `docs/benchmarks/scene.md`),
//! so it is computed once per distinct bank and shared by its instances
//! ([`ShapeCache`]).

use std::sync::Arc;

use modal_bank::ModeBank;
use parry3d::transformation::vhacd::{VHACDParameters, VHACD};
use rapier3d::prelude::*;

use crate::spec::{ColliderKind, AUTO_DECOMPOSITION_RATIO};
use crate::SceneError;

/// Most vertices kept in a dynamic body's convex hull.
pub const MAX_HULL_VERTICES: usize = 384;

/// Voxels along the longest extent of a decomposed surface.
pub const DECOMPOSITION_RESOLUTION: u32 = 64;
/// Largest concavity (relative) of a decomposition part.
pub const DECOMPOSITION_CONCAVITY: f32 = 0.01;

/// Shapes already built, keyed by bank identity and collider kind.
#[derive(Default)]
pub(crate) struct ShapeCache {
    shapes: Vec<(*const ModeBank, ColliderKind, SharedShape)>,
}

impl ShapeCache {
    /// The collision shape of a dynamic body with `bank` (`path` names the object in errors).
    pub fn dynamic_shape(
        &mut self,
        bank: &Arc<ModeBank>,
        kind: ColliderKind,
        path: &str,
    ) -> Result<SharedShape, SceneError> {
        let key = Arc::as_ptr(bank);
        if let Some((_, _, s)) = self.shapes.iter().find(|(b, k, _)| *b == key && *k == kind) {
            return Ok(s.clone());
        }
        let points = surface_points(bank);
        let hull = || {
            reduced_hull(&points).ok_or_else(|| SceneError::Collider {
                path: path.into(),
                message: "degenerate convex hull".into(),
            })
        };
        let shape = match kind {
            ColliderKind::Hull => hull()?,
            ColliderKind::Decomposition => decomposition(bank, &points, path)?,
            ColliderKind::Auto => {
                let h = hull()?;
                let mesh_volume = bank.mass.mass_kg / bank.material.density_kg_m3;
                let hull_volume = h.mass_properties(1.0).mass() as f64;
                if hull_volume > AUTO_DECOMPOSITION_RATIO * mesh_volume {
                    decomposition(bank, &points, path)?
                } else {
                    h
                }
            }
        };
        self.shapes.push((key, kind, shape.clone()));
        Ok(shape)
    }
}

/// The surface nodes as rapier vectors (mesh frame).
pub(crate) fn surface_points(bank: &ModeBank) -> Vec<Vector> {
    bank.surface.positions.iter().map(|p| Vector::new(p[0] as f32, p[1] as f32, p[2] as f32)).collect()
}

/// The surface triangles as rapier indices.
pub(crate) fn surface_triangles(bank: &ModeBank) -> Vec<[u32; 3]> {
    bank.surface.triangles.iter().map(|t| t.map(|k| k as u32)).collect()
}

/// The convex hull of `points`, with at most [`MAX_HULL_VERTICES`] vertices.
fn reduced_hull(points: &[Vector]) -> Option<SharedShape> {
    let full = SharedShape::convex_hull(points)?;
    let vertices = full.as_convex_polyhedron()?.points();
    if vertices.len() <= MAX_HULL_VERTICES {
        return Some(full);
    }
    SharedShape::convex_hull(&farthest_points(vertices, MAX_HULL_VERTICES)).or(Some(full))
}

/// `k` of `points` spread as evenly as possible: greedy farthest-point
/// sampling from the point farthest from the centroid (deterministic).
fn farthest_points(points: &[Vector], k: usize) -> Vec<Vector> {
    let argmax = |d: &[f32]| d.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map(|(i, _)| i);
    let centroid = points.iter().fold(Vector::ZERO, |a, p| a + *p) / points.len() as f32;
    let from_centroid: Vec<f32> = points.iter().map(|p| (*p - centroid).length_squared()).collect();
    let Some(first) = argmax(&from_centroid) else { return Vec::new() };
    let mut chosen = vec![points[first]];
    let mut nearest: Vec<f32> = points.iter().map(|q| (*q - points[first]).length_squared()).collect();
    while chosen.len() < k {
        let Some(best) = argmax(&nearest).filter(|&i| nearest[i] > 0.0) else { break };
        let p = points[best];
        chosen.push(p);
        for (d, q) in nearest.iter_mut().zip(points) {
            *d = d.min((*q - p).length_squared());
        }
    }
    chosen
}

fn decomposition(bank: &ModeBank, points: &[Vector], path: &str) -> Result<SharedShape, SceneError> {
    let params = VHACDParameters {
        resolution: DECOMPOSITION_RESOLUTION,
        concavity: DECOMPOSITION_CONCAVITY,
        ..VHACDParameters::default()
    };
    let triangles = surface_triangles(bank);
    let parts: Vec<(Pose, SharedShape)> = VHACD::decompose(&params, points, &triangles, true)
        .compute_exact_convex_hulls(points, &triangles)
        .into_iter()
        .filter_map(|(vertices, _)| SharedShape::convex_hull(&vertices))
        .map(|s| (Pose::IDENTITY, s))
        .collect();
    if parts.is_empty() {
        return Err(SceneError::Collider {
            path: path.into(),
            message: "the convex decomposition produced no part".into(),
        });
    }
    Ok(SharedShape::compound(parts))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a sphere of radius 1 (a Fibonacci lattice).
    fn sphere_points(n: usize) -> Vec<Vector> {
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).sqrt();
                let phi = golden * i as f32;
                Vector::new(r * phi.cos(), y, r * phi.sin())
            })
            .collect()
    }

    #[test]
    fn reduced_hull_keeps_few_vertices_and_stays_close_inside() {
        let points = sphere_points(3000);
        let hull = reduced_hull(&points).expect("hull");
        let poly = hull.as_convex_polyhedron().expect("polyhedron");
        assert!(poly.points().len() <= MAX_HULL_VERTICES, "{} vertices", poly.points().len());
        // Every dropped point lies outside (or on) the reduced hull, by at most
        // the sag between its vertices: 384 points on the unit sphere are
        // δ ≈ √(4π/384) ≈ 0.18 apart, sag ≈ δ²/(3·2R) ≈ 0.006 for a regular
        // layout; greedy sampling is less regular (measured 0.0124).
        let worst = points.iter().map(|p| hull.distance_to_local_point(*p, true)).fold(0.0f32, f32::max);
        assert!(worst > 0.0 && worst < 0.015, "largest gap {worst}");
        // Small hulls stay exact.
        let few = sphere_points(100);
        let exact = reduced_hull(&few).expect("hull");
        assert_eq!(exact.as_convex_polyhedron().expect("polyhedron").points().len(), 100);
    }

    #[test]
    fn farthest_points_are_spread_and_distinct() {
        let points = sphere_points(1000);
        let chosen = farthest_points(&points, 50);
        assert_eq!(chosen.len(), 50);
        let closest = chosen
            .iter()
            .enumerate()
            .flat_map(|(i, a)| chosen[i + 1..].iter().map(move |b| (*a - *b).length()))
            .fold(f32::INFINITY, f32::min);
        // 50 evenly spread points on the unit sphere are ≈ √(4π/50) ≈ 0.5 apart.
        assert!(closest > 0.25, "two chosen points only {closest} apart");
    }
}
