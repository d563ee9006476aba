//! The driver: validation, ordering, shift choice, searches, final Rayleigh–Ritz,
//! residuals and the Sylvester inertia proof of completeness.
//!
//! Shift choice ("scaled to the problem"): with `λ_lo = (2π f_min)²` and
//! `λ_scale = maxᵢ Kᵢᵢ/Mᵢᵢ`: if `λ_lo ≤ 1e-6·λ_scale` (audio band edges) the search starts
//! below the spectrum directly. Otherwise the LDLᵀ of `K − λ_lo M` first counts the eigenvalues
//! below the band (ν_lo, rigid ones included). If few elastic modes lie below the band, the operator shift is `σ = −max(λ_lo, 1e-10·λ_scale)` where
//! `λ_scale = maxᵢ Kᵢᵢ/Mᵢᵢ` estimates the top of the spectrum; this keeps `K − σM` positive
//! definite with condition ≲ 1e10 whatever the units, so Cholesky is used. If many modes lie
//! below the band (ultrasonic bands), the LDLᵀ factor at `σ = λ_lo` itself is the operator.
//!
//! Completeness proof: Sylvester's law of inertia on an LDLᵀ of `K − σ'M` with σ' just above
//! the highest returned mode. With [`EigenOptions::overlap_check`] this factorization starts
//! as a second task of the solver's pool as soon as the Ritz values accurate to
//! `krylov::EARLY_GATE` determine σ', overlapping the rest of the iteration (spectrum
//! slicing: the count needs no solves).
//! It is accepted only if σ' lies above every returned mode and the count equals the modes
//! known below σ'; otherwise the check is factored again at the final σ'.

use crate::block::{hcat, rayleigh_ritz_kM, spmm, svqb, sym_eig, tmul, Deflation, RitzSet};
use crate::factor::{Analysis, CountBuffers, ShiftedFactor};
use crate::krylov::{attainable, residuals, search, BasisStorage, Counters, KsConfig};
use crate::types::*;
use faer::linalg::matmul::matmul;
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatRef, Par};
use std::time::Instant;

/// Elastic modes below the band up to which the operator shift goes below the spectrum.
const MAX_BELOW_FOR_LOW_SHIFT: usize = 24;
/// Below `f_min` with λ_lo ≤ this × λ_scale, the lower inertia factorization is skipped.
const LOW_EDGE_FRACTION: f64 = 1e-6;
/// Smallest |σ| relative to the spectrum scale max Kᵢᵢ/Mᵢᵢ (condition of K − σM ≲ 1e10).
const SHIFT_FLOOR: f64 = 1e-10;
/// Cap on the basis columns beyond `2·nev` (see [`basis_size`]).
const EXTRA_BASIS: usize = 100;
/// Searches for missed modes after an inertia mismatch.
const MAX_SEARCHES: usize = 4;

