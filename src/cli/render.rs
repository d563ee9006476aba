//! `modal render` (and `modal` with no arguments): simulate a rigid-body
//! scene and write what its listener hears.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{Context, Result};
use modal_bank::{BankCache, CacheKey, ModeBank, RadiationTable};
use modal_fem::Material;
use modal_mesh::generate::ElementSizes;
use modal_mesh::{Cells, TetMesh};
use modal_precompute::{MeshSource, Request};
use modal_scene::{BankProvider, BankRequest, ProvidedBank, ProviderError, Scene};
use modal_synth::WavFormat;

use super::args::{RadiationChoice, RenderArgs};
use super::interrupt;
use super::output::{print_json, warn};
use super::precompute::{memory_limit_from_env, open_cache};
use super::progress::Spinner;
use super::scene_warnings;

/// Default `--transfer-max-freq` [Hz]: modes up to it get their acoustic
/// transfer solved (once per asset, cached), higher ones keep the level
/// estimate. Measured (BENCHMARKS.md, "Cost today", 2026-11-26): the
/// demo's three assets cost about 15 s at this cap on 2 cores (against
/// 2.5–3 s of eigen solves), every playable mode about 4 minutes.
pub const DEFAULT_TRANSFER_MAX_HZ: f64 = 6000.0;

/// Where the demo is written when no output is given.
pub const DEMO_OUTPUT: &str = "audio_out/demo.wav";

/// Serves scene objects' banks through the precompute pipeline and its cache.
struct PipelineProvider<'a> {
    cache: Option<BankCache>,
    spinner: &'a Spinner,
    threads: Option<usize>,
    /// Warnings to print once the spinner is gone.
    warnings: Vec<String>,
    /// Assets served from the cache and solved fresh.
    cached: usize,
    solved: usize,
    /// Serve cached banks in two steps (surface and mass first, the shapes
    /// verified while the physics runs).
    defer: bool,
    /// Set when a deferred entry failed its verification.
    deferred_failed: Arc<AtomicBool>,
    /// Acoustic transfers solved in this run: (asset, modes, seconds).
    radiation_solved: Vec<(String, usize, f64)>,
    /// Highest mode frequency whose transfer is solved [Hz] (`--transfer-max-freq`).
    transfer_max_hz: f64,
    /// The solver's memory guard [bytes] when `MODAL_MEMORY_LIMIT_GB` sets it
    /// (else the eigensolver's default).
    memory_limit_bytes: Option<u64>,
    /// Bank files retuned to their object's material or scale, each with its
    /// stored transfer as it carries over (`None`: it does not, or none) and
    /// whether the file stored one.
    retuned: Vec<(BankRequest, Option<RadiationTable>, bool)>,
    /// `--accuracy` of surface-mesh objects (`None`: one solve, no estimate).
    accuracy: Option<modal_precompute::AccuracyTarget>,
}

/// Refuses a generated shape whose quadratic mesh could not fit the memory
/// guard, from its exact tet count alone and before generating it (a
/// 3.3 M-tet tube took 50 s to generate only to be refused by the
/// assembly's own check): K and M of `T` 10-node tets hold at least
/// [`modal_fem::min_quadratic_matrices_bytes`]. Linear meshes have no such
/// bound per tet and are left to that check.
fn refuse_beyond_memory(
    shape: &modal_mesh::generate::Shape,
    sizes: modal_mesh::generate::ElementSizes,
    order: u8,
    limit_bytes: Option<u64>,
    what: &str,
) -> Result<(), ProviderError> {
    if order != 2 {
        return Ok(());
    }
    let Some(limit) = limit_bytes.or_else(modal_eigen::default_memory_limit) else { return Ok(()) };
    let tets = shape.tet_count(sizes);
    let needed = modal_fem::min_quadratic_matrices_bytes(tets);
    if needed <= limit {
        return Ok(());
    }
    Err(format!(
        "{what}: its element size {:.3e} m gives {tets} quadratic tets, whose stiffness and mass matrices alone \
         would need at least {:.2} GB, above the memory limit of {:.2} GB; give a larger element_size",
        sizes.h,
        needed as f64 / 1e9,
        limit as f64 / 1e9
    )
    .into())
}

