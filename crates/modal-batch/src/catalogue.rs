//! The catalogue: what a batch produced, one entry per asset.
//!
//! `catalogue.json` (unsharded) or `catalogue-shard-I-of-N.json` (shard I of
//! N; several shards can share one output directory) is
//! `{"assets": [{"path", "bank", "id", "hash", "modes", "first_frequency_hz",
//! "transfer_modes", "seconds", "status", "cached"}], "pending": [...], "pending_banks": [...],
//! "complete": bool, "shard": {"index", "count"} | null}`; the names are a contract.
//!
//! Entries are sorted by (`path`, `bank`, `hash`, `status`), so a catalogue
//! does not depend on the order in which parallel jobs finished, and
//! [`merge`] of the shards of a run equals the unsharded run's catalogue in
//! every field except the two that describe the run rather than the asset:
//! `seconds` (wall time) and `cached` (served from the cache or solved).
//! [`Catalogue::results`] drops exactly those two.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::fsio::write_atomic;
use crate::{BatchError, Shard};

/// Name of an unsharded run's (or a merge's default) catalogue.
pub const CATALOGUE_FILE: &str = "catalogue.json";

/// One asset's outcome.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CatalogueEntry {
    /// The asset's path as the manifest spells it (relative to the manifest).
    pub path: String,
    /// The bank file, relative to the catalogue's directory; `null` when the asset failed.
    pub bank: Option<String>,
    /// The asset's bank as the manifest names it (relative to the output
    /// directory of its run), failed or not: with `path`, what tells an asset
    /// from another across catalogues, shards and merges (one file listed
    /// twice with two materials has one path and two banks). Empty in
    /// catalogues written before it was recorded.
    #[serde(default)]
    pub id: String,
    /// The content hash (cache key) of the asset's inputs; `null` when it
    /// could not be computed (e.g. a missing file).
    pub hash: Option<String>,
    /// Number of modes in the bank (0 on failure).
    pub modes: usize,
    /// Lowest mode's frequency \[Hz\]; `null` without modes.
    pub first_frequency_hz: Option<f64>,
    /// Modes whose acoustic transfer the bank stores (the manifest's
    /// `transfer_max_freq`; 0 without it or on failure).
    #[serde(default)]
    pub transfer_modes: usize,
    /// Wall time spent on the asset in this run \[s\].
    pub seconds: f64,
    /// `"ok"`, or the error message.
    pub status: String,
    /// True when the bank was served from the cache (or found finished in
    /// the output directory) instead of solved in this run.
    #[serde(default)]
    pub cached: bool,
    /// The body's mass \[kg\]; `null` when the asset failed. With `size_m`, the
    /// check a library needs that every file was read in its unit (a 12 cm mug
    /// written in inches weighs 24 t).
    #[serde(default)]
    pub mass_kg: Option<f64>,
    /// The body's size: its bounding-box diagonal \[m\]; `null` when the asset failed.
    #[serde(default)]
    pub size_m: Option<f64>,
    /// This run's warnings about the asset, as printed on stderr. A bank reused
    /// (`cached`) carries only the warning its size gives, judged from the bank.
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl CatalogueEntry {
    /// True when the asset succeeded.
    pub fn is_ok(&self) -> bool {
        self.status == "ok"
    }

    fn sort_key(&self) -> (&str, Option<&str>, Option<&str>, &str) {
        (&self.path, self.bank.as_deref(), self.hash.as_deref(), &self.status)
    }

    /// What identifies the asset in its library: its `id`; in a catalogue
    /// written before ids, its bank, else its path.
    pub(crate) fn identity(&self) -> &str {
        match (self.id.as_str(), &self.bank) {
            ("", Some(bank)) => bank,
            ("", None) => &self.path,
            (id, _) => id,
        }
    }

    /// The entry without the fields that describe the run (`seconds`, `cached`,
    /// `warnings`: a reused bank keeps only its size warning).
    pub fn result(&self) -> CatalogueEntry {
        CatalogueEntry { seconds: 0.0, cached: false, warnings: Vec::new(), ..self.clone() }
    }
}

/// Which shard a catalogue is from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// Shard index, 0-based.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

/// The library a catalogue is part of: every asset its manifest resolved
/// to, on every shard. Shards of one run agree on it; shards of two runs
/// (another manifest, other options, a node that saw fewer files) do not,
/// and a merge of them is refused or found short.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Library {
    /// SHA-256 (hex) of every asset's path, bank and resolved options, in
    /// bank order, with the source file named by its manifest path (so the
    /// manifest's location on a node does not matter).
    pub fingerprint: String,
    /// Number of assets (all shards).
    pub assets: usize,
}

impl Library {
    /// The library of `assets` (all of the manifest's, before sharding).
    pub fn of(assets: &[crate::Asset]) -> Library {
        use sha2::{Digest, Sha256};
        let mut sorted: Vec<&crate::Asset> = assets.iter().collect();
        sorted.sort_by(|a, b| a.bank.cmp(&b.bank));
        let mut h = Sha256::new();
        h.update(b"modal-batch-library-v1");
        for asset in sorted {
            let mut request = asset.request.clone();
            request.source = modal_precompute::MeshSource::File(asset.path.clone().into());
            let line = format!("{}\0{}\0{request:?}\0{:?}\n", asset.path, asset.bank, asset.transfer_max_hz);
            h.update(line.as_bytes());
        }
        let fingerprint = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
        Library { fingerprint, assets: assets.len() }
    }
}

