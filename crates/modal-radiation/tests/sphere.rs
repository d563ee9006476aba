//! Closed forms on the sphere: a field `v_n = Y_l^m` on a sphere of
//! radius `a` radiates `p(r) = iρ₀c h_l(kr)/h_l'(ka) Y_l^m` (time
//! convention `e^{−iωt}`), so the pulsating (l = 0) and the oscillating
//! rigid sphere (l = 1, `v_n = U cos θ`) and every spheroidal pattern have
//! exact answers. Plus the fictitious frequency `ka = π`, multipole fits,
//! mirror symmetry, reciprocity and thread-count independence.

use faer::c64;
use modal_radiation::bem::interior_wavenumber_bound;
use modal_radiation::special::{
    lm_index, spherical_hankel, spherical_hankel_derivative, spherical_harmonics,
};
use modal_radiation::{multipole, solve, Air, BoundaryMesh, Formulation, SurfaceField};

const A: f64 = 0.1;

fn sphere(subdiv: u32) -> BoundaryMesh {
    let (v, t) = modal_mesh::icosphere(subdiv);
    BoundaryMesh::new(v.iter().map(|p| p.map(|x| A * x)).collect(), &t).unwrap()
}

/// Frequency [Hz] giving `ka` on the test sphere.
fn freq(ka: f64) -> f64 {
    ka / A * Air::default().sound_speed_m_s / (2.0 * std::f64::consts::PI)
}

/// Exact pressure of `v_n = Σ c_lm Y_l^m` (degree `l` only) at `x`.
fn exact(l: usize, coeffs: &[(i64, c64)], ka: f64, x: [f64; 3]) -> c64 {
    let air = Air::default();
    let k = ka / A;
    let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    let h = spherical_hankel(l, k * r)[l];
    let hp = spherical_hankel_derivative(l, ka)[l];
    let y = spherical_harmonics(l, x);
    let s: c64 = coeffs.iter().map(|&(m, c)| c * y[lm_index(l, m)]).sum();
    c64::new(0.0, air.impedance()) * h / hp * s
}

/// `v_n` per panel from a function of the unit normal direction.
fn field(mesh: &BoundaryMesh, f: impl Fn([f64; 3]) -> c64) -> Vec<c64> {
    mesh.panels.iter().map(|p| f(p.centroid)).collect()
}

fn db(a: c64, b: c64) -> f64 {
    20.0 * (a.norm() / b.norm()).log10()
}

/// Test points around the sphere at radius `r`.
fn ring(r: f64) -> Vec<[f64; 3]> {
    let mut pts = Vec::new();
    for i in 0..7 {
        let th = 0.2 + 0.4 * i as f64;
        let ph = 0.7 * i as f64;
        pts.push([r * th.sin() * ph.cos(), r * th.sin() * ph.sin(), r * th.cos()]);
    }
    pts
}

fn solve_one(mesh: &BoundaryMesh, ka: f64, v: Vec<c64>, f: Formulation) -> SurfaceField {
    solve(mesh, Air::default(), freq(ka), &[v], f).unwrap().remove(0)
}

/// Largest level error [dB] and phase error [rad] over the ring at `r`.
fn errors(mesh: &BoundaryMesh, s: &SurfaceField, r: f64, want: impl Fn([f64; 3]) -> c64) -> (f64, f64) {
    let (mut level, mut phase) = (0.0f64, 0.0f64);
    for x in ring(r) {
        let got = s.pressure_at(mesh, x).unwrap();
        let w = want(x);
        level = level.max(db(got, w).abs());
        phase = phase.max((got / w).arg().abs());
    }
    (level, phase)
}

