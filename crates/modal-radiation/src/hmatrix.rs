//! Hierarchical (H-) matrix of the clustered Burton–Miller system of
//! [`crate::assembly`]: far blocks stored as low-rank products found by
//! adaptive cross approximation, near blocks dense.
//!
//! **Cluster tree.** The unknowns (pressure clusters of panels, each with
//! a centre and the box of its panels' corners) are bisected recursively:
//! each node's unknowns are sorted by centre along the longest side of the
//! box of their centres (ties by index) and halved, down to
//! [`LEAF_SIZE`]. Each node keeps the box of its panels, which holds every
//! point the row of an unknown is collocated at.
//!
//! **Blocks.** Node pairs `(τ, σ)` are split until they are admissible,
//! `min(diam τ, diam σ) ≤ η·dist(τ, σ)` (box diagonals and distance,
//! [`ETA`]), or a leaf pair (dense). On an admissible block the Helmholtz
//! kernels are smooth in both arguments, so its rows are, to a relative
//! error `ε`, combinations of few rows: `M ≈ U Vᵀ`, rank `r ≪ m, n`.
//!
//! **ACA with partial pivoting** finds `U Vᵀ` from `r` rows and `r`
//! columns of the residual `R_k = M − Σ_{l<k} u_l v_lᵀ`: take row `i_k` of
//! `R_k`, its largest entry `j_k`, `v_k = R_k[i_k, :] / R_k[i_k, j_k]`,
//! `u_k = R_k[:, j_k]`, next row `i_{k+1} = argmax |u_k|` (unused rows);
//! stop when `‖u_k‖‖v_k‖ ≤ ε ‖S_k‖_F`, `S_k = Σ_{l≤k} u_l v_lᵀ`, with
//! `‖S_k‖²_F = ‖S_{k−1}‖²_F + 2 Re Σ_{l<k} (u_l^H u_k)(v_l^H v_k) + ‖u_k‖²‖v_k‖²`.
//! A block that would need rank above half its smaller side is dense.
//!
//! The entries are those of the dense assembly ([`Assembly::row`], with
//! its far cluster sums): `A_ic` and each source cluster's part of the
//! right-hand sides `R_f(i, c) = Σ_{j∈c} op_ij q_fj` (`b_i = Σ_c R_f(i, c)`),
//! which one row evaluation gives together. So ACA runs once per block on
//! the side-by-side matrix `[A | s_1 R_1 | … ]` (`s_f` evens the parts'
//! norms on the block's first row): the parts share their dependence on
//! the row point, and the rank of the whole is about that of `A`. `A`'s
//! factors are kept; the right-hand side's block is used once,
//! `b_τ += U (V_fᵀ 1) / s_f`.
//!
//! Cost: `r (m + n_σ)` entries per far block instead of `m n_σ`, and the
//! product `A x` in the stored entries instead of `n²`.
//!
//! Determinism: blocks are built in parallel, each by one thread in a
//! fixed order; the right-hand side and every product are summed over the
//! blocks in their fixed order: bit-identical for any thread count.

use faer::c64;
use rayon::prelude::*;

use crate::assembly::Assembly;

/// Most unknowns in a leaf of the cluster tree.
pub const LEAF_SIZE: usize = 32;

/// Admissibility `min(diam τ, diam σ) ≤ η·dist(τ, σ)`. Measured on the
/// demo bowl at 5 251 and 5 754 unknowns: η = 1 stores 63 % of `n²` and
/// takes longest; η = 2 stores 54–56 % (largest rank 60–81), η = 3–4 about
/// 48–53 % at ranks up to 144 and no faster.
pub const ETA: f64 = 2.0;

/// Relative Frobenius error `ε` at which ACA stops on each block.
pub const ACA_TOLERANCE: f64 = 1e-6;

/// One node of the cluster tree: unknowns `perm[start..end]`, the box of
/// their spheres, its children.
#[derive(Clone, Debug)]
struct Node {
    start: usize,
    end: usize,
    lo: [f64; 3],
    hi: [f64; 3],
    children: Option<[usize; 2]>,
}

impl Node {
    fn diameter(&self) -> f64 {
        (0..3).map(|k| (self.hi[k] - self.lo[k]).powi(2)).sum::<f64>().sqrt()
    }

