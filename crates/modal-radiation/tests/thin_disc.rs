//! A thin rigid disc translating along its axis (broadside): at low `ka`
//! a dipole whose strength is the disc's added mass, `(8/3) ρ₀ a³` for a
//! disc of no thickness (Lamb, *Hydrodynamics* §108), plus its volume
//! `π a² t`: `|p| = ρ₀ c k² ((8/3) a³ + π a² t) U cos θ / (4π r)` far away.
//! It probes what a thin wall does to the solver (the two faces a wall
//! thickness apart, panels wider than that).

use faer::c64;
use modal_radiation::refine::refine_near_creases;
use modal_radiation::{solve, Air, BoundaryMesh, Formulation};

/// A closed disc of radius `a` and thickness `t` about the origin: `rings`
/// rings of `segments = 6·rings` nodes on each face and one band of quads
/// around the rim ([`modal_mesh::disc_surface`]).
fn disc(a: f64, t: f64, rings: usize, segments: usize) -> BoundaryMesh {
    assert_eq!(segments, 6 * rings);
    let (v, tris) = modal_mesh::disc_surface(a, t, rings);
    BoundaryMesh::new(v, &tris).unwrap()
}

#[test]
fn a_thin_rigid_disc_translating_broadside_radiates_its_added_mass_dipole() {
    // Measured (level error on the axis and at θ = 0.6, the same to 0.03 dB):
    // 1 536 panels 1.14 dB, 3 072 panels 0.90 dB, 6 144 panels 0.55 dB: panels
    // 2.5–5 times wider than the wall cost about half a dB, falling as they shrink.
    let (a, t, f) = (0.1, 0.002, 100.0);
    let errors = |rings: usize, segments: usize| errors_with(disc(a, t, rings, segments), a, t, f);
    let (coarse, fine) = (errors(8, 48), errors(16, 96));
    for (c, f) in coarse.iter().zip(&fine) {
        assert!(f.abs() < 0.7, "6 144 panels: {f:.3} dB");
        assert!(f.abs() < 0.7 * c.abs(), "no closer on a finer mesh: {c:.3} then {f:.3} dB");
    }
}

/// Level errors [dB] of the translating disc `mesh` (radius `a`, thickness
/// `t`) at `f` [Hz] against the closed form, on the axis and at θ = 0.6.
fn errors_with(mesh: BoundaryMesh, a: f64, t: f64, f: f64) -> Vec<f64> {
    let air = Air::default();
    let k = 2.0 * std::f64::consts::PI * f / air.sound_speed_m_s;
    let strength = 8.0 / 3.0 * a * a * a + std::f64::consts::PI * a * a * t;
    let v: Vec<c64> = mesh.panels.iter().map(|p| c64::new(p.normal[2], 0.0)).collect();
    let s = solve(&mesh, air, f, &[v], Formulation::BurtonMiller).unwrap().remove(0);
    [0.0f64, 0.6]
        .iter()
        .map(|&theta| {
            let x = [theta.sin(), 0.0, theta.cos()];
            let want = air.density_kg_m3 * air.sound_speed_m_s * k * k * strength * theta.cos()
                / (4.0 * std::f64::consts::PI);
            20.0 * (s.pressure_at(&mesh, x).unwrap().norm() / want).log10()
        })
        .collect()
}

/// Splitting the panels at the rim (hanging midpoints beside unsplit
/// panels) must leave this field's level where it was: a translating disc's
/// error is its faces' (panels wider than the wall), not its rim's.
/// Measured: 1.143 dB with 1 536 panels, then 1.130 / 1.138 / 1.142 dB
/// after one, two, three rounds (2 400 / 4 704 / 9 312 panels), where a
/// uniform split to 6 144 panels gives 0.55 dB. The elastic disc's
/// rim-localized modes are another matter (docs/radiation.md, "Thin walls").
#[test]
fn refining_a_translating_discs_rim_leaves_its_dipole_unchanged() {
    let (a, t, f) = (0.1, 0.002, 100.0);
    let mesh = disc(a, t, 8, 48);
    let panels: Vec<usize> = (0..mesh.len()).collect();
    let (refined, parents) = refine_near_creases(&mesh, &panels, 1, 25.0, |&p| [p; 4]).unwrap();
    assert!(refined.len() > mesh.len() && refined.len() < 2 * mesh.len(), "{} panels", refined.len());
    assert!(parents.iter().all(|&p| p < mesh.len()));
    let (before, after) = (errors_with(mesh, a, t, f), errors_with(refined, a, t, f));
    for (b, r) in before.iter().zip(&after) {
        assert!((b - r).abs() < 0.05, "{b:.3} dB before, {r:.3} dB after one round");
    }
}
