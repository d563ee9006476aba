//! Collision shapes of bodies, built from a bank's surface (mesh frame).
//!
//! - fixed bodies: the surface triangle mesh, unless the surface is convex
//!   (its hull's volume within [`FIXED_CONVEX_RATIO`] of the mesh's volume):
//!   then the same hull or exact ball as a dynamic body. A body resting
//!   exactly on a triangle mesh whose faces it shares (a bar on a fixed bar,
//!   a block on a fixed block of the same footprint) gets contacts from the
//!   mesh's side triangles through the shared edges: in rapier 0.36 a bar
//!   turned 0.1–2° on a fixed bar was thrown off at up to 8 m/s, where the
//!   same bar on the fixed bar's hull stays put (`tests/stacks.rs`);
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
//! - a dynamic body whose surface nodes all lie on one sphere (within
//!   [`SPHERE_TOLERANCE`] of its radius), with `collider = "hull"` or
//!   `"auto"`: an exact ball. A faceted hull rolls on its facet edges and hops
//!   (a 2 cm ball at 0.5 m/s left the floor every ≈ 0.1 s), which is heard as
//!   ticks when it should roll smoothly (issue #16).
//!
//! - likewise a dynamic body whose hull is a circular cylinder (a solid
//!   cylinder, a tube, a can; [`cylinder_of`]): an exact cylinder.
//!
//! Every convex polyhedron (a hull, each part of a decomposition) is a
//! [`FaceHull`]: parry's own polyhedron reduces a face with many vertices to
//! its first 4 when generating contacts, which let a flat thin disc sink
//! through the floor ([`crate::face_hull`]).
//!
//! A decomposition costs set-up time (measured in `docs/benchmarks/scene.md`),
//! so it is computed once per distinct bank and shared by its instances
//! ([`ShapeCache`]).

use std::sync::Arc;

use modal_bank::ModeBank;
use parry3d::transformation::vhacd::{VHACDParameters, VHACD};
use rapier3d::prelude::*;

use crate::face_hull::FaceHull;
use crate::spec::{ColliderKind, AUTO_DECOMPOSITION_RATIO};
use crate::SceneError;

/// Most vertices kept in a dynamic body's convex hull.
pub const MAX_HULL_VERTICES: usize = 384;