    fn distance(&self, o: &Node) -> f64 {
        (0..3).map(|k| (self.lo[k] - o.hi[k]).max(o.lo[k] - self.hi[k]).max(0.0).powi(2)).sum::<f64>().sqrt()
    }
}

/// An unknown's centre and the box (low, high) of its panels.
type Bounds = ([f64; 3], [f64; 3], [f64; 3]);

/// Recursive bisection of the unknowns (module doc); `perm` lists them in
/// tree order, node 0 the root.
struct ClusterTree {
    perm: Vec<usize>,
    nodes: Vec<Node>,
}

impl ClusterTree {
    /// The tree of unknowns given by (centre, box low, box high).
    fn new(bounds: &[Bounds]) -> ClusterTree {
        let mut tree = ClusterTree { perm: (0..bounds.len()).collect(), nodes: Vec::new() };
        tree.split(bounds, 0, bounds.len());
        tree
    }

    /// Adds the node of `perm[start..end]` and its subtree; returns its index.
    fn split(&mut self, bounds: &[Bounds], start: usize, end: usize) -> usize {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let (mut clo, mut chi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &u in &self.perm[start..end] {
            let (c, blo, bhi) = bounds[u];
            for k in 0..3 {
                lo[k] = lo[k].min(blo[k]);
                hi[k] = hi[k].max(bhi[k]);
                clo[k] = clo[k].min(c[k]);
                chi[k] = chi[k].max(c[k]);
            }
        }
        let id = self.nodes.len();
        self.nodes.push(Node { start, end, lo, hi, children: None });
        if end - start > LEAF_SIZE {
            let axis = (0..3).max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b]))).unwrap_or(0);
            self.perm[start..end]
                .sort_by(|&a, &b| bounds[a].0[axis].total_cmp(&bounds[b].0[axis]).then(a.cmp(&b)));
            let mid = start + (end - start) / 2;
            let left = self.split(bounds, start, mid);
            let right = self.split(bounds, mid, end);
            self.nodes[id].children = Some([left, right]);
        }
        id
    }

    /// The blocks of the matrix as (row node, column node, admissible),
    /// in a fixed order.
    fn blocks(&self) -> Vec<(usize, usize, bool)> {
        let mut out = Vec::new();
        let mut stack = vec![(0usize, 0usize)];
        while let Some((t, s)) = stack.pop() {
            let (nt, ns) = (&self.nodes[t], &self.nodes[s]);
            if nt.diameter().min(ns.diameter()) <= ETA * nt.distance(ns) {
                out.push((t, s, true));
                continue;
            }
            match (nt.children, ns.children) {
                (None, None) => out.push((t, s, false)),
                (None, Some([a, b])) => stack.extend([(t, b), (t, a)]),
                (Some([a, b]), None) => stack.extend([(b, s), (a, s)]),
                (Some([a, b]), Some([c, d])) => stack.extend([(b, d), (b, c), (a, d), (a, c)]),
            }
        }
        out
    }
}

/// The stored part of one block of `A`.
enum Data {
    /// `m × n_σ`, row-major.
    Dense(Vec<c64>),
    /// `U` (`r` columns of length `m`) and `W = Vᵀ` (`r` rows of length `n_σ`).
    LowRank { u: Vec<Vec<c64>>, w: Vec<Vec<c64>> },
}

struct Block {
    /// Rows `perm[rows.0..rows.1]`, columns `perm[cols.0..cols.1]`.
    rows: (usize, usize),
    cols: (usize, usize),
    data: Data,
}

/// The compressed system matrix `A` (module doc).
pub struct HMatrix {
    perm: Vec<usize>,
    blocks: Vec<Block>,
    /// Indices of the blocks with the same rows, in block order.
    groups: Vec<Vec<usize>>,
    diagonal: Vec<c64>,
}

/// Statistics of a compressed matrix.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HStats {
    /// Dense blocks.
    pub dense_blocks: usize,
    /// Low-rank blocks.
    pub low_rank_blocks: usize,
    /// Largest rank of a low-rank block.
    pub max_rank: usize,
    /// Complex entries stored.
    pub stored: usize,
}

