//! The exterior Neumann problem: surface pressure from normal velocity.
//!
//! Time convention `e^{−iωt}`, `k = ω/c`, normal `n` out of the body into
//! the air, `q = ∂p/∂n = iωρ₀ v_n` (momentum equation). For `x` in the air
//! (Kirchhoff–Helmholtz)
//!
//! `p(x) = ∫_S [p(y) ∂G/∂n_y(x, y) − G(x, y) q(y)] dS_y`,
//!
//! and on the surface (`K`, `K'`, `L`, `N` the double, adjoint double,
//! single and hypersingular layer operators of [`crate::kernels`])
//!
//! - CBIE: `(½ − K) p = −L q`,
//! - HBIE: `N p = (½ + K') q`.
//!
//! The CBIE alone is singular at the interior Dirichlet eigenfrequencies
//! (a sphere at `ka = π`); Burton–Miller solves
//! `(½ − K − αN) p = −(L + α(½ + K')) q` with `α = i/k`, which has a
//! unique solution at every `k > 0` because `Im α ≠ 0`.
//!
//! Discretisation: piecewise-constant `q` on flat panels; `p` piecewise
//! constant on the panels or on clusters of panels ([`crate::cluster`]:
//! fewer unknowns where the wavelength allows, every panel still
//! integrated exactly as before), collocation at one panel centroid per
//! cluster, dense complex LU with partial pivoting (faer, sequential, so
//! the result does not depend on the thread count) below
//! [`ITERATIVE_MIN_UNKNOWNS`] unknowns, restarted GMRES ([`crate::gmres`],
//! LU if it fails to converge) above. Rows are assembled
//! independently in parallel (rayon), each by one thread in a fixed order:
//! bit-identical across thread counts.

use faer::c64;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

use crate::cluster::Clusters;
use crate::error::RadiationError;
use crate::geometry::{dot, norm, sub, BoundaryMesh, Panel};
use crate::kernels::{Kernels, PanelIntegrals};
use crate::near::NearField;

/// Properties of the air.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Air {
    /// Density ρ₀ [kg/m³].
    pub density_kg_m3: f64,
    /// Speed of sound c [m/s].
    pub sound_speed_m_s: f64,
}

impl Default for Air {
    /// ρ₀ = 1.21 kg/m³, c = 343 m/s (air at 20 °C).
    fn default() -> Air {
        Air { density_kg_m3: 1.21, sound_speed_m_s: 343.0 }
    }
}

impl Air {
    /// Errors unless both values are finite and positive.
    pub fn validate(&self) -> Result<(), RadiationError> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if ok(self.density_kg_m3) && ok(self.sound_speed_m_s) {
            Ok(())
        } else {
            Err(RadiationError::BadAir { density: self.density_kg_m3, speed: self.sound_speed_m_s })
        }
    }

    /// Characteristic impedance ρ₀c [Pa·s/m].
    pub fn impedance(&self) -> f64 {
        self.density_kg_m3 * self.sound_speed_m_s
    }
}

/// Which boundary integral equation is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Formulation {
    /// CBIE + (i/k)·HBIE: unique at every frequency (the default).
    #[default]
    BurtonMiller,
    /// The CBIE alone: wrong near interior resonances (kept to show why
    /// the guard is needed).
    Conventional,
}

/// Surface solution of one velocity field at one frequency.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceField {
    /// Frequency [Hz].
    pub frequency_hz: f64,
    /// Wavenumber k = 2πf/c [1/m].
    pub wavenumber: f64,
    /// Air the field lives in.
    pub air: Air,
    /// Pressure amplitude on each panel [Pa].
    pub pressure: Vec<c64>,
    /// Normal velocity amplitude on each panel [m/s] (the input).
    pub normal_velocity: Vec<c64>,
}

impl SurfaceField {
    /// `q = ∂p/∂n = iωρ₀ v_n` on panel `j` [Pa/m].
    pub fn dpdn(&self, j: usize) -> c64 {
        let omega = 2.0 * std::f64::consts::PI * self.frequency_hz;
        self.normal_velocity[j] * c64::new(0.0, omega * self.air.density_kg_m3)
    }

