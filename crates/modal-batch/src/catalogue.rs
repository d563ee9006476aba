//! The catalogue: what a batch produced, one entry per asset.
//!
//! `catalogue.json` (unsharded) or `catalogue-shard-I-of-N.json` (shard I of
//! N; several shards can share one output directory) is
//! `{"assets": [{"path", "bank", "hash", "modes", "first_frequency_hz",
//! "transfer_modes", "seconds", "status", "cached"}], "pending": [...], "complete": bool,
//! "shard": {"index", "count"} | null}`; the names are a contract.
//!
//! Entries are sorted by (`path`, `bank`, `hash`, `status`), so a catalogue
//! does not depend on the order in which parallel jobs finished, and
//! [`merge`] of the shards of a run equals the unsharded run's catalogue in
//! every field except the two that describe the run rather than the asset:
//! `seconds` (wall time) and `cached` (served from the cache or solved).
//! [`Catalogue::results`] drops exactly those two.

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

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

    /// A catalogue of `entries` (sorted here) with `pending` assets still to run.
    pub fn new(mut entries: Vec<CatalogueEntry>, mut pending: Vec<String>, shard: Shard) -> Catalogue {
        entries.sort_by(|a, b| a.sort_key().cmp(&b.sort_key()));
        pending.sort();
        Catalogue {
            assets: entries,
            complete: pending.is_empty(),
            pending,
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

/// What [`merge`] found besides the merged catalogue.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MergeReport {
    /// The catalogue files read.
    pub inputs: Vec<PathBuf>,
    /// Shards no input catalogue is from (`"shard I of N"`).
    pub missing: Vec<String>,
}

/// Joins catalogues into one whose banks are relative to `out_dir`.
///
/// Each input is a catalogue file, or a directory whose
/// `catalogue-shard-I-of-N.json` files are all read, or, with no shard
/// files, its `catalogue.json`. The shard catalogues read, named as files
/// or found in directories, must agree on N; the indices none of them is
/// from are reported in [`MergeReport::missing`] (an unsharded or merged
/// catalogue among the inputs covers every shard). Entries that agree on
/// everything but `seconds`/`cached` are kept once; two different results
/// for one bank file are an error (mixed runs in one directory). The result
/// is complete when every input was and no shard is missing.
pub fn merge(inputs: &[PathBuf], out_dir: &Path) -> Result<(Catalogue, MergeReport), BatchError> {
    let mut report = MergeReport::default();
    let mut entries = Vec::new();
    let mut pending = Vec::new();
    let mut complete = true;
    let mut shards = ShardCoverage::default();
    let mut library = LibraryCheck::default();
    for input in inputs {
        for file in catalogue_files(input)? {
            let catalogue = Catalogue::load(&file)?;
            shards.add(catalogue.shard, &file)?;
            library.add(catalogue.library.as_ref(), &file)?;
            let dir = file.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            complete &= catalogue.complete;
            pending.extend(catalogue.pending);
            for mut entry in catalogue.assets {
                if let Some(bank) = &entry.bank {
                    entry.bank = Some(rebase(dir, bank, out_dir));
                }
                entries.push(entry);
            }
            report.inputs.push(file);
        }
    }
    if report.inputs.is_empty() {
        return Err(BatchError::Catalogue { path: "(none)".into(), message: "no catalogue to merge".into() });
    }
    report.missing = shards.missing();
    entries.sort_by(|a, b| a.sort_key().cmp(&b.sort_key()).then(a.seconds.total_cmp(&b.seconds)));
    entries.dedup_by(|later, first| later.result() == first.result());
    let mut by_bank: BTreeMap<&str, &CatalogueEntry> = BTreeMap::new();
    for e in &entries {
        if let Some(bank) = e.bank.as_deref() {
            if let Some(other) = by_bank.insert(bank, e) {
                return Err(BatchError::Catalogue {
                    path: bank.to_string(),
                    message: format!(
                        "two different results for this bank (hashes {:?} and {:?}): catalogues of \
                         different runs were mixed",
                        other.hash, e.hash
                    ),
                });
            }
        }
    }
    pending.sort();
    pending.dedup();
    let mut merged = Catalogue::new(entries, pending, Shard::WHOLE);
    merged.library = library.common();
    if let Some(lib) = &merged.library {
        // Entries are one per asset once repeats are dropped (above).
        let listed = merged.assets.len() + merged.pending.len();
        if listed < lib.assets {
            report.missing.push(format!("{} of the library's {} assets", lib.assets - listed, lib.assets));
        }
    }
    merged.complete = complete && merged.pending.is_empty() && report.missing.is_empty();
    Ok((merged, report))
}

/// The library the merged catalogues agree on.
#[derive(Default)]
struct LibraryCheck {
    /// The first library seen and its file.
    first: Option<(Library, PathBuf)>,
    /// A catalogue without one was read (written before it was recorded).
    unknown: bool,
}

impl LibraryCheck {
    /// Records the library of the catalogue `file`; two different ones are an error.
    fn add(&mut self, library: Option<&Library>, file: &Path) -> Result<(), BatchError> {
        let Some(library) = library else {
            self.unknown = true;
            return Ok(());
        };
        match &self.first {
            Some((first, first_file)) if first != library => Err(BatchError::Catalogue {
                path: file.display().to_string(),
                message: format!(
                    "is from another library than {} ({} against {} assets, or other files or \
                     options): merge the catalogues of one run",
                    first_file.display(),
                    library.assets,
                    first.assets
                ),
            }),
            Some(_) => Ok(()),
            None => {
                self.first = Some((library.clone(), file.to_path_buf()));
                Ok(())
            }
        }
    }

    /// The library every catalogue named (none when one named none).
    fn common(self) -> Option<Library> {
        self.first.filter(|_| !self.unknown).map(|(library, _)| library)
    }
}

/// Which shards the merged catalogues are from.
#[derive(Default)]
struct ShardCoverage {
    /// The shard count and the file that set it.
    count: Option<(usize, PathBuf)>,
    /// Indices seen.
    seen: std::collections::BTreeSet<usize>,
    /// An unsharded (or already merged) catalogue was read: it covers all.
    whole: bool,
}

impl ShardCoverage {
    /// Records the shard of the catalogue `file`; shard counts must agree.
    fn add(&mut self, shard: Option<ShardInfo>, file: &Path) -> Result<(), BatchError> {
        let Some(ShardInfo { index, count }) = shard else {
            self.whole = true;
            return Ok(());
        };
        match &self.count {
            Some((n, first)) if *n != count => {
                return Err(BatchError::Catalogue {
                    path: file.display().to_string(),
                    message: format!(
                    "is shard {index} of {count}, but {} is of {n} shards: merge the catalogues of one run",
                    first.display()
                ),
                })
            }
            Some(_) => {}
            None => self.count = Some((count, file.to_path_buf())),
        }
        self.seen.insert(index);
        Ok(())
    }

    /// The shards no catalogue is from (none when a whole one was read).
    fn missing(&self) -> Vec<String> {
        match (&self.count, self.whole) {
            (Some((n, _)), false) => {
                (0..*n).filter(|i| !self.seen.contains(i)).map(|i| format!("shard {i} of {n}")).collect()
            }
            _ => Vec::new(),
        }
    }
}

/// The catalogue files an input stands for (see [`merge`]).
fn catalogue_files(input: &Path) -> Result<Vec<PathBuf>, BatchError> {
    let bad = |message: String| BatchError::Catalogue { path: input.display().to_string(), message };
    if !input.is_dir() {
        return if input.is_file() {
            Ok(vec![input.to_path_buf()])
        } else {
            Err(bad("no such file or directory".into()))
        };
    }
    let rd = std::fs::read_dir(input)
        .map_err(|source| BatchError::Read { path: input.display().to_string(), source })?;
    let mut shards: BTreeMap<usize, BTreeMap<usize, PathBuf>> = BTreeMap::new();
    for entry in rd.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if let Some((i, n)) = parse_shard_name(&name) {
            shards.entry(n).or_default().insert(i, entry.path());
        }
    }
    if shards.is_empty() {
        let whole = input.join(CATALOGUE_FILE);
        return if whole.is_file() {
            Ok(vec![whole])
        } else {
            Err(bad(format!("holds neither {CATALOGUE_FILE} nor catalogue-shard-I-of-N.json files")))
        };
    }
    if shards.len() > 1 {
        let counts: Vec<String> = shards.keys().map(usize::to_string).collect();
        return Err(bad(format!(
            "holds shard catalogues of different shard counts ({}): merge the files of one run explicitly",
            counts.join(", ")
        )));
    }
    let (_, files) = shards.into_iter().next().expect("one shard count");
    Ok(files.into_values().collect())
}