impl HMatrix {
    /// The compressed `A` and the right-hand sides (row-major `n × nrhs`)
    /// of an assembly.
    pub(crate) fn assemble(asm: &Assembly<'_>) -> (HMatrix, Vec<c64>) {
        let n = asm.len();
        let nrhs = asm.fields().len();
        let zero = c64::new(0.0, 0.0);
        let bounds: Vec<Bounds> = (0..n).map(|c| asm.bounds(c)).collect();
        let tree = ClusterTree::new(&bounds);
        let perm = tree.perm.clone();
        let built: Vec<(Block, Vec<c64>)> = tree
            .blocks()
            .into_par_iter()
            .map(|(t, s, admissible)| {
                let (nt, ns) = (&tree.nodes[t], &tree.nodes[s]);
                let (rows, cols) = (&perm[nt.start..nt.end], &perm[ns.start..ns.end]);
                let low = if admissible { low_rank(asm, rows, cols) } else { None };
                let (data, rhs) = low.unwrap_or_else(|| dense(asm, rows, cols));
                (Block { rows: (nt.start, nt.end), cols: (ns.start, ns.end), data }, rhs)
            })
            .collect();
        let mut rhs = vec![zero; n * nrhs];
        let mut diagonal = vec![zero; n];
        let mut blocks = Vec::with_capacity(built.len());
        for (block, b) in built {
            for (i, bi) in b.chunks(nrhs.max(1)).enumerate() {
                let row = perm[block.rows.0 + i];
                for (out, v) in rhs[row * nrhs..(row + 1) * nrhs].iter_mut().zip(bi) {
                    *out += v;
                }
            }
            if let Data::Dense(d) = &block.data {
                let width = block.cols.1 - block.cols.0;
                for p in block.rows.0.max(block.cols.0)..block.rows.1.min(block.cols.1) {
                    diagonal[perm[p]] = d[(p - block.rows.0) * width + (p - block.cols.0)];
                }
            }
            blocks.push(block);
        }
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut group_of = std::collections::BTreeMap::new();
        for (i, b) in blocks.iter().enumerate() {
            let g = *group_of.entry(b.rows).or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
            groups[g].push(i);
        }
        (HMatrix { perm, blocks, groups, diagonal }, rhs)
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.perm.len()
    }

    /// True for an empty matrix.
    pub fn is_empty(&self) -> bool {
        self.perm.is_empty()
    }

    /// The diagonal `A_ii`.
    pub fn diagonal(&self) -> &[c64] {
        &self.diagonal
    }

    /// `y = A x`: the blocks of each row node in parallel, each node's
    /// blocks in their fixed order, the nodes summed in a fixed order.
    pub fn apply(&self, x: &[c64], y: &mut [c64]) {
        let zero = c64::new(0.0, 0.0);
        let xp: Vec<c64> = self.perm.iter().map(|&c| x[c]).collect();
        let parts: Vec<Vec<c64>> = self
            .groups
            .par_iter()
            .map(|g| {
                let rows = self.blocks[g[0]].rows;
                let mut out = vec![zero; rows.1 - rows.0];
                for b in g.iter().map(|&b| &self.blocks[b]) {
                    let xs = &xp[b.cols.0..b.cols.1];
                    match &b.data {
                        Data::Dense(d) => {
                            for (o, row) in out.iter_mut().zip(d.chunks(xs.len())) {
                                *o += dot(row, xs);
                            }
                        }
                        Data::LowRank { u, w } => {
                            for (uk, wk) in u.iter().zip(w) {
                                let t = dot(wk, xs);
                                for (o, v) in out.iter_mut().zip(uk) {
                                    *o += v * t;
                                }
                            }
                        }
                    }
                }
                out
            })
            .collect();
        let mut yp = vec![zero; self.len()];
        for (g, part) in self.groups.iter().zip(parts) {
            let rows = self.blocks[g[0]].rows;
            for (o, v) in yp[rows.0..rows.1].iter_mut().zip(part) {
                *o += v;
            }
        }
        for (&c, v) in self.perm.iter().zip(yp) {
            y[c] = v;
        }
    }

    /// Block counts, largest rank and stored entries.
    pub fn stats(&self) -> HStats {
        let mut s = HStats::default();
        for b in &self.blocks {
            match &b.data {
                Data::Dense(d) => {
                    s.dense_blocks += 1;
                    s.stored += d.len();
                }
                Data::LowRank { u, w } => {
                    s.low_rank_blocks += 1;
                    s.max_rank = s.max_rank.max(u.len());
                    s.stored += u.iter().chain(w).map(Vec::len).sum::<usize>();
                }
            }
        }
        s
    }