#[test]
fn pulsating_sphere_matches_the_closed_form() {
    let mesh = sphere(3);
    let y00 = 1.0 / (4.0 * std::f64::consts::PI).sqrt();
    for ka in [0.2, 1.0, 3.0] {
        let s = solve_one(&mesh, ka, vec![c64::new(1.0, 0.0); mesh.len()], Formulation::BurtonMiller);
        let (level, phase) =
            errors(&mesh, &s, 2.5 * A, |x| exact(0, &[(0, c64::new(1.0 / y00, 0.0))], ka, x));
        assert!(level < 0.2 && phase < 0.02, "ka={ka}: {level} dB, {phase} rad");
        // Power: ρ₀c·4πa²·(ka)²/(1 + (ka)²)/2 for unit velocity, from the far field.
        let air = Air::default();
        let want = 0.5 * air.impedance() * 4.0 * std::f64::consts::PI * A * A * ka * ka / (1.0 + ka * ka);
        let mp =
            multipole::fit(&mesh, std::slice::from_ref(&s), [0.0; 3], multipole::DEFAULT_TOLERANCE).remove(0);
        let got = mp.radiated_power(air);
        assert!((got / want - 1.0).abs() < 0.05, "ka={ka}: power {got} vs {want}");
        assert_eq!(mp.order, 0, "ka={ka}: a monopole");
    }
}

#[test]
fn oscillating_rigid_sphere_matches_the_closed_form() {
    // Rigid translation U ẑ: v_n = U n_z = U cos θ = U √(4π/3) Y_1^0.
    let mesh = sphere(3);
    let c = (4.0 * std::f64::consts::PI / 3.0).sqrt();
    for ka in [0.1, 1.0, 4.0] {
        let v = mesh.panels.iter().map(|p| c64::new(p.normal[2], 0.0)).collect();
        let s = solve_one(&mesh, ka, v, Formulation::BurtonMiller);
        let (level, phase) = errors(&mesh, &s, 2.5 * A, |x| exact(1, &[(0, c64::new(c, 0.0))], ka, x));
        assert!(level < 0.15 && phase < 0.03, "ka={ka}: {level} dB, {phase} rad");
    }
}

#[test]
fn one_unknown_per_panel_above_the_dense_limit_is_solved_compressed() {
    // 20 480 panels, more than the dense solve takes (the fallback of every
    // default solve): what `--full-resolution` asks on a thin wall's split.
    let mesh = sphere(5);
    assert!(mesh.len() > modal_radiation::bem::MAX_DENSE_UNKNOWNS);
    let c = (4.0 * std::f64::consts::PI / 3.0).sqrt();
    let ka = 1.0;
    let v = mesh.panels.iter().map(|p| c64::new(p.normal[2], 0.0)).collect();
    let s = solve_one(&mesh, ka, v, Formulation::BurtonMiller);
    let (level, phase) = errors(&mesh, &s, 2.5 * A, |x| exact(1, &[(0, c64::new(c, 0.0))], ka, x));
    assert!(level < 0.05 && phase < 0.01, "{level} dB, {phase} rad");
}

/// The default equation ([`Formulation::Automatic`]) is the conventional
/// one below 0.8 of the lowest interior resonance's Faber–Krahn bound
/// (`ka = π` for a sphere, slightly above on its inscribed panels) and
/// Burton–Miller above: the same bits as each.
#[test]
fn the_default_equation_is_conventional_below_the_interior_resonances_and_burton_miller_near_them() {
    let mesh = sphere(2);
    let bound_ka = interior_wavenumber_bound(&mesh) * A;
    assert!(bound_ka > std::f64::consts::PI && bound_ka < 1.02 * std::f64::consts::PI, "{bound_ka}");
    let v: Vec<c64> = mesh.panels.iter().map(|p| c64::new(p.normal[2] + 0.3, 0.0)).collect();
    for (ka, expected) in [
        (1.0, Formulation::Conventional),
        (0.79 * bound_ka, Formulation::Conventional),
        (0.81 * bound_ka, Formulation::BurtonMiller),
        (std::f64::consts::PI, Formulation::BurtonMiller),
    ] {
        assert_eq!(Formulation::Automatic.resolved(ka / A, &mesh), expected, "ka = {ka}");
        let auto = solve_one(&mesh, ka, v.clone(), Formulation::Automatic);
        assert_eq!(auto.pressure, solve_one(&mesh, ka, v.clone(), expected).pressure, "ka = {ka}");
    }
}

