//! Thickness-aware sizing field for the graded mesh.
//!
//! Local thickness (the shape diameter function, Shapira et al. 2008, on the
//! implicit solid {w ≥ ½}): from a surface sample p with outward normal n,
//! five rays (−n and four at [`CONE_DEG`] around it) are followed to the
//! first surface crossing after which the winding number w falls below ½
//! (where the ray leaves the solid); the thickness t(p) is the median
//! length. A narrow cone and the median keep samples near the edges and
//! corners of thick parts from reading as thin (two of the five rays may
//! leave early through a neighbouring face). Rays longer than the thickness that could matter count as that
//! length.
//!
//! Sizing field (cell size of the background lattice, m):
//!   h(x) = min(h_max, min_s [h_s + γ · |x − p_s|]),  h_s = t_s / c,
//! with c the cells wanted across the thickness and γ = [`GRADING`] the
//! growth of the size per unit distance. Only samples with h_s < h_max
//! enter the minimum, tabulated on a grid (see [`Sizing::new`]).

use std::collections::HashMap;

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::geom::{add, area_vector, cross, norm, scale, sub, V3};
use crate::graded::MAX_LEVELS;

/// Half-angle (degrees) of the cone of thickness rays.
pub const CONE_DEG: f64 = 15.0;
/// Growth of the element size per unit distance from a thin part.
pub const GRADING: f64 = 0.5;
/// Thickness samples are about this fraction of the bulk cell apart.
pub const SPACING: f64 = 0.25;
/// At most about this many thickness samples (larger surfaces are thinned
/// on a grid: one sample per cell and normal direction).
const MAX_SAMPLES: usize = 40_000;

/// A thin place: where, how thick, which size it asks for.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Thin {
    pub at: V3,
    pub thickness: f64,
    pub size: f64,
}

/// The sizing field, tabulated on a grid (see [`Sizing::new`]).
pub(crate) struct Sizing {
    h_max: f64,
    origin: V3,
    g: f64,
    dims: [usize; 3],
    grid: Vec<f32>,
    thin: Vec<Thin>,
}

impl Sizing {
    /// Field for cells of at most `h_max` and `cells` cells across the local
    /// thickness of the solid of `bvh` bounded by the oriented `triangles`.
    ///
    /// The minimum over samples is tabulated on a grid of spacing g =
    /// max(h_max / 8, diagonal / 250) by a two-pass chamfer transform
    /// (3×3×3 neighbourhoods, Euclidean steps): each grid value is the least
    /// h_s + γ·(path length) to a sample's cell, which is within a few
    /// percent of γ·|x − p_s| (the field is only a target).
    pub fn new(vertices: &[V3], triangles: &[[usize; 3]], bvh: &Bvh, h_max: f64, cells: f64) -> Self {
        let samples = samples(vertices, triangles, SPACING * h_max);
        let reach = cells * h_max * 1.25;
        let thin: Vec<Thin> = samples
            .par_iter()
            .filter_map(|&(p, n, eps)| {
                let t = thickness(bvh, p, n, eps, reach)?;
                let size = t / cells;
                (size < h_max).then_some(Thin { at: p, thickness: t, size })
            })
            .collect();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for s in &thin {
            for c in 0..3 {
                lo[c] = lo[c].min(s.at[c]);
                hi[c] = hi[c].max(s.at[c]);
            }
        }
        if thin.is_empty() {
            return Sizing { h_max, origin: [0.0; 3], g: 1.0, dims: [0; 3], grid: Vec::new(), thin };
        }
        // The field reaches h_max within (h_max − h_s) / γ of a sample.
        let pad = h_max / GRADING + h_max;
        let diagonal = norm(sub(hi, lo)) + 2.0 * pad;
        let g = (h_max / 8.0).max(diagonal / 250.0);
        let origin = lo.map(|x| x - pad);
        let dims: [usize; 3] = std::array::from_fn(|c| ((hi[c] - lo[c] + 2.0 * pad) / g).ceil() as usize + 1);
        let mut grid = vec![h_max as f32; dims[0] * dims[1] * dims[2]];
        // Sizes below the finest bisection level are not asked for.
        let floor = h_max / f64::from(1u32 << MAX_LEVELS);
        let index = |i: [usize; 3]| i[0] + dims[0] * (i[1] + dims[1] * i[2]);
        for s in &thin {
            let i: [usize; 3] =
                std::array::from_fn(|c| (((s.at[c] - origin[c]) / g).round() as usize).min(dims[c] - 1));
            let k = index(i);
            grid[k] = grid[k].min(s.size.max(floor) as f32);
        }
        chamfer(&mut grid, dims, (GRADING * g) as f32);
        Sizing { h_max, origin, g, dims, grid, thin }
    }

