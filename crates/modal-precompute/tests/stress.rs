//! Numerical stress suite of the whole offline pipeline (issue 7, point 3):
//! Poisson's ratio 0 … 0.49, density 100 … 20 000 kg/m³, jittered and sliver
//! elements, exactly and nearly repeated eigenvalues. Every case must meet its
//! accuracy bound, or be rejected with a clear error — never a silent wrong
//! answer. (E 1e6–1e12 Pa, sizes 1 mm–10 m, the 200:1 plate and disjoint parts
//! are in crates/modal-eigen/tests/physics.rs; folded meshes in modal-mesh.)
//!
//! References: /work/shared/reference/analytic.md (Lamb's sphere, the bar).
//! The Lamb S2 roots for ν = 0, 0.45 and 0.49, not in that table, were solved
//! from its spheroidal frequency equation with scipy (`spherical_jn` + `brentq`;
//! the same script reproduces the table's 2.6327 / 2.6462 / 2.6519 for ν = 0.2 /
//! 0.3 / 0.35).

use std::f64::consts::PI;

use modal_bank::ModeBank;
use modal_fem::Material;
use modal_mesh::generate::{box_mesh, generate, sphere, Shape};
use modal_mesh::TetMesh;
use modal_precompute::{precompute, MeshSource, Outcome, Request, TARGET_RESIDUAL};

const E: f64 = 200e9;
const RHO: f64 = 7850.0;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Runs the pipeline without a cache and checks the invariants every bank
/// must satisfy: residuals at the target, a complete inertia count.
fn run(mesh: TetMesh, material: Material, max_modes: usize, max_freq_hz: f64) -> Outcome {
    let outcome = run_unchecked(mesh, material, max_modes, max_freq_hz);
    assert_invariants(&outcome.bank);
    outcome
}

fn run_unchecked(mesh: TetMesh, material: Material, max_modes: usize, max_freq_hz: f64) -> Outcome {
    let source = MeshSource::Memory { mesh, identity: "stress".into() };
    let request = Request { max_modes, max_freq_hz, ..Request::new(source, material) };
    precompute(&request, None, false, &mut |_| {}).expect("pipeline")
}

fn assert_invariants(bank: &ModeBank) {
    assert!(bank.residuals.iter().all(|&r| r <= TARGET_RESIDUAL), "residuals {:?}", bank.residuals);
    assert_eq!(bank.info.inertia_expected, bank.info.inertia_found, "inertia check");
    assert!(bank.frequencies_hz.windows(2).all(|w| w[0] <= w[1]), "ascending");
}

fn material(nu: f64, rho: f64) -> Material {
    Material::custom(E, nu, rho, 0.0, 0.0).unwrap()
}

/// Lamb's sphere: frequency of root η for radius a, f = η c_T / (2π a).
fn lamb_hz(eta: f64, nu: f64, radius: f64) -> f64 {
    let shear_speed = (E / (2.0 * (1.0 + nu)) / RHO).sqrt();
    eta * shear_speed / (2.0 * PI * radius)
}

#[test]
fn poisson_ratio_0_to_0_49_sphere_quintuplets_match_lamb() {
    // (ν, S2 root η); T2 is η = 2.5011 for every ν.
    let cases = [(0.0, 2.5920), (0.2, 2.6327), (0.35, 2.6519), (0.45, 2.6615), (0.49, 2.6648)];
    let radius = 0.05;
    let coarse = sphere(radius, 0.02, 2).unwrap(); // curved P2 boundary
    for (nu, s2_eta) in cases {
        let bank = run(coarse.clone(), material(nu, RHO), 10, 80_000.0).bank;
        let f = &bank.frequencies_hz;
        assert_eq!(f.len(), 10, "ν {nu}: both quintuplets: {f:?}");
        let (t2, s2) = (lamb_hz(2.5011, nu, radius), lamb_hz(s2_eta, nu, radius));
        // Curved P2 tets at h = 2 cm are within 0.41 % for ν ≤ 0.45 and
        // 0.71 % at ν = 0.49 (measured): the mild volumetric locking of
        // displacement elements near incompressibility shows but stays small.
        for (i, got) in f.iter().enumerate() {
            let want = if i < 5 { t2 } else { s2 };
            assert!(rel(*got, want) < 0.01, "ν {nu}, mode {}: {got:.1} Hz vs Lamb {want:.1} Hz", i + 1);
        }
    }
}

