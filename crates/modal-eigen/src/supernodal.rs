//! Numeric supernodal factorization `LLᵀ` / `LDLᵀ` (no pivoting) of the shifted matrix on
//! faer's symbolic structure, split over two cores along the elimination tree.
//!
//! Why not faer's numeric factorization: it is left-looking over the supernodes in order and
//! parallel only inside each dense product, which does not pay for the many small supernodes
//! of a 3D mesh (30k DOF: one core 0.45–0.5 s, two cores no faster). Here the supernodes
//! are dealt to the same two bins of disjoint subtrees as the tiled solves (`tiled::split`):
//!
//! - the bins factor their supernodes at the same time (a supernode's updates come only from
//!   its descendants, which are in its own bin);
//! - then the top supernodes (the nested-dissection separators) in order; each one's list of
//!   descendant updates is cut in two halves, computed in parallel — the first into the
//!   supernode itself, the second into a zeroed copy added afterwards — and large dense
//!   blocks factor with faer's parallel kernels.
//!
//! The algorithm per supernode is the classical left-looking one (as faer's): scatter the
//! entries of A, subtract `L_d,rows · L_d,colsᵀ` (times `D_d` for LDLᵀ) of every descendant d
//! whose pattern meets the supernode's columns, factor the diagonal block densely, and solve
//! for the rows below it. The values are written in faer's layout (column-major block per
//! supernode, diagonal block first), so faer's and the tiled solves read them unchanged.
//!
//! Only the lower triangle of each update's square part is computed (the separators' updates
//! are nearly square; the full product doubled their cost).
//!
//! Measured on the 30k-DOF box (`supernodal_speed`, below): two cores 354 ms, one core
//! 527 ms, faer's (one core, with its allocation) 617 ms; in the whole solve the factor phase
//! went from 0.68–0.95 to 0.58–0.63 s (4 interleaved pairs) and the solve from a median
//! 2.47 to 2.35 s (8 pairs, faster in 7). Used below faer's parallel threshold
//! (`PARALLEL_LLT_NNZ`); the early inertia count, one core beside the iteration, keeps faer's.
//!
//! Reproducibility: the bins, the halves of each update list, the dense kernels' split
//! (`Par::rayon(2)` whatever the pool) and every summation order depend on the structure
//! only, so one thread or two give the same bits (tested).

use crate::tiled::FactorKind;
use crate::types::EigenError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::SymbolicSparseColMatRef;
use faer::{Accum, MatMut, MatRef, Par};
use std::ops::Range;

/// Supernodes with at least this many columns factor their diagonal block with two threads.
const PARALLEL_DENSE_COLUMNS: usize = 256;

/// One supernode of the factor.
struct Node {
    start: usize,
    ncols: usize,
    /// Offset of its block in the values.
    offset: usize,
    /// Its pattern rows (below the diagonal block), in `Plan::rows`.
    pattern: Range<usize>,
}

impl Node {
    fn nrows(&self) -> usize {
        self.ncols + self.pattern.len()
    }
}

/// A descendant `d`'s contribution to a supernode: `d`'s pattern rows from index `first` on,
/// of which the first `count` lie in the supernode's columns.
#[derive(Clone, Copy)]
struct Update {
    d: usize,
    first: usize,
    count: usize,
}

/// Everything about the factorization that depends on the structure only.
pub struct Plan {
    n: usize,
    nodes: Vec<Node>,
    rows: Vec<usize>,
    /// Per supernode, its updates in `updates` (descendants ascending).
    update_ptr: Vec<usize>,
    updates: Vec<Update>,
    /// Position in the values of each entry of the (unpermuted, upper) pattern of A.
    a_to_l: Vec<usize>,
    len_val: usize,
    /// The two bins of subtrees and the top, as supernode lists (ascending).
    bins: [Vec<usize>; 2],
    top: Vec<usize>,
    /// For each top supernode, where its update list is cut into two halves.
    top_cut: Vec<usize>,
}