    /// Wanted cell size (m) at `x` (the value at the nearest grid node).
    pub fn size(&self, x: V3) -> f64 {
        if self.grid.is_empty() {
            return self.h_max;
        }
        let mut i = [0usize; 3];
        for c in 0..3 {
            let f = ((x[c] - self.origin[c]) / self.g).round();
            if f < 0.0 || f >= self.dims[c] as f64 {
                return self.h_max;
            }
            i[c] = f as usize;
        }
        f64::from(self.grid[i[0] + self.dims[0] * (i[1] + self.dims[1] * i[2])]).min(self.h_max)
    }

    /// The thin places found (size below h_max).
    pub fn thin(&self) -> &[Thin] {
        &self.thin
    }
}

/// Two-pass chamfer transform: v(c) = min over neighbours n of v(n) + step·|c − n|
/// (grid units), forward then backward in raster order.
fn chamfer(grid: &mut [f32], dims: [usize; 3], step: f32) {
    let [nx, ny, nz] = dims.map(|d| d as i64);
    let mut forward: Vec<([i64; 3], f32)> = Vec::new();
    for dz in -1..=1i64 {
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                let earlier = (dz, dy, dx) < (0, 0, 0);
                if earlier {
                    let length = ((dx * dx + dy * dy + dz * dz) as f32).sqrt();
                    forward.push(([dx, dy, dz], step * length));
                }
            }
        }
    }
    let at = |x: i64, y: i64, z: i64| (x + nx * (y + ny * z)) as usize;
    for pass in 0..2 {
        let sign = if pass == 0 { 1 } else { -1 };
        for zz in 0..nz {
            for yy in 0..ny {
                for xx in 0..nx {
                    let (x, y, z) =
                        if pass == 0 { (xx, yy, zz) } else { (nx - 1 - xx, ny - 1 - yy, nz - 1 - zz) };
                    let mut best = grid[at(x, y, z)];
                    for &(d, cost) in &forward {
                        let (a, b, c) = (x + sign * d[0], y + sign * d[1], z + sign * d[2]);
                        if a >= 0 && b >= 0 && c >= 0 && a < nx && b < ny && c < nz {
                            best = best.min(grid[at(a, b, c)] + cost);
                        }
                    }
                    grid[at(x, y, z)] = best;
                }
            }
        }
    }
}

