//! Relative error of computed frequencies against a reference list.
//!
//! Matching: the k-th lowest computed frequency is compared with the k-th lowest
//! reference frequency, `e_k = |f_k − f_ref,k| / f_ref,k`. Sorting both lists pairs the
//! members of a multiplet (Lamb's (2l+1)-fold roots split by the mesh) and swaps of
//! near-degenerate modes (the bar's modes 4 and 5, 0.2 % apart) without guessing mode
//! families, and among all one-to-one pairings it minimises the largest absolute
//! deviation, so it never overstates the error. Modes the solver did not return are
//! counted as missing, not silently dropped.

use serde::{Deserialize, Serialize};

/// The error of one case against its reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Reference frequencies compared (Hz), ascending.
    pub reference_hz: Vec<f64>,
    /// Relative error of each compared mode (same order as `reference_hz`).
    pub relative_errors: Vec<f64>,
    /// Largest relative error (NaN when nothing was compared).
    pub max_relative_error: f64,
    /// Median relative error (NaN when nothing was compared).
    pub median_relative_error: f64,
    /// Reference modes without a computed partner.
    pub missing: usize,
}

/// Compares sorted `computed` with sorted `reference` (both Hz), see the module docs.
pub fn compare_sorted(computed: &[f64], reference: &[f64]) -> Comparison {
    let mut c = computed.to_vec();
    let mut r = reference.to_vec();
    c.sort_by(f64::total_cmp);
    r.sort_by(f64::total_cmp);
    let n = c.len().min(r.len());
    let errors: Vec<f64> = (0..n).map(|i| ((c[i] - r[i]) / r[i]).abs()).collect();
    Comparison {
        max_relative_error: if n == 0 { f64::NAN } else { errors.iter().copied().fold(0.0, f64::max) },
        median_relative_error: median(&errors),
        missing: r.len() - n,
        reference_hz: r[..n].to_vec(),
        relative_errors: errors,
    }
}

/// Median of `values` (NaN when empty); the mean of the middle two for even counts.
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let mid = v.len() / 2;
    if v.len() % 2 == 1 {
        v[mid]
    } else {
        0.5 * (v[mid - 1] + v[mid])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn swapped_near_degenerate_modes_are_paired_by_value() {
        let c = compare_sorted(&[3051.0, 3044.0, 574.0], &[574.0, 3044.0, 3051.0]);
        assert_eq!(c.max_relative_error, 0.0);
        assert_eq!(c.missing, 0);
    }

    #[test]
    fn errors_median_and_missing_modes() {
        let c = compare_sorted(&[110.0, 190.0], &[100.0, 200.0, 300.0]);
        assert!((c.relative_errors[0] - 0.1).abs() < 1e-15);
        assert!((c.relative_errors[1] - 0.05).abs() < 1e-15);
        assert!((c.median_relative_error - 0.075).abs() < 1e-15);
        assert_eq!(c.missing, 1);
        assert!(compare_sorted(&[], &[1.0]).max_relative_error.is_nan());
    }
}
