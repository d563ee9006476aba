//! Radiation of a bank's modes: each mode vibrating harmonically at its
//! undamped frequency with unit modal velocity amplitude.
//!
//! Mass-normalized shapes `φ_i` [1/√kg] and modal velocity amplitude 1
//! give the surface velocity `φ_i(x)` [m/s]; a panel's normal velocity is
//! the mean of `φ · n` over its corners (all surface nodes: a quadratic
//! surface triangle is four panels), `n` the smooth-surface normal at the
//! node (see [`normal_velocity`]). Modes whose frequencies lie within a relative
//! `group_tolerance` of each other (degenerate pairs and multiplets) are
//! solved at their geometric-mean frequency with one factorization: the
//! transfer varies smoothly with `k` (no resonances in the exterior
//! problem), by about `(l+1)·δf/f` in power for a degree-`l` multipole,
//! i.e. < 0.04 dB at the default 10⁻³.

use std::time::Instant;

use faer::c64;
use modal_bank::ModeBank;

use crate::bem::{solve, Air, Formulation, SurfaceField};
use crate::error::RadiationError;
use crate::geometry::{dot, BoundaryMesh};
use crate::multipole::{fit, Multipole, DEFAULT_TOLERANCE};

/// Options of a bank radiation run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiationOptions {
    /// The air.
    pub air: Air,
    /// Modes closer than this relative frequency share one solve.
    pub group_tolerance: f64,
    /// Relative RMS error of the multipole truncation at twice the body radius.
    pub multipole_tolerance: f64,
    /// Boundary integral equation (Burton–Miller unless studying).
    pub formulation: Formulation,
}

impl Default for RadiationOptions {
    fn default() -> Self {
        RadiationOptions {
            air: Air::default(),
            group_tolerance: 1e-3,
            multipole_tolerance: DEFAULT_TOLERANCE,
            formulation: Formulation::BurtonMiller,
        }
    }
}

/// The radiation of one mode.
#[derive(Clone, Debug)]
pub struct ModeRadiation {
    /// Mode index in the bank.
    pub mode: usize,
    /// The mode's undamped frequency [Hz].
    pub frequency_hz: f64,
    /// Surface pressure and normal velocity (solved at the group frequency).
    pub surface: SurfaceField,
    /// Radiated power at unit modal velocity amplitude [W], from the far
    /// field (the multipole coefficients), which stays accurate at low `ka`
    /// where the surface integral `½Re∫p v*` is a small difference of
    /// large reactive terms.
    pub power_w: f64,
    /// Radiation efficiency `P / (½ρ₀c∫|v_n|²dS)`.
    pub efficiency: f64,
    /// Far-field representation about the centre of mass.
    pub multipole: Multipole,
}

/// Progress of a run, for the caller to show.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// Groups solved so far.
    pub groups_done: usize,
    /// Groups in all.
    pub groups: usize,
    /// Modes in the group just solved.
    pub modes: Vec<usize>,
    /// Its frequency [Hz].
    pub frequency_hz: f64,
    /// Seconds spent in the solve (assembly + LU).
    pub solve_s: f64,
    /// Seconds spent in the multipole fit.
    pub fit_s: f64,
}

impl std::fmt::Display for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "radiation {}/{}: mode(s) {:?} at {:.1} Hz, solve {:.2} s, fit {:.2} s",
            self.groups_done, self.groups, self.modes, self.frequency_hz, self.solve_s, self.fit_s
        )
    }
}

/// The bank's surface as flat panels (quadratic triangles split in four).
pub fn boundary_mesh(bank: &ModeBank) -> Result<BoundaryMesh, RadiationError> {
    let s = &bank.surface;
    match &s.triangle_edge_nodes {
        Some(edges) => BoundaryMesh::quadratic(s.positions.clone(), &s.triangles, edges),
        None => BoundaryMesh::new(s.positions.clone(), &s.triangles),
    }
}

/// Panels whose normal is within this angle of a node's averaged normal
/// use the averaged normal at that corner (smooth surface); across
/// creases (a bar's edges) the panel's own normal is used.
pub const CREASE_ANGLE_DEG: f64 = 25.0;

