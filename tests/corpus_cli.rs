//! Issue 14: the generated corpus of real-world-like assets through the CLI.
//!
//! Fast cases run in CI; the full set at default settings is `#[ignore]`d
//! (run it with `cargo test --release --test corpus_cli -- --ignored`).

mod common;

use common::{modal, temp_dir};
use modal_tetra::corpus::{asset, ASSETS};

#[test]
fn corpus_command_writes_every_asset_as_a_readable_obj() {
    let dir = temp_dir();
    let out = dir.path().join("corpus");
    let run = modal(dir.path(), &["mesh", "corpus", "--out", out.to_str().unwrap(), "--json"]).ok();
    let listed = run.json();
    let listed = listed.as_array().expect("a JSON list");
    assert_eq!(listed.len(), ASSETS.len());
    for (entry, info) in listed.iter().zip(ASSETS) {
        assert_eq!(entry["name"], info.name);
        let path = out.join(format!("{}.obj", info.name));
        let (read, report) = modal_tetra::read_surface(&path, 1.0, None).expect("the OBJ reads back");
        let generated = asset(info.name).unwrap();
        assert_eq!(read.triangles.len(), generated.triangles.len(), "{}", info.name);
        assert_eq!(entry["triangles"], generated.triangles.len());
        assert!((report.diagonal_m - 0.2).abs() < 1e-9, "{}: {}", info.name, report.diagonal_m);
        let names: Vec<&str> = read.parts.iter().map(|(n, _)| n.as_str()).collect();
        let want: Vec<&str> = generated.parts.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, want, "{}", info.name);
        let size = std::fs::metadata(&path).unwrap().len();
        assert!(size < 400_000, "{} is {size} bytes", info.name);
    }
}

#[test]
fn corpus_command_refuses_an_unknown_name_in_one_line() {
    let dir = temp_dir();
    modal(dir.path(), &["mesh", "corpus", "--out", "x", "--name", "dragon"]).fails_with("teapot");
    assert!(!dir.path().join("x").exists());
}
