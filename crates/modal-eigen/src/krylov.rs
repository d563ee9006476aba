//! Restarted block Krylov–Schur (Stewart 2001; block form as in Zhou & Saad 2008) for the
//! shift-invert operator `A = (K − σM)⁻¹ M`, which is self-adjoint in the M-inner product.
//!
//! Eigenpairs: `A y = θ y` ⇔ `K y = λ M y` with `λ = σ + 1/θ`; the wanted λ closest above σ
//! have the largest θ. With an M-orthonormal basis V (block Arnoldi with full
//! reorthogonalization, block CGS2 + SVQB) the relation `A V_k = V_k H_k + V_next E_kᵀ`
//! holds; Rayleigh–Ritz on the symmetric part of `H_k` gives Ritz pairs with operator
//! residual `‖A y − θ y‖_M = ‖E sᵢ‖`. A thick restart keeps the best `l` Ritz vectors and the
//! residual block (Krylov–Schur form). Every mode is accepted on its OWN relative residual
//! `‖K y − λ M y‖₂ / (λ ‖M y‖₂)`, computed explicitly. Block size ≥ multiplicity finds
//! exactly repeated eigenvalues directly; larger clusters are caught by the inertia check.

use crate::block::{
    matmul_tall, next_block, rayleigh_ritz_kM, residuals_from, spmm, sym_eig, Deflation, Rng,
};
use crate::factor::ShiftedFactor;
use crate::types::{EigenError, Progress};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::matmul::matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatRef, Par};
use std::time::Instant;

/// Parameters of one Krylov–Schur search.
pub struct KsConfig {
    /// Ritz pairs wanted (sizing of the subspace).
    pub nev: usize,
    /// Maximum basis size (excluding the residual block).
    pub ncv: usize,
    /// Block size.
    pub block: usize,
    /// Restart limit.
    pub max_restarts: usize,
    /// Relative residual tolerance.
    pub tol: f64,
    /// Random seed of the start block.
    pub seed: u64,
    /// Spectrum scale maxᵢ Kᵢᵢ/Mᵢᵢ (rad²/s²) for the double-precision residual floor.
    pub lambda_scale: f64,
}

/// Acceptance bound on the relative residual of a mode with eigenvalue λ: the requested
/// tolerance, unless double precision cannot certify it — rounding w to ε and forming K w
/// leave a residual ≈ ε·λ_max/λ, so the bound is max(tol, 32·ε·λ_scale/λ) (λ_scale from
/// [`crate::SolveStats::lambda_scale`]). Only low modes of very fine or very thin meshes
/// (λ_max/λ > 1e7) reach the floor.
pub fn attainable(tol: f64, lambda: f64, lambda_scale: f64) -> f64 {
    tol.max(FLOOR_FACTOR * f64::EPSILON * lambda_scale / lambda.abs().max(f64::MIN_POSITIVE))
}

/// First gate on the Ritz estimates `‖E s‖ ≤ gate·θ`, relative to the tolerance, before the
/// explicit residual check (which alone accepts modes). Measured on a 30k-DOF box, 50 modes:
/// the explicit residuals came out at 0.2–0.8 × the gate; 0.1 over-converged by one restart.
const INITIAL_GATE: f64 = 0.5;

/// Gate on the Ritz estimates `‖E s‖ ≤ gate·θ` at which the wanted set and its Ritz values
/// are taken as known for the early inertia check (Ritz values err by about the square of
/// the residual, and from above, so σ' still lies above the wanted modes; a wrong guess only
/// costs the overlap, never the proof). 30k-DOF box, 50 modes, 5 interleaved runs each:
/// 1e-4 started the count ≈ 0.15 s later than 1e-3 and the search then waited for it;
/// 1e-2 was no faster than 1e-3.
pub const EARLY_GATE: f64 = 1e-3;

/// Safety factor of the double-precision residual floor.
pub const FLOOR_FACTOR: f64 = 32.0;