impl Plan {
    /// The plan for faer's supernodal structure `sn` with the fill-reducing permutation
    /// `perm_inv` (old → new) of the upper-triangular pattern `a` of A; `None` if the tree
    /// does not split into two bins worth running in parallel.
    pub fn new(
        sn: &SymbolicSupernodalCholesky<usize>,
        perm_inv: &[usize],
        a: SymbolicSparseColMatRef<'_, usize>,
        min_values: usize,
    ) -> Option<Self> {
        let n = sn.nrows();
        let (begin, end, val_ptr) = (sn.supernode_begin(), sn.supernode_end(), sn.col_ptr_for_val());
        let mut rows = Vec::new();
        let nodes: Vec<Node> = (0..sn.n_supernodes())
            .map(|s| {
                let first = rows.len();
                rows.extend_from_slice(sn.supernode(s).pattern());
                Node {
                    start: begin[s],
                    ncols: end[s] - begin[s],
                    offset: val_ptr[s],
                    pattern: first..rows.len(),
                }
            })
            .collect();
        let mut node_of_column = vec![0usize; n];
        for (s, node) in nodes.iter().enumerate() {
            node_of_column[node.start..node.start + node.ncols].fill(s);
        }
        let (update_ptr, updates) = update_lists(&nodes, &rows, &node_of_column);
        let a_to_l = assembly_map(&nodes, &rows, &node_of_column, perm_inv, a)?;
        // Work per supernode: its dense factorization and the updates it receives.
        let work: Vec<usize> = (0..nodes.len())
            .map(|s| {
                let node = &nodes[s];
                let own = node.ncols * node.ncols * node.nrows();
                let received: usize = updates[update_ptr[s]..update_ptr[s + 1]]
                    .iter()
                    .map(|u| (nodes[u.d].pattern.len() - u.first) * u.count * nodes[u.d].ncols)
                    .sum();
                own + received
            })
            .collect();
        let parent: Vec<Option<usize>> = nodes
            .iter()
            .map(|node| rows.get(node.pattern.clone()).and_then(|p| p.first()).map(|&r| node_of_column[r]))
            .collect();
        let starts: Vec<usize> = nodes.iter().map(|x| x.start).collect();
        let ncols: Vec<usize> = nodes.iter().map(|x| x.ncols).collect();
        let cut = crate::tiled::split_tree(&starts, &ncols, &parent, &work, min_values)?;
        let flatten = |r: &[Range<usize>]| -> Vec<usize> { r.iter().flat_map(|x| x.clone()).collect() };
        let top = flatten(&cut.top);
        // Cut each top supernode's update list where half of its update work is done.
        let top_cut = top
            .iter()
            .map(|&s| {
                let list = &updates[update_ptr[s]..update_ptr[s + 1]];
                let cost = |u: &Update| (nodes[u.d].pattern.len() - u.first) * u.count * nodes[u.d].ncols;
                let total: usize = list.iter().map(cost).sum();
                let mut acc = 0;
                list.iter()
                    .position(|u| {
                        acc += cost(u);
                        2 * acc >= total
                    })
                    .map_or(0, |p| p + 1)
            })
            .collect();
        Some(Self {
            n,
            nodes,
            rows,
            update_ptr,
            updates,
            a_to_l,
            len_val: sn.len_val(),
            bins: [flatten(&cut.bins[0]), flatten(&cut.bins[1])],
            top,
            top_cut,
        })
    }

    /// Bytes held by the plan and, at most, by one factorization's work space (two row maps,
    /// the largest update product, the second-half sums of the largest top supernode).
    pub fn bytes(&self) -> u64 {
        let words = self.rows.len()
            + 4 * self.nodes.len()
            + 3 * self.updates.len()
            + self.update_ptr.len()
            + self.a_to_l.len()
            + 2 * self.n;
        let largest_update = (0..self.nodes.len())
            .flat_map(|s| self.updates[self.update_ptr[s]..self.update_ptr[s + 1]].iter())
            .map(|u| (self.nodes[u.d].pattern.len() - u.first) * u.count.max(self.nodes[u.d].ncols))
            .max()
            .unwrap_or(0);
        let largest_top =
            self.top.iter().map(|&s| self.nodes[s].nrows() * self.nodes[s].ncols).max().unwrap_or(0);
        ((words + 2 * largest_update + largest_top) * 8) as u64
    }

