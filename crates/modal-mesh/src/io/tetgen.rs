//! TetGen `.node` / `.ele` reader (TetGen manual, section "File formats").
//!
//! `.node`: `<#points> <dim = 3> <#attributes> <#boundary markers 0|1>`, then
//! `<point #> <x> <y> <z> [attributes] [marker]`. `.ele`:
//! `<#tets> <nodes per tet 4|10> <#attributes>`, then
//! `<tet #> <node> … [attributes]`. Lines starting with `#` are comments.
//! Point numbers may start at 0 or 1 (whatever the `.node` file uses);
//! elements refer to them by number.
//!
//! 10-node tets (`tetgen -o2`): TetGen's `highorder()` puts each extra node
//! at the exact midpoint of an edge, in an order that follows its internal
//! edge enumeration. Rather than trust a fixed order, the reader assigns
//! each of the six extra nodes to the edge whose midpoint it coincides with
//! (to 1e-6 of the tet's longest edge) and stores them in our
//! [`crate::TET10_EDGES`] order; a node that sits on no edge midpoint is an
//! error naming the element.

use std::collections::HashMap;

use super::cursor::Cursor;
use crate::{Cells, MeshError, TetMesh, TET10_EDGES};

/// Reads a TetGen mesh from the contents of its `.node` and `.ele` files,
/// multiplying coordinates by `scale`.
pub fn read_tetgen(node_file: &[u8], ele_file: &[u8], scale: f64) -> Result<TetMesh, MeshError> {
    let (nodes, number_of) = read_node_file(node_file, scale)?;
    let mut cur = Cursor::new(ele_file);
    cur.skip_space_and_comments(b'#');
    let count: u64 = cur.parse("the number of tetrahedra")?;
    let per: usize = cur.parse("the number of nodes per tetrahedron")?;
    let n_attr: usize = cur.parse("the number of element attributes")?;
    if per != 4 && per != 10 {
        return Err(cur.error(format!("{per} nodes per tetrahedron; expected 4 or 10")));
    }
    let count = cur.check_count(count, 2 * (1 + per + n_attr.min(1 << 20)), "tetrahedron")?;
    let mut tet4 = Vec::new();
    let mut tet10 = Vec::new();
    for e in 0..count {
        cur.skip_space_and_comments(b'#');
        cur.parse::<i64>("a tetrahedron number")?;
        let mut t = Vec::with_capacity(per);
        for _ in 0..per {
            let number: i64 = cur.parse("a node number")?;
            let index = number_of.get(&number).copied().ok_or_else(|| {
                cur.error(format!(
                    "tetrahedron {e} references node number {number}, which is not in the .node file"
                ))
            })?;
            t.push(index);
        }
        for _ in 0..n_attr {
            cur.parse::<f64>("an element attribute")?;
        }
        if per == 4 {
            tet4.push([t[0], t[1], t[2], t[3]]);
        } else {
            tet10.push(order_tet10(&nodes, &t).map_err(|node| {
                cur.error(format!(
                    "10-node tetrahedron {e}: node {node} is not at the midpoint of a free edge"
                ))
            })?);
        }
    }
    let cells = if per == 4 { Cells::Tet4(tet4) } else { Cells::Tet10(tet10) };
    if cells.is_empty() {
        return Err(MeshError::NoTets);
    }
    Ok(TetMesh { nodes, cells, groups: Vec::new() })
}

/// Node coordinates and the map point number → node index.
type NodeFile = (Vec<[f64; 3]>, HashMap<i64, usize>);

/// Reads the `.node` file: node coordinates and point number → index.
fn read_node_file(data: &[u8], scale: f64) -> Result<NodeFile, MeshError> {
    let mut cur = Cursor::new(data);
    cur.skip_space_and_comments(b'#');
    let count: u64 = cur.parse("the number of points")?;
    let dim: usize = cur.parse("the dimension")?;
    let n_attr: usize = cur.parse("the number of point attributes")?;
    let n_mark: usize = cur.parse("the number of boundary markers")?;
    if dim != 3 {
        return Err(cur.error(format!("dimension {dim}; expected 3")));
    }
    if n_mark > 1 {
        return Err(cur.error(format!("{n_mark} boundary markers; expected 0 or 1")));
    }
    let count = cur.check_count(count, 2 * (4 + n_attr.min(1 << 20) + n_mark), "point")?;
    let mut nodes = Vec::with_capacity(count);
    let mut number_of = HashMap::with_capacity(count);
    for index in 0..count {
        cur.skip_space_and_comments(b'#');
        let number: i64 = cur.parse("a point number")?;
        let xyz = [
            cur.parse::<f64>("an x coordinate")?,
            cur.parse("a y coordinate")?,
            cur.parse("a z coordinate")?,
        ];
        if !xyz.iter().all(|c| c.is_finite()) {
            return Err(cur.error(format!("point number {number} has a non-finite coordinate {xyz:?}")));
        }
        for _ in 0..n_attr {
            cur.parse::<f64>("a point attribute")?;
        }
        for _ in 0..n_mark {
            cur.parse::<i64>("a boundary marker")?;
        }
        if number_of.insert(number, index).is_some() {
            return Err(cur.error(format!("point number {number} appears twice")));
        }
        nodes.push(xyz.map(|c| c * scale));
    }
    Ok((nodes, number_of))
}

/// Puts the six extra nodes of a TetGen 10-node tet in our edge order by
/// matching each to the edge midpoint it sits on; `Err(node)` names a node
/// that fits no free edge.
fn order_tet10(nodes: &[[f64; 3]], t: &[usize]) -> Result<[usize; 10], usize> {
    let corner = |k: usize| nodes[t[k]];
    let dist2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>();
    let longest = TET10_EDGES.iter().map(|&[a, b]| dist2(corner(a), corner(b))).fold(0.0, f64::max);
    let tolerance = 1e-12 * longest;
    let mut out = [usize::MAX; 10];
    out[..4].copy_from_slice(&t[..4]);
    for &extra in &t[4..] {
        let p = nodes[extra];
        let edge = TET10_EDGES.iter().position(|&[a, b]| {
            let m = [0, 1, 2].map(|c| 0.5 * (corner(a)[c] + corner(b)[c]));
            dist2(p, m) <= tolerance
        });
        match edge {
            Some(e) if out[4 + e] == usize::MAX => out[4 + e] = extra,
            _ => return Err(extra),
        }
    }
    Ok(out)
}