#[test]
fn density_100_to_20000_scales_frequencies_and_mass_exactly() {
    let bar = box_mesh([0.3, 0.02, 0.01], [15, 2, 1]);
    let base = run(bar.clone(), material(0.3, RHO), 8, 1e6).bank;
    for rho in [100.0, 20_000.0] {
        let bank = run(bar.clone(), material(0.3, rho), 8, 1e6).bank;
        // K is independent of ρ and M ∝ ρ, so f ∝ 1/√ρ exactly and mass ∝ ρ.
        let factor = (RHO / rho).sqrt();
        for (got, want) in bank.frequencies_hz.iter().zip(&base.frequencies_hz) {
            assert!(rel(*got, want * factor) < 1e-8, "ρ {rho}: {got} vs {}", want * factor);
        }
        assert!(rel(bank.mass.mass_kg, base.mass.mass_kg * rho / RHO) < 1e-12);
    }
}

/// The 3D-converged free-free bar (analytic.md §1), first 10 of its 12 modes.
const BAR_TABLE_HZ: &[f64] = modal_study::reference::BAR_FREE_HZ.split_at(10).0;

/// Largest relative error against [`BAR_TABLE_HZ`], matching each reference
/// value to its nearest computed frequency (modes 4 and 5 are 0.2 % apart).
fn bar_table_error(f: &[f64]) -> f64 {
    BAR_TABLE_HZ
        .iter()
        .map(|want| f.iter().map(|got| rel(*got, *want)).fold(f64::INFINITY, f64::min))
        .fold(0.0, f64::max)
}

/// Deterministic pseudo-random numbers in [−1, 1) (SplitMix64).
fn jitter_source(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

#[test]
fn jittered_interior_nodes_keep_the_bar_accurate() {
    let (size, cells) = ([0.3, 0.02, 0.01], [40, 4, 2]);
    let mut mesh = box_mesh(size, cells);
    let spacing = [size[0] / 40.0, size[1] / 4.0, size[2] / 2.0];
    let mut random = jitter_source(7);
    // Interior nodes move by up to 25 % of the local spacing in each
    // direction: distorted, but no element folds.
    for p in &mut mesh.nodes {
        let interior = (0..3).all(|c| p[c] > 1e-9 && p[c] < size[c] - 1e-9);
        if interior {
            for c in 0..3 {
                p[c] += 0.25 * spacing[c] * random();
            }
        }
    }
    let bank = run(mesh, material(0.3, RHO), 10, 20_000.0).bank;
    let error = bar_table_error(&bank.frequencies_hz);
    assert!(error < 0.01, "jittered bar: max error {error:.4} ({:?})", bank.frequencies_hz);
}

#[test]
fn sliver_elements_are_reported_and_stay_accurate() {
    let (size, cells) = ([0.3, 0.02, 0.01], [40, 4, 2]);
    let mut mesh = box_mesh(size, cells);
    // Move the bar's centre node most of the way along its x edge towards
    // the next node: the tets around that edge flatten into slivers
    // (dihedral angles below 5°) without folding.
    let target = [size[0] / 2.0, size[1] / 2.0, size[2] / 2.0];
    let node = mesh
        .nodes
        .iter()
        .position(|p| (0..3).all(|c| (p[c] - target[c]).abs() < 1e-9))
        .expect("a node at the bar's centre");
    mesh.nodes[node][0] += 0.97 * size[0] / 40.0;
    let outcome = run(mesh, material(0.3, RHO), 10, 20_000.0);
    assert!(
        outcome.warnings.iter().any(|w| w.contains("dihedral angle below")),
        "sliver warning expected: {:?}",
        outcome.warnings
    );
    let error = bar_table_error(&outcome.bank.frequencies_hz);
    assert!(error < 0.01, "sliver bar: max error {error:.4}");
}

/// Groups of frequencies whose relative spread is below `tol`.
fn clusters(f: &[f64], tol: f64) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    for &x in f {
        match out.last_mut() {
            Some(group) if rel(x, group[0]) < tol => group.push(x),
            _ => out.push(vec![x]),
        }
    }
    out
}