/// Normal of each panel corner: the node's smooth-surface normal where
/// the surface is smooth, the panel's own normal across creases (see
/// [`CREASE_ANGLE_DEG`]). The node normal is the area-weighted mean over
/// the surrounding triangles of the normal of the *curved* 6-node triangle
/// at that node (`∂x/∂ξ × ∂x/∂η` of the quadratic map) for quadratic
/// banks, and of the flat panel normals otherwise. (On the FEM sphere the
/// flat-panel average leaves torsional modes ≈ 50× more normal velocity
/// energy than the exact radial normal; the quadratic normal matches it.)
pub fn corner_normals(bank: &ModeBank, mesh: &BoundaryMesh) -> Vec<[[f64; 3]; 3]> {
    let mut node = vec![[0.0; 3]; mesh.vertices.len()];
    match &bank.surface.triangle_edge_nodes {
        Some(edges) if mesh.vertices.len() == bank.surface_node_count() => {
            for (tri, e) in bank.surface.triangles.iter().zip(edges) {
                let nodes = [tri[0], tri[1], tri[2], e[0], e[1], e[2]];
                let x = nodes.map(|i| mesh.vertices[i]);
                // Reference coordinates (ξ, η) of the six nodes.
                let at = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)];
                for (k, &(xi, eta)) in at.iter().enumerate() {
                    let n = quadratic_normal(&x, xi, eta);
                    for q in 0..3 {
                        node[nodes[k]][q] += n[q];
                    }
                }
            }
        }
        _ => {
            for p in &mesh.panels {
                for &c in &p.corners {
                    for (acc, n) in node[c].iter_mut().zip(p.normal) {
                        *acc += p.area * n;
                    }
                }
            }
        }
    }
    let cos_crease = CREASE_ANGLE_DEG.to_radians().cos();
    mesh.panels
        .iter()
        .map(|p| {
            p.corners.map(|c| {
                let n = node[c];
                let len = dot(n, n).sqrt();
                if len > 0.0 && dot(n, p.normal) >= cos_crease * len {
                    n.map(|x| x / len)
                } else {
                    p.normal
                }
            })
        })
        .collect()
}

/// `∂x/∂ξ × ∂x/∂η` of the 6-node triangle (corners 0–2, mid-edge nodes of
/// edges 01, 12, 20) at `(ξ, η)`: the normal scaled by twice the local area
/// element.
fn quadratic_normal(x: &[[f64; 3]; 6], xi: f64, eta: f64) -> [f64; 3] {
    let l0 = 1.0 - xi - eta;
    let d_xi = [-(4.0 * l0 - 1.0), 4.0 * xi - 1.0, 0.0, 4.0 * (l0 - xi), 4.0 * eta, -4.0 * eta];
    let d_eta = [-(4.0 * l0 - 1.0), 0.0, 4.0 * eta - 1.0, -4.0 * xi, 4.0 * xi, 4.0 * (l0 - eta)];
    let mut a = [0.0; 3];
    let mut b = [0.0; 3];
    for k in 0..6 {
        for q in 0..3 {
            a[q] += d_xi[k] * x[k][q];
            b[q] += d_eta[k] * x[k][q];
        }
    }
    crate::geometry::cross(a, b)
}

/// Normal velocity of mode `mode` on each panel at unit modal velocity
/// [m/s]: the mean over the panel's corners of `φ · n` with the corner
/// normals of [`corner_normals`] (so a purely tangential motion of a
/// curved surface, like a sphere's torsional modes, gives ≈ 0 rather than
/// the facets' tilt).
pub fn normal_velocity(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    mode: usize,
) -> Result<Vec<c64>, RadiationError> {
    normal_velocity_with(bank, mesh, &corner_normals(bank, mesh), mode)
}

