//! Glob patterns for `[[globs]]`: `/`-separated segments where `*` matches
//! any run of characters within one segment, `?` one character, and a whole
//! segment `**` any number of directories (zero included). Names starting
//! with `.` are matched only by a segment that itself starts with `.`.
//! Matches are returned sorted, as `/`-separated paths relative to the base
//! directory, so a manifest expands identically on every machine.

use std::path::{Path, PathBuf};

use crate::BatchError;

/// A parsed glob pattern.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pattern {
    segments: Vec<String>,
}

impl Pattern {
    /// Parses `text` (relative, `/`-separated; no `..` segment, not empty).
    pub fn new(text: &str) -> Result<Pattern, String> {
        if text.is_empty() {
            return Err("the pattern is empty".into());
        }
        if text.starts_with('/') || text.contains('\\') {
            return Err(format!("pattern '{text}' must be relative to the manifest and use '/'"));
        }
        let segments: Vec<String> =
            text.split('/').filter(|s| !s.is_empty() && *s != ".").map(str::to_string).collect();
        if segments.iter().any(|s| s == "..") {
            return Err(format!("pattern '{text}' must not contain '..'"));
        }
        if segments.last().is_none_or(|s| s == "**") {
            return Err(format!("pattern '{text}' must end in a file name pattern"));
        }
        Ok(Pattern { segments })
    }

    /// True when the relative `/`-separated `path` matches.
    pub fn matches(&self, path: &str) -> bool {
        let parts: Vec<&str> = path.split('/').filter(|s| !s.is_empty()).collect();
        match_segments(&self.segments, &parts)
    }
}

fn match_segments(pattern: &[String], parts: &[&str]) -> bool {
    match pattern.split_first() {
        None => parts.is_empty(),
        Some((seg, rest)) if seg == "**" => (0..=parts.len()).any(|skip| {
            parts[..skip].iter().all(|p| !p.starts_with('.')) && match_segments(rest, &parts[skip..])
        }),
        Some((seg, rest)) => {
            parts.split_first().is_some_and(|(p, tail)| match_name(seg, p) && match_segments(rest, tail))
        }
    }
}