/// Restarts in a row without progress after which a search is declared stalled
/// ([`EigenError::Stalled`]) instead of running to `max_restarts`. Progress is a longer
/// converged prefix, a changed gate, or the relative Ritz estimate `‖E s‖/θ` of the first
/// unconverged pair falling below half its best so far (an exactly repeated cluster, e.g.
/// two identical parts, converges together after several restarts with a flat prefix). A healthy search converges its prefix within one or two restarts
/// (30k-DOF box, 50 modes: 1–2 restarts in all); a search that gains nothing for this many
/// is facing a cluster it cannot separate (near-mechanisms: parts joined by hinges or very
/// thin necks), and more restarts only cost minutes.
pub const STALL_RESTARTS: usize = 12;

/// A restart whose relative Ritz estimate of the first unconverged pair is below the square
/// of this fraction of the estimate two restarts earlier does not count towards
/// [`STALL_RESTARTS`]: the search is converging, slowly. (A hinge's stalled search, test
/// `a_hinge_mechanism_stops_early…`, alternates its estimate by ≈ 30 % from one restart to
/// the next and falls by only 3–5 % over two.) Measured on the synthetic grid with 100 elastic modes below its band
/// (`band_far_above_lowest_modes_uses_indefinite_shift`): after a triplet converged, the next
/// estimate fell by 8–20 % a restart (1.9·10⁻⁷ → 6.1·10⁻⁸ over 7 restarts) and was declared
/// stalled after 12 restarts without halving, on one CPU and not on another.
pub const STEADY_DECREASE: f64 = 0.9;

/// Converged eigenpairs of one search, in order of increasing λ − σ (λ > σ).
pub struct KsOutput {
    /// Eigenvalues λ.
    pub lambdas: Vec<f64>,
    /// M-orthonormal eigenvectors (columns).
    pub vectors: Mat<f64>,
    /// Relative residuals.
    pub residuals: Vec<f64>,
    /// Restarts done.
    pub restarts: usize,
    /// Block solves done.
    pub block_solves: usize,
}

/// The memory of a search's basis V (`n × columns`) and of its M-image (kept alongside V:
/// the operator input and every M-inner product come from it), made — and faulted in — ahead
/// of the search if the caller has a core to spare (see `solve`).
pub struct BasisStorage {
    v: Mat<f64>,
    mv: Mat<f64>,
}

impl BasisStorage {
    /// Zeroed storage for `columns` basis columns (including the residual block).
    pub fn new(n: usize, columns: usize) -> Self {
        Self { v: Mat::zeros(n, columns), mv: Mat::zeros(n, columns) }
    }
}

/// Counters threaded through searches for progress reporting.
#[derive(Default)]
pub struct Counters {
    /// Restarts.
    pub restarts: usize,
    /// Block solves.
    pub block_solves: usize,
    /// Explicit residual checks of candidate Ritz pairs.
    pub residual_checks: usize,
    /// Seconds in block solves.
    pub block_solve_s: f64,
    /// Seconds orthogonalizing new blocks.
    pub orthogonalize_s: f64,
    /// Seconds in Rayleigh–Ritz of the projected matrix and explicit residual checks.
    pub residual_check_s: f64,
}

/// Relative residuals ‖K y − λ M y‖ / (|λ| ‖M y‖) of columns of `y`.
pub fn residuals(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    lambdas: &[f64],
    y: MatRef<'_, f64>,
) -> Vec<f64> {
    residuals_from(lambdas, spmm(k, y).as_ref(), spmm(m, y).as_ref())
}

struct Ritz {
    /// θ descending.
    theta: Vec<f64>,
    /// Columns of S in the same order.
    s: Mat<f64>,
    /// ‖E sᵢ‖.
    est: Vec<f64>,
}

