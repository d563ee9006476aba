//! Global assembly of stiffness `K` and consistent mass `M` into faer sparse
//! matrices with full symmetric storage (both triangles).
//!
//! DOF numbering: DOF `3i + c` is component `c` (x, y, z) of node `i`.
//!
//! Symbolic before numeric: [`SparsityPattern::new`] builds the pattern once
//! from the connectivity (node `j`'s column block holds the 3×3 blocks of
//! every node sharing an element with `j`, rows sorted); [`SparsityPattern::assemble`]
//! fills values and can be called again for another material. `K` and `M`
//! share this pattern (M's cross-component entries are stored zeros), so
//! `K − σM` can be formed entry by entry.
//!
//! Determinism: element matrices are computed in parallel (rayon) into
//! per-element buffers, one chunk of elements at a time; then the global
//! value array is split into disjoint column ranges and each range adds the
//! chunk's contributions to its own columns in element order (also in
//! parallel). Every global entry is therefore the same sum in the same order
//! for any thread count: bit-identical results.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use modal_mesh::TetMesh;
use rayon::prelude::*;

use crate::element::{element_matrices_into, ElementRules};
use crate::{FemError, Material};

/// Elements whose matrices are computed in one parallel batch.
const CHUNK: usize = 1024;

/// Bytes that K, M (each its own row indices and values) and the shared
/// pattern hold for `nnz` stored entries and `dofs` columns: 8-byte indices
/// and values, so `5·8·nnz` plus the column pointers.
pub fn matrices_bytes(nnz: u64, dofs: u64) -> u64 {
    5 * 8 * nnz + 3 * 8 * (dofs + 1)
}

/// Fewest distinct pairs of different nodes that share an element, per
/// element, in any mesh of 10-node tets: 15.
///
/// Three kinds of node pair in one tet are shared by few others. Two
/// mid-edge nodes on one face (12 pairs) and a corner with the mid-edge node
/// of an edge of the opposite face (12 pairs) span that face, so at most
/// the two tets on the face hold them; the mid-edge nodes of two opposite
/// edges (3 pairs) span the tet itself. So `T` tets hold at least
/// `12T/2 + 12T/2 + 3T = 15T` such pairs, whatever their shape or sizes.
/// (The structured meshes of `modal_mesh::generate` measure 383 stored
/// entries per tet against the `2·9·15 = 270` this bound gives.)
pub const MIN_NODE_PAIRS_PER_QUADRATIC_TET: u64 = 15;

/// The fewest bytes [`matrices_bytes`] can be for a mesh of `tets` 10-node
/// tets ([`MIN_NODE_PAIRS_PER_QUADRATIC_TET`]: each pair is a 3 × 3 block on
/// both sides of the diagonal): a lower bound known from the element count
/// alone, before the mesh exists.
pub fn min_quadratic_matrices_bytes(tets: u64) -> u64 {
    matrices_bytes(2 * 9 * MIN_NODE_PAIRS_PER_QUADRATIC_TET * tets, 0)
}

/// Assembled global stiffness `k` \[N/m\] and consistent mass `m` \[kg\], both
/// `3·nodes × 3·nodes`, full symmetric storage, same sparsity pattern.
#[derive(Clone, Debug)]
pub struct Assembly {
    /// Stiffness matrix K.
    pub k: SparseColMat<usize, f64>,
    /// Consistent mass matrix M.
    pub m: SparseColMat<usize, f64>,
}

/// The sparsity pattern of K and M for one mesh connectivity.
#[derive(Clone, Debug)]
pub struct SparsityPattern {
    symbolic: SymbolicSparseColMat<usize>,
    /// `adj[adj_ptr[j]..adj_ptr[j + 1]]`: sorted nodes sharing an element with node `j`.
    adj_ptr: Vec<usize>,
    adj: Vec<usize>,
    order: u8,
    element_count: usize,
}

impl SparsityPattern {
    /// Builds the pattern of `mesh`. Fails on an empty mesh or a node index
    /// out of range.
    pub fn new(mesh: &TetMesh) -> Result<SparsityPattern, FemError> {
        Self::new_within(mesh, None)
    }