/// Why the conventional equation below the resonances: on constant panels
/// Burton–Miller's hypersingular term leaves a residue that does not fall
/// with the panels (docs/radiation.md), so its far field converges like
/// the panels' size, the conventional equation's like their area. The
/// oscillating sphere at ka = 1, complex RMS error over a ring at 2.5a,
/// 1 280 → 5 120 panels (measured: 1.0 → 0.57 % against 0.62 → 0.15 %).
#[test]
fn below_the_resonances_the_conventional_equation_converges_faster() {
    let c = (4.0 * std::f64::consts::PI / 3.0).sqrt();
    let rms = |subdiv: u32, form: Formulation| {
        let mesh = sphere(subdiv);
        let v = mesh.panels.iter().map(|p| c64::new(p.normal[2], 0.0)).collect();
        let s = solve_one(&mesh, 1.0, v, form);
        let (mut e, mut w2) = (0.0, 0.0);
        for x in ring(2.5 * A) {
            let want = exact(1, &[(0, c64::new(c, 0.0))], 1.0, x);
            e += (s.pressure_at(&mesh, x).unwrap() - want).norm_sqr();
            w2 += want.norm_sqr();
        }
        (e / w2).sqrt()
    };
    let (bm, auto) =
        ([3, 4].map(|d| rms(d, Formulation::BurtonMiller)), [3, 4].map(|d| rms(d, Formulation::Automatic)));
    eprintln!("RMS error, 1 280 → 5 120 panels: Burton–Miller {bm:?}, default {auto:?}");
    assert!(bm[0] / bm[1] < 2.5, "Burton–Miller {bm:?}");
    assert!(auto[0] / auto[1] > 3.0 && auto[1] < 0.5 * bm[1], "default {auto:?}, Burton–Miller {bm:?}");
}

#[test]
fn fictitious_frequency_ka_pi_is_solved_by_burton_miller_and_not_by_the_cbie() {
    let mesh = sphere(3);
    let y00 = 1.0 / (4.0 * std::f64::consts::PI).sqrt();
    let want = |x: [f64; 3]| exact(0, &[(0, c64::new(1.0 / y00, 0.0))], std::f64::consts::PI, x);
    let v = vec![c64::new(1.0, 0.0); mesh.len()];
    let bm = solve_one(&mesh, std::f64::consts::PI, v.clone(), Formulation::BurtonMiller);
    let (level, phase) = errors(&mesh, &bm, 2.5 * A, want);
    assert!(level < 0.25 && phase < 0.02, "Burton–Miller: {level} dB, {phase} rad");
    // The conventional equation is (nearly) singular here: same mesh, far
    // worse (measured 0.64 dB with far panels by centroid, 1.1 dB with the
    // 7-point rule everywhere: the size of the error depends on how close to
    // singular the discrete system lands; it is < 0.1 dB at ka = 3).
    let cbie = solve_one(&mesh, std::f64::consts::PI, v, Formulation::Conventional);
    let (bad_level, _) = errors(&mesh, &cbie, 2.5 * A, want);
    eprintln!("ka = π: Burton–Miller {level:.3} dB, CBIE {bad_level:.3} dB");
    assert!(
        bad_level > 0.5 && bad_level > 2.5 * level,
        "CBIE at its fictitious frequency: only {bad_level} dB off (Burton–Miller {level} dB)"
    );
}

