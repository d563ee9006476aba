//! Boundary surface of a tet mesh: the faces that belong to exactly one tet.
//!
//! Faces are matched by their corner nodes, and then once more by their
//! corners' positions: two boundary faces on the same three points (a
//! mesher's cut points computed twice, a hair's breadth apart) are the two
//! sides of an internal crack, not surface. Kept, they put panels of
//! opposite normals at zero distance, where a boundary-element solve's
//! kernels blow up (a glass mug's handle root gave matrix entries of 10³⁷).
//!
//! A closed component of boundary faces that encloses negative volume faces
//! into what it encloses: the wall of a sealed cavity (a hollow ball's
//! inside). No sound leaves a sealed cavity, so it is not surface either:
//! kept, a boundary-element solve would also solve the cavity's air, which
//! resonates (the interior Neumann problem: a 4.7 cm cavity at 2.4 kHz and
//! on), and a struck point could snap to it.
//!
//! For a positively oriented tet `[0, 1, 2, 3]` the faces
//! `[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]` (opposite corners 0..3) have
//! counter-clockwise corners seen from outside, i.e. the normal
//! `(b − a) × (c − a)` points out of the tet; boundary faces keep that
//! orientation, so the surface normals point out of the body.

use std::collections::HashMap;

use crate::validate::{cross, dot, find, sub};
use crate::{Cells, Surface, TetMesh, TET10_EDGES};

/// Outward faces of a positive tet, as local corner indices.
const TET_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// Local index (4..10) of the mid-edge node between corners `a` and `b`.
fn edge_slot(a: usize, b: usize) -> usize {
    let e = TET10_EDGES.iter().position(|&[p, q]| (p == a && q == b) || (p == b && q == a));
    4 + e.expect("corners of a tet edge")
}

/// Corner nodes of face `id` (`4·tet + face`), outward for a positive tet.
fn face_corners(mesh: &TetMesh, id: usize) -> [usize; 3] {
    TET_FACES[id % 4].map(|k| mesh.cells.corners(id / 4)[k])
}

/// Nodes closer than this times the bounding-box diagonal are one point
/// when matching boundary faces (module doc).
pub const COINCIDENT_NODE_TOLERANCE: f64 = 1e-10;

/// Clears `on_boundary` (indexed `4·tet + face`) for every boundary face
/// that shares its three corner positions, within
/// [`COINCIDENT_NODE_TOLERANCE`], with another boundary face.
fn drop_coincident_faces(mesh: &TetMesh, on_boundary: &mut [bool]) {
    let ids: Vec<usize> = (0..on_boundary.len()).filter(|&id| on_boundary[id]).collect();
    let mut nodes: Vec<usize> = ids.iter().flat_map(|&id| face_corners(mesh, id)).collect();
    nodes.sort_unstable();
    nodes.dedup();
    let point = |n: usize| mesh.nodes[n];
    let (lo, hi) = crate::bounding_box(nodes.iter().map(|&n| point(n)));
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let tol = COINCIDENT_NODE_TOLERANCE * diagonal;
    if !(tol > 0.0 && tol.is_finite()) {
        return;
    }
    // Each node's representative: the first node (in index order) within
    // `tol`, found in the 27 grid cells of side `tol` around it.
    let cell = |p: [f64; 3]| p.map(|x| (x / tol).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut representative = vec![usize::MAX; mesh.nodes.len()];
    let mut merged = false;
    for &n in &nodes {
        let (p, c) = (point(n), cell(point(n)));
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &m in grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]).into_iter().flatten() {
                        let d = sub(point(m), p);
                        if dot(d, d) <= tol * tol {
                            found = Some(m);
                            break 'search;
                        }
                    }
                }
            }
        }
        match found {
            Some(m) => {
                representative[n] = representative[m];
                merged = true;
            }
            None => {
                representative[n] = n;
                grid.entry(c).or_default().push(n);
            }
        }
    }
    if !merged {
        return;
    }
    let mut keyed: Vec<([usize; 3], usize)> = ids
        .iter()
        .map(|&id| {
            let mut key = face_corners(mesh, id).map(|n| representative[n]);
            key.sort_unstable();
            (key, id)
        })
        .collect();
    keyed.sort_unstable();
    for run in keyed.chunk_by(|a, b| a.0 == b.0).filter(|run| run.len() > 1) {
        for &(_, id) in run {
            on_boundary[id] = false;
        }
    }
}

