//! Shared helpers for the eigensolver tests: synthetic problems with analytic spectra and
//! the invariants asserted after every solve.
#![allow(dead_code)]

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use modal_eigen::{EigenOptions, EigenSolution};

/// Eigenvalues of the free (Neumann) path-graph Laplacian with `n` nodes: 2 − 2cos(πk/n).
pub fn path_free(n: usize) -> Vec<f64> {
    (0..n).map(|k| 2.0 - 2.0 * (std::f64::consts::PI * k as f64 / n as f64).cos()).collect()
}

/// Eigenvalues of the path Laplacian with node 0 removed (fixed end) and `n` nodes left:
/// 2 − 2cos((2k−1)π/(2n+1)).
pub fn path_fixed(n: usize) -> Vec<f64> {
    (1..=n)
        .map(|k| 2.0 - 2.0 * (std::f64::consts::PI * (2 * k - 1) as f64 / (2 * n + 1) as f64).cos())
        .collect()
}

/// 3D grid problem: K = ks · (L_x ⊕ L_y ⊕ L_z) ⊗ I₃, M = ms · I (lumped), nodes numbered
/// x fastest; `fix_x0` removes the nodes with x = 0 (clamped face).
pub struct Grid {
    pub k: SparseColMat<usize, f64>,
    pub m: SparseColMat<usize, f64>,
    /// Analytic eigenvalues (all, ascending, with multiplicity).
    pub exact: Vec<f64>,
    /// Translation fields (n × 3), empty if clamped.
    pub rigid: Mat<f64>,
}

pub fn grid(nx: usize, ny: usize, nz: usize, ks: f64, ms: f64, fix_x0: bool) -> Grid {
    let id = |x: usize, y: usize, z: usize| -> Option<usize> {
        if fix_x0 {
            if x == 0 {
                return None;
            }
            Some((x - 1) + (nx - 1) * (y + ny * z))
        } else {
            Some(x + nx * (y + ny * z))
        }
    };
    let nodes = if fix_x0 { (nx - 1) * ny * nz } else { nx * ny * nz };
    let n = 3 * nodes;
    let mut t = Vec::new();
    let add_edge = |a: Option<usize>, b: Option<usize>, t: &mut Vec<Triplet<usize, usize, f64>>| {
        for c in 0..3 {
            if let Some(a) = a {
                t.push(Triplet::new(3 * a + c, 3 * a + c, ks));
            }
            if let Some(b) = b {
                t.push(Triplet::new(3 * b + c, 3 * b + c, ks));
            }
            if let (Some(a), Some(b)) = (a, b) {
                t.push(Triplet::new(3 * a + c, 3 * b + c, -ks));
                t.push(Triplet::new(3 * b + c, 3 * a + c, -ks));
            }
        }
    };
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                if x + 1 < nx {
                    add_edge(id(x, y, z), id(x + 1, y, z), &mut t);
                }
                if y + 1 < ny {
                    add_edge(id(x, y, z), id(x, y + 1, z), &mut t);
                }
                if z + 1 < nz {
                    add_edge(id(x, y, z), id(x, y, z + 1), &mut t);
                }
            }
        }
    }
    let k = SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
    let mt: Vec<_> = (0..n).map(|i| Triplet::new(i, i, ms)).collect();
    let m = SparseColMat::try_new_from_triplets(n, n, &mt).unwrap();
    let lx = if fix_x0 { path_fixed(nx - 1) } else { path_free(nx) };
    let (ly, lz) = (path_free(ny), path_free(nz));
    let mut exact = Vec::new();
    for a in &lx {
        for b in &ly {
            for c in &lz {
                for _ in 0..3 {
                    exact.push(ks / ms * (a + b + c));
                }
            }
        }
    }
    exact.sort_by(f64::total_cmp);
    let mut rigid = Mat::zeros(n, if fix_x0 { 0 } else { 3 });
    if !fix_x0 {
        for i in 0..nodes {
            for c in 0..3 {
                rigid[(3 * i + c, c)] = 1.0;
            }
        }
    }
    Grid { k, m, exact, rigid }
}

/// Invariants asserted after every solve: residuals, M-orthonormality, inertia, band, cap.
pub fn check_solution(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    sol: &EigenSolution,
    opts: &EigenOptions,
) {
    let n = k.nrows();
    let nm = sol.eigenvalues.len();
    assert_eq!(sol.vectors.nrows(), n);
    assert_eq!(sol.vectors.ncols(), nm);
    assert!(nm <= opts.max_modes);
    for w in sol.eigenvalues.windows(2) {
        assert!(w[0] <= w[1], "eigenvalues not ascending");
    }
    for f in sol.frequencies_hz() {
        assert!(f >= opts.min_freq_hz && f <= opts.max_freq_hz, "{f} Hz outside band");
    }
    // Independent residuals.
    let w = sol.vectors.as_ref();
    let kw = k.as_ref() * w;
    let mw = m.as_ref() * w;
    for j in 0..nm {
        let l = sol.eigenvalues[j];
        let r = (kw.col(j) - mw.col(j) * faer::Scale(l)).norm_l2() / (l * mw.col(j).norm_l2());
        let bound = modal_eigen::residual_bound(opts.tolerance, l, sol.stats.lambda_scale);
        assert!(r <= 1.5 * bound, "mode {j}: residual {r:e} > {bound:e}");
        assert!(sol.residuals[j] <= bound);
    }
    let g = w.transpose() * &mw;
    for i in 0..nm {
        for j in 0..nm {
            let e = if i == j { 1.0 } else { 0.0 };
            assert!((g[(i, j)] - e).abs() <= 1e-10, "W^T M W[{i},{j}] = {}", g[(i, j)]);
        }
    }
    assert_eq!(sol.stats.inertia_expected, sol.stats.inertia_found, "inertia check");
}

/// Relative difference.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