    /// Time-averaged radiated power `½ Re ∫ p v_n* dS` [W] from the surface
    /// solution. At low `ka` it is a small difference of large reactive
    /// terms and loses accuracy (tens of % at ka = 0.2 on 1280 panels):
    /// prefer [`crate::Multipole::radiated_power`].
    pub fn radiated_power(&self, mesh: &BoundaryMesh) -> f64 {
        0.5 * mesh
            .panels
            .iter()
            .zip(self.pressure.iter().zip(&self.normal_velocity))
            .map(|(p, (pr, v))| (pr * v.conj()).re * p.area)
            .sum::<f64>()
    }

    /// `½ ρ₀c ∫|v_n|² dS` [W]: the power a large pulsating surface with
    /// this velocity would radiate, the denominator of the radiation
    /// efficiency `σ = P / (½ ρ₀c ∫|v_n|² dS)` (1 for a large pulsating
    /// sphere, ≪ 1 for cancelling, multipole motion).
    pub fn velocity_power_scale(&self, mesh: &BoundaryMesh) -> f64 {
        let v2: f64 = mesh.panels.iter().zip(&self.normal_velocity).map(|(p, v)| v.norm_sqr() * p.area).sum();
        0.5 * self.air.impedance() * v2
    }

    /// Pressure at `x` in the air [Pa] (representation formula). Errors
    /// when `x` lies inside the body.
    pub fn pressure_at(&self, mesh: &BoundaryMesh, x: [f64; 3]) -> Result<c64, RadiationError> {
        if mesh.contains(x) {
            return Err(RadiationError::PointInsideBody { x: x[0], y: x[1], z: x[2] });
        }
        let kern = Kernels::new(self.wavenumber);
        let mut p = c64::new(0.0, 0.0);
        for (j, panel) in mesh.panels.iter().enumerate() {
            let i = kern.panel(mesh, panel, x, [0.0, 0.0, 1.0]);
            p += self.pressure[j] * i.dg_dny - self.dpdn(j) * i.g;
        }
        Ok(p)
    }
}

/// Solves the exterior Neumann problem at `frequency_hz` for each normal
/// velocity field (one value per panel, [m/s]); the fields share one
/// factorization.
pub fn solve(
    mesh: &BoundaryMesh,
    air: Air,
    frequency_hz: f64,
    velocities: &[Vec<c64>],
    formulation: Formulation,
) -> Result<Vec<SurfaceField>, RadiationError> {
    solve_clustered(mesh, &Clusters::identity(mesh.len()), air, frequency_hz, velocities, formulation)
}

/// [`solve`] with the pressure constant on each cluster of `clusters` (one
/// unknown and one collocation point per cluster); the returned fields
/// hold the pressure per panel (its cluster's value).
pub fn solve_clustered(
    mesh: &BoundaryMesh,
    clusters: &Clusters,
    air: Air,
    frequency_hz: f64,
    velocities: &[Vec<c64>],
    formulation: Formulation,
) -> Result<Vec<SurfaceField>, RadiationError> {
    let near = NearField::new(mesh);
    solve_with_near(mesh, &near, clusters, air, frequency_hz, velocities, formulation)
}

/// [`solve_clustered`] with the mesh's near field computed beforehand
/// (`NearField::new(mesh)`, reused across frequencies).
pub fn solve_with_near(
    mesh: &BoundaryMesh,
    near: &NearField,
    clusters: &Clusters,
    air: Air,
    frequency_hz: f64,
    velocities: &[Vec<c64>],
    formulation: Formulation,
) -> Result<Vec<SurfaceField>, RadiationError> {
    if clusters.of_panel.len() != mesh.len() || clusters.of_panel.iter().any(|&c| c >= clusters.len()) {
        return Err(RadiationError::Bank("the clusters do not partition the panels".into()));
    }
    air.validate()?;
    if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
        return Err(RadiationError::BadFrequency(frequency_hz));
    }
    let n = mesh.len();
    for (f, v) in velocities.iter().enumerate() {
        if v.len() != n || v.iter().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
            return Err(RadiationError::BadVelocity { field: f, got: v.len(), expected: n });
        }
    }
    let omega = 2.0 * std::f64::consts::PI * frequency_hz;
    let k = omega / air.sound_speed_m_s;
    let iwr = c64::new(0.0, omega * air.density_kg_m3);
    let nrhs = velocities.len();
    let (mut at, mut rhs) = assemble(mesh, near, clusters, k, formulation, velocities, iwr);
    let pressures = iterative_solve(&at, clusters.len(), &rhs, nrhs)
        .or_else(|| lu_solve_transposed(&mut at, clusters.len(), &mut rhs, nrhs))
        .ok_or(RadiationError::Singular { frequency_hz })?;
    Ok((0..nrhs)
        .map(|f| SurfaceField {
            frequency_hz,
            wavenumber: k,
            air,
            pressure: clusters.of_panel.iter().map(|&c| pressures[(c, f)]).collect(),
            normal_velocity: velocities[f].clone(),
        })
        .collect())
}

