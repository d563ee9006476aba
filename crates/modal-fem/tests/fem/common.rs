//! Shared helpers (not every test module uses all of them): materials, meshes, dense generalized eigen solves.

#![allow(dead_code)]

use faer::{linalg::triangular_solve::solve_lower_triangular_in_place, Mat, Par, Side};
use modal_fem::Material;
use modal_mesh::{Cells, TetMesh};

/// The test material of `shared/reference/analytic.md`: E = 200 GPa, ν = 0.3, ρ = 7850.
pub fn steel() -> Material {
    Material::custom(200e9, 0.3, 7850.0, 0.0, 0.0).unwrap()
}

/// Relative closeness with a readable failure message.
#[track_caller]
pub fn assert_close(got: f64, want: f64, rel: f64, what: &str) {
    let err = (got - want).abs() / want.abs().max(f64::MIN_POSITIVE);
    assert!(err <= rel, "{what}: got {got:.15e}, want {want:.15e}, relative error {err:.3e} > {rel:.1e}");
}

/// Dense copy of a full-storage sparse matrix.
pub fn dense(a: &faer::sparse::SparseColMat<usize, f64>) -> Mat<f64> {
    a.to_dense()
}

/// Eigenvalues of `K w = λ M w` (ascending) by `M = L Lᵀ` and the
/// self-adjoint eigen solve of `L⁻¹ K L⁻ᵀ`.
pub fn generalized_eigenvalues(k: &Mat<f64>, m: &Mat<f64>) -> Vec<f64> {
    let llt = m.llt(Side::Lower).expect("M must be positive definite");
    let l = llt.L();
    let mut x = k.clone(); // L⁻¹ K
    solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut a = x.transpose().to_owned(); // (L⁻¹ K)ᵀ = K L⁻ᵀ
    solve_lower_triangular_in_place(l, a.as_mut(), Par::Seq); // L⁻¹ K L⁻ᵀ
    let sym = Mat::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    sym.self_adjoint_eigenvalues(Side::Lower).unwrap()
}

/// Frequencies [Hz] from eigenvalues λ = ω² (negative round-off → 0).
pub fn hz(eigenvalues: &[f64]) -> Vec<f64> {
    eigenvalues.iter().map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)).collect()
}

/// Two meshes side by side as one mesh (second one's node indices offset).
pub fn union(a: &TetMesh, b: &TetMesh) -> TetMesh {
    let offset = a.nodes.len();
    let nodes = a.nodes.iter().chain(&b.nodes).copied().collect();
    let cells = match (&a.cells, &b.cells) {
        (Cells::Tet4(x), Cells::Tet4(y)) => {
            Cells::Tet4(x.iter().copied().chain(y.iter().map(|t| t.map(|n| n + offset))).collect())
        }
        (Cells::Tet10(x), Cells::Tet10(y)) => {
            Cells::Tet10(x.iter().copied().chain(y.iter().map(|t| t.map(|n| n + offset))).collect())
        }
        _ => panic!("mixed orders"),
    };
    TetMesh { nodes, cells, groups: Vec::new() }
}

/// `mesh` translated by `d`.
pub fn translated(mesh: &TetMesh, d: [f64; 3]) -> TetMesh {
    let mut out = mesh.clone();
    out.nodes.iter_mut().for_each(|p| (0..3).for_each(|c| p[c] += d[c]));
    out
}

/// Moves interior nodes of a box mesh `[0, size]` by a deterministic
/// pseudo-random fraction of `h` so elements are irregular; boundary
/// nodes stay, so the domain is still the box.
pub fn jiggle_interior(mesh: &mut TetMesh, size: [f64; 3], h: f64) {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for p in &mut mesh.nodes {
        let interior = (0..3).all(|c| p[c] > 1e-12 * size[c] && p[c] < size[c] * (1.0 - 1e-12));
        let shift = [next(), next(), next()];
        if interior {
            (0..3).for_each(|c| p[c] += 0.25 * h * shift[c]);
        }
    }
}

