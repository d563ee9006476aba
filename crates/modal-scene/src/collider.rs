//! Collision shapes of bodies, built from a bank's surface (mesh frame).
//!
//! - fixed bodies: the surface triangle mesh;
//! - dynamic bodies, `collider = "hull"`: the convex hull of the surface nodes,
//!   reduced to at most [`MAX_HULL_VERTICES`] vertices: the points extreme
//!   along as many directions spread over the sphere (vertices of the full
//!   hull; their hull lies inside it, by at most ≈ 1.3 % of the radius on a
//!   sphere — 0.8 mm for a 6 cm bowl, see the unit test). The full hull is
//!   never built: for a fine mesh it costs more than the whole render of a
//!   cached scene. Rapier recomputes a hull's bounding box from
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
    if points.len() <= MAX_HULL_VERTICES {
        return SharedShape::convex_hull(points);
    }
    SharedShape::convex_hull(&extreme_points(points, MAX_HULL_VERTICES))
}

/// The points of `points` extreme along `k` directions spread evenly over
/// the sphere (a Fibonacci lattice): each is a vertex of the full hull, and
/// their hull lies inside the full one, closer the more directions
/// (deterministic).
fn extreme_points(points: &[Vector], k: usize) -> Vec<Vector> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let mut chosen: Vec<usize> = (0..k)
        .filter_map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / k as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let (s, c) = (golden * i as f32).sin_cos();
            let d = Vector::new(r * c, y, r * s);
            points.iter().map(|p| p.dot(d)).enumerate().max_by(|a, b| a.1.total_cmp(&b.1)).map(|(j, _)| j)
        })
        .collect();
    chosen.sort_unstable();
    chosen.dedup();
    chosen.into_iter().map(|j| points[j]).collect()
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
        // the sag between the kept vertices (384 directions α ≈ 0.18 rad
        // apart; measured 0.0125 on 3000 Fibonacci points).
        let worst = points.iter().map(|p| hull.distance_to_local_point(*p, true)).fold(0.0f32, f32::max);
        assert!(worst > 0.0 && worst < 0.015, "largest gap {worst}");
        // Small hulls stay exact.
        let few = sphere_points(100);
        let exact = reduced_hull(&few).expect("hull");
        assert_eq!(exact.as_convex_polyhedron().expect("polyhedron").points().len(), 100);
    }

    #[test]
    fn extreme_points_are_distinct_vertices_of_the_hull() {
        let mut points = sphere_points(1000);
        // Interior points are never extreme.
        points.extend(sphere_points(500).into_iter().map(|p| p * 0.5));
        let chosen = extreme_points(&points, 64);
        assert!(chosen.len() > 48 && chosen.len() <= 64, "{} points", chosen.len());
        assert!(chosen.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
    }
}