impl BankProvider for PipelineProvider<'_> {
    fn bank(&mut self, request: &BankRequest) -> Result<Arc<ModeBank>, ProviderError> {
        if let Some(path) = &request.bank {
            if request.material.is_some() || request.scale.is_some() {
                return self.retuned_bank_file(request, path).map(Arc::new);
            }
            if modal_export::gltf::is_gltf_path(path) {
                let imported = modal_export::gltf::import_gltf_file(path)?;
                self.warnings.extend(imported.warnings.iter().map(|w| format!("{}: {w}", path.display())));
                return Ok(Arc::new(imported.bank));
            }
            return Ok(Arc::new(ModeBank::load(path)?));
        }
        let mesh = request.mesh.as_ref().ok_or("the object names neither a mesh nor a bank")?;
        if let modal_scene::MeshSource::File(path) = mesh {
            // A glTF holding a modal model is a bank, as `modal precompute` reads it.
            if modal_export::gltf::is_gltf_path(path) && modal_export::gltf::holds_modal_model(path)? {
                self.warnings.push(format!(
                    "{}: holds a modal model: used as the object's bank, retuned to its material \
                     (`bank = ...` says so without this warning)",
                    path.display()
                ));
                return self.retuned_bank_file(request, path).map(Arc::new);
            }
        }
        let material = request.material.clone().ok_or("an object given as a mesh needs a material")?;
        let what = describe(mesh);
        let source = match mesh {
            modal_scene::MeshSource::File(path) => MeshSource::File(path.clone()),
            modal_scene::MeshSource::Generate(spec) => {
                let (shape, sizes, order, identity) = recipe(spec, request)?;
                // The cache key of a generated mesh is its recipe: a cached
                // bank is served without generating the mesh at all.
                if let Some(bank) = self.cached_generated(request, &material, &identity, &what)? {
                    return Ok(bank);
                }
                refuse_beyond_memory(&shape, sizes, order, self.memory_limit_bytes, &what)?;
                // At the requested order, so curved shapes get curved (P2) boundaries.
                let mesh = modal_mesh::generate::generate_sized(&shape, sizes, order)?;
                MeshSource::Memory { mesh, identity }
            }
        };
        let pipeline = self.request(request, material, source);
        self.spinner.set(format!("mode bank for {what}"));
        // A solve can take minutes: say so on stderr (also in a log, where
        // the spinner is hidden) when the first level is assembled, i.e.
        // only when the bank is not cached.
        let spinner = self.spinner;
        let started = std::time::Instant::now();
        let mut announced = false;
        let outcome = modal_precompute::precompute(&pipeline, self.cache.as_ref(), false, &mut |stage| {
            if let modal_precompute::Stage::Assemble { dofs } = stage {
                if !announced {
                    spinner
                        .note(&format!("mode bank for {what}: solving {dofs} DOF once (cached afterwards)"));
                    announced = true;
                }
                spinner.set(format!("mode bank for {what}: {dofs} DOF"));
            }
        })
        .map_err(|e| format!("{what}: {e}"))?;
        if announced {
            spinner.note(&format!(
                "mode bank for {what}: {} mode(s) in {:.1} s",
                outcome.bank.mode_count(),
                started.elapsed().as_secs_f64()
            ));
        }
        self.warnings.extend(outcome.warnings.into_iter().map(|w| format!("{what}: {w}")));
        self.warnings.extend(mode_count_warning(request, &outcome.bank).map(|w| format!("{what}: {w}")));
        if outcome.cached {
            self.cached += 1;
        } else {
            self.solved += 1;
        }
        Ok(Arc::new(outcome.bank))
    }

    fn provide(&mut self, request: &BankRequest) -> Result<ProvidedBank, ProviderError> {
        if self.defer {
            if let Some(pending) = self.cached_generated_deferred(request)? {
                return Ok(pending);
            }
        }
        self.bank(request).map(ProvidedBank::Ready)
    }

    /// A bank file's stored table; for a mesh, the cached table or a
    /// solve now (then cached). Failures become a warning and the estimate.
    fn radiation(
        &mut self,
        request: &BankRequest,
        bank: &Arc<ModeBank>,
    ) -> Result<Option<Arc<RadiationTable>>, ProviderError> {
        let what = match (&request.mesh, &request.bank) {
            (Some(mesh), _) => describe(mesh),
            (None, Some(path)) => path.display().to_string(),
            (None, None) => return Ok(None),
        };
        if let Some((_, table, stored)) = self.retuned.iter().find(|(r, _, _)| r == request) {
            match (table, stored) {
                (Some(_), _) => {}
                (None, false) => self.warnings.push(format!(
                    "{what} has no radiation table: its level is a pulsating-sphere estimate \
                     (run `modal radiation BANK --store OUT.bank`)"
                )),
                (None, true) => self.warnings.push(format!(
                    "{what}, retuned to the object's material or scale: its stored transfer does not carry \
                     over (every mode moved to a new ka): its level is a pulsating-sphere estimate"
                )),
            }
            return Ok(table.clone().map(Arc::new));
        }
        if let Some(path) = &request.bank {
            let table = super::listener::stored_radiation(path)?;
            if table.is_none() {
                self.warnings.push(format!(
                    "{what} has no radiation table: its level is a pulsating-sphere estimate \
                     (run `modal radiation BANK --store OUT.bank`)"
                ));
            }
            return Ok(table.map(Arc::new));
        }
        match self.solved_radiation(request, bank, &what) {
            Ok(table) => Ok(table),
            Err(e) => {
                self.warnings.push(format!("{what}: no acoustic transfer ({e}); its level is estimated"));
                Ok(None)
            }
        }
    }
}

