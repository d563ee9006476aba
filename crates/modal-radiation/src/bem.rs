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
//! unique solution at every `k > 0` because `Im α ≠ 0`. But on constant
//! panels `N` leaves a residue at each centroid that does not fall with the
//! panels (the pressure's jumps at the edges; [`crate::continuous`]), so
//! the default ([`Formulation::Automatic`]) solves the CBIE wherever no
//! interior resonance can be, below 0.8 of a rigorous bound on the lowest
//! one ([`interior_wavenumber_bound`]), and Burton–Miller above.
//!
//! Discretisation: piecewise-constant `q` on flat panels; `p` piecewise
//! constant on the panels or on clusters of panels ([`crate::cluster`]:
//! fewer unknowns where the wavelength allows; every panel keeps its own
//! velocity and geometry), collocation at one panel centroid per
//! cluster (assembly and its quadrature rules: [`crate::assembly`]; far
//! clusters are summed as points with the velocity's first two moments),
//! dense complex LU with partial pivoting (faer, sequential, so
//! the result does not depend on the thread count) below
//! [`ITERATIVE_MIN_UNKNOWNS`] unknowns, restarted GMRES ([`crate::gmres`],
//! preconditioned by the diagonal blocks of the cluster tree's leaves,
//! [`crate::precond`]; all fields at once; LU if it fails to converge)
//! above. Rows are assembled
//! independently in parallel (rayon), each by one thread in a fixed order:
//! bit-identical across thread counts.

use faer::c64;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::Perm;
use faer::{Mat, MatMut, MatRef, Par};

use crate::assembly::{assemble_dense, Assembly};
pub use crate::assembly::{AGGREGATE_RATIO, CLUSTER_NEAR_RATIO, FAR_POINT_RATIO, MID_POINT_RATIO};
use crate::batch::{Formula, SourcePoints};
use crate::cluster::Clusters;
use crate::error::RadiationError;
use crate::geometry::BoundaryMesh;
use crate::hmatrix::{HMatrix, OverBudget};
use crate::kernels::{CoupledKernels, Kernels};
use crate::near::NearField;
use crate::precond::BlockJacobi;
use crate::quadrature::{on_triangle, TRIANGLE_7};
pub use crate::resonance::interior_wavenumber_bound;

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

/// Densities accepted for the medium [kg/m³]: gases to the densest
/// liquids (hydrogen 0.09, air 1.2, water 1000, mercury 13 500).
pub const DENSITY_RANGE_KG_M3: (f64, f64) = (0.01, 20_000.0);

/// Sound speeds accepted for the medium [m/s] (gases and liquids: 150 to
/// 2 000). Far below it the wavenumber `ω/c` of an audible mode makes every
/// panel many wavelengths wide: at 2 m/s one run took 18 s, at 1 m/s it
/// had not finished after 120 s.
pub const SOUND_SPEED_RANGE_M_S: (f64, f64) = (50.0, 10_000.0);

