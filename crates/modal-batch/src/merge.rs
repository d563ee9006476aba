//! Joining the catalogues of a run's shards (or of several nodes) into one
//! whose banks are relative to a chosen directory ([`merge`]).

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

use crate::catalogue::parse_shard_name;
use crate::{BatchError, Catalogue, CatalogueEntry, Library, Shard, ShardInfo, CATALOGUE_FILE};

/// What [`merge`] found besides the merged catalogue.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MergeReport {
    /// The catalogue files read.
    pub inputs: Vec<PathBuf>,
    /// Shards no input catalogue is from (`"shard I of N"`).
    pub missing: Vec<String>,
    /// Assets of the library (as the catalogues record it) that no input
    /// lists, finished or pending: a shard's catalogue lost or cut short.
    pub missing_assets: usize,
}

/// Joins catalogues into one whose banks are relative to `out_dir`.
///
/// Each input is a catalogue file, or a directory whose
/// `catalogue-shard-I-of-N.json` files are all read, or, with no shard
/// files, its `catalogue.json`. The shard catalogues read, named as files
/// or found in directories, must agree on N; the indices none of them is
/// from are reported in [`MergeReport::missing`] (an unsharded or merged
/// catalogue among the inputs covers every shard). An asset is known by its
/// `id` (its bank as the manifest names it): entries of one asset that
/// agree on everything but `seconds`/`cached`/`warnings` and where their
/// bank now lies (one shard merged from two nodes' directories) are kept
/// once; two different results for one asset are an error (mixed runs in
/// one directory), and so are more assets than the library has. An asset
/// pending in one catalogue and finished in another is finished. The result
/// is complete when every input was and no shard or asset is missing.
pub fn merge(inputs: &[PathBuf], out_dir: &Path) -> Result<(Catalogue, MergeReport), BatchError> {
    let mut report = MergeReport::default();
    let mut finished: BTreeMap<String, CatalogueEntry> = BTreeMap::new();
    let mut pending: BTreeMap<String, String> = BTreeMap::new();
    let mut complete = true;
    let mut shards = ShardCoverage::default();
    let mut library = LibraryCheck::default();
    for input in inputs {
        for file in catalogue_files(input)? {
            let catalogue = Catalogue::load(&file)?;
            shards.add(catalogue.shard, &file)?;
            library.add(catalogue.library.as_ref(), &file)?;
            let dir = file.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            // Incomplete for its pending assets only: they are judged below
            // (another catalogue may have finished them).
            complete &= catalogue.complete || !catalogue.pending.is_empty();
            pending.extend(catalogue.pending_assets().into_iter().map(|(path, id)| (id, path)));
            for mut entry in catalogue.assets {
                let id = entry.identity().to_string();
                if let Some(bank) = &entry.bank {
                    entry.bank = Some(rebase(dir, bank, out_dir));
                }
                add_finished(&mut finished, id, entry)?;
            }
            report.inputs.push(file);
        }
    }
    if report.inputs.is_empty() {
        return Err(BatchError::Catalogue { path: "(none)".into(), message: "no catalogue to merge".into() });
    }
    report.missing = shards.missing();
    pending.retain(|id, _| !finished.contains_key(id));
    let pending: Vec<(String, String)> = pending.into_iter().map(|(id, path)| (path, id)).collect();
    let mut merged = Catalogue::new(finished.into_values().collect(), pending, Shard::WHOLE);
    merged.library = library.common();
    if let Some(lib) = &merged.library {
        let listed = merged.assets.len() + merged.pending.len();
        if listed > lib.assets {
            return Err(BatchError::Catalogue {
                path: report.inputs.first().map(|f| f.display().to_string()).unwrap_or_default(),
                message: format!(
                    "the catalogues list {listed} assets, more than the library's {}: catalogues of different \
                     runs were mixed",
                    lib.assets
                ),
            });
        }
        report.missing_assets = lib.assets - listed;
    }
    merged.complete =
        complete && merged.pending.is_empty() && report.missing.is_empty() && report.missing_assets == 0;
    Ok((merged, report))
}