/// Computes the elastic modes of `K w = λ M w` in the band of `opts` (see the crate docs).
///
/// `k`, `m`: n × n, full symmetric storage, K positive semi-definite, M positive definite.
/// `rigid_fields`: n × r raw rigid-body fields (any basis, need not be orthonormal) spanning
/// the null space of K; they are M-orthonormalized and deflated. `None` if K is nonsingular.
///
/// Runs on a rayon pool of [`EigenOptions::threads`] threads (sparse products split by rows,
/// tall dense products by fixed row halves); the result is bit-identical for any thread count.
/// `progress` is called on the calling thread.
pub fn solve(
    k: &faer::sparse::SparseColMat<usize, f64>,
    m: &faer::sparse::SparseColMat<usize, f64>,
    rigid_fields: Option<MatRef<'_, f64>>,
    opts: &EigenOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<EigenSolution, EigenError> {
    solve_analyzed(k, m, rigid_fields, opts, None, progress)
}

/// [`solve`] with the ordering and symbolic factorization made beforehand by
/// [`crate::analyze`] from the pattern of K (e.g. while K and M were assembled); it is used
/// if it matches the pattern of `K − σM`, else the analysis is redone.
pub fn solve_analyzed(
    k: &faer::sparse::SparseColMat<usize, f64>,
    m: &faer::sparse::SparseColMat<usize, f64>,
    rigid_fields: Option<MatRef<'_, f64>>,
    opts: &EigenOptions,
    analysis: Option<Analysis>,
    progress: &mut dyn FnMut(Progress),
) -> Result<EigenSolution, EigenError> {
    let (k, m) = (k.as_ref(), m.as_ref());
    validate(k, m, rigid_fields, opts)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| EigenError::Factorization(format!("cannot start the solver threads: {e}")))?;
    let (events, received) = std::sync::mpsc::channel();
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            pool.install(move || {
                // The receiver lives until this thread ends.
                let mut send = |p: Progress| {
                    let _ = events.send(p);
                };
                let first = solve_validated(k, m, rigid_fields, opts, analysis, false, &mut send);
                match first {
                    // A search that stalls or fails without the lower inertia count is redone
                    // with it: it tells how many near-zero modes (near-mechanisms) lie below the
                    // band, so the search can be sized for them or aimed past them.
                    Err(EigenError::Stalled { .. } | EigenError::NoConvergence { .. })
                        if !counts_below_band(k, m, opts)? =>
                    {
                        solve_validated(k, m, rigid_fields, opts, None, true, &mut send)
                    }
                    other => other,
                }
            })
        });
        for event in received {
            progress(event);
        }
        worker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

