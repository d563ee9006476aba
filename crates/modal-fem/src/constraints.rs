//! Clamped (Dirichlet `u = 0`) DOFs: selecting them and removing them from
//! `K` and `M`, then putting reduced vectors back on the full DOF set.
//!
//! Removing the clamped rows and columns of `K w = λ M w` gives the
//! eigenproblem of the constrained body; its shapes are zero at the clamped
//! DOFs ([`DofMap::expand`]).

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Mat, MatRef};

use crate::FemError;

/// Per-DOF clamp mask (`3·nodes` long, DOF `3i + c`): true for the three
/// DOFs of every node inside the closed axis-aligned box
/// `[x0, y0, z0, x1, y1, z1]` \[m\].
pub fn fix_box(nodes: &[[f64; 3]], bounds: [f64; 6]) -> Vec<bool> {
    let [x0, y0, z0, x1, y1, z1] = bounds;
    let (lo, hi) = ([x0, y0, z0], [x1, y1, z1]);
    nodes
        .iter()
        .flat_map(|p| {
            let inside = (0..3).all(|c| p[c] >= lo[c] && p[c] <= hi[c]);
            [inside; 3]
        })
        .collect()
}

/// The numbering of free DOFs inside the full DOF set.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// Full DOF index of each free DOF (increasing).
    pub free_to_full: Vec<usize>,
    /// Free index of each full DOF, `None` when clamped.
    pub full_to_free: Vec<Option<usize>>,
}

impl DofMap {
    /// The map for clamp mask `clamped` (true = clamped).
    pub fn from_clamped(clamped: &[bool]) -> DofMap {
        let mut free_to_full = Vec::new();
        let full_to_free = clamped
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                (!c).then(|| {
                    free_to_full.push(i);
                    free_to_full.len() - 1
                })
            })
            .collect();
        DofMap { free_to_full, full_to_free }
    }

    /// Number of free DOFs.
    pub fn free_count(&self) -> usize {
        self.free_to_full.len()
    }

    /// Number of DOFs in the full set.
    pub fn full_count(&self) -> usize {
        self.full_to_free.len()
    }

    /// A full-length vector with `free` at the free DOFs and 0 at clamped ones.
    pub fn expand(&self, free: &[f64]) -> Result<Vec<f64>, FemError> {
        if free.len() != self.free_count() {
            return Err(FemError::DofCountMismatch {
                what: "free vector",
                expected: self.free_count(),
                got: free.len(),
            });
        }
        let mut full = vec![0.0; self.full_count()];
        for (&i, &v) in self.free_to_full.iter().zip(free) {
            full[i] = v;
        }
        Ok(full)
    }

    /// Every column of `free` (free DOFs × k) expanded to the full DOF set.
    pub fn expand_columns(&self, free: MatRef<'_, f64>) -> Result<Mat<f64>, FemError> {
        if free.nrows() != self.free_count() {
            return Err(FemError::DofCountMismatch {
                what: "free matrix rows",
                expected: self.free_count(),
                got: free.nrows(),
            });
        }
        let mut full = Mat::zeros(self.full_count(), free.ncols());
        for j in 0..free.ncols() {
            for (r, &i) in self.free_to_full.iter().enumerate() {
                full[(i, j)] = free[(r, j)];
            }
        }
        Ok(full)
    }
}

/// `K` and `M` without the clamped DOFs, and the DOF numbering.
#[derive(Clone, Debug)]
pub struct Restricted {
    /// Stiffness on the free DOFs.
    pub k: SparseColMat<usize, f64>,
    /// Mass on the free DOFs.
    pub m: SparseColMat<usize, f64>,
    /// Free ↔ full DOF numbering (use [`DofMap::expand`] to put shapes back).
    pub dofs: DofMap,
}

/// Removes the clamped rows and columns (`clamped[i]` true, e.g. from
/// [`fix_box`]) from `k` and `m`.
pub fn restrict(
    k: &SparseColMat<usize, f64>,
    m: &SparseColMat<usize, f64>,
    clamped: &[bool],
) -> Result<Restricted, FemError> {
    for (what, a) in [("K", k), ("M", m)] {
        if a.nrows() != clamped.len() || a.ncols() != clamped.len() {
            return Err(FemError::DofCountMismatch { what, expected: clamped.len(), got: a.nrows() });
        }
    }
    let map = DofMap::from_clamped(clamped);
    Ok(Restricted { k: restrict_one(k, &map), m: restrict_one(m, &map), dofs: map })
}

fn restrict_one(a: &SparseColMat<usize, f64>, map: &DofMap) -> SparseColMat<usize, f64> {
    let (symbolic, values) = a.parts();
    let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
    let mut new_ptr = Vec::with_capacity(map.free_count() + 1);
    let mut new_rows = Vec::new();
    let mut new_vals = Vec::new();
    new_ptr.push(0);
    for &j in &map.free_to_full {
        for p in col_ptr[j]..col_ptr[j + 1] {
            if let Some(r) = map.full_to_free[row_idx[p]] {
                new_rows.push(r);
                new_vals.push(values[p]);
            }
        }
        new_ptr.push(new_rows.len());
    }
    let n = map.free_count();
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, new_ptr, None, new_rows), new_vals)
}
