//! Running a batch: every asset through `modal-precompute` and the
//! content-addressed cache, with a catalogue kept current on disk.
//!
//! Per asset: (1) a bank already in the output directory whose
//! `input_hash` equals the asset's cache key (and, with `transfer_max_freq`,
//! which stores that transfer) is taken as finished (a killed run resumes
//! even without a shared cache); (2) otherwise the pipeline runs, served
//! from the cache when it holds the key (a damaged or torn cache entry is
//! detected by the bank checksum and recomputed), and with
//! `transfer_max_freq` the acoustic transfer of its audible modes is solved
//! (`modal_radiation::modes::transfer_table`, default air); (3) the bank is
//! written atomically into the output directory, the transfer stored in it
//! (format 2). Any error, even a panic, becomes the asset's catalogue
//! `status`; the batch goes on.
//!
//! The catalogue is rewritten atomically as assets finish, listing the
//! assets not finished yet under `pending`, so a killed run leaves an honest
//! partial catalogue behind: at most every [`SNAPSHOT_INTERVAL`] (rewriting
//! it after each of 3 000 instant assets wrote 1.9 GB), and at the end. A
//! run killed in between lists its last assets as pending; a re-run finds
//! their banks finished.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use modal_bank::{BankCache, ModeBank};
use modal_precompute::cache_key;
use modal_radiation::modes::{audible_modes, is_transfer_table_of, transfer_table};
use modal_radiation::RadiationOptions;

use crate::terms::in_manifest_terms;
use crate::{Asset, BatchError, Catalogue, CatalogueEntry, Shard};

/// The shortest time between two rewrites of the catalogue during a run.
pub const SNAPSHOT_INTERVAL: Duration = Duration::from_secs(2);

/// How to run a batch.
#[derive(Clone, Debug)]
pub struct BatchOptions {
    /// Directory receiving the banks and the catalogue.
    pub out_dir: PathBuf,
    /// The shared bank cache (`None`: no cache; only finished banks in
    /// `out_dir` are reused).
    pub cache: Option<BankCache>,
    /// Assets solved at the same time (at least 1).
    pub jobs: usize,
    /// Recompute even what is cached or finished.
    pub force: bool,
    /// Solver threads per asset (`None`: the pipeline's default).
    pub threads: Option<usize>,
    /// The shard being run (names the catalogue file).
    pub shard: Shard,
    /// The whole library (all shards), recorded in the catalogue so a merge
    /// can tell the shards of one run from those of another.
    pub library: Option<crate::Library>,
}

/// Progress of a batch, for the CLI's display.
#[derive(Clone, Copy, Debug)]
pub enum Event<'a> {
    /// An asset was started.
    Started {
        /// The asset.
        asset: &'a Asset,
    },
    /// An asset finished (successfully or not).
    Finished {
        /// The asset.
        asset: &'a Asset,
        /// Its catalogue entry, with the warnings for the user (mesh fixes, a
        /// damaged cache entry, ...).
        entry: &'a CatalogueEntry,
    },
}

/// Runs `assets` (one shard's) and returns the final catalogue, also
/// written to `out_dir`/[`Catalogue::file_name`]. Fails only when the
/// catalogue cannot be written; failing assets are catalogue entries.
pub fn run_batch(
    assets: &[Asset],
    options: &BatchOptions,
    on_event: &(dyn Fn(Event<'_>) + Sync),
) -> Result<Catalogue, BatchError> {
    let path = options.out_dir.join(Catalogue::file_name(options.shard));
    let pending: Vec<(String, String)> = assets.iter().map(|a| (a.path.clone(), a.bank.clone())).collect();
    let catalogue_of = |done: Vec<CatalogueEntry>, pending: Vec<(String, String)>| Catalogue {
        library: options.library.clone(),
        ..Catalogue::new(done, pending, options.shard)
    };
    catalogue_of(Vec::new(), pending.clone()).save(&path)?;
    struct State {
        done: Vec<CatalogueEntry>,
        pending: Vec<(String, String)>,
        write_error: Option<BatchError>,
        saved: Instant,
    }
    let state = Mutex::new(State { done: Vec::new(), pending, write_error: None, saved: Instant::now() });
    let next = AtomicUsize::new(0);
    let worker = || loop {
        let i = next.fetch_add(1, Ordering::Relaxed);
        let Some(asset) = assets.get(i) else { break };
        on_event(Event::Started { asset });
        let entry = run_asset(asset, options);
        {
            let mut s = state.lock().unwrap_or_else(|e| e.into_inner());
            s.done.push(entry.clone());
            // By bank: one file listed twice (two materials) is two assets.
            if let Some(at) = s.pending.iter().position(|(_, bank)| *bank == asset.bank) {
                s.pending.remove(at);
            }
            if s.saved.elapsed() >= SNAPSHOT_INTERVAL {
                let snapshot = catalogue_of(s.done.clone(), s.pending.clone());
                if let Err(e) = snapshot.save(&path) {
                    s.write_error.get_or_insert(e);
                }
                s.saved = Instant::now();
            }
        }
        on_event(Event::Finished { asset, entry: &entry });
    };
    let jobs = options.jobs.clamp(1, assets.len().max(1));
    std::thread::scope(|scope| {
        for _ in 1..jobs {
            scope.spawn(worker);
        }
        worker();
    });
    let s = state.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(e) = s.write_error {
        return Err(e);
    }
    let catalogue = catalogue_of(s.done, s.pending);
    catalogue.save(&path)?;
    Ok(catalogue)
}

/// Runs one asset; never fails: errors (and panics) become the entry's status.
pub fn run_asset(asset: &Asset, options: &BatchOptions) -> CatalogueEntry {
    let start = Instant::now();
    let mut request = asset.request.clone();
    request.threads = options.threads;
    let hash = cache_key(&request).ok();
    let mut warnings = asset.warnings.clone();
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        solve(asset, &request, hash.as_deref(), options, &mut warnings)
    }))
    .unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(format!("internal error (please report): {what}"))
    });
    let seconds = start.elapsed().as_secs_f64();
    match outcome {
        Ok(Solved { bank, transfer_modes, cached }) => {
            let size_m = modal_mesh::bounding_diagonal(&bank.surface.positions);
            // A reused bank's file was not read again, but its size still says whether
            // the file was in metres (a solve says so when it reads the file).
            let size_warning = modal_mesh::unit_warning(size_m).filter(|_| cached && !request.scale_stated);
            warnings.extend(size_warning.map(|w| format!("{}: {}", asset.path, in_manifest_terms(&w))));
            CatalogueEntry {
                path: asset.path.clone(),
                bank: Some(asset.bank.clone()),
                id: asset.bank.clone(),
                hash: Some(bank.info.input_hash.clone()),
                modes: bank.frequencies_hz.len(),
                first_frequency_hz: bank.frequencies_hz.first().copied(),
                transfer_modes,
                seconds,
                status: "ok".into(),
                cached,
                mass_kg: Some(bank.mass.mass_kg),
                size_m: Some(size_m),
                warnings,
            }
        }
        Err(status) => CatalogueEntry {
            path: asset.path.clone(),
            bank: None,
            id: asset.bank.clone(),
            hash,
            modes: 0,
            first_frequency_hz: None,
            transfer_modes: 0,
            seconds,
            status,
            cached: false,
            mass_kg: None,
            size_m: None,
            warnings,
        },
    }
}

