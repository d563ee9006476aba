//! Sparse factorizations of the shifted matrix `A(σ) = K − σM`.
//!
//! The union pattern of the upper triangles of K and M and the symbolic factorization
//! (ordering, elimination tree, supernodes) are computed once; every shift σ only refills
//! values and runs a numeric factorization:
//! - `LLᵀ` (Cholesky) when σ is below the spectrum (A positive definite);
//! - `LDLᵀ` (no pivoting) for an indefinite A. By Sylvester's law of inertia the number of
//!   negative entries of D equals the number of eigenvalues of `K w = λ M w` below σ.
//!
//! A factor that serves block solves is repacked into row tiles ([`crate::tiled`]) and faer's
//! copy of the values is freed: the Cholesky factor always (it exists only as the operator),
//! an LDLᵀ factor when the driver makes it the operator ([`ShiftedFactor::prepare_solves`]).

use crate::ordering::{metis_node_ordering, Permutation};
use crate::supernodal::Plan;
use crate::tiled::{FactorKind, TiledFactor};
use crate::types::{EigenError, OrderingUsed};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLdltRef, CholeskySymbolicParams, LdltRef, LltRef,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{MatMut, Par, Side};

/// Upper-triangular union pattern of K and M with maps from K and M entries to its slots.
struct ShiftedPattern {
    symbolic: SymbolicSparseColMat<usize>,
    /// (slot, index into K values)
    k_map: Vec<(usize, usize)>,
    /// (slot, index into M values); `None` when M's pattern is K's and `k_map` serves both.
    m_map: Option<Vec<(usize, usize)>>,
}

impl ShiftedPattern {
    fn new(k: SparseColMatRef<'_, usize, f64>, m: SparseColMatRef<'_, usize, f64>) -> Self {
        Self::same_upper(k, m).unwrap_or_else(|| Self::union(k, m))
    }

    /// The fast path for K and M assembled on one mesh: identical patterns with sorted rows
    /// and every diagonal entry stored, so the upper triangle of K is the pattern and slot i
    /// takes entry `src[i]` of both (30k DOF: 70–100 ms for the general union, ≈ 10 here).
    fn same_upper(k: SparseColMatRef<'_, usize, f64>, m: SparseColMatRef<'_, usize, f64>) -> Option<Self> {
        let (ks, ms) = (k.symbolic(), m.symbolic());
        if ks.col_ptr() != ms.col_ptr() || ks.row_idx() != ms.row_idx() || ks.col_nnz().is_some() {
            return None;
        }
        let symbolic = upper_triangle(ks)?;
        // Slot i of column j is entry i of K's column j.
        let upper_ptr = symbolic.col_ptr();
        let src =
            (0..k.ncols()).flat_map(|j| ks.col_ptr()[j]..ks.col_ptr()[j] + (upper_ptr[j + 1] - upper_ptr[j]));
        Some(Self { k_map: src.enumerate().collect(), symbolic, m_map: None })
    }

    /// The general union of the upper triangles of K and M (plus the diagonal).
    fn union(k: SparseColMatRef<'_, usize, f64>, m: SparseColMatRef<'_, usize, f64>) -> Self {
        let n = k.ncols();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut k_map = Vec::new();
        let mut m_map = Vec::new();
        col_ptr.push(0usize);
        let mut entries: Vec<(usize, bool, usize)> = Vec::new();
        for j in 0..n {
            entries.clear();
            let kr = k.symbolic().row_idx_of_col_raw(j);
            let kstart = k.symbolic().col_range(j).start;
            for (o, &r) in kr.iter().enumerate() {
                if r <= j {
                    entries.push((r, true, kstart + o));
                }
            }
            let mr = m.symbolic().row_idx_of_col_raw(j);
            let mstart = m.symbolic().col_range(j).start;
            for (o, &r) in mr.iter().enumerate() {
                if r <= j {
                    entries.push((r, false, mstart + o));
                }
            }
            // The diagonal is always present so the factorization has a pivot slot.
            entries.push((j, true, usize::MAX));
            entries.sort_unstable_by_key(|e| e.0);
            let mut last = usize::MAX;
            for &(r, is_k, idx) in entries.iter() {
                if r != last {
                    row_idx.push(r);
                    last = r;
                }
                let slot = row_idx.len() - 1;
                if idx != usize::MAX {
                    if is_k {
                        k_map.push((slot, idx));
                    } else {
                        m_map.push((slot, idx));
                    }
                }
            }
            col_ptr.push(row_idx.len());
        }
        // SAFETY-free: new_checked validates sorted, in-range, non-duplicate row indices.
        let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        Self { symbolic, k_map, m_map: Some(m_map) }
    }