impl Air {
    /// Errors unless both values are finite and within
    /// [`DENSITY_RANGE_KG_M3`] and [`SOUND_SPEED_RANGE_M_S`].
    pub fn validate(&self) -> Result<(), RadiationError> {
        let within = |v: f64, (lo, hi): (f64, f64)| v.is_finite() && (lo..=hi).contains(&v);
        if within(self.density_kg_m3, DENSITY_RANGE_KG_M3)
            && within(self.sound_speed_m_s, SOUND_SPEED_RANGE_M_S)
        {
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
    /// The conventional equation below [`CONVENTIONAL_MAX_FRACTION`] of
    /// the body's lowest interior resonance (its bound,
    /// [`interior_wavenumber_bound`]), Burton–Miller above (the default;
    /// [`Formulation::resolved`] says which).
    #[default]
    Automatic,
    /// CBIE + (i/k)·HBIE: unique at every frequency. On constant panels its
    /// hypersingular term leaves a residue that does not fall with the
    /// panels (docs/radiation.md, "Burton–Miller's hypersingular term on
    /// constant panels").
    BurtonMiller,
    /// The CBIE alone: wrong near interior resonances, converging like the
    /// panels' area below them.
    Conventional,
}

/// [`Formulation::Automatic`] takes the conventional equation up to this
/// fraction of [`interior_wavenumber_bound`] (the larger of the
/// Faber–Krahn and bounding-box bounds, [`crate::resonance`]): every interior resonance is
/// then at least 25 % above the frequency, where the equation is well
/// conditioned.
pub const CONVENTIONAL_MAX_FRACTION: f64 = 0.8;

impl Formulation {
    /// The equation solved at wavenumber `k` [1/m] on `mesh`:
    /// [`Formulation::Automatic`] resolved to the conventional equation or
    /// Burton–Miller, the others as they are.
    pub fn resolved(self, k: f64, mesh: &BoundaryMesh) -> Formulation {
        match self {
            Formulation::Automatic => self.resolved_below(k, interior_wavenumber_bound(mesh)),
            other => other,
        }
    }

    /// [`Formulation::resolved`] given the mesh's
    /// [`interior_wavenumber_bound`] `bound` [1/m] (computed once per mesh).
    pub fn resolved_below(self, k: f64, bound: f64) -> Formulation {
        match self {
            Formulation::Automatic if k <= CONVENTIONAL_MAX_FRACTION * bound => Formulation::Conventional,
            Formulation::Automatic => Formulation::BurtonMiller,
            other => other,
        }
    }
}

impl std::fmt::Display for Formulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Formulation::Automatic => "automatic",
            Formulation::BurtonMiller => "Burton–Miller",
            Formulation::Conventional => "conventional equation",
        })
    }
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
    /// when `x` lies inside the body or on its surface
    /// ([`BoundaryMesh::check_field_point`]: closer to a panel than the
    /// formula's quadrature is accurate).
    pub fn pressure_at(&self, mesh: &BoundaryMesh, x: [f64; 3]) -> Result<c64, RadiationError> {
        mesh.check_field_point(x)?;
        Ok(self.representation(mesh, x, &mut SourcePoints::default()))
    }

    /// [`SurfaceField::pressure_at`] at each of `points` [Pa], the points
    /// in parallel (each by one thread: the same bits for any thread
    /// count); the first refused point is the error.
    pub fn pressures_at(&self, mesh: &BoundaryMesh, points: &[[f64; 3]]) -> Result<Vec<c64>, RadiationError> {
        use rayon::prelude::*;
        points
            .par_iter()
            .map_init(SourcePoints::default, |pts, &x| {
                mesh.check_field_point(x)?;
                Ok(self.representation(mesh, x, pts))
            })
            .collect()
    }

    /// `p(x) = ∫ [p ∂G/∂n_y − q G] dS` by each panel's adaptive rule
    /// ([`Kernels::panel`]); the panels it would not split (the point
    /// [`crate::kernels::NEAR_RATIO`] diameters or more from the centroid)
    /// take its 7-point rule in SIMD lanes ([`crate::batch`] with `α = 0`:
    /// `a = −∂G/∂n_y w`, `op = −G w`), `REPRESENTATION_SLAB` points at a
    /// time.
    fn representation(&self, mesh: &BoundaryMesh, x: [f64; 3], pts: &mut SourcePoints) -> c64 {
        const REPRESENTATION_SLAB: usize = 4096;
        let kern = Kernels::new(self.wavenumber);
        let plain = CoupledKernels::new(self.wavenumber, c64::new(0.0, 0.0));
        let mut p = c64::new(0.0, 0.0);
        let flush = |pts: &mut SourcePoints, p: &mut c64| {
            pts.evaluate(&plain, Formula::Coupled);
            for (i, (_, j)) in pts.owners().enumerate() {
                let (a, op) = pts.weights(i);
                *p += self.dpdn(j) * op - self.pressure[j] * a;
            }
            pts.clear();
        };
        pts.clear();
        for (j, panel) in mesh.panels.iter().enumerate() {
            let t = panel.corners.map(|i| mesh.vertices[i]);
            if crate::kernels::adaptive_splits(t, panel.diameter, x) {
                let i = kern.panel(mesh, panel, x, [0.0, 0.0, 1.0]);
                p += self.pressure[j] * i.dg_dny - self.dpdn(j) * i.g;
                continue;
            }
            for (b, w) in TRIANGLE_7 {
                pts.push((x, [0.0; 3]), on_triangle(b, t), panel.normal, w * panel.area, 0, j);
            }
            if pts.len() >= REPRESENTATION_SLAB {
                flush(pts, &mut p);
            }
        }
        flush(pts, &mut p);
        p
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
    let disc = Discretization { mesh, near: &near, clusters, aggregate: true, memory_limit_bytes: None };
    solve_on(&disc, air, frequency_hz, velocities, formulation).map(|(fields, _)| fields)
}

