//! Retune against the exact scaling laws of linear elasticity.

mod common;

use common::{linear_bank, quadratic_bank, steel};
use modal_bank::{keeping_poisson, poisson_shift, retune, BankError, ModeBank, RetuneSpec};
use modal_fem::Material;
use std::f64::consts::PI;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Steel's ν with other E, ρ, α, β (ν must not change).
fn stiff_light() -> Material {
    Material {
        name: Some("test".into()),
        youngs_pa: 7.0e10,
        poisson: 0.29,
        density_kg_m3: 2700.0,
        alpha: 1.0,
        beta: 1e-7,
    }
}

fn with_material(m: Material) -> RetuneSpec {
    RetuneSpec { material: Some(m), scale: None }
}

#[test]
fn youngs_modulus_times_four_doubles_frequencies_and_keeps_shapes() {
    let bank = linear_bank(4);
    let mut m = steel();
    m.youngs_pa *= 4.0;
    let out = retune(&bank, with_material(m)).unwrap();
    for (f2, f) in out.frequencies_hz.iter().zip(&bank.frequencies_hz) {
        assert!(rel(*f2, 2.0 * f) <= 1e-15);
    }
    assert_eq!(out.shapes, bank.shapes);
    assert_eq!(out.mass, bank.mass);
    assert_eq!(out.residuals, bank.residuals);
}

#[test]
fn density_times_four_halves_frequencies_shapes_and_quadruples_mass() {
    let bank = linear_bank(4);
    let mut m = steel();
    m.density_kg_m3 *= 4.0;
    let out = retune(&bank, with_material(m)).unwrap();
    for (f2, f) in out.frequencies_hz.iter().zip(&bank.frequencies_hz) {
        assert!(rel(*f2, 0.5 * f) <= 1e-15);
    }
    for (a, b) in out.shapes.iter().zip(&bank.shapes) {
        assert_eq!(*a, 0.5 * b); // exact: power-of-two factor
    }
    assert_eq!(out.mass.mass_kg, 4.0 * bank.mass.mass_kg);
    assert_eq!(out.mass.volume_m3, bank.mass.volume_m3);
    assert_eq!(out.mass.inertia_kg_m2[1][1], 4.0 * bank.mass.inertia_kg_m2[1][1]);
}

#[test]
fn geometric_scale_follows_the_size_laws() {
    let bank = quadratic_bank(3);
    let g = 2.0;
    let out = retune(&bank, RetuneSpec { material: None, scale: Some(g) }).unwrap();
    for (f2, f) in out.frequencies_hz.iter().zip(&bank.frequencies_hz) {
        assert!(rel(*f2, f / g) <= 1e-15);
    }
    let k = g.powf(-1.5);
    for (a, b) in out.shapes.iter().zip(&bank.shapes) {
        assert!(rel(f64::from(*a), f64::from(*b) * k) <= 1e-7, "{a} vs {b}·{k}");
    }
    for (p2, p) in out.surface.positions.iter().zip(&bank.surface.positions) {
        assert_eq!(*p2, p.map(|x| x * g));
    }
    assert_eq!(out.mass.volume_m3, 8.0 * bank.mass.volume_m3);
    assert_eq!(out.mass.mass_kg, 8.0 * bank.mass.mass_kg);
    assert_eq!(out.mass.inertia_kg_m2[0][0], 32.0 * bank.mass.inertia_kg_m2[0][0]);
    assert_eq!(out.mass.center_of_mass_m, bank.mass.center_of_mass_m.map(|x| x * g));
    assert_eq!(out.surface.triangles, bank.surface.triangles);
    assert_eq!(out.surface.triangle_edge_nodes, bank.surface.triangle_edge_nodes);
}

#[test]
fn mass_normalization_is_preserved() {
    // φᵀMφ = 1 ⇒ φ² · mass is invariant under any retune (M scales like the mass).
    let bank = linear_bank(3);
    let out = retune(&bank, RetuneSpec { material: Some(stiff_light()), scale: Some(0.37) }).unwrap();
    for (a, b) in out.shapes.iter().zip(&bank.shapes) {
        let before = f64::from(*b).powi(2) * bank.mass.mass_kg;
        let after = f64::from(*a).powi(2) * out.mass.mass_kg;
        assert!(rel(after, before) <= 1e-6, "{after} vs {before}");
    }
}

#[test]
fn matches_euler_bernoulli_bar_scaling() {
    // Free-free bar, first bending: f = (4.730040745)² / (2π L²) · √(E I / (ρ A)),
    // square section of side h: I/A = h²/12.
    let bar = |e: f64, rho: f64, l: f64, h: f64| {
        let b = 4.730_040_744_862_704_f64;
        b * b / (2.0 * PI * l * l) * (e * h * h / 12.0 / rho).sqrt()
    };
    let mut bank = linear_bank(1);
    let s = steel();
    bank.frequencies_hz[0] = bar(s.youngs_pa, s.density_kg_m3, 1.0, 0.02);
    bank.recompute_damping();
    let m = stiff_light();
    let out = retune(&bank, RetuneSpec { material: Some(m.clone()), scale: Some(0.5) }).unwrap();
    let expected = bar(m.youngs_pa, m.density_kg_m3, 0.5, 0.01);
    assert!(rel(out.frequencies_hz[0], expected) <= 1e-13, "{} vs {expected}", out.frequencies_hz[0]);
}