    /// Values of K − σM in this pattern.
    fn values(&self, k: &[f64], m: &[f64], sigma: f64, out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.symbolic.row_idx().len(), 0.0);
        for &(s, i) in &self.k_map {
            out[s] += k[i];
        }
        for &(s, i) in self.m_map.as_ref().unwrap_or(&self.k_map) {
            out[s] -= sigma * m[i];
        }
    }
}

/// Factor entries from which the Cholesky factorization runs in parallel (see
/// [`ShiftedFactor::llt_par`]).
const PARALLEL_LLT_NNZ: usize = 40_000_000;

/// Fill-reducing ordering and symbolic Cholesky factorization of the upper pattern of
/// `K − σM`. It depends on the pattern only, so a caller can make it from the mesh's
/// connectivity while K and M are being assembled ([`crate::solve_analyzed`]).
pub struct Analysis {
    /// Upper triangle (with the diagonal) of the pattern, in faer's sorted form.
    pub(crate) upper: SymbolicSparseColMat<usize>,
    pub(crate) symbolic: SymbolicCholesky<usize>,
    ordering: OrderingUsed,
    /// The two-core numeric factorization (`None`: faer's).
    plan: Option<Plan>,
}

impl Analysis {
    /// Bytes of the factor's values (8 per stored entry), known from the
    /// symbolic analysis before any matrix value exists: the bulk of a large
    /// solve's memory, and a lower bound of it.
    pub fn factor_value_bytes(&self) -> u64 {
        self.symbolic.len_val() as u64 * 8
    }

    /// Analysis of the symmetric pattern `pattern` (full or upper storage, sorted rows, every
    /// diagonal entry present). `use_metis`: METIS nested dissection of the node graph when
    /// the DOFs come in threes (else, or if METIS fails, faer's AMD).
    pub fn new(pattern: SymbolicSparseColMatRef<'_, usize>, use_metis: bool) -> Result<Self, EigenError> {
        let (upper, perm) = rayon::join(
            || upper_triangle(pattern),
            || if use_metis { metis_node_ordering(pattern) } else { None },
        );
        let upper = upper.ok_or_else(|| {
            EigenError::Factorization("pattern: unsorted rows or a missing diagonal entry".into())
        })?;
        Self::with_ordering(upper, perm)
    }

    /// Analysis of an upper pattern (with diagonal).
    fn of_upper(upper: SymbolicSparseColMat<usize>, use_metis: bool) -> Result<Self, EigenError> {
        let perm = if use_metis { metis_node_ordering(upper.as_ref()) } else { None };
        Self::with_ordering(upper, perm)
    }

    fn with_ordering(
        upper: SymbolicSparseColMat<usize>,
        perm: Option<Permutation>,
    ) -> Result<Self, EigenError> {
        let fail = |e: faer::sparse::FaerError| EigenError::Factorization(format!("{e:?}"));
        let (ordering, used) = match &perm {
            Some(p) => (
                SymmetricOrdering::Custom(PermRef::new_checked(&p.fwd, &p.inv, p.fwd.len())),
                OrderingUsed::Metis,
            ),
            None => (SymmetricOrdering::Amd, OrderingUsed::Amd),
        };
        let symbolic = factorize_symbolic_cholesky(
            upper.as_ref(),
            Side::Upper,
            ordering,
            CholeskySymbolicParams::default(),
        )
        .map_err(fail)?;
        // Our two-core factorization where faer's runs on one core (see `supernodal`).
        let plan = match (symbolic.raw(), symbolic.perm()) {
            (SymbolicCholeskyRaw::Supernodal(sn), Some(perm)) if symbolic.len_val() < PARALLEL_LLT_NNZ => {
                Plan::new(sn, perm.arrays().1, upper.as_ref(), PLAN_MIN_WORK)
            }
            _ => None,
        };
        Ok(Self { upper, symbolic, ordering: used, plan })
    }
}

