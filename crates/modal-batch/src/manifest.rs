//! The batch manifest (TOML; the format is documented in `docs/asset-libraries.md`):
//!
//! ```toml
//! [defaults]                 # optional; every key optional
//! material = "steel"
//! order = 1
//!
//! [[assets]]
//! path = "props/cup.obj"     # relative to the manifest
//! material = "ceramic"
//! scale = 0.001
//!
//! [[globs]]
//! pattern = "props/**/*.stl" # every match becomes an asset
//! material = "wood"
//! ```
//!
//! An option set on an asset wins over its glob's, which wins over
//! `[defaults]`, which wins over `modal precompute`'s defaults. Unknown keys
//! are errors (a misspelt `matrial` must not silently give steel).

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

use modal_fem::{Material, MaterialOverrides};
use modal_precompute::{AccuracyTarget, MeshSource, Request, SurfaceMeshing};
use serde::Deserialize;

use crate::glob::{expand_reporting, Pattern};
use crate::BatchError;

/// Per-asset options; `None` inherits (asset > glob > `[defaults]` > CLI defaults).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Options {
    /// Material preset name (as `--material`).
    pub material: Option<String>,
    /// Young's modulus E \[Pa\] (overrides the preset's).
    pub youngs: Option<f64>,
    /// Poisson's ratio ν (overrides the preset's).
    pub poisson: Option<f64>,
    /// Density ρ \[kg/m³\] (overrides the preset's).
    pub density: Option<f64>,
    /// Rayleigh α \[1/s\].
    pub alpha: Option<f64>,
    /// Rayleigh β \[s\].
    pub beta: Option<f64>,
    /// Factor applied to the coordinates (e.g. 0.001 for millimetres).
    pub scale: Option<f64>,
    /// Element order, 1 or 2.
    pub order: Option<u8>,
    /// Keep at most this many modes.
    pub modes: Option<usize>,
    /// Lowest frequency kept \[Hz\].
    pub min_freq: Option<f64>,
    /// Highest frequency kept \[Hz\].
    pub max_freq: Option<f64>,
    /// Lattice cell size \[m\] for surface meshes (the mesher option).
    pub cell: Option<f64>,
    /// Object of a multi-object surface file.
    pub part: Option<String>,
    /// Wall thickness \[m\] given to open parts (sheets modelled as one surface).
    pub sheet_thickness: Option<f64>,
    /// Per-mode error estimate of surface meshes and the accuracy to reach, as
    /// `modal precompute --accuracy` (unset everywhere: its default, 1 %).
    pub accuracy: Option<Accuracy>,
    /// Store each audible mode's acoustic transfer up to this frequency
    /// \[Hz\] in the bank, as `modal radiation --store` does (0: none).
    pub transfer_max_freq: Option<f64>,
}

/// The `accuracy` key: a target in percent (`accuracy = 0.5`), or `accuracy = "off"`
/// (one solve, no estimate: about a third faster per surface asset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Accuracy {
    /// Refine until the lowest 10 modes are estimated within this many percent.
    Target(f64),
    /// No estimate.
    Off,
}

/// The `accuracy` key as written: a number or a word.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
enum AccuracyKey {
    Percent(f64),
    Word(String),
}

impl AccuracyKey {
    fn parse(&self) -> Result<Accuracy, String> {
        match self {
            AccuracyKey::Percent(p) if p.is_finite() && *p > 0.0 => Ok(Accuracy::Target(*p)),
            AccuracyKey::Word(w) if w.eq_ignore_ascii_case("off") => Ok(Accuracy::Off),
            AccuracyKey::Percent(p) => {
                Err(format!("`accuracy` must be a positive percentage or \"off\", got {p}"))
            }
            AccuracyKey::Word(w) => {
                Err(format!("`accuracy` must be a positive percentage or \"off\", got {w:?}"))
            }
        }
    }
}

