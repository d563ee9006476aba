//! Dense block kernels in the M-inner product ⟨x, y⟩ = xᵀ M y.
//!
//! - block classical Gram–Schmidt, applied twice ("twice is enough", Giraud et al. 2005),
//!   against a deflation set and the current basis;
//! - SVQB (Stathopoulos & Wu 2002): Z = Q B with G = Zᵀ M Z = U Σ Uᵀ, Q = Z U Σ^{-1/2},
//!   B = Σ^{1/2} Uᵀ; directions with Σᵢ ≤ (drop·scale)² are rank deficient and replaced by
//!   random vectors (reported with zero coupling in B).

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

/// Rows of Y computed per parallel task in [`spmm`].
const SPMM_ROWS_PER_TASK: usize = 2048;

/// Columns of X per pass of [`spmm`]: A is streamed once per pass.
const SPMM_PASS_COLUMNS: usize = 32;

/// Y = A X for a sparse **symmetric** A in full storage (K and M).
///
/// Gather form: column j of A is row j, so `Y[j, :] = Σᵢ A[i, j] X[i, :]` — every output
/// row is written by one task, the rows are split over rayon's threads, and each row's sum
/// runs in the same order whatever the thread count (results are bit-identical). X goes
/// through a row-major copy, up to 32 columns per pass padded to whole rows of 8, so that
/// each stored entry of A costs one load of a row of X and one multiply–add per 8 columns,
/// with two partial sums per row to halve the dependency chain.
pub fn spmm(a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    debug_assert_eq!(a.nrows(), a.ncols(), "spmm: A must be square (symmetric)");
    let (n, p) = (a.nrows(), x.ncols());
    let mut y = Mat::zeros(n, p);
    for c0 in (0..p).step_by(SPMM_PASS_COLUMNS) {
        let width = SPMM_PASS_COLUMNS.min(p - c0);
        let (xs, ys) = (x.subcols(c0, width), y.as_mut().subcols_mut(c0, width));
        match width.div_ceil(8) {
            1 => spmm_pass::<1>(a, xs, ys),
            2 => spmm_pass::<2>(a, xs, ys),
            _ => spmm_pass::<4>(a, xs, ys),
        }
    }
    y
}

/// One pass of [`spmm`] over at most `8·R` columns (rows of `R` × 8 values).
fn spmm_pass<const R: usize>(a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>, mut y: MatMut<'_, f64>) {
    use rayon::prelude::*;
    let n = a.nrows();
    let mut xr = vec![[[0.0; 8]; R]; n];
    for c in 0..x.ncols() {
        for (row, v) in xr.iter_mut().zip(x.col(c).iter()) {
            row[c / 8][c % 8] = *v;
        }
    }
    let mut yr = vec![[[0.0; 8]; R]; n];
    yr.par_chunks_mut(SPMM_ROWS_PER_TASK).enumerate().for_each(|(chunk, out)| {
        crate::simd::dispatch(GatherRows { a, xr: &xr, first: chunk * SPMM_ROWS_PER_TASK, out });
    });
    for c in 0..x.ncols() {
        for (v, row) in y.rb_mut().col_mut(c).iter_mut().zip(&yr) {
            *v = row[c / 8][c % 8];
        }
    }
}

/// Rows `first..first + out.len()` of A·X from the row-major X.
struct GatherRows<'a, const R: usize> {
    a: SparseColMatRef<'a, usize, f64>,
    xr: &'a [[[f64; 8]; R]],
    first: usize,
    out: &'a mut [[[f64; 8]; R]],
}

/// `acc += w · x` on rows of 8.
#[inline(always)]
fn axpy<F: crate::simd::MulAdd, const R: usize>(acc: &mut [[f64; 8]; R], w: f64, x: &[[f64; 8]; R]) {
    // Index loops: the zipped-iterator form measured 3× slower here (not unrolled).
    #[allow(clippy::needless_range_loop)]
    for k in 0..R {
        for c in 0..8 {
            acc[k][c] = F::mul_add(w, x[k][c], acc[k][c]);
        }
    }
}

