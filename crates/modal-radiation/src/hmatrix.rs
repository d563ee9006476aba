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
//! Each entry is evaluated once per block: the rows and columns ACA
//! fetched are kept, a column reads the fetched rows it crosses and a row
//! the fetched columns, and a block ACA gives up on is completed dense
//! from them (it gave up after `m/2` rows and as many columns, a quarter
//! of its entries left). Measured on the demo bowl at 5 296 Hz (5 707
//! unknowns): 5 485 of the 6 488 admissible blocks give up (ranks ≈ 23 of
//! 32 even by SVD at `ε`), 36 % of the stored entries; evaluating them
//! twice had cost 17 % of the assembly.
//!
//! ACA's rank overshoots the SVD's: each low-rank `A` block is then
//! recompressed to `ε` ([`crate::lowrank`]; the right-hand side is taken
//! before). Measured on the demo bowl (release, load ≈ 4, paired runs):
//! at 5 296 Hz largest rank 85 → 60, stored entries 16.6 M → 14.5 M (51 %
//! → 44 % of `n²`), +1.0–1.3 s of assembly against 1.9–3.4 s less in the
//! GMRES solves of its two right-hand sides; at 11 243 Hz 60 % → 53 %,
//! +0–0.9 s against 1.6–2.8 s less; levels within 4·10⁻⁵ dB.
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
                let (data, rhs) = block(asm, rows, cols, admissible);
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

/// The entries of one block `rows × cols` fetched so far, as whole rows
/// and whole columns of `A` and of each source's right-hand-side parts
/// ([`Assembly::row`]): ACA asks for each entry once (a column crossing a
/// fetched row reads it, and so on), and a block ACA gives up on is
/// completed dense from them: it gave up after `m/2` rows and as many
/// columns, so only a quarter of its entries are left to evaluate.
struct Entries<'a, 'b> {
    asm: &'a Assembly<'b>,
    rows: &'a [usize],
    cols: &'a [usize],
    /// Right-hand sides, at least one (the layout of [`Assembly::row`]).
    nrhs: usize,
    /// Where each block row (column) is among the fetched ones.
    row_at: Vec<Option<usize>>,
    col_at: Vec<Option<usize>>,
    /// Fetched rows: `A` (`n_σ`) and the parts (`n_σ × nrhs`, row-major).
    fetched_rows: Vec<(Vec<c64>, Vec<c64>)>,
    /// Fetched columns: `A` (`m`) and the parts (`m × nrhs`, row-major).
    fetched_cols: Vec<(Vec<c64>, Vec<c64>)>,
}

impl<'a, 'b> Entries<'a, 'b> {
    fn new(asm: &'a Assembly<'b>, rows: &'a [usize], cols: &'a [usize]) -> Self {
        Entries {
            asm,
            rows,
            cols,
            nrhs: asm.fields().len().max(1),
            row_at: vec![None; rows.len()],
            col_at: vec![None; cols.len()],
            fetched_rows: Vec::new(),
            fetched_cols: Vec::new(),
        }
    }

    /// Row `i` of the block, `A` and parts: evaluated where no fetched
    /// column crosses it.
    fn row(&mut self, i: usize) -> &(Vec<c64>, Vec<c64>) {
        if self.row_at[i].is_none() {
            let (width, nrhs) = (self.cols.len(), self.nrhs);
            let zero = c64::new(0.0, 0.0);
            let todo: Vec<usize> = (0..width).filter(|&c| self.col_at[c].is_none()).collect();
            let sources: Vec<usize> = todo.iter().map(|&c| self.cols[c]).collect();
            let (mut a, mut parts) = (vec![zero; todo.len()], vec![zero; todo.len() * nrhs]);
            self.asm.row(self.rows[i], &sources, &mut a, &mut parts);
            let (mut ra, mut rp) = (vec![zero; width], vec![zero; width * nrhs]);
            for (t, &c) in todo.iter().enumerate() {
                ra[c] = a[t];
                rp[c * nrhs..(c + 1) * nrhs].copy_from_slice(&parts[t * nrhs..(t + 1) * nrhs]);
            }
            for (c, at) in self.col_at.iter().enumerate() {
                if let Some(k) = at {
                    let (ca, cp) = &self.fetched_cols[*k];
                    ra[c] = ca[i];
                    rp[c * nrhs..(c + 1) * nrhs].copy_from_slice(&cp[i * nrhs..(i + 1) * nrhs]);
                }
            }
            self.row_at[i] = Some(self.fetched_rows.len());
            self.fetched_rows.push((ra, rp));
        }
        self.row_at[i].map(|k| &self.fetched_rows[k]).unwrap_or_else(|| unreachable!())
    }