#[test]
fn square_bar_bending_pairs_are_found_twice_exact_and_near_repeated() {
    // Square section: bending in y and z are the same mode rotated by 90°,
    // so each bending frequency is an exact double eigenvalue of the
    // continuum; the structured mesh splits it by round-off only if its
    // pattern is symmetric, by a little more otherwise. A 0.5 % thicker
    // section splits each pair by ≈ 0.5 %: nearly repeated. Both must come
    // out as pairs, with all invariants (residual, inertia) intact.
    for (depth, max_split) in [(0.02, 2e-3), (0.0201, 8e-3)] {
        let mesh = box_mesh([0.3, 0.02, depth], [30, 3, 3]);
        let bank = run(mesh, material(0.3, RHO), 6, 20_000.0).bank;
        let f = &bank.frequencies_hz;
        let pairs = clusters(&f[..4], 0.01);
        assert_eq!(pairs.iter().map(Vec::len).collect::<Vec<_>>(), [2, 2], "depth {depth}: {f:?}");
        for pair in &pairs {
            let split = rel(pair[1], pair[0]);
            assert!(split < max_split, "depth {depth}: pair {pair:?} split {split:.2e}");
        }
        // Euler–Bernoulli free-free first bending, √(E I/(ρ A)) with I = b h³/12:
        // shear and rotary inertia lower it by ≈ (β h / L)² ≈ 1.3 %.
        let beam = 4.730041f64.powi(2) / (2.0 * PI * 0.09) * (E * 0.02 * 0.02 / 12.0 / RHO).sqrt();
        assert!(rel(pairs[0][0], beam) < 0.03, "depth {depth}: {} vs beam {beam}", pairs[0][0]);
    }
}

#[test]
fn thin_plate_residuals_meet_the_target_or_say_why_not() {
    // A 200:1 plate: λ_max/λ₁ is so large that double precision may not
    // certify 1e-8 for the lowest modes. That must never pass silently.
    let plate = box_mesh([0.2, 0.2, 0.001], [16, 16, 1]);
    let outcome = run_unchecked(plate, material(0.3, RHO), 8, 20_000.0);
    let bank = &outcome.bank;
    assert_eq!(bank.frequencies_hz.len(), 8);
    assert_eq!(bank.info.inertia_expected, bank.info.inertia_found);
    let worst = bank.residuals.iter().copied().fold(0.0, f64::max);
    let warned = outcome.warnings.iter().any(|w| w.contains("limit of double precision"));
    assert_eq!(warned, worst > TARGET_RESIDUAL, "worst residual {worst:e}, warnings {:?}", outcome.warnings);
    assert!(worst < 1e-5, "even at the floor the residual stays small: {worst:e}");
}

#[test]
fn default_element_size_keeps_bar_and_sphere_within_one_percent() {
    // The default chosen by the accuracy study (Shape::default_element_size):
    // ≤ 0.72 % measured there on the first 12–20 modes; here the bar's first
    // 10 table modes and the sphere's T2/S2 quintuplets, through the pipeline.
    let bar = Shape::Box { size: [0.3, 0.02, 0.01] };
    let mesh = generate(&bar, bar.default_element_size(2), 2).unwrap();
    let f = run(mesh, material(0.3, RHO), 10, 20_000.0).bank.frequencies_hz;
    let error = bar_table_error(&f);
    assert!(error < 0.01, "bar at the default size: max error {error:.4}");

    let ball = Shape::Sphere { radius: 0.05 };
    let mesh = generate(&ball, ball.default_element_size(2), 2).unwrap();
    let f = run(mesh, material(0.3, RHO), 10, 80_000.0).bank.frequencies_hz;
    let (t2, s2) = (lamb_hz(2.5011, 0.3, 0.05), lamb_hz(2.6462, 0.3, 0.05));
    for (i, got) in f.iter().enumerate() {
        let want = if i < 5 { t2 } else { s2 };
        assert!(rel(*got, want) < 0.01, "sphere at the default size, mode {}: {got:.1} vs {want:.1}", i + 1);
    }
}

/// Heavy variant (`cargo test -p modal-precompute --release --test stress -- --ignored`):
/// a finer curved sphere across ν, with a bound four times tighter.
#[test]
#[ignore = "heavy: ≈ 22k-DOF solves; run by hand in release"]
fn fine_sphere_poisson_sweep_within_a_quarter_percent() {
    let radius = 0.05;
    let fine = sphere(radius, 0.014, 2).unwrap();
    for (nu, s2_eta) in [(0.0, 2.5920), (0.3, 2.6462), (0.49, 2.6648)] {
        let f = run(fine.clone(), material(nu, RHO), 10, 80_000.0).bank.frequencies_hz;
        let (t2, s2) = (lamb_hz(2.5011, nu, radius), lamb_hz(s2_eta, nu, radius));
        for (i, got) in f.iter().enumerate() {
            let want = if i < 5 { t2 } else { s2 };
            eprintln!("nu {nu} mode {} err {:.2e}", i + 1, rel(*got, want));
            assert!(rel(*got, want) < 0.0025, "ν {nu}, mode {}: {got:.1} Hz vs Lamb {want:.1} Hz", i + 1);
        }
    }
}
