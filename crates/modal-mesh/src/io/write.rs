//! Gmsh MSH 4.1 ASCII writer (readable by Gmsh and meshio).
//!
//! Layout: `$MeshFormat 4.1 0 8`, `$PhysicalNames` (when the mesh has
//! groups), `$Entities` with one volume entity per distinct set of groups a
//! tet belongs to, one `$Nodes` block (tags `1..=N` in mesh order, so node
//! `i` gets tag `i + 1`) and one `$Elements` block per volume entity
//! (type 4 or 11; 10-node tets written in Gmsh's node order). Coordinates
//! use Rust's shortest round-trip formatting, so reading back is exact.

use std::collections::BTreeMap;
use std::io::{self, Write};
use std::path::Path;

use super::msh::GMSH_TET10;
use crate::{Cells, MeshError, TetMesh};

/// Writes `mesh` as Gmsh MSH 4.1 ASCII.
pub fn write_msh41(mesh: &TetMesh, mut out: impl Write) -> io::Result<()> {
    let entities = volume_entities(mesh);
    writeln!(out, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    if !mesh.groups.is_empty() {
        writeln!(out, "$PhysicalNames\n{}", mesh.groups.len())?;
        for g in &mesh.groups {
            writeln!(out, "3 {} \"{}\"", g.tag, g.name.replace('"', "'"))?;
        }
        writeln!(out, "$EndPhysicalNames")?;
    }
    let (lo, hi) = bounding_box(&mesh.nodes);
    writeln!(out, "$Entities\n0 0 0 {}", entities.len())?;
    for (e, (physicals, _)) in entities.iter().enumerate() {
        write!(
            out,
            "{} {:e} {:e} {:e} {:e} {:e} {:e} {}",
            e + 1,
            lo[0],
            lo[1],
            lo[2],
            hi[0],
            hi[1],
            hi[2],
            physicals.len()
        )?;
        for p in physicals {
            write!(out, " {p}")?;
        }
        writeln!(out, " 0")?;
    }
    writeln!(out, "$EndEntities")?;
    let n = mesh.nodes.len();
    writeln!(out, "$Nodes\n1 {n} 1 {n}\n3 1 0 {n}")?;
    for i in 1..=n {
        writeln!(out, "{i}")?;
    }
    for p in &mesh.nodes {
        writeln!(out, "{:e} {:e} {:e}", p[0], p[1], p[2])?;
    }
    writeln!(out, "$EndNodes")?;
    let count = mesh.cells.len();
    writeln!(out, "$Elements\n{} {count} 1 {count}", entities.len())?;
    let (kind, gmsh_order): (u8, &[usize]) = match mesh.cells {
        Cells::Tet4(_) => (4, &GMSH_TET10[..4]),
        Cells::Tet10(_) => (11, &GMSH_TET10),
    };
    let mut tag = 0;
    for (e, (_, cells)) in entities.iter().enumerate() {
        writeln!(out, "3 {} {kind} {}", e + 1, cells.len())?;
        for &c in cells {
            tag += 1;
            let nodes = mesh.cells.nodes_of(c);
            write!(out, "{tag}")?;
            for &k in gmsh_order {
                write!(out, " {}", nodes[k] + 1)?;
            }
            writeln!(out)?;
        }
    }
    writeln!(out, "$EndElements")?;
    out.flush()
}

/// Writes `mesh` to `path` atomically: a temporary file in the same
/// directory is written, synced and renamed over `path`.
pub fn write_msh41_file(path: &Path, mesh: &TetMesh) -> Result<(), MeshError> {
    let io_error = |e: io::Error| MeshError::Io { path: path.display().to_string(), message: e.to_string() };
    let name = path.file_name().ok_or_else(|| io_error(io::Error::other("not a file path")))?;
    let tmp = path.with_file_name(format!(".{}.tmp{}", name.to_string_lossy(), std::process::id()));
    let result = (|| {
        let file = std::fs::File::create(&tmp)?;
        let mut writer = io::BufWriter::new(file);
        write_msh41(mesh, &mut writer)?;
        writer.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(io_error)
}

/// Groups cells by the (sorted) set of physical tags they carry; each set
/// becomes one Gmsh volume entity. Cells in no group share an entity with
/// no physical tags.
fn volume_entities(mesh: &TetMesh) -> Vec<(Vec<i32>, Vec<usize>)> {
    let n = mesh.cells.len();
    let mut tags_of: Vec<Vec<i32>> = vec![Vec::new(); n];
    for g in &mesh.groups {
        for &c in g.cells.iter().filter(|&&c| c < n) {
            tags_of[c].push(g.tag);
        }
    }
    let mut entities: BTreeMap<Vec<i32>, Vec<usize>> = BTreeMap::new();
    for (c, mut tags) in tags_of.into_iter().enumerate() {
        tags.sort_unstable();
        tags.dedup();
        entities.entry(tags).or_default().push(c);
    }
    entities.into_iter().collect()
}

/// Axis-aligned bounding box `(min, max)` of points (zeros when empty).
pub fn bounding_box(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    if points.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    crate::bounding_box(points.iter().copied())
}
