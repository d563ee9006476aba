//! Synthetic problems with analytic spectra: 3D grid Laplacian ⊗ I₃ with lumped mass.
//! Kronecker structure gives exactly repeated eigenvalues (×3 from I₃, ×3 more on a cube).

mod common;
use common::*;
use modal_eigen::{hz_to_lambda, lambda_to_hz, solve, EigenOptions, Ordering};

fn wide_band(max_modes: usize) -> EigenOptions {
    EigenOptions { min_freq_hz: 0.0, max_freq_hz: 1e9, max_modes, ..Default::default() }
}

fn assert_matches(sol: &[f64], exact: &[f64], tol: f64) {
    for (i, (a, b)) in sol.iter().zip(exact).enumerate() {
        assert!(rel(*a, *b) < tol, "mode {i}: {a} vs exact {b}");
    }
}

#[test]
fn free_grid_with_rigid_deflation() {
    let g = grid(12, 9, 7, 1e4, 1e-5, false);
    let opts = wide_band(30);
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.stats.rigid_modes_removed, 3);
    eprintln!("searches? factorizations {}", sol.stats.factorizations);
    assert_matches(&sol.eigenvalues, &g.exact[3..], 1e-9);
}

#[test]
fn cube_grid_ninefold_multiplets() {
    // 8×8×8 nodes: each x/y/z permutation triple ×3 DOFs → 9-fold exact multiplets > block size.
    let g = grid(8, 8, 8, 1e4, 1e-5, false);
    let opts = wide_band(40);
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.eigenvalues.len(), 40);
    assert_matches(&sol.eigenvalues, &g.exact[3..], 1e-9);
}

#[test]
fn clamped_grid_no_rigid_modes() {
    let g = grid(10, 6, 5, 1e4, 1e-5, true);
    let opts = wide_band(20);
    let sol = solve(&g.k, &g.m, None, &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.stats.rigid_modes_removed, 0);
    assert_matches(&sol.eigenvalues, &g.exact, 1e-9);
}

#[test]
fn band_min_freq_excludes_low_modes() {
    let g = grid(12, 9, 7, 1e4, 1e-5, false);
    let elastic = &g.exact[3..];
    // Band edge between elastic modes 9 and 10 (exact values are in ×3 groups).
    let lo = 0.5 * (elastic[8] + elastic[9]);
    let hi = 0.5 * (elastic[26] + elastic[27]);
    let opts = EigenOptions {
        min_freq_hz: lambda_to_hz(lo),
        max_freq_hz: lambda_to_hz(hi),
        max_modes: 64,
        ..Default::default()
    };
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.stats.elastic_below_band, 9);
    assert_eq!(sol.eigenvalues.len(), 18);
    assert_matches(&sol.eigenvalues, &elastic[9..27], 1e-9);
}

#[test]
fn band_far_above_lowest_modes_uses_indefinite_shift() {
    let g = grid(12, 9, 7, 1e4, 1e-5, false);
    let elastic = &g.exact[3..];
    // First gap between distinct eigenvalues after 100 elastic modes.
    let below = (100..).find(|&i| rel(elastic[i + 1], elastic[i]) > 1e-6).unwrap() + 1;
    let lo = 0.5 * (elastic[below - 1] + elastic[below]);
    let opts =
        EigenOptions { min_freq_hz: lambda_to_hz(lo), max_freq_hz: 1e9, max_modes: 15, ..Default::default() };
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.stats.elastic_below_band, below);
    assert!(sol.stats.shift > 0.0);
    assert_eq!(sol.eigenvalues.len(), 15);
    assert_matches(&sol.eigenvalues, &elastic[below..below + 15], 1e-9);
}

#[test]
fn cap_splitting_a_multiplet_still_passes_inertia() {
    let g = grid(12, 9, 7, 1e4, 1e-5, false);
    let opts = wide_band(10); // exact values come in ×3: the cap splits a triple
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.eigenvalues.len(), 10);
    assert_matches(&sol.eigenvalues, &g.exact[3..], 1e-9);
}

#[test]
fn amd_and_metis_agree() {
    let g = grid(10, 7, 6, 1e4, 1e-5, false);
    let mut opts = wide_band(12);
    let a = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    opts.ordering = Ordering::Amd;
    let b = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &b, &opts);
    assert_matches(&a.eigenvalues, &b.eigenvalues, 1e-10);
    assert_eq!(a.stats.ordering, Some(modal_eigen::OrderingUsed::Metis));
    assert_eq!(b.stats.ordering, Some(modal_eigen::OrderingUsed::Amd));
}

#[test]
fn tiny_problem_uses_dense_path() {
    let g = grid(3, 2, 2, 1e4, 1e-5, false);
    let opts = wide_band(5);
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_matches(&sol.eigenvalues, &g.exact[3..], 1e-9);
}

