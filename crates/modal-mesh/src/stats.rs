//! Weighted statistics of per-triangle quantities (a wall's thickness over
//! its area), shared by the thin-shell mesher and the radiation solver's
//! thin-wall check.

/// The weighted median of `(value, weight)` pairs: the smallest value at
/// which the cumulative weight, in increasing order of value, reaches half
/// the total. Sorts `pairs`; 0 for none.
pub fn weighted_median(pairs: &mut [(f64, f64)]) -> f64 {
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let half = 0.5 * pairs.iter().map(|p| p.1).sum::<f64>();
    let mut acc = 0.0;
    for &(value, weight) in pairs.iter() {
        acc += weight;
        if acc >= half {
            return value;
        }
    }
    pairs.last().map_or(0.0, |p| p.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_weighted_median_follows_the_weights() {
        assert_eq!(weighted_median(&mut []), 0.0);
        assert_eq!(weighted_median(&mut [(3.0, 1.0), (1.0, 1.0), (2.0, 1.0)]), 2.0);
        // One heavy value outweighs the others, wherever it sorts.
        assert_eq!(weighted_median(&mut [(1.0, 1.0), (5.0, 10.0), (2.0, 1.0)]), 5.0);
        // Exactly half reached at the first value: it is the median.
        assert_eq!(weighted_median(&mut [(2.0, 1.0), (1.0, 1.0)]), 1.0);
    }
}
