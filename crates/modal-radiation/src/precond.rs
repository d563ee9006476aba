//! Block-Jacobi preconditioner `M = blockdiag(A_{τ₁τ₁}, A_{τ₂τ₂}, …)` for
//! GMRES ([`crate::gmres`]).
//!
//! The blocks are the diagonal blocks of `A` on the leaves `τ` of the
//! cluster tree ([`crate::hmatrix`]: a few dozen unknowns that lie close
//! together). Each is factorised once, `P A_ττ = L U` (Gaussian
//! elimination with partial pivoting), and `M⁻¹ v` solves every block on
//! its own: `n·|τ|` operations, against `≈ n²/2` for one product with `A`.
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
//! Determinism: pivots are chosen by largest modulus, ties to the lower
//! row; every block is solved in a fixed order.

use faer::c64;

/// One factorised diagonal block.
#[derive(Clone, Debug)]
struct Block {
    /// The unknowns of the block, in the order of its rows.
    unknowns: Vec<usize>,
    /// `L` (unit, below the diagonal) and `U` (on and above), row-major.
    lu: Vec<c64>,
    /// Row `i` of `P A_ττ` is row `pivot[i]` of `A_ττ`.
    pivot: Vec<usize>,
}

/// The factorised block-diagonal part of `A` (module doc).
#[derive(Clone, Debug)]
pub struct BlockJacobi {
    n: usize,
    blocks: Vec<Block>,
}

impl BlockJacobi {
    /// Factorises the blocks `(unknowns, A restricted to them, row-major)`,
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
            let (lu, pivot) = factor(a, m)?;
            out.push(Block { unknowns: unknowns.to_vec(), lu, pivot });
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
        let mut y = Vec::new();
        for b in &self.blocks {
            let m = b.unknowns.len();
            // L y = P v (forward), then U x = y (backward).
            y.clear();
            y.extend(b.pivot.iter().map(|&p| v[b.unknowns[p]]));
            for i in 0..m {
                let row = &b.lu[i * m..i * m + i];
                let s = row.iter().zip(&y[..i]).fold(y[i], |s, (l, yk)| s - l * yk);
                y[i] = s;
            }
            for i in (0..m).rev() {
                let row = &b.lu[i * m..(i + 1) * m];
                let s = row[i + 1..].iter().zip(&y[i + 1..]).fold(y[i], |s, (u, yk)| s - u * yk);
                y[i] = s / row[i];
            }
            for (&u, yi) in b.unknowns.iter().zip(&y) {
                out[u] = *yi;
            }
        }
    }
}

/// `P A = L U` of the row-major `m × m` matrix `a` in place; `None` when a
/// pivot is zero or a factor not finite.
fn factor(mut a: Vec<c64>, m: usize) -> Option<(Vec<c64>, Vec<usize>)> {
    let mut pivot: Vec<usize> = (0..m).collect();
    for k in 0..m {
        let p = (k..m).fold(k, |best, i| if a[i * m + k].norm() > a[best * m + k].norm() { i } else { best });
        if a[p * m + k].norm() == 0.0 {
            return None;
        }
        if p != k {
            for j in 0..m {
                a.swap(k * m + j, p * m + j);
            }
            pivot.swap(k, p);
        }
        let inv = 1.0 / a[k * m + k];
        for i in k + 1..m {
            let l = a[i * m + k] * inv;
            a[i * m + k] = l;
            for j in k + 1..m {
                let akj = a[k * m + j];
                a[i * m + j] -= l * akj;
            }
        }
    }
    let finite = a.iter().all(|z| z.re.is_finite() && z.im.is_finite());
    finite.then_some((a, pivot))
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