/// The upper triangle of a symmetric pattern; `None` unless every column's rows are sorted
/// and hold the diagonal.
fn upper_triangle(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<SymbolicSparseColMat<usize>> {
    let n = pattern.ncols();
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0usize);
    for j in 0..n {
        let rows = pattern.row_idx_of_col_raw(j);
        if !rows.windows(2).all(|w| w[0] < w[1]) {
            return None;
        }
        let upper = rows.partition_point(|&r| r <= j);
        if upper == 0 || rows[upper - 1] != j {
            return None;
        }
        row_idx.extend_from_slice(&rows[..upper]);
        col_ptr.push(row_idx.len());
    }
    SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx).into()
}

/// Sizes of the buffers of one inertia count, from the symbolic analysis alone: the buffers
/// can be made on another core while the factor is busy.
#[derive(Clone, Copy, Debug)]
pub struct CountSizes {
    a: usize,
    values: usize,
}

impl CountSizes {
    /// Allocates the buffers and faults their pages in.
    pub fn allocate(self) -> Result<CountBuffers, EigenError> {
        Ok(CountBuffers { a: touched(self.a)?, values: touched(self.values)? })
    }
}

/// Storage of one inertia count ([`ShiftedFactor::inertia_at`]): the values of K − σM in the
/// pattern and the factor's values.
pub struct CountBuffers {
    a: Vec<f64>,
    values: Vec<f64>,
}

/// A zeroed vector of `len` values whose pages are faulted in now, two halves in parallel.
/// Fresh memory is mapped page by page on first touch, and on the virtual machines measured
/// a 4 KiB fault costs ≈ 4 µs: ≈ 80 ms for the 145 MB factor of a 30k-DOF box.
fn touched(len: usize) -> Result<Vec<f64>, EigenError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| EigenError::Factorization("out of memory for the factor".into()))?;
    let (lower, upper) = v.spare_capacity_mut()[..len].split_at_mut(len / 2);
    let zero = |half: &mut [std::mem::MaybeUninit<f64>]| {
        for x in half {
            x.write(0.0);
        }
    };
    rayon::join(|| zero(lower), || zero(upper));
    // SAFETY: the first `len` elements were initialized just above.
    unsafe { v.set_len(len) };
    Ok(v)
}

/// Work (multiply–adds) from which the numeric factorization is split over two cores.
const PLAN_MIN_WORK: usize = 1 << 26;

/// Kind of numeric factor held.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Kind {
    Llt,
    Ldlt,
}

/// Symbolic analysis plus (at most) one numeric factor of `K − σM`.
pub struct ShiftedFactor<'a> {
    k: SparseColMatRef<'a, usize, f64>,
    m: SparseColMatRef<'a, usize, f64>,
    pattern: ShiftedPattern,
    pub(crate) symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    a_values: Vec<f64>,
    kind: Option<Kind>,
    /// Factor entries from which the Cholesky factorization runs in parallel.
    parallel_llt_nnz: usize,
    /// The current factor repacked for solves (then `values` is empty).
    pub(crate) tiled: Option<TiledFactor>,
    /// The two-core numeric factorization (`None`: faer's, for small trees and for factors
    /// large enough for faer's own parallel one).
    plan: Option<Plan>,
    shift: f64,
    par: Par,
    /// Ordering that was used.
    pub ordering: OrderingUsed,
}