/// A generator recipe resolved: shape, element size, order and the identity
/// that keys its bank in the cache.
fn recipe(
    spec: &modal_scene::GeneratorSpec,
    request: &BankRequest,
) -> Result<(modal_mesh::generate::Shape, ElementSizes, u8, String), ProviderError> {
    let shape = spec.shape()?;
    let order = request.order.unwrap_or(2);
    let sizes = spec.element_size.map_or_else(|| shape.default_sizes(order), ElementSizes::uniform);
    let mut identity = format!("generated {shape:?} h={:e}", sizes.h);
    if sizes.axial != sizes.h {
        identity.push_str(&format!(" axial={:e}", sizes.axial));
    }
    Ok((shape, sizes, order, identity))
}

impl PipelineProvider<'_> {
    /// A bank file retuned to its object's `material` and `scale`
    /// (docs/scene-format.md): E and ρ scale the frequencies, the bank's ν is
    /// kept (said when the material's differs), and the stored transfer
    /// carries over only when the retune keeps every mode's ka.
    fn retuned_bank_file(&mut self, request: &BankRequest, path: &Path) -> Result<ModeBank, ProviderError> {
        let (bank, table) = if modal_export::gltf::is_gltf_path(path) {
            let imported = modal_export::gltf::import_gltf_file(path)?;
            self.warnings.extend(imported.warnings.iter().map(|w| format!("{}: {w}", path.display())));
            (imported.bank, imported.radiation)
        } else {
            ModeBank::load_with_radiation(path)?
        };
        let material = request.material.clone().map(|material| {
            let (material, asked) = modal_bank::keeping_poisson(&bank, material);
            if let Some(asked) = asked {
                let said = super::bank_cmds::poisson_kept_warning(&bank, &material, asked);
                self.warnings.push(format!("{}: {said}", path.display()));
            }
            material
        });
        let spec = modal_bank::RetuneSpec { material, scale: request.scale };
        let retuned =
            modal_bank::retune(&bank, spec.clone()).map_err(|e| format!("{}: {e}", path.display()))?;
        let stored = table.is_some();
        let table = table.and_then(|t| modal_bank::retune_radiation(&bank, &t, &spec));
        self.retuned.push((request.clone(), table, stored));
        Ok(retuned)
    }

    /// The transfer of a mesh asset's bank: from the cache entry keyed by
    /// the bank's key and the radiation settings, or solved now and cached.
    fn solved_radiation(
        &mut self,
        request: &BankRequest,
        bank: &ModeBank,
        what: &str,
    ) -> Result<Option<Arc<RadiationTable>>, ProviderError> {
        let opts = modal_radiation::RadiationOptions::default();
        // Modes the synthesizer can play (below 0.45 fs, audible, not overdamped).
        let playable = modal_synth::MAX_FREQUENCY_FRACTION * 2.0 * request.max_frequency_hz;
        let top = playable.min(self.transfer_max_hz);
        let modes: Vec<usize> = (0..bank.mode_count())
            .filter(|&i| {
                let fd = bank.damped_frequency_hz(i);
                fd >= modal_synth::MIN_FREQUENCY_HZ && fd < top && bank.damping_ratios[i] < 1.0
            })
            .collect();
        let above = (0..bank.mode_count())
            .filter(|&i| {
                let fd = bank.damped_frequency_hz(i);
                fd >= top && fd < playable && bank.damping_ratios[i] < 1.0
            })
            .count();
        let entry = match (&self.cache, self.bank_key(request)?) {
            (Some(cache), Some(key)) => {
                // v2: geometry-only near field (modal_radiation::near); v3: node normals
                // fitted to the surface (modal_radiation::normals); v4: far clusters summed
                // as points (modal_radiation::assembly); v5: 3-point rule for far panels at
                // 1 < k·h ≤ 2; v6: default pressure clusters κ = 0.3 (was 0.5); v7: compressed
                // (H-matrix, ACA) assembly from 4 000 unknowns; v13: kernel points
                // evaluated in SIMD lanes (levels within 0.0001 dB, other bits); v14:
                // compressed assembly from 2 000 unknowns; v15: each panel the exact mean of
                // its triangle's interpolated velocity (modal_radiation::velocity); v16: ACA's
                // right-hand-side parts balanced on a block's first row and column (≤ 0.1 dB);
                // v17: the conventional equation below the interior resonances' bound
                // (modal_radiation::bem::Formulation::Automatic).
                let key = CacheKey::new("modal-radiation-v17")
                    .add_str("bank", &key)
                    .add_f64("air_density_kg_m3", opts.air.density_kg_m3)
                    .add_f64("sound_speed_m_s", opts.air.sound_speed_m_s)
                    .add_f64("multipole_tolerance", opts.multipole_tolerance)
                    .add_f64("top_hz", top)
                    .finish();
                Some(cache.path_for(&key)?)
            }
            _ => None,
        };
        if let Some(path) = entry.as_ref().filter(|p| p.exists()) {
            match ModeBank::load_with_radiation(path) {
                Ok((cached, Some(table))) if cached.frequencies_hz == bank.frequencies_hz => {
                    return Ok(Some(Arc::new(table)));
                }
                _ => self
                    .warnings
                    .push(format!("{what}: damaged radiation cache entry {}: solving again", path.display())),
            }
        }
        if modes.is_empty() {
            // Nothing to solve: every playable mode is above the cap (or none is playable).
            if above > 0 {
                self.spinner.note(&format!(
                    "acoustic transfer of {what}: its {above} playable mode(s) are above {top:.0} Hz: \
                     level estimate (--transfer-max-freq)"
                ));
            }
            return Ok(None);
        }
        let mesh = modal_radiation::modes::boundary_mesh(bank)?;
        let started = std::time::Instant::now();
        let spinner = self.spinner;
        let capped = if above > 0 {
            format!("; {above} mode(s) above {top:.0} Hz keep the level estimate (--transfer-max-freq)")
        } else {
            String::new()
        };
        spinner.note(&format!(
            "acoustic transfer of {what}: solving {} mode(s) on {} panels once (cached afterwards; \
             --radiation estimate skips it){capped}",
            modes.len(),
            mesh.len()
        ));
        let results = modal_radiation::modes::radiate_modes_on(bank, &mesh, &modes, &opts, &mut |p| {
            spinner.set(format!(
                "acoustic transfer of {what}: {}/{} at {:.0} Hz, {} unknowns on {} panels, {:.1} s",
                p.groups_done,
                p.groups,
                p.frequency_hz,
                p.unknowns,
                p.panels,
                p.solve_s + p.fit_s
            ))
        })?;
        let table = modal_radiation::modes::to_table(&results, &opts).ok_or("no audible mode")?;
        self.radiation_solved.push((what.to_string(), results.len(), started.elapsed().as_secs_f64()));
        if let Some(path) = &entry {
            if let Err(e) = bank.save_with_radiation(path, &table) {
                self.warnings.push(format!("{what}: cannot cache the acoustic transfer: {e}"));
            }
        }
        Ok(Some(Arc::new(table)))
    }

    /// The cache key of a mesh asset's bank (`None` for bank files).
    fn bank_key(&self, request: &BankRequest) -> Result<Option<String>, ProviderError> {
        let Some(material) = &request.material else { return Ok(None) };
        Ok(Some(match &request.mesh {
            Some(modal_scene::MeshSource::Generate(spec)) => {
                let (_, _, _, identity) = recipe(spec, request)?;
                self.generated_key(request, material, &identity)?
            }
            Some(modal_scene::MeshSource::File(path)) => modal_precompute::cache_key(&self.request(
                request,
                material.clone(),
                MeshSource::File(path.clone()),
            ))?,
            None => return Ok(None),
        }))
    }

    /// The precompute request for a scene object's bank.
    fn request(&self, request: &BankRequest, material: Material, source: MeshSource) -> Request {
        let mut pipeline = Request::new(source, material);
        pipeline.scale = request.scale.unwrap_or(1.0);
        pipeline.scale_stated = request.scale.is_some();
        pipeline.surface.sheet_thickness = request.sheet_thickness;
        pipeline.order = request.order.unwrap_or(2);
        // No modes above the scene's Nyquist frequency are worth solving for;
        // rounded up to a standard band, so 44.1 and 48 kHz share a bank.
        pipeline.max_freq_hz = request.band_to_solve_hz();
        pipeline.max_modes = request.max_modes.unwrap_or(modal_scene::DEFAULT_SCENE_MODES);
        pipeline.threads = self.threads;
        pipeline.memory_limit_bytes = self.memory_limit_bytes;
        // As `precompute` solves a surface mesh (a tet mesh or a generated
        // shape is solved as given, and would only be told so).
        if modal_precompute::remeshable(&pipeline.source) {
            pipeline.accuracy = self.accuracy.clone();
        }
        pipeline
    }

    /// The cache key of the bank of a generated mesh named by `identity`
    /// (the key reads only the identity of an in-memory mesh, so an empty
    /// mesh stands in for the one not generated).
    fn generated_key(
        &self,
        request: &BankRequest,
        material: &Material,
        identity: &str,
    ) -> Result<String, ProviderError> {
        let placeholder = TetMesh { nodes: Vec::new(), cells: Cells::Tet4(Vec::new()), groups: Vec::new() };
        let source = MeshSource::Memory { mesh: placeholder, identity: identity.to_string() };
        Ok(modal_precompute::cache_key(&self.request(request, material.clone(), source))?)
    }

    /// Counts a bank served from the cache and gives the warning the pipeline
    /// gives for one.
    fn served_from_cache(&mut self, request: &BankRequest, bank: &ModeBank, what: &str) {
        let warning = modal_precompute::residual_floor_warning(bank);
        self.warnings.extend(warning.map(|w| format!("{what}: {w}")));
        if bank.mode_count() == 0 {
            // Said on every render, not only the one that solved the bank.
            self.warnings.push(format!(
                "{what}: no mode below the scene's sample_rate / 2: the bank is silent (a small or stiff \
                 object rings higher)"
            ));
        }
        self.warnings.extend(mode_count_warning(request, bank).map(|w| format!("{what}: {w}")));
        self.cached += 1;
    }

    /// The cached bank of a generated mesh named by `identity` (`what` in
    /// messages), looked up by its cache key. `None` when there is no cache
    /// or no valid entry: the caller then runs the pipeline, which reports a
    /// damaged entry and recomputes it.
    fn cached_generated(
        &mut self,
        request: &BankRequest,
        material: &Material,
        identity: &str,
        what: &str,
    ) -> Result<Option<Arc<ModeBank>>, ProviderError> {
        let Some(cache) = &self.cache else { return Ok(None) };
        let key = self.generated_key(request, material, identity)?;
        // A missing, damaged or foreign entry is left to the pipeline.
        let Ok(Some(bank)) = cache.get(&key) else { return Ok(None) };
        self.served_from_cache(request, &bank, what);
        Ok(Some(Arc::new(bank)))
    }

    /// [`Self::cached_generated`] in two steps: the bank without its shapes
    /// now, the shapes read and the entry verified while the physics runs. A
    /// failed verification sets `deferred_failed` (the render then fails and
    /// `run` renders again through the plain path).
    fn cached_generated_deferred(
        &mut self,
        request: &BankRequest,
    ) -> Result<Option<ProvidedBank>, ProviderError> {
        let (Some(cache), Some(modal_scene::MeshSource::Generate(spec)), Some(material)) =
            (&self.cache, &request.mesh, &request.material)
        else {
            return Ok(None);
        };
        let (_, _, _, identity) = recipe(spec, request)?;
        let key = self.generated_key(request, material, &identity)?;
        let Ok(Some((light, rest))) = cache.get_deferred(&key) else { return Ok(None) };
        self.served_from_cache(request, &light, &describe(request.mesh.as_ref().ok_or("no mesh")?));
        let failed = Arc::clone(&self.deferred_failed);
        let rest = Box::new(move || {
            rest.finish().map_err(|e| {
                failed.store(true, Ordering::SeqCst);
                ProviderError::from(e)
            })
        });
        Ok(Some(ProvidedBank::Pending { light: Box::new(light), rest }))
    }
}