/// What a solve is assembled on.
#[derive(Clone, Copy, Debug)]
pub struct Discretization<'a> {
    /// The panels (geometry and normal velocity).
    pub mesh: &'a BoundaryMesh,
    /// Their near field (`NearField::new(mesh)`, reused across frequencies).
    pub near: &'a NearField,
    /// The pressure unknowns.
    pub clusters: &'a Clusters,
    /// Sum far clusters as points ([`crate::assembly`]); off, every panel is
    /// integrated on its own (the reference of the error measurements).
    pub aggregate: bool,
    /// Most bytes the system's matrix and the near field may hold together;
    /// beyond it the solve is refused ([`RadiationError::OutOfMemory`])
    /// rather than exhaust the machine. `None`: no limit.
    pub memory_limit_bytes: Option<u64>,
}

/// How a system was solved (for progress reports: a fallback is slow).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverPath {
    /// GMRES on the compressed matrix ([`crate::hmatrix`]), with its
    /// iterations (the largest over the right-hand sides).
    CompressedGmres(usize),
    /// GMRES on the dense matrix, with its iterations.
    DenseGmres(usize),
    /// Dense LU; `after_gmres`: GMRES was tried first and did not converge.
    Lu {
        /// GMRES failed before it.
        after_gmres: bool,
    },
}

impl std::fmt::Display for SolverPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolverPath::CompressedGmres(it) => write!(f, "compressed GMRES, {it} iterations"),
            SolverPath::DenseGmres(it) => write!(f, "dense GMRES, {it} iterations"),
            SolverPath::Lu { after_gmres: false } => write!(f, "dense LU"),
            SolverPath::Lu { after_gmres: true } => write!(f, "dense LU after GMRES did not converge"),
        }
    }
}

/// The checks every surface solve makes of its inputs: the air, a finite
/// positive frequency, and per field one finite normal velocity per panel
/// (`panels` of them).
pub(crate) fn check_problem(
    air: Air,
    frequency_hz: f64,
    panels: usize,
    velocities: &[Vec<c64>],
) -> Result<(), RadiationError> {
    air.validate()?;
    if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
        return Err(RadiationError::BadFrequency(frequency_hz));
    }
    for (f, v) in velocities.iter().enumerate() {
        if v.len() != panels || v.iter().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
            return Err(RadiationError::BadVelocity { field: f, got: v.len(), expected: panels });
        }
    }
    Ok(())
}

