//! Where mode banks come from. The scene never solves eigenproblems: it asks a
//! [`BankProvider`] once per distinct asset ([`BankRequest`]) and shares the
//! returned bank among all instances.

use std::sync::Arc;

use modal_bank::{ModeBank, RadiationTable};
use modal_fem::Material;

use crate::material::resolve_material;
use crate::spec::{MeshSource, ObjectSpec, Scene};
use crate::SceneError;

/// What to solve or load: everything that changes a bank, nothing that does
/// not (pose, velocity, name). Two objects with equal requests share a bank.
#[derive(Clone, Debug, PartialEq)]
pub struct BankRequest {
    /// A mesh to precompute (file path already resolved against the scene
    /// file, or a generator recipe) ...
    pub mesh: Option<MeshSource>,
    /// ... or an existing bank file.
    pub bank: Option<std::path::PathBuf>,
    /// Material; `None` only for a bank used as stored.
    pub material: Option<Material>,
    /// Element order 1 or 2, `None` = provider default.
    pub order: Option<u8>,
    /// Uniform geometric scale of the mesh (`None`: 1, not stated by the scene).
    pub scale: Option<f64>,
    /// Wall thickness [m] given to a surface mesh's open parts (`None`: none).
    pub sheet_thickness: Option<f64>,
    /// Highest frequency worth solving for [Hz]: the scene's Nyquist frequency.
    pub max_frequency_hz: f64,
    /// Most modes kept (`None`: [`crate::DEFAULT_SCENE_MODES`]).
    pub max_modes: Option<usize>,
}

/// The two mantissas of the standard solve bands: `{4, 6} kHz · 2^j`, the
/// Nyquist frequencies of the 48 kHz family (8, 16, 24, 48, 96 kHz ... and
/// 12 kHz between). Every standard rate's Nyquist frequency is one of them
/// or at most 8.8 % below one (22.05 kHz, 44.1 kHz's, below 24 kHz).
const BAND_MANTISSAS_HZ: [f64; 2] = [4000.0, 6000.0];

impl BankRequest {
    /// The band a bank is solved to [Hz]: the Nyquist frequency rounded up to
    /// the next standard band (`{4, 6} kHz · 2^j`), so scenes at 44.1 and
    /// 48 kHz (both 24 kHz), or 22.05 and 24 kHz, share one bank instead of
    /// solving one per sample rate. The synthesizer plays only the modes
    /// below its own Nyquist limit, so the few modes above it cost solve
    /// time and nothing else.
    pub fn band_to_solve_hz(&self) -> f64 {
        standard_band_at_least(self.max_frequency_hz)
    }
}

/// The smallest standard band `{4, 6} kHz · 2^j` not below `frequency_hz`
/// (`frequency_hz` itself when it is not finite and positive: the
/// pipeline's own check then refuses it).
fn standard_band_at_least(frequency_hz: f64) -> f64 {
    if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
        return frequency_hz;
    }
    let octave = (frequency_hz / BAND_MANTISSAS_HZ[0]).log2().floor();
    // The octave below, this one and the next bracket the answer whatever
    // the rounding of `log2`.
    let band = (-1..=1)
        .flat_map(|shift| BAND_MANTISSAS_HZ.map(|m| m * (octave + f64::from(shift)).exp2()))
        .filter(|&band| band >= frequency_hz)
        .fold(f64::INFINITY, f64::min);
    debug_assert!(band >= frequency_hz && band <= 1.5 * frequency_hz * (1.0 + 1e-12));
    band
}

impl BankRequest {
    /// The request behind object `object` of `scene`.
    pub fn for_object(scene: &Scene, object: &ObjectSpec) -> Result<BankRequest, String> {
        let material = object.material.as_ref().map(resolve_material).transpose()?;
        Ok(BankRequest {
            mesh: object.mesh.clone(),
            bank: object.bank.clone(),
            material,
            order: object.order,
            scale: object.scale,
            sheet_thickness: object.sheet_thickness,
            max_frequency_hz: 0.5 * scene.sample_rate_hz as f64,
            max_modes: object.modes,
        })
    }
}

/// The provider's error type: anything printable.
pub type ProviderError = Box<dyn std::error::Error + Send + Sync>;

/// The work that completes a [`ProvidedBank::Pending`] bank.
pub type BankCompletion = Box<dyn FnOnce() -> Result<ModeBank, ProviderError> + Send>;

/// A bank as a provider hands it over.
pub enum ProvidedBank {
    /// The complete bank.
    Ready(Arc<ModeBank>),
    /// Everything but the mode shapes (`light.shapes` is empty), not yet
    /// verified, and the work that completes and verifies it. The render runs
    /// that work on the second core while the physics — which needs only the
    /// surface, mass and material — runs; if it fails, the render fails before
    /// any output exists.
    Pending {
        /// The bank without its shapes.
        light: Box<ModeBank>,
        /// Reads, verifies and returns the complete bank.
        rest: BankCompletion,
    },
}

