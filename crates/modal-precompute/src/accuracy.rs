//! Per-mode discretization error from two discretization levels (issue 14, item 4).
//!
//! A natural frequency computed on a mesh of element size `h` behaves like
//!
//! ```text
//!   f_h = f + C hᵖ + o(hᵖ)
//! ```
//!
//! so a fine level `h` and a coarse level `H = r h` give the Richardson estimate of
//! the fine level's error
//!
//! ```text
//!   e_h = f_h − f ≈ (f_H − f_h) / (rᵖ − 1),     estimate_pct = 100 · |e_h| / f_h.
//! ```
//!
//! - `r` is measured from the two meshes, `r = (N_h / N_H)^{1/3}` with `N` the DOF
//!   count, not taken from the requested sizes (the mesher rounds, clips and grades).
//! - `p` is [`ASSUMED_ORDER`]: the smallest order observed on the corpus against
//!   converged references (BENCHMARKS.md, "Real assets"). A smaller `p` gives a larger
//!   estimate, so the estimate errs on the safe side when a mode converges faster.
//! - The levels are not nested (each is a fresh isosurface stuffing), so `f_H − f_h`
//!   carries geometric noise besides the `C hᵖ` term: one mode's two levels can agree by
//!   chance while both are off (measured on the corpus bracket: a mode 2.5 % off whose two
//!   levels agreed to 0.005 %). The discretization error varies smoothly with frequency
//!   (it depends on the wavelength against the element size), the noise does not, so
//!   each mode takes the larger of its own relative difference `dᵢ = |f_H − f_h| / f_h`
//!   and the RMS of `d` over the matched modes within [`POOL_WINDOW`] of its frequency:
//!   `estimate_pct = SAFETY · 100 · max(dᵢ, rms_window(d)) / (rᵖ − 1)`. [`SAFETY`] covers
//!   the rest. Both were chosen by measurement: the estimate must bracket the true error
//!   on the corpus against independent references (`tests/accuracy_cli.rs`).
//!
//! Modes are matched between the levels by shape, not by frequency order (near-repeated
//! frequencies swap order between meshes): the modal assurance criterion
//!
//! ```text
//!   MAC(a, b) = (aᵀb)² / (aᵀa · bᵀb)
//! ```
//!
//! on displacement vectors at (a subsample of) the fine surface nodes, the coarse shape
//! taken at the nearest coarse surface node. Pairs are assigned greedily by decreasing
//! MAC among modes within [`FREQUENCY_WINDOW`] of each other. Inside a cluster of
//! near-repeated modes each level picks an arbitrary basis of the shared eigenspace, so
//! a fine mode whose best MAC is below [`CLEAR_MAC`] takes the largest difference to any
//! coarse mode it shares shape with (MAC ≥ [`SHARED_MAC`]): conservative, never smaller
//! than the one-to-one difference. A mode with no coarse partner of MAC ≥ [`SHARED_MAC`]
//! gets no estimate (`None`).

use modal_bank::ModeBank;

/// Convergence order `p` of the frequency in the element size used by the estimate
/// (see the module docs).
pub const ASSUMED_ORDER: f64 = 2.0;

/// Factor applied to the Richardson estimate for the geometric noise of non-nested levels.
pub const SAFETY: f64 = 2.0;

/// Modes within this relative frequency distance pool their level differences (see the
/// module docs).
pub const POOL_WINDOW: f64 = 0.3;

/// Modes further apart than this relative frequency difference are never matched.
pub const FREQUENCY_WINDOW: f64 = 0.3;

/// A match with at least this MAC is one-to-one.
pub const CLEAR_MAC: f64 = 0.8;

/// Coarse modes with at least this MAC with a fine mode share its eigenspace.
pub const SHARED_MAC: f64 = 0.15;

/// At most this many fine surface nodes enter the MAC (an even subsample).
const MAC_SAMPLES: usize = 6000;

/// The estimate for one pair of levels.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelEstimate {
    /// Estimated error of each fine mode's frequency [%]; `None` when unmatched.
    pub error_pct: Vec<Option<f64>>,
    /// Coarse mode matched to each fine mode (best MAC), if any.
    pub matched: Vec<Option<usize>>,
    /// MAC of that match.
    pub mac: Vec<f64>,
    /// Measured size ratio `r = (N_fine / N_coarse)^{1/3}`.
    pub ratio: f64,
}