    /// Memory held by the blocks [bytes].
    pub fn bytes(&self) -> usize {
        self.stats().stored * std::mem::size_of::<c64>()
    }
}

impl HMatrix {
    /// The unknowns of each leaf of the cluster tree of `asm` (module doc),
    /// the leaves in tree order: blocks of nearby unknowns for
    /// [`crate::precond::BlockJacobi`] on a dense system.
    pub(crate) fn leaves(asm: &Assembly<'_>) -> Vec<Vec<usize>> {
        let bounds: Vec<Bounds> = (0..asm.len()).map(|c| asm.bounds(c)).collect();
        let tree = ClusterTree::new(&bounds);
        tree.nodes
            .iter()
            .filter(|nd| nd.children.is_none())
            .map(|nd| tree.perm[nd.start..nd.end].to_vec())
            .collect()
    }

    /// The diagonal blocks `A_ττ` of the leaves `τ` (always dense: a leaf
    /// is never admissible with itself) as (unknowns, row-major entries).
    pub(crate) fn diagonal_blocks(&self) -> impl Iterator<Item = (&[usize], &[c64])> {
        self.blocks.iter().filter(|b| b.rows == b.cols).filter_map(|b| match &b.data {
            Data::Dense(d) => Some((&self.perm[b.rows.0..b.rows.1], &d[..])),
            Data::LowRank { .. } => None,
        })
    }

    /// `ys[v] = A xs[v]` for several vectors in one pass over the stored
    /// blocks (each block is read once for all of them), every row sum by
    /// [`crate::gmres::row_dot`]: each vector gets the same bits as it
    /// would alone, and [`HMatrix::apply`]'s up to rounding.
    pub(crate) fn apply_many(&self, xs: &[&[c64]], ys: &mut [Vec<c64>]) {
        let zero = c64::new(0.0, 0.0);
        let nv = xs.len();
        let xp: Vec<Vec<c64>> = xs.iter().map(|x| self.perm.iter().map(|&c| x[c]).collect()).collect();
        let parts: Vec<Vec<c64>> = self
            .groups
            .par_iter()
            .map(|g| {
                let rows = self.blocks[g[0]].rows;
                // out[i·nv + v]: row i of the node, vector v.
                let mut out = vec![zero; (rows.1 - rows.0) * nv];
                let mut t = vec![zero; nv];
                for b in g.iter().map(|&b| &self.blocks[b]) {
                    let (c0, c1) = b.cols;
                    match &b.data {
                        Data::Dense(d) => {
                            for (o, row) in out.chunks_mut(nv).zip(d.chunks(c1 - c0)) {
                                for (ov, x) in o.iter_mut().zip(&xp) {
                                    *ov += crate::gmres::row_dot(row, &x[c0..c1]);
                                }
                            }
                        }
                        Data::LowRank { u, w } => {
                            for (uk, wk) in u.iter().zip(w) {
                                for (tv, x) in t.iter_mut().zip(&xp) {
                                    *tv = crate::gmres::row_dot(wk, &x[c0..c1]);
                                }
                                for (o, v) in out.chunks_mut(nv).zip(uk) {
                                    for (ov, tv) in o.iter_mut().zip(&t) {
                                        *ov += v * tv;
                                    }
                                }
                            }
                        }
                    }
                }
                out
            })
            .collect();
        let mut yp = vec![zero; self.len() * nv];
        for (g, part) in self.groups.iter().zip(parts) {
            let rows = self.blocks[g[0]].rows;
            for (o, v) in yp[rows.0 * nv..rows.1 * nv].iter_mut().zip(part) {
                *o += v;
            }
        }
        for (p, &c) in self.perm.iter().enumerate() {
            for (y, v) in ys.iter_mut().zip(&yp[p * nv..(p + 1) * nv]) {
                y[c] = *v;
            }
        }
    }
}

/// `Σ a_i b_i` in order.
fn dot(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).fold(c64::new(0.0, 0.0), |s, (x, y)| s + x * y)
}