/// Supplies mode banks (precompute + cache in the application, in-memory
/// banks in tests). The bank's `mass` and `surface` define the rigid body;
/// its `material` is used for Hertz contact.
pub trait BankProvider {
    /// The bank for one distinct asset. Called at most once per distinct
    /// request during a render.
    fn bank(&mut self, request: &BankRequest) -> Result<Arc<ModeBank>, ProviderError>;

    /// [`Self::bank`], or a bank whose shapes are still to be loaded (see
    /// [`ProvidedBank::Pending`]). The render calls this one; the default
    /// serves [`Self::bank`].
    fn provide(&mut self, request: &BankRequest) -> Result<ProvidedBank, ProviderError> {
        self.bank(request).map(ProvidedBank::Ready)
    }

    /// The per-mode acoustic transfer of `bank` (the complete bank of
    /// `request`): stored with it, cached, or solved now. `None`: the render
    /// uses the level estimate for this asset. Called once per distinct
    /// asset when the scene's listener asks for the transfer
    /// (`[listener] radiation = "transfer"`); the default has none.
    fn radiation(
        &mut self,
        request: &BankRequest,
        bank: &Arc<ModeBank>,
    ) -> Result<Option<Arc<RadiationTable>>, ProviderError> {
        let _ = (request, bank);
        Ok(None)
    }
}

/// A provider serving fixed banks by generator name or file name, for tests
/// and embedding: a request matches an entry whose key equals the generator
/// name (`mesh = { generate = KEY }`) or the file name of `mesh`/`bank`.
#[derive(Default)]
pub struct InMemoryProvider {
    entries: Vec<(String, Arc<ModeBank>)>,
    tables: Vec<(String, Arc<RadiationTable>)>,
    /// Requests served so far, in order.
    pub requests: Vec<BankRequest>,
}

impl InMemoryProvider {
    /// An empty provider.
    pub fn new() -> Self {
        Self::default()
    }

    /// Serves `bank` for requests with key `key`.
    pub fn insert(&mut self, key: impl Into<String>, bank: ModeBank) -> &mut Self {
        self.entries.push((key.into(), Arc::new(bank)));
        self
    }

    /// Serves `table` as the radiation of the bank with key `key`.
    pub fn insert_radiation(&mut self, key: impl Into<String>, table: RadiationTable) -> &mut Self {
        self.tables.push((key.into(), Arc::new(table)));
        self
    }

    fn key(request: &BankRequest) -> Option<String> {
        match (&request.mesh, &request.bank) {
            (Some(MeshSource::Generate(g)), _) => Some(g.generate.clone()),
            (Some(MeshSource::File(p)), _) | (None, Some(p)) => {
                p.file_name().map(|n| n.to_string_lossy().into_owned())
            }
            (None, None) => None,
        }
    }
}

impl BankProvider for InMemoryProvider {
    fn bank(&mut self, request: &BankRequest) -> Result<Arc<ModeBank>, ProviderError> {
        self.requests.push(request.clone());
        let key = Self::key(request).ok_or("request names no asset")?;
        self.entries
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, b)| Arc::clone(b))
            .ok_or_else(|| format!("no in-memory bank named '{key}'").into())
    }

    fn radiation(
        &mut self,
        request: &BankRequest,
        _bank: &Arc<ModeBank>,
    ) -> Result<Option<Arc<RadiationTable>>, ProviderError> {
        let key = Self::key(request);
        Ok(self.tables.iter().find(|(k, _)| Some(k) == key.as_ref()).map(|(_, t)| Arc::clone(t)))
    }
}

/// The banks of a scene's objects: complete or light (see [`ProvidedBank`]).
pub(crate) struct ResolvedBanks {
    /// Per distinct asset: its bank (light when pending), the work completing
    /// it (`None`: already complete) and the first object's path for errors.
    assets: Vec<(Arc<ModeBank>, Option<BankCompletion>, String)>,
    /// Per object, its asset.
    asset_of: Vec<usize>,
    /// Per distinct asset, its request.
    requests: Vec<BankRequest>,
}

impl ResolvedBanks {
    /// Distinct assets asked for.
    pub fn requested(&self) -> usize {
        self.assets.len()
    }

    /// Per distinct asset its request, and per object its asset.
    pub fn requests(&self) -> (Vec<BankRequest>, Vec<usize>) {
        (self.requests.clone(), self.asset_of.clone())
    }

    /// One bank per object (instances of an asset share one `Arc`); pending
    /// assets give their light bank, without shapes.
    pub fn light(&self) -> Vec<Arc<ModeBank>> {
        self.asset_of.iter().map(|&a| Arc::clone(&self.assets[a].0)).collect()
    }