impl Options {
    /// `self` with unset fields taken from `base`.
    pub fn over(&self, base: &Options) -> Options {
        Options {
            material: self.material.clone().or_else(|| base.material.clone()),
            youngs: self.youngs.or(base.youngs),
            poisson: self.poisson.or(base.poisson),
            density: self.density.or(base.density),
            alpha: self.alpha.or(base.alpha),
            beta: self.beta.or(base.beta),
            scale: self.scale.or(base.scale),
            order: self.order.or(base.order),
            modes: self.modes.or(base.modes),
            min_freq: self.min_freq.or(base.min_freq),
            max_freq: self.max_freq.or(base.max_freq),
            cell: self.cell.or(base.cell),
            part: self.part.clone().or_else(|| base.part.clone()),
            sheet_thickness: self.sheet_thickness.or(base.sheet_thickness),
            accuracy: self.accuracy.or(base.accuracy),
            transfer_max_freq: self.transfer_max_freq.or(base.transfer_max_freq),
        }
    }
}

/// One table of the manifest as written: `[defaults]`, `[[assets]]` or
/// `[[globs]]` (which keys each may hold is checked in [`Manifest::resolve`];
/// serde's `flatten` cannot be combined with `deny_unknown_fields`).
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct Table {
    path: Option<String>,
    pattern: Option<String>,
    bank: Option<String>,
    material: Option<String>,
    youngs: Option<f64>,
    poisson: Option<f64>,
    density: Option<f64>,
    alpha: Option<f64>,
    beta: Option<f64>,
    scale: Option<f64>,
    order: Option<u8>,
    modes: Option<usize>,
    min_freq: Option<f64>,
    max_freq: Option<f64>,
    cell: Option<f64>,
    part: Option<String>,
    sheet_thickness: Option<f64>,
    accuracy: Option<AccuracyKey>,
    transfer_max_freq: Option<f64>,
}

impl Table {
    fn options(&self) -> Result<Options, String> {
        Ok(Options {
            material: self.material.clone(),
            youngs: self.youngs,
            poisson: self.poisson,
            density: self.density,
            alpha: self.alpha,
            beta: self.beta,
            scale: self.scale,
            order: self.order,
            modes: self.modes,
            min_freq: self.min_freq,
            max_freq: self.max_freq,
            cell: self.cell,
            part: self.part.clone(),
            sheet_thickness: self.sheet_thickness,
            accuracy: self.accuracy.as_ref().map(AccuracyKey::parse).transpose()?,
            transfer_max_freq: self.transfer_max_freq,
        })
    }

    /// Names of the keys among `path`, `pattern`, `bank` that are set but not `allowed`.
    fn misplaced(&self, allowed: &[&str]) -> Vec<&'static str> {
        [("path", self.path.is_some()), ("pattern", self.pattern.is_some()), ("bank", self.bank.is_some())]
            .into_iter()
            .filter(|(k, set)| *set && !allowed.contains(k))
            .map(|(k, _)| k)
            .collect()
    }
}

#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct ManifestFile {
    #[serde(default)]
    defaults: Table,
    #[serde(default)]
    assets: Vec<Table>,
    #[serde(default)]
    globs: Vec<Table>,
}

/// A parsed manifest and the directory its paths are relative to.
#[derive(Clone, Debug, PartialEq)]
pub struct Manifest {
    file: ManifestFile,
    /// Where the manifest came from (for messages).
    pub source: String,
    /// Directory that asset paths and glob patterns are relative to.
    pub base: PathBuf,
}

/// One asset to precompute, with everything resolved.
#[derive(Clone, Debug)]
pub struct Asset {
    /// The path as the manifest (or the glob match) spells it, `/`-separated,
    /// relative to the manifest: the catalogue's `path`.
    pub path: String,
    /// The bank's path inside the output directory, `/`-separated.
    pub bank: String,
    /// The pipeline request (source file, material, order, band, mesher).
    pub request: Request,
    /// Store each audible mode's acoustic transfer up to this frequency
    /// \[Hz\] in the bank (`None`: no transfer).
    pub transfer_max_hz: Option<f64>,
    /// Things the user should know (e.g. undamped material).
    pub warnings: Vec<String>,
}

impl Manifest {
    /// Parses manifest text; `base` is the directory paths are relative to.
    pub fn parse(text: &str, source: &str, base: &Path) -> Result<Manifest, BatchError> {
        let file: ManifestFile = toml::from_str(text).map_err(|e| BatchError::Toml {
            path: source.to_string(),
            message: located(e.message(), e.span().map(|span| (line_and_column(text, span.start), text))),
        })?;
        Ok(Manifest { file, source: source.to_string(), base: base.to_path_buf() })
    }

