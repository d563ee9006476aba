//! Helpers for end-to-end tests of the `modal` binary.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Exit status and captured output of one `modal` run.
pub struct Run {
    pub success: bool,
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `modal ARGS` in `dir` with a private cache directory.
pub fn modal(dir: &Path, args: &[&str]) -> Run {
    modal_with_env(dir, args, &[])
}

/// [`modal`] under a memory guard of `gb` GB (`MODAL_MEMORY_LIMIT_GB`, as given).
pub fn modal_within_memory(dir: &Path, args: &[&str], gb: &str) -> Run {
    modal_with_env(dir, args, &[("MODAL_MEMORY_LIMIT_GB", Path::new(gb))])
}

/// [`modal`] with extra environment variables.
pub fn modal_with_env(dir: &Path, args: &[&str], env: &[(&str, &Path)]) -> Run {
    let output = Command::new(env!("CARGO_BIN_EXE_modal"))
        .args(args)
        .current_dir(dir)
        .env("MODAL_CACHE_DIR", dir.join("cache"))
        .envs(env.iter().copied())
        .output()
        .expect("the modal binary runs");
    Run {
        success: output.status.success(),
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

impl Run {
    /// Asserts the run succeeded, showing its stderr otherwise.
    pub fn ok(self) -> Self {
        assert!(self.success, "modal failed: {}\nstdout: {}", self.stderr, self.stdout);
        self
    }

    /// Asserts a clean failure: non-zero exit, exactly one `error:` line on
    /// stderr mentioning `needle` (case-insensitive), no panic.
    pub fn fails_with(self, needle: &str) -> Self {
        assert!(!self.success, "expected failure, got success: {}", self.stdout);
        assert_eq!(self.code, Some(1), "expected exit code 1, stderr: {}", self.stderr);
        assert!(!self.stderr.contains("panicked"), "panic: {}", self.stderr);
        let errors: Vec<&str> = self.stderr.lines().filter(|l| l.starts_with("error")).collect();
        assert_eq!(errors.len(), 1, "expected one error line, got: {}", self.stderr);
        assert!(
            errors[0].to_lowercase().contains(&needle.to_lowercase()),
            "error line '{}' does not mention '{needle}'",
            errors[0]
        );
        self
    }

    /// Parses stdout as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(&self.stdout)
            .unwrap_or_else(|e| panic!("stdout is not JSON ({e}): {}", self.stdout))
    }
}

/// A fresh temporary directory.
pub fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// Path of a committed example mesh.
pub fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes").join(name)
}

/// Files in `dir` (names), to check nothing partial was left behind.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    names.sort();
    names
}

/// Explicit steel of the reference tables (not the preset, whose ν is 0.29).
pub const STEEL: [&str; 6] = ["--youngs", "200e9", "--poisson", "0.3", "--density", "7850"];