    /// [`SparsityPattern::new`], refused with [`FemError::TooLarge`] before
    /// the pattern is built when K, M and the pattern would hold more than
    /// `limit_bytes` ([`matrices_bytes`]): the node adjacency alone (a
    /// ninth of the pattern's entries) tells, so an absurd mesh fails in
    /// seconds instead of exhausting memory in assembly.
    pub fn new_within(mesh: &TetMesh, limit_bytes: Option<u64>) -> Result<SparsityPattern, FemError> {
        let n_nodes = mesh.node_count();
        let n_el = mesh.cells.len();
        if n_el == 0 {
            return Err(FemError::EmptyMesh);
        }
        for e in 0..n_el {
            if let Some(&node) = mesh.cells.nodes_of(e).iter().find(|&&n| n >= n_nodes) {
                return Err(FemError::NodeOutOfRange { element: e, node, node_count: n_nodes });
            }
        }
        let (adj_ptr, adj) = node_adjacency(mesh);
        let n_dof = 3 * n_nodes;
        let needed_bytes = matrices_bytes(9 * adj.len() as u64, n_dof as u64);
        if let Some(limit_bytes) = limit_bytes.filter(|&l| needed_bytes > l) {
            return Err(FemError::TooLarge { dofs: n_dof, needed_bytes, limit_bytes });
        }
        let mut col_ptr = Vec::with_capacity(n_dof + 1);
        let mut row_idx = Vec::with_capacity(9 * adj.len());
        col_ptr.push(0);
        for j in 0..n_nodes {
            let neighbours = &adj[adj_ptr[j]..adj_ptr[j + 1]];
            for _ in 0..3 {
                row_idx.extend(neighbours.iter().flat_map(|&k| [3 * k, 3 * k + 1, 3 * k + 2]));
                col_ptr.push(row_idx.len());
            }
        }
        let symbolic = SymbolicSparseColMat::new_checked(n_dof, n_dof, col_ptr, None, row_idx);
        Ok(SparsityPattern { symbolic, adj_ptr, adj, order: mesh.order(), element_count: n_el })
    }

    /// Number of DOFs (3 × nodes).
    pub fn dof_count(&self) -> usize {
        self.symbolic.nrows()
    }

    /// Number of stored entries (both triangles).
    pub fn nnz(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// The faer symbolic structure shared by K and M.
    pub fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// Position in the value array of entry (row `3r + ci`, column `3c + cj`).
    fn position(&self, r: usize, c: usize, ci: usize, cj: usize) -> usize {
        let (start, end) = (self.adj_ptr[c], self.adj_ptr[c + 1]);
        let degree = end - start;
        let k = match self.adj[start..end].binary_search(&r) {
            Ok(k) => k,
            Err(_) => unreachable!("node {r} is not in the pattern of node {c}"),
        };
        9 * start + 3 * cj * degree + 3 * k + ci
    }

    /// Up to `parts` consecutive node ranges with about equal numbers of
    /// stored entries, covering all nodes.
    fn node_ranges(&self, parts: usize) -> Vec<(usize, usize)> {
        let n_nodes = self.adj_ptr.len() - 1;
        let total = self.adj_ptr[n_nodes];
        let mut ranges = Vec::with_capacity(parts);
        let mut start = 0;
        for p in 1..=parts {
            let goal = total * p / parts;
            let mut end = start;
            while end < n_nodes && (self.adj_ptr[end] < goal || p == parts) {
                end += 1;
            }
            if end > start {
                ranges.push((start, end));
                start = end;
            }
        }
        ranges
    }

    /// Assembles K and M of `mesh` (same connectivity as the pattern) for
    /// `material` (validated here).
    ///
    /// # Panics
    /// If `mesh` has another element order, element count or node count
    /// than the mesh the pattern was built from (a broken contract).
    pub fn assemble(&self, mesh: &TetMesh, material: &Material) -> Result<Assembly, FemError> {
        material.validate()?;
        assert!(
            mesh.order() == self.order
                && mesh.cells.len() == self.element_count
                && 3 * mesh.node_count() == self.dof_count(),
            "sparsity pattern built for another mesh"
        );
        let nodes_per = if self.order == 1 { 4 } else { 10 };
        let block = (3 * nodes_per) * (3 * nodes_per);
        let rules = ElementRules::default();
        let lame = material.lame();
        let rho = material.density_kg_m3;
        let mut k_val = vec![0.0; self.nnz()];
        let mut m_val = vec![0.0; self.nnz()];
        let chunk = CHUNK.min(mesh.cells.len());
        let mut k_buf = vec![0.0; chunk * block];
        let mut m_buf = vec![0.0; chunk * block];
        for first in (0..mesh.cells.len()).step_by(CHUNK) {
            let count = CHUNK.min(mesh.cells.len() - first);
            let failure = k_buf[..count * block]
                .par_chunks_mut(block)
                .zip(m_buf[..count * block].par_chunks_mut(block))
                .enumerate()
                .filter_map(|(i, (ke, me))| {
                    let e = first + i;
                    let x = gather(mesh, e);
                    element_matrices_into(e, &x[..nodes_per], lame, rho, &rules, ke, me).err()
                })
                .min_by_key(|err| match err {
                    FemError::NonPositiveJacobian { element, .. } => *element,
                    _ => usize::MAX,
                });
            if let Some(err) = failure {
                return Err(err);
            }
            let ranges = self.node_ranges(SCATTER_RANGES);
            let k_parts = split_by_ranges(&mut k_val, &ranges, &self.adj_ptr);
            let m_parts = split_by_ranges(&mut m_val, &ranges, &self.adj_ptr);
            k_parts.into_par_iter().zip(m_parts).zip(ranges.par_iter()).for_each(|((kv, mv), &(n0, n1))| {
                let offset = 9 * self.adj_ptr[n0];
                for i in 0..count {
                    let nodes = mesh.cells.nodes_of(first + i);
                    let range = i * block..(i + 1) * block;
                    let target = ScatterTarget { columns: n0..n1, offset };
                    self.scatter(nodes, &k_buf[range.clone()], kv, &target, false);
                    self.scatter(nodes, &m_buf[range], mv, &target, true);
                }
            });
        }
        Ok(Assembly {
            k: SparseColMat::new(self.symbolic.clone(), k_val),
            m: SparseColMat::new(self.symbolic.clone(), m_val),
        })
    }

    /// Adds one element matrix (row-major, `3n × 3n`) into `values`; with
    /// `same_component_only` (mass matrices) only entries `ci == cj`, the
    /// others being exactly zero.
    /// Only columns of nodes in `target.columns` are written; `values` is
    /// the slice of the global value array starting at `target.offset`.
    fn scatter(
        &self,
        nodes: &[usize],
        element: &[f64],
        values: &mut [f64],
        target: &ScatterTarget,
        same_component_only: bool,
    ) {
        let size = 3 * nodes.len();
        for (b, &nb) in nodes.iter().enumerate() {
            if !target.columns.contains(&nb) {
                continue;
            }
            for (a, &na) in nodes.iter().enumerate() {
                let base = self.position(na, nb, 0, 0) - target.offset;
                let degree = self.adj_ptr[nb + 1] - self.adj_ptr[nb];
                for cj in 0..3 {
                    let col = base + 3 * cj * degree;
                    if same_component_only {
                        values[col + cj] += element[(3 * a + cj) * size + 3 * b + cj];
                        continue;
                    }
                    for ci in 0..3 {
                        values[col + ci] += element[(3 * a + ci) * size + 3 * b + cj];
                    }
                }
            }
        }
    }
}

/// Node ranges whose column blocks are scattered in parallel. Any count
/// gives bit-identical sums (each entry is still summed in element order).
const SCATTER_RANGES: usize = 16;

/// The node columns one parallel scatter task owns, and where its slice of
/// the global value array starts.
struct ScatterTarget {
    columns: std::ops::Range<usize>,
    offset: usize,
}

/// Splits `values` into the disjoint slices of the column blocks of each
/// node range.
fn split_by_ranges<'a>(
    values: &'a mut [f64],
    ranges: &[(usize, usize)],
    adj_ptr: &[usize],
) -> Vec<&'a mut [f64]> {
    let mut parts = Vec::with_capacity(ranges.len());
    let mut rest = values;
    for &(n0, n1) in ranges {
        let (head, tail) = rest.split_at_mut(9 * (adj_ptr[n1] - adj_ptr[n0]));
        parts.push(head);
        rest = tail;
    }
    parts
}

