//! Block-Jacobi preconditioner `M = blockdiag(A_{τ₁τ₁}, A_{τ₂τ₂}, …)` for
//! GMRES ([`crate::gmres`]).
//!
//! The blocks are the diagonal blocks of `A` on the leaves `τ` of the
//! cluster tree ([`crate::hmatrix`]: a few dozen unknowns that lie close
//! together). Each is inverted once (faer's LU with partial pivoting, one
//! thread), and `M⁻¹ v` multiplies every block's inverse with its part of
//! `v`: `n·|τ|` operations, against `≈ n²/2` for one product with `A`.
//! An explicit inverse rather than two triangular solves per block and
//! iteration: a plain matrix–vector product, and `M` need not be `A_ττ⁻¹`
//! to the last bit, only the same fixed operator at every iteration.
//!
//! Why blocks and not the diagonal alone: on a thin shell (the demo bowl's
//! 4 mm wall) a panel of the inner face and the one facing it on the outer
//! face, a wall thickness apart, couple almost as strongly as each panel
//! with itself (near-singular double-layer and hypersingular kernels). A
//! leaf box that holds both faces puts that coupling in `M`; GMRES on
//! `A M⁻¹` then sees the smooth far interaction, close to the identity,
//! and needs fewer iterations. Right preconditioning (`A M⁻¹ u = b`,
//! `x = M⁻¹ u`) keeps GMRES's residual the true one, `b − A x`.
//!
//! Determinism: every block is inverted on one thread and applied in a
//! fixed order.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::inverse;
use faer::{c64, Mat, MatMut, Par};

/// One inverted diagonal block.
#[derive(Clone, Debug)]
struct Block {
    /// The unknowns of the block, in the order of its rows.
    unknowns: Vec<usize>,
    /// `A_ττ⁻¹`, row-major.
    inverse: Vec<c64>,
}

/// The inverted block-diagonal part of `A` (module doc).
#[derive(Clone, Debug)]
pub struct BlockJacobi {
    n: usize,
    blocks: Vec<Block>,
}

impl BlockJacobi {
    /// Inverts the blocks `(unknowns, A restricted to them, row-major)`,
    /// which must partition `0..n`. `None` when a block is singular or not
    /// finite (GMRES's caller then factorises the whole system).
    pub fn new<'a>(
        n: usize,
        blocks: impl IntoIterator<Item = (&'a [usize], Vec<c64>)>,
    ) -> Option<BlockJacobi> {
        let mut seen = vec![false; n];
        let mut out = Vec::new();
        for (unknowns, a) in blocks {
            let m = unknowns.len();
            assert_eq!(a.len(), m * m, "a diagonal block is m × m");
            for &u in unknowns {
                assert!(
                    u < n && !std::mem::replace(&mut seen[u], true),
                    "blocks must partition the unknowns"
                );
            }
            out.push(Block { unknowns: unknowns.to_vec(), inverse: invert(&a, m)? });
        }
        assert!(seen.iter().all(|&s| s), "blocks must partition the unknowns");
        Some(BlockJacobi { n, blocks: out })
    }

    /// The point-Jacobi case: every block one unknown, `A_ii`.
    pub fn diagonal(diagonal: &[c64]) -> Option<BlockJacobi> {
        let singles: Vec<[usize; 1]> = (0..diagonal.len()).map(|i| [i]).collect();
        BlockJacobi::new(diagonal.len(), singles.iter().zip(diagonal).map(|(u, &d)| (&u[..], vec![d])))
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True for an empty preconditioner.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// `out = M⁻¹ v`.
    pub fn solve(&self, v: &[c64], out: &mut [c64]) {
        assert!(v.len() == self.n && out.len() == self.n);
        let mut part = Vec::new();
        for b in &self.blocks {
            let m = b.unknowns.len();
            part.clear();
            part.extend(b.unknowns.iter().map(|&u| v[u]));
            for (&u, row) in b.unknowns.iter().zip(b.inverse.chunks_exact(m)) {
                out[u] = row.iter().zip(&part).fold(c64::new(0.0, 0.0), |s, (a, x)| s + a * x);
            }
        }
    }
}

/// The inverse of the row-major `m × m` matrix `a`, row-major; `None` when
/// a pivot of its LU factorisation is zero or not finite, or the inverse
/// is not finite.
fn invert(a: &[c64], m: usize) -> Option<Vec<c64>> {
    // Column-major storage of `aᵀ`: faer reads the row-major block as its
    // transpose, whose inverse is the transpose of the inverse; taking
    // `aᵀ` keeps both in row-major order without copies.
    let mut lu = a.to_vec();
    let mut lu = MatMut::from_column_major_slice_mut(&mut lu, m, m);
    let p = crate::bem::lu_in_place(lu.as_mut())?;
    let par = Par::Seq;
    let mut buf = MemBuffer::new(inverse::inverse_scratch::<usize, c64>(m, par));
    let mut inv = Mat::<c64>::zeros(m, m);
    inverse::inverse(inv.as_mut(), lu.as_ref(), lu.as_ref(), p.as_ref(), par, MemStack::new(&mut buf));
    // `inv` is (aᵀ)⁻¹ = (a⁻¹)ᵀ: entry (i, j) of a⁻¹ is inv(j, i).
    let out: Vec<c64> = (0..m * m).map(|k| inv[(k % m, k / m)]).collect();
    out.iter().all(|z| z.re.is_finite() && z.im.is_finite()).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_block_diagonal_matrix_exactly() {
        // Two interleaved 3 × 3 blocks of a 6 × 6 matrix, one needing a pivot
        // (zero leading entry).
        let blocks: [(Vec<usize>, Vec<c64>); 2] = [
            (
                vec![4, 0, 2],
                [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.5, 4.0].map(|x| c64::new(x, 0.3 * x)).to_vec(),
            ),
            (vec![1, 5, 3], [5.0, 1.0, 0.0, 1.0, 4.0, 1.0, 0.0, 1.0, 3.0].map(|x| c64::new(x, -x)).to_vec()),
        ];
        let pc = BlockJacobi::new(6, blocks.iter().map(|(u, a)| (&u[..], a.clone()))).expect("regular");
        let x: Vec<c64> = (0..6).map(|i| c64::new(i as f64 + 1.0, 0.5 - i as f64)).collect();
        let mut b = vec![c64::new(0.0, 0.0); 6];
        for (u, a) in &blocks {
            for (r, &i) in u.iter().enumerate() {
                b[i] = u.iter().enumerate().map(|(c, &j)| a[r * 3 + c] * x[j]).sum();
            }
        }
        let mut y = vec![c64::new(0.0, 0.0); 6];
        pc.solve(&b, &mut y);
        for (yi, xi) in y.iter().zip(&x) {
            assert!((yi - xi).norm() < 1e-13, "{yi} vs {xi}");
        }
    }

    #[test]
    fn a_singular_block_gives_none() {
        let a = vec![c64::new(1.0, 0.0), c64::new(2.0, 0.0), c64::new(2.0, 0.0), c64::new(4.0, 0.0)];
        assert!(BlockJacobi::new(2, [(&[0usize, 1][..], a)]).is_none());
        assert!(BlockJacobi::diagonal(&[c64::new(1.0, 0.0), c64::new(0.0, 0.0)]).is_none());
    }
}
