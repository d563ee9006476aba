//! Mesh checks: turn a raw [`TetMesh`] into one the FEM can trust.
//!
//! [`check`] runs, in order:
//! 1. non-finite coordinates, node indices out of range, a node repeated
//!    inside one tet → error naming the element (or node);
//! 2. duplicate tets (same corner set) → error naming both elements;
//! 3. orientation: a tet with `(b − a) × (c − a) · (d − a) < 0` is
//!    reoriented by swapping corners 1 and 2 — for 10-node tets the
//!    mid-edge nodes are permuted with them (edges (0,1) ↔ (0,2) and
//!    (1,3) ↔ (2,3)) — and counted in the report;
//! 4. degenerate tets: `|V| ≤ 1e-10 · ℓ³` with ℓ the tet's longest edge
//!    (a regular tet has `V/ℓ³ ≈ 0.118`; the threshold is far below any
//!    usable element and far above round-off, and does not depend on the
//!    mesh's overall size or units) → error;
//! 5. overlaps: two tets sharing a face must lie on opposite sides of it
//!    (a folded mesh is an error, not something to reorient; see
//!    [`crate::overlap`]); three tets on one face are an error too;
//! 6. 10-node tets: the Jacobian determinant of the quadratic geometry map
//!    must be positive at 15 reference points (the 4 vertices, the 6 edge
//!    midpoints, the 4 points of the degree-2 Keast rule and the centroid);
//!    det J is a cubic polynomial, so this is a sampled check, the standard
//!    one in FE codes → error naming the element and the point;
//! 7. unused nodes are dropped (indices renumbered, order kept) and counted;
//! 8. parts are found through shared faces ([`crate::face_parts`]); parts
//!    that touch only at an edge or a vertex (zero-stiffness hinges) get
//!    their own copies of the shared nodes ([`crate::split_hinges`]) and a
//!    warning naming each contact, so they are solved as separate bodies;
//!    after that the node-connected parts ([`connected_parts`]) are the
//!    face-connected ones, each with its own six rigid-body modes;
//! 9. quality: the smallest dihedral angle is reported and tets with one
//!    below 5° are counted as slivers (a warning only).

use std::collections::HashMap;

use crate::{Cells, MeshError, TetMesh, TET10_EDGES};

/// Relative volume tolerance of the degenerate-tet check (times ℓ³).
pub const DEGENERATE_VOLUME_RATIO: f64 = 1e-10;

/// Dihedral angle (degrees) below which a valid tet is counted as a sliver
/// in [`MeshReport::slivers`] (a warning, not an error).
pub const SLIVER_ANGLE_DEG: f64 = 5.0;

/// Smallest dihedral angle and the number of tets with one below
/// [`SLIVER_ANGLE_DEG`].
fn dihedral_summary(mesh: &TetMesh) -> (f64, usize) {
    let mut smallest = 180.0f64;
    let mut slivers = 0;
    for e in 0..mesh.cells.len() {
        let angles = crate::dihedral_angles_deg(mesh.cells.corners(e).map(|n| mesh.nodes[n]));
        let min = angles.iter().fold(180.0f64, |a, &b| a.min(b));
        smallest = smallest.min(min);
        slivers += usize::from(min < SLIVER_ANGLE_DEG);
    }
    (smallest, slivers)
}

/// What [`check`] found and changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshReport {
    /// Nodes after unused ones were dropped.
    pub nodes: usize,
    /// Number of tets.
    pub tets: usize,
    /// Element order (1 or 2).
    pub order: u8,
    /// Tets that were negatively oriented and have been reoriented.
    pub reoriented: usize,
    /// Nodes used by no tet, dropped.
    pub unused_nodes_dropped: usize,
    /// Parts connected through shared faces (each contributes six
    /// rigid-body modes), after hinges were split.
    pub parts: usize,
    /// Pairs of parts that touched only at edges or vertices (hinges).
    pub hinges: usize,
    /// Nodes duplicated to separate hinged parts.
    pub hinge_nodes_split: usize,
    /// Total volume (m³) (straight-sided corner tets).
    pub volume: f64,
    /// Smallest corner-tet volume (m³).
    pub min_tet_volume: f64,
    /// Largest corner-tet volume (m³).
    pub max_tet_volume: f64,
    /// Smallest dihedral angle of any (corner) tet, degrees.
    pub min_dihedral_deg: f64,
    /// Tets with a dihedral angle below [`SLIVER_ANGLE_DEG`] (valid but
    /// poorly shaped; they stiffen the FEM and slow the eigensolver).
    pub slivers: usize,
    /// Human-readable warnings for the CLI (one line each).
    pub warnings: Vec<String>,
}