/// [`solve_clustered`] on a prepared [`Discretization`], also saying how
/// the system was solved.
pub fn solve_on(
    disc: &Discretization<'_>,
    air: Air,
    frequency_hz: f64,
    velocities: &[Vec<c64>],
    formulation: Formulation,
) -> Result<(Vec<SurfaceField>, SolverPath), RadiationError> {
    let (mesh, clusters) = (disc.mesh, disc.clusters);
    if clusters.of_panel.len() != mesh.len() || clusters.of_panel.iter().any(|&c| c >= clusters.len()) {
        return Err(RadiationError::Bank("the clusters do not partition the panels".into()));
    }
    check_problem(air, frequency_hz, mesh.len(), velocities)?;
    let omega = 2.0 * std::f64::consts::PI * frequency_hz;
    let k = omega / air.sound_speed_m_s;
    let iwr = c64::new(0.0, omega * air.density_kg_m3);
    let nrhs = velocities.len();
    let alpha = match formulation.resolved(k, mesh) {
        Formulation::Conventional => c64::new(0.0, 0.0),
        _ => c64::new(0.0, 1.0 / k),
    };
    let q: Vec<Vec<c64>> = velocities.iter().map(|v| v.iter().map(|z| z * iwr).collect()).collect();
    let kern = Kernels::new(k);
    let asm = Assembly::new(mesh, disc.near, clusters, &kern, alpha, &q, disc.aggregate);
    let compressed = clusters.len() >= HMATRIX_MIN_UNKNOWNS;
    // The matrix's share of the memory guard: what the near field leaves.
    let budget = disc.memory_limit_bytes.map_or(usize::MAX, |limit| {
        usize::try_from(limit).unwrap_or(usize::MAX).saturating_sub(disc.near.bytes())
    });
    let out_of_memory = |needed_bytes: usize| RadiationError::OutOfMemory {
        frequency_hz,
        unknowns: clusters.len(),
        needed_bytes: needed_bytes.saturating_add(disc.near.bytes()) as u64,
        limit_bytes: disc.memory_limit_bytes.unwrap_or(u64::MAX),
    };
    let solved = if compressed {
        compressed_solve(&asm, budget).map_err(|over| out_of_memory(over.stored_bytes))?
    } else {
        None
    };
    let dense_bytes =
        clusters.len().saturating_mul(clusters.len()).saturating_mul(std::mem::size_of::<c64>());
    if solved.is_none() && clusters.len() <= MAX_DENSE_UNKNOWNS && dense_bytes > budget {
        return Err(out_of_memory(dense_bytes));
    }
    let (pressures, path) = solved
        .map(|(p, it)| (p, SolverPath::CompressedGmres(it)))
        .or_else(|| {
            if clusters.len() > MAX_DENSE_UNKNOWNS {
                return None;
            }
            let (mut at, mut rhs) = assemble_dense(&asm);
            let iterative = clusters.len() >= ITERATIVE_MIN_UNKNOWNS;
            iterative_solve(&asm, &at, &rhs).map(|(p, it)| (p, SolverPath::DenseGmres(it))).or_else(|| {
                lu_solve_transposed(&mut at, clusters.len(), &mut rhs, nrhs)
                    .map(|p| (p, SolverPath::Lu { after_gmres: compressed || iterative }))
            })
        })
        .ok_or(if clusters.len() > MAX_DENSE_UNKNOWNS {
            RadiationError::NotConverged { frequency_hz, unknowns: clusters.len(), max: MAX_DENSE_UNKNOWNS }
        } else {
            RadiationError::Singular { frequency_hz }
        })?;
    let fields = (0..nrhs)
        .map(|f| SurfaceField {
            frequency_hz,
            wavenumber: k,
            air,
            pressure: clusters.of_panel.iter().map(|&c| pressures[(c, f)]).collect(),
            normal_velocity: velocities[f].clone(),
        })
        .collect();
    Ok((fields, path))
}

/// Systems with at least this many unknowns are solved by GMRES
/// ([`crate::gmres`], `n²` per iteration) instead of LU (`n³`); below it
/// the LU is cheaper than the iterations. On the demo bar's modes 5 and 12
/// (3 264 and 4 928 unknowns) the radiated power moved by < 10⁻⁹ relative
/// (test: `gmres_and_lu_agree_on_a_burton_miller_system`).
pub const ITERATIVE_MIN_UNKNOWNS: usize = 800;

/// Systems with at least this many unknowns are assembled compressed
/// ([`crate::hmatrix`]) and solved by GMRES on it. Measured on the demo
/// bowl (release, load 5–7): at 5 754 unknowns on 25 344 panels (21.1 kHz,
/// no cluster summed as a point) 33 s against 46 s dense; at 5 251
/// (5.3 kHz, far clusters summed as points) both about 19 s. Once the
/// kernel points were evaluated in SIMD lanes ([`crate::batch`]) the dense
/// products' memory traffic weighed more than the assembly, and from
/// 2 000 (was 4 000) the demo's modes ≤ 6 kHz took, two pairs: bar 5.15 /
/// 5.16 → 4.63 / 4.62 s user, bowl 13.5 / 13.6 → 13.3 / 13.3 s, levels
/// within 0.042 dB (the ACA tolerance's budget is 0.1 dB); 1 200 was the
/// same as 2 000 (no demo group lies between).
pub const HMATRIX_MIN_UNKNOWNS: usize = 2000;