impl<'a> ShiftedFactor<'a> {
    /// Ordering and symbolic factorization (`given`: made beforehand from the pattern of K
    /// by [`Analysis::new`], used if it is the pattern of `K − σM`). `use_metis` requests
    /// METIS (falls back to AMD).
    pub fn analyze(
        k: SparseColMatRef<'a, usize, f64>,
        m: SparseColMatRef<'a, usize, f64>,
        given: Option<Analysis>,
        use_metis: bool,
        par: Par,
    ) -> Result<Self, EigenError> {
        // Without a given analysis, one is made from K's pattern beside the construction of
        // the shifted pattern: when K and M share their pattern (the assembled case) the two
        // coincide, and METIS (≈ 75 ms at 30k DOF) overlaps the shifted pattern (≈ 30 ms).
        let (pattern, analysis) = match given {
            Some(a) => (ShiftedPattern::new(k, m), Ok(a)),
            None => rayon::join(|| ShiftedPattern::new(k, m), || Analysis::new(k.symbolic(), use_metis)),
        };
        let analysis = match analysis {
            Ok(a)
                if a.upper.col_ptr() == pattern.symbolic.col_ptr()
                    && a.upper.row_idx() == pattern.symbolic.row_idx() =>
            {
                a
            }
            _ => Analysis::of_upper(pattern.symbolic.clone(), use_metis)?,
        };
        let Analysis { symbolic, ordering, plan, .. } = analysis;
        Ok(Self {
            k,
            m,
            plan,
            pattern,
            symbolic,
            values: Vec::new(),
            a_values: Vec::new(),
            kind: None,
            tiled: None,
            parallel_llt_nnz: PARALLEL_LLT_NNZ,
            shift: f64::NAN,
            par,
            ordering,
        })
    }

    /// Number of stored entries of the factor.
    pub fn factor_nnz(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Parallelism of the Cholesky factorization: faer's parallel supernodal factorization
    /// pays off only for large factors (98k-DOF box, 98 M entries: 5.6 → 4.2 s; 30k, 18 M:
    /// no gain). Two tasks whatever the pool size, so the split — and the result — does not
    /// depend on the thread count (on one thread the tasks run in turn). The LDLᵀ inertia
    /// counts stay sequential: they overlap the iteration on the second core.
    fn llt_par(&self) -> Par {
        if self.factor_nnz() >= self.parallel_llt_nnz {
            Par::rayon(2)
        } else {
            self.par
        }
    }

    /// Estimated peak bytes of one numeric factor: its values (or their tiles, repacked in
    /// place, see [`TiledFactor::pack`]), the factorization scratch and the copy of A.
    pub fn memory_estimate(&self) -> u64 {
        let scratch = self
            .symbolic
            .factorize_numeric_ldlt_scratch::<f64>(self.par, Default::default())
            .or(self.symbolic.factorize_numeric_llt_scratch::<f64>(self.llt_par(), Default::default()))
            .size_bytes();
        let a = self.pattern.symbolic.row_idx().len() * 8 * 2;
        let tiled = TiledFactor::packed_len(&self.symbolic).unwrap_or(0);
        let values = self.factor_nnz().max(tiled) * 8;
        (values + scratch + a) as u64
    }

    /// Bytes of the shifted pattern, its maps from K and M and the two-core factorization's
    /// plan and work space (held for the whole solve).
    pub fn pattern_bytes(&self) -> u64 {
        let entries = self.pattern.symbolic.row_idx().len() + self.pattern.symbolic.col_ptr().len();
        let maps = (self.pattern.k_map.len() + self.pattern.m_map.as_ref().map_or(0, Vec::len)) * 16;
        (entries * 8 + maps) as u64 + self.plan.as_ref().map_or(0, Plan::bytes)
    }

    /// Shift of the current factor.
    pub fn shift(&self) -> f64 {
        self.shift
    }

    fn fill(&mut self, sigma: f64) -> Result<(), EigenError> {
        // A tiled factor's allocation serves the next factorization (no fresh pages).
        if let Some(tiled) = self.tiled.take() {
            self.values = tiled.into_values();
        }
        let mut a = std::mem::take(&mut self.a_values);
        self.pattern.values(self.k.val(), self.m.val(), sigma, &mut a);
        self.a_values = a;
        let len = self.symbolic.len_val();
        if self.values.capacity() < len {
            self.values = touched(len)?;
        } else {
            self.values.clear();
            self.values.resize(len, 0.0);
        }
        Ok(())
    }

    /// Sizes of the buffers of one inertia count (see [`CountSizes::allocate`]).
    pub fn count_sizes(&self) -> CountSizes {
        CountSizes { a: self.pattern.symbolic.row_idx().len(), values: self.symbolic.len_val() }
    }

    fn buffer(&self, req: StackReq) -> Result<MemBuffer, EigenError> {
        MemBuffer::try_new(req)
            .map_err(|_| EigenError::Factorization("out of memory for the workspace".into()))
    }

    /// Cholesky `K − σM = LLᵀ`; fails with `NotPositiveDefinite` if σ is not below the spectrum.
    pub fn factor_llt(&mut self, sigma: f64) -> Result<(), EigenError> {
        self.kind = None;
        self.fill(sigma)?;
        if let Some(plan) = &self.plan {
            plan.factor(&self.a_values, &mut self.values, FactorKind::Llt, sigma, true)?;
        } else {
            let par = self.llt_par();
            let req = self.symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default());
            let mut buf = self.buffer(req)?;
            let a = SparseColMatRef::new(self.pattern.symbolic.as_ref(), &self.a_values);
            let res = self.symbolic.factorize_numeric_llt(
                &mut self.values,
                a,
                Side::Upper,
                LltRegularization::default(),
                par,
                MemStack::new(&mut buf),
                Default::default(),
            );
            if let Err(LltError::NonPositivePivot { index }) = res {
                return Err(EigenError::NotPositiveDefinite { pivot: index });
            }
        }
        self.kind = Some(Kind::Llt);
        self.shift = sigma;
        self.prepare_solves();
        Ok(())
    }