/// Checks and repairs a raw mesh; see the module doc for the rules.
pub fn check(mut mesh: TetMesh) -> Result<(TetMesh, MeshReport), MeshError> {
    if mesh.cells.is_empty() {
        return Err(MeshError::NoTets);
    }
    check_finite(&mesh)?;
    check_indices(&mesh)?;
    check_duplicates(&mesh)?;
    let reoriented = orient(&mut mesh);
    let (volume, min_v, max_v) = check_volumes(&mesh)?;
    crate::overlap::check_overlaps(&mesh)?;
    if let Cells::Tet10(tets) = &mesh.cells {
        for (e, t) in tets.iter().enumerate() {
            check_tet10_jacobian(&mesh.nodes, e, t)?;
        }
    }
    let dropped = drop_unused_nodes(&mut mesh);
    let mut warnings = Vec::new();
    let face = crate::face_parts(&mesh);
    let hinges = face.hinges.len();
    let hinge_nodes_split = if hinges > 0 {
        let added = crate::split_hinges(&mut mesh, &face);
        warnings.push(format!(
            "{} parts touch only at edges or vertices (zero-stiffness hinges, {added} nodes duplicated): {}; \
             they are solved as separate bodies (remesh or join them to couple them)",
            face.count,
            crate::describe_hinges(&face, 3)
        ));
        added
    } else {
        0
    };
    let (parts, _) = connected_parts(&mesh);
    let (min_dihedral_deg, slivers) = dihedral_summary(&mesh);
    if reoriented > 0 {
        warnings.push(format!(
            "{reoriented} of {} tets were negatively oriented and have been reoriented",
            mesh.cells.len()
        ));
    }
    if dropped > 0 {
        warnings.push(format!("{dropped} nodes belong to no tet and were dropped"));
    }
    if parts > 1 {
        warnings.push(format!("the mesh has {parts} disconnected parts (6 rigid-body modes each)"));
    }
    if slivers > 0 {
        warnings.push(format!(
            "{slivers} tets have a dihedral angle below {SLIVER_ANGLE_DEG} degrees (smallest {min_dihedral_deg:.2}); \
             results may be inaccurate"
        ));
    }
    let report = MeshReport {
        nodes: mesh.nodes.len(),
        tets: mesh.cells.len(),
        order: mesh.order(),
        reoriented,
        unused_nodes_dropped: dropped,
        parts,
        hinges,
        hinge_nodes_split,
        volume,
        min_tet_volume: min_v,
        max_tet_volume: max_v,
        min_dihedral_deg,
        slivers,
        warnings,
    };
    Ok((mesh, report))
}

fn check_finite(mesh: &TetMesh) -> Result<(), MeshError> {
    match mesh.nodes.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        Some(node) => Err(MeshError::NonFiniteCoordinate { node, coordinate: mesh.nodes[node] }),
        None => Ok(()),
    }
}

fn check_indices(mesh: &TetMesh) -> Result<(), MeshError> {
    let node_count = mesh.nodes.len();
    for element in 0..mesh.cells.len() {
        let nodes = mesh.cells.nodes_of(element);
        for (k, &node) in nodes.iter().enumerate() {
            if node >= node_count {
                return Err(MeshError::NodeOutOfRange { element, node, node_count });
            }
            if nodes[..k].contains(&node) {
                return Err(MeshError::RepeatedNode { element, node });
            }
        }
    }
    Ok(())
}