/// Node coordinates of element `e` (first 4 or 10 entries used).
fn gather(mesh: &TetMesh, e: usize) -> [[f64; 3]; 10] {
    let mut x = [[0.0; 3]; 10];
    for (xi, &n) in x.iter_mut().zip(mesh.cells.nodes_of(e)) {
        *xi = mesh.nodes[n];
    }
    x
}

/// CSR-like node adjacency (each node's sorted neighbours, itself included).
fn node_adjacency(mesh: &TetMesh) -> (Vec<usize>, Vec<usize>) {
    let n_nodes = mesh.node_count();
    let mut lists: Vec<Vec<usize>> = vec![Vec::new(); n_nodes];
    for e in 0..mesh.cells.len() {
        let nodes = mesh.cells.nodes_of(e);
        for &a in nodes {
            lists[a].extend_from_slice(nodes);
        }
    }
    let mut adj_ptr = Vec::with_capacity(n_nodes + 1);
    let mut adj = Vec::new();
    adj_ptr.push(0);
    for mut list in lists {
        list.sort_unstable();
        list.dedup();
        adj.extend_from_slice(&list);
        adj_ptr.push(adj.len());
    }
    (adj_ptr, adj)
}

/// Assembles K and M of `mesh` for `material` (pattern built and discarded).
pub fn assemble(mesh: &TetMesh, material: &Material) -> Result<Assembly, FemError> {
    SparsityPattern::new(mesh)?.assemble(mesh, material)
}

/// The mesh at element order `order`: 1 → 4-node tets (a 10-node mesh keeps
/// its corner nodes), 2 → 10-node tets (a 4-node mesh gains shared straight
/// mid-edge nodes; a 10-node mesh keeps its own, possibly curved, ones).
/// Order 2 is the project default.
pub fn prepare_mesh(mesh: &TetMesh, order: u8) -> Result<TetMesh, FemError> {
    match order {
        1 => Ok(modal_mesh::to_linear(mesh)),
        2 => Ok(modal_mesh::to_quadratic(mesh)),
        other => Err(FemError::UnsupportedOrder(other)),
    }
}

/// Default element order (10-node tets) — a project contract.
pub const DEFAULT_ORDER: u8 = 2;