    /// Repacks the current factor into tiles for block solves, in place (a simplicial factor
    /// of a small problem stays as it is and uses faer's solve).
    pub fn prepare_solves(&mut self) {
        let kind = match self.kind {
            Some(Kind::Llt) => FactorKind::Llt,
            Some(Kind::Ldlt) => FactorKind::Ldlt,
            None => return,
        };
        if self.tiled.is_some() {
            return;
        }
        match TiledFactor::pack(&self.symbolic, std::mem::take(&mut self.values), kind) {
            Ok(tiled) => self.tiled = Some(tiled),
            Err(values) => self.values = values,
        }
    }

    /// `K − σM = LDLᵀ` without pivoting; returns the number of negative pivots
    /// (= eigenvalues below σ by Sylvester's law of inertia).
    pub fn factor_ldlt(&mut self, sigma: f64) -> Result<usize, EigenError> {
        self.kind = None;
        self.fill(sigma)?;
        let mut values = std::mem::take(&mut self.values);
        let res = self.ldlt_into(&self.a_values, &mut values, sigma, true);
        self.values = values;
        res?;
        self.kind = Some(Kind::Ldlt);
        self.shift = sigma;
        Ok(negative_pivots(&self.symbolic, &self.values))
    }

    /// Sylvester inertia at σ (eigenvalues below σ) from an LDLᵀ into private buffers
    /// (`buffers`, or fresh ones), leaving the current factor untouched, so that it can run
    /// on another thread while this factor serves block solves. Memory: one more factor
    /// ([`Self::memory_estimate`]).
    pub fn inertia_at(&self, sigma: f64, buffers: Option<CountBuffers>) -> Result<usize, EigenError> {
        let CountBuffers { mut a, mut values } = match buffers {
            Some(b) => b,
            None => self.count_sizes().allocate()?,
        };
        debug_assert_eq!(values.len(), self.symbolic.len_val());
        self.pattern.values(self.k.val(), self.m.val(), sigma, &mut a);
        self.ldlt_into(&a, &mut values, sigma, false)?;
        Ok(negative_pivots(&self.symbolic, &values))
    }