fn check_duplicates(mesh: &TetMesh) -> Result<(), MeshError> {
    let mut seen: HashMap<[usize; 4], usize> = HashMap::with_capacity(mesh.cells.len());
    for element in 0..mesh.cells.len() {
        let mut key = mesh.cells.corners(element);
        key.sort_unstable();
        if let Some(&first) = seen.get(&key) {
            return Err(MeshError::DuplicateTet { element, first });
        }
        seen.insert(key, element);
    }
    Ok(())
}

/// Six times the signed volume of the corner tet.
pub(crate) fn volume6(nodes: &[[f64; 3]], tet: [usize; 4]) -> f64 {
    let [a, b, c, d] = tet.map(|n| nodes[n]);
    let u = sub(b, a);
    let v = sub(c, a);
    let w = sub(d, a);
    dot(cross(u, v), w)
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Position permutation of a 10-node tet that swaps corners 1 and 2:
/// new node `k` is old node `TET10_SWAP12[k]`. Derived from
/// [`TET10_EDGES`]: edge (0,1) ↔ (0,2), (1,2) stays, (1,3) ↔ (2,3).
pub(crate) const TET10_SWAP12: [usize; 10] = tet10_swap12();

const fn tet10_swap12() -> [usize; 10] {
    const fn swapped(c: usize) -> usize {
        match c {
            1 => 2,
            2 => 1,
            c => c,
        }
    }
    let mut perm = [0, 2, 1, 3, 0, 0, 0, 0, 0, 0];
    let mut e = 0;
    while e < 6 {
        let [a, b] = TET10_EDGES[e];
        let (a, b) = (swapped(a), swapped(b));
        let mut f = 0;
        while f < 6 {
            let [c, d] = TET10_EDGES[f];
            if (c == a && d == b) || (c == b && d == a) {
                perm[4 + e] = 4 + f;
            }
            f += 1;
        }
        e += 1;
    }
    perm
}

/// Reorients negative tets in place; returns how many.
fn orient(mesh: &mut TetMesh) -> usize {
    let nodes = &mesh.nodes;
    let mut count = 0;
    match &mut mesh.cells {
        Cells::Tet4(tets) => {
            for t in tets.iter_mut().filter(|t| volume6(nodes, **t) < 0.0) {
                t.swap(1, 2);
                count += 1;
            }
        }
        Cells::Tet10(tets) => {
            for t in tets.iter_mut().filter(|t| volume6(nodes, [t[0], t[1], t[2], t[3]]) < 0.0) {
                *t = TET10_SWAP12.map(|k| t[k]);
                count += 1;
            }
        }
    }
    count
}

/// Errors on degenerate tets; returns (total, min, max) corner volume.
fn check_volumes(mesh: &TetMesh) -> Result<(f64, f64, f64), MeshError> {
    let (mut total, mut min_v, mut max_v) = (0.0, f64::INFINITY, 0.0f64);
    for element in 0..mesh.cells.len() {
        let corners = mesh.cells.corners(element);
        let volume = volume6(&mesh.nodes, corners) / 6.0;
        let longest2 = TET10_EDGES
            .iter()
            .map(|&[a, b]| {
                let d = sub(mesh.nodes[corners[a]], mesh.nodes[corners[b]]);
                dot(d, d)
            })
            .fold(0.0, f64::max);
        let tolerance = DEGENERATE_VOLUME_RATIO * longest2 * longest2.sqrt();
        if volume <= tolerance || volume.is_nan() {
            return Err(MeshError::DegenerateTet { element, volume, tolerance });
        }
        total += volume;
        min_v = min_v.min(volume);
        max_v = max_v.max(volume);
    }
    Ok((total, min_v, max_v))
}

/// Reference points (ξ, η, ζ) where the Jacobian of a 10-node tet is checked.
const JACOBIAN_POINTS: [[f64; 3]; 15] = {
    const A: f64 = 0.585_410_196_624_968_5;
    const B: f64 = 0.138_196_601_125_010_5;
    [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.5, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.0, 0.5],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
        [B, B, B],
        [A, B, B],
        [B, A, B],
        [B, B, A],
        [0.25, 0.25, 0.25],
    ]
};