#[test]
fn damping_comes_from_the_new_material() {
    let bank = linear_bank(4);
    let m = stiff_light();
    let out = retune(&bank, RetuneSpec { material: Some(m.clone()), scale: Some(3.0) }).unwrap();
    for i in 0..4 {
        let w = 2.0 * PI * out.frequencies_hz[i];
        assert!(rel(out.decay_rates[i], 0.5 * (m.alpha + m.beta * w * w)) <= 1e-14);
        assert!(rel(out.damping_ratios[i], 0.5 * (m.alpha / w + m.beta * w)) <= 1e-14);
    }
    assert_eq!(out.material, m);
}

#[test]
fn poisson_change_needs_a_new_solve() {
    let mut m = steel();
    m.poisson = 0.3;
    let err = retune(&linear_bank(2), with_material(m)).unwrap_err();
    assert!(matches!(err, BankError::PoissonChanged { .. }));
    assert!(err.to_string().starts_with("changing Poisson's ratio needs a new solve"), "{err}");
}

/// "This steel bank in aluminium": E and ρ move, ν stays the bank's (a
/// retune cannot change it), the preset is named `+custom` and the ν it
/// asked for is returned, for the caller's warning.
#[test]
fn a_preset_of_another_poisson_ratio_keeps_the_banks() {
    let bank = linear_bank(2);
    let aluminium = Material::preset("aluminium").unwrap();
    let (kept, asked) = keeping_poisson(&bank, aluminium.clone());
    assert_eq!(asked, Some(0.33));
    assert_eq!((kept.poisson, kept.youngs_pa, kept.density_kg_m3), (0.29, 7.0e10, 2700.0));
    assert_eq!(kept.name.as_deref(), Some("aluminium+custom"));
    let retuned = retune(&bank, with_material(kept)).unwrap();
    let ratio = retuned.frequencies_hz[0] / bank.frequencies_hz[0];
    assert!(rel(ratio, (3.5e-1_f64 / (2700.0 / 7850.0)).sqrt()) < 1e-12, "{ratio}");
    // The same ν: nothing changes, nothing is said.
    let (same, none) = keeping_poisson(&bank, steel());
    assert_eq!((same, none), (steel(), None));
}

/// The bound on what ν moves a frequency, against the wave speeds from the
/// Lamé constants `λ = Eν/((1+ν)(1−2ν))`, `μ = E/(2(1+ν))`:
/// `c_s² = μ/ρ`, `c_p² = (λ+2μ)/ρ`, and a plate's `D ∝ E/(1−ν²)`.
#[test]
fn the_poisson_shift_is_the_largest_wave_speed_change() {
    let speeds = |nu: f64| {
        let (e, rho) = (7.0e10, 2700.0);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        [(mu / rho).sqrt(), ((lambda + 2.0 * mu) / rho).sqrt(), (e / (1.0 - nu * nu)).sqrt()]
    };
    let (a, b) = (speeds(0.29), speeds(0.33));
    let want = (0..3).map(|i| (b[i] / a[i] - 1.0).abs()).fold(0.0, f64::max);
    assert!(rel(poisson_shift(0.29, 0.33), want) < 1e-12, "{} vs {want}", poisson_shift(0.29, 0.33));
    assert!((poisson_shift(0.29, 0.33) - 0.0633).abs() < 5e-4, "compression moves most");
    assert_eq!(poisson_shift(0.3, 0.3), 0.0);
}

#[test]
fn bad_scale_and_material_are_rejected() {
    let bank = linear_bank(2);
    for g in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = retune(&bank, RetuneSpec { material: None, scale: Some(g) }).unwrap_err();
        assert!(matches!(err, BankError::InvalidScale(_)), "{g}: {err}");
    }
    let mut m = steel();
    m.density_kg_m3 = 0.0;
    assert!(matches!(retune(&bank, with_material(m)), Err(BankError::InvalidMaterial(_))));
}

#[test]
fn retuned_hash_is_marked_and_spec_dependent() {
    let bank = linear_bank(2);
    let a = retune(&bank, RetuneSpec { material: None, scale: Some(2.0) }).unwrap();
    let a2 = retune(&bank, RetuneSpec { material: None, scale: Some(2.0) }).unwrap();
    let b = retune(&bank, RetuneSpec { material: None, scale: Some(3.0) }).unwrap();
    let c = retune(&bank, RetuneSpec::default()).unwrap();
    assert!(a.info.input_hash.starts_with("retuned:"));
    assert_eq!(a.info.input_hash, a2.info.input_hash);
    assert_ne!(a.info.input_hash, b.info.input_hash);
    assert_ne!(c.info.input_hash, bank.info.input_hash, "even an identity retune is marked");
    assert_eq!(c.frequencies_hz, bank.frequencies_hz);
}

#[test]
fn retune_there_and_back_and_through_a_file() {
    let bank = quadratic_bank(3);
    let there = retune(&bank, RetuneSpec { material: Some(stiff_light()), scale: Some(4.0) }).unwrap();
    let back = retune(&there, RetuneSpec { material: Some(steel()), scale: Some(0.25) }).unwrap();
    for (x, y) in back.frequencies_hz.iter().zip(&bank.frequencies_hz) {
        assert!(rel(*x, *y) <= 1e-14);
    }
    for (x, y) in back.shapes.iter().zip(&bank.shapes) {
        assert!(rel(f64::from(*x), f64::from(*y)) <= 2e-7);
    }
    assert_eq!(ModeBank::from_bytes(&there.to_bytes().unwrap()).unwrap(), there);
}