fn normal_velocity_with(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    normals: &[[[f64; 3]; 3]],
    mode: usize,
) -> Result<Vec<c64>, RadiationError> {
    if mode >= bank.mode_count() {
        return Err(RadiationError::NoSuchMode { mode, count: bank.mode_count() });
    }
    if mesh.vertices.len() != bank.surface_node_count() {
        return Err(RadiationError::Bank("the panel mesh is not the bank's surface".into()));
    }
    Ok(mesh
        .panels
        .iter()
        .zip(normals)
        .map(|(p, n)| {
            let v: f64 = p
                .corners
                .iter()
                .zip(n)
                .map(|(&c, n)| {
                    let s = bank.shape_at(mode, c);
                    dot([s[0] as f64, s[1] as f64, s[2] as f64], *n)
                })
                .sum();
            c64::new(v / 3.0, 0.0)
        })
        .collect())
}

/// Groups of mode indices (ascending frequency) within `tol` of the group's first.
pub fn frequency_groups(bank: &ModeBank, modes: &[usize], tol: f64) -> Vec<Vec<usize>> {
    let mut sorted = modes.to_vec();
    sorted.sort_by(|&a, &b| bank.frequencies_hz[a].total_cmp(&bank.frequencies_hz[b]).then(a.cmp(&b)));
    sorted.dedup();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for m in sorted {
        let f = bank.frequencies_hz[m];
        match groups.last_mut() {
            Some(g) if f <= bank.frequencies_hz[g[0]] * (1.0 + tol) => g.push(m),
            _ => groups.push(vec![m]),
        }
    }
    groups
}

/// Solves the radiation of `modes` of `bank` (any order; results in
/// ascending frequency), reporting each solved group to `progress`.
pub fn radiate_modes(
    bank: &ModeBank,
    modes: &[usize],
    opts: &RadiationOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Vec<ModeRadiation>, RadiationError> {
    opts.air.validate()?;
    let mesh = boundary_mesh(bank)?;
    radiate_modes_on(bank, &mesh, modes, opts, progress)
}

/// [`radiate_modes`] on a given panel mesh of the bank's surface.
pub fn radiate_modes_on(
    bank: &ModeBank,
    mesh: &BoundaryMesh,
    modes: &[usize],
    opts: &RadiationOptions,
    progress: &mut dyn FnMut(&Progress),
) -> Result<Vec<ModeRadiation>, RadiationError> {
    let centre = bank.mass.center_of_mass_m;
    let mut velocities = Vec::with_capacity(modes.len());
    let normals = corner_normals(bank, mesh);
    for &m in modes {
        let v = normal_velocity_with(bank, mesh, &normals, m)?;
        if v.iter().all(|z| z.norm() == 0.0) {
            return Err(RadiationError::NoSurfaceVelocity { mode: m });
        }
        velocities.push((m, v));
    }
    let groups = frequency_groups(bank, modes, opts.group_tolerance);
    let mut out = Vec::with_capacity(modes.len());
    for (gi, group) in groups.iter().enumerate() {
        let (lo, hi) =
            (bank.frequencies_hz[group[0]], bank.frequencies_hz[*group.last().unwrap_or(&group[0])]);
        let f = (lo * hi).sqrt();
        let fields: Vec<Vec<c64>> = group
            .iter()
            .map(|m| velocities.iter().find(|(i, _)| i == m).map(|(_, v)| v.clone()).unwrap_or_default())
            .collect();
        let t0 = Instant::now();
        let surfaces = solve(mesh, opts.air, f, &fields, opts.formulation)?;
        let solve_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let multipoles = fit(mesh, &surfaces, centre, opts.multipole_tolerance);
        let fit_s = t1.elapsed().as_secs_f64();
        for ((&mode, surface), multipole) in group.iter().zip(surfaces).zip(multipoles) {
            out.push(ModeRadiation {
                mode,
                frequency_hz: bank.frequencies_hz[mode],
                power_w: multipole.radiated_power(opts.air),
                efficiency: multipole.radiated_power(opts.air) / surface.velocity_power_scale(mesh),
                surface,
                multipole,
            });
        }
        progress(&Progress {
            groups_done: gi + 1,
            groups: groups.len(),
            modes: group.clone(),
            frequency_hz: f,
            solve_s,
            fit_s,
        });
    }
    Ok(out)
}
