//! Curved generator shapes: cylinder, tube, sphere and bowl, each a
//! multi-block mapped mesh (see [`super::mapped`]).
//!
//! - sphere (centre at the origin): an O-grid — a central cube of half-size
//!   0.4 R in q-space plus six shell blocks whose grid lines follow rays
//!   from the centre, mapped onto the ball by [`ogrid`];
//! - cylinder (axis z, base at z = 0): the 2D O-grid of the disk (a square
//!   core plus four shell blocks) extruded along z;
//! - tube: one polar block (θ periodic, z, r);
//! - bowl (hemispherical shell, centre of curvature at the origin, opening
//!   towards +z, rim at z = 0): the disk O-grid lifted onto the hemisphere
//!   (polar angle proportional to the disk radius), extruded through the
//!   thickness.
//!
//! Element size `h`: shell blocks get `ceil(π R / (4 h))` cells across each
//! half of a 90° sector, so boundary cells are about `h` wide; radial and
//! axial directions get `ceil(length / h)` cells (at least one). Every
//! function validates its lengths (finite, positive, inner below outer) and
//! `order` (1 or 2) and caps the tet count at [`super::MAX_GENERATED_TETS`].

use std::f64::consts::PI;

use super::mapped::{self, linspace, mid, ogrid, positive, smaller, total_tets, Block, BlockMesh};
use super::{ElementSizes, Shape};
use crate::{MeshError, TetMesh};

/// Half-size of the O-grid's core box in q-space (the unit ball has radius 1).
const CORE: f64 = 0.4;

/// Cells needed to cover `length` with cells of size about `h` (≥ 1),
/// capped so a huge ratio cannot overflow (the tet-count check rejects it).
pub(crate) fn cells_for(length: f64, h: f64) -> usize {
    (length / h).ceil().clamp(1.0, 1e7) as usize
}

/// An O-grid resolution: `core` cells across each half of the core box,
/// `shell` cells radially through the shell blocks.
#[derive(Clone, Copy)]
struct OGrid {
    core: usize,
    shell: usize,
}

impl OGrid {
    /// Resolution for a disk/ball of radius `radius` (or arc length
    /// `π radius / 2` from centre to rim) at element size `h`.
    fn new(radius: f64, h: f64) -> Self {
        OGrid { core: cells_for(PI * radius / 4.0, h), shell: cells_for((1.0 - CORE) * radius, h) }
    }

    /// Tangential fraction −1..1 of grid line `i` of `2 core` cells.
    fn frac(self, i: usize) -> f64 {
        -1.0 + i as f64 / self.core as f64
    }

    /// q-space max-norm of shell level `k` (CORE at k = 0, 1 at the surface).
    fn level(self, k: usize) -> f64 {
        if k == self.shell {
            1.0
        } else {
            CORE + (1.0 - CORE) * k as f64 / self.shell as f64
        }
    }

    /// Disk O-grid blocks in the (x, y) plane extruded through `zs`.
    /// Core local axes (x, y, z); shell blocks (tangential, z, radial).
    fn disk_blocks(self, zs: &[f64]) -> Vec<Block<'_>> {
        let nz = zs.len() - 1;
        let n = 2 * self.core;
        let mut blocks = vec![Block {
            cells: [n, n, nz],
            point: Box::new(move |i, j, l| [CORE * self.frac(i), CORE * self.frac(j), zs[l]]),
        }];
        for (axis, sign) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)] {
            blocks.push(Block {
                cells: [n, nz, self.shell],
                point: Box::new(move |i, l, k| {
                    let r = self.level(k);
                    let t = r * self.frac(i);
                    if axis == 0 {
                        [sign * r, t, zs[l]]
                    } else {
                        [t, sign * r, zs[l]]
                    }
                }),
            });
        }
        blocks
    }

    /// Ball O-grid blocks. Core local axes (x, y, z); shell block normal to
    /// axis `a`: (the other two axes in increasing order, radial).
    fn ball_blocks(self) -> Vec<Block<'static>> {
        let n = 2 * self.core;
        let mut blocks = vec![Block {
            cells: [n, n, n],
            point: Box::new(move |i, j, l| [self.frac(i), self.frac(j), self.frac(l)].map(|f| CORE * f)),
        }];
        for axis in 0..3 {
            for sign in [1.0, -1.0] {
                blocks.push(Block {
                    cells: [n, n, self.shell],
                    point: Box::new(move |i, j, k| {
                        let r = self.level(k);
                        let mut tangential = [r * self.frac(i), r * self.frac(j)].into_iter();
                        let mut q = [0.0; 3];
                        for (c, x) in q.iter_mut().enumerate() {
                            *x = if c == axis { sign * r } else { tangential.next().unwrap_or(0.0) };
                        }
                        q
                    }),
                });
            }
        }
        blocks
    }
}

/// Solid cylinder of `radius` and `length` (m) along z from z = 0.
pub fn cylinder(radius: f64, length: f64, h: f64, order: u8) -> Result<TetMesh, MeshError> {
    positive("radius", radius)?;
    positive("length", length)?;
    positive("h", h)?;
    let zs = linspace(0.0, length, cells_for(length, h));
    let map = |q: [f64; 3]| {
        let [x, y] = ogrid([q[0], q[1]], CORE);
        [radius * x, radius * y, q[2]]
    };
    let mesh = BlockMesh { blocks: OGrid::new(radius, h).disk_blocks(&zs), map: &map, midpoint: &mid };
    mesh.build(order)
}