/// A cluster seen as a test region: its panels with area weights, its
/// area-weighted centre and normal, and its radius about the centre.
struct TestRegion {
    members: Vec<(usize, f64)>,
    centre: [f64; 3],
    normal: [f64; 3],
    radius: f64,
}

fn test_regions(mesh: &BoundaryMesh, clusters: &Clusters) -> Vec<TestRegion> {
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); clusters.len()];
    for (p, &c) in clusters.of_panel.iter().enumerate() {
        members[c].push(p);
    }
    members
        .into_iter()
        .map(|m| {
            let area: f64 = m.iter().map(|&p| mesh.panels[p].area).sum();
            let mean = |f: &dyn Fn(usize) -> [f64; 3]| {
                [0, 1, 2].map(|k| m.iter().map(|&p| mesh.panels[p].area * f(p)[k]).sum::<f64>() / area)
            };
            let centre = mean(&|p| mesh.panels[p].centroid);
            let n = mean(&|p| mesh.panels[p].normal);
            let len = norm(n);
            let radius = m
                .iter()
                .map(|&p| norm(sub(mesh.panels[p].centroid, centre)) + mesh.panels[p].diameter)
                .fold(0.0, f64::max);
            let members = m.iter().map(|&p| (p, mesh.panels[p].area / area)).collect();
            TestRegion { members, centre, normal: n.map(|x| x / len), radius }
        })
        .collect()
}

/// Panels closer than this many (cluster radius + panel diameter) to a
/// cluster's centre are tested at every member centroid; farther ones at
/// the cluster's centre alone (the mean of a smooth kernel over the
/// cluster, to second order in its size). Also every panel within the
/// cluster radius plus [`MID_POINT_RATIO`] of its diameters, so that every
/// pair of the near field ([`crate::near`]) is met at its member point and
/// the cluster's centre never needs the adaptive rule.
pub const CLUSTER_NEAR_RATIO: f64 = 1.5;

/// Panels farther than this many diameters from the point (and with
/// `k·h ≤ 1`) are integrated by their centroid alone: relative error
/// `O((h/r)²)` of the smooth kernel: measured ≤ 0.4 % at k·h = 0, ≤ 2 %
/// at k·h = 1 (the phase across the panel).
pub const FAR_POINT_RATIO: f64 = 8.0;

/// Panels between this many and [`FAR_POINT_RATIO`] diameters from the
/// point (and with `k·h ≤ 1`) are integrated by the 3-point rule (degree
/// 2); closer ones by the adaptive 7-point rule. Relative error of the four
/// kernels against the adaptive rule from 3 diameters on: ≤ 6.8·10⁻⁴
/// (k·d ≤ 1), against ≤ 2·10⁻² for the centroid rule beyond
/// [`FAR_POINT_RATIO`] (test `far_rules_meet_their_stated_error`).
pub const MID_POINT_RATIO: f64 = 3.0;

/// The four panel integrals of `panel` seen from `x`: one centroid point
/// when far ([`FAR_POINT_RATIO`]), three points at mid range
/// ([`MID_POINT_RATIO`]), the adaptive rule otherwise.
fn integrals(
    kern: &Kernels,
    mesh: &BoundaryMesh,
    panel: &Panel,
    x: [f64; 3],
    nx: [f64; 3],
) -> PanelIntegrals {
    let d = sub(panel.centroid, x);
    let r2 = dot(d, d);
    let smooth = kern.k() * panel.diameter <= 1.0;
    let (far, mid) = (FAR_POINT_RATIO * panel.diameter, MID_POINT_RATIO * panel.diameter);
    if smooth && r2 > far * far {
        kern.point(x, nx, panel.centroid, panel.normal, panel.area)
    } else if smooth && r2 > mid * mid {
        kern.three_point(mesh, panel, x, nx)
    } else {
        kern.panel(mesh, panel, x, nx)
    }
}