/// Makes the directory of the bank `out` and checks that a file can be made
/// there and that `out` is no directory (another asset's bank may need one
/// by that name): the asset fails at once, not after its solve.
fn writable(out: &Path) -> Result<(), String> {
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    if out.is_dir() {
        return Err(format!("cannot write bank {}: a directory of that name is in the way", out.display()));
    }
    let probe = tempfile::Builder::new().prefix(".modal-probe-").tempfile_in(dir);
    probe.map(drop).map_err(|e| format!("cannot write bank {}: {e}", out.display()))
}

/// An asset's bank as written to the output directory.
struct Solved {
    bank: ModeBank,
    /// Modes with a stored transfer.
    transfer_modes: usize,
    /// Reused (finished, or served from the cache with nothing solved).
    cached: bool,
}

/// The bank of `asset`, with its transfer when asked, and whether it was
/// reused (finished or cached).
fn solve(
    asset: &Asset,
    request: &modal_precompute::Request,
    hash: Option<&str>,
    options: &BatchOptions,
    warnings: &mut Vec<String>,
) -> Result<Solved, String> {
    let out = options.out_dir.join(&asset.bank);
    let radiation = RadiationOptions::default();
    if let (Some(hash), false, true) = (hash, options.force, out.exists()) {
        match ModeBank::load_with_radiation(&out) {
            Ok((bank, table)) if bank.info.input_hash == hash => {
                let stored = match (asset.transfer_max_hz, &table) {
                    (None, _) => Some(table.map_or(0, |t| t.modes.len())),
                    (Some(f), Some(t)) => {
                        is_transfer_table_of(t, &bank, f, &radiation).then_some(t.modes.len())
                    }
                    (Some(f), None) => audible_modes(&bank, f).is_empty().then_some(0),
                };
                if let Some(transfer_modes) = stored {
                    return Ok(Solved { bank, transfer_modes, cached: true });
                }
            }
            Ok(_) => {}
            Err(e) => {
                warnings.push(format!("{}: replacing the damaged bank {} ({e})", asset.path, out.display()))
            }
        }
    }
    // Where the bank goes is made ready before the solve, not found unwritable after it.
    writable(&out)?;
    let outcome = modal_precompute::precompute(request, options.cache.as_ref(), options.force, &mut |_| {})
        .map_err(|e| in_manifest_terms(&chain(&e)))?;
    warnings.extend(outcome.warnings.iter().map(|w| format!("{}: {}", asset.path, in_manifest_terms(w))));
    let table = match asset.transfer_max_hz {
        Some(f) => in_pool(options.threads, || transfer_table(&outcome.bank, f, &radiation, &mut |_| {}))?
            .map_err(|e| format!("acoustic transfer: {}", chain(&e)))?,
        None => None,
    };
    let written = match &table {
        Some(t) => outcome.bank.save_with_radiation(&out, t),
        None => outcome.bank.save(&out),
    };
    written.map_err(|e| format!("cannot write bank {}: {}", out.display(), chain(&e)))?;
    Ok(Solved {
        transfer_modes: table.as_ref().map_or(0, |t| t.modes.len()),
        cached: outcome.cached && table.is_none(),
        bank: outcome.bank,
    })
}

/// `f` on `threads` threads (`None`: rayon's global pool).
fn in_pool<T: Send>(threads: Option<usize>, f: impl FnOnce() -> T + Send) -> Result<T, String> {
    match threads {
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| format!("cannot start {n} threads: {e}"))?
            .install(f)),
        None => Ok(f()),
    }
}

/// An error and its causes, `": "`-separated, each said once.
fn chain(err: &dyn std::error::Error) -> String {
    let mut text = err.to_string();
    let mut source = err.source();
    while let Some(cause) = source {
        let s = cause.to_string();
        if !text.contains(&s) {
            text = format!("{text}: {s}");
        }
        source = cause.source();
    }
    text
}