    /// Column `c` of the block, `A` and parts: evaluated where no fetched
    /// row crosses it.
    fn col(&mut self, c: usize) -> &(Vec<c64>, Vec<c64>) {
        if self.col_at[c].is_none() {
            let (m, nrhs) = (self.rows.len(), self.nrhs);
            let zero = c64::new(0.0, 0.0);
            let (mut ca, mut cp) = (vec![zero; m], vec![zero; m * nrhs]);
            for (i, at) in self.row_at.iter().enumerate() {
                let (a, p) = (&mut ca[i..=i], &mut cp[i * nrhs..(i + 1) * nrhs]);
                match at {
                    Some(k) => {
                        let (ra, rp) = &self.fetched_rows[*k];
                        a[0] = ra[c];
                        p.copy_from_slice(&rp[c * nrhs..(c + 1) * nrhs]);
                    }
                    None => self.asm.row(self.rows[i], &self.cols[c..=c], a, p),
                }
            }
            self.col_at[c] = Some(self.fetched_cols.len());
            self.fetched_cols.push((ca, cp));
        }
        self.col_at[c].map(|k| &self.fetched_cols[k]).unwrap_or_else(|| unreachable!())
    }

    /// The whole block, dense, and its right-hand side part (row-major
    /// `m × nrhs`, each row's parts summed in column order).
    fn dense(mut self) -> (Data, Vec<c64>) {
        let (m, width, nrhs) = (self.rows.len(), self.cols.len(), self.nrhs);
        let zero = c64::new(0.0, 0.0);
        let mut d = vec![zero; m * width];
        let mut rhs = vec![zero; m * nrhs];
        for ((i, row), b) in d.chunks_mut(width.max(1)).enumerate().zip(rhs.chunks_mut(nrhs)) {
            let (a, parts) = self.row(i);
            row.copy_from_slice(a);
            for part in parts.chunks(nrhs) {
                for (bf, p) in b.iter_mut().zip(part) {
                    *bf += p;
                }
            }
        }
        (Data::Dense(d), rhs)
    }
}

/// `M ≈ Σ_k u_k v_kᵀ` for [`aca`]: a matrix given by its rows and columns.
trait Crosses {
    /// Rows of `M`.
    fn rows(&self) -> usize;
    /// Columns of `M`.
    fn cols(&self) -> usize;
    /// Row `i` into `out`.
    fn row(&mut self, i: usize, out: &mut [c64]);
    /// Column `j` into `out`.
    fn col(&mut self, j: usize, out: &mut [c64]);
}

/// The side-by-side block `[A | s_1 R_1 | …]` (module doc) of some entries.
struct SideBySide<'e, 'a, 'b> {
    entries: &'e mut Entries<'a, 'b>,
    /// `s_f`.
    scale: Vec<f64>,
    /// Right-hand sides (`scale.len()`, possibly 0).
    fields: usize,
}

impl Crosses for SideBySide<'_, '_, '_> {
    fn rows(&self) -> usize {
        self.entries.rows.len()
    }

    fn cols(&self) -> usize {
        self.entries.cols.len() * (1 + self.fields)
    }

    fn row(&mut self, i: usize, out: &mut [c64]) {
        let (width, nrhs) = (self.entries.cols.len(), self.entries.nrhs);
        let (a, parts) = self.entries.row(i);
        out[..width].copy_from_slice(a);
        for (f, s) in self.scale.iter().enumerate() {
            for (c, x) in out[(1 + f) * width..(2 + f) * width].iter_mut().enumerate() {
                *x = parts[c * nrhs + f] * s;
            }
        }
    }

    fn col(&mut self, j: usize, out: &mut [c64]) {
        let (width, nrhs) = (self.entries.cols.len(), self.entries.nrhs);
        let (part, c) = (j / width, j % width);
        let (a, parts) = self.entries.col(c);
        if part == 0 {
            out.copy_from_slice(a);
        } else {
            let s = self.scale[part - 1];
            for (o, p) in out.iter_mut().zip(parts.chunks(nrhs)) {
                *o = p[part - 1] * s;
            }
        }
    }
}

/// The block `rows × cols` (module doc) and its right-hand side part
/// (row-major `m × nrhs`): low rank when `admissible` and ACA finds it
/// within half the smaller side, dense otherwise.
fn block(asm: &Assembly<'_>, rows: &[usize], cols: &[usize], admissible: bool) -> (Data, Vec<c64>) {
    let mut entries = Entries::new(asm, rows, cols);
    if admissible {
        if let Some(low) = low_rank(&mut entries) {
            return low;
        }
    }
    entries.dense()
}

/// The low-rank block of some entries (module doc) and its right-hand
/// side part, or `None` when ACA needs more than half the smaller side.
fn low_rank(entries: &mut Entries<'_, '_>) -> Option<(Data, Vec<c64>)> {
    let (m, width, nrhs) = (entries.rows.len(), entries.cols.len(), entries.asm.fields().len());
    let (zero, stride) = (c64::new(0.0, 0.0), entries.nrhs);
    let (a0, p0) = entries.row(0);
    let a0 = a0.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt().max(f64::MIN_POSITIVE);
    let scale: Vec<f64> = (0..nrhs)
        .map(|f| {
            let s = p0.chunks(stride).map(|p| p[f].norm_sqr()).sum::<f64>().sqrt();
            if s > 0.0 {
                a0 / s
            } else {
                1.0
            }
        })
        .collect();
    let mut side = SideBySide { entries, scale, fields: nrhs };
    let (u, v) = aca(&mut side, m.min(width) / 2)?;
    let w: Vec<Vec<c64>> = v.iter().map(|vk| vk[..width].to_vec()).collect();
    let mut rhs = vec![zero; m * nrhs];
    for (f, s) in side.scale.iter().enumerate() {
        for (uk, vk) in u.iter().zip(&v) {
            let t = vk[(1 + f) * width..(2 + f) * width].iter().sum::<c64>() / s;
            for (i, ui) in uk.iter().enumerate() {
                rhs[i * nrhs + f] += ui * t;
            }
        }
    }
    let (u, w) = crate::lowrank::recompress(&u, &w, ACA_TOLERANCE).unwrap_or((u, w));
    Some((Data::LowRank { u, w }, rhs))
}