/// A surface is a sphere when every node's distance from the nodes' bounding
/// box centre is within this fraction of the mean distance.
pub const SPHERE_TOLERANCE: f64 = 1e-3;

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
        let hull = || match cylinder_of(bank) {
            Some(cylinder) => Ok(cylinder.shape()),
            None => reduced_hull(&points).ok_or_else(|| SceneError::Collider {
                path: path.into(),
                message: "degenerate convex hull".into(),
            }),
        };
        let sphere = match kind {
            ColliderKind::Hull | ColliderKind::Auto => sphere_of(bank),
            ColliderKind::Decomposition => None,
        };
        let shape = match kind {
            _ if sphere.is_some() => {
                let (c, r) = sphere.unwrap_or_default();
                let at = Pose::from_translation(Vector::new(c[0] as f32, c[1] as f32, c[2] as f32));
                SharedShape::compound(vec![(at, SharedShape::ball(r as f32))])
            }
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

/// A fixed body is convex, and collides as its hull, when the hull's volume
/// is at most this many times the mesh's own volume (module doc).
pub const FIXED_CONVEX_RATIO: f64 = 1.01;

impl ShapeCache {
    /// The collision shape of a fixed body with `bank`: its exact ball or
    /// hull when the surface is convex (within [`FIXED_CONVEX_RATIO`]), else
    /// `None` (the caller builds the surface triangle mesh).
    pub fn fixed_convex_shape(
        &mut self,
        bank: &Arc<ModeBank>,
        path: &str,
    ) -> Result<Option<SharedShape>, SceneError> {
        let shape = self.dynamic_shape(bank, ColliderKind::Hull, path)?;
        // A one-part compound is the exact ball or the exact cylinder; else
        // the shape is the faceted hull itself.
        let part = shape.as_compound().and_then(|c| c.shapes().first()).map(|(_, s)| s);
        if part.is_some_and(|s| s.as_ball().is_some()) {
            return Ok(Some(shape));
        }
        // The faceted hull's volume, not an exact cylinder's: a hollow tube is
        // not convex, and a faceted solid cylinder's mesh is its faceted hull.
        let faceted = match part {
            Some(_) => reduced_hull(&surface_points(bank)),
            None => Some(shape.clone()),
        };
        let Some(faceted) = faceted else { return Ok(None) };
        let mesh_volume = bank.mass.mass_kg / bank.material.density_kg_m3;
        let hull_volume = faceted.mass_properties(1.0).mass() as f64;
        Ok((hull_volume <= FIXED_CONVEX_RATIO * mesh_volume).then_some(shape))
    }
}

/// Centre and radius of the sphere every surface node lies on (module doc),
/// if there is one.
fn sphere_of(bank: &ModeBank) -> Option<([f64; 3], f64)> {
    let p = &bank.surface.positions;
    if p.len() < 12 {
        return None;
    }
    let (lo, hi) = bank.surface.bounding_box();
    let centre: [f64; 3] = std::array::from_fn(|c| 0.5 * (lo[c] + hi[c]));
    let dist = |x: &[f64; 3]| (0..3).map(|c| (x[c] - centre[c]).powi(2)).sum::<f64>().sqrt();
    let mean = p.iter().map(dist).sum::<f64>() / p.len() as f64;
    let round = mean > 0.0 && p.iter().all(|x| (dist(x) - mean).abs() <= SPHERE_TOLERANCE * mean);
    round.then_some((centre, mean))
}

/// Nodes within this fraction of a cylinder's length of a cap lie on it, and
/// within this fraction of its radius of the round side ([`cylinder_of`]);
/// the side's is looser, for a polygon's vertices seen from its bounding
/// box's centre.
pub const CYLINDER_TOLERANCE: f64 = 1e-3;
const CYLINDER_SIDE_TOLERANCE: f64 = 1e-2;

/// Largest angle between neighbouring rim nodes of a round cap [rad]: a
/// 12-gon is round, a hexagonal pencil is not.
pub const MAX_RIM_GAP_RAD: f64 = std::f64::consts::PI / 6.0;

/// A circular cylinder along a mesh-frame axis (mesh frame, metres).
struct RoundHull {
    axis: usize,
    centre: [f64; 3],
    radius: f64,
    half_length: f64,
}

impl RoundHull {
    /// parry's cylinder (axis y) turned onto the axis, in a one-part compound
    /// as the exact ball is.
    fn shape(&self) -> SharedShape {
        let mut axis = Vector::ZERO;
        axis[self.axis] = 1.0;
        let rotation = Rotation::from_rotation_arc(Vector::Y, axis);
        let c = self.centre.map(|x| x as f32);
        let pose = Pose::from_parts(Vector::new(c[0], c[1], c[2]), rotation);
        SharedShape::compound(vec![(
            pose,
            SharedShape::cylinder(self.half_length as f32, self.radius as f32),
        )])
    }
}

/// The cylinder that is the convex hull of the surface nodes, if there is
/// one: along a bounding-box axis with (nearly) equal extents across it, its
/// radius the farthest node's from the axis, and both end rims round (nodes
/// at that radius all around, no gap wider than [`MAX_RIM_GAP_RAD`]). A solid cylinder, a
/// tube, a can. Its faceted hull rolls on facet edges, loses speed at each
/// (a tube rolling at 0.2 m/s with no rolling resistance covered 0.30 m of
/// 0.40 m in 2 s) and is heard as ticks, as a faceted ball was. A disc
/// (shorter than its radius) keeps its faceted hull: parry approximates a
/// cylinder's cap by a square in contacts, and `meshes/spin.toml`'s Euler's
/// disk, which runs on its cap's rim, then slid flat with no landing.
fn cylinder_of(bank: &ModeBank) -> Option<RoundHull> {
    let p = &bank.surface.positions;
    if p.len() < 24 {
        return None;
    }
    let (lo, hi) = bank.surface.bounding_box();
    let extent: [f64; 3] = std::array::from_fn(|c| hi[c] - lo[c]);
    let centre: [f64; 3] = std::array::from_fn(|c| 0.5 * (lo[c] + hi[c]));
    (0..3).find_map(|axis| {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        if (extent[u] - extent[v]).abs() > 5.0 * CYLINDER_SIDE_TOLERANCE * extent[u].max(extent[v]) {
            return None;
        }
        let off_axis = |x: &[f64; 3]| (x[u] - centre[u]).hypot(x[v] - centre[v]);
        let radius = p.iter().map(off_axis).fold(0.0, f64::max);
        if radius <= 0.0 || extent[axis] < radius {
            return None; // degenerate, or a disc: see the doc above
        }
        let round_rim = |end: f64| {
            let mut angles: Vec<f64> = p
                .iter()
                .filter(|x| (x[axis] - end).abs() <= CYLINDER_TOLERANCE * extent[axis])
                .filter(|x| off_axis(x) >= radius * (1.0 - CYLINDER_SIDE_TOLERANCE))
                .map(|x| (x[v] - centre[v]).atan2(x[u] - centre[u]))
                .collect();
            angles.sort_by(f64::total_cmp);
            let (Some(first), Some(last)) = (angles.first(), angles.last()) else { return false };
            let wrap = first + std::f64::consts::TAU - last;
            angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f64::max) <= MAX_RIM_GAP_RAD
        };
        (round_rim(lo[axis]) && round_rim(hi[axis])).then_some(RoundHull {
            axis,
            centre,
            radius,
            half_length: 0.5 * extent[axis],
        })
    })
}