/// Row `i` (cluster `i`) of the system matrix `A` is stored as column `i`
/// of `at` (column-major `n × n`, `n` clusters), i.e. `at = Aᵀ`. The
/// equation of a cluster is the area-weighted mean of the collocation
/// equations at its panels' centroids (each balanced about its own panel,
/// which a single off-centre point of the hypersingular equation is not);
/// entry `(i, c)` sums the integrals over the panels of cluster `c`. A
/// single panel per cluster is plain centroid collocation. The right-hand
/// sides come back row-major `n × nrhs`.
fn assemble(
    mesh: &BoundaryMesh,
    near_field: &NearField,
    clusters: &Clusters,
    k: f64,
    formulation: Formulation,
    velocities: &[Vec<c64>],
    iwr: c64,
) -> (Vec<c64>, Vec<c64>) {
    let n = clusters.len();
    let nrhs = velocities.len();
    let alpha = match formulation {
        Formulation::BurtonMiller => c64::new(0.0, 1.0 / k),
        Formulation::Conventional => c64::new(0.0, 0.0),
    };
    let kern = Kernels::new(k);
    let zero = c64::new(0.0, 0.0);
    let regions = test_regions(mesh, clusters);
    let mut at = vec![zero; n * n];
    let mut rhs = vec![zero; n * nrhs];
    at.par_chunks_mut(n).zip(rhs.par_chunks_mut(nrhs.max(1))).enumerate().for_each(|(i, (row, b))| {
        let region = &regions[i];
        let single = region.members.len() == 1;
        // Per member, its near-field row and a cursor into it (panels ascend with j).
        let rows: Vec<_> = region.members.iter().map(|&(t, _)| near_field.row(t)).collect();
        let mut cursor = vec![0usize; rows.len()];
        for (j, pj) in mesh.panels.iter().enumerate() {
            let dist = norm(sub(pj.centroid, region.centre));
            let near = single
                || dist < CLUSTER_NEAR_RATIO * (region.radius + pj.diameter)
                || dist < region.radius + MID_POINT_RATIO * pj.diameter;
            let (mut a, mut op) = (zero, zero);
            if near {
                for (m, &(t, w)) in region.members.iter().enumerate() {
                    let pt = &mesh.panels[t];
                    let (panels, statics) = rows[m];
                    while cursor[m] < panels.len() && (panels[cursor[m]] as usize) < j {
                        cursor[m] += 1;
                    }
                    let ints = if t == j {
                        kern.self_integrals(mesh, pj)
                    } else if cursor[m] < panels.len() && panels[cursor[m]] as usize == j {
                        kern.near(mesh, pj, pt.centroid, pt.normal, &statics[cursor[m]])
                    } else {
                        integrals(&kern, mesh, pj, pt.centroid, pt.normal)
                    };
                    let half = if t == j { 0.5 } else { 0.0 };
                    a += (c64::new(half, 0.0) - ints.dg_dny - alpha * ints.d2g) * w;
                    // −(L + α(½ + K')) q_j
                    op -= (ints.g + alpha * (ints.dg_dnx + half)) * w;
                }
            } else {
                let ints = integrals(&kern, mesh, pj, region.centre, region.normal);
                a = -ints.dg_dny - alpha * ints.d2g;
                op = -(ints.g + alpha * ints.dg_dnx);
            }
            row[clusters.of_panel[j]] += a;
            for (f, v) in velocities.iter().enumerate() {
                b[f] += op * (v[j] * iwr);
            }
        }
    });
    (at, rhs)
}

/// Systems with at least this many unknowns are solved by GMRES
/// ([`crate::gmres`], `n²` per iteration) instead of LU (`n³`); below it
/// the LU is cheaper than the iterations. On the demo bar's modes 5 and 12
/// (3 264 and 4 928 unknowns) the radiated power moved by < 10⁻⁹ relative
/// (test: `gmres_and_lu_agree_on_a_burton_miller_system`).
pub const ITERATIVE_MIN_UNKNOWNS: usize = 800;