    /// Reads and parses the manifest at `path`.
    pub fn load(path: &Path) -> Result<Manifest, BatchError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| BatchError::Read { path: path.display().to_string(), source })?;
        let base = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        Manifest::parse(&text, &path.display().to_string(), base)
    }

    fn error(&self, message: String) -> BatchError {
        BatchError::Manifest { path: self.source.clone(), message }
    }

    /// Expands globs, merges options and checks everything that can be
    /// checked without solving: materials, bands, orders, bank names (no two
    /// assets may write one bank). Returns the assets sorted by bank name,
    /// and warnings (e.g. a glob matching nothing).
    ///
    /// A path listed in `[[assets]]` is taken from there even when a glob
    /// also matches it; a path matched by several globs takes the first
    /// glob's options.
    pub fn resolve(&self) -> Result<(Vec<Asset>, Vec<String>), BatchError> {
        let f = &self.file;
        if f.assets.is_empty() && f.globs.is_empty() {
            return Err(self.error("no [[assets]] and no [[globs]]: nothing to precompute".into()));
        }
        let mut warnings = Vec::new();
        let misplaced = f.defaults.misplaced(&[]);
        if !misplaced.is_empty() {
            return Err(self.error(format!("[defaults] cannot set {}", misplaced.join(", "))));
        }
        let defaults = f.defaults.options().map_err(|m| self.error(format!("[defaults]: {m}")))?;
        let mut specs: Vec<(String, Option<String>, Options, String)> = Vec::new();
        let mut explicit = std::collections::BTreeSet::new();
        for (i, a) in f.assets.iter().enumerate() {
            let Some(path) = &a.path else {
                return Err(self.error(format!("[[assets]] #{} has no `path`", i + 1)));
            };
            let table = format!("[[assets]] #{} (path = \"{path}\")", i + 1);
            let misplaced = a.misplaced(&["path", "bank"]);
            if !misplaced.is_empty() {
                return Err(self.error(format!("{table} cannot set {}", misplaced.join(", "))));
            }
            explicit.insert(normalize(path));
            let options = a.options().map_err(|m| self.error(format!("{table}: {m}")))?;
            specs.push((path.clone(), a.bank.clone(), options.over(&defaults), table));
        }
        let mut globbed = std::collections::BTreeSet::new();
        for (i, g) in f.globs.iter().enumerate() {
            let Some(text) = &g.pattern else {
                return Err(self.error(format!("[[globs]] #{} has no `pattern`", i + 1)));
            };
            let table = format!("[[globs]] #{} (pattern = \"{text}\")", i + 1);
            let misplaced = g.misplaced(&["pattern"]);
            if !misplaced.is_empty() {
                return Err(self.error(format!("{table} cannot set {}", misplaced.join(", "))));
            }
            let pattern = Pattern::new(text).map_err(|m| self.error(format!("{table}: {m}")))?;
            let (matches, not_utf8) = expand_reporting(&self.base, &pattern)?;
            if let Some(first) = not_utf8.first() {
                warnings.push(format!(
                    "{table}: {} file name(s) are not UTF-8 and are left out (e.g. {first}): rename them",
                    not_utf8.len()
                ));
            }
            if matches.is_empty() {
                warnings.push(format!("{table} matches no file under {}", self.base.display()));
            }
            let options = g.options().map_err(|m| self.error(format!("{table}: {m}")))?.over(&defaults);
            for path in matches {
                if explicit.contains(&path) || !globbed.insert(path.clone()) {
                    continue;
                }
                specs.push((path, None, options.clone(), table.clone()));
            }
        }
        let mut by_bank: BTreeMap<String, Asset> = BTreeMap::new();
        let mut origin: BTreeMap<String, String> = BTreeMap::new();
        for (path, bank, options, table) in specs {
            let asset = self.asset(&path, bank, &options).map_err(|m| self.error(format!("{table}: {m}")))?;
            if let Some(first) = origin.get(&asset.bank) {
                return Err(self.error(format!(
                    "{first} and {table} would both write bank '{}': give one of them `bank = \"…\"` \
                     in an [[assets]] table",
                    asset.bank
                )));
            }
            origin.insert(asset.bank.clone(), table);
            by_bank.insert(asset.bank.clone(), asset);
        }
        // A bank named like a directory another bank needs (`props` beside
        // `props/cup.bank`): one of the two could not be written.
        for bank in by_bank.keys() {
            let dir = format!("{bank}/");
            if let Some((inside, _)) =
                by_bank.range(dir.clone()..).next().filter(|(b, _)| b.starts_with(&dir))
            {
                return Err(self.error(format!(
                    "{} writes bank '{bank}', a file where {} needs a directory for '{inside}': give one \
                     of them another `bank = \"…\"`",
                    origin[bank], origin[inside]
                )));
            }
        }
        Ok((by_bank.into_values().collect(), warnings))
    }

    fn asset(&self, path: &str, bank: Option<String>, o: &Options) -> Result<Asset, String> {
        if path.trim().is_empty() {
            return Err("`path` is empty".into());
        }
        let path = normalize(path);
        let bank = match bank {
            Some(b) => check_bank_name(&b)?,
            None => bank_name(&path),
        };
        let overrides = MaterialOverrides {
            youngs: o.youngs,
            poisson: o.poisson,
            density: o.density,
            alpha: o.alpha,
            beta: o.beta,
        };
        let resolved = Material::resolve(o.material.as_deref(), &overrides).map_err(|e| {
            format!("invalid material ({e}; set `material = \"NAME\"`, or all of youngs, poisson, density)")
        })?;
        let mut warnings = Vec::new();
        if resolved.damping_defaulted_to_zero {
            warnings.push(format!("{path}: no damping given (alpha/beta): its modes ring forever"));
        }
        let file = if self.base == Path::new(".") { PathBuf::from(&path) } else { self.base.join(&path) };
        let mut request = Request::new(MeshSource::File(file), resolved.material);
        request.scale = o.scale.unwrap_or(1.0);
        request.scale_stated = o.scale.is_some();
        request.order = o.order.unwrap_or(request.order);
        request.max_modes = o.modes.unwrap_or(request.max_modes);
        request.min_freq_hz = o.min_freq.unwrap_or(request.min_freq_hz);
        request.max_freq_hz = o.max_freq.unwrap_or(request.max_freq_hz);
        request.surface = SurfaceMeshing {
            cell: o.cell,
            part: o.part.clone(),
            sheet_thickness: o.sheet_thickness,
            ..Default::default()
        };
        request.accuracy = match o.accuracy.unwrap_or(Accuracy::Target(AccuracyTarget::default().target_pct))
        {
            Accuracy::Target(target_pct) => Some(AccuracyTarget { target_pct, ..AccuracyTarget::default() }),
            Accuracy::Off => None,
        };
        check_request(&request, o)?;
        let transfer_max_hz = match o.transfer_max_freq {
            None => None,
            Some(0.0) => None,
            Some(f) if f.is_finite() && f > 0.0 => Some(f),
            Some(f) => {
                return Err(format!(
                    "`transfer_max_freq` must be a positive frequency in Hz or 0 (none), got {f}"
                ))
            }
        };
        Ok(Asset { path, bank, request, transfer_max_hz, warnings })
    }
}