impl LevelEstimate {
    /// Largest estimate over the first `modes` modes; `None` if one of them has none
    /// (or there are no modes).
    pub fn worst_of_first(&self, modes: usize) -> Option<f64> {
        let first = &self.error_pct[..modes.min(self.error_pct.len())];
        if first.is_empty() {
            return None;
        }
        first.iter().try_fold(0.0_f64, |acc, e| e.map(|e| acc.max(e)))
    }

    /// One line saying how the estimate was made (stored in the bank).
    pub fn method(&self, fine_dofs: usize, coarse_dofs: usize) -> String {
        format!(
            "two-level Richardson: {fine_dofs} and {coarse_dofs} DOF, size ratio r = {:.3}, order p = {ASSUMED_ORDER}, \
             safety {SAFETY}, modes matched by MAC, differences pooled within ±{:.0} %",
            self.ratio,
            100.0 * POOL_WINDOW
        )
    }
}

/// Estimates the error of every mode of `fine` from the same object solved on a coarser
/// mesh (`coarse`). `fine_dofs` and `coarse_dofs` give the size ratio.
pub fn estimate(fine: &ModeBank, coarse: &ModeBank, fine_dofs: usize, coarse_dofs: usize) -> LevelEstimate {
    let ratio = (fine_dofs as f64 / coarse_dofs.max(1) as f64).cbrt();
    let mac = mac_matrix(fine, coarse);
    let matched = match_modes(&mac, &fine.frequencies_hz, &coarse.frequencies_hz);
    let denominator = ratio.powf(ASSUMED_ORDER) - 1.0;
    let mut difference = Vec::with_capacity(matched.len());
    let mut best_mac = Vec::with_capacity(matched.len());
    for (i, m) in matched.iter().enumerate() {
        let f = fine.frequencies_hz[i];
        let shared = |j: &usize| mac[i][*j] >= SHARED_MAC && within_window(f, coarse.frequencies_hz[*j]);
        let diff = match *m {
            Some(j) if mac[i][j] >= CLEAR_MAC => Some((coarse.frequencies_hz[j] - f).abs()),
            Some(j) => Some(
                (0..coarse.frequencies_hz.len())
                    .filter(shared)
                    .map(|k| (coarse.frequencies_hz[k] - f).abs())
                    .fold((coarse.frequencies_hz[j] - f).abs(), f64::max),
            ),
            None => None,
        };
        best_mac.push(m.map_or(0.0, |j| mac[i][j]));
        difference.push(diff.map(|d| d / f));
    }
    let pooled = pool(&fine.frequencies_hz, &difference);
    // A ratio ≤ 1 (the "coarse" level is not coarser) cannot extrapolate.
    let error_pct = difference
        .iter()
        .zip(&pooled)
        .map(|(d, p)| d.filter(|_| denominator > 1e-6).map(|d| SAFETY * 100.0 * d.max(*p) / denominator))
        .collect();
    LevelEstimate { error_pct, matched, mac: best_mac, ratio }
}

/// RMS of the known relative differences `d` of the modes within [`POOL_WINDOW`] of
/// each mode's frequency (0 where none is known).
fn pool(frequencies: &[f64], d: &[Option<f64>]) -> Vec<f64> {
    frequencies
        .iter()
        .map(|&f| {
            let near: Vec<f64> = frequencies
                .iter()
                .zip(d)
                .filter(|(&g, _)| (g - f).abs() <= POOL_WINDOW * f)
                .filter_map(|(_, d)| *d)
                .collect();
            if near.is_empty() {
                0.0
            } else {
                (near.iter().map(|x| x * x).sum::<f64>() / near.len() as f64).sqrt()
            }
        })
        .collect()
}

fn within_window(a: f64, b: f64) -> bool {
    (a - b).abs() <= FREQUENCY_WINDOW * a.max(b)
}

