//! Rigid-body displacement fields and connected parts.
//!
//! For each connected part with node centroid `c` (unweighted mean of its
//! node positions), the six fields are the unit translations `eₖ` and the
//! infinitesimal rotations `eₖ × (x − c)`, k = x, y, z. Any free elastic
//! body has `K u = 0` for all six (up to round-off), so they span the
//! zero-frequency eigenspace of `K w = λ M w` per part.

use faer::sparse::SparseColMat;
use faer::Mat;
use modal_mesh::{DisjointSets, TetMesh};

/// Connected parts of `mesh`: `(part_of_node, part_count)`, two nodes being
/// in one part when an element chain links them. Parts are numbered in order
/// of their lowest node; a node in no element forms a part of its own.
pub fn node_parts(mesh: &TetMesh) -> (Vec<usize>, usize) {
    let n = mesh.node_count();
    let mut sets = DisjointSets::new(n);
    for e in 0..mesh.cells.len() {
        let nodes = mesh.cells.nodes_of(e);
        for &other in &nodes[1..] {
            sets.join(nodes[0], other);
        }
    }
    let mut part_of_root = vec![usize::MAX; n];
    let mut part = vec![0; n];
    let mut count = 0;
    for i in 0..n {
        let r = sets.root(i);
        if part_of_root[r] == usize::MAX {
            part_of_root[r] = count;
            count += 1;
        }
        part[i] = part_of_root[r];
    }
    (part, count)
}

/// The rigid-body fields of every part not listed in `exclude_parts`:
/// a `3·nodes × 6·(included parts)` matrix whose columns, per included part
/// in increasing part order, are translations x, y, z then rotations about
/// x, y, z through the part's node centroid. Each field is zero outside its
/// part. The fields are NOT orthonormalized (see [`m_orthonormalize`]).
///
/// # Panics
/// If `part_of_node.len() != nodes.len()` or a part index is ≥ `n_parts`
/// (a broken contract: use [`node_parts`]).
pub fn rigid_body_fields(
    nodes: &[[f64; 3]],
    part_of_node: &[usize],
    n_parts: usize,
    exclude_parts: &[usize],
) -> Mat<f64> {
    assert_eq!(part_of_node.len(), nodes.len(), "one part index per node");
    assert!(part_of_node.iter().all(|&p| p < n_parts), "part index out of range");
    let mut centroid = vec![[0.0; 3]; n_parts];
    let mut count = vec![0usize; n_parts];
    for (p, &part) in nodes.iter().zip(part_of_node) {
        (0..3).for_each(|c| centroid[part][c] += p[c]);
        count[part] += 1;
    }
    for (c, &k) in centroid.iter_mut().zip(&count) {
        *c = c.map(|v| v / k.max(1) as f64);
    }
    let mut column_of = vec![usize::MAX; n_parts];
    let mut included = 0;
    for (part, col) in column_of.iter_mut().enumerate() {
        if !exclude_parts.contains(&part) {
            *col = 6 * included;
            included += 1;
        }
    }
    let mut fields = Mat::zeros(3 * nodes.len(), 6 * included);
    for (i, (p, &part)) in nodes.iter().zip(part_of_node).enumerate() {
        let col = column_of[part];
        if col == usize::MAX {
            continue;
        }
        let r = [0, 1, 2].map(|c| p[c] - centroid[part][c]);
        for c in 0..3 {
            fields[(3 * i + c, col + c)] = 1.0;
        }
        // e_x × r = (0, −r_z, r_y); e_y × r = (r_z, 0, −r_x); e_z × r = (−r_y, r_x, 0).
        let rot = [[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]];
        for (k, v) in rot.iter().enumerate() {
            for c in 0..3 {
                fields[(3 * i + c, col + 3 + k)] = v[c];
            }
        }
    }
    fields
}

/// `y = A x` for a sparse matrix in full storage.
pub(crate) fn sparse_mul(a: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; a.nrows()];
    let (symbolic, values) = a.parts();
    let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
    for (j, &xj) in x.iter().enumerate().take(a.ncols()) {
        for p in col_ptr[j]..col_ptr[j + 1] {
            y[row_idx[p]] += values[p] * xj;
        }
    }
    y
}

/// M-orthonormalizes the columns of `fields` (modified Gram–Schmidt in the
/// inner product `⟨u, v⟩ = uᵀ M v`, applied twice for stability), so that
/// `Fᵀ M F = 𝟙`. Columns that become numerically dependent (norm below
/// 1e-10 of their original norm) are dropped.
pub fn m_orthonormalize(fields: &Mat<f64>, m: &SparseColMat<usize, f64>) -> Mat<f64> {
    let n = fields.nrows();
    assert_eq!(m.nrows(), n, "M and the fields must have the same row count");
    let mut basis: Vec<(Vec<f64>, Vec<f64>)> = Vec::new(); // (v, M v)
    for j in 0..fields.ncols() {
        let mut v: Vec<f64> = (0..n).map(|i| fields[(i, j)]).collect();
        let original = dot(&v, &sparse_mul(m, &v)).max(0.0).sqrt();
        for _ in 0..2 {
            for (b, mb) in &basis {
                let c = dot(&v, mb);
                v.iter_mut().zip(b).for_each(|(vi, bi)| *vi -= c * bi);
            }
        }
        let mv = sparse_mul(m, &v);
        let norm = dot(&v, &mv).max(0.0).sqrt();
        if norm > 1e-10 * original && norm > 0.0 {
            basis.push((v.iter().map(|x| x / norm).collect(), mv.iter().map(|x| x / norm).collect()));
        }
    }
    Mat::from_fn(n, basis.len(), |i, j| basis[j].0[i])
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