/// [`solve`] after validation, on the solver's thread pool.
fn solve_validated(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    rigid_fields: Option<MatRef<'_, f64>>,
    opts: &EigenOptions,
    analysis: Option<Analysis>,
    force_count: bool,
    progress: &mut dyn FnMut(Progress),
) -> Result<EigenSolution, EigenError> {
    let n = k.nrows();
    // faer's own parallel factorization measured slower than sequential on 2 cores
    // (30k DOF: 1.18 s vs 0.6 s); the parallelism is ours (see `solve`).
    let par = Par::Seq;
    let mut stats = SolveStats::default();
    let lam_lo = hz_to_lambda(opts.min_freq_hz);
    let lam_hi = hz_to_lambda(opts.max_freq_hz);
    let lam_scale = spectrum_scale(k, m)?;
    stats.lambda_scale = lam_scale;

    // Rigid-body deflation (searches after the first also deflate the pairs found).
    let mut defl = Deflation::empty(n);
    if let Some(r) = rigid_fields {
        if r.ncols() > 0 {
            let mut z = r.to_owned();
            let (rank, _) = svqb(m, z.as_mut(), 1e-8);
            defl.extend(m, z.as_ref().subcols(0, rank));
        }
    }
    stats.rigid_modes_removed = defl.len();
    let n_rigid = defl.len();

    // Ordering + symbolic analysis.
    progress(Progress::PhaseStart(Phase::Symbolic));
    let t = Instant::now();
    let use_metis = matches!(opts.ordering, Ordering::Metis | Ordering::Auto);
    let mut factor = ShiftedFactor::analyze(k, m, analysis, use_metis, par)?;
    stats.symbolic_s = t.elapsed().as_secs_f64();
    stats.ordering = Some(factor.ordering);
    stats.factor_nnz = factor.factor_nnz();
    progress(Progress::PhaseEnd { phase: Phase::Symbolic, seconds: stats.symbolic_s });

    let block = opts.block_size.min(n.saturating_sub(n_rigid).max(1));
    let nev_guess = opts.max_modes.saturating_add(MAX_BELOW_FOR_LOW_SHIFT);
    let ncv_guess = basis_size(nev_guess, block);
    let search_space = vector_bytes(n, nev_guess, ncv_guess, block);
    stats.memory_estimate_bytes =
        factor.memory_estimate().saturating_add(factor.pattern_bytes()).saturating_add(search_space);
    let limit = opts.memory_limit_bytes.or_else(default_memory_limit);
    if let Some(limit) = limit {
        if stats.memory_estimate_bytes > limit {
            return Err(EigenError::MemoryLimit {
                estimated: stats.memory_estimate_bytes,
                limit,
                search_space,
                modes: opts.max_modes,
            });
        }
    }
    let overlap = opts.overlap_check
        && limit.is_none_or(|l| stats.memory_estimate_bytes.saturating_add(factor.memory_estimate()) <= l);
    if overlap {
        stats.memory_estimate_bytes = stats.memory_estimate_bytes.saturating_add(factor.memory_estimate());
    }

    // Lower inertia count and shift choice.
    progress(Progress::PhaseStart(Phase::Factor));
    let t = Instant::now();
    // A band edge far below the top of the spectrum (20 Hz vs MHz) cannot have many modes
    // below it worth a factorization: the upper inertia count then proves completeness of
    // everything below σ' including the modes below f_min that the search converges anyway.
    let count_below = force_count || lam_lo > LOW_EDGE_FRACTION * lam_scale;
    let nu_lo = if count_below {
        stats.factorizations += 1;
        inertia(&mut factor, lam_lo)?
    } else {
        n_rigid
    };
    let mut elastic_below = nu_lo.saturating_sub(n_rigid);
    let low_shift = !count_below || elastic_below <= MAX_BELOW_FOR_LOW_SHIFT;
    let below_known = if low_shift { elastic_below } else { 0 };
    let mut wanted = below_known.saturating_add(opts.max_modes);
    // Memory the first search and the early inertia count will write, made on the second
    // core while the Cholesky factorization keeps the first one busy (fresh pages cost ≈ 4 µs
    // each to fault in on the machines measured; see `factor::touched`).
    let mut prefaulted: Option<(BasisStorage, Option<CountBuffers>)> = None;
    if low_shift {
        let sigma = -lam_lo.max(SHIFT_FLOOR * lam_scale);
        stats.factorizations += 1;
        let (_, ncv) = search_size(wanted, n - defl.len(), block);
        let count = factor.count_sizes();
        // The factorization is the second task, so an idle worker starts it at once, and
        // its own second half is free to be taken by this one when the memory is made.
        let (spare, llt) = rayon::join(
            || (BasisStorage::new(n, ncv + block), overlap.then(|| count.allocate().ok()).flatten()),
            || factor.factor_llt(sigma),
        );
        llt?;
        prefaulted = Some(spare);
    } else {
        factor.prepare_solves();
    }
    stats.shift = factor.shift();
    stats.factor_s = t.elapsed().as_secs_f64();
    progress(Progress::PhaseEnd { phase: Phase::Factor, seconds: stats.factor_s });

    // Known eigenpairs (λ ascending after each merge).
    let mut known = Known::default();
    // After an inertia mismatch: the check shift and how many eigenvalues below it are missing.
    let mut missing: Option<(f64, usize)> = None;
    let cap = opts.max_modes;
    let mut counters = Counters::default();
    let mut searches = 0usize;
    let t_iter = Instant::now();
    let mut check_s = 0.0;
    progress(Progress::PhaseStart(Phase::Iterate));
    loop {
        searches += 1;
        // Built only for a repeated search: after a single one (the rule) the pairs found
        // never need their M-images (a sparse product on all of them).
        let with_known;
        let defl = match &known.vectors {
            Some(v) => {
                with_known = defl.extended(m, v.as_ref());
                &with_known
            }
            None => &defl,
        };
        let free = n - defl.len();
        let (nev, ncv) = search_size(wanted, free, block);
        let known_before = known.lambdas.clone();
        let enough = |l: &[f64]| -> bool {
            if let Some((sig, count)) = missing {
                // A repeated search looks for the missed modes only: it may stop once it has
                // them, or once its converged prefix passes σ' without them (then the count
                // decides again). The band's cap is already met by the known modes.
                let below = l.iter().filter(|&&x| x < sig).count();
                return below >= count || l.iter().any(|&x| x >= sig) || l.len() >= free;
            }
            let mut all: Vec<f64> = known_before.iter().chain(l.iter()).cloned().collect();
            all.sort_by(f64::total_cmp);
            let in_band = all.iter().filter(|&&x| x >= lam_lo && x <= lam_hi).count();
            in_band >= cap || l.iter().any(|&x| x > lam_hi) || all.len() >= free
        };
        let (out, early) = if ncv < nev + block || free <= 2 * block + nev {
            (dense_all(k, m, defl)?, None)
        } else {
            let cfg = KsConfig {
                nev,
                ncv,
                block,
                max_restarts: opts.max_restarts,
                tol: opts.tolerance,
                seed: 0x5EED_0000 + searches as u64,
                lambda_scale: lam_scale,
            };
            let band = Band { lo: lam_lo, hi: lam_hi, cap };
            let early_ok = overlap && searches == 1;
            let f = &factor;
            // The early count runs as a task of the solver's pool: on two threads it takes
            // one worker while the search's parallel halves run inline on the other (an OS
            // thread of its own would time-slice against both workers); on one thread it runs
            // after the search.
            let slot = std::sync::OnceLock::new();
            let (storage, mut count_buffers) = prefaulted.take().unzip();
            let out = rayon::in_place_scope(|scope| {
                let mut spawned = false;
                let mut early = |l: &[f64], next: f64| {
                    if early_ok && !spawned {
                        spawned = true;
                        let sig = band.early_check_shift(&known_before, l, next);
                        let (slot, buffers) = (&slot, count_buffers.take().flatten());
                        scope.spawn(move |_| {
                            let _ = slot.set((sig, f.inertia_at(sig, buffers)));
                        });
                    }
                };
                search(f, k, m, defl, &cfg, &enough, &mut early, &mut counters, storage, progress)
            });
            let early = slot.into_inner().and_then(|(sig, r)| r.ok().map(|nu| (sig, nu)));
            let hint = |e| stall_hint(e, count_below.then_some(elastic_below), opts.min_freq_hz);
            (out.map_err(hint)?, early)
        };
        known.merge(out.lambdas, out.vectors, out.residuals);

        // Select, polish, check.
        let t_check = Instant::now();
        progress(Progress::PhaseStart(Phase::Check));
        let sel: Vec<usize> = (0..known.lambdas.len())
            .filter(|&i| known.lambdas[i] >= lam_lo && known.lambdas[i] <= lam_hi)
            .take(cap)
            .collect();
        let capped = sel.len() == cap;
        let (lams, vecs, res) =
            if searches == 1 { known.select(n, &sel) } else { polish(k, m, &known, &sel)? };
        if !count_below {
            elastic_below = known.lambdas.iter().filter(|&&x| x < lam_lo).count();
        }
        stats.elastic_below_band = elastic_below;
        // Eigenvalues known below σ': rigid, below the band, and the known elastic ones in
        // [λ_lo, σ') — the returned ones plus converged ones beyond the cap (e.g. the rest of
        // a multiplet split by `max_modes`).
        let found_below = |sig: f64| {
            let in_check = known.lambdas.iter().filter(|&&x| x >= lam_lo && x < sig).count();
            n_rigid + elastic_below + in_check.max(lams.len())
        };
        let top = lams.last().copied().unwrap_or(f64::NEG_INFINITY);
        if early.is_some() {
            stats.factorizations += 1;
        }
        // The early count proves completeness below its σ' if σ' lies above every returned
        // mode and the count matches; otherwise count again at the final σ'.
        let (sigma_hi, nu_hi) = match early {
            Some((sig, nu)) if sig > top && nu == found_below(sig) => (sig, nu),
            _ => {
                let sig = upper_check_shift(&known.lambdas, &lams, capped, lam_hi);
                stats.factorizations += 1;
                (sig, inertia(&mut factor, sig)?)
            }
        };
        let found = found_below(sigma_hi);
        stats.inertia_expected = nu_hi;
        stats.inertia_found = found;
        stats.inertia_shift = sigma_hi;
        let dt = t_check.elapsed().as_secs_f64();
        check_s += dt;
        progress(Progress::PhaseEnd { phase: Phase::Check, seconds: dt });
        let worst = res
            .iter()
            .zip(&lams)
            .map(|(r, l)| r / attainable(opts.tolerance, *l, lam_scale))
            .fold(0.0, f64::max);
        if nu_hi == found && worst <= 1.0 {
            stats.block_solves = counters.block_solves;
            stats.residual_checks = counters.residual_checks;
            stats.block_solve_s = counters.block_solve_s;
            stats.orthogonalize_s = counters.orthogonalize_s;
            stats.residual_check_s = counters.residual_check_s;
            stats.iterations = counters.restarts;
            stats.check_s = check_s;
            stats.solve_s = t_iter.elapsed().as_secs_f64() - check_s;
            progress(Progress::PhaseEnd { phase: Phase::Iterate, seconds: stats.solve_s });
            return Ok(EigenSolution { eigenvalues: lams, vectors: vecs, residuals: res, stats });
        }
        if nu_hi < found || searches >= MAX_SEARCHES {
            return Err(EigenError::InertiaMismatch { expected: nu_hi, found });
        }
        // Missed modes: search again with everything found so far deflated.
        if !low_shift || factor.shift() != stats.shift {
            refactor_operator(&mut factor, stats.shift, low_shift)?;
            stats.factorizations += 1;
        }
        wanted = nu_hi - found + block;
        missing = Some((sigma_hi, nu_hi - found));
    }
}