/// When a bank stopped at its mode count below the scene's Nyquist frequency:
/// the modes above are not heard, which the user must know (a 40 × 30 cm steel
/// slab's 64 modes end at 10.9 kHz).
fn mode_count_warning(request: &BankRequest, bank: &ModeBank) -> Option<String> {
    let kept = request.max_modes.unwrap_or(modal_scene::DEFAULT_SCENE_MODES);
    let highest = bank.frequencies_hz.last().copied()?;
    (bank.mode_count() >= kept && highest < request.max_frequency_hz).then(|| {
        format!(
            "keeps {kept} modes, the highest at {highest:.0} Hz, below the scene's {:.0} Hz: set `modes` higher \
             on the object (`[ground] modes` for a sounding slab) to hear the rest",
            request.max_frequency_hz
        )
    })
}

fn describe(mesh: &modal_scene::MeshSource) -> String {
    match mesh {
        modal_scene::MeshSource::File(path) => path.display().to_string(),
        modal_scene::MeshSource::Generate(spec) => format!("generated {}", spec.generate),
    }
}

pub fn run(args: RenderArgs) -> Result<()> {
    let (scene, default_out) = match &args.scene {
        Some(path) => {
            let scene = Scene::from_file(path).with_context(|| path.display().to_string())?;
            let out = scene.output.clone().unwrap_or_else(|| path.with_extension("wav"));
            (scene, out)
        }
        None => (Scene::demo(), PathBuf::from(DEMO_OUTPUT)),
    };
    super::args::check_transfer_max_freq(args.transfer_max_freq)?;
    let mut scene = scene;
    match args.radiation {
        Some(RadiationChoice::Estimate) => scene.listener.radiation = modal_scene::Radiation::Estimate,
        Some(RadiationChoice::Transfer) => scene.listener.radiation = modal_scene::Radiation::Transfer,
        None => {}
    }
    // Checked here, not only when a bank is solved: a cached scene accepted 0.
    modal_precompute::check_threads(args.threads)?;
    let out = args.out.clone().unwrap_or(default_out);
    check_outputs(&out, &args)?;
    let spinner = Spinner::new("preparing the scene");
    let mut provider = PipelineProvider {
        cache: open_cache(args.cache_dir.as_deref(), false)?,
        spinner: &spinner,
        threads: args.threads,
        warnings: Vec::new(),
        cached: 0,
        solved: 0,
        defer: true,
        deferred_failed: Arc::new(AtomicBool::new(false)),
        radiation_solved: Vec::new(),
        transfer_max_hz: args.transfer_max_freq.unwrap_or(DEFAULT_TRANSFER_MAX_HZ),
        memory_limit_bytes: memory_limit_from_env()?,
        retuned: Vec::new(),
        accuracy: args.accuracy.0.map(|target_pct| modal_precompute::AccuracyTarget {
            target_pct,
            modes: modal_precompute::DEFAULT_ACCURACY_MODES,
        }),
    };
    let options = modal_scene::RenderOptions { collect_events: args.events.is_some() };
    let mut rendered = modal_scene::render(&scene, &mut provider, &options);
    if rendered.is_err() && provider.deferred_failed.load(Ordering::SeqCst) {
        // A cached entry failed its checksum after the physics had started
        // from its surface: render again through the plain path, which
        // reports the entry, recomputes the bank and replaces the entry.
        provider.defer = false;
        (provider.cached, provider.solved) = (0, 0);
        provider.warnings.clear();
        rendered = modal_scene::render(&scene, &mut provider, &options);
    }
    spinner.set("writing");
    let (warnings, cached, solved) =
        (std::mem::take(&mut provider.warnings), provider.cached, provider.solved);
    let radiation_solved = std::mem::take(&mut provider.radiation_solved);
    spinner.finish();
    warnings.iter().for_each(|w| warn(w));
    for (what, modes, seconds) in &radiation_solved {
        eprintln!("acoustic transfer of {what}: {modes} mode(s) solved in {seconds:.1} s (cached)");
    }
    let rendered = rendered.context("render failed")?;
    let format = if args.float { WavFormat::Float32 } else { WavFormat::Pcm16 };
    // The side files first, the sound last; a failure removes what this run
    // wrote, so a render never leaves a WAV without the files asked with it.
    let mut written: Vec<&Path> = Vec::new();
    let result = (|| -> Result<modal_synth::WavReport> {
        if let Some(path) = &args.events {
            interrupt::guarded(|| modal_scene::write_events_json(&rendered.contact_events(), path))
                .with_context(|| format!("cannot write --events {}", path.display()))?;
            written.push(path);
        }
        if let Some(path) = &args.spectrogram {
            interrupt::guarded(|| {
                modal_scene::write_spectrogram_png(&rendered.channels, rendered.sample_rate, path)
            })
            .with_context(|| format!("cannot write --spectrogram {}", path.display()))?;
            written.push(path);
        }
        Ok(interrupt::guarded(|| modal_scene::write_wav(&rendered, &out, format))?)
    })();
    let wav = result.inspect_err(|_| written.iter().for_each(|p| drop(std::fs::remove_file(p))))?;
    if wav.clipped > 0 {
        warn(&scene_warnings::clipping_advice(wav.clipped, rendered.report.peak, scene.listener.gain));
    }
    scene_warnings::after_render(&scene, &rendered.report).iter().for_each(|w| warn(w));
    let report = &rendered.report;
    if args.json {
        let mut json = serde_json::to_value(report)?;
        json["out"] = out.display().to_string().into();
        json["banks_cached"] = cached.into();
        json["banks_solved"] = solved.into();
        json["real_time_factor"] = report.real_time_factor().into();
        json["whole_real_time_factor"] = report.whole_real_time_factor().into();
        json["radiation_solved"] = radiation_solved
            .iter()
            .map(|(what, modes, seconds)| serde_json::json!({"asset": what, "modes": modes, "seconds": seconds}))
            .collect::<Vec<_>>()
            .into();
        return print_json(&json);
    }
    print_report(report, &out, cached, solved);
    Ok(())
}

