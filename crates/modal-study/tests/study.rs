//! The study's pieces: rate fit, references, and a tiny real study of the bar.

use modal_study::reference::{sphere_lamb_hz, timoshenko_cantilever_check, CANTILEVER_HZ};
use modal_study::{fit_power_law, run_case, CaseSpec, StudyReport, StudyShape};

#[test]
fn rate_fit_recovers_a_known_slope() {
    // e = 3 h^2.5 with a ±1 % deterministic wobble.
    let pts: Vec<(f64, f64)> = (0..6)
        .map(|k| {
            let h = 0.01 * 2f64.powf(-k as f64 / 2.0);
            (h, 3.0 * h.powf(2.5) * (1.0 + 0.01 * if k % 2 == 0 { 1.0 } else { -1.0 }))
        })
        .collect();
    let fit = fit_power_law(&pts).expect("fit");
    assert!((fit.slope - 2.5).abs() < 0.02, "slope {}", fit.slope);
    assert!((fit.intercept - 3f64.log10()).abs() < 0.05, "intercept {}", fit.intercept);
    assert_eq!(fit.points, 6);
    // Non-positive points are ignored; one point is not enough.
    assert!(fit_power_law(&[(1.0, 1.0), (2.0, 0.0), (-1.0, 3.0)]).is_none());
    assert!(fit_power_law(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
}

#[test]
fn sphere_reference_matches_the_worked_example() {
    // analytic.md §2: a = 0.05 m steel, T2 = 24 921.9 Hz (×5), S2 = 26 367.5 Hz, S1 = 35 173.6 Hz.
    let f = sphere_lamb_hz(0.05);
    assert_eq!(f.len(), 20);
    for (i, want) in [(0, 24_921.9), (4, 24_921.9), (5, 26_367.5), (10, 35_173.6)] {
        assert!((f[i] / want - 1.0).abs() < 2e-5, "mode {i}: {} vs {want}", f[i]);
    }
    assert!(f.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn cantilever_reference_agrees_with_timoshenko_for_slender_bending() {
    // Flat bending modes are the 1st and 3rd of the cantilever (edge bending 1 sits between).
    let beam = timoshenko_cantilever_check();
    for (mode, want) in [(0, beam[0]), (2, beam[1])] {
        let rel = CANTILEVER_HZ[mode] / want - 1.0;
        assert!(rel.abs() < 5e-3, "mode {mode}: 3D {} vs beam {want} ({rel:+.2e})", CANTILEVER_HZ[mode]);
    }
    assert!(CANTILEVER_HZ.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn case_spec_round_trip_and_bad_text() {
    let spec = CaseSpec::parse("cantilever:1:4").expect("valid");
    assert_eq!(spec, CaseSpec::new(StudyShape::Cantilever, 1, 4));
    assert_eq!(spec.label(), "cantilever:1:4");
    let sized = CaseSpec::parse("bar:2:h=2.5").expect("valid");
    assert_eq!(sized.label(), "bar:2:h=2.5");
    assert!((sized.h_m() - 2.5e-3).abs() < 1e-15);
    assert!(
        (sized.h_m() - StudyShape::Bar.level_h_m(2, 4)).abs() < 1e-15,
        "D/4 is level 4 of the TET10 bar ladder"
    );
    for bad in
        ["bar:3:1", "bar:2", "cube:2:1", "bar:2:x", "bar:2:99", "bar:2:h=0.01", "bar:2:h=nan", "bar:2:h=-1"]
    {
        assert!(CaseSpec::parse(bad).is_err(), "{bad}");
    }
}

/// Two coarse levels of the free-free bar at each order: errors fall with refinement,
/// and TET10 beats TET4 at the finer level (TET4's ladder starts one halving finer,
/// so the two have comparable DOF counts).
#[test]
fn tiny_bar_study_converges_and_tet10_wins() {
    let mut cases = Vec::new();
    for order in [1u8, 2] {
        for level in 0..2 {
            let case = run_case(CaseSpec::new(StudyShape::Bar, order, level)).expect("case runs");
            assert_eq!(case.comparison.missing, 0);
            assert_eq!(case.comparison.relative_errors.len(), 12);
            cases.push(case);
        }
    }
    let err = |i: usize| cases[i].comparison.max_relative_error;
    assert!(err(1) < err(0), "TET4 refines: {} -> {}", err(0), err(1));
    assert!(err(3) < err(2), "TET10 refines: {} -> {}", err(2), err(3));
    assert!(err(3) < 0.2 * err(1), "TET10 {} vs TET4 {}", err(3), err(1));
    // Linear tets are far too stiff in bending (analytic.md: +26 % at 4 mm); TET10 is close.
    assert!(err(1) > 0.05 && err(3) < 0.05, "TET4 {} TET10 {}", err(1), err(3));
    let report = StudyReport::new(cases, 0.01);
    assert_eq!(report.rates.len(), 2);
    let tet10 = report.rates[1].vs_h.expect("fit");
    assert!(tet10.slope > 1.0, "TET10 error falls faster than h: {}", tet10.slope);
    let md = report.to_markdown();
    assert!(md.contains("| bar | TET10 | 1 |"), "{md}");
}