/// Whether [`solve_validated`] counts the eigenvalues below the band without being asked to.
fn counts_below_band(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    opts: &EigenOptions,
) -> Result<bool, EigenError> {
    Ok(hz_to_lambda(opts.min_freq_hz) > LOW_EDGE_FRACTION * spectrum_scale(k, m)?)
}

/// Says in a stall error why the search stalled and what to change; `below`: the elastic
/// modes below the band if they were counted.
fn stall_hint(e: EigenError, below: Option<usize>, min_freq_hz: f64) -> EigenError {
    let EigenError::Stalled { converged, wanted, restarts, .. } = e else { return e };
    let hint = match below {
        Some(b) if b > 0 => format!(
            "{b} modes besides the rigid-body ones lie below {min_freq_hz} Hz: near-mechanisms (parts joined \
             by a hinge or a very thin neck) that the search cannot separate; raise the lower band edge above \
             them, or remesh the thin connections finer"
        ),
        Some(_) => "the wanted modes form clusters the search cannot separate; ask for fewer modes or a \
                    narrower band"
            .into(),
        None => "the lowest modes form a cluster the search cannot separate (near-mechanisms?)".into(),
    };
    EigenError::Stalled { converged, wanted, restarts, hint }
}

/// Bytes per DOF of the dense vectors a solve for `opts` holds at its peak (the basis, work
/// blocks and Ritz vectors of [`vector_bytes`]; part of `memory_estimate_bytes`), known
/// before any matrix exists: at a million DOF and 64 modes they take ≈ 9 GB, more than
/// most factors.
pub fn vector_bytes_per_dof(opts: &EigenOptions) -> u64 {
    let block = opts.block_size.max(1);
    let nev = opts.max_modes.saturating_add(MAX_BELOW_FOR_LOW_SHIFT);
    vector_bytes(1, nev, basis_size(nev, block), block)
}

