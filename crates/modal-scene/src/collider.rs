//! Collision shapes of bodies, built from a bank's surface (mesh frame).
//!
//! - fixed bodies: the surface triangle mesh;
//! - dynamic bodies, `collider = "hull"`: the convex hull of the surface nodes;
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
            SharedShape::convex_hull(&points).ok_or_else(|| SceneError::Collider {
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