fn rayleigh_ritz(h: &Mat<f64>, k: usize, p: usize) -> Option<Ritz> {
    let (sv, u) = sym_eig(h.as_ref().submatrix(0, 0, k, k))?;
    let mut s = Mat::<f64>::zeros(k, k);
    let mut theta = Vec::with_capacity(k);
    for c in 0..k {
        let src = k - 1 - c;
        theta.push(sv[src]);
        s.as_mut().col_mut(c).copy_from(u.col(src));
    }
    let mut e = Mat::<f64>::zeros(p, k);
    matmul(e.as_mut(), Accum::Replace, h.as_ref().submatrix(k, 0, p, k), s.as_ref(), 1.0, Par::Seq);
    let est = (0..k).map(|c| e.col(c).norm_l2()).collect();
    Some(Ritz { theta, s, est })
}

/// Runs one search (in `storage` if it has the shape `n × (ncv + block)`). `enough(λs)`
/// receives the λ of the converged prefix (ascending λ − σ) and says whether the search may
/// stop. `early(λs, λ_next)` is called whenever the prefix
/// of Ritz values accurate to [`EARLY_GATE`] already satisfies `enough` (λ_next: the next
/// Ritz value, +∞ if none), so the caller can start the inertia check of the final shift
/// while the iteration polishes the vectors.
#[allow(clippy::too_many_arguments)]
pub fn search(
    factor: &ShiftedFactor<'_>,
    k_mat: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    defl: &Deflation,
    cfg: &KsConfig,
    enough: &dyn Fn(&[f64]) -> bool,
    early: &mut dyn FnMut(&[f64], f64),
    counters: &mut Counters,
    storage: Option<BasisStorage>,
    progress: &mut dyn FnMut(Progress),
) -> Result<KsOutput, EigenError> {
    let n = m.nrows();
    let p = cfg.block;
    let ncv = cfg.ncv;
    let sigma = factor.shift();
    let mut rng = Rng::new(cfg.seed);
    let BasisStorage { mut v, mut mv } = match storage {
        Some(s) if (s.v.nrows(), s.v.ncols()) == (n, ncv + p) => s,
        _ => BasisStorage::new(n, ncv + p),
    };
    let mut h = Mat::<f64>::zeros(ncv + p, ncv + p);
    let mut buf = MemBuffer::try_new(factor.solve_scratch(p))
        .map_err(|_| EigenError::Factorization("out of memory for the solve workspace".into()))?;
    {
        let mut z = Mat::<f64>::zeros(n, p);
        rng.fill(z.as_mut());
        let empty = Mat::<f64>::zeros(n, 0);
        let (_, _, mz) = next_block(m, defl, empty.as_ref(), empty.as_ref(), z.as_mut(), &mut rng);
        v.as_mut().subcols_mut(0, p).copy_from(z.as_ref());
        mv.as_mut().subcols_mut(0, p).copy_from(mz.as_ref());
    }
    let mut k = 0usize;
    let mut gate = INITIAL_GATE * cfg.tol;
    let mut restarts = 0usize;
    // Stall detection: the best converged prefix at the current gate, and restarts since.
    let (mut best, mut since, mut best_gate, mut best_est) = (0usize, 0usize, gate, f64::INFINITY);
    // The estimates of the two restarts before this one, the older first.
    let mut earlier_est = [f64::INFINITY; 2];
    let check_from = (cfg.nev + p).min(ncv);
    loop {
        // Expand the basis by blocks until full, checking convergence as we go.
        let mut stop = None;
        while k + p <= ncv {
            let t = Instant::now();
            let mut x = mv.as_ref().subcols(k, p).to_owned();
            factor.solve_in_place(x.as_mut(), MemStack::new(&mut buf));
            counters.block_solves += 1;
            counters.block_solve_s += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let (b, c, mx) = next_block(
                m,
                defl,
                v.as_ref().subcols(0, k + p),
                mv.as_ref().subcols(0, k + p),
                x.as_mut(),
                &mut rng,
            );
            mv.as_mut().subcols_mut(k + p, p).copy_from(mx.as_ref());
            h.as_mut().submatrix_mut(0, k, k + p, p).copy_from(c.as_ref());
            h.as_mut().submatrix_mut(k + p, k, p, p).copy_from(b.as_ref());
            v.as_mut().subcols_mut(k + p, p).copy_from(x.as_ref());
            k += p;
            counters.orthogonalize_s += t.elapsed().as_secs_f64();
            if k >= check_from {
                let t = Instant::now();
                let finish = try_finish(&h, &v, k, p, sigma, gate, cfg, k_mat, m, enough, early)?;
                counters.residual_check_s += t.elapsed().as_secs_f64();
                if let Some(out) = finish {
                    counters.residual_checks += 1;
                    match out {
                        Finish::Done(o) => {
                            stop = Some(o);
                            break;
                        }
                        Finish::Tighten(factor_) => gate = (gate * factor_).max(1e-6 * cfg.tol),
                    }
                }
            }
        }
        if let Some(mut o) = stop {
            o.restarts = restarts;
            o.block_solves = counters.block_solves;
            return Ok(o);
        }
        restarts += 1;
        counters.restarts += 1;
        let ritz = rayleigh_ritz(&h, k, p)
            .ok_or_else(|| EigenError::Factorization("Rayleigh-Ritz eigensolver failed".into()))?;
        let conv = converged_prefix(&ritz, sigma, gate).len();
        progress(Progress::Iteration {
            restart: counters.restarts,
            block_solves: counters.block_solves,
            converged: conv.min(cfg.nev),
            wanted: cfg.nev,
        });
        if restarts > cfg.max_restarts {
            return Err(EigenError::NoConvergence { converged: conv.min(cfg.nev), wanted: cfg.nev });
        }
        let est = ritz.theta.get(conv).filter(|t| **t > 0.0).map_or(f64::INFINITY, |t| ritz.est[conv] / t);
        if gate != best_gate || conv > best || est < 0.5 * best_est {
            (best, since, best_gate, best_est) = (conv, 0, gate, est);
        } else if est > STEADY_DECREASE * STEADY_DECREASE * earlier_est[0] {
            // A steady geometric decrease is slow convergence, not a stall. Two restarts
            // back: a stalled cluster's estimate alternates up and down by ≈ 30 %.
            since += 1;
            if since >= STALL_RESTARTS {
                return Err(EigenError::Stalled {
                    converged: conv.min(cfg.nev),
                    wanted: cfg.nev,
                    restarts: counters.restarts,
                    hint: String::new(),
                });
            }
        }
        earlier_est = [earlier_est[1], est];
        // Thick restart: keep the l best Ritz vectors plus the residual block.
        let l = ((cfg.nev + ncv) / 2).max(conv + p).min(ncv - p).min(k);
        let mut y = Mat::<f64>::zeros(n, l);
        matmul_tall(y.as_mut(), Accum::Replace, v.as_ref().subcols(0, k), ritz.s.as_ref().subcols(0, l), 1.0);
        let resid = v.as_ref().subcols(k, p).to_owned();
        v.as_mut().subcols_mut(0, l).copy_from(y.as_ref());
        v.as_mut().subcols_mut(l, p).copy_from(resid.as_ref());
        matmul_tall(
            y.as_mut(),
            Accum::Replace,
            mv.as_ref().subcols(0, k),
            ritz.s.as_ref().subcols(0, l),
            1.0,
        );
        let mresid = mv.as_ref().subcols(k, p).to_owned();
        mv.as_mut().subcols_mut(0, l).copy_from(y.as_ref());
        mv.as_mut().subcols_mut(l, p).copy_from(mresid.as_ref());
        let mut e = Mat::<f64>::zeros(p, l);
        matmul(
            e.as_mut(),
            Accum::Replace,
            h.as_ref().submatrix(k, 0, p, k),
            ritz.s.as_ref().subcols(0, l),
            1.0,
            Par::Seq,
        );
        h.fill(0.0);
        for i in 0..l {
            h[(i, i)] = ritz.theta[i];
        }
        h.as_mut().submatrix_mut(l, 0, p, l).copy_from(e.as_ref());
        k = l;
    }
}