/// The dense block of `rows × cols` and its right-hand side part
/// (row-major `m × nrhs`).
fn dense(asm: &Assembly<'_>, rows: &[usize], cols: &[usize]) -> (Data, Vec<c64>) {
    let (m, width, nrhs) = (rows.len(), cols.len(), asm.fields().len().max(1));
    let zero = c64::new(0.0, 0.0);
    let mut d = vec![zero; m * width];
    let mut rhs = vec![zero; m * nrhs];
    let mut parts = vec![zero; width * nrhs];
    for ((&i, row), b) in rows.iter().zip(d.chunks_mut(width)).zip(rhs.chunks_mut(nrhs)) {
        asm.row(i, cols, row, &mut parts);
        for part in parts.chunks(nrhs) {
            for (bf, p) in b.iter_mut().zip(part) {
                *bf += p;
            }
        }
    }
    (Data::Dense(d), rhs)
}

/// The low-rank block of `rows × cols` (module doc) and its right-hand
/// side part, or `None` when ACA needs more than half the smaller side.
fn low_rank(asm: &Assembly<'_>, rows: &[usize], cols: &[usize]) -> Option<(Data, Vec<c64>)> {
    let (m, width, nrhs) = (rows.len(), cols.len(), asm.fields().len());
    let zero = c64::new(0.0, 0.0);
    // One row of [A | R_1 | …] unscaled: A's entries, then each field's.
    let fetch = |i: usize, a: &mut [c64], r: &mut [c64]| {
        let mut parts = vec![zero; width * nrhs.max(1)];
        asm.row(rows[i], cols, a, &mut parts);
        for f in 0..nrhs {
            for (c, x) in r[f * width..(f + 1) * width].iter_mut().enumerate() {
                *x = parts[c * nrhs + f];
            }
        }
    };
    let (mut a0, mut r0) = (vec![zero; width], vec![zero; width * nrhs]);
    fetch(0, &mut a0, &mut r0);
    let size = |v: &[c64]| v.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    let scale: Vec<f64> = r0
        .chunks(width.max(1))
        .map(|r| {
            let s = size(r);
            if s > 0.0 {
                size(&a0).max(f64::MIN_POSITIVE) / s
            } else {
                1.0
            }
        })
        .collect();
    let full = width * (1 + nrhs);
    let row = |i: usize, out: &mut [c64]| {
        let (a, r) = out.split_at_mut(width);
        fetch(i, a, r);
        for (f, s) in scale.iter().enumerate() {
            r[f * width..(f + 1) * width].iter_mut().for_each(|x| *x *= s);
        }
    };
    let col = |j: usize, out: &mut [c64]| {
        let (part, c) = (j / width, j % width);
        let mut b = vec![zero; nrhs.max(1)];
        for (o, &i) in out.iter_mut().zip(rows) {
            let mut a = [zero];
            asm.row(i, &cols[c..=c], &mut a, &mut b);
            *o = if part == 0 { a[0] } else { b[part - 1] * scale[part - 1] };
        }
    };
    let (u, v) = aca(m, full, &row, &col, m.min(width) / 2)?;
    let w = v.iter().map(|vk| vk[..width].to_vec()).collect();
    let mut rhs = vec![zero; m * nrhs];
    for (f, s) in scale.iter().enumerate() {
        for (uk, vk) in u.iter().zip(&v) {
            let t = vk[(1 + f) * width..(2 + f) * width].iter().sum::<c64>() / s;
            for (i, ui) in uk.iter().enumerate() {
                rhs[i * nrhs + f] += ui * t;
            }
        }
    }
    Some((Data::LowRank { u, w }, rhs))
}