    /// Numeric factorization of A (values `a` in the pattern given to [`Plan::new`]) into
    /// `values` (faer's layout, `len_val` long). LDLᵀ: D on the diagonal, unit L below.
    /// `parallel`: use two threads (bins, update halves, large dense blocks).
    pub fn factor(
        &self,
        a: &[f64],
        values: &mut [f64],
        kind: FactorKind,
        sigma: f64,
        parallel: bool,
    ) -> Result<(), EigenError> {
        assert_eq!(values.len(), self.len_val, "supernodal: values do not match the plan");
        assert_eq!(a.len(), self.a_to_l.len(), "supernodal: A does not match the plan");
        values.fill(0.0);
        for (&pos, &v) in self.a_to_l.iter().zip(a) {
            values[pos] += v;
        }
        let shared = Shared(values.as_mut_ptr(), values.len());
        let run_bin = |bin: &[usize]| -> Result<(), EigenError> {
            let mut scratch = Scratch::new(self.n);
            for &s in bin.iter() {
                // SAFETY: a bin's supernodes read only their descendants, which are in the
                // same bin (disjoint subtrees), and write only themselves.
                unsafe { self.factor_node(&shared, s, kind, Par::Seq, &mut scratch)? };
            }
            Ok(())
        };
        let (r0, r1) = if parallel {
            rayon::join(|| run_bin(&self.bins[0]), || run_bin(&self.bins[1]))
        } else {
            (run_bin(&self.bins[0]), run_bin(&self.bins[1]))
        };
        let mut scratch = [Scratch::new(self.n), Scratch::new(self.n)];
        let top = || -> Result<(), EigenError> {
            r0?;
            r1?;
            for (t, &s) in self.top.iter().enumerate() {
                // SAFETY: the top supernodes run one at a time after both bins.
                unsafe { self.factor_top_node(&shared, s, self.top_cut[t], kind, parallel, &mut scratch)? };
            }
            Ok(())
        };
        top().map_err(|e| match e {
            EigenError::ZeroPivot { pivot, .. } => EigenError::ZeroPivot { pivot, shift: sigma },
            e => e,
        })
    }