/// Tube (hollow cylinder) with radii `inner < outer` and `length` (m)
/// along z from z = 0. q-space is physical space; quadratic mid-edge nodes
/// are placed by averaging in cylindrical coordinates, so they stay on the
/// walls.
pub fn tube(inner: f64, outer: f64, length: f64, h: f64, order: u8) -> Result<TetMesh, MeshError> {
    tube_sized(inner, outer, length, h, h, order)
}

/// [`tube`] with cells of about `h` around and through the wall and
/// `axial_h` along the axis (a long thin tube needs cells near its wall
/// thickness around it, not along it).
pub fn tube_sized(
    inner: f64,
    outer: f64,
    length: f64,
    h: f64,
    axial_h: f64,
    order: u8,
) -> Result<TetMesh, MeshError> {
    positive("inner_radius", inner)?;
    positive("outer_radius", outer)?;
    positive("length", length)?;
    positive("h", h)?;
    positive("axial h", axial_h)?;
    smaller("inner_radius", inner, "outer_radius", outer)?;
    let (around, radii, zs) = tube_grid(inner, outer, length, h, axial_h);
    let (radii, zs) = (&radii, &zs);
    let block = Block {
        cells: [around, zs.len() - 1, radii.len() - 1],
        point: Box::new(move |i, l, k| {
            let theta = 2.0 * PI * (i % around) as f64 / around as f64;
            [radii[k] * theta.cos(), radii[k] * theta.sin(), zs[l]]
        }),
    };
    let midpoint = |a: [f64; 3], b: [f64; 3]| {
        let (ta, mut tb) = (a[1].atan2(a[0]), b[1].atan2(b[0]));
        if tb - ta > PI {
            tb -= 2.0 * PI;
        } else if ta - tb > PI {
            tb += 2.0 * PI;
        }
        let (theta, r) = (0.5 * (ta + tb), 0.5 * (a[0].hypot(a[1]) + b[0].hypot(b[1])));
        [r * theta.cos(), r * theta.sin(), 0.5 * (a[2] + b[2])]
    };
    let mesh = BlockMesh { blocks: vec![block], map: &|q| q, midpoint: &midpoint };
    mesh.build(order)
}

/// The tube's cells around, and its radii and heights of grid lines.
fn tube_grid(inner: f64, outer: f64, length: f64, h: f64, axial_h: f64) -> (usize, Vec<f64>, Vec<f64>) {
    let around = cells_for(PI * (inner + outer), h).max(8);
    (
        around,
        linspace(inner, outer, cells_for(outer - inner, h)),
        linspace(0.0, length, cells_for(length, axial_h)),
    )
}

/// The bowl's O-grid (its disk radius 1 maps to the arc π R_mid / 2 from
/// bottom to rim) and its levels through the wall.
fn bowl_grid(radius: f64, thickness: f64, h: f64) -> (OGrid, Vec<f64>) {
    (OGrid::new(0.5 * PI * (radius - 0.5 * thickness), h), linspace(0.0, 1.0, cells_for(thickness, h)))
}

/// Tets the generator makes for `shape` at `sizes` (the same cell counts,
/// no mesh built; saturating).
pub(crate) fn tet_count(shape: &Shape, sizes: ElementSizes) -> u64 {
    let h = sizes.h;
    match *shape {
        Shape::Box { size } => mapped::tet_count(size.map(|s| cells_for(s, h))),
        Shape::Cylinder { radius, length } => {
            let zs = linspace(0.0, length, cells_for(length, h));
            let blocks = OGrid::new(radius, h).disk_blocks(&zs);
            total_tets(&blocks)
        }
        Shape::Tube { inner_radius, outer_radius, length } => {
            let (around, radii, zs) = tube_grid(inner_radius, outer_radius, length, h, sizes.axial);
            mapped::tet_count([around, zs.len() - 1, radii.len() - 1])
        }
        Shape::Sphere { radius } => total_tets(&OGrid::new(radius, h).ball_blocks()),
        Shape::Bowl { radius, thickness } => {
            let (grid, ws) = bowl_grid(radius, thickness, h);
            let blocks = grid.disk_blocks(&ws);
            total_tets(&blocks)
        }
    }
}

/// Solid ball of `radius` (m) centred at the origin.
pub fn sphere(radius: f64, h: f64, order: u8) -> Result<TetMesh, MeshError> {
    positive("radius", radius)?;
    positive("h", h)?;
    let map = |q: [f64; 3]| ogrid(q, CORE).map(|x| radius * x);
    let mesh = BlockMesh { blocks: OGrid::new(radius, h).ball_blocks(), map: &map, midpoint: &mid };
    mesh.build(order)
}

/// Hemispherical shell of outer `radius` and `thickness` (m): the points
/// with `radius − thickness ≤ |x| ≤ radius` and `z ≤ 0` (a bowl opening
/// upwards, its rim in the plane z = 0).
pub fn bowl(radius: f64, thickness: f64, h: f64, order: u8) -> Result<TetMesh, MeshError> {
    positive("radius", radius)?;
    positive("thickness", thickness)?;
    positive("h", h)?;
    smaller("thickness", thickness, "the radius", radius)?;
    let inner = radius - thickness;
    let (grid, ws) = bowl_grid(radius, thickness, h);
    let map = |q: [f64; 3]| {
        let d = ogrid([q[0], q[1]], CORE);
        let rho = d[0].hypot(d[1]);
        let polar = 0.5 * PI * rho;
        // sin(polar)/rho → π/2 at the bottom point.
        let lateral = if rho > 1e-12 { polar.sin() / rho } else { 0.5 * PI };
        let r = inner + thickness * q[2];
        [r * lateral * d[0], r * lateral * d[1], -r * polar.cos()]
    };
    let mesh = BlockMesh { blocks: grid.disk_blocks(&ws), map: &map, midpoint: &mid };
    mesh.build(order)
}