fn print_report(report: &modal_scene::RenderReport, out: &Path, cached: usize, solved: usize) {
    println!(
        "{:>16}  {:>7}  {:>7}  {:>8}  {:>12}  {:>14}  {:>12}",
        "object", "impacts", "modes", "transfer", "mode-samples", "samples", "peak Pa @1m"
    );
    for o in &report.objects {
        println!(
            "{:>16}  {:>7}  {:>3}/{:<3}  {:>8}  {:>12}  {:>14}  {:>12.3e}",
            o.name,
            o.impacts,
            o.modes_synthesized,
            o.modes_total,
            o.modes_with_transfer,
            o.mode_samples,
            o.samples_computed,
            o.peak_pa_at_1m
        );
    }
    println!(
        "banks: {} distinct ({} from cache, {} solved) in {:.2} s; acoustic transfer {:.2} s; colliders {:.3} s, \
         physics {:.3} s ({} steps), excitation {:.3} s, synthesis {:.3} s, mix {:.3} s: these stages {:.0}x real \
         time, the whole render {:.2}x",
        report.banks_requested,
        cached,
        solved,
        report.banks_s,
        report.radiation_s,
        report.colliders_s,
        report.physics_s,
        report.physics_steps,
        report.excitation_s,
        report.synthesis_s,
        report.mix_s,
        report.real_time_factor(),
        report.whole_real_time_factor()
    );
    println!(
        "wrote {} ({:.2} s at {} Hz, {} impacts, peak {:.3} of full scale)",
        out.display(),
        report.duration_s,
        report.sample_rate,
        report.impacts,
        report.peak
    );
}

/// Before any work: the WAV, `--events` and `--spectrogram` are three
/// different files, each of which can be written (a shared path would have
/// each write replace the one before).
fn check_outputs(out: &Path, args: &RenderArgs) -> Result<()> {
    let named = [
        ("-o", Some(out)),
        ("--events", args.events.as_deref()),
        ("--spectrogram", args.spectrogram.as_deref()),
    ];
    let named: Vec<(&str, &Path)> = named.into_iter().filter_map(|(flag, p)| Some((flag, p?))).collect();
    for (k, (flag, path)) in named.iter().enumerate() {
        super::prepare_output(path).with_context(|| format!("cannot write {flag} {}", path.display()))?;
        if let Some(scene) = &args.scene {
            super::check_not_input(path, scene, flag)?;
        }
        for (other, earlier) in &named[..k] {
            anyhow::ensure!(
                output_identity(path) != output_identity(earlier),
                "{flag} and {other} name the same file {}: give each output its own path",
                path.display()
            );
        }
    }
    Ok(())
}

/// `path` with its directory resolved, to compare outputs.
fn output_identity(path: &Path) -> PathBuf {
    let dir = super::directory_of(path);
    let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    dir.join(path.file_name().unwrap_or_default())
}