    /// The block of supernode `s`.
    ///
    /// # Safety
    /// No other live reference may overlap the block.
    #[allow(clippy::mut_from_ref)]
    unsafe fn block_mut<'v>(&self, v: &'v Shared, s: usize) -> &'v mut [f64] {
        let node = &self.nodes[s];
        let len = node.nrows() * node.ncols;
        debug_assert!(node.offset + len <= v.1);
        // SAFETY: in bounds (checked above); exclusivity is the caller's promise.
        unsafe { std::slice::from_raw_parts_mut(v.0.add(node.offset), len) }
    }

    /// The block of supernode `d`, read-only.
    ///
    /// # Safety
    /// No live mutable reference may overlap the block.
    unsafe fn block<'v>(&self, v: &'v Shared, d: usize) -> MatRef<'v, f64> {
        let node = &self.nodes[d];
        let len = node.nrows() * node.ncols;
        // SAFETY: in bounds; no writer (the caller's promise).
        let slice = unsafe { std::slice::from_raw_parts(v.0.add(node.offset), len) };
        MatRef::from_column_major_slice(slice, node.nrows(), node.ncols)
    }

    /// Updates, dense factorization and solve of one supernode.
    ///
    /// # Safety
    /// `s`'s block is not referenced elsewhere and all its descendants are final.
    unsafe fn factor_node(
        &self,
        v: &Shared,
        s: usize,
        kind: FactorKind,
        par: Par,
        scratch: &mut Scratch,
    ) -> Result<(), EigenError> {
        // SAFETY: the caller's promise.
        let ls = unsafe { self.block_mut(v, s) };
        let list = &self.updates[self.update_ptr[s]..self.update_ptr[s + 1]];
        self.map_rows(s, scratch);
        for u in list {
            // SAFETY: descendants are final and distinct from s.
            let ld = unsafe { self.block(v, u.d) };
            self.apply_update(s, ld, *u, kind, ls, scratch);
        }
        self.unmap_rows(s, scratch);
        let node = &self.nodes[s];
        self.dense(s, MatMut::from_column_major_slice_mut(ls, node.nrows(), node.ncols), kind, par)
    }

    /// [`Self::factor_node`] for a top supernode, its updates in two parallel halves.
    ///
    /// # Safety
    /// As [`Self::factor_node`].
    unsafe fn factor_top_node(
        &self,
        v: &Shared,
        s: usize,
        cut: usize,
        kind: FactorKind,
        parallel: bool,
        scratch: &mut [Scratch; 2],
    ) -> Result<(), EigenError> {
        let node = &self.nodes[s];
        let list = &self.updates[self.update_ptr[s]..self.update_ptr[s + 1]];
        let (first, second) = list.split_at(cut.min(list.len()));
        // SAFETY: the caller's promise.
        let ls = unsafe { self.block_mut(v, s) };
        let [s0, s1] = scratch;
        // The second half's sum, in a buffer kept across top supernodes (its pages are
        // faulted in once).
        let mut extra = std::mem::take(&mut s1.extra);
        extra.clear();
        extra.resize(node.nrows() * node.ncols, 0.0);
        let half = |updates: &[Update], target: &mut [f64], scratch: &mut Scratch| {
            self.map_rows(s, scratch);
            for u in updates {
                // SAFETY: descendants are final and distinct from s.
                let ld = unsafe { self.block(v, u.d) };
                self.apply_update(s, ld, *u, kind, target, scratch);
            }
            self.unmap_rows(s, scratch);
        };
        if parallel {
            rayon::join(|| half(first, &mut *ls, s0), || half(second, &mut extra, s1));
        } else {
            half(first, &mut *ls, s0);
            half(second, &mut extra, s1);
        }
        for (x, e) in ls.iter_mut().zip(&extra) {
            *x += e;
        }
        s1.extra = extra;
        let ls = MatMut::from_column_major_slice_mut(ls, node.nrows(), node.ncols);
        let par = if parallel && node.ncols >= PARALLEL_DENSE_COLUMNS { Par::rayon(2) } else { Par::Seq };
        self.dense(s, ls, kind, par)
    }

    /// Marks the local row of every pattern row of `s` in `scratch.local`.
    fn map_rows(&self, s: usize, scratch: &mut Scratch) {
        let node = &self.nodes[s];
        for (i, &r) in self.rows[node.pattern.clone()].iter().enumerate() {
            scratch.local[r] = node.ncols + i;
        }
    }

    fn unmap_rows(&self, s: usize, scratch: &mut Scratch) {
        for &r in &self.rows[self.nodes[s].pattern.clone()] {
            scratch.local[r] = usize::MAX;
        }
    }

    /// `L_s −= L_d[rows] · (D_d) · L_d[cols]ᵀ` for one descendant `d` (rows from `u.first` on,
    /// columns the `u.count` rows inside s), scattered into `target` (s's block shape).
    fn apply_update(
        &self,
        s: usize,
        ld: MatRef<'_, f64>,
        u: Update,
        kind: FactorKind,
        target: &mut [f64],
        scratch: &mut Scratch,
    ) {
        let (dn, sn) = (&self.nodes[u.d], &self.nodes[s]);
        let d_rows = &self.rows[dn.pattern.clone()][u.first..];
        let m = d_rows.len();
        let below = ld.subrows(dn.ncols + u.first, m);
        let cols = below.subrows(0, u.count);
        scratch.product.resize(m * u.count, 0.0);
        let w = MatMut::from_column_major_slice_mut(&mut scratch.product, m, u.count);
        let rhs = match kind {
            FactorKind::Llt => cols,
            FactorKind::Ldlt => {
                // L_d[cols] D_d: scale the columns by the pivots of d.
                scratch.scaled.resize(u.count * dn.ncols, 0.0);
                for j in 0..dn.ncols {
                    let dj = ld[(j, j)];
                    for i in 0..u.count {
                        scratch.scaled[j * u.count + i] = cols[(i, j)] * dj;
                    }
                }
                MatRef::from_column_major_slice(&scratch.scaled, u.count, dn.ncols)
            }
        };
        // Only the lower triangle of the square part lands in s (its upper half would
        // double the work of the separator updates).
        let (w_square, w_rest) = w.split_at_row_mut(u.count);
        triangular::matmul(
            w_square,
            BlockStructure::TriangularLower,
            Accum::Replace,
            cols,
            BlockStructure::Rectangular,
            rhs.transpose(),
            BlockStructure::Rectangular,
            1.0,
            Par::Seq,
        );
        matmul(w_rest, Accum::Replace, below.subrows(u.count, m - u.count), rhs.transpose(), 1.0, Par::Seq);
        // Scatter the lower part: column jj is s's column d_rows[jj]; row ii ≥ jj goes to
        // s's diagonal block or to its pattern row.
        scratch.target_rows.clear();
        let end = sn.start + sn.ncols;
        scratch
            .target_rows
            .extend(d_rows.iter().map(|&r| if r < end { r - sn.start } else { scratch.local[r] }));
        debug_assert!(scratch.target_rows.iter().all(|&r| r < sn.nrows()), "update row outside the pattern");
        let nrows = sn.nrows();
        for jj in 0..u.count {
            let col = &mut target[(d_rows[jj] - sn.start) * nrows..][..nrows];
            let wcol = &scratch.product[jj * m..(jj + 1) * m];
            for (&row, &x) in scratch.target_rows[jj..].iter().zip(&wcol[jj..]) {
                col[row] -= x;
            }
        }
    }

    /// Dense factorization of s's diagonal block and the solve for the rows below it.
    fn dense(&self, s: usize, ls: MatMut<'_, f64>, kind: FactorKind, par: Par) -> Result<(), EigenError> {
        let node = &self.nodes[s];
        let (mut top, mut bottom) = ls.split_at_row_mut(node.ncols);
        let req = faer::linalg::cholesky::ldlt::factor::cholesky_in_place_scratch::<f64>(
            node.ncols,
            par,
            Default::default(),
        );
        let mut buf = MemBuffer::try_new(req)
            .map_err(|_| EigenError::Factorization("out of memory for the workspace".into()))?;
        let stack = MemStack::new(&mut buf);
        match kind {
            FactorKind::Llt => {
                match faer::linalg::cholesky::llt::factor::cholesky_in_place(
                    top.rb_mut(),
                    LltRegularization::default(),
                    par,
                    stack,
                    Default::default(),
                ) {
                    Ok(_) => {}
                    Err(LltError::NonPositivePivot { index }) => {
                        return Err(EigenError::NotPositiveDefinite { pivot: node.start + index })
                    }
                }
                faer::linalg::triangular_solve::solve_lower_triangular_in_place(
                    top.rb(),
                    bottom.rb_mut().transpose_mut(),
                    par,
                );
            }
            FactorKind::Ldlt => {
                match faer::linalg::cholesky::ldlt::factor::cholesky_in_place(
                    top.rb_mut(),
                    LdltRegularization::default(),
                    par,
                    stack,
                    Default::default(),
                ) {
                    Ok(_) => {}
                    Err(LdltError::ZeroPivot { index }) => {
                        return Err(EigenError::ZeroPivot { pivot: node.start + index, shift: f64::NAN })
                    }
                }
                for j in 1..node.ncols {
                    for i in 0..j {
                        top[(i, j)] = 0.0;
                    }
                }
                faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place(
                    top.rb(),
                    bottom.rb_mut().transpose_mut(),
                    par,
                );
                for j in 0..node.ncols {
                    let inv = top[(j, j)].recip();
                    for i in 0..bottom.nrows() {
                        bottom[(i, j)] *= inv;
                    }
                }
            }
        }
        Ok(())
    }
}