/// The surface nodes as rapier vectors (mesh frame).
pub(crate) fn surface_points(bank: &ModeBank) -> Vec<Vector> {
    bank.surface.positions.iter().map(|p| Vector::new(p[0] as f32, p[1] as f32, p[2] as f32)).collect()
}

/// The surface triangles as rapier indices.
pub(crate) fn surface_triangles(bank: &ModeBank) -> Vec<[u32; 3]> {
    bank.surface.triangles.iter().map(|t| t.map(|k| k as u32)).collect()
}

/// The convex hull of `points` as a [`FaceHull`].
fn face_hull(points: &[Vector]) -> Option<SharedShape> {
    parry3d::shape::ConvexPolyhedron::from_convex_hull(points).map(|p| SharedShape::new(FaceHull::new(p)))
}

/// The convex hull of `points`, with at most [`MAX_HULL_VERTICES`] vertices.
fn reduced_hull(points: &[Vector]) -> Option<SharedShape> {
    if points.len() <= MAX_HULL_VERTICES {
        return face_hull(points);
    }
    face_hull(&extreme_points(points, MAX_HULL_VERTICES))
}

/// The points of `points` extreme along `k` directions spread evenly over
/// the sphere (a Fibonacci lattice): each is a vertex of the full hull, and
/// their hull lies inside the full one, closer the more directions
/// (deterministic). Along each direction the winner is the point with the
/// largest `p·d` in `f32` (ordered as `f32::total_cmp`), the last such point
/// on ties.
fn extreme_points(points: &[Vector], k: usize) -> Vec<Vector> {
    if points.is_empty() {
        return Vec::new();
    }
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let directions: Vec<Vector> = (0..k)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / k as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let (s, c) = (golden * i as f32).sin_cos();
            Vector::new(r * c, y, r * s)
        })
        .collect();
    let cloud = Cloud::new(points);
    let mut chosen: Vec<usize> = Vec::with_capacity(k);
    for block in directions.chunks(SCAN_LANES) {
        chosen.extend(&cloud.argmax(block)[..block.len()]);
    }
    chosen.sort_unstable();
    chosen.dedup();
    chosen.into_iter().map(|j| points[j]).collect()
}

/// Directions scanned together in one pass over the points.
const SCAN_LANES: usize = 8;

/// Points as structure of arrays, for [`Cloud::argmax`].
struct Cloud {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Cloud {
    fn new(points: &[Vector]) -> Cloud {
        Cloud {
            x: points.iter().map(|p| p.x).collect(),
            y: points.iter().map(|p| p.y).collect(),
            z: points.iter().map(|p| p.z).collect(),
        }
    }

    /// Index of the point with the largest `p·d` for each of up to
    /// [`SCAN_LANES`] directions (unused lanes hold garbage): one pass over
    /// the points, a branch-free compare-and-select per lane. The dot product
    /// is evaluated as glam's `Vec3::dot`, `(x·dx + y·dy) + z·dz`, so the
    /// result equals a per-direction `max_by(total_cmp)` exactly.
    fn argmax(&self, directions: &[Vector]) -> [usize; SCAN_LANES] {
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.argmax_avx2(directions) };
        }
        self.argmax_lanes(directions)
    }

    /// [`Cloud::argmax`] compiled for AVX2 (no FMA: the products round as in
    /// the portable path).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn argmax_avx2(&self, directions: &[Vector]) -> [usize; SCAN_LANES] {
        self.argmax_lanes(directions)
    }

    #[inline(always)]
    fn argmax_lanes(&self, directions: &[Vector]) -> [usize; SCAN_LANES] {
        let (mut dx, mut dy, mut dz) = ([0.0f32; SCAN_LANES], [0.0f32; SCAN_LANES], [0.0f32; SCAN_LANES]);
        for (l, d) in directions.iter().take(SCAN_LANES).enumerate() {
            (dx[l], dy[l], dz[l]) = (d.x, d.y, d.z);
        }
        let mut best = [i32::MIN; SCAN_LANES];
        let mut index = [0u32; SCAN_LANES];
        let n = self.x.len().min(self.y.len()).min(self.z.len());
        let (xs, ys, zs) = (&self.x[..n], &self.y[..n], &self.z[..n]);
        for j in 0..n {
            let (x, y, z) = (xs[j], ys[j], zs[j]);
            for l in 0..SCAN_LANES {
                let key = total_order_key((x * dx[l]) + (y * dy[l]) + (z * dz[l]));
                let take = key >= best[l];
                best[l] = if take { key } else { best[l] };
                index[l] = if take { j as u32 } else { index[l] };
            }
        }
        index.map(|i| i as usize)
    }
}