/// A batch's catalogue.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Catalogue {
    /// One entry per finished asset, sorted.
    pub assets: Vec<CatalogueEntry>,
    /// Paths of assets not finished yet (a run in progress or killed), sorted.
    #[serde(default)]
    pub pending: Vec<String>,
    /// Their banks (`id`s): `pending_banks[i]` is the bank of `pending[i]`.
    #[serde(default)]
    pub pending_banks: Vec<String>,
    /// True when every asset of the run (or, merged, of every shard) is in `assets`.
    #[serde(default)]
    pub complete: bool,
    /// The shard this catalogue is from; `null` for an unsharded run or a merge.
    #[serde(default)]
    pub shard: Option<ShardInfo>,
    /// The whole library the run's manifest resolved to (`null` in
    /// catalogues written before it was recorded).
    #[serde(default)]
    pub library: Option<Library>,
}

impl Catalogue {
    /// The catalogue file name of `shard` in the output directory.
    pub fn file_name(shard: Shard) -> String {
        if shard.is_whole() {
            CATALOGUE_FILE.to_string()
        } else {
            format!("catalogue-shard-{}-of-{}.json", shard.index, shard.count)
        }
    }

    /// A catalogue of `entries` (sorted here) with `pending` assets still to
    /// run, each as (path, bank).
    pub fn new(
        mut entries: Vec<CatalogueEntry>,
        mut pending: Vec<(String, String)>,
        shard: Shard,
    ) -> Catalogue {
        entries.sort_by(|a, b| a.sort_key().cmp(&b.sort_key()));
        pending.sort();
        let (pending, pending_banks): (Vec<String>, Vec<String>) = pending.into_iter().unzip();
        Catalogue {
            assets: entries,
            complete: pending.is_empty(),
            pending,
            pending_banks,
            shard: (!shard.is_whole()).then_some(ShardInfo { index: shard.index, count: shard.count }),
            library: None,
        }
    }

    /// The catalogue with `seconds` and `cached` cleared in every entry:
    /// what must agree between a sharded and an unsharded run.
    pub fn results(&self) -> Catalogue {
        Catalogue { assets: self.assets.iter().map(CatalogueEntry::result).collect(), ..self.clone() }
    }

    /// Number of failed assets.
    pub fn failed(&self) -> usize {
        self.assets.iter().filter(|e| !e.is_ok()).count()
    }

    /// Writes the catalogue (pretty JSON) atomically.
    pub fn save(&self, path: &Path) -> Result<(), BatchError> {
        let mut text = serde_json::to_string_pretty(self).expect("a catalogue serializes");
        text.push('\n');
        write_atomic(path, text.as_bytes())
    }

    /// The pending assets as (path, bank); a catalogue written before
    /// `pending_banks` gives each its path for a bank.
    pub fn pending_assets(&self) -> Vec<(String, String)> {
        if self.pending_banks.len() == self.pending.len() {
            self.pending.iter().cloned().zip(self.pending_banks.iter().cloned()).collect()
        } else {
            self.pending.iter().map(|p| (p.clone(), p.clone())).collect()
        }
    }

    /// Reads a catalogue file.
    pub fn load(path: &Path) -> Result<Catalogue, BatchError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| BatchError::Read { path: path.display().to_string(), source })?;
        serde_json::from_str(&text).map_err(|e| BatchError::Catalogue {
            path: path.display().to_string(),
            message: format!("not a catalogue: {e}"),
        })
    }
}

/// `(I, N)` of a `catalogue-shard-I-of-N.json` name with `I < N`.
pub(crate) fn parse_shard_name(name: &str) -> Option<(usize, usize)> {
    let middle = name.strip_prefix("catalogue-shard-")?.strip_suffix(".json")?;
    let (i, n) = middle.split_once("-of-")?;
    let (i, n) = (i.parse().ok()?, n.parse().ok()?);
    (i < n).then_some((i, n))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An entry of `path` (its bank `path` with `.bank`), ok or failed.
    pub(crate) fn entry(path: &str, status: &str, seconds: f64) -> CatalogueEntry {
        let ok = status == "ok";
        CatalogueEntry {
            path: path.into(),
            bank: ok.then(|| path.replace(".obj", ".bank")),
            id: path.replace(".obj", ".bank"),
            hash: Some(format!("{:064x}", path.len())),
            modes: if ok { 4 } else { 0 },
            first_frequency_hz: ok.then_some(100.0 + path.len() as f64),
            transfer_modes: if ok { 2 } else { 0 },
            seconds,
            status: status.into(),
            cached: false,
            mass_kg: ok.then_some(0.25),
            size_m: ok.then_some(0.1),
            warnings: Vec::new(),
        }
    }

    #[test]
    fn shard_file_names_round_trip() {
        assert_eq!(Catalogue::file_name(Shard::WHOLE), "catalogue.json");
        let name = Catalogue::file_name(Shard::new(2, 3).unwrap());
        assert_eq!(name, "catalogue-shard-2-of-3.json");
        assert_eq!(parse_shard_name(&name), Some((2, 3)));
        assert_eq!(parse_shard_name("catalogue-shard-3-of-3.json"), None);
        assert_eq!(parse_shard_name("catalogue.json"), None);
    }
}