use faer::reborrow::{Reborrow, ReborrowMut};

/// The factor's values, shared between the two bins (which touch disjoint supernodes).
struct Shared(*mut f64, usize);
// SAFETY: access is coordinated by `Plan::factor` (disjoint subtrees, then one supernode at a
// time with disjoint targets).
unsafe impl Sync for Shared {}
unsafe impl Send for Shared {}

/// Per-thread work space.
struct Scratch {
    /// Global row → local row of the current supernode (`usize::MAX` elsewhere).
    local: Vec<usize>,
    product: Vec<f64>,
    scaled: Vec<f64>,
    /// Rows of the current update in the target block.
    target_rows: Vec<usize>,
    /// Second-half sums of a top supernode.
    extra: Vec<f64>,
}

impl Scratch {
    fn new(n: usize) -> Self {
        Self {
            local: vec![usize::MAX; n],
            product: Vec::new(),
            scaled: Vec::new(),
            target_rows: Vec::new(),
            extra: Vec::new(),
        }
    }
}

/// Per target supernode, the descendants updating it: walking each supernode's pattern, the
/// runs of rows in one later supernode.
fn update_lists(nodes: &[Node], rows: &[usize], node_of_column: &[usize]) -> (Vec<usize>, Vec<Update>) {
    let mut lists: Vec<Vec<Update>> = vec![Vec::new(); nodes.len()];
    for (d, node) in nodes.iter().enumerate() {
        let pattern = &rows[node.pattern.clone()];
        let mut i = 0;
        while i < pattern.len() {
            let s = node_of_column[pattern[i]];
            let count = pattern[i..].iter().take_while(|&&r| node_of_column[r] == s).count();
            lists[s].push(Update { d, first: i, count });
            i += count;
        }
    }
    let mut ptr = Vec::with_capacity(nodes.len() + 1);
    ptr.push(0);
    let mut flat = Vec::new();
    for list in lists {
        flat.extend(list);
        ptr.push(flat.len());
    }
    (ptr, flat)
}