#[test]
fn spheroidal_patterns_radiate_as_one_multipole_within_half_a_db() {
    // Real combinations of degree 2 and 3 harmonics, with directivity.
    let mesh = sphere(3);
    let cases: [(usize, Vec<(i64, c64)>); 3] = [
        (2, vec![(0, c64::new(1.0, 0.0))]),
        (2, vec![(2, c64::new(0.5, 0.0)), (-2, c64::new(0.5, 0.0))]),
        (
            3,
            vec![
                (1, c64::new(0.0, 0.7)),
                (-1, c64::new(0.0, 0.7)),
                (3, c64::new(0.3, 0.0)),
                (-3, c64::new(-0.3, 0.0)),
            ],
        ),
    ];
    for (l, coeffs) in &cases {
        let vn = |x: [f64; 3]| {
            let y = spherical_harmonics(*l, x);
            coeffs.iter().map(|&(m, c)| c * y[lm_index(*l, m)]).sum::<c64>()
        };
        for ka in [0.3, 2.0] {
            let s = solve_one(&mesh, ka, field(&mesh, vn), Formulation::BurtonMiller);
            let mut worst = 0.0f64;
            for x in ring(2.0 * A) {
                let w = exact(*l, coeffs, ka, x);
                if w.norm() > 1e-3 * s.pressure.iter().map(|p| p.norm()).fold(0.0, f64::max) {
                    worst = worst.max(db(s.pressure_at(&mesh, x).unwrap(), w).abs());
                }
            }
            assert!(worst < 0.5, "l={l} ka={ka}: {worst} dB");
            // The multipole fit finds degree l and reproduces the solution.
            let mp = multipole::fit(&mesh, std::slice::from_ref(&s), [0.0; 3], multipole::DEFAULT_TOLERANCE)
                .remove(0);
            let e = mp.degree_energies();
            let total: f64 = e.iter().sum();
            assert!(e[*l] > 0.99 * total, "l={l} ka={ka}: degree energies {e:?}");
            for x in ring(3.0 * A) {
                let (a, b) = (mp.pressure_at(x), s.pressure_at(&mesh, x).unwrap());
                assert!((a - b).norm() < 0.02 * b.norm().max(1e-3), "multipole {a} vs BEM {b}");
            }
            // P = ρ₀c Σ|c_lm|² / (2k²|h_l'(ka)|²).
            let k = ka / A;
            let hp = spherical_hankel_derivative(*l, ka)[*l];
            let c2: f64 = coeffs.iter().map(|(_, c)| c.norm_sqr()).sum();
            let want = Air::default().impedance() * c2 / (2.0 * k * k * hp.norm_sqr());
            let pm = mp.radiated_power(Air::default());
            assert!((pm / want - 1.0).abs() < 0.08, "l={l} ka={ka}: power {pm} vs {want}");
        }
    }
}

/// An ellipsoid (semi-axes 1.5a, a, 0.7a) from the icosphere: mirror
/// symmetric in each coordinate plane.
fn ellipsoid() -> BoundaryMesh {
    let (v, t) = modal_mesh::icosphere(3);
    BoundaryMesh::new(v.iter().map(|p| [1.5 * A * p[0], A * p[1], 0.7 * A * p[2]]).collect(), &t).unwrap()
}

#[test]
fn mirror_symmetric_fields_give_mirror_symmetric_pressure() {
    let mesh = ellipsoid();
    // v_n even in x, odd in z.
    let v = field(&mesh, |c| c64::new(c[2] * (1.0 + 20.0 * c[0] * c[0]), 0.3 * c[2]));
    let s = solve_one(&mesh, 1.5, v, Formulation::BurtonMiller);
    let (x, mx, mz) = ([0.2, 0.13, 0.17], [-0.2, 0.13, 0.17], [0.2, 0.13, -0.17]);
    let [p, px, pz] = [x, mx, mz].map(|q| s.pressure_at(&mesh, q).unwrap());
    // Symmetric to the solver's error ≈ cond·tol: the block-Jacobi leaves are not mirror-symmetric.
    let tol = 10.0 * modal_radiation::gmres::TOLERANCE;
    assert!((p - px).norm() < tol * p.norm(), "{p} vs {px}");
    assert!((p + pz).norm() < tol * p.norm(), "{p} vs {pz}");
}