/// The checks `modal precompute` makes on its flags, phrased with manifest keys.
fn check_request(r: &Request, o: &Options) -> Result<(), String> {
    if let Some(why) = modal_mesh::scale_refusal(r.scale) {
        return Err(format!("`scale` {why}"));
    }
    if !matches!(r.order, 1 | 2) {
        return Err(format!("`order` must be 1 or 2, got {}", r.order));
    }
    if !(1..=modal_precompute::MAX_MODES).contains(&r.max_modes) {
        return Err(format!(
            "`modes` must be between 1 and {}, got {}",
            modal_precompute::MAX_MODES,
            r.max_modes
        ));
    }
    if !(r.min_freq_hz.is_finite() && r.min_freq_hz >= 0.0) {
        return Err(format!("`min_freq` must be a non-negative number, got {}", r.min_freq_hz));
    }
    if !(r.max_freq_hz.is_finite() && r.max_freq_hz > r.min_freq_hz) {
        return Err(format!(
            "`max_freq` ({}) must be a finite number above `min_freq` ({})",
            r.max_freq_hz, r.min_freq_hz
        ));
    }
    if o.cell.is_some_and(|c| !(c.is_finite() && c > 0.0)) {
        return Err(format!("`cell` must be a positive length in metres, got {}", o.cell.unwrap_or(0.0)));
    }
    if let Some(t) = o.sheet_thickness.filter(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(format!("`sheet_thickness` must be a positive length in metres, got {t}"));
    }
    Ok(())
}