/// Partial-pivoting ACA (module doc) of an `m × n` matrix given by its rows
/// and columns: `(U, V)` with `M ≈ Σ_k u_k v_kᵀ` to [`ACA_TOLERANCE`], or
/// `None` when the rank would pass `max_rank`.
#[allow(clippy::type_complexity)]
fn aca(mat: &mut dyn Crosses, max_rank: usize) -> Option<(Vec<Vec<c64>>, Vec<Vec<c64>>)> {
    let (m, n) = (mat.rows(), mat.cols());
    let zero = c64::new(0.0, 0.0);
    let (mut us, mut vs): (Vec<Vec<c64>>, Vec<Vec<c64>>) = (Vec::new(), Vec::new());
    let mut used = vec![false; m];
    let mut norm2 = 0.0f64;
    let mut i = 0;
    loop {
        used[i] = true;
        let mut r = vec![zero; n];
        mat.row(i, &mut r);
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
        mat.col(j, &mut u);
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

    /// An `m × n` matrix given entry by entry.
    pub(super) struct Entrywise<F: Fn(usize, usize) -> c64>(pub usize, pub usize, pub F);

    impl<F: Fn(usize, usize) -> c64> Crosses for Entrywise<F> {
        fn rows(&self) -> usize {
            self.0
        }
        fn cols(&self) -> usize {
            self.1
        }
        fn row(&mut self, i: usize, out: &mut [c64]) {
            out.iter_mut().enumerate().for_each(|(j, o)| *o = (self.2)(i, j));
        }
        fn col(&mut self, j: usize, out: &mut [c64]) {
            out.iter_mut().enumerate().for_each(|(i, o)| *o = (self.2)(i, j));
        }
    }

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
        let (u, v) = aca(&mut Entrywise(60, 80, f), 30).expect("low rank");
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
        let r = aca(&mut Entrywise(20, 20, id), 10);
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

    /// Two velocity fields on `mesh`: the normal velocity of a rigid motion
    /// along z, and the same plus an imaginary part varying along x.
    fn two_fields(mesh: &crate::geometry::BoundaryMesh) -> Vec<Vec<c64>> {
        [0.0, 1.0]
            .iter()
            .map(|s| mesh.panels.iter().map(|p| c64::new(p.normal[2], s * 30.0 * p.centroid[0])).collect())
            .collect()
    }

    /// A block completed from the rows and columns fetched so far holds the
    /// entries and right-hand side of a direct evaluation, bit for bit.
    #[test]
    fn fetched_rows_and_columns_complete_the_block_exactly() {
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.06, 0.04], 2);
        let near = NearField::new(&mesh);
        let k = 2.0 * std::f64::consts::PI * 3000.0 / 343.0;
        let clusters = Clusters::identity(mesh.len());
        let fields = two_fields(&mesh);
        let kern = Kernels::new(k);
        let asm = Assembly::new(&mesh, &near, &clusters, &kern, c64::new(0.0, 1.0 / k), &fields, true);
        let rows: Vec<usize> = (0..asm.len()).step_by(7).take(30).collect();
        let cols: Vec<usize> = (3..asm.len()).step_by(5).take(40).collect();
        let (m, n, nrhs) = (rows.len(), cols.len(), fields.len());
        let zero = c64::new(0.0, 0.0);
        let mut entries = Entries::new(&asm, &rows, &cols);
        for (i, c) in [(4, 9), (0, 0), (17, 39), (4, 21)] {
            entries.col(c);
            entries.row(i);
        }
        let (Data::Dense(d), rhs) = entries.dense() else { panic!("dense block expected") };
        let (mut a, mut parts) = (vec![zero; n], vec![zero; n * nrhs]);
        for (i, &row) in rows.iter().enumerate() {
            asm.row(row, &cols, &mut a, &mut parts);
            assert!(d[i * n..(i + 1) * n] == a[..], "row {i}");
            let b: Vec<c64> = (0..nrhs).map(|f| parts.chunks(nrhs).fold(zero, |s, p| s + p[f])).collect();
            assert!(rhs[i * nrhs..(i + 1) * nrhs] == b[..], "right-hand side of row {i}");
        }
        assert_eq!(d.len(), m * n);
    }

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
        let fields = two_fields(&mesh);
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