/// Krylov basis size (columns, excluding the residual block) for `nev` wanted pairs:
/// `nev + max(nev, min(2·nev, EXTRA_BASIS), 3·block)`. A basis of about 3·nev for up to 50
/// modes measured 12 % fewer block solves than ARPACK's customary 2·nev (box, 30k DOF,
/// 50 modes: 29 instead of 33) and 1–2 restarts instead of 7; beyond that the extra columns are
/// capped so that orthogonalization and memory stay linear in nev.
fn basis_size(nev: usize, block: usize) -> usize {
    nev.saturating_add(nev.max(nev.saturating_mul(2).min(EXTRA_BASIS)).max(3 * block))
}

/// (nev, ncv) of a search for `wanted` pairs with `free` dimensions left after deflation.
fn search_size(wanted: usize, free: usize, block: usize) -> (usize, usize) {
    let nev = wanted.min(free);
    (nev, basis_size(nev, block).min(free.saturating_sub(block)))
}

/// Dense n-vectors the iteration holds at its peak: the basis V and its M-image (ncv + one
/// block each), a few blocks of work space, and the residual check's Ritz vectors with their
/// K- and M-images and rotated copies (six sets of up to `nev` vectors).
fn vector_bytes(n: usize, nev: usize, ncv: usize, block: usize) -> u64 {
    // Saturating: an absurd mode count must read as "too much memory", not wrap.
    let columns = (ncv as u64).saturating_add(block as u64).saturating_mul(2);
    let columns = columns.saturating_add(4 * block as u64).saturating_add((nev as u64).saturating_mul(6));
    (n as u64).saturating_mul(columns).saturating_mul(8)
}