    /// The complete banks, one per object, shared as the light ones are.
    pub fn complete(self) -> Result<Vec<Arc<ModeBank>>, SceneError> {
        let mut full = Vec::with_capacity(self.assets.len());
        for (light, rest, path) in self.assets {
            full.push(match rest {
                None => light,
                Some(rest) => {
                    let bank = rest().map_err(|source| SceneError::Bank { path: path.clone(), source })?;
                    check_bank(&path, &bank)?;
                    // The physics ran on the light bank: it must be the verified one.
                    if light.surface != bank.surface
                        || light.mass != bank.mass
                        || light.material != bank.material
                    {
                        return Err(SceneError::invalid(&path, "the bank changed while it was being loaded"));
                    }
                    Arc::new(bank)
                }
            });
        }
        Ok(self.asset_of.iter().map(|&a| Arc::clone(&full[a])).collect())
    }
}

/// Asks the provider once per distinct request; returns one bank per object.
pub(crate) fn resolve_banks(
    scene: &Scene,
    provider: &mut dyn BankProvider,
) -> Result<ResolvedBanks, SceneError> {
    let mut requests: Vec<BankRequest> = Vec::new();
    let mut assets = Vec::new();
    let mut asset_of = Vec::with_capacity(scene.objects.len());
    for (i, object) in scene.objects.iter().enumerate() {
        let path = format!("objects[{i}]");
        let request = BankRequest::for_object(scene, object)
            .map_err(|m| SceneError::invalid(format!("{path}.material"), m))?;
        if let Some(a) = requests.iter().position(|r| *r == request) {
            asset_of.push(a);
            continue;
        }
        let provided =
            provider.provide(&request).map_err(|source| SceneError::Bank { path: path.clone(), source })?;
        let (bank, rest) = match provided {
            ProvidedBank::Ready(bank) => {
                check_bank(&path, &bank)?;
                (bank, None)
            }
            ProvidedBank::Pending { light, rest } => {
                check_body(&path, &light)?;
                (Arc::from(light), Some(rest))
            }
        };
        asset_of.push(assets.len());
        requests.push(request);
        assets.push((bank, rest, path));
    }
    Ok(ResolvedBanks { assets, asset_of, requests })
}

/// The scene relies on a bank's surface and mass properties; reject banks it
/// cannot use instead of panicking later.
fn check_bank(path: &str, bank: &ModeBank) -> Result<(), SceneError> {
    check_body(path, bank)?;
    let n = bank.surface.positions.len();
    if bank.shapes.len() != bank.mode_count() * n * 3
        || bank.decay_rates.len() != bank.mode_count()
        || bank.damping_ratios.len() != bank.mode_count()
    {
        return Err(SceneError::invalid(path, "unusable bank: its arrays disagree in length"));
    }
    Ok(())
}

/// What the rigid body needs of a bank: a surface and sane mass properties.
fn check_body(path: &str, bank: &ModeBank) -> Result<(), SceneError> {
    let bad = |m: &str| Err(SceneError::invalid(path, format!("unusable bank: {m}")));
    let n = bank.surface.positions.len();
    if n < 4 || bank.surface.triangles.is_empty() {
        return bad("its surface has fewer than 4 nodes or no triangles");
    }
    if bank.surface.triangles.iter().flatten().any(|&k| k >= n) {
        return bad("a surface triangle refers to a missing node");
    }
    if bank.surface.positions.iter().flatten().any(|x| !x.is_finite()) {
        return bad("a surface position is not finite");
    }
    let m = &bank.mass;
    if !(m.mass_kg.is_finite() && m.mass_kg > 0.0) {
        return bad("its mass is not positive");
    }
    if m.center_of_mass_m.iter().chain(m.inertia_kg_m2.iter().flatten()).any(|x| !x.is_finite()) {
        return bad("its centre of mass or inertia is not finite");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::standard_band_at_least;

    #[test]
    fn standard_rates_share_the_band_of_their_family() {
        // (sample rate, band its scene's banks are solved to)
        let cases = [
            (8000, 4000.0),
            (11025, 6000.0),
            (16000, 8000.0),
            (22050, 12000.0),
            (24000, 12000.0),
            (32000, 16000.0),
            (44100, 24000.0),
            (48000, 24000.0),
            (88200, 48000.0),
            (96000, 48000.0),
            (192000, 96000.0),
        ];
        for (rate, band) in cases {
            assert_eq!(standard_band_at_least(0.5 * f64::from(rate)), band, "{rate} Hz");
        }
        // Between the bands: the next one up, never more than 1.5 times the Nyquist frequency.
        assert_eq!(standard_band_at_least(12000.5), 16000.0);
        assert_eq!(standard_band_at_least(16000.5), 24000.0);
        assert_eq!(standard_band_at_least(24000.5), 32000.0);
        for nyquist in (4000..=96000).step_by(37) {
            let band = standard_band_at_least(f64::from(nyquist));
            assert!(band >= f64::from(nyquist) && band <= 1.5 * f64::from(nyquist), "{nyquist}: {band}");
        }
        assert!(standard_band_at_least(f64::NAN).is_nan());
    }
}