    /// Numeric LDLᵀ of the pattern values `a` (of `K − σM`) into `values`: on two cores if
    /// `parallel` and the plan allows, else faer's (the early inertia count runs on one core
    /// beside the iteration, where faer's is as fast and needs no second worker).
    fn ldlt_into(&self, a: &[f64], values: &mut [f64], sigma: f64, parallel: bool) -> Result<(), EigenError> {
        if let (Some(plan), true) = (&self.plan, parallel) {
            return plan.factor(a, values, FactorKind::Ldlt, sigma, true);
        }
        let req = self.symbolic.factorize_numeric_ldlt_scratch::<f64>(self.par, Default::default());
        let mut buf = self.buffer(req)?;
        let a = SparseColMatRef::new(self.pattern.symbolic.as_ref(), a);
        let res = self.symbolic.factorize_numeric_ldlt(
            values,
            a,
            Side::Upper,
            LdltRegularization::default(),
            self.par,
            MemStack::new(&mut buf),
            Default::default(),
        );
        match res {
            Ok(_) => Ok(()),
            Err(LdltError::ZeroPivot { index }) => Err(EigenError::ZeroPivot { pivot: index, shift: sigma }),
        }
    }

    /// Solve workspace requirement for `ncols` right-hand sides.
    pub fn solve_scratch(&self, ncols: usize) -> StackReq {
        self.symbolic
            .solve_in_place_scratch::<f64>(ncols, self.par)
            .or(TiledFactor::scratch(self.symbolic.nrows()))
    }

    /// Solves `(K − σM) X = B` in place with the current factor.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>, stack: &mut MemStack) {
        if let Some(t) = &self.tiled {
            return t.solve_in_place(rhs, stack);
        }
        match self.kind {
            Some(Kind::Llt) => LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
                faer::Conj::No,
                rhs,
                self.par,
                stack,
            ),
            Some(Kind::Ldlt) => LdltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
                faer::Conj::No,
                rhs,
                self.par,
                stack,
            ),
            None => panic!("solve_in_place called without a numeric factor"),
        }
    }
}

/// Negative entries of D in an LDLᵀ factor (NaN pivots count as negative).
fn negative_pivots(symbolic: &SymbolicCholesky<usize>, values: &[f64]) -> usize {
    let neg = |d: f64| d <= 0.0 || d.is_nan();
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let cp = s.col_ptr();
            (0..s.nrows()).filter(|&j| neg(values[cp[j]])).count()
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let f = SupernodalLdltRef::new(s, values);
            let mut count = 0;
            for i in 0..s.n_supernodes() {
                let v = f.supernode(i).val();
                for c in 0..v.ncols() {
                    if neg(v[(c, c)]) {
                        count += 1;
                    }
                }
            }
            count
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel Cholesky factorization gives the same bits on one thread as on two (its
    /// split is fixed at two tasks), so solves stay independent of the thread count.
    #[test]
    fn parallel_cholesky_does_not_depend_on_the_thread_count() {
        let a = crate::test_support::steel_box([6, 5, 4]);
        let factor_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut f = ShiftedFactor::analyze(a.k.as_ref(), a.m.as_ref(), None, true, Par::Seq).unwrap();
                f.parallel_llt_nnz = 0;
                assert!(matches!(f.llt_par(), Par::Rayon(_)));
                f.factor_llt(-1e3).unwrap();
                // The factor as the solves use it: tiles, or faer's values if simplicial.
                f.tiled.take().map_or_else(|| std::mem::take(&mut f.values), TiledFactor::into_values)
            })
        };
        let one = factor_on(1);
        assert!(one.iter().all(|v| v.is_finite()));
        assert!(one == factor_on(2), "the factor changed with the thread count");
    }
}