impl<const R: usize> crate::simd::Kernel for GatherRows<'_, R> {
    type Output = ();
    #[inline(always)]
    fn run<F: crate::simd::MulAdd>(self) {
        let sym = self.a.symbolic();
        let (rows, vals) = (sym.row_idx(), self.a.val());
        for (r, yrow) in self.out.iter_mut().enumerate() {
            let range = sym.col_range(self.first + r);
            let (idx, v) = (&rows[range.clone()], &vals[range]);
            let mut even = [[0.0; 8]; R];
            let mut odd = [[0.0; 8]; R];
            for (i, w) in idx.chunks_exact(2).zip(v.chunks_exact(2)) {
                axpy::<F, R>(&mut even, w[0], &self.xr[i[0]]);
                axpy::<F, R>(&mut odd, w[1], &self.xr[i[1]]);
            }
            if let (Some(&i), Some(&w)) = (idx.chunks_exact(2).remainder().first(), v.last()) {
                axpy::<F, R>(&mut even, w, &self.xr[i]);
            }
            for ((y, e), o) in yrow.iter_mut().flatten().zip(even.iter().flatten()).zip(odd.iter().flatten())
            {
                *y = e + o;
            }
        }
    }
}

/// Tall dense products with at least this many rows run as two parallel tasks.
const SPLIT_MIN_ROWS: usize = 4096;

/// Where the rows of a tall product are split: a fixed point that depends on the row count
/// only, so the arithmetic (and the result, bit for bit) is the same for any thread count.
fn row_split(n: usize) -> Option<usize> {
    (n >= SPLIT_MIN_ROWS).then_some(n / 2)
}

/// C = Aᵀ B for tall A and B (n × a, n × b): the two halves of the rows are reduced as
/// parallel tasks (each streams half of A and B) and added.
pub fn tmul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let seq = |a: MatRef<'_, f64>, b: MatRef<'_, f64>| {
        let mut c = Mat::zeros(a.ncols(), b.ncols());
        matmul(c.as_mut(), Accum::Replace, a.transpose(), b, 1.0, Par::Seq);
        c
    };
    match row_split(a.nrows()) {
        None => seq(a, b),
        Some(h) => {
            let (a0, a1) = a.split_at_row(h);
            let (b0, b1) = b.split_at_row(h);
            let (c0, c1) = rayon::join(|| seq(a0, b0), || seq(a1, b1));
            c0 + c1
        }
    }
}

/// `out ← α·A·B` (`accum` Replace) or `out ← out + α·A·B` (Add) for a tall A (n × k) and a
/// small B (k × m): the two halves of the rows run as parallel tasks.
pub fn matmul_tall(out: MatMut<'_, f64>, accum: Accum, a: MatRef<'_, f64>, b: MatRef<'_, f64>, alpha: f64) {
    match row_split(a.nrows()) {
        None => matmul(out, accum, a, b, alpha, Par::Seq),
        Some(h) => {
            let (o0, o1) = out.split_at_row_mut(h);
            let (a0, a1) = a.split_at_row(h);
            rayon::join(
                || matmul(o0, accum, a0, b, alpha, Par::Seq),
                || matmul(o1, accum, a1, b, alpha, Par::Seq),
            );
        }
    }
}

/// Deterministic SplitMix64 source of uniform numbers in (−1, 1).
pub struct Rng(u64);

impl Rng {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// Fills `x` with uniform random numbers.
    pub fn fill(&mut self, mut x: MatMut<'_, f64>) {
        for j in 0..x.ncols() {
            for i in 0..x.nrows() {
                x[(i, j)] = self.next();
            }
        }
    }
}

/// An M-orthonormal set of vectors kept out of every Krylov block (rigid modes, locked modes).
pub struct Deflation {
    /// n × d, M-orthonormal.
    pub v: Mat<f64>,
    /// M v.
    pub mv: Mat<f64>,
}

impl Deflation {
    /// Empty set for dimension n.
    pub fn empty(n: usize) -> Self {
        Self { v: Mat::zeros(n, 0), mv: Mat::zeros(n, 0) }
    }

    /// Number of vectors.
    pub fn len(&self) -> usize {
        self.v.ncols()
    }

    /// Appends M-orthonormal vectors `w` (already M-orthogonal to the set).
    pub fn extend(&mut self, m: SparseColMatRef<'_, usize, f64>, w: MatRef<'_, f64>) {
        *self = self.extended(m, w);
    }

    /// This set plus M-orthonormal vectors `w` (already M-orthogonal to it).
    pub fn extended(&self, m: SparseColMatRef<'_, usize, f64>, w: MatRef<'_, f64>) -> Deflation {
        let mw = spmm(m, w);
        Deflation { v: hcat(self.v.as_ref(), w), mv: hcat(self.mv.as_ref(), mw.as_ref()) }
    }