/// Where each entry of the upper pattern of A lands in the values (permuted, lower).
fn assembly_map(
    nodes: &[Node],
    rows: &[usize],
    node_of_column: &[usize],
    perm_inv: &[usize],
    a: SymbolicSparseColMatRef<'_, usize>,
) -> Option<Vec<usize>> {
    let mut map = Vec::with_capacity(a.row_idx().len());
    for j in 0..a.ncols() {
        for &r in a.row_idx_of_col_raw(j) {
            let (p, q) = (perm_inv[r], perm_inv[j]);
            let (row, col) = if p >= q { (p, q) } else { (q, p) };
            let s = node_of_column[col];
            let node = &nodes[s];
            let local_row = if row < node.start + node.ncols {
                row - node.start
            } else {
                node.ncols + rows[node.pattern.clone()].binary_search(&row).ok()?
            };
            map.push(node.offset + (col - node.start) * node.nrows() + local_row);
        }
    }
    Some(map)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::factor::Analysis;
    use crate::test_support::{steel_box, time_ms};
    use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
    use faer::sparse::{SparseColMat, SparseColMatRef};

    /// A steel box's analysis, its two-core plan (split however small) and the values of
    /// `K − σM` (σ relative to max Kᵢᵢ/Mᵢᵢ) on the analysis' upper pattern.
    fn setup(cells: [usize; 3], sigma_rel: f64) -> (Analysis, Plan, Vec<f64>) {
        setup_with(steel_box(cells), sigma_rel)
    }

    /// Two disjoint copies of a box (block-diagonal K and M): an elimination forest.
    fn two_boxes(cells: [usize; 3]) -> modal_fem::Assembly {
        let asm = steel_box(cells);
        let n = asm.k.nrows();
        let twice = |a: &SparseColMat<usize, f64>| {
            let mut triplets = Vec::new();
            for copy in 0..2 {
                for j in 0..n {
                    for (i, &v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                        triplets.push(faer::sparse::Triplet::new(i + copy * n, j + copy * n, v));
                    }
                }
            }
            SparseColMat::try_new_from_triplets(2 * n, 2 * n, &triplets).unwrap()
        };
        modal_fem::Assembly { k: twice(&asm.k), m: twice(&asm.m) }
    }

    fn setup_with(asm: modal_fem::Assembly, sigma_rel: f64) -> (Analysis, Plan, Vec<f64>) {
        let scale = (0..asm.k.ncols())
            .map(|j| asm.k.get(j, j).copied().unwrap_or(0.0) / asm.m.get(j, j).copied().unwrap())
            .fold(0.0, f64::max);
        let analysis = Analysis::new(asm.k.symbolic(), true).unwrap();
        let SymbolicCholeskyRaw::Supernodal(sn) = analysis.symbolic.raw() else { panic!("supernodal") };
        let perm = analysis.symbolic.perm().unwrap();
        let plan = Plan::new(sn, perm.arrays().1, analysis.upper.as_ref(), 1).expect("a two-bin split");
        let shifted: SparseColMat<usize, f64> = &asm.k - &(&asm.m * faer::Scale(sigma_rel * scale));
        let upper = analysis.upper.as_ref();
        let a: Vec<f64> = (0..upper.ncols())
            .flat_map(|j| {
                let count = upper.row_idx_of_col_raw(j).len();
                shifted.val_of_col(j)[..count].to_vec()
            })
            .collect();
        (analysis, plan, a)
    }

    fn faer_factor(analysis: &Analysis, a: &[f64], kind: FactorKind) -> Vec<f64> {
        let a = SparseColMatRef::new(analysis.upper.as_ref(), a);
        crate::test_support::faer_numeric(&analysis.symbolic, a, kind)
    }

    /// Largest difference relative to the largest value (NaN fails).
    fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter().zip(y).map(|(a, b)| (a - b).abs() / scale).fold(0.0, |m, d| {
            if d.is_nan() {
                f64::INFINITY
            } else {
                m.max(d)
            }
        })
    }

    #[test]
    fn factors_match_faer_and_do_not_depend_on_the_thread_count() {
        // LLᵀ below the spectrum, LDLᵀ inside it (negative pivots = eigenvalues below σ).
        for (kind, sigma_rel) in [(FactorKind::Llt, -1e-6), (FactorKind::Ldlt, 1e-3)] {
            let (analysis, plan, a) = setup([8, 6, 5], sigma_rel);
            let want = faer_factor(&analysis, &a, kind);
            let mut two = vec![0.0; want.len()];
            let mut one = vec![0.0; want.len()];
            plan.factor(&a, &mut two, kind, 0.0, true).unwrap();
            rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap()
                .install(|| plan.factor(&a, &mut one, kind, 0.0, true).unwrap());
            assert!(rel_diff(&two, &want) < 1e-11, "{kind:?}: {}", rel_diff(&two, &want));
            assert!(one == two, "{kind:?}: one thread differs from two");
            let mut sequential = vec![0.0; want.len()];
            plan.factor(&a, &mut sequential, kind, 0.0, false).unwrap();
            assert!(sequential == two, "{kind:?}: the sequential order differs");
        }
    }

    #[test]
    fn disjoint_parts_factor_like_faer() {
        // Two roots in the elimination forest: the bins may be whole parts, the top empty.
        let (analysis, plan, a) = setup_with(two_boxes([5, 4, 3]), -1e-6);
        let want = faer_factor(&analysis, &a, FactorKind::Llt);
        let mut got = vec![0.0; want.len()];
        plan.factor(&a, &mut got, FactorKind::Llt, 0.0, true).unwrap();
        assert!(rel_diff(&got, &want) < 1e-11, "{}", rel_diff(&got, &want));
    }

    #[test]
    fn a_non_positive_pivot_is_reported() {
        let (_, plan, a) = setup([6, 5, 4], 1e-3);
        let mut values = vec![0.0; plan.len_val];
        assert!(matches!(
            plan.factor(&a, &mut values, FactorKind::Llt, 0.0, true),
            Err(EigenError::NotPositiveDefinite { .. })
        ));
    }

    /// `cargo test --release -p modal-eigen --lib supernodal_speed -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn supernodal_speed() {
        let (analysis, plan, a) = setup([14, 11, 7], -1e-6);
        let mut values = vec![0.0; plan.len_val];
        let two = time_ms(5, &mut || plan.factor(&a, &mut values, FactorKind::Llt, 0.0, true).unwrap());
        let one = time_ms(5, &mut || plan.factor(&a, &mut values, FactorKind::Llt, 0.0, false).unwrap());
        let faer = time_ms(5, &mut || drop(faer_factor(&analysis, &a, FactorKind::Llt)));
        eprintln!("30k box LLᵀ: two cores {two:.0} ms, one core {one:.0} ms, faer (one core, incl. allocation) {faer:.0} ms");
    }
}