/// `path` with `\` as `/`, `.` segments and repeated separators removed.
fn normalize(path: &str) -> String {
    let unified = path.replace('\\', "/");
    let absolute = unified.starts_with('/');
    let parts: Vec<&str> = unified.split('/').filter(|s| !s.is_empty() && *s != ".").collect();
    let joined = parts.join("/");
    if absolute {
        format!("/{joined}")
    } else {
        joined
    }
}

/// `message (at line L, column C: the line)`, 1-based, the line as written
/// (it names the key a wrong value belongs to).
fn located(message: &str, at: Option<((usize, usize), &str)>) -> String {
    let Some(((line, column), text)) = at else { return message.trim().to_string() };
    let written: String = text.lines().nth(line - 1).unwrap_or_default().trim().chars().take(80).collect();
    format!("{} (at line {line}, column {column}: `{written}`)", message.trim())
}

/// The 1-based line and column (in characters) of byte `offset` of `text`.
fn line_and_column(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (before.matches('\n').count() + 1, before[line_start..].chars().count() + 1)
}

/// The default bank name of an asset: its path with the extension replaced
/// by `.bank`, `..` segments written `_up_` and a leading `/` dropped, so the
/// bank always lands inside the output directory.
pub(crate) fn bank_name(path: &str) -> String {
    let parts: Vec<String> = Path::new(path)
        .components()
        .filter_map(|c| match c {
            Component::Normal(s) => Some(s.to_string_lossy().into_owned()),
            Component::ParentDir => Some("_up_".into()),
            _ => None,
        })
        .collect();
    let joined = parts.join("/");
    let stem = match joined.rsplit_once('.') {
        Some((stem, ext)) if !ext.contains('/') && !stem.is_empty() && !stem.ends_with('/') => stem,
        _ => joined.as_str(),
    };
    format!("{stem}.bank")
}