/// Clears `on_boundary` (indexed `4·tet + face`) for every face of a
/// boundary component (faces joined by shared corner edges) whose signed
/// volume `Σ a·(b × c)/6` is negative: a sealed cavity's wall (module doc).
fn drop_cavity_walls(mesh: &TetMesh, on_boundary: &mut [bool]) {
    let ids: Vec<usize> = (0..on_boundary.len()).filter(|&id| on_boundary[id]).collect();
    // Union–find over the faces, joined through their shared edges.
    let mut parent: Vec<usize> = (0..ids.len()).collect();
    let mut edges: Vec<((usize, usize), usize)> = Vec::with_capacity(3 * ids.len());
    for (i, &id) in ids.iter().enumerate() {
        let c = face_corners(mesh, id);
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            edges.push(((a.min(b), a.max(b)), i));
        }
    }
    edges.sort_unstable();
    for run in edges.chunk_by(|a, b| a.0 == b.0) {
        for pair in run.windows(2) {
            let (a, b) = (find(&mut parent, pair[0].1), find(&mut parent, pair[1].1));
            parent[a.max(b)] = a.min(b);
        }
    }
    // About a boundary point, not the origin: a small part far from it would cancel.
    let Some(&first) = ids.first() else { return };
    let origin = mesh.nodes[face_corners(mesh, first)[0]];
    let mut volume: HashMap<usize, f64> = HashMap::new();
    for (i, &id) in ids.iter().enumerate() {
        let [a, b, c] = face_corners(mesh, id).map(|n| sub(mesh.nodes[n], origin));
        *volume.entry(find(&mut parent, i)).or_default() += dot(a, cross(b, c)) / 6.0;
    }
    for (i, &id) in ids.iter().enumerate() {
        if volume[&find(&mut parent, i)] < 0.0 {
            on_boundary[id] = false;
        }
    }
}

/// The boundary surface of `mesh` (faces used by exactly one tet, less the
/// coincident pairs and the sealed cavities' walls of the module doc), outward
/// oriented if the tets are positively oriented (run [`crate::check`] first),
/// with local node numbering in order of first use. For 10-node meshes the
/// mid-edge nodes of each triangle's edges (0,1), (1,2), (2,0) are included.
/// Faces are listed in tet order, then face order, so the result is
/// deterministic. Node indices must be in range.
pub fn boundary_surface(mesh: &TetMesh) -> Surface {
    let n_tets = mesh.cells.len();
    // Sort all faces by their corner set; a face seen once is on the boundary.
    let mut faces: Vec<([usize; 3], usize)> = Vec::with_capacity(4 * n_tets);
    for e in 0..n_tets {
        let c = mesh.cells.corners(e);
        for (f, face) in TET_FACES.iter().enumerate() {
            let mut key = face.map(|k| c[k]);
            key.sort_unstable();
            faces.push((key, 4 * e + f));
        }
    }
    faces.sort_unstable();
    let mut on_boundary = vec![false; 4 * n_tets];
    for run in faces.chunk_by(|a, b| a.0 == b.0) {
        if let [(_, id)] = run {
            on_boundary[*id] = true;
        }
    }
    drop_coincident_faces(mesh, &mut on_boundary);
    drop_cavity_walls(mesh, &mut on_boundary);
    let quadratic = matches!(mesh.cells, Cells::Tet10(_));
    let mut local = vec![usize::MAX; mesh.nodes.len()];
    let mut surface = Surface::default();
    let mut edge_nodes = Vec::new();
    let mut local_of = |node: usize, s: &mut Surface| {
        if local[node] == usize::MAX {
            local[node] = s.node_ids.len();
            s.node_ids.push(node);
            s.positions.push(mesh.nodes[node]);
        }
        local[node]
    };
    for e in 0..n_tets {
        let c = mesh.cells.corners(e);
        let all = mesh.cells.nodes_of(e);
        for (f, face) in TET_FACES.iter().enumerate() {
            if !on_boundary[4 * e + f] {
                continue;
            }
            let triangle = face.map(|k| local_of(c[k], &mut surface));
            surface.triangles.push(triangle);
            if quadratic {
                let mids = [0, 1, 2].map(|i| all[edge_slot(face[i], face[(i + 1) % 3])]);
                edge_nodes.push(mids.map(|n| local_of(n, &mut surface)));
            }
        }
    }
    if quadratic {
        surface.triangle_edge_nodes = Some(edge_nodes);
    }
    surface
}

impl Surface {
    /// Area vector `(b − a) × (c − a) / 2` of triangle `t` (m²): the
    /// outward normal times the (flat) triangle's area.
    pub fn area_vector(&self, t: usize) -> [f64; 3] {
        let [a, b, c] = self.triangles[t].map(|k| self.positions[k]);
        cross(sub(b, a), sub(c, a)).map(|x| 0.5 * x)
    }

    /// Total area of the flat corner triangles (m²).
    pub fn area(&self) -> f64 {
        (0..self.triangles.len()).map(|t| dot(self.area_vector(t), self.area_vector(t)).sqrt()).sum()
    }

    /// Axis-aligned bounding box `(min, max)` of the surface nodes (m).
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        crate::io::bounding_box(&self.positions)
    }

    /// Number of surface edges used by other than exactly two triangles
    /// (0 for a closed, manifold surface).
    pub fn open_edge_count(&self) -> usize {
        let mut uses: HashMap<(usize, usize), u32> = HashMap::new();
        for t in &self.triangles {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        uses.values().filter(|&&n| n != 2).count()
    }
}
