//! Recompression of a low-rank block `M = U Wᵀ = Σ_k u_k w_kᵀ` (`r` terms,
//! as ACA leaves them, [`crate::hmatrix`]) to the fewest terms within a
//! relative Frobenius error `ε`.
//!
//! ACA's terms are not orthogonal and its rank overshoots the SVD's. With
//! the Gram matrices `UᴴU = E_U Λ_U E_Uᴴ` (eigenvalues below
//! [`GRAM_FLOOR`]`·λ_max` dropped), `U = P_U S_U E_Uᴴ`, `S_U = Λ_U^{1/2}`,
//! `P_U = U E_U S_U⁻¹` orthonormal; likewise `W`. Then
//!
//! `M = P_U C P_Wᵀ`, core `C = S_U E_Uᴴ conj(E_W) S_W` (`r × r`),
//!
//! and the SVD `C = X Σ Yᴴ` gives `M = Σ_k (σ_k P_U x_k)(P_W conj(y_k))ᵀ`,
//! from which the smallest `σ_k` are dropped while their sum of squares
//! stays within `ε² Σ σ²`. The new factors are `U T_U`, `W T_W` with
//! `T_U = E_U S_U⁻¹ X Σ`, `T_W = E_W S_W⁻¹ conj(Y)` (`r × K`): the work is
//! `O((m + n) r²)` in products, against `O(r³)` for the small problems.
//!
//! The columns are first balanced (`‖u_k‖ = ‖w_k‖`), so the Gram
//! eigenvalues span the square root of ACA's spread (`ε` → `ε^{1/2}` ≈
//! 10⁻³ of the largest), far above their rounding (`10⁻¹⁶`).
//!
//! Every step runs on one thread (`Par::Seq`): the same bits for any
//! thread count.

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors};
use faer::linalg::matmul::matmul;
use faer::linalg::svd::{svd, svd_scratch, ComputeSvdVectors};
use faer::{c64, Accum, Mat, MatRef, Par};

/// Gram eigenvalues below this fraction of the largest are dropped: their
/// directions carry below `10⁻⁷` of the balanced factor, far under `ε`.
pub const GRAM_FLOOR: f64 = 1e-14;

