//! Dense block kernels in the M-inner product ⟨x, y⟩ = xᵀ M y.
//!
//! - block classical Gram–Schmidt, applied twice ("twice is enough", Giraud et al. 2005),
//!   against a deflation set and the current basis;
//! - SVQB (Stathopoulos & Wu 2002): Z = Q B with G = Zᵀ M Z = U Σ Uᵀ, Q = Z U Σ^{-1/2},
//!   B = Σ^{1/2} Uᵀ; directions with Σᵢ ≤ (drop·scale)² are rank deficient and replaced by
//!   random vectors (reported with zero coupling in B).

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

/// Y = A X for a sparse A stored in full symmetric form.
pub fn spmm(a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut y = Mat::zeros(a.nrows(), x.ncols());
    sparse_dense_matmul(y.as_mut(), Accum::Replace, a, x, 1.0, Par::Seq);
    y
}

/// C = Aᵀ B.
pub fn tmul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::zeros(a.ncols(), b.ncols());
    matmul(c.as_mut(), Accum::Replace, a.transpose(), b, 1.0, Par::Seq);
    c
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
        let mw = spmm(m, w);
        self.v = hcat(self.v.as_ref(), w);
        self.mv = hcat(self.mv.as_ref(), mw.as_ref());
    }

    /// z ← z − V (MV)ᵀ z.
    pub fn project_out(&self, mut z: MatMut<'_, f64>) {
        if self.len() == 0 {
            return;
        }
        let c = tmul(self.mv.as_ref(), z.rb());
        matmul(z.rb_mut(), Accum::Add, self.v.as_ref(), c.as_ref(), -1.0, Par::Seq);
    }
}

/// [a b] column concatenation.
pub fn hcat(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let mut c = Mat::zeros(a.nrows(), a.ncols() + b.ncols());
    c.as_mut().subcols_mut(0, a.ncols()).copy_from(a);
    c.as_mut().subcols_mut(a.ncols(), b.ncols()).copy_from(b);
    c
}

/// M-orthonormalizes the columns of `z` in place (SVQB, twice), keeping at most `max_rank`
/// directions whose M-norm exceeds `drop` × (largest M-norm). Returns (rank, B) with
/// `z_in ≈ z_out[:, ..rank] · B` (B is rank × ncols); columns beyond rank are garbage.
pub fn svqb(m: SparseColMatRef<'_, usize, f64>, mut z: MatMut<'_, f64>, drop: f64) -> (usize, Mat<f64>) {
    let p = z.ncols();
    let mut b_total = Mat::<f64>::identity(p, p);
    let mut rank = p;
    for pass in 0..2 {
        let zr = z.rb().subcols(0, rank);
        let mz = spmm(m, zr);
        let g = tmul(zr, mz.as_ref());
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
        matmul(q.as_mut(), Accum::Replace, zr, t.as_ref(), 1.0, Par::Seq);
        z.rb_mut().subcols_mut(0, r).copy_from(q.as_ref());
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

/// Block CGS2 of `z` against the deflation set and `basis` (both M-orthonormal).
/// Returns the accumulated coefficients C (basis.ncols() × z.ncols()), z ← z − basis C.
pub fn orthogonalize(
    m: SparseColMatRef<'_, usize, f64>,
    defl: &Deflation,
    basis: MatRef<'_, f64>,
    mut z: MatMut<'_, f64>,
) -> Mat<f64> {
    let mut coeffs = Mat::<f64>::zeros(basis.ncols(), z.ncols());
    for _ in 0..2 {
        defl.project_out(z.rb_mut());
        if basis.ncols() > 0 {
            let mz = spmm(m, z.rb());
            let c = tmul(basis, mz.as_ref());
            matmul(z.rb_mut(), Accum::Add, basis, c.as_ref(), -1.0, Par::Seq);
            coeffs += &c;
        }
    }
    coeffs
}

/// M-orthonormal block orthogonal to `defl` and `basis`: orthogonalizes `z`, SVQB, and
/// replaces rank-deficient directions by random ones. Returns B (z.ncols() × z.ncols()) with
/// z_in − basis·C = z_out · B, and C.
pub fn next_block(
    m: SparseColMatRef<'_, usize, f64>,
    defl: &Deflation,
    basis: MatRef<'_, f64>,
    mut z: MatMut<'_, f64>,
    rng: &mut Rng,
) -> (Mat<f64>, Mat<f64>) {
    let p = z.ncols();
    let norm_before = m_norm_max(m, z.rb());
    let c = orthogonalize(m, defl, basis, z.rb_mut());
    let norm_after = m_norm_max(m, z.rb());
    let drop = if norm_after > 0.0 { 1e-10 * norm_before.max(norm_after) / norm_after } else { 1.0 };
    let (rank, b_small) = svqb(m, z.rb_mut(), drop.min(1.0));
    let mut b = Mat::<f64>::zeros(p, p);
    b.as_mut().subrows_mut(0, rank).copy_from(b_small.as_ref());
    if rank < p {
        // Breakdown: the Krylov space is (nearly) invariant; continue with random directions.
        let mut fill = Mat::<f64>::zeros(z.nrows(), p - rank);
        for _attempt in 0..3 {
            rng.fill(fill.as_mut());
            let both = hcat(basis, z.rb().subcols(0, rank));
            orthogonalize(m, defl, both.as_ref(), fill.as_mut());
            let (r2, _) = svqb(m, fill.as_mut(), 1e-8);
            if r2 == p - rank {
                break;
            }
        }
        z.rb_mut().subcols_mut(rank, p - rank).copy_from(fill.as_ref());
    }
    (b, c)
}

/// max_j ‖z_j‖_M.
fn m_norm_max(m: SparseColMatRef<'_, usize, f64>, z: MatRef<'_, f64>) -> f64 {
    let mz = spmm(m, z);
    (0..z.ncols())
        .map(|j| {
            let mut s = 0.0;
            for i in 0..z.nrows() {
                s += z[(i, j)] * mz[(i, j)];
            }
            s.max(0.0).sqrt()
        })
        .fold(0.0, f64::max)
}

/// Rayleigh–Ritz of the pencil (K, M) on span(y): M-orthonormalizes y (SVQB), solves the
/// projected problem, returns (λ ascending, M-orthonormal Ritz vectors).
#[allow(non_snake_case)]
pub fn rayleigh_ritz_kM(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    mut y: Mat<f64>,
) -> Result<(Vec<f64>, Mat<f64>), crate::EigenError> {
    let n = k.nrows();
    let q = y.ncols();
    if q == 0 {
        return Ok((Vec::new(), y));
    }
    let (rank, _) = svqb(m, y.as_mut(), 1e-12);
    if rank < q {
        return Err(crate::EigenError::Factorization("converged vectors are linearly dependent".into()));
    }
    let ky = spmm(k, y.as_ref());
    let kq = tmul(y.as_ref(), ky.as_ref());
    let (lams, u) = sym_eig(kq.as_ref())
        .ok_or_else(|| crate::EigenError::Factorization("dense eigensolver failed".into()))?;
    let mut w = Mat::<f64>::zeros(n, q);
    matmul(w.as_mut(), Accum::Replace, y.as_ref(), u.as_ref(), 1.0, Par::Seq);
    Ok((lams, w))
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