/// Re-establishes the operator factor after an inertia factorization replaced it.
fn refactor_operator(f: &mut ShiftedFactor<'_>, sigma: f64, low: bool) -> Result<(), EigenError> {
    if low {
        f.factor_llt(sigma)
    } else {
        f.factor_ldlt(sigma)?;
        f.prepare_solves();
        Ok(())
    }
}

/// LDLᵀ inertia at σ, nudging σ by 1e-9 relative on an exactly zero pivot.
fn inertia(f: &mut ShiftedFactor<'_>, sigma: f64) -> Result<usize, EigenError> {
    match f.factor_ldlt(sigma) {
        Err(EigenError::ZeroPivot { .. }) => f.factor_ldlt(sigma * (1.0 - 1e-9)),
        r => r,
    }
}

/// σ' for the upper inertia count: f_max if the band was not capped, otherwise between the
/// highest returned eigenvalue and the next known one (or 1e-6 relative above it).
fn upper_check_shift(all: &[f64], returned: &[f64], capped: bool, lam_hi: f64) -> f64 {
    let Some(&top) = returned.last() else { return lam_hi };
    if !capped {
        return lam_hi;
    }
    let next = all.iter().cloned().filter(|&x| x > top * (1.0 + 1e-9)).fold(f64::INFINITY, f64::min);
    let bump = top * (1.0 + 1e-6);
    if next.is_finite() {
        (0.5 * (top + next)).min(bump)
    } else {
        bump
    }
}

/// The wanted band `[lo, hi]` (λ, rad²/s²) and the mode cap.
#[derive(Copy, Clone)]
struct Band {
    lo: f64,
    hi: f64,
    cap: usize,
}

impl Band {
    /// σ' the final check would use if the known eigenvalues plus the accurate Ritz values
    /// `early` (ascending, `next` the following Ritz value) were the converged ones.
    fn early_check_shift(&self, known: &[f64], early: &[f64], next: f64) -> f64 {
        let mut all: Vec<f64> = known.iter().chain(early).copied().collect();
        all.sort_by(f64::total_cmp);
        let sel: Vec<f64> =
            all.iter().copied().filter(|&x| x >= self.lo && x <= self.hi).take(self.cap).collect();
        if next.is_finite() {
            all.push(next);
        }
        upper_check_shift(&all, &sel, sel.len() == self.cap, self.hi)
    }
}

/// All converged eigenpairs so far (λ ascending).
#[derive(Default)]
struct Known {
    lambdas: Vec<f64>,
    vectors: Option<Mat<f64>>,
    residuals: Vec<f64>,
}

impl Known {
    /// Adds new pairs (M-orthogonal to all known ones: they were deflated) and sorts.
    fn merge(&mut self, l: Vec<f64>, v: Mat<f64>, r: Vec<f64>) {
        debug_assert_eq!(l.len(), r.len());
        // New pairs are M-orthogonal to everything deflated (old pairs and rigid modes).
        let mut lam = std::mem::take(&mut self.lambdas);
        lam.extend(&l);
        let mut res = std::mem::take(&mut self.residuals);
        res.extend(&r);
        let all = match self.vectors.take() {
            Some(old) => hcat(old.as_ref(), v.as_ref()),
            None => v.clone(),
        };
        let mut order: Vec<usize> = (0..lam.len()).collect();
        order.sort_by(|&a, &b| lam[a].total_cmp(&lam[b]));
        let mut sorted = Mat::<f64>::zeros(all.nrows(), order.len());
        for (c, &o) in order.iter().enumerate() {
            sorted.as_mut().col_mut(c).copy_from(all.col(o));
        }
        self.lambdas = order.iter().map(|&o| lam[o]).collect();
        self.residuals = order.iter().map(|&o| res[o]).collect();
        self.vectors = Some(sorted);
    }