/// An integer that orders like `f32::total_cmp` orders the float.
#[inline(always)]
fn total_order_key(v: f32) -> i32 {
    let bits = v.to_bits() as i32;
    bits ^ (((bits >> 31) as u32) >> 1) as i32
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
        .filter_map(|(vertices, _)| face_hull(&vertices))
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
        let poly = hull.as_shape::<FaceHull>().expect("face hull").polyhedron();
        assert!(poly.points().len() <= MAX_HULL_VERTICES, "{} vertices", poly.points().len());
        // Every dropped point lies outside (or on) the reduced hull, by at most
        // the sag between the kept vertices (384 directions α ≈ 0.18 rad
        // apart; measured 0.0125 on 3000 Fibonacci points).
        let worst = points.iter().map(|p| hull.distance_to_local_point(*p, true)).fold(0.0f32, f32::max);
        assert!(worst > 0.0 && worst < 0.015, "largest gap {worst}");
        // Small hulls stay exact.
        let few = sphere_points(100);
        let exact = reduced_hull(&few).expect("hull");
        assert_eq!(exact.as_shape::<FaceHull>().expect("face hull").polyhedron().points().len(), 100);
    }

    /// The plain per-direction scan [`extreme_points`] must reproduce.
    fn extreme_points_reference(points: &[Vector], k: usize) -> Vec<Vector> {
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

    #[test]
    fn extreme_points_equal_the_per_direction_scan() {
        // A noisy cloud with exact duplicates (ties go to the last index),
        // and direction counts that leave partly filled lane blocks.
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        let mut points: Vec<Vector> = (0..2000).map(|_| Vector::new(rnd(), 0.3 * rnd(), rnd())).collect();
        points.extend_from_within(..500);
        points.push(Vector::new(-0.0, 0.0, 0.0));
        for k in [1, 7, 8, 61, 384] {
            assert_eq!(extreme_points(&points, k), extreme_points_reference(&points, k), "k = {k}");
        }
        assert_eq!(
            extreme_points(&sphere_points(3000), 384),
            extreme_points_reference(&sphere_points(3000), 384)
        );
        assert!(extreme_points(&[], 8).is_empty());
    }

    fn bank_of(mesh: &modal_mesh::TetMesh) -> ModeBank {
        crate::stand_in::synthetic_bank(mesh, modal_fem::Material::preset("steel").expect("steel"), &[1000.0])
    }

    #[test]
    fn round_hulls_are_found_and_others_are_not() {
        use modal_mesh::generate::{bowl, box_mesh, cylinder, tube};
        let tube = cylinder_of(&bank_of(&tube(0.027, 0.03, 0.15, 0.006, 1).expect("tube"))).expect("a tube");
        assert_eq!(tube.axis, 2);
        assert!((tube.radius - 0.03).abs() < 1e-9 && (tube.half_length - 0.075).abs() < 1e-9);
        assert!(cylinder_of(&bank_of(&cylinder(0.02, 0.1, 0.005, 2).expect("rod"))).is_some());
        // A square bar, a disc (kept faceted: see `cylinder_of`) and a bowl are not.
        assert!(cylinder_of(&bank_of(&box_mesh([0.02, 0.3, 0.02], [2, 30, 2]))).is_none());
        assert!(cylinder_of(&bank_of(&cylinder(0.04, 0.006, 0.006, 2).expect("disc"))).is_none());
        assert!(cylinder_of(&bank_of(&bowl(0.06, 0.004, 0.01, 2).expect("bowl"))).is_none());
    }

    #[test]
    fn total_order_key_orders_like_total_cmp() {
        let values = [f32::NEG_INFINITY, -1.5, -0.0, 0.0, 1e-30, 2.0, f32::INFINITY];
        for a in values {
            for b in values {
                assert_eq!(total_order_key(a).cmp(&total_order_key(b)), a.total_cmp(&b), "{a} vs {b}");
            }
        }
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