/// Partial-pivoting ACA (module doc) of an `m × n` matrix given by its rows
/// `row(i, out)` and columns `col(j, out)`: `(U, V)` with `M ≈ Σ_k u_k v_kᵀ`
/// to [`ACA_TOLERANCE`], or `None` when the rank would pass `max_rank`.
#[allow(clippy::type_complexity)]
fn aca(
    m: usize,
    n: usize,
    row: &dyn Fn(usize, &mut [c64]),
    col: &dyn Fn(usize, &mut [c64]),
    max_rank: usize,
) -> Option<(Vec<Vec<c64>>, Vec<Vec<c64>>)> {
    let zero = c64::new(0.0, 0.0);
    let (mut us, mut vs): (Vec<Vec<c64>>, Vec<Vec<c64>>) = (Vec::new(), Vec::new());
    let mut used = vec![false; m];
    let mut norm2 = 0.0f64;
    let mut i = 0;
    loop {
        used[i] = true;
        let mut r = vec![zero; n];
        row(i, &mut r);
        for (uk, vk) in us.iter().zip(&vs) {
            let a = uk[i];
            for (x, v) in r.iter_mut().zip(vk) {
                *x -= a * v;
            }
        }
        let (j, pivot) = r.iter().enumerate().fold((0, 0.0f64), |best, (j, x)| {
            let a = x.norm();
            if a > best.1 {
                (j, a)
            } else {
                best
            }
        });
        if pivot == 0.0 {
            // Row `i` is already represented: try the next unused row.
            match used.iter().position(|&u| !u) {
                Some(next) => {
                    i = next;
                    continue;
                }
                None => break,
            }
        }
        if us.len() >= max_rank {
            return None;
        }
        let inv = 1.0 / r[j];
        let v: Vec<c64> = r.iter().map(|x| x * inv).collect();
        let mut u = vec![zero; m];
        col(j, &mut u);
        for (uk, vk) in us.iter().zip(&vs) {
            let a = vk[j];
            for (x, w) in u.iter_mut().zip(uk) {
                *x -= a * w;
            }
        }
        let (uu, vv) = (sq(&u), sq(&v));
        let cross: f64 = us.iter().zip(&vs).map(|(uk, vk)| (cdot(uk, &u) * cdot(vk, &v)).re).sum();
        norm2 += uu * vv + 2.0 * cross;
        let next =
            (0..m).filter(|&p| !used[p]).max_by(|&a, &b| u[a].norm().total_cmp(&u[b].norm()).then(b.cmp(&a)));
        us.push(u);
        vs.push(v);
        if (uu * vv).sqrt() <= ACA_TOLERANCE * norm2.max(0.0).sqrt() {
            break;
        }
        match next {
            Some(p) => i = p,
            None => break,
        }
    }
    Some((us, vs))
}

fn sq(a: &[c64]) -> f64 {
    a.iter().map(|z| z.norm_sqr()).sum()
}