/// `(I, N)` of a `catalogue-shard-I-of-N.json` name with `I < N`.
pub(crate) fn parse_shard_name(name: &str) -> Option<(usize, usize)> {
    let middle = name.strip_prefix("catalogue-shard-")?.strip_suffix(".json")?;
    let (i, n) = middle.split_once("-of-")?;
    let (i, n) = (i.parse().ok()?, n.parse().ok()?);
    (i < n).then_some((i, n))
}

/// `bank` (relative to `from`) as a path relative to `to` (both directories),
/// `/`-separated; unchanged when the directories are the same.
fn rebase(from: &Path, bank: &str, to: &Path) -> String {
    let canon = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let (from, to) = (canon(from), canon(to));
    if from == to || Path::new(bank).is_absolute() {
        return bank.to_string();
    }
    let target = from.join(bank);
    let t: Vec<Component> = target.components().collect();
    let d: Vec<Component> = to.components().collect();
    let common = t.iter().zip(&d).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return target.to_string_lossy().into_owned();
    }
    let mut parts: Vec<String> = vec!["..".to_string(); d.len() - common];
    parts.extend(t[common..].iter().map(|c| c.as_os_str().to_string_lossy().into_owned()));
    parts.join("/")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(path: &str, status: &str, seconds: f64) -> CatalogueEntry {
        let ok = status == "ok";
        CatalogueEntry {
            path: path.into(),
            bank: ok.then(|| path.replace(".obj", ".bank")),
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

    #[test]
    fn merged_shards_equal_the_whole_and_report_gaps() {
        let dir = tempfile::tempdir().unwrap();
        let all: Vec<CatalogueEntry> =
            ["a.obj", "bb.obj", "ccc.obj", "dddd.obj", "e.obj"].iter().map(|p| entry(p, "ok", 1.0)).collect();
        let mut with_failure = all.clone();
        with_failure.push(entry("zz.obj", "cannot read zz.obj", 0.1));
        let whole = Catalogue::new(with_failure.clone(), vec![], Shard::WHOLE);
        let count = 3;
        for i in 0..count {
            let shard = Shard::new(i, count).unwrap();
            let mine: Vec<CatalogueEntry> = with_failure
                .iter()
                .filter(|e| shard.owns(&e.path))
                .map(|e| CatalogueEntry { seconds: 7.0 + i as f64, cached: i == 1, ..e.clone() })
                .collect();
            Catalogue::new(mine, vec![], shard).save(&dir.path().join(Catalogue::file_name(shard))).unwrap();
        }
        let (merged, report) = merge(&[dir.path().to_path_buf()], dir.path()).unwrap();
        assert_eq!(report.inputs.len(), 3);
        assert!(report.missing.is_empty());
        assert!(merged.complete);
        assert_eq!(merged.results(), whole.results());
        assert_ne!(merged, whole, "seconds differ, so full equality must not hold");
        // A second merge input repeating a shard changes nothing.
        let again = dir.path().join(Catalogue::file_name(Shard::new(0, 3).unwrap()));
        let (twice, _) = merge(&[dir.path().to_path_buf(), again.clone()], dir.path()).unwrap();
        assert_eq!(twice.results(), whole.results());
        // A missing shard is reported and the result is not complete.
        std::fs::remove_file(&again).unwrap();
        let (partial, report) = merge(&[dir.path().to_path_buf()], dir.path()).unwrap();
        assert_eq!(report.missing.len(), 1);
        assert!(report.missing[0].contains("shard 0 of 3"));
        assert!(!partial.complete);
        // Named as files, the shards are checked alike: shards 1 and 2 of 3 are not all.
        let file = |i| dir.path().join(Catalogue::file_name(Shard::new(i, count).unwrap()));
        let (files, report) = merge(&[file(1), file(2)], dir.path()).unwrap();
        assert_eq!(report.missing, ["shard 0 of 3"]);
        assert!(!files.complete);
        // An unsharded catalogue covers every shard.
        let whole_file = dir.path().join("whole.json");
        whole.save(&whole_file).unwrap();
        let (covered, report) = merge(&[file(1), whole_file], dir.path()).unwrap();
        assert!(report.missing.is_empty() && covered.complete);
        // A shard of another count is another run.
        let other = Shard::new(0, 5).unwrap();
        let other_file = dir.path().join("other").join(Catalogue::file_name(other));
        Catalogue::new(vec![], vec![], other).save(&other_file).unwrap();
        let err = merge(&[file(1), other_file], dir.path()).unwrap_err().to_string();
        assert!(err.contains("of 5") && err.contains("of 3 shards"), "{err}");
    }

    #[test]
    fn shards_of_one_library_merge_and_a_short_or_foreign_one_is_caught() {
        let dir = tempfile::tempdir().unwrap();
        let library = |fingerprint: &str, assets| Some(Library { fingerprint: fingerprint.into(), assets });
        let save = |name: &str, shard: Shard, paths: &[&str], lib: Option<Library>| {
            let entries = paths.iter().map(|p| entry(p, "ok", 1.0)).collect();
            let catalogue = Catalogue { library: lib, ..Catalogue::new(entries, vec![], shard) };
            let path = dir.path().join(name);
            catalogue.save(&path).unwrap();
            path
        };
        let (a, b) = (Shard::new(0, 2).unwrap(), Shard::new(1, 2).unwrap());
        let first = save("a.json", a, &["a.obj", "b.obj"], library("f", 4));
        let second = save("b.json", b, &["c.obj", "d.obj"], library("f", 4));
        let (merged, report) = merge(&[first.clone(), second], dir.path()).unwrap();
        assert!(merged.complete && report.missing.is_empty());
        assert_eq!(merged.library, library("f", 4));
        // The second node saw one file fewer: its library differs.
        let short = save("c.json", b, &["c.obj"], library("g", 3));
        let err = merge(&[first.clone(), short], dir.path()).unwrap_err().to_string();
        assert!(err.contains("another library"), "{err}");
        // Same library, an asset not in any catalogue: incomplete.
        let lost = save("d.json", b, &["c.obj"], library("f", 4));
        let (merged, report) = merge(&[first.clone(), lost], dir.path()).unwrap();
        assert!(!merged.complete);
        assert_eq!(report.missing, ["1 of the library's 4 assets"]);
        // A catalogue from before libraries were recorded: merged, not checked.
        let old = save("e.json", b, &["c.obj"], None);
        let (merged, _) = merge(&[first, old], dir.path()).unwrap();
        assert!(merged.complete && merged.library.is_none());
    }

    #[test]
    fn conflicts_and_mixed_counts_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let a = entry("a.obj", "ok", 1.0);
        let b = CatalogueEntry { hash: Some("f".repeat(64)), ..a.clone() };
        Catalogue::new(vec![a], vec![], Shard::WHOLE).save(&dir.path().join("one.json")).unwrap();
        Catalogue::new(vec![b], vec![], Shard::WHOLE).save(&dir.path().join("two.json")).unwrap();
        let files = [dir.path().join("one.json"), dir.path().join("two.json")];
        assert!(merge(&files, dir.path()).unwrap_err().to_string().contains("different results"));
        let mixed = tempfile::tempdir().unwrap();
        for shard in [Shard::new(0, 2).unwrap(), Shard::new(0, 3).unwrap()] {
            Catalogue::new(vec![], vec![], shard)
                .save(&mixed.path().join(Catalogue::file_name(shard)))
                .unwrap();
        }
        assert!(merge(&[mixed.path().to_path_buf()], mixed.path()).unwrap_err().to_string().contains("2, 3"));
        let empty = tempfile::tempdir().unwrap();
        assert!(merge(&[empty.path().to_path_buf()], empty.path()).is_err());
    }

    #[test]
    fn banks_are_rebased_to_the_output_directory() {
        let root = tempfile::tempdir().unwrap();
        let run = root.path().join("runs/one");
        std::fs::create_dir_all(&run).unwrap();
        Catalogue::new(vec![entry("props/a.obj", "ok", 1.0)], vec!["b.obj".into()], Shard::WHOLE)
            .save(&run.join(CATALOGUE_FILE))
            .unwrap();
        let (merged, _) = merge(std::slice::from_ref(&run), root.path()).unwrap();
        assert_eq!(merged.assets[0].bank.as_deref(), Some("runs/one/props/a.bank"));
        assert_eq!(merged.pending, ["b.obj"]);
        assert!(!merged.complete);
        let elsewhere = root.path().join("out");
        std::fs::create_dir_all(&elsewhere).unwrap();
        let (merged, _) = merge(&[run], &elsewhere).unwrap();
        assert_eq!(merged.assets[0].bank.as_deref(), Some("../runs/one/props/a.bank"));
    }
}
