//! Multi-block structured meshes in a parameter space ("q-space"), split
//! into Kuhn tets and mapped to physical space by a smooth function.
//!
//! Each block is a structured grid of `cells[0] × cells[1] × cells[2]`
//! cells with local axes (u, v, w); every cell is split by the same six-tet
//! Kuhn template around its local diagonal (0,0,0) → (1,1,1). On a cell
//! face normal to one local axis, the template's face diagonal joins the
//! (low, low) and (high, high) corners of the other two axes. Blocks meet
//! conformingly when, on every shared face, both blocks' local axes run in
//! the same directions — the shapes below choose their axes so (tangential
//! coordinates in increasing global order, the radial axis last and
//! outward). Nodes shared by blocks are merged by the exact bits of their
//! q-space position, which the shapes compute with identical formulas.
//!
//! A block's map has a Jacobian of constant sign, so one flip per block
//! (decided on its first tet) makes every physical tet positive. Quadratic
//! meshes place each mid-edge node at `map(midpoint(q_a, q_b))`, so mid-edge
//! nodes of boundary edges lie on the true curved surface.

use std::collections::HashMap;

use super::boxes::KUHN_TETS;
use crate::validate::volume6;
use crate::{to_quadratic_with, Cells, MeshError, TetMesh};

/// Largest tet count a generator will produce.
pub const MAX_GENERATED_TETS: u64 = 4_000_000;

/// One structured block: cell counts along its local axes and the q-space
/// position of local grid node (i, j, k).
pub(crate) struct Block<'a> {
    pub cells: [usize; 3],
    pub point: Box<dyn Fn(usize, usize, usize) -> [f64; 3] + 'a>,
}

/// Blocks plus the q-space → physical map and the q-space edge midpoint.
pub(crate) struct BlockMesh<'a> {
    pub blocks: Vec<Block<'a>>,
    pub map: &'a dyn Fn([f64; 3]) -> [f64; 3],
    pub midpoint: &'a dyn Fn([f64; 3], [f64; 3]) -> [f64; 3],
}

/// Arithmetic midpoint.
pub(crate) fn mid(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|c| 0.5 * (a[c] + b[c]))
}

/// Errors when `count` tets would exceed [`MAX_GENERATED_TETS`].
pub(crate) fn check_count(count: u64) -> Result<(), MeshError> {
    if count > MAX_GENERATED_TETS {
        return Err(MeshError::TooManyElements { count, limit: MAX_GENERATED_TETS });
    }
    Ok(())
}

/// Tets of a grid with these cell counts, saturating.
pub(crate) fn tet_count(cells: [usize; 3]) -> u64 {
    cells.iter().fold(6u64, |acc, &n| acc.saturating_mul(n as u64))
}

/// Tets of all `blocks`, saturating.
pub(crate) fn total_tets(blocks: &[Block<'_>]) -> u64 {
    blocks.iter().fold(0u64, |acc, b| acc.saturating_add(tet_count(b.cells)))
}

/// Errors unless `order` is 1 or 2.
pub(crate) fn check_order(order: u8) -> Result<(), MeshError> {
    if order == 1 || order == 2 {
        Ok(())
    } else {
        Err(MeshError::InvalidParameter { name: "order", message: format!("{order}; expected 1 or 2") })
    }
}

impl BlockMesh<'_> {
    /// Builds the mesh at element order 1 or 2.
    pub fn build(&self, order: u8) -> Result<TetMesh, MeshError> {
        check_order(order)?;
        let total = total_tets(&self.blocks);
        check_count(total)?;
        let template = oriented_template();
        let mut param: Vec<[f64; 3]> = Vec::new();
        let mut index_of: HashMap<[u64; 3], usize> = HashMap::new();
        let mut tets: Vec<[usize; 4]> = Vec::with_capacity(total as usize);
        for block in &self.blocks {
            let [nu, nv, nw] = block.cells;
            let mut local = Vec::with_capacity((nu + 1) * (nv + 1) * (nw + 1));
            for k in 0..=nw {
                for j in 0..=nv {
                    for i in 0..=nu {
                        let q = (block.point)(i, j, k).map(|x| if x == 0.0 { 0.0 } else { x });
                        let next = param.len();
                        let id = *index_of.entry(q.map(f64::to_bits)).or_insert(next);
                        if id == next {
                            param.push(q);
                        }
                        local.push(id);
                    }
                }
            }
            let node = |i: usize, j: usize, k: usize| local[i + (nu + 1) * (j + (nv + 1) * k)];
            let first = tets.len();
            for k in 0..nw {
                for j in 0..nv {
                    for i in 0..nu {
                        let corner = |c: usize| node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                        tets.extend(template.iter().map(|t| t.map(corner)));
                    }
                }
            }
            let block_tets = &mut tets[first..];
            if let Some(&t) = block_tets.first() {
                if volume6(&t.map(|n| (self.map)(param[n])), [0, 1, 2, 3]) < 0.0 {
                    block_tets.iter_mut().for_each(|t| t.swap(2, 3));
                }
            }
        }
        let in_param = TetMesh { nodes: param, cells: Cells::Tet4(tets), groups: Vec::new() };
        let mut mesh = if order == 2 { to_quadratic_with(&in_param, self.midpoint) } else { in_param };
        mesh.nodes.iter_mut().for_each(|p| *p = (self.map)(*p));
        Ok(mesh)
    }
}