#[test]
fn reciprocity_with_a_point_source_scattered_by_the_rigid_body() {
    // p(x0) = −iωρ₀ ∫ u(y; x0) v_n(y) dS, u the total field of a unit point
    // source G(·, x0) scattered by the rigid body: a second, different solve.
    let mesh = ellipsoid();
    let air = Air::default();
    let ka = 1.2;
    let f = freq(ka);
    let k = ka / A;
    let omega = 2.0 * std::f64::consts::PI * f;
    let x0 = [0.25, -0.1, 0.12];
    let v = field(&mesh, |c| c64::new(1.0 + 8.0 * c[0], 5.0 * c[1] * c[2] / A));
    let radiated =
        solve(&mesh, air, f, std::slice::from_ref(&v), Formulation::BurtonMiller).unwrap().remove(0);
    let direct = radiated.pressure_at(&mesh, x0).unwrap();
    // Incident G(y, x0) and its normal derivative at the panel centroids.
    let inc = |y: [f64; 3], n: [f64; 3]| {
        let d = [y[0] - x0[0], y[1] - x0[1], y[2] - x0[2]];
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let g = c64::new((k * r).cos(), (k * r).sin()) / (4.0 * std::f64::consts::PI * r);
        let dgdr = g * c64::new(-1.0 / r, k);
        (g, dgdr * ((d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / r))
    };
    // Scattered field: ∂p_s/∂n = −∂G/∂n, i.e. v_s = −∂G/∂n / (iωρ₀).
    let iwr = c64::new(0.0, omega * air.density_kg_m3);
    let vs: Vec<c64> = mesh.panels.iter().map(|p| -inc(p.centroid, p.normal).1 / iwr).collect();
    let scattered = solve(&mesh, air, f, &[vs], Formulation::BurtonMiller).unwrap().remove(0);
    let mut via = c64::new(0.0, 0.0);
    for (j, p) in mesh.panels.iter().enumerate() {
        let u = scattered.pressure[j] + inc(p.centroid, p.normal).0;
        via += u * v[j] * p.area;
    }
    via *= -iwr;
    assert!((via - direct).norm() < 0.02 * direct.norm(), "reciprocity {via} vs direct {direct}");
}

#[test]
fn thread_count_does_not_change_a_single_bit() {
    let mesh = sphere(2);
    let v = field(&mesh, |c| c64::new(c[0] + 0.2, c[1] * c[2]));
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let s = solve_one(&mesh, 2.0, v.clone(), Formulation::BurtonMiller);
            let mp = multipole::fit(&mesh, std::slice::from_ref(&s), [0.0; 3], 1e-3).remove(0);
            (s.pressure, mp.coefficients)
        })
    };
    let (a, b) = (run(1), run(2));
    let bits = |v: &[c64]| v.iter().flat_map(|z| [z.re.to_bits(), z.im.to_bits()]).collect::<Vec<_>>();
    assert_eq!(bits(&a.0), bits(&b.0));
    assert_eq!(bits(&a.1), bits(&b.1));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mesh = sphere(1);
    let air = Air::default();
    let v = vec![c64::new(1.0, 0.0); mesh.len()];
    assert!(solve(&mesh, air, -1.0, std::slice::from_ref(&v), Formulation::BurtonMiller).is_err());
    assert!(solve(&mesh, air, 100.0, &[vec![c64::new(1.0, 0.0); 3]], Formulation::BurtonMiller).is_err());
    let bad_air = Air { density_kg_m3: 0.0, ..air };
    assert!(solve(&mesh, bad_air, 100.0, std::slice::from_ref(&v), Formulation::BurtonMiller).is_err());
    let s = solve(&mesh, air, 100.0, &[v], Formulation::BurtonMiller).unwrap().remove(0);
    let err = s.pressure_at(&mesh, [0.01, 0.0, 0.0]).unwrap_err();
    assert!(err.to_string().contains("inside the body"), "{err}");
}