enum Finish {
    Done(KsOutput),
    /// Multiply the gate by this factor.
    Tighten(f64),
}

/// Indices (into the θ-descending order) of the converged prefix with θ > 0.
fn converged_prefix(r: &Ritz, sigma: f64, gate: f64) -> Vec<usize> {
    let _ = sigma;
    let mut out = Vec::new();
    for i in 0..r.theta.len() {
        let th = r.theta[i];
        if th <= 0.0 || r.est[i] > gate * th {
            break;
        }
        out.push(i);
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn try_finish(
    h: &Mat<f64>,
    v: &Mat<f64>,
    k: usize,
    p: usize,
    sigma: f64,
    gate: f64,
    cfg: &KsConfig,
    k_mat: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    enough: &dyn Fn(&[f64]) -> bool,
    early: &mut dyn FnMut(&[f64], f64),
) -> Result<Option<Finish>, EigenError> {
    let ritz = rayleigh_ritz(h, k, p)
        .ok_or_else(|| EigenError::Factorization("Rayleigh-Ritz eigensolver failed".into()))?;
    let loose = converged_prefix(&ritz, sigma, EARLY_GATE);
    let loose_lambdas: Vec<f64> = loose.iter().map(|&i| sigma + 1.0 / ritz.theta[i]).collect();
    if !loose.is_empty() && enough(&loose_lambdas) {
        let next =
            ritz.theta.get(loose.len()).filter(|t| **t > 0.0).map_or(f64::INFINITY, |t| sigma + 1.0 / t);
        early(&loose_lambdas, next);
    }
    let idx = converged_prefix(&ritz, sigma, gate);
    let lambdas: Vec<f64> = idx.iter().map(|&i| sigma + 1.0 / ritz.theta[i]).collect();
    if idx.is_empty() || !enough(&lambdas) {
        return Ok(None);
    }
    let q = idx.len();
    // Ritz vectors with one free operator step (Ericsson & Ruhe 1980):
    // y' = A y / θ = V s + V_next E s / θ, whose residual ‖K y' − λ M y'‖ = ‖M r‖/θ² is not
    // amplified by K (the plain Ritz vector's residual is (K − σM) r / θ).
    let mut y = Mat::<f64>::zeros(v.nrows(), q);
    matmul_tall(y.as_mut(), Accum::Replace, v.as_ref().subcols(0, k), ritz.s.as_ref().subcols(0, q), 1.0);
    let mut e = Mat::<f64>::zeros(p, q);
    matmul(
        e.as_mut(),
        Accum::Replace,
        h.as_ref().submatrix(k, 0, p, k),
        ritz.s.as_ref().subcols(0, q),
        1.0,
        Par::Seq,
    );
    for c in 0..q {
        let inv = 1.0 / ritz.theta[c];
        for r in 0..p {
            e[(r, c)] *= inv;
        }
    }
    matmul_tall(y.as_mut(), Accum::Add, v.as_ref().subcols(k, p), e.as_ref(), 1.0);
    let (lambdas, y, res) = rayleigh_ritz_kM(k_mat, m, y)?;
    let worst = res
        .iter()
        .zip(&lambdas)
        .map(|(r, l)| r / attainable(cfg.tol, *l, cfg.lambda_scale))
        .fold(0.0, f64::max);
    if worst <= 1.0 {
        return Ok(Some(Finish::Done(KsOutput {
            lambdas,
            vectors: y,
            residuals: res,
            restarts: 0,
            block_solves: 0,
        })));
    }
    // Aggressive: every failed explicit check costs two sparse products on all candidates.
    let f = (0.1 / worst).clamp(1e-3, 0.1);
    Ok(Some(Finish::Tighten(f)))
}