/// `Σ_k u_k w_kᵀ` (`u_k` of length `m`, `w_k` of length `n`) recompressed
/// to relative Frobenius error `tol` (module doc), or `None` when that
/// would not lower the rank (or the factors are empty or not finite).
#[allow(clippy::type_complexity)]
pub fn recompress(u: &[Vec<c64>], w: &[Vec<c64>], tol: f64) -> Option<(Vec<Vec<c64>>, Vec<Vec<c64>>)> {
    let r = u.len();
    if r < 2 || w.len() != r {
        return None;
    }
    let (m, n) = (u[0].len(), w[0].len());
    // Balance: u_k·t_k, w_k/t_k with ‖u_k‖ t_k = ‖w_k‖ / t_k.
    let size = |v: &[c64]| v.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    let t: Vec<f64> = u.iter().zip(w).map(|(uk, wk)| (size(wk) / size(uk)).sqrt()).collect();
    if t.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
        return None;
    }
    let um = Mat::from_fn(m, r, |i, k| u[k][i] * t[k]);
    let wm = Mat::from_fn(n, r, |j, k| w[k][j] / t[k]);
    // A_U = E_U S_U (kept eigenpairs) and E_U S_U⁻¹, likewise W.
    let (au, bu) = half_gram(um.as_ref())?;
    let (aw, bw) = half_gram(wm.as_ref())?;
    let mut core = Mat::<c64>::zeros(au.ncols(), aw.ncols());
    matmul(core.as_mut(), Accum::Replace, au.adjoint(), aw.conjugate(), c64::new(1.0, 0.0), Par::Seq);
    let (rows, cols) = (core.nrows(), core.ncols());
    let size = rows.min(cols);
    let (mut s, mut x, mut y) =
        (Diag::<c64>::zeros(size), Mat::<c64>::zeros(rows, size), Mat::<c64>::zeros(cols, size));
    let req = svd_scratch::<c64>(
        rows,
        cols,
        ComputeSvdVectors::Thin,
        ComputeSvdVectors::Thin,
        Par::Seq,
        Default::default(),
    );
    let mut mem = MemBuffer::new(req);
    svd(
        core.as_ref(),
        s.as_mut(),
        Some(x.as_mut()),
        Some(y.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    // σ in descending order (faer's); keep the fewest within tol.
    let sigma: Vec<f64> = (0..size).map(|k| s.column_vector()[k].re).collect();
    let total: f64 = sigma.iter().map(|s| s * s).sum();
    let (mut keep, mut tail) = (size, 0.0);
    while keep > 0 && tail + sigma[keep - 1].powi(2) <= tol * tol * total {
        tail += sigma[keep - 1].powi(2);
        keep -= 1;
    }
    if keep >= r || !total.is_finite() {
        return None;
    }
    // T_U = E_U S_U⁻¹ X Σ, T_W = E_W S_W⁻¹ conj(Y) (first `keep` columns).
    let xs = Mat::from_fn(rows, keep, |i, k| x[(i, k)] * sigma[k]);
    let yc = Mat::from_fn(cols, keep, |i, k| y[(i, k)].conj());
    let product = |a: MatRef<'_, c64>, b: MatRef<'_, c64>| {
        let mut out = Mat::<c64>::zeros(a.nrows(), b.ncols());
        matmul(out.as_mut(), Accum::Replace, a, b, c64::new(1.0, 0.0), Par::Seq);
        out
    };
    let nu = product(um.as_ref(), product(bu.as_ref(), xs.as_ref()).as_ref());
    let nw = product(wm.as_ref(), product(bw.as_ref(), yc.as_ref()).as_ref());
    let columns = |a: &Mat<c64>| (0..keep).map(|k| (0..a.nrows()).map(|i| a[(i, k)]).collect()).collect();
    Some((columns(&nu), columns(&nw)))
}

/// `(E S, E S⁻¹)` of the Gram matrix `AᴴA = E S² Eᴴ`, the eigenpairs below
/// [`GRAM_FLOOR`] of the largest dropped.
fn half_gram(a: MatRef<'_, c64>) -> Option<(Mat<c64>, Mat<c64>)> {
    let r = a.ncols();
    let mut gram = Mat::<c64>::zeros(r, r);
    matmul(gram.as_mut(), Accum::Replace, a.adjoint(), a, c64::new(1.0, 0.0), Par::Seq);
    let (mut s, mut e) = (Diag::<c64>::zeros(r), Mat::<c64>::zeros(r, r));
    let req = self_adjoint_evd_scratch::<c64>(r, ComputeEigenvectors::Yes, Par::Seq, Default::default());
    let mut mem = MemBuffer::new(req);
    self_adjoint_evd(
        gram.as_ref(),
        s.as_mut(),
        Some(e.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let lambda: Vec<f64> = (0..r).map(|k| s.column_vector()[k].re).collect();
    let top = lambda.iter().copied().fold(0.0, f64::max);
    if !(top.is_finite() && top > 0.0) {
        return None;
    }
    let kept: Vec<usize> = (0..r).filter(|&k| lambda[k] > GRAM_FLOOR * top).collect();
    let scaled = |p: f64| Mat::from_fn(r, kept.len(), |i, c| e[(i, kept[c])] * lambda[kept[c]].powf(p));
    Some((scaled(0.5), scaled(-0.5)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Σ_k u_k w_kᵀ` as a dense row-major `m × n` matrix.
    fn expand(u: &[Vec<c64>], w: &[Vec<c64>]) -> Vec<c64> {
        let (m, n) = (u[0].len(), w[0].len());
        (0..m * n).map(|p| u.iter().zip(w).map(|(uk, wk)| uk[p / n] * wk[p % n]).sum()).collect()
    }

    fn relative(a: &[c64], b: &[c64]) -> f64 {
        let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).norm_sqr()).sum();
        (d / a.iter().map(|x| x.norm_sqr()).sum::<f64>()).sqrt()
    }

    /// A deterministic pseudo-random complex number in the unit square
    /// from two indices (SplitMix64 of the pair).
    fn noise(i: usize, j: usize) -> c64 {
        let mix = |mut z: u64| {
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let h = mix((i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ mix(j as u64 + 1));
        let unit = |b: u64| (b >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        c64::new(unit(h), unit(mix(h)))
    }

    #[test]
    fn a_rank_deficient_block_recompresses_to_its_rank() {
        // 12 terms, each a mix of the same 5 outer products: rank 5.
        let (m, n, rank) = (40, 30, 5);
        let base_u: Vec<Vec<c64>> = (0..rank).map(|k| (0..m).map(|i| noise(i, k)).collect()).collect();
        let base_w: Vec<Vec<c64>> = (0..rank).map(|k| (0..n).map(|j| noise(j + 100, k)).collect()).collect();
        let mut u = Vec::new();
        let mut w = Vec::new();
        for t in 0..12 {
            let k = t % rank;
            let c = noise(t, 500);
            u.push(base_u[k].iter().map(|x| x * c).collect::<Vec<_>>());
            w.push(base_w[k].clone());
        }
        let (nu, nw) = recompress(&u, &w, 1e-10).expect("lower rank");
        assert_eq!(nu.len(), rank);
        assert!(relative(&expand(&u, &w), &expand(&nu, &nw)) < 1e-12);
    }

    #[test]
    fn recompression_keeps_a_smooth_kernel_block_to_its_tolerance() {
        // e^{ik|x−y|}/|x−y| between separated points, as a padded sum of
        // 40 exact rank-one terms (rows of the identity times rows of M).
        let (m, n, k) = (40, 50, 12.0);
        let f = |i: usize, j: usize| {
            let r = 2.0 + j as f64 * 0.02 - i as f64 * 0.015;
            c64::new((k * r).cos(), (k * r).sin()) / r
        };
        let u: Vec<Vec<c64>> =
            (0..m).map(|l| (0..m).map(|i| c64::new(if i == l { 1.0 } else { 0.0 }, 0.0)).collect()).collect();
        let w: Vec<Vec<c64>> = (0..m).map(|l| (0..n).map(|j| f(l, j)).collect()).collect();
        for tol in [1e-4, 1e-6, 1e-8] {
            let (nu, nw) = recompress(&u, &w, tol).expect("lower rank");
            let err = relative(&expand(&u, &w), &expand(&nu, &nw));
            assert!(nu.len() < 20 && err <= tol * (1.0 + 1e-6), "tol {tol}: rank {}, error {err}", nu.len());
        }
    }

    #[test]
    fn a_full_rank_block_is_left_alone() {
        let u: Vec<Vec<c64>> = (0..6).map(|k| (0..6).map(|i| noise(i, k)).collect()).collect();
        let w: Vec<Vec<c64>> = (0..6).map(|k| (0..9).map(|j| noise(j + 50, k)).collect()).collect();
        assert!(recompress(&u, &w, 1e-6).is_none());
    }
}