    /// z ← z − V (MV)ᵀ z.
    pub fn project_out(&self, mut z: MatMut<'_, f64>) {
        if self.len() == 0 {
            return;
        }
        let c = tmul(self.mv.as_ref(), z.rb());
        matmul_tall(z.rb_mut(), Accum::Add, self.v.as_ref(), c.as_ref(), -1.0);
    }
}

/// [a b] column concatenation.
pub fn hcat(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::zeros(a.nrows(), a.ncols() + b.ncols());
    c.as_mut().subcols_mut(0, a.ncols()).copy_from(a);
    c.as_mut().subcols_mut(a.ncols(), b.ncols()).copy_from(b);
    c
}

/// M-orthonormalizes the columns of `z` in place (SVQB, twice), keeping directions whose
/// M-norm exceeds `drop` × (largest M-norm). Returns (rank, B) with
/// `z_in ≈ z_out[:, ..rank] · B` (B is rank × ncols); columns beyond rank are garbage.
pub fn svqb(m: SparseColMatRef<'_, usize, f64>, z: MatMut<'_, f64>, drop: f64) -> (usize, Mat<f64>) {
    let mut mz = spmm(m, z.rb());
    svqb_with(z, mz.as_mut(), drop)
}

/// [`svqb`] given `mz = M z`; both are updated (no sparse product).
pub fn svqb_with(mut z: MatMut<'_, f64>, mut mz: MatMut<'_, f64>, drop: f64) -> (usize, Mat<f64>) {
    let p = z.ncols();
    let mut b_total = Mat::<f64>::identity(p, p);
    let mut rank = p;
    for pass in 0..2 {
        let zr = z.rb().subcols(0, rank);
        let g = tmul(zr, mz.rb().subcols(0, rank));
        let Some((s, u)) = sym_eig(g.as_ref()) else {
            return (0, Mat::zeros(0, p));
        };
        let smax = (0..rank).map(|i| s[i]).fold(0.0f64, f64::max);
        let thresh = if pass == 0 { drop * drop * smax } else { 1e-3 * smax };
        // Keep eigen-directions in descending order of Σ.
        let keep: Vec<usize> = (0..rank).rev().filter(|&i| s[i] > thresh && s[i] > 0.0).collect();
        let r = keep.len();
        let mut t = Mat::<f64>::zeros(rank, r); // U Σ^{-1/2}
        let mut bt = Mat::<f64>::zeros(r, rank); // Σ^{1/2} Uᵀ
        for (c, &i) in keep.iter().enumerate() {
            let si = s[i].sqrt();
            for row in 0..rank {
                t[(row, c)] = u[(row, i)] / si;
                bt[(c, row)] = u[(row, i)] * si;
            }
        }
        let mut q = Mat::<f64>::zeros(z.nrows(), r);
        matmul_tall(q.as_mut(), Accum::Replace, zr, t.as_ref(), 1.0);
        z.rb_mut().subcols_mut(0, r).copy_from(q.as_ref());
        matmul_tall(q.as_mut(), Accum::Replace, mz.rb().subcols(0, rank), t.as_ref(), 1.0);
        mz.rb_mut().subcols_mut(0, r).copy_from(q.as_ref());
        let mut nb = Mat::<f64>::zeros(r, p);
        matmul(nb.as_mut(), Accum::Replace, bt.as_ref(), b_total.as_ref().subrows(0, rank), 1.0, Par::Seq);
        b_total = nb;
        rank = r;
        if rank == 0 {
            break;
        }
    }
    (rank, b_total)
}

