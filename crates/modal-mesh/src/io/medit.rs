//! Medit `.mesh` (ASCII) reader, the INRIA format also written by TetGen,
//! MMG and CGAL: keyword sections `Vertices` (`x y z ref` per line) and
//! `Tetrahedra` (`v1 v2 v3 v4 ref`, 1-based). Every other section
//! (`Triangles`, `Edges`, `Corners`, …) is skipped; comments start with `#`.

use super::cursor::Cursor;
use crate::{Cells, MeshError, TetMesh};

/// Reads a Medit mesh from the bytes of a `.mesh` file, multiplying
/// coordinates by `scale`.
pub fn read_medit(data: &[u8], scale: f64) -> Result<TetMesh, MeshError> {
    let mut cur = Cursor::new(data);
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    let mut tets: Vec<[usize; 4]> = Vec::new();
    let mut saw_header = false;
    loop {
        cur.skip_space_and_comments(b'#');
        let Some(keyword) = cur.token() else { break };
        let keyword = String::from_utf8_lossy(keyword).into_owned();
        match keyword.as_str() {
            "MeshVersionFormatted" => {
                cur.parse::<u32>("the mesh version")?;
                saw_header = true;
            }
            "Dimension" => {
                let dim: u32 = cur.parse("the dimension")?;
                if dim != 3 {
                    return Err(cur.error(format!("dimension {dim}; expected 3")));
                }
            }
            "Vertices" => {
                let count: u64 = cur.parse("the number of vertices")?;
                let count = cur.check_count(count, 8, "vertex")?;
                nodes.reserve(count);
                for v in 0..count {
                    let xyz = [
                        cur.parse::<f64>("an x coordinate")?,
                        cur.parse("a y coordinate")?,
                        cur.parse("a z coordinate")?,
                    ];
                    if !xyz.iter().all(|c| c.is_finite()) {
                        return Err(
                            cur.error(format!("vertex {} has a non-finite coordinate {xyz:?}", v + 1))
                        );
                    }
                    cur.parse::<i64>("a vertex reference")?;
                    nodes.push(xyz.map(|c| c * scale));
                }
            }
            "Tetrahedra" => {
                let count: u64 = cur.parse("the number of tetrahedra")?;
                let count = cur.check_count(count, 10, "tetrahedron")?;
                tets.reserve(count);
                for e in 0..count {
                    let mut t = [0usize; 4];
                    for slot in &mut t {
                        let v: usize = cur.parse("a vertex number")?;
                        if v == 0 {
                            return Err(cur.error(format!(
                                "tetrahedron {} references vertex 0 (vertices are 1-based)",
                                e + 1
                            )));
                        }
                        *slot = v - 1;
                    }
                    cur.parse::<i64>("a tetrahedron reference")?;
                    tets.push(t);
                }
            }
            "End" => break,
            k if k.starts_with(|c: char| c.is_ascii_alphabetic()) => skip_section(&mut cur),
            k => {
                let shown: String = k.chars().take(40).collect();
                return Err(cur.error(format!("expected a section keyword, found `{shown}`")));
            }
        }
    }
    if !saw_header {
        return Err(MeshError::Syntax {
            at: crate::Location::Line(1),
            message: "not a Medit file: no `MeshVersionFormatted`".into(),
        });
    }
    if tets.is_empty() {
        return Err(MeshError::NoTets);
    }
    if let Some((e, &n)) = tets
        .iter()
        .enumerate()
        .flat_map(|(e, t)| t.iter().map(move |n| (e, n)))
        .find(|(_, &n)| n >= nodes.len())
    {
        return Err(MeshError::NodeOutOfRange { element: e, node: n, node_count: nodes.len() });
    }
    Ok(TetMesh { nodes, cells: Cells::Tet4(tets), groups: Vec::new() })
}

/// Skips the numbers of an unknown section, up to the next keyword.
fn skip_section(cur: &mut Cursor<'_>) {
    loop {
        cur.skip_space_and_comments(b'#');
        let before = cur.remaining();
        match cur.token() {
            Some(t) if t[0].is_ascii_alphabetic() => {
                cur.unread(before);
                return;
            }
            Some(_) => {}
            None => return,
        }
    }
}