/// `a^H b`.
fn cdot(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).fold(c64::new(0.0, 0.0), |s, (x, y)| s + x.conj() * y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aca_recovers_a_smooth_kernel_block_to_its_tolerance() {
        // e^{ik|x−y|}/|x−y| between two separated point rows: numerically low rank.
        let xs: Vec<f64> = (0..60).map(|i| i as f64 * 0.01).collect();
        let ys: Vec<f64> = (0..80).map(|j| 2.0 + j as f64 * 0.0125).collect();
        let k = 10.0;
        let f = |i: usize, j: usize| {
            let r = ys[j] - xs[i];
            c64::new((k * r).cos(), (k * r).sin()) / r
        };
        let (u, v) = aca(
            60,
            80,
            &|i, out: &mut [c64]| out.iter_mut().enumerate().for_each(|(j, o)| *o = f(i, j)),
            &|j, out: &mut [c64]| out.iter_mut().enumerate().for_each(|(i, o)| *o = f(i, j)),
            30,
        )
        .expect("low rank");
        assert!(u.len() < 15, "rank {}", u.len());
        let (mut err, mut size) = (0.0, 0.0);
        for i in 0..60 {
            for j in 0..80 {
                let approx: c64 = u.iter().zip(&v).map(|(uk, vk)| uk[i] * vk[j]).sum();
                err += (approx - f(i, j)).norm_sqr();
                size += f(i, j).norm_sqr();
            }
        }
        let rel = (err / size).sqrt();
        assert!(rel < 10.0 * ACA_TOLERANCE, "relative error {rel}");
    }

    #[test]
    fn a_full_rank_block_gives_up() {
        let id = |i: usize, j: usize| c64::new(if i == j { 1.0 } else { 0.0 }, 0.0);
        let r = aca(
            20,
            20,
            &|i, out: &mut [c64]| out.iter_mut().enumerate().for_each(|(j, o)| *o = id(i, j)),
            &|j, out: &mut [c64]| out.iter_mut().enumerate().for_each(|(i, o)| *o = id(i, j)),
            10,
        );
        assert!(r.is_none());
    }

    #[test]
    fn blocks_tile_the_matrix_once() {
        let bounds: Vec<Bounds> = (0..500)
            .map(|i| {
                let t = i as f64 * 0.7;
                let c = [t.cos(), t.sin(), 0.002 * i as f64];
                (c, c.map(|x| x - 0.01), c.map(|x| x + 0.01))
            })
            .collect();
        let tree = ClusterTree::new(&bounds);
        let mut sorted = tree.perm.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..500).collect::<Vec<_>>());
        let mut covered = vec![0u8; 500 * 500];
        let blocks = tree.blocks();
        assert!(blocks.iter().any(|b| b.2) && blocks.iter().any(|b| !b.2));
        for (t, s, admissible) in blocks {
            let (nt, ns) = (&tree.nodes[t], &tree.nodes[s]);
            assert!(admissible || (nt.end - nt.start <= LEAF_SIZE && ns.end - ns.start <= LEAF_SIZE));
            for i in nt.start..nt.end {
                for j in ns.start..ns.end {
                    covered[i * 500 + j] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
    }
}

#[cfg(test)]
mod system_tests {
    use super::*;
    use crate::cluster::{Adjacency, Clusters};
    use crate::kernels::Kernels;
    use crate::near::NearField;

    /// The compressed matrix against the dense assembly of the same system
    /// (an ellipsoid, 1 280 panels, 6 kHz, two fields): product
    /// with a fixed vector, diagonal and right-hand sides; and the same bits
    /// on one thread and on three. Measured (`cargo test -p modal-radiation
    /// --lib compressed_system -- --nocapture`): 1 101 unknowns, product
    /// within 1e-8, right-hand sides within 1e-7.
    #[test]
    fn compressed_system_matches_the_dense_one() {
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.06, 0.04], 3);
        let near = NearField::new(&mesh);
        let k = 2.0 * std::f64::consts::PI * 6000.0 / 343.0;
        let clusters = Clusters::grow(&mesh, &Adjacency::new(&mesh), 0.6 / k);
        let fields: Vec<Vec<c64>> = [0.0, 1.0]
            .iter()
            .map(|s| mesh.panels.iter().map(|p| c64::new(p.normal[2], s * 30.0 * p.centroid[0])).collect())
            .collect();
        let kern = Kernels::new(k);
        let asm = Assembly::new(&mesh, &near, &clusters, &kern, c64::new(0.0, 1.0 / k), &fields, true);
        let n = asm.len();
        let (at, rhs) = crate::assembly::assemble_dense(&asm);
        let (h, hrhs) = HMatrix::assemble(&asm);
        let stats = h.stats();
        assert!(stats.low_rank_blocks > 0 && stats.stored < n * n, "{stats:?}, n = {n}");
        let x: Vec<c64> =
            (0..n).map(|i| c64::new((i as f64 * 0.37).sin(), (i as f64 * 0.11).cos())).collect();
        let mut y = vec![c64::new(0.0, 0.0); n];
        h.apply(&x, &mut y);
        let (mut err, mut size) = (0.0, 0.0);
        for i in 0..n {
            let s: c64 = (0..n).map(|j| at[i * n + j] * x[j]).sum();
            err += (s - y[i]).norm_sqr();
            size += s.norm_sqr();
            assert_eq!(h.diagonal()[i], at[i * n + i]);
        }
        let product = (err / size).sqrt();
        let rel = |a: &[c64], b: &[c64]| {
            let d: f64 = a.iter().zip(b).map(|(a, b)| (a - b).norm_sqr()).sum();
            (d / a.iter().map(|a| a.norm_sqr()).sum::<f64>()).sqrt()
        };
        let b = rel(&rhs, &hrhs);
        eprintln!("n {n}, {stats:?}: product relative error {product:.2e}, right-hand sides {b:.2e}");
        assert!(product < 1e-5 && b < 1e-5, "product {product}, right-hand sides {b}");
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let (h, rhs) = HMatrix::assemble(&asm);
                let mut y = vec![c64::new(0.0, 0.0); n];
                h.apply(&x, &mut y);
                (rhs, y)
            })
        };
        assert!(on(1) == on(3), "thread count changed the compressed system");
    }
}