/// A ← (A + Aᵀ)/2.
pub fn symmetrize(mut a: MatMut<'_, f64>) {
    let n = a.nrows();
    for j in 0..n {
        for i in 0..j {
            let v = 0.5 * (a[(i, j)] + a[(j, i)]);
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
}

/// Block CGS2 of `z` against the deflation set and `basis` (both M-orthonormal, with their
/// M-images `mbasis`). Returns the accumulated coefficients C, z ← z − basis C. No sparse
/// product: ⟨basis, z⟩_M = (M basis)ᵀ z.
pub fn orthogonalize(
    defl: &Deflation,
    basis: MatRef<'_, f64>,
    mbasis: MatRef<'_, f64>,
    mut z: MatMut<'_, f64>,
) -> Mat<f64> {
    if z.ncols() <= crate::cgs::WIDTH && crate::cgs::available() {
        return orthogonalize_rows(defl, basis, mbasis, z);
    }
    let mut coeffs = Mat::<f64>::zeros(basis.ncols(), z.ncols());
    for _ in 0..2 {
        defl.project_out(z.rb_mut());
        if basis.ncols() > 0 {
            let c = tmul(mbasis, z.rb());
            matmul_tall(z.rb_mut(), Accum::Add, basis, c.as_ref(), -1.0);
            coeffs += &c;
        }
    }
    coeffs
}

/// [`orthogonalize`] with the row-major kernels of [`crate::cgs`] (blocks of ≤ 8 columns):
/// the block is transposed once for all four products of each pass.
fn orthogonalize_rows(
    defl: &Deflation,
    basis: MatRef<'_, f64>,
    mbasis: MatRef<'_, f64>,
    z: MatMut<'_, f64>,
) -> Mat<f64> {
    use crate::cgs::{gram, subtract_product, RowBlock};
    let mut rows = RowBlock::from_mat(z.rb());
    let mut coeffs = Mat::<f64>::zeros(basis.ncols(), z.ncols());
    for _ in 0..2 {
        if defl.len() > 0 {
            let c = gram(defl.mv.as_ref(), &rows);
            subtract_product(defl.v.as_ref(), c.as_ref(), &mut rows);
        }
        if basis.ncols() > 0 {
            let c = gram(mbasis, &rows);
            subtract_product(basis, c.as_ref(), &mut rows);
            coeffs += &c;
        }
    }
    rows.write_to(z);
    coeffs
}

/// M-orthonormal block orthogonal to `defl` and `basis`: orthogonalizes `z`, SVQB, and
/// replaces rank-deficient directions by random ones. Returns (B, C, M z_out) with
/// z_in − basis·C = z_out · B.
pub fn next_block(
    m: SparseColMatRef<'_, usize, f64>,
    defl: &Deflation,
    basis: MatRef<'_, f64>,
    mbasis: MatRef<'_, f64>,
    mut z: MatMut<'_, f64>,
    rng: &mut Rng,
) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
    let p = z.ncols();
    let norm_before = col_norm_max(z.rb());
    let c = orthogonalize(defl, basis, mbasis, z.rb_mut());
    let norm_after = col_norm_max(z.rb());
    // Euclidean norms only gauge the cancellation; SVQB's drop is on M-norms relative to
    // the largest remaining column.
    let drop = if norm_after > 0.0 { (1e-10 * norm_before / norm_after).min(1.0) } else { 1.0 };
    let mut mz = spmm(m, z.rb());
    let (rank, b_small) = svqb_with(z.rb_mut(), mz.as_mut(), drop);
    let mut b = Mat::<f64>::zeros(p, p);
    b.as_mut().subrows_mut(0, rank).copy_from(b_small.as_ref());
    if rank < p {
        // Breakdown: the Krylov space is (nearly) invariant; continue with random directions.
        let mut fill = Mat::<f64>::zeros(z.nrows(), p - rank);
        let both = hcat(basis, z.rb().subcols(0, rank));
        let mboth = hcat(mbasis, mz.as_ref().subcols(0, rank));
        let mut mfill = Mat::<f64>::zeros(z.nrows(), p - rank);
        for _attempt in 0..3 {
            rng.fill(fill.as_mut());
            orthogonalize(defl, both.as_ref(), mboth.as_ref(), fill.as_mut());
            mfill = spmm(m, fill.as_ref());
            let (r2, _) = svqb_with(fill.as_mut(), mfill.as_mut(), 1e-8);
            if r2 == p - rank {
                break;
            }
        }
        z.rb_mut().subcols_mut(rank, p - rank).copy_from(fill.as_ref());
        mz.as_mut().subcols_mut(rank, p - rank).copy_from(mfill.as_ref());
    }
    (b, c, mz)
}

/// max_j ‖z_j‖₂.
fn col_norm_max(z: MatRef<'_, f64>) -> f64 {
    (0..z.ncols()).map(|j| z.col(j).norm_l2()).fold(0.0, f64::max)
}

/// Rayleigh–Ritz of the pencil (K, M) on span(y): M-orthonormalizes y (SVQB), solves the
/// projected problem, returns (λ ascending, M-orthonormal Ritz vectors, relative residuals).
#[allow(non_snake_case)]
pub fn rayleigh_ritz_kM(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    mut y: Mat<f64>,
) -> Result<RitzSet, crate::EigenError> {
    let n = k.nrows();
    let q = y.ncols();
    if q == 0 {
        return Ok((Vec::new(), y, Vec::new()));
    }
    let mut my = spmm(m, y.as_ref());
    let (rank, _) = svqb_with(y.as_mut(), my.as_mut(), 1e-12);
    if rank < q {
        return Err(crate::EigenError::Factorization("converged vectors are linearly dependent".into()));
    }
    let ky = spmm(k, y.as_ref());
    let kq = tmul(y.as_ref(), ky.as_ref());
    let (lams, u) = sym_eig(kq.as_ref())
        .ok_or_else(|| crate::EigenError::Factorization("dense eigensolver failed".into()))?;
    let mut w = Mat::<f64>::zeros(n, q);
    matmul_tall(w.as_mut(), Accum::Replace, y.as_ref(), u.as_ref(), 1.0);
    let mut kw = Mat::<f64>::zeros(n, q);
    matmul_tall(kw.as_mut(), Accum::Replace, ky.as_ref(), u.as_ref(), 1.0);
    let mut mw = Mat::<f64>::zeros(n, q);
    matmul_tall(mw.as_mut(), Accum::Replace, my.as_ref(), u.as_ref(), 1.0);
    let res = residuals_from(&lams, kw.as_ref(), mw.as_ref());
    Ok((lams, w, res))
}

/// Eigen-decomposition of a small symmetric matrix (ascending), computed on a copy scaled to
/// unit max-norm: faer's dense solver uses absolute thresholds, and projected SI matrices
/// have entries of 1e-10 (shift-invert) or 1e10 (stiffness).
pub fn sym_eig(a: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = a.nrows();
    let mut t = a.to_owned();
    symmetrize(t.as_mut());
    let scale = t.norm_max();
    if !scale.is_finite() {
        return None;
    }
    let scale = if scale > 0.0 { scale } else { 1.0 };
    t *= faer::Scale(1.0 / scale);
    let eig = t.self_adjoint_eigen(Side::Lower).ok()?;
    let vals = (0..n).map(|i| eig.S().column_vector()[i] * scale).collect();
    Some((vals, eig.U().to_owned()))
}

/// (λ ascending, M-orthonormal vectors, relative residuals).
pub type RitzSet = (Vec<f64>, Mat<f64>, Vec<f64>);

/// Relative residuals ‖K w − λ M w‖₂ / (|λ| ‖M w‖₂) from the products K w and M w.
pub fn residuals_from(lambdas: &[f64], kw: MatRef<'_, f64>, mw: MatRef<'_, f64>) -> Vec<f64> {
    (0..kw.ncols())
        .map(|j| {
            let (mut r2, mut m2) = (0.0, 0.0);
            for i in 0..kw.nrows() {
                let r = kw[(i, j)] - lambdas[j] * mw[(i, j)];
                r2 += r * r;
                m2 += mw[(i, j)] * mw[(i, j)];
            }
            r2.sqrt() / (lambdas[j].abs() * m2.sqrt()).max(f64::MIN_POSITIVE)
        })
        .collect()
}

#[cfg(test)]
mod speed {
    use super::*;
    use crate::test_support::{steel_box, time_ms};

    /// `cargo test --release -p modal-eigen --lib spmm_speed -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn spmm_speed() {
        let asm = steel_box([14, 11, 7]);
        let n = asm.k.nrows();
        for p in [8, 58] {
            let mut x = Mat::zeros(n, p);
            Rng::new(1).fill(x.as_mut());
            let spmm_ms = time_ms(20, &mut || drop(std::hint::black_box(spmm(asm.k.as_ref(), x.as_ref()))));
            let tmul_ms = time_ms(20, &mut || drop(std::hint::black_box(tmul(x.as_ref(), x.as_ref()))));
            let nnz = asm.k.compute_nnz();
            eprintln!("n {n} nnz {nnz} p {p}: spmm {spmm_ms:.2} ms, tmul xtx {tmul_ms:.2} ms");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// spmm equals the plain sparse × dense product for widths that exercise every pass
    /// shape (1, 2 and 4 rows of 8, several passes, odd row lengths), in every SIMD variant.
    #[test]
    fn spmm_matches_plain_product() {
        let n = 300;
        let mut rng = Rng::new(11);
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, 4.0 + rng.next()));
            for d in [1, 7, 31] {
                if i + d < n {
                    let v = rng.next();
                    t.push(Triplet::new(i, i + d, v));
                    t.push(Triplet::new(i + d, i, v));
                }
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
        for p in [1, 8, 9, 17, 33, 70] {
            let mut x = Mat::zeros(n, p);
            rng.fill(x.as_mut());
            let want = &a * &x;
            let got = spmm(a.as_ref(), x.as_ref());
            let err = (&got - &want).norm_max() / want.norm_max();
            assert!(err < 1e-14, "p = {p}: {err:e}");
        }
    }
}