/// `*` and `?` matching of one path segment (hidden names need a literal `.`).
fn match_name(pattern: &str, name: &str) -> bool {
    if name.starts_with('.') && !pattern.starts_with('.') {
        return false;
    }
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    // Iterative wildcard match with backtracking to the last `*`.
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some((i, j));
            i += 1;
        } else if let Some((si, sj)) = star {
            i = si + 1;
            j = sj + 1;
            star = Some((si, sj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// The regular files under `base` that `pattern` matches, sorted, as
/// `/`-separated relative paths. Symbolic links to files are followed;
/// symbolic links to directories are not descended by `**` (no cycles).
pub fn expand(base: &Path, pattern: &Pattern) -> Result<Vec<String>, BatchError> {
    Ok(expand_reporting(base, pattern)?.0)
}

/// [`expand`], and the names it could not match because they are not
/// UTF-8 (a manifest's paths and bank names are text), lossily, sorted.
pub fn expand_reporting(base: &Path, pattern: &Pattern) -> Result<(Vec<String>, Vec<String>), BatchError> {
    let mut walker = Walk { base, found: Vec::new(), not_utf8: Vec::new() };
    walker.walk(&mut Vec::new(), &pattern.segments)?;
    for list in [&mut walker.found, &mut walker.not_utf8] {
        list.sort();
        list.dedup();
    }
    Ok((walker.found, walker.not_utf8))
}

/// A pattern's walk under `base`: the files found, the names skipped.
struct Walk<'a> {
    base: &'a Path,
    found: Vec<String>,
    not_utf8: Vec<String>,
}

impl Walk<'_> {
    /// The entries of `dir`, noting the names that are not UTF-8.
    fn entries(&mut self, dir: &Path) -> Result<Vec<(String, Kind)>, BatchError> {
        let (entries, not_utf8) = entries(dir)?;
        self.not_utf8.extend(not_utf8.into_iter().map(|name| dir.join(name).display().to_string()));
        Ok(entries)
    }

    fn walk(&mut self, prefix: &mut Vec<String>, pattern: &[String]) -> Result<(), BatchError> {
        let Some((seg, rest)) = pattern.split_first() else { return Ok(()) };
        let dir: PathBuf = prefix.iter().fold(self.base.to_path_buf(), |d, p| d.join(p));
        if seg == "**" {
            self.walk(prefix, rest)?;
            for (name, kind) in self.entries(&dir)? {
                if kind == Kind::Dir && !name.starts_with('.') {
                    prefix.push(name);
                    self.walk(prefix, pattern)?;
                    prefix.pop();
                }
            }
            return Ok(());
        }
        for (name, kind) in self.entries(&dir)? {
            if !match_name(seg, &name) {
                continue;
            }
            match (rest.is_empty(), kind) {
                (true, Kind::File) => {
                    let mut parts = prefix.clone();
                    parts.push(name);
                    self.found.push(parts.join("/"));
                }
                (false, Kind::Dir | Kind::LinkDir) => {
                    prefix.push(name);
                    self.walk(prefix, rest)?;
                    prefix.pop();
                }
                _ => {}
            }
        }
        Ok(())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    File,
    Dir,
    /// A symbolic link to a directory: entered by literal segments, not by `**`.
    LinkDir,
    Other,
}

/// A directory's entries with their kinds, and the names that are not UTF-8.
type Listing = (Vec<(String, Kind)>, Vec<std::ffi::OsString>);

/// The entries of `dir`; a missing directory has none.
fn entries(dir: &Path) -> Result<Listing, BatchError> {
    let read_err = |source| BatchError::Read { path: dir.display().to_string(), source };
    let rd = match std::fs::read_dir(dir) {
        Ok(rd) => rd,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Default::default()),
        Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => return Ok(Default::default()),
        Err(e) => return Err(read_err(e)),
    };
    let (mut out, mut not_utf8) = (Vec::new(), Vec::new());
    for entry in rd {
        let entry = entry.map_err(read_err)?;
        let Some(name) = entry.file_name().to_str().map(str::to_string) else {
            not_utf8.push(entry.file_name());
            continue;
        };
        let link = entry.file_type().is_ok_and(|t| t.is_symlink());
        let kind = match std::fs::metadata(entry.path()) {
            Ok(m) if m.is_file() => Kind::File,
            Ok(m) if m.is_dir() && link => Kind::LinkDir,
            Ok(m) if m.is_dir() => Kind::Dir,
            _ => Kind::Other,
        };
        out.push((name, kind));
    }
    out.sort();
    Ok((out, not_utf8))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_match_stars_and_question_marks() {
        assert!(match_name("*.obj", "cup.obj"));
        assert!(!match_name("*.obj", "cup.stl"));
        assert!(match_name("c?p.*", "cup.obj"));
        assert!(match_name("*a*b*", "xxaxxbxx"));
        assert!(!match_name("*a*b", "xxaxxbxx"));
        assert!(match_name("*", "anything"));
        assert!(!match_name("*", ".hidden"));
        assert!(match_name(".*", ".hidden"));
        assert!(match_name("a*", "a"));
        assert!(!match_name("a?", "a"));
    }

    #[test]
    fn double_star_spans_directories() {
        let p = Pattern::new("props/**/*.obj").unwrap();
        assert!(p.matches("props/cup.obj"));
        assert!(p.matches("props/kitchen/old/cup.obj"));
        assert!(!p.matches("other/cup.obj"));
        assert!(!p.matches("props/.git/cup.obj"));
        assert!(Pattern::new("../x/*.obj").is_err());
        assert!(Pattern::new("/abs/*.obj").is_err());
        assert!(Pattern::new("props/**").is_err());
        assert!(Pattern::new("").is_err());
    }

    #[test]
    fn expansion_is_sorted_and_matches_the_matcher() {
        let dir = tempfile::tempdir().unwrap();
        let files =
            ["props/b.obj", "props/a.obj", "props/sub/c.obj", "props/sub/d.stl", "props/.h/e.obj", "f.obj"];
        for f in files {
            let path = dir.path().join(f);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, "x").unwrap();
        }
        let flat = expand(dir.path(), &Pattern::new("props/*.obj").unwrap()).unwrap();
        assert_eq!(flat, ["props/a.obj", "props/b.obj"]);
        let deep = Pattern::new("**/*.obj").unwrap();
        let all = expand(dir.path(), &deep).unwrap();
        assert_eq!(all, ["f.obj", "props/a.obj", "props/b.obj", "props/sub/c.obj"]);
        // Expansion agrees with the matcher on every file.
        for f in files {
            assert_eq!(all.contains(&f.to_string()), deep.matches(f), "{f}");
        }
        assert!(expand(dir.path(), &Pattern::new("none/*.obj").unwrap()).unwrap().is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn names_that_are_not_utf8_are_reported_not_dropped_silently() {
        use std::os::unix::ffi::OsStrExt;
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("good.msh"), b"").unwrap();
        let latin1 = std::ffi::OsStr::from_bytes(b"caf\xe9.msh");
        if std::fs::write(dir.path().join(latin1), b"").is_err() {
            return; // a file system that refuses such names has none to report
        }
        let (found, not_utf8) = expand_reporting(dir.path(), &Pattern::new("**/*.msh").unwrap()).unwrap();
        assert_eq!(found, ["good.msh"]);
        assert_eq!(not_utf8.len(), 1, "{not_utf8:?}");
        assert!(not_utf8[0].ends_with("caf\u{FFFD}.msh"), "{not_utf8:?}");
    }
}