/// Gradients (d/dξ, d/dη, d/dζ) of the ten quadratic shape functions at a
/// reference point, with barycentrics L0 = 1 − ξ − η − ζ, L1 = ξ, L2 = η,
/// L3 = ζ; corner i: Li(2Li − 1), edge node (a,b): 4 La Lb.
pub fn tet10_shape_gradients(p: [f64; 3]) -> [[f64; 3]; 10] {
    let l = [1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]];
    let dl: [[f64; 3]; 4] = [[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut g = [[0.0; 3]; 10];
    for i in 0..4 {
        g[i] = dl[i].map(|d| (4.0 * l[i] - 1.0) * d);
    }
    for (e, &[a, b]) in TET10_EDGES.iter().enumerate() {
        g[4 + e] = [0, 1, 2].map(|c| 4.0 * (dl[a][c] * l[b] + l[a] * dl[b][c]));
    }
    g
}

fn check_tet10_jacobian(nodes: &[[f64; 3]], element: usize, t: &[usize; 10]) -> Result<(), MeshError> {
    // Scale-free threshold: compare with the straight tet's determinant.
    let straight = volume6(nodes, [t[0], t[1], t[2], t[3]]);
    for point in JACOBIAN_POINTS {
        let grads = tet10_shape_gradients(point);
        let mut jac = [[0.0; 3]; 3]; // jac[r][c] = d x_r / d ξ_c
        for (k, g) in grads.iter().enumerate() {
            let x = nodes[t[k]];
            for r in 0..3 {
                for c in 0..3 {
                    jac[r][c] += x[r] * g[c];
                }
            }
        }
        let det = dot(jac[0], cross(jac[1], jac[2]));
        if det <= 1e-12 * straight.abs() || det.is_nan() {
            return Err(MeshError::InvertedTet10 { element, point, det });
        }
    }
    Ok(())
}

/// Drops nodes no tet uses, renumbering the rest in their original order;
/// returns how many were dropped.
fn drop_unused_nodes(mesh: &mut TetMesh) -> usize {
    let mut used = vec![false; mesh.nodes.len()];
    for e in 0..mesh.cells.len() {
        mesh.cells.nodes_of(e).iter().for_each(|&n| used[n] = true);
    }
    let dropped = used.iter().filter(|&&u| !u).count();
    if dropped == 0 {
        return 0;
    }
    let mut new_index = vec![usize::MAX; used.len()];
    let mut nodes = Vec::with_capacity(used.len() - dropped);
    for (n, _) in used.iter().enumerate().filter(|(_, &u)| u) {
        new_index[n] = nodes.len();
        nodes.push(mesh.nodes[n]);
    }
    mesh.nodes = nodes;
    match &mut mesh.cells {
        Cells::Tet4(t) => t.iter_mut().flatten().for_each(|n| *n = new_index[*n]),
        Cells::Tet10(t) => t.iter_mut().flatten().for_each(|n| *n = new_index[*n]),
    }
    dropped
}

/// Root of `x` in the union–find forest `parent` (each entry its parent, a root
/// its own), halving the path on the way.
pub(crate) fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Connected parts of the mesh (tets sharing a node are connected).
/// Returns the number of parts and, per node, its part id `0..count`
/// (numbered in order of each part's lowest node); nodes used by no tet get
/// `usize::MAX` and are not counted. Out-of-range node indices are ignored.
pub fn connected_parts(mesh: &TetMesh) -> (usize, Vec<usize>) {
    let n = mesh.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut used = vec![false; n];
    for e in 0..mesh.cells.len() {
        let nodes: Vec<usize> = mesh.cells.nodes_of(e).iter().copied().filter(|&k| k < n).collect();
        for &k in &nodes {
            used[k] = true;
        }
        if let Some(&first) = nodes.first() {
            for &k in &nodes[1..] {
                let (ra, rb) = (find(&mut parent, first), find(&mut parent, k));
                if ra != rb {
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
    }
    let mut id_of_root = vec![usize::MAX; n];
    let mut part = vec![usize::MAX; n];
    let mut count = 0;
    for k in (0..n).filter(|&k| used[k]) {
        let root = find(&mut parent, k);
        if id_of_root[root] == usize::MAX {
            id_of_root[root] = count;
            count += 1;
        }
        part[k] = id_of_root[root];
    }
    (count, part)
}