/// Largest system assembled dense (16 B × n²: 6 000 unknowns ≈ 0.58 GB):
/// the fallback when GMRES on the compressed matrix does not converge.
pub const MAX_DENSE_UNKNOWNS: usize = 6000;

/// The compressed system solved by GMRES ([`crate::gmres::solve_many`],
/// all fields at once), preconditioned by the diagonal blocks of the
/// cluster tree's leaves ([`crate::precond`]); `None` when a block is
/// singular or any field does not converge; an error when the matrix
/// holds more than `budget` bytes.
fn compressed_solve(asm: &Assembly<'_>, budget: usize) -> Result<Option<(Mat<c64>, usize)>, OverBudget> {
    let (h, rhs) = HMatrix::assemble_within(asm, budget)?;
    let Some(pc) = BlockJacobi::new(asm.len(), h.diagonal_blocks().map(|(u, d)| (u, d.to_vec()))) else {
        return Ok(None);
    };
    let apply = |xs: &[&[c64]], ys: &mut [Vec<c64>]| h.apply_many(xs, ys);
    Ok(gmres_solve(&pc, &apply, &rhs, asm.fields().len()))
}

/// GMRES on the dense system (`a` = `A` row-major, which the assembly's
/// `Aᵀ` column-major layout is), preconditioned by its diagonal blocks on
/// the leaves of the cluster tree of `asm` ([`HMatrix::leaves`]); `None`
/// below [`ITERATIVE_MIN_UNKNOWNS`] or when any field does not converge
/// (the caller then factorises).
fn iterative_solve(asm: &Assembly<'_>, a: &[c64], rhs: &[c64]) -> Option<(Mat<c64>, usize)> {
    let n = asm.len();
    if n < ITERATIVE_MIN_UNKNOWNS {
        return None;
    }
    let leaves = HMatrix::leaves(asm);
    let block = |u: &[usize]| u.iter().flat_map(|&i| u.iter().map(move |&j| a[i * n + j])).collect();
    let pc = BlockJacobi::new(n, leaves.iter().map(|u| (&u[..], block(u))))?;
    gmres_solve(
        &pc,
        &|xs: &[&[c64]], ys: &mut [Vec<c64>]| crate::gmres::product(a, xs, ys),
        rhs,
        asm.fields().len(),
    )
}

/// [`crate::gmres::solve_many`] on the right-hand sides `rhs` (row-major
/// `n × nrhs`); the solutions as columns, and the most iterations any took.
fn gmres_solve(
    pc: &BlockJacobi,
    apply: &crate::gmres::MultiProduct<'_>,
    rhs: &[c64],
    nrhs: usize,
) -> Option<(Mat<c64>, usize)> {
    let n = pc.len();
    let bs: Vec<Vec<c64>> = (0..nrhs).map(|f| (0..n).map(|i| rhs[i * nrhs + f]).collect()).collect();
    let bs: Vec<&[c64]> = bs.iter().map(Vec::as_slice).collect();
    let solutions = crate::gmres::solve_many(pc, apply, &bs)?;
    let iterations = solutions.iter().map(|s| s.iterations).max().unwrap_or(0);
    Some((Mat::from_fn(n, nrhs, |i, f| solutions[f].x[i]), iterations))
}