/// GMRES for each right-hand side (`a` = `A` row-major, which the
/// assembly's `Aᵀ` column-major layout is); `None` below
/// [`ITERATIVE_MIN_UNKNOWNS`] or when any does not converge (the caller
/// then factorises).
fn iterative_solve(a: &[c64], n: usize, rhs: &[c64], nrhs: usize) -> Option<Mat<c64>> {
    if n < ITERATIVE_MIN_UNKNOWNS {
        return None;
    }
    let mut x = Mat::zeros(n, nrhs);
    for f in 0..nrhs {
        let b: Vec<c64> = (0..n).map(|i| rhs[i * nrhs + f]).collect();
        let s = crate::gmres::solve(a, &b)?;
        for (i, v) in s.x.into_iter().enumerate() {
            x[(i, f)] = v;
        }
    }
    Some(x)
}

/// Solves `A x = b` given `at = Aᵀ` (column-major `n × n`, overwritten by
/// its LU factors) and `b` row-major `n × nrhs`. `None` when a pivot is
/// zero or the solution is not finite.
fn lu_solve_transposed(at: &mut [c64], n: usize, rhs: &mut [c64], nrhs: usize) -> Option<Mat<c64>> {
    let mut lu = MatMut::from_column_major_slice_mut(at, n, n);
    let mut perm = vec![0usize; n];
    let mut perm_inv = vec![0usize; n];
    let par = Par::Seq;
    let mut buf = MemBuffer::new(factor::lu_in_place_scratch::<usize, c64>(n, n, par, Default::default()));
    let (_, p) = factor::lu_in_place(
        lu.as_mut(),
        &mut perm,
        &mut perm_inv,
        par,
        MemStack::new(&mut buf),
        Default::default(),
    );
    let lu_ref: MatRef<'_, c64> = lu.as_ref();
    if (0..n).any(|i| {
        let d = lu_ref[(i, i)];
        d.norm() == 0.0 || !d.re.is_finite() || !d.im.is_finite()
    }) {
        return None;
    }
    let mut x = Mat::from_fn(n, nrhs, |i, f| rhs[i * nrhs + f]);
    let mut buf = MemBuffer::new(solve::solve_transpose_in_place_scratch::<usize, c64>(n, nrhs, par));
    solve::solve_transpose_in_place(lu_ref, lu_ref, p, x.as_mut(), par, MemStack::new(&mut buf));
    let finite = (0..nrhs).all(|f| x.col(f).iter().all(|z| z.re.is_finite() && z.im.is_finite()));
    finite.then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gmres_and_lu_agree_on_a_burton_miller_system() {
        // 1280 panels (above ITERATIVE_MIN_UNKNOWNS), an ellipsoid, ka ≈ 2.
        let (v, t) = modal_mesh::icosphere(3);
        let verts = v.iter().map(|p| [0.1 * p[0], 0.07 * p[1], 0.05 * p[2]]).collect();
        let mesh = BoundaryMesh::new(verts, &t).unwrap();
        let n = mesh.len();
        assert!(n >= ITERATIVE_MIN_UNKNOWNS);
        let vel: Vec<c64> =
            mesh.panels.iter().map(|p| c64::new(p.normal[0] + 0.3 * p.normal[2], 0.0)).collect();
        let k = 20.0;
        let iwr = c64::new(0.0, k * 343.0 * 1.21);
        let near = NearField::new(&mesh);
        let (mut at, mut rhs) =
            assemble(&mesh, &near, &Clusters::identity(n), k, Formulation::BurtonMiller, &[vel], iwr);
        let it = iterative_solve(&at, n, &rhs, 1).expect("GMRES converges");
        let lu = lu_solve_transposed(&mut at, n, &mut rhs, 1).unwrap();
        let diff: f64 = (0..n).map(|i| (it[(i, 0)] - lu[(i, 0)]).norm_sqr()).sum::<f64>().sqrt();
        let size: f64 = (0..n).map(|i| lu[(i, 0)].norm_sqr()).sum::<f64>().sqrt();
        assert!(diff < 1e-6 * size, "relative difference {}", diff / size);
    }
}