/// Checks a `bank = "…"` name: relative, inside the output directory.
fn check_bank_name(name: &str) -> Result<String, String> {
    let outside = || format!("`bank = \"{name}\"` must be a relative path inside the output directory");
    // `x/../rod.bank` stays inside: `..` undoes the part before it, if any.
    let mut inside: Vec<&str> = Vec::new();
    let normalized = normalize(name);
    for part in normalized.split('/') {
        match part {
            ".." => {
                inside.pop().ok_or_else(outside)?;
            }
            _ => inside.push(part),
        }
    }
    let n = inside.join("/");
    let escapes = Path::new(&n).components().any(|c| !matches!(c, Component::Normal(_)));
    if n.is_empty() || escapes || normalized.starts_with('/') {
        return Err(outside());
    }
    // The catalogue would overwrite the bank (and be listed as it).
    if n == crate::CATALOGUE_FILE || crate::catalogue::parse_shard_name(&n).is_some() {
        return Err(format!("`bank = \"{name}\"` is the name of the batch's catalogue: choose another"));
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn resolve(text: &str, base: &Path) -> Result<(Vec<Asset>, Vec<String>), BatchError> {
        Manifest::parse(text, "m.toml", base)?.resolve()
    }

    #[test]
    fn options_merge_asset_over_glob_over_defaults() {
        let dir = tempfile::tempdir().unwrap();
        for f in ["props/a.obj", "props/b.obj", "props/c.stl"] {
            std::fs::create_dir_all(dir.path().join("props")).unwrap();
            std::fs::write(dir.path().join(f), "").unwrap();
        }
        let text = r#"
            [defaults]
            material = "steel"
            order = 1
            modes = 8
            [[assets]]
            path = "props/a.obj"
            material = "glass"
            scale = 0.001
            cell = 0.5
            sheet_thickness = 0.002
            [[assets]]
            path = "../shared/x.msh"
            bank = "shared_x.bank"
            [[globs]]
            pattern = "props/*.obj"
            material = "wood"
            max_freq = 8000
        "#;
        let (assets, warnings) = resolve(text, dir.path()).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        let names: Vec<&str> = assets.iter().map(|a| a.bank.as_str()).collect();
        assert_eq!(names, ["props/a.bank", "props/b.bank", "shared_x.bank"]);
        let a = &assets[0].request;
        assert_eq!(a.material.name.as_deref(), Some("glass"));
        assert_eq!((a.scale, a.order, a.max_modes, a.max_freq_hz), (0.001, 1, 8, 20_000.0));
        assert_eq!((a.surface.cell, a.surface.sheet_thickness), (Some(0.5), Some(0.002)));
        let b = &assets[1].request;
        assert_eq!(b.material.name.as_deref(), Some("wood"));
        assert_eq!((b.scale, b.order, b.max_modes, b.max_freq_hz), (1.0, 1, 8, 8000.0));
        assert_eq!(assets[1].path, "props/b.obj");
        match &assets[2].request.source {
            MeshSource::File(p) => assert_eq!(p, &dir.path().join("../shared/x.msh")),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn mistakes_are_named() {
        let base = Path::new(".");
        let err = |text: &str| resolve(text, base).unwrap_err().to_string();
        assert!(err("[[assets]]\npath = \"a.obj\"\nmatrial = \"steel\"").contains("matrial"));
        assert!(err("").contains("nothing to precompute"));
        assert!(err("[[assets]]\npath = \"a.obj\"").contains("material"));
        assert!(err("[[assets]]\npath = \"a.obj\"\nmaterial = \"unobtainium\"").contains("unobtainium"));
        let e = err("[[assets]]\npath = \"a.obj\"\nmaterial = \"steel\"\norder = 3");
        assert!(e.contains("order") && e.contains("#1"), "{e}");
        assert!(err(
            "[defaults]\nmaterial = \"steel\"\nmin_freq = 100\nmax_freq = 50\n[[assets]]\npath = \"a.obj\""
        )
        .contains("max_freq"));
        let e = err(
            "[defaults]\nmaterial = \"steel\"\n[[assets]]\npath = \"a.obj\"\n[[assets]]\npath = \"a.stl\"",
        );
        assert!(e.contains("a.bank") && e.contains("#2"), "{e}");
        assert!(err("[defaults]\nmaterial = \"steel\"\n[[assets]]\npath = \"a.obj\"\nbank = \"../x.bank\"")
            .contains("inside the output directory"));
        assert!(err("[[globs]]\npattern = \"../*.obj\"\nmaterial = \"steel\"").contains(".."));
        assert!(err("[[assets]]\npath = \"a.obj\"\nmaterial = \"steel\"\nscale = -1").contains("scale"));
        assert!(err("[[assets]]\npath = \"a.obj\"\nmaterial = \"steel\"\ncell = 0").contains("cell"));
        let thin = "[[assets]]\npath = \"a.obj\"\nmaterial = \"steel\"\nsheet_thickness = -1";
        assert!(err(thin).contains("sheet_thickness"), "{}", err(thin));
    }

    #[test]
    fn accuracy_defaults_like_precompute_and_can_be_set_or_turned_off() {
        let base = Path::new(".");
        let accuracy = |extra: &str| {
            let text = format!("[defaults]\nmaterial = \"steel\"\n{extra}\n[[assets]]\npath = \"a.obj\"");
            resolve(&text, base).map(|(assets, _)| assets[0].request.accuracy.clone())
        };
        assert_eq!(accuracy("").unwrap(), Some(AccuracyTarget::default()));
        assert_eq!(accuracy("accuracy = \"off\"").unwrap(), None);
        let half = AccuracyTarget { target_pct: 0.5, ..AccuracyTarget::default() };
        assert_eq!(accuracy("accuracy = 0.5").unwrap(), Some(half));
        assert_eq!(accuracy("accuracy = 2").unwrap().map(|a| a.target_pct), Some(2.0));
        for bad in ["accuracy = 0", "accuracy = -1", "accuracy = \"fast\""] {
            let e = accuracy(bad).unwrap_err().to_string();
            assert!(e.contains("`accuracy`") && e.contains("[defaults]"), "{bad}: {e}");
        }
    }

    #[test]
    fn transfer_is_off_unless_asked_and_can_be_turned_off_per_asset() {
        let base = Path::new(".");
        let transfer = |defaults: &str, asset: &str| {
            let text = format!(
                "[defaults]\nmaterial = \"steel\"\n{defaults}\n[[assets]]\npath = \"a.obj\"\n{asset}"
            );
            resolve(&text, base).map(|(assets, _)| assets[0].transfer_max_hz)
        };
        assert_eq!(transfer("", "").unwrap(), None);
        assert_eq!(transfer("transfer_max_freq = 6000", "").unwrap(), Some(6000.0));
        assert_eq!(transfer("transfer_max_freq = 6000", "transfer_max_freq = 0").unwrap(), None);
        assert_eq!(transfer("", "transfer_max_freq = 12000.5").unwrap(), Some(12000.5));
        for bad in ["transfer_max_freq = -1", "transfer_max_freq = nan", "transfer_max_freq = inf"] {
            let e = transfer("", bad).unwrap_err().to_string();
            assert!(e.contains("`transfer_max_freq`") && e.contains("#1"), "{bad}: {e}");
        }
        let e = transfer("", "transfer_max_freq = \"high\"").unwrap_err().to_string();
        assert!(e.contains("transfer_max_freq"), "{e}");
    }

    #[test]
    fn a_glob_matching_nothing_warns() {
        let dir = tempfile::tempdir().unwrap();
        let (assets, warnings) =
            resolve("[[globs]]\npattern = \"*.obj\"\nmaterial = \"steel\"", dir.path()).unwrap();
        assert!(assets.is_empty());
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("matches no file"));
    }

    #[test]
    fn a_bank_may_not_take_the_catalogue_s_name() {
        for name in ["catalogue.json", "catalogue-shard-1-of-3.json", "./catalogue.json"] {
            assert!(check_bank_name(name).unwrap_err().contains("catalogue"), "{name}");
        }
        assert_eq!(check_bank_name("sub/catalogue.json").unwrap(), "sub/catalogue.json");
        // `..` that stays inside is followed; one that leaves, or an absolute path, is not.
        assert_eq!(check_bank_name("x/./y/../rod.bank").unwrap(), "x/rod.bank");
        for outside in ["../rod.bank", "x/../../rod.bank", "/abs/rod.bank", "x/.."] {
            assert!(
                check_bank_name(outside).unwrap_err().contains("inside the output directory"),
                "{outside}"
            );
        }
    }

    /// A manifest's TOML error is one line with where it is (its caret
    /// diagram was squashed into the error line).
    #[test]
    fn a_manifest_typo_is_one_line_with_its_place() {
        let text = "# ünïcode first\n[defaults]\nmaterial = \"steel\"\n  modse = 4\n";
        let e = resolve(text, Path::new(".")).unwrap_err().to_string();
        assert!(!e.contains('\n') && !e.contains('|') && !e.contains('^'), "{e}");
        assert!(
            e.contains("unknown field `modse`") && e.ends_with("(at line 4, column 3: `modse = 4`)"),
            "{e}"
        );
        assert_eq!(line_and_column("aé\nbc", 5), (2, 2));
    }

    #[test]
    fn a_bank_named_like_another_banks_directory_is_refused() {
        let text = "[defaults]\nmaterial = \"steel\"\n[[assets]]\npath = \"a.obj\"\nbank = \"props\"\n\
                    [[assets]]\npath = \"props/cup.obj\"\n[[assets]]\npath = \"propsx/cup.obj\"";
        let e = resolve(text, Path::new(".")).unwrap_err().to_string();
        assert!(e.contains("writes bank 'props', a file where") && e.contains("'props/cup.bank'"), "{e}");
        let apart = text.replace("bank = \"props\"", "bank = \"props.bank\"");
        assert!(resolve(&apart, Path::new(".")).is_ok(), "'props.bank' and 'propsx/' need no 'props/'");
    }

    #[test]
    fn bank_names_stay_inside_the_output_directory() {
        assert_eq!(bank_name("props/cup.obj"), "props/cup.bank");
        assert_eq!(bank_name("./cup.tar.obj"), "cup.tar.bank");
        assert_eq!(bank_name("../lib/cup.obj"), "_up_/lib/cup.bank");
        assert_eq!(bank_name("/abs/cup"), "abs/cup.bank");
        assert_eq!(bank_name("dir.v2/cup"), "dir.v2/cup.bank");
        assert_eq!(normalize("a//b/./c.obj"), "a/b/c.obj");
        assert_eq!(normalize("a\\b.obj"), "a/b.obj");
    }
}