    /// The pairs `sel` as they are. Valid as final answer when they all come from one search:
    /// its last Rayleigh–Ritz on (K, M) already made them K- and M-orthogonal and computed
    /// their residuals, so a second Rayleigh–Ritz (see [`polish`]) would only repeat it.
    fn select(&self, n: usize, sel: &[usize]) -> RitzSet {
        let Some(all) = &self.vectors else { return (Vec::new(), Mat::zeros(n, 0), Vec::new()) };
        let mut w = Mat::<f64>::zeros(all.nrows(), sel.len());
        for (c, &i) in sel.iter().enumerate() {
            w.as_mut().col_mut(c).copy_from(all.col(i));
        }
        (sel.iter().map(|&i| self.lambdas[i]).collect(), w, sel.iter().map(|&i| self.residuals[i]).collect())
    }
}

/// Final Rayleigh–Ritz on the selected known vectors (pairs from several searches).
fn polish(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    known: &Known,
    sel: &[usize],
) -> Result<RitzSet, EigenError> {
    let n = k.nrows();
    let Some(all) = &known.vectors else { return Ok((Vec::new(), Mat::zeros(n, 0), Vec::new())) };
    let mut y = Mat::<f64>::zeros(n, sel.len());
    for (c, &i) in sel.iter().enumerate() {
        y.as_mut().col_mut(c).copy_from(all.col(i));
    }
    rayleigh_ritz_kM(k, m, y)
}

/// Dense fallback for tiny problems: every eigenpair of the deflated problem.
fn dense_all(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    defl: &Deflation,
) -> Result<crate::krylov::KsOutput, EigenError> {
    let n = k.nrows();
    let mut q = Mat::<f64>::identity(n, n);
    defl.project_out(q.as_mut());
    defl.project_out(q.as_mut());
    let (rank, _) = svqb(m, q.as_mut(), 1e-7);
    let q = q.as_ref().subcols(0, rank.min(n - defl.len()));
    if q.ncols() == 0 {
        let empty = Mat::zeros(n, 0);
        return Ok(crate::krylov::KsOutput {
            lambdas: Vec::new(),
            vectors: empty,
            residuals: Vec::new(),
            restarts: 0,
            block_solves: 0,
        });
    }
    let kq0 = spmm(k, q);
    let kq = tmul(q, kq0.as_ref());
    let (lambdas, u) =
        sym_eig(kq.as_ref()).ok_or_else(|| EigenError::Factorization("dense eigensolver failed".into()))?;
    let mut w = Mat::<f64>::zeros(n, q.ncols());
    matmul(w.as_mut(), Accum::Replace, q, u.as_ref(), 1.0, Par::Seq);
    let residuals = residuals(k, m, &lambdas, w.as_ref());
    Ok(crate::krylov::KsOutput { lambdas, vectors: w, residuals, restarts: 0, block_solves: 0 })
}

/// Ordering and symbolic factorization of the pattern of K (full or upper storage, sorted
/// rows, every diagonal entry present) for [`solve_analyzed`]: they depend on the pattern
/// only, so they can be made while K and M are assembled.
pub fn analyze(
    pattern: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
    ordering: Ordering,
) -> Result<Analysis, EigenError> {
    Analysis::new(pattern, matches!(ordering, Ordering::Metis | Ordering::Auto))
}

