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
    let mut rays = WallRays::new(mesh);
    let (mut total, mut thin) = (0.0, Vec::new());
    for i in (0..mesh.len()).step_by(stride) {
        let p = &mesh.panels[i];
        total += p.area;
        if let Some((_, t)) = rays.across(i, THIN_WALL_RATIO * p.diameter) {
            thin.push((p.area, t, p.diameter));
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

/// The other face of a thin wall under each panel: for panel `i`, the
/// opposite-facing panel first crossed by the ray along `−n` from its
/// centroid, if it lies closer than `max_ratio` times the panel's diameter
/// ([`WallRays::across`]).
pub fn opposite_panels(mesh: &BoundaryMesh, max_ratio: f64) -> Vec<Option<usize>> {
    let mut rays = WallRays::new(mesh);
    (0..mesh.len()).map(|i| rays.across(i, max_ratio * mesh.panels[i].diameter).map(|(j, _)| j)).collect()
}

/// Rays into the body from panel centroids, against the panels bucketed in
/// a uniform grid of the median panel diameter: each short ray tests the
/// few panels near it, `O(N)` for a surface of similar panels (a test of
/// every panel per ray cost 1.13 s for 2 000 rays on a 64 656-panel goblet).
pub struct WallRays<'a> {
    mesh: &'a BoundaryMesh,
    grid: PanelGrid,
    /// Per panel, the last query that listed it (so each query lists a
    /// panel once, and a query never sees an earlier one's marks).
    stamp: Vec<u64>,
    query: u64,
    candidates: Vec<usize>,
}

impl<'a> WallRays<'a> {
    /// The grid of `mesh`'s panels.
    pub fn new(mesh: &'a BoundaryMesh) -> WallRays<'a> {
        WallRays {
            mesh,
            grid: PanelGrid::new(mesh),
            stamp: vec![0; mesh.len()],
            query: 0,
            candidates: Vec::new(),
        }
    }

    /// The wall under panel `i`: the nearest panel facing the other way
    /// (`n·n' < −½`, the wall's other face) that the ray along `−n` from the
    /// centroid crosses within `reach` [m], and the distance to it.
    pub fn across(&mut self, i: usize, reach: f64) -> Option<(usize, f64)> {
        let mesh = self.mesh;
        let p = &mesh.panels[i];
        let dir = p.normal.map(|x| -x);
        let end = [0, 1, 2].map(|k| p.centroid[k] + reach * dir[k]);
        self.candidates.clear();
        self.query += 1;
        self.grid.panels_near_segment(
            p.centroid,
            end,
            i,
            (&mut self.stamp, self.query),
            &mut self.candidates,
        );
        self.candidates
            .iter()
            .filter(|&&j| dot(mesh.panels[j].normal, p.normal) < -0.5)
            .filter_map(|&j| {
                let tri = mesh.panels[j].corners.map(|c| mesh.vertices[c]);
                ray_hits_triangle(p.centroid, dir, tri).filter(|&t| t > 0.0 && t < reach).map(|t| (j, t))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
    }
}

/// Panels bucketed by the grid cells their bounding boxes touch.
struct PanelGrid {
    origin: [f64; 3],
    cell: f64,
    dims: [usize; 3],
    start: Vec<usize>,
    list: Vec<usize>,
}

impl PanelGrid {
    fn new(mesh: &BoundaryMesh) -> PanelGrid {
        let mut diameters: Vec<(f64, f64)> = mesh.panels.iter().map(|p| (p.diameter, 1.0)).collect();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for v in &mesh.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let span = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        // At most ~64³ cells: a median below span/64 only lengthens the lists.
        let cell = modal_mesh::weighted_median(&mut diameters).max(span / 64.0);
        let dims = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / cell) as usize + 1).min(1 << 16));
        let cell_of = |x: f64, k: usize| (((x - lo[k]) / cell).floor().max(0.0) as usize).min(dims[k] - 1);
        let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        for (j, p) in mesh.panels.iter().enumerate() {
            let corners = p.corners.map(|c| mesh.vertices[c]);
            let range = |k: usize| {
                let (a, b) = corners
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| (a.min(c[k]), b.max(c[k])));
                cell_of(a, k)..=cell_of(b, k)
            };
            for x in range(0) {
                for y in range(1) {
                    for z in range(2) {
                        buckets[(x * dims[1] + y) * dims[2] + z].push(j);
                    }
                }
            }
        }
        let mut start = Vec::with_capacity(buckets.len() + 1);
        let mut list = Vec::new();
        for b in &buckets {
            start.push(list.len());
            list.extend_from_slice(b);
        }
        start.push(list.len());
        PanelGrid { origin: lo, cell, dims, start, list }
    }

    /// Appends to `out` each panel (other than `skip`) bucketed in a cell
    /// of the segment `a`–`b`'s bounding box, once (`stamp[j] = query`
    /// marks the panels this query has listed).
    fn panels_near_segment(
        &self,
        a: [f64; 3],
        b: [f64; 3],
        skip: usize,
        (stamp, query): (&mut [u64], u64),
        out: &mut Vec<usize>,
    ) {
        let cell_of = |x: f64, k: usize| {
            (((x - self.origin[k]) / self.cell).floor().max(0.0) as usize).min(self.dims[k] - 1)
        };
        let range = |k: usize| cell_of(a[k].min(b[k]), k)..=cell_of(a[k].max(b[k]), k);
        for x in range(0) {
            for y in range(1) {
                for z in range(2) {
                    let c = (x * self.dims[1] + y) * self.dims[2] + z;
                    for &j in &self.list[self.start[c]..self.start[c + 1]] {
                        if j != skip && stamp[j] != query {
                            stamp[j] = query;
                            out.push(j);
                        }
                    }
                }
            }
        }
    }
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

    /// The grid finds what a test of every panel finds: on a hollow ball
    /// (a wall 0.05 thick between spheres of radius 1 and 0.95) every
    /// panel's nearest opposite-facing crossing within 0.2, none within
    /// 0.04, and the same again when asked again.
    #[test]
    fn wall_rays_find_what_a_test_of_every_panel_finds() {
        let (v, t) = modal_mesh::icosphere(3);
        let mut vertices: Vec<[f64; 3]> = v.clone();
        vertices.extend(v.iter().map(|p| p.map(|x| 0.95 * x)));
        let mut triangles = t.clone();
        triangles.extend(t.iter().map(|&[a, b, c]| [a + v.len(), c + v.len(), b + v.len()]));
        let mesh = BoundaryMesh::new(vertices, &triangles).unwrap();
        let mut rays = WallRays::new(&mesh);
        for (i, p) in mesh.panels.iter().enumerate() {
            let dir = p.normal.map(|x| -x);
            let brute = (0..mesh.len())
                .filter(|&j| j != i && dot(mesh.panels[j].normal, p.normal) < -0.5)
                .filter_map(|j| {
                    let tri = mesh.panels[j].corners.map(|c| mesh.vertices[c]);
                    ray_hits_triangle(p.centroid, dir, tri).filter(|&t| t > 0.0 && t < 0.2).map(|t| (j, t))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            assert!(brute.is_some(), "panel {i} sees no wall");
            assert_eq!(rays.across(i, 0.2), brute, "panel {i}");
            assert_eq!(rays.across(i, 0.04), None, "panel {i}");
            assert_eq!(rays.across(i, 0.2), brute, "panel {i} asked again");
        }
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