#[test]
fn invalid_input_is_a_typed_error() {
    let g = grid(4, 3, 3, 1e4, 1e-5, false);
    let opts = EigenOptions { max_modes: 0, ..Default::default() };
    assert!(matches!(
        solve(&g.k, &g.m, None, &opts, &mut |_| {}),
        Err(modal_eigen::EigenError::InvalidOption { name: "max_modes", .. })
    ));
    let opts = EigenOptions { min_freq_hz: f64::NAN, ..Default::default() };
    assert!(solve(&g.k, &g.m, None, &opts, &mut |_| {}).is_err());
    // Zero mass at a DOF.
    let n = g.m.nrows();
    let t: Vec<_> =
        (0..n).map(|i| faer::sparse::Triplet::new(i, i, if i == 7 { 0.0 } else { 1e-5 })).collect();
    let m0 = faer::sparse::SparseColMat::try_new_from_triplets(n, n, &t).unwrap();
    assert_eq!(
        solve(&g.k, &m0, None, &EigenOptions::default(), &mut |_| {}).unwrap_err(),
        modal_eigen::EigenError::MassNotPositive { dof: 7 }
    );
    // NaN in K.
    let mut k = g.k.clone();
    k.val_mut()[3] = f64::NAN;
    assert!(matches!(
        solve(&k, &g.m, None, &EigenOptions::default(), &mut |_| {}),
        Err(modal_eigen::EigenError::NonFinite { matrix: "K", .. })
    ));
    let _ = hz_to_lambda(1.0);
}

#[test]
fn many_modes_with_restarts() {
    let g = grid(12, 9, 7, 1e4, 1e-5, false);
    let opts = wide_band(73);
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
}

#[test]
fn overlapped_inertia_check_matches_the_sequential_one() {
    // The early inertia check on a second thread must give the same modes and a proof as
    // valid as the check at the final shift (free grid with multiplets, cap mid-spectrum).
    let g = grid(12, 9, 7, 1e4, 1e-5, false);
    let mut runs = Vec::new();
    for overlap_check in [true, false] {
        let opts = EigenOptions { overlap_check, ..wide_band(25) };
        let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
        check_solution(&g.k, &g.m, &sol, &opts);
        assert_eq!(sol.stats.inertia_expected, sol.stats.inertia_found);
        assert!(sol.stats.inertia_shift > *sol.eigenvalues.last().unwrap());
        assert_matches(&sol.eigenvalues, &g.exact[3..], 1e-9);
        runs.push(sol);
    }
    // Overlap never costs more than the one speculative factorization.
    assert!(runs[0].stats.factorizations <= runs[1].stats.factorizations + 1);
    assert_eq!(runs[0].eigenvalues.len(), runs[1].eigenvalues.len());
}

#[test]
fn multiplets_wider_than_the_block_are_completed_by_repeated_searches() {
    // Blocks of 4 on a cube grid with 9-fold multiplets: a block Krylov space holds at most
    // 4 copies of an exact multiplet (rounding aside), so the inertia count finds modes
    // missing and repeated searches, with everything found deflated, must each go on until
    // they have the missing modes. (When each stopped at its first new mode, this ended in
    // InertiaMismatch { expected: 51, found: 46 } after 4 searches.)
    let g = grid(8, 8, 8, 1e4, 1e-5, false);
    let opts = EigenOptions { block_size: 4, ..wide_band(40) };
    let sol = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    check_solution(&g.k, &g.m, &sol, &opts);
    assert_eq!(sol.eigenvalues.len(), 40);
    assert_matches(&sol.eigenvalues, &g.exact[3..], 1e-9);
}

#[test]
fn a_given_analysis_is_used_when_it_fits_and_redone_when_not() {
    let g = grid(10, 6, 5, 1e4, 1e-5, false);
    let other = grid(6, 6, 6, 1e4, 1e-5, false);
    let opts = wide_band(20);
    let plain = solve(&g.k, &g.m, Some(g.rigid.as_ref()), &opts, &mut |_| {}).unwrap();
    for source in [&g, &other] {
        let analysis = modal_eigen::analyze(source.k.symbolic(), Ordering::Auto).unwrap();
        let sol = modal_eigen::solve_analyzed(
            &g.k,
            &g.m,
            Some(g.rigid.as_ref()),
            &opts,
            Some(analysis),
            &mut |_| {},
        )
        .unwrap();
        check_solution(&g.k, &g.m, &sol, &opts);
        // The same ordering either way (given, or redone from this pattern): the same bits.
        assert_eq!(sol.eigenvalues, plain.eigenvalues);
        assert!(sol.vectors == plain.vectors);
    }
}