/// Samples (point, outward unit normal, offset) on the surface, about
/// `spacing` apart (centroids of a barycentric subdivision of each
/// triangle), thinned to about [`MAX_SAMPLES`] on a grid.
pub(crate) fn samples(vertices: &[V3], triangles: &[[usize; 3]], spacing: f64) -> Vec<(V3, V3, f64)> {
    let mut all: Vec<(V3, V3, f64, f64)> = triangles
        .par_iter()
        .flat_map_iter(|t| {
            let [a, b, c] = t.map(|v| vertices[v]);
            let av = area_vector(a, b, c);
            let area = norm(av);
            let longest = norm(sub(b, a)).max(norm(sub(c, a))).max(norm(sub(c, b)));
            let n = if area > 0.0 { ((longest / spacing).ceil() as usize).clamp(1, 64) } else { 0 };
            let normal = scale(av, 1.0 / area.max(f64::MIN_POSITIVE));
            let (ab, ac) = (sub(b, a), sub(c, a));
            let at = move |u: f64, v: f64| add(a, add(scale(ab, u / n as f64), scale(ac, v / n as f64)));
            let sub_area = area / (n * n).max(1) as f64;
            (0..n).flat_map(move |i| {
                (0..n - i).flat_map(move |j| {
                    let up = Some(at(i as f64 + 1.0 / 3.0, j as f64 + 1.0 / 3.0));
                    let down = (i + j + 1 < n).then(|| at(i as f64 + 2.0 / 3.0, j as f64 + 2.0 / 3.0));
                    [up, down].into_iter().flatten().map(move |p| (p, normal, sub_area, longest / n as f64))
                })
            })
        })
        .collect();
    if all.len() > MAX_SAMPLES {
        let total: f64 = all.iter().map(|s| s.2).sum();
        let cell = (total / MAX_SAMPLES as f64).sqrt();
        let mut seen: HashMap<([i64; 3], u8), ()> = HashMap::new();
        all.retain(|(p, n, _, _)| {
            let axis = (0..3).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs())).unwrap_or(0);
            let dir = (2 * axis + usize::from(n[axis] < 0.0)) as u8;
            seen.insert((p.map(|x| (x / cell).floor() as i64), dir), ()).is_none()
        });
    }
    all.into_iter().map(|(p, n, _, size)| (p, n, 1e-4 * size)).collect()
}

/// Median distance from `p` (inside by `eps`) along rays around −n to where
/// the solid ends, rays capped at `reach`; `None` when the start point is not
/// inside (a wrongly oriented or open place) or no ray leaves the solid.
fn thickness(bvh: &Bvh, p: V3, n: V3, eps: f64, reach: f64) -> Option<f64> {
    let start = sub(p, scale(n, eps));
    if bvh.winding(start) < 0.5 {
        return None;
    }
    // An orthonormal frame (n, u, v).
    let helper = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let u = {
        let c = cross(n, helper);
        scale(c, 1.0 / norm(c))
    };
    let v = cross(n, u);
    let (sin, cos) = CONE_DEG.to_radians().sin_cos();
    let mut lengths: Vec<f64> = Vec::with_capacity(5);
    let mut dirs = vec![scale(n, -1.0)];
    for k in 0..4 {
        let phi = k as f64 * std::f64::consts::FRAC_PI_2;
        let side = add(scale(u, phi.cos()), scale(v, phi.sin()));
        dirs.push(add(scale(n, -cos), scale(side, sin)));
    }
    let mut hits_any = false;
    for d in dirs {
        let end = add(start, scale(d, reach));
        let hits = bvh.crossings(start, end);
        let mut length = reach;
        for (k, &t) in hits.iter().enumerate() {
            // The side is constant between crossings: probe half-way to the next.
            let next = hits.get(k + 1).copied().unwrap_or(1.0);
            let after = add(start, scale(d, reach * (0.5 * (t + next))));
            if bvh.winding(after) < 0.5 {
                length = t * reach;
                hits_any = true;
                break;
            }
        }
        lengths.push(length);
    }
    if !hits_any {
        return None;
    }
    lengths.sort_by(f64::total_cmp);
    Some(lengths[lengths.len() / 2])
}

/// Largest distance (m) from the boundary of the solid {w ≥ ½} to the
/// boundary of the mesh, and where: over surface samples about `spacing`
/// apart that separate inside from outside (w ≥ ½ a little inside, < ½ a
/// little outside; parts of shells buried inside the solid do not count).
/// `mesh_boundary` holds the mesh's boundary triangles.
pub(crate) fn surface_gap(
    vertices: &[V3],
    triangles: &[[usize; 3]],
    bvh: &Bvh,
    mesh_boundary: &Bvh,
    spacing: f64,
) -> (f64, V3) {
    let samples = samples(vertices, triangles, spacing);
    samples
        .par_iter()
        .filter_map(|&(p, n, eps)| {
            let delta = 10.0 * eps;
            let separates =
                bvh.winding(sub(p, scale(n, delta))) >= 0.5 && bvh.winding(add(p, scale(n, delta))) < 0.5;
            separates.then(|| (mesh_boundary.distance(p), p))
        })
        .reduce(|| (0.0, [0.0; 3]), |a, b| if b.0 > a.0 { b } else { a })
}