/// The Kuhn template, each tet positively oriented in local index space.
fn oriented_template() -> [[usize; 4]; 6] {
    let unit: Vec<[f64; 3]> =
        (0..8).map(|c| [(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]).collect();
    KUHN_TETS.map(|mut t| {
        if volume6(&unit, t) < 0.0 {
            t.swap(2, 3);
        }
        t
    })
}

/// `n` equal steps from `a` to `b` (`n + 1` values, both ends exact).
pub(crate) fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|i| if i == n { b } else { a + (b - a) * i as f64 / n as f64 }).collect()
}

/// O-grid map of q-space onto the unit ball (D = 3) or disk (D = 2):
/// identity on the core box `|q|∞ ≤ a`; outside it, along each ray from
/// the centre, a linear blend from the core box's surface (`t = 0`) to the
/// unit sphere (`t = 1`), `t = (|q|∞ − a)/(1 − a)`. Injective for
/// `a < 1/√D`; rays map to rays.
pub(crate) fn ogrid<const D: usize>(q: [f64; D], a: f64) -> [f64; D] {
    let m = q.iter().fold(0.0f64, |acc, x| acc.max(x.abs()));
    if m <= a {
        return q;
    }
    let s = q.map(|x| x / m);
    let norm = s.iter().map(|x| x * x).sum::<f64>().sqrt();
    let t = (m - a) / (1.0 - a);
    let factor = a * (1.0 - t) + t / norm;
    s.map(|x| x * factor)
}

/// Lengths a generated shape takes [m]: a 1 µm bead to a 10 km span. Beyond
/// them a typo (`1e300`, `1e-300`) made a mesh whose sizes printed as 300
/// digits, or as 0, and whose solve then failed on its degenerate or
/// infinite size.
pub const LENGTH_RANGE_M: std::ops::RangeInclusive<f64> = 1e-6..=1e4;

/// Errors unless `value` is a finite positive length in [`LENGTH_RANGE_M`].
pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), MeshError> {
    if !(value.is_finite() && value > 0.0) {
        return Err(MeshError::InvalidParameter {
            name,
            message: format!("{value} is not a finite positive length"),
        });
    }
    if !LENGTH_RANGE_M.contains(&value) {
        return Err(MeshError::InvalidParameter {
            name,
            message: format!(
                "{value:e} m is outside the lengths a generated shape takes, {:e} ..= {:e} m",
                LENGTH_RANGE_M.start(),
                LENGTH_RANGE_M.end()
            ),
        });
    }
    Ok(())
}

/// Errors unless `small < large`.
pub(crate) fn smaller(name: &'static str, small: f64, other: &str, large: f64) -> Result<(), MeshError> {
    if small < large {
        Ok(())
    } else {
        Err(MeshError::InvalidParameter {
            name,
            message: format!("{small} m must be smaller than {other} {large} m"),
        })
    }
}