/// Solves `A x = b` given `at = Aᵀ` (column-major `n × n`, overwritten by
/// its LU factors) and `b` row-major `n × nrhs`. `None` when a pivot is
/// zero or the solution is not finite.
pub(crate) fn lu_solve_transposed(
    at: &mut [c64],
    n: usize,
    rhs: &mut [c64],
    nrhs: usize,
) -> Option<Mat<c64>> {
    let mut lu = MatMut::from_column_major_slice_mut(at, n, n);
    let p = lu_in_place(lu.as_mut())?;
    let lu_ref: MatRef<'_, c64> = lu.as_ref();
    let par = Par::Seq;
    let mut x = Mat::from_fn(n, nrhs, |i, f| rhs[i * nrhs + f]);
    let mut buf = MemBuffer::new(solve::solve_transpose_in_place_scratch::<usize, c64>(n, nrhs, par));
    solve::solve_transpose_in_place(lu_ref, lu_ref, p.as_ref(), x.as_mut(), par, MemStack::new(&mut buf));
    let finite = (0..nrhs).all(|f| x.col(f).iter().all(|z| z.re.is_finite() && z.im.is_finite()));
    finite.then_some(x)
}

/// `P A = L U` of the square `a` in place (faer, partial pivoting, one
/// thread: the same bits for any thread count); the row permutation `P`,
/// or `None` when a pivot is zero or a factor not finite.
pub(crate) fn lu_in_place(mut a: MatMut<'_, c64>) -> Option<Perm<usize>> {
    let n = a.nrows();
    let (mut perm, mut perm_inv) = (vec![0usize; n], vec![0usize; n]);
    let par = Par::Seq;
    let mut buf = MemBuffer::new(factor::lu_in_place_scratch::<usize, c64>(n, n, par, Default::default()));
    factor::lu_in_place(
        a.as_mut(),
        &mut perm,
        &mut perm_inv,
        par,
        MemStack::new(&mut buf),
        Default::default(),
    );
    let regular = (0..n).all(|i| {
        let d = a[(i, i)];
        d.norm() != 0.0 && d.re.is_finite() && d.im.is_finite()
    });
    regular.then(|| Perm::new_checked(perm.into_boxed_slice(), perm_inv.into_boxed_slice(), n))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Measured (`cargo test -p modal-radiation --lib far_clusters -- --nocapture`):
    /// level change at 12 points at twice the radius when far clusters are
    /// summed as points instead of panel by panel.
    #[test]
    fn far_clusters_summed_as_points_match_panel_by_panel() {
        use crate::cluster::Adjacency;
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.06, 0.04], 4);
        let near = NearField::new(&mesh);
        // A bending-like field: sign changes along x and z.
        let vel: Vec<c64> = mesh
            .panels
            .iter()
            .map(|p| c64::new((40.0 * p.centroid[0]).cos() * p.normal[2] + 0.3 * p.normal[0], 0.0))
            .collect();
        let air = Air::default();
        for f in [800.0, 3000.0] {
            let k = 2.0 * std::f64::consts::PI * f / air.sound_speed_m_s;
            let clusters = Clusters::grow(&mesh, &Adjacency::new(&mesh), (0.5 / k).min(0.025));
            assert!(clusters.len() < mesh.len() / 2, "{} clusters", clusters.len());
            let field = |aggregate| {
                let disc = Discretization {
                    mesh: &mesh,
                    near: &near,
                    clusters: &clusters,
                    aggregate,
                    memory_limit_bytes: None,
                };
                solve_on(&disc, air, f, std::slice::from_ref(&vel), Formulation::BurtonMiller)
                    .unwrap()
                    .0
                    .remove(0)
            };
            let (each, summed) = (field(false), field(true));
            let mut worst = 0.0f64;
            for i in 0..12 {
                let (th, ph) = (0.3 + 0.23 * i as f64, 1.1 * i as f64);
                let x = [0.2 * th.sin() * ph.cos(), 0.2 * th.sin() * ph.sin(), 0.2 * th.cos()];
                let (a, b) = (each.pressure_at(&mesh, x).unwrap(), summed.pressure_at(&mesh, x).unwrap());
                worst = worst.max((20.0 * (b.norm() / a.norm()).log10()).abs());
            }
            eprintln!("{f} Hz, {} clusters: largest level change {worst:.4} dB", clusters.len());
            assert!(each.pressure != summed.pressure, "no cluster was summed");
            assert!(worst < 0.1, "{f} Hz: {worst} dB");
        }
    }

    #[test]
    fn batched_representation_formula_equals_the_panel_by_panel_sum() {
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.06, 0.04], 3);
        let vel: Vec<c64> = mesh.panels.iter().map(|p| c64::new(p.normal[0], 0.2 * p.normal[2])).collect();
        let field =
            solve(&mesh, Air::default(), 6000.0, &[vel], Formulation::BurtonMiller).unwrap().remove(0);
        let kern = Kernels::new(field.wavenumber);
        // Near the surface (panels split by the adaptive rule), at two bounding
        // radii, and 1 km away, where k·r exceeds the lanes' sin_cos range.
        let points = [[0.0, 0.0, 0.043], [0.2, -0.05, 0.1], [1000.0, 0.0, 0.0]];
        assert!(field.wavenumber * 1000.0 > crate::sincos::MAX_ARGUMENT);
        let batched = field.pressures_at(&mesh, &points).unwrap();
        for (x, got) in points.iter().zip(&batched) {
            let mut want = c64::new(0.0, 0.0);
            for (j, panel) in mesh.panels.iter().enumerate() {
                let i = kern.panel(&mesh, panel, *x, [0.0, 0.0, 1.0]);
                want += field.pressure[j] * i.dg_dny - field.dpdn(j) * i.g;
            }
            assert!((got - want).norm() <= 1e-12 * want.norm(), "at {x:?}: {got} vs {want}");
            assert_eq!(field.pressure_at(&mesh, *x).unwrap(), *got, "one point at a time");
        }
        assert!(matches!(
            field.pressures_at(&mesh, &[[0.2, 0.0, 0.0], [0.0; 3]]),
            Err(RadiationError::PointInsideBody { .. })
        ));
    }

    /// `solve_on` names the path each size takes.
    #[test]
    fn the_report_names_how_each_system_was_solved() {
        let air = Air::default();
        let path = |subdivisions: u32| {
            let mesh = crate::geometry::tests::ellipsoid([0.1, 0.07, 0.05], subdivisions);
            let vel: Vec<c64> = mesh.panels.iter().map(|p| c64::new(p.normal[0], 0.0)).collect();
            let (near, clusters) = (NearField::new(&mesh), Clusters::identity(mesh.len()));
            let disc = Discretization {
                mesh: &mesh,
                near: &near,
                clusters: &clusters,
                aggregate: true,
                memory_limit_bytes: None,
            };
            let (fields, path) =
                solve_on(&disc, air, 1000.0, std::slice::from_ref(&vel), Formulation::BurtonMiller).unwrap();
            assert_eq!(fields.len(), 1);
            (mesh.len(), path)
        };
        let (n, small) = path(2);
        assert!(
            n < ITERATIVE_MIN_UNKNOWNS && small == SolverPath::Lu { after_gmres: false },
            "{n}: {small:?}"
        );
        let (n, large) = path(3);
        assert!((ITERATIVE_MIN_UNKNOWNS..HMATRIX_MIN_UNKNOWNS).contains(&n), "{n}");
        assert!(matches!(large, SolverPath::DenseGmres(it) if it > 0), "{large:?}");
        assert_eq!(SolverPath::Lu { after_gmres: true }.to_string(), "dense LU after GMRES did not converge");
    }

    /// A solve beyond the memory guard is refused, dense or compressed,
    /// with the frequency, the unknowns and the limit; within it, the same
    /// bits as with no guard.
    #[test]
    fn a_system_beyond_the_memory_limit_is_refused() {
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.07, 0.05], 2);
        let vel: Vec<c64> = mesh.panels.iter().map(|p| c64::new(p.normal[0], 0.0)).collect();
        let (near, clusters) = (NearField::new(&mesh), Clusters::identity(mesh.len()));
        let solve_within = |memory_limit_bytes| {
            let disc = Discretization {
                mesh: &mesh,
                near: &near,
                clusters: &clusters,
                aggregate: true,
                memory_limit_bytes,
            };
            solve_on(&disc, Air::default(), 1000.0, std::slice::from_ref(&vel), Formulation::BurtonMiller)
        };
        let n = mesh.len();
        // The dense matrix (16 B an entry) and the near field fit exactly.
        let needed = (16 * n * n + near.bytes()) as u64;
        let err = solve_within(Some(needed - 1)).expect_err("one byte short");
        assert!(
            matches!(err, RadiationError::OutOfMemory { unknowns, limit_bytes, .. }
                if unknowns == n && limit_bytes == needed - 1),
            "{err:?}"
        );
        let said = err.to_string();
        assert!(said.starts_with("the boundary-element system at 1000 Hz (320 unknowns)"), "{said}");
        assert!(said.contains("memory limit of 0.00 GB") && said.contains("--full-resolution"), "{said}");
        let free = solve_within(None).unwrap();
        assert!(solve_within(Some(needed)).unwrap() == free, "the guard changed the solve");
        // The compressed path: refused inside its assembly.
        let system = crate::hmatrix::system_tests::EllipsoidSystem::new();
        let asm = system.assembly();
        assert!(matches!(compressed_solve(&asm, 1 << 20), Err(over) if over.stored_bytes > 1 << 20));
    }

    #[test]
    fn gmres_and_lu_agree_on_a_burton_miller_system() {
        // 1280 panels (above ITERATIVE_MIN_UNKNOWNS), an ellipsoid, ka ≈ 2.
        let mesh = crate::geometry::tests::ellipsoid([0.1, 0.07, 0.05], 3);
        let n = mesh.len();
        assert!(n >= ITERATIVE_MIN_UNKNOWNS);
        let vel: Vec<c64> =
            mesh.panels.iter().map(|p| c64::new(p.normal[0] + 0.3 * p.normal[2], 0.0)).collect();
        let k = 20.0;
        let q: Vec<c64> = vel.iter().map(|v| v * c64::new(0.0, k * 343.0 * 1.21)).collect();
        let near = NearField::new(&mesh);
        let kern = Kernels::new(k);
        let alpha = c64::new(0.0, 1.0 / k);
        let (clusters, fields) = (Clusters::identity(n), [q]);
        let asm = Assembly::new(&mesh, &near, &clusters, &kern, alpha, &fields, true);
        let (mut at, mut rhs) =
            crate::assembly::assemble(&mesh, &near, &clusters, &kern, alpha, &fields, true);
        let (it, iterations) = iterative_solve(&asm, &at, &rhs).expect("GMRES converges");
        assert!(iterations > 0 && iterations < n, "{iterations} iterations");
        let lu = lu_solve_transposed(&mut at, n, &mut rhs, 1).unwrap();
        let diff: f64 = (0..n).map(|i| (it[(i, 0)] - lu[(i, 0)]).norm_sqr()).sum::<f64>().sqrt();
        let size: f64 = (0..n).map(|i| lu[(i, 0)].norm_sqr()).sum::<f64>().sqrt();
        // cond(A) · tolerance, cond(A) of order 10.
        assert!(diff < 100.0 * crate::gmres::TOLERANCE * size, "relative difference {}", diff / size);
    }

    /// The compressed path (block-Jacobi GMRES on the H-matrix, two fields
    /// sharing each product) against the dense LU of the same system, and
    /// the same bits on one thread and on three.
    #[test]
    fn compressed_gmres_matches_lu_and_is_bit_identical_across_thread_counts() {
        let system = crate::hmatrix::system_tests::EllipsoidSystem::new();
        let asm = system.assembly();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| compressed_solve(&asm, usize::MAX).expect("no budget").expect("GMRES converges"))
        };
        let (it, iterations) = on(1);
        assert!(iterations > 0);
        assert!((it.clone(), iterations) == on(3), "thread count changed the compressed solve");
        let n = asm.len();
        let (mut at, mut rhs) = assemble_dense(&asm);
        let lu = lu_solve_transposed(&mut at, n, &mut rhs, 2).unwrap();
        for f in 0..2 {
            let diff: f64 = (0..n).map(|i| (it[(i, f)] - lu[(i, f)]).norm_sqr()).sum::<f64>().sqrt();
            let size: f64 = (0..n).map(|i| lu[(i, f)].norm_sqr()).sum::<f64>().sqrt();
            // ACA's ε on each block plus GMRES's tolerance, times cond(A).
            assert!(diff < 1e-4 * size, "field {f}: relative difference {}", diff / size);
        }
    }
}