/// `y = A x`.
pub fn mul(a: &faer::sparse::SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let (s, v) = a.parts();
    let mut y = vec![0.0; a.nrows()];
    for j in 0..a.ncols() {
        for p in s.col_ptr()[j]..s.col_ptr()[j + 1] {
            y[s.row_idx()[p]] += v[p] * x[j];
        }
    }
    y
}

/// `xᵀ y`.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// Eigenpairs of the small dense problem `K q = λ M q`: ascending values and
/// M-orthonormal vectors (columns).
pub fn generalized_eigen(k: &Mat<f64>, m: &Mat<f64>) -> (Vec<f64>, Mat<f64>) {
    use faer::linalg::triangular_solve::solve_upper_triangular_in_place;
    let llt = m.llt(Side::Lower).expect("M must be positive definite");
    let l = llt.L();
    let mut x = k.clone();
    solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut a = x.transpose().to_owned();
    solve_lower_triangular_in_place(l, a.as_mut(), Par::Seq);
    let sym = Mat::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let evd = sym.self_adjoint_eigen(Side::Lower).unwrap();
    let values = (0..sym.nrows()).map(|i| evd.S()[i]).collect();
    let mut q = evd.U().to_owned();
    solve_upper_triangular_in_place(l.transpose(), q.as_mut(), Par::Seq);
    (values, q)
}

/// `Aᵀ B` for tall dense blocks.
fn at_b(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    a.transpose() * b
}

/// `A X` column by column for a sparse `A`.
fn sparse_times(a: &faer::sparse::SparseColMat<usize, f64>, x: &Mat<f64>) -> Mat<f64> {
    let mut out = Mat::zeros(x.nrows(), x.ncols());
    for j in 0..x.ncols() {
        let col: Vec<f64> = (0..x.nrows()).map(|i| x[(i, j)]).collect();
        for (i, v) in mul(a, &col).into_iter().enumerate() {
            out[(i, j)] = v;
        }
    }
    out
}

/// The `count` lowest eigenvalues of `K w = λ M w` (K, M sharing one
/// sparsity pattern) by shift-invert subspace iteration with Rayleigh–Ritz:
/// `K − σM = LLᵀ` (faer sparse Cholesky), σ = −(2π·10 Hz)², block of
/// `count + 12` vectors, until the wanted values change by < 1e-13 of the
/// largest wanted one between iterations.
pub fn lowest_eigenvalues(
    k: &faer::sparse::SparseColMat<usize, f64>,
    m: &faer::sparse::SparseColMat<usize, f64>,
    count: usize,
) -> Vec<f64> {
    use faer::linalg::solvers::Solve;
    use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
    use faer::sparse::SparseColMat;
    let sigma = -(2.0 * std::f64::consts::PI * 10.0f64).powi(2);
    let values: Vec<f64> = k.val().iter().zip(m.val()).map(|(a, b)| a - sigma * b).collect();
    let shifted = SparseColMat::new(k.symbolic().to_owned().unwrap(), values);
    let symbolic = SymbolicLlt::try_new(shifted.symbolic(), Side::Lower).unwrap();
    let llt = Llt::try_new_with_symbolic(symbolic, shifted.as_ref(), Side::Lower).unwrap();
    let n = k.nrows();
    let p = count + 12;
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut x = Mat::from_fn(n, p, |_, _| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    });
    let mut previous = vec![f64::INFINITY; count];
    for _ in 0..100 {
        let mut y = sparse_times(m, &x);
        llt.solve_in_place(y.as_mut());
        let (lambda, q) = generalized_eigen(&at_b(&y, &sparse_times(k, &y)), &at_b(&y, &sparse_times(m, &y)));
        x = &y * &q;
        let scale = lambda[count - 1].abs();
        let converged = lambda[..count].iter().zip(&previous).all(|(a, b)| (a - b).abs() <= 1e-13 * scale);
        previous.copy_from_slice(&lambda[..count]);
        if converged {
            return previous;
        }
    }
    panic!("subspace iteration did not converge");
}
