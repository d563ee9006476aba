//! The per-mode `error_estimate_pct` of `SolveInfo`: additive in the format
//! (older banks load, banks without an estimate keep their bytes), validated,
//! carried through retuning.

mod common;

use common::linear_bank;
use modal_bank::{retune, ModeBank, RetuneSpec, SolveInfo};

#[test]
fn estimates_round_trip_including_unmatched_modes() {
    let mut bank = linear_bank(4);
    bank.info.error_estimate_pct = vec![Some(0.25), None, Some(1.5e-3), Some(7.0)];
    bank.info.error_estimate_method = "two levels, test".into();
    let back = ModeBank::from_bytes(&bank.to_bytes().unwrap()).unwrap();
    assert_eq!(back.info.error_estimate_pct, bank.info.error_estimate_pct);
    assert_eq!(back.info.error_estimate_method, "two levels, test");
    assert_eq!(back, bank);
}

#[test]
fn banks_without_estimate_keep_their_solve_info_json() {
    // Older readers and older banks: no key at all when there is no estimate.
    let bank = linear_bank(3);
    assert!(bank.info.error_estimate_pct.is_empty());
    let json = serde_json::to_string(&bank.info).unwrap();
    assert!(!json.contains("error_estimate"), "{json}");
    // A solve_info written before the field existed reads as "no estimate".
    let old: SolveInfo = serde_json::from_str(r#"{"order":2,"dofs":30,"input_hash":"x"}"#).unwrap();
    assert!(old.error_estimate_pct.is_empty());
    assert!(old.error_estimate_method.is_empty());
    let back = ModeBank::from_bytes(&bank.to_bytes().unwrap()).unwrap();
    assert!(back.info.error_estimate_pct.is_empty());
}

#[test]
fn wrong_length_and_bad_values_are_rejected() {
    let mut bank = linear_bank(3);
    bank.info.error_estimate_pct = vec![Some(1.0); 2];
    let err = bank.validate().unwrap_err().to_string();
    assert!(err.contains("error_estimate_pct has 2 entries"), "{err}");
    for bad in [-0.5, f64::NAN, f64::INFINITY] {
        bank.info.error_estimate_pct = vec![Some(1.0), Some(bad), None];
        let err = bank.validate().unwrap_err().to_string();
        assert!(err.contains("error_estimate_pct[1]"), "{bad}: {err}");
        assert!(bank.to_bytes().is_err(), "saving must refuse {bad}");
    }
}

#[test]
fn relative_estimates_survive_retuning() {
    let mut bank = linear_bank(3);
    bank.info.error_estimate_pct = vec![Some(0.5), Some(0.75), None];
    let spec = RetuneSpec { material: None, scale: Some(2.0) };
    let new = retune(&bank, spec).unwrap();
    assert_eq!(new.info.error_estimate_pct, bank.info.error_estimate_pct);
    assert!((new.frequencies_hz[0] - bank.frequencies_hz[0] / 2.0).abs() < 1e-9 * bank.frequencies_hz[0]);
}