/// Adds the finished `entry` of asset `id`: once, however many catalogues
/// list it; a second, different result for it is an error.
fn add_finished(
    finished: &mut BTreeMap<String, CatalogueEntry>,
    id: String,
    entry: CatalogueEntry,
) -> Result<(), BatchError> {
    // Where the bank lies after rebasing is not part of the result.
    let outcome =
        |e: &CatalogueEntry| CatalogueEntry { bank: e.bank.as_ref().map(|_| String::new()), ..e.result() };
    match finished.get(&id) {
        Some(first) if outcome(first) != outcome(&entry) => Err(BatchError::Catalogue {
            path: id,
            message: format!(
                "two different results for this bank (hashes {:?} and {:?}, status {:?} and {:?}): catalogues of \
                 different runs were mixed",
                first.hash, entry.hash, first.status, entry.status
            ),
        }),
        Some(_) => Ok(()),
        None => {
            finished.insert(id, entry);
            Ok(())
        }
    }
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
    use crate::catalogue::tests::entry;

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
        assert!(report.missing.is_empty());
        assert_eq!(report.missing_assets, 1);
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
        Catalogue::new(
            vec![entry("props/a.obj", "ok", 1.0)],
            vec![("b.obj".into(), "b.bank".into())],
            Shard::WHOLE,
        )
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

    /// One file listed twice with two materials is two assets, by their
    /// banks, failed or pending alike; one shard's catalogue found in two
    /// nodes' directories is one; more assets than the library has is mixed
    /// runs. (All three were wrong: a complete catalogue with two failed
    /// copies could not be merged, a shard given twice doubled its assets
    /// and still said complete, and two pending copies counted as one.)
    #[test]
    fn assets_are_told_apart_by_bank_across_catalogues() {
        let root = tempfile::tempdir().unwrap();
        let library = Some(Library { fingerprint: "f".into(), assets: 3 });
        let failed =
            |bank: &str| CatalogueEntry { id: bank.into(), ..entry("vase.obj", "cannot read vase.obj", 0.1) };
        let save = |dir: &str, catalogue: Catalogue| {
            let path = root.path().join(dir).join(CATALOGUE_FILE);
            Catalogue { library: library.clone(), ..catalogue }.save(&path).unwrap();
            path
        };
        let two_failures =
            vec![entry("rod.obj", "ok", 1.0), failed("vase_ceramic.bank"), failed("vase_glass.bank")];
        let whole = save("whole", Catalogue::new(two_failures, vec![], Shard::WHOLE));
        let (merged, report) = merge(std::slice::from_ref(&whole), root.path()).unwrap();
        assert!(merged.complete && report.missing.is_empty(), "{report:?}");
        assert_eq!(merged.assets.len(), 3);
        // The same catalogue from two directories: its banks rebase apart, the assets stay three.
        let copy = save("node_b", Catalogue::load(&whole).unwrap());
        let (twice, _) = merge(&[whole.clone(), copy], root.path()).unwrap();
        assert_eq!(twice.results().assets.len(), 3);
        assert_eq!(twice.assets[0].bank.as_deref(), Some("whole/rod.bank"));
        // Two pending copies of one file are two pending assets, not one missing.
        let pending = vec![
            ("vase.obj".to_string(), "vase_ceramic.bank".to_string()),
            ("vase.obj".into(), "vase_glass.bank".into()),
        ];
        let killed = save("killed", Catalogue::new(vec![entry("rod.obj", "ok", 1.0)], pending, Shard::WHOLE));
        let (merged, report) = merge(std::slice::from_ref(&killed), root.path()).unwrap();
        assert_eq!((merged.pending.len(), merged.pending_banks.len()), (2, 2));
        assert!(report.missing.is_empty() && !merged.complete, "{report:?}");
        // Finished in one catalogue, pending in the other: finished.
        let (resumed, _) = merge(&[killed, whole.clone()], root.path()).unwrap();
        assert!(resumed.pending.is_empty() && resumed.complete);
        // A fourth asset in a three-asset library: catalogues of two runs.
        let extra = save("extra", Catalogue::new(vec![entry("cup.obj", "ok", 1.0)], vec![], Shard::WHOLE));
        let err = merge(&[whole, extra], root.path()).unwrap_err().to_string();
        assert!(err.contains("list 4 assets, more than the library's 3"), "{err}");
    }
}
