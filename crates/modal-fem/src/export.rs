//! Plain-text export for cross-checking with other tools.
//!
//! MatrixMarket (`%%MatrixMarket matrix coordinate real symmetric`): a size
//! line `n n entries`, then one `i j value` line per stored entry of the
//! LOWER triangle (`i ≥ j`), 1-based, column by column, values with 17
//! significant digits in C `%.16e` style (`-1.2345678901234567e+09`), which
//! round-trips every f64. Entries that are exactly zero (e.g. the
//! cross-component entries of M, which shares K's pattern) are omitted.
//!
//! Nodes CSV: header `x,y,z`, one row per node (mid-edge nodes included)
//! in node order, so DOF `3i + c` belongs to data row `i`.

use std::io::{self, Write};

use faer::sparse::SparseColMat;

/// Formats `v` with 17 significant digits and a signed two-digit-minimum
/// exponent, like C's `%.16e`.
fn sci(v: f64) -> String {
    let s = format!("{v:.16e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => {
            let (sign, digits) = exp.strip_prefix('-').map_or(("+", exp), |d| ("-", d));
            format!("{mantissa}e{sign}{digits:0>2}")
        }
        None => s, // inf / NaN
    }
}

/// Writes the lower triangle of the symmetric matrix `a` (full storage) in
/// MatrixMarket coordinate real symmetric format, and returns the number of
/// entries written (the size line's third number): the stored lower-triangle
/// entries that are not exactly zero, not `a`'s stored count.
pub fn write_matrix_market(a: &SparseColMat<usize, f64>, out: impl Write) -> io::Result<usize> {
    let mut out = io::BufWriter::new(out);
    let (symbolic, values) = a.parts();
    let (col_ptr, row_idx) = (symbolic.col_ptr(), symbolic.row_idx());
    let lower = |j: usize| (col_ptr[j]..col_ptr[j + 1]).filter(move |&p| row_idx[p] >= j && values[p] != 0.0);
    let count: usize = (0..a.ncols()).map(|j| lower(j).count()).sum();
    writeln!(out, "%%MatrixMarket matrix coordinate real symmetric")?;
    writeln!(out, "% written by modal-fem; lower triangle, 1-based")?;
    writeln!(out, "{} {} {}", a.nrows(), a.ncols(), count)?;
    for j in 0..a.ncols() {
        for p in lower(j) {
            writeln!(out, "{} {} {}", row_idx[p] + 1, j + 1, sci(values[p]))?;
        }
    }
    out.flush()?;
    Ok(count)
}

/// Writes node coordinates \[m\] as CSV with header `x,y,z`, full precision.
pub fn write_nodes_csv(nodes: &[[f64; 3]], out: impl Write) -> io::Result<()> {
    let mut out = io::BufWriter::new(out);
    writeln!(out, "x,y,z")?;
    for p in nodes {
        writeln!(out, "{},{},{}", sci(p[0]), sci(p[1]), sci(p[2]))?;
    }
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scientific_format_matches_c_and_round_trips() {
        assert_eq!(sci(1.0), "1.0000000000000000e+00");
        assert_eq!(sci(-0.25), "-2.5000000000000000e-01");
        assert_eq!(sci(2f64.powi(-40)), "9.0949470177292824e-13");
        assert_eq!(sci(2f64.powi(400)), "2.5822498780869086e+120");
        for v in [0.1, 1.0 / 3.0, 2.0e11 / 7.0, -1e-300, f64::MAX] {
            assert_eq!(sci(v).parse::<f64>().unwrap(), v);
        }
    }
}
