//! How much of a surface is a wall thinner than its panels: the case the
//! default solve gets wrong by several dB in quiet directions
//! (docs/radiation.md, "Thin walls").
//!
//! From a panel's centroid a ray goes into the body along `−n`; the wall
//! there is the distance `t` to the first panel it crosses that faces the
//! other way (`n·n' < −½`, the wall's other face). The panel is thin when
//! `t < THIN_WALL_RATIO · h`, `h` its own diameter. Measured where it
//! matters (`t/h` over the corner triangles, 10th / 50th / 90th
//! percentile): a free steel disc 2 mm thick, 0.25 / 0.37 / 0.49, is
//! several dB off at the defaults (BENCHMARKS.md, "The thin disc again");
//! the demo's 4 mm glass bowls, 0.57 / 0.77 / 0.98 and 0.58 / 0.80 / 1.05,
//! pass the bempp cross-check. The ratio is set between the two; walls
//! between 0.4 and 0.75 have not been measured.

use crate::geometry::{cross, dot, sub, BoundaryMesh};

/// A panel whose wall is thinner than this fraction of its diameter is
/// thin (module doc).
pub const THIN_WALL_RATIO: f64 = 0.5;

/// At most this many panels cast a ray (evenly strided: the area share is
/// an estimate, and a check of every panel would cost `O(N²)`).
const MAX_RAYS: usize = 2000;

/// The thin part of a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinWalls {
    /// Share of the sampled area on thin panels (0–1).
    pub area_fraction: f64,
    /// Area-weighted median wall of the thin panels [m] (0 when none).
    pub median_wall_m: f64,
    /// Area-weighted median diameter of the thin panels [m] (0 when none).
    pub median_panel_m: f64,
}

/// [`ThinWalls`] of `mesh` (a closed, outward surface).
pub fn thin_walls(mesh: &BoundaryMesh) -> ThinWalls {
    let stride = mesh.len().div_ceil(MAX_RAYS).max(1);
    let (mut total, mut thin) = (0.0, Vec::new());
    for i in (0..mesh.len()).step_by(stride) {
        let p = &mesh.panels[i];
        total += p.area;
        if let Some(t) = wall_at(mesh, i) {
            if t < THIN_WALL_RATIO * p.diameter {
                thin.push((p.area, t, p.diameter));
            }
        }
    }
    let thin_area: f64 = thin.iter().map(|x| x.0).sum();
    let median = |value: fn(&(f64, f64, f64)) -> f64| {
        modal_mesh::weighted_median(&mut thin.iter().map(|x| (value(x), x.0)).collect::<Vec<_>>())
    };
    ThinWalls {
        area_fraction: if total > 0.0 { thin_area / total } else { 0.0 },
        median_wall_m: median(|x| x.1),
        median_panel_m: median(|x| x.2),
    }
}

/// The wall at panel `i`: distance along `−n` from its centroid to the
/// nearest opposite-facing panel the ray crosses; `None` if it crosses none.
fn wall_at(mesh: &BoundaryMesh, i: usize) -> Option<f64> {
    let p = &mesh.panels[i];
    let dir = p.normal.map(|x| -x);
    mesh.panels
        .iter()
        .enumerate()
        .filter(|&(j, q)| j != i && dot(q.normal, p.normal) < -0.5)
        .filter_map(|(_, q)| ray_hits_triangle(p.centroid, dir, q.corners.map(|c| mesh.vertices[c])))
        .filter(|&t| t > 0.0)
        .reduce(f64::min)
}

/// Distance along the unit `dir` from `origin` at which the ray crosses
/// the triangle `tri` (Möller–Trumbore), if it does.
fn ray_hits_triangle(origin: [f64; 3], dir: [f64; 3], tri: [[f64; 3]; 3]) -> Option<f64> {
    let (e1, e2) = (sub(tri[1], tri[0]), sub(tri[2], tri[0]));
    let pv = cross(dir, e2);
    let det = dot(e1, pv);
    if det.abs() < 1e-300 {
        return None;
    }
    let tv = sub(origin, tri[0]);
    let u = dot(tv, pv) / det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = cross(tv, e1);
    let v = dot(dir, qv) / det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(dot(e2, qv) / det)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box `[0, x] × [0, y] × [0, z]`, each face split into
    /// `n × n` quads of two triangles.
    fn box_mesh(x: f64, y: f64, z: f64, n: usize) -> BoundaryMesh {
        let mut v = Vec::new();
        let mut tris = Vec::new();
        // Each face: origin, two edge vectors (u × w points outward).
        let faces: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
            ([0.0, 0.0, 0.0], [0.0, y, 0.0], [x, 0.0, 0.0]),
            ([0.0, 0.0, z], [x, 0.0, 0.0], [0.0, y, 0.0]),
            ([0.0, 0.0, 0.0], [x, 0.0, 0.0], [0.0, 0.0, z]),
            ([0.0, y, 0.0], [0.0, 0.0, z], [x, 0.0, 0.0]),
            ([0.0, 0.0, 0.0], [0.0, 0.0, z], [0.0, y, 0.0]),
            ([x, 0.0, 0.0], [0.0, y, 0.0], [0.0, 0.0, z]),
        ];
        for (o, u, w) in faces {
            let base = v.len();
            for i in 0..=n {
                for j in 0..=n {
                    let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                    v.push([0, 1, 2].map(|k| o[k] + a * u[k] + b * w[k]));
                }
            }
            let at = |i: usize, j: usize| base + i * (n + 1) + j;
            for i in 0..n {
                for j in 0..n {
                    tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                    tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        BoundaryMesh::new(v, &tris).unwrap()
    }

    /// A plate 2 mm thick on 14 mm panels is thin over its faces (about
    /// 95 % of the area, wall 2 mm); a 40 mm block on the same panels is
    /// not; the sides of the plate (edges 2 mm wide) do not count.
    #[test]
    fn a_plate_thinner_than_its_panels_is_found_and_a_block_is_not() {
        let plate = box_mesh(0.1, 0.1, 0.002, 10);
        assert!(plate.contains([0.05, 0.05, 0.001]));
        let thin = thin_walls(&plate);
        assert!(thin.area_fraction > 0.9 && thin.area_fraction < 1.0, "{thin:?}");
        assert!((thin.median_wall_m - 0.002).abs() < 1e-9, "{thin:?}");
        assert!(thin.median_panel_m > 0.01, "{thin:?}");
        let block = box_mesh(0.1, 0.1, 0.04, 10);
        assert_eq!(thin_walls(&block).area_fraction, 0.0);
    }
}