/// `mac[i][j]`: MAC of fine mode `i` with coarse mode `j` on the sampled fine surface
/// nodes (coarse shapes at the nearest coarse surface node).
pub fn mac_matrix(fine: &ModeBank, coarse: &ModeBank) -> Vec<Vec<f64>> {
    let (nf, nc) = (fine.mode_count(), coarse.mode_count());
    let s = fine.surface_node_count();
    if s == 0 || coarse.surface_node_count() == 0 {
        return vec![vec![0.0; nc]; nf];
    }
    let stride = s.div_ceil(MAC_SAMPLES).max(1);
    let samples: Vec<usize> = (0..s).step_by(stride).collect();
    let grid = NearestGrid::new(&coarse.surface.positions);
    let partner: Vec<usize> = samples.iter().map(|&k| grid.nearest(fine.surface.positions[k])).collect();
    let gather = |bank: &ModeBank, mode: usize, nodes: &mut dyn Iterator<Item = usize>| -> Vec<f64> {
        nodes.flat_map(|k| bank.shape_at(mode, k).map(f64::from)).collect()
    };
    let fine_vecs: Vec<Vec<f64>> = (0..nf).map(|i| gather(fine, i, &mut samples.iter().copied())).collect();
    let coarse_vecs: Vec<Vec<f64>> =
        (0..nc).map(|j| gather(coarse, j, &mut partner.iter().copied())).collect();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let fine_norm: Vec<f64> = fine_vecs.iter().map(|a| dot(a, a)).collect();
    let coarse_norm: Vec<f64> = coarse_vecs.iter().map(|b| dot(b, b)).collect();
    (0..nf)
        .map(|i| {
            (0..nc)
                .map(|j| {
                    let d = dot(&fine_vecs[i], &coarse_vecs[j]);
                    let n = fine_norm[i] * coarse_norm[j];
                    if n > 0.0 {
                        d * d / n
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}

/// Greedy one-to-one assignment by decreasing MAC among pairs within
/// [`FREQUENCY_WINDOW`] and with MAC ≥ [`SHARED_MAC`]; ties broken by the
/// smaller frequency difference, then by index (deterministic).
pub fn match_modes(mac: &[Vec<f64>], fine_hz: &[f64], coarse_hz: &[f64]) -> Vec<Option<usize>> {
    let mut pairs: Vec<(f64, f64, usize, usize)> = Vec::new();
    for (i, row) in mac.iter().enumerate() {
        for (j, &m) in row.iter().enumerate() {
            if m >= SHARED_MAC && within_window(fine_hz[i], coarse_hz[j]) {
                pairs.push((m, (fine_hz[i] - coarse_hz[j]).abs(), i, j));
            }
        }
    }
    pairs.sort_by(|a, b| {
        b.0.total_cmp(&a.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)).then(a.3.cmp(&b.3))
    });
    let mut fine_of = vec![None; mac.len()];
    let mut coarse_used = vec![false; coarse_hz.len()];
    for (_, _, i, j) in pairs {
        if fine_of[i].is_none() && !coarse_used[j] {
            fine_of[i] = Some(j);
            coarse_used[j] = true;
        }
    }
    fine_of
}

/// Nearest point among a fixed set: a uniform grid over the bounding box,
/// searched in growing shells of cells.
struct NearestGrid<'a> {
    points: &'a [[f64; 3]],
    origin: [f64; 3],
    cell: f64,
    dims: [usize; 3],
    /// Start of each cell's points in `order` (length cells + 1).
    start: Vec<usize>,
    order: Vec<usize>,
}

impl<'a> NearestGrid<'a> {
    fn new(points: &'a [[f64; 3]]) -> Self {
        let (lo, hi) = modal_mesh::bounding_box(points.iter().copied());
        let extent: f64 = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt().max(1e-12);
        // Surface points: about √n cells along the diagonal puts a few points per
        // occupied cell.
        let cell = extent / (points.len() as f64).sqrt().max(1.0);
        let dims = [0, 1, 2].map(|c| (((hi[c] - lo[c]) / cell) as usize + 1).min(1 << 10));
        let cell_of = |p: &[f64; 3]| -> usize {
            let idx = [0, 1, 2].map(|c| (((p[c] - lo[c]) / cell) as usize).min(dims[c] - 1));
            (idx[2] * dims[1] + idx[1]) * dims[0] + idx[0]
        };
        let cells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0usize; cells + 1];
        for p in points {
            start[cell_of(p) + 1] += 1;
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut order = vec![0; points.len()];
        for (k, p) in points.iter().enumerate() {
            let c = cell_of(p);
            order[fill[c]] = k;
            fill[c] += 1;
        }
        NearestGrid { points, origin: lo, cell, dims, start, order }
    }

    fn nearest(&self, q: [f64; 3]) -> usize {
        let idx = [0, 1, 2]
            .map(|c| (((q[c] - self.origin[c]) / self.cell).floor().max(0.0) as usize).min(self.dims[c] - 1));
        let (mut best, mut best_d2) = (0, f64::INFINITY);
        let max_shell = *self.dims.iter().max().unwrap_or(&1);
        for shell in 0..=max_shell {
            // Every point in a cell of this shell is at least (shell − 1) cells away.
            let reach = (shell as f64 - 1.0).max(0.0) * self.cell;
            if best_d2.is_finite() && reach * reach > best_d2 {
                break;
            }
            let lo = idx.map(|i| i.saturating_sub(shell));
            let hi = [0, 1, 2].map(|c| (idx[c] + shell).min(self.dims[c] - 1));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let on_shell = [x, y, z].iter().zip(idx).any(|(&v, i)| v.abs_diff(i) == shell);
                        if !on_shell {
                            continue;
                        }
                        let c = (z * self.dims[1] + y) * self.dims[0] + x;
                        for &k in &self.order[self.start[c]..self.start[c + 1]] {
                            let p = self.points[k];
                            let d2 = (0..3).map(|a| (p[a] - q[a]).powi(2)).sum::<f64>();
                            if d2 < best_d2 || (d2 == best_d2 && k < best) {
                                (best, best_d2) = (k, d2);
                            }
                        }
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg_points(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut x = seed;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(|_| [next(), 0.3 * next(), 2.0 * next()]).collect()
    }

    #[test]
    fn nearest_grid_agrees_with_brute_force() {
        let points = lcg_points(2000, 7);
        let grid = NearestGrid::new(&points);
        for q in lcg_points(500, 99).into_iter().chain([[5.0, -3.0, 1.0], [-1.0, 0.1, 9.0]]) {
            let brute = (0..points.len())
                .min_by(|&a, &b| {
                    let d = |k: usize| (0..3).map(|c| (points[k][c] - q[c]).powi(2)).sum::<f64>();
                    d(a).total_cmp(&d(b)).then(a.cmp(&b))
                })
                .unwrap();
            assert_eq!(grid.nearest(q), brute, "query {q:?}");
        }
    }

    #[test]
    fn matching_follows_shape_not_frequency_order() {
        // Fine modes 0 and 1 swapped order on the coarse level; a third mode has no partner.
        let mac = vec![vec![0.02, 0.97, 0.0], vec![0.95, 0.03, 0.0], vec![0.01, 0.02, 0.05]];
        let fine = [100.0, 101.0, 300.0];
        let coarse = [102.0, 103.0, 305.0];
        assert_eq!(match_modes(&mac, &fine, &coarse), vec![Some(1), Some(0), None]);
    }

    #[test]
    fn matching_respects_the_frequency_window() {
        let mac = vec![vec![0.9, 0.5]];
        // The best shape partner is 2× higher: refused; the second is taken.
        assert_eq!(match_modes(&mac, &[100.0], &[200.0, 110.0]), vec![Some(1)]);
    }

    #[test]
    fn pooling_lifts_a_mode_whose_levels_agree_by_chance() {
        let f = [100.0, 110.0, 120.0, 400.0];
        let d = [Some(0.02), Some(0.0), Some(0.02), Some(0.001)];
        let p = pool(&f, &d);
        // Modes 1-3 share a window: rms(0.02, 0, 0.02) for each; mode 4 is alone.
        let rms = (0.0008_f64 / 3.0).sqrt();
        for (k, &v) in p.iter().enumerate().take(3) {
            assert!((v - rms).abs() < 1e-15, "mode {k}: {v}");
        }
        assert!((p[3] - 0.001).abs() < 1e-15);
        assert_eq!(pool(&[1.0], &[None]), vec![0.0]);
    }

    #[test]
    fn worst_of_first_needs_every_mode() {
        let e = LevelEstimate {
            error_pct: vec![Some(0.5), Some(0.9), None, Some(3.0)],
            matched: vec![Some(0), Some(1), None, Some(3)],
            mac: vec![1.0, 1.0, 0.0, 1.0],
            ratio: 1.5,
        };
        assert_eq!(e.worst_of_first(2), Some(0.9));
        assert_eq!(e.worst_of_first(3), None);
        assert_eq!(e.worst_of_first(0), None);
    }
}