/// maxᵢ Kᵢᵢ / Mᵢᵢ, an estimate of the top of the spectrum; errors on Mᵢᵢ ≤ 0.
fn spectrum_scale(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
) -> Result<f64, EigenError> {
    let diag = |a: SparseColMatRef<'_, usize, f64>, j: usize| -> f64 {
        let rows = a.symbolic().row_idx_of_col_raw(j);
        let vals = a.val_of_col(j);
        rows.iter().zip(vals).filter(|(&r, _)| r == j).map(|(_, &v)| v).sum()
    };
    let mut scale = 0.0f64;
    for j in 0..k.ncols() {
        let mj = diag(m, j);
        if mj <= 0.0 || mj.is_nan() {
            return Err(EigenError::MassNotPositive { dof: j });
        }
        scale = scale.max(diag(k, j) / mj);
    }
    if scale <= 0.0 || scale.is_nan() {
        return Err(EigenError::InvalidOption {
            name: "K",
            reason: "stiffness matrix has no positive diagonal entry".into(),
        });
    }
    Ok(scale)
}

/// 75 % of MemAvailable from /proc/meminfo.
/// The solver's default memory limit: 75 % of the available memory
/// (`MemAvailable` in `/proc/meminfo`), `None` where that is unknown.
pub fn default_memory_limit() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024 / 4 * 3)
}

fn validate(
    k: SparseColMatRef<'_, usize, f64>,
    m: SparseColMatRef<'_, usize, f64>,
    rigid: Option<MatRef<'_, f64>>,
    o: &EigenOptions,
) -> Result<(), EigenError> {
    if k.nrows() != k.ncols() || m.nrows() != m.ncols() || k.nrows() != m.nrows() || k.nrows() == 0 {
        return Err(EigenError::Shape {
            k_rows: k.nrows(),
            k_cols: k.ncols(),
            m_rows: m.nrows(),
            m_cols: m.ncols(),
        });
    }
    for (name, a) in [("K", k), ("M", m)] {
        for j in 0..a.ncols() {
            let rows = a.symbolic().row_idx_of_col_raw(j);
            if let Some(p) = a.val_of_col(j).iter().position(|v| !v.is_finite()) {
                return Err(EigenError::NonFinite { matrix: name, row: rows[p], col: j });
            }
        }
    }
    if let Some(r) = rigid {
        if r.nrows() != k.nrows() {
            return Err(EigenError::RigidShape { rows: r.nrows(), expected: k.nrows() });
        }
        for j in 0..r.ncols() {
            for i in 0..r.nrows() {
                if !r[(i, j)].is_finite() {
                    return Err(EigenError::NonFinite { matrix: "rigid fields", row: i, col: j });
                }
            }
        }
    }
    let bad =
        |name: &'static str, reason: &str| Err(EigenError::InvalidOption { name, reason: reason.into() });
    if o.min_freq_hz < 0.0 || !o.min_freq_hz.is_finite() {
        return bad("min_freq_hz", "must be finite and >= 0");
    }
    if o.max_freq_hz <= o.min_freq_hz || !o.max_freq_hz.is_finite() {
        return bad("max_freq_hz", "must be finite and above min_freq_hz");
    }
    if o.max_modes == 0 {
        return bad("max_modes", "must be at least 1");
    }
    if !(o.tolerance > 0.0 && o.tolerance < 1e-2) {
        return bad("tolerance", "must be in (0, 1e-2)");
    }
    if o.block_size == 0 || o.block_size > 64 {
        return bad("block_size", "must be in 1..=64");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_absurd_mode_count_saturates_the_memory_estimate_instead_of_wrapping() {
        // Wrapped, `usize::MAX` modes read as a few bytes and the solve went ahead.
        let nev = usize::MAX.saturating_add(MAX_BELOW_FOR_LOW_SHIFT);
        assert_eq!(vector_bytes(4149, nev, basis_size(nev, 8), 8), u64::MAX);
        let message = EigenError::MemoryLimit {
            estimated: u64::MAX,
            limit: 1 << 30,
            search_space: u64::MAX,
            modes: nev,
        }
        .to_string();
        assert!(message.contains("ask for fewer modes"), "{message}");
        let mesh_bound =
            EigenError::MemoryLimit { estimated: 4 << 30, limit: 1 << 30, search_space: 1 << 20, modes: 64 }
                .to_string();
        assert!(mesh_bound.contains("coarser mesh"), "{mesh_bound}");
    }
}
