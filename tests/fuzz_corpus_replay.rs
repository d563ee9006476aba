//! Replays the fuzz corpus (`fuzz/corpus/<target>/*`) through every parser on
//! stable Rust, plus deterministic mutants of each entry (bit flips, byte
//! overwrites, truncations, duplicated spans), so CI catches a panic on
//! hostile input even without nightly cargo-fuzz. Each parser must return
//! (Ok or a typed error) and never panic.

use std::path::Path;

/// The parser behind a fuzz target (same calls as `fuzz/fuzz_targets/*.rs`).
fn run_target(target: &str, data: &[u8]) {
    match target {
        "msh" => check_mesh(modal_mesh::io::read_msh(data, 1.0)),
        "medit" => check_mesh(modal_mesh::io::read_medit(data, 1.0)),
        "tetgen" => {
            let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
            let (node, ele) = data.split_at(split);
            check_mesh(modal_mesh::io::read_tetgen(node, ele.get(1..).unwrap_or(&[]), 1.0));
        }
        "obj" => drop(modal_tetra::parse_surface(data, modal_tetra::SurfaceFormat::Obj, 1.0, None)),
        "stl" => drop(modal_tetra::parse_surface(data, modal_tetra::SurfaceFormat::Stl, 1.0, None)),
        "ply" => drop(modal_tetra::parse_surface(data, modal_tetra::SurfaceFormat::Ply, 1.0, None)),
        "bank" => drop(modal_bank::ModeBank::from_bytes(data)),
        "scene" => {
            if let Ok(text) = std::str::from_utf8(data) {
                drop(modal_scene::Scene::from_toml_str(text, Path::new(".")));
            }
        }
        other => panic!("corpus folder '{other}' has no target"),
    }
}

/// A parsed mesh also goes through the checks, as in the fuzz targets.
fn check_mesh(parsed: Result<modal_mesh::TetMesh, modal_mesh::MeshError>) {
    if let Ok(mesh) = parsed {
        drop(modal_mesh::check(mesh));
    }
}

/// xorshift64*: deterministic mutations, the same on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The `k`-th mutant of `seed`.
fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut data = seed.to_vec();
    if data.is_empty() {
        return vec![rng.next() as u8];
    }
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(data.len());
        match rng.below(5) {
            0 => data[at] ^= 1 << rng.below(8),
            1 => data[at] = [b'0', b'9', b'-', b' ', b'\n', 0xff, b'e', b'.'][rng.below(8)],
            2 => data.truncate(at),
            3 => {
                let len = rng.below(64).min(data.len() - at);
                let span = data[at..at + len].to_vec();
                let to = rng.below(data.len());
                data.splice(to..to, span);
            }
            _ => data.insert(at, b"999999999"[rng.below(9)]),
        }
        if data.is_empty() {
            break;
        }
    }
    data
}

#[test]
fn corpus_and_mutants_never_panic() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let mut replayed = 0;
    for target_dir in std::fs::read_dir(&corpus).expect("fuzz/corpus exists") {
        let target_dir = target_dir.unwrap().path();
        let target = target_dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut entries: Vec<_> =
            std::fs::read_dir(&target_dir).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for (k, entry) in entries.iter().enumerate() {
            let seed = std::fs::read(entry).unwrap();
            run_target(&target, &seed);
            // Hand-written seeds get many mutants; the 48 cargo-fuzz-minimized
            // entries per target (named by their SHA-1) and large seeds fewer,
            // so the test stays quick in debug builds.
            let minimized = entry.file_name().is_some_and(|n| n.len() == 40);
            let mutants = if seed.len() > 10_000 {
                50
            } else if minimized {
                40
            } else {
                1000
            };
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ ((k as u64 + 1) * 7919));
            for _ in 0..mutants {
                run_target(&target, &mutate(&seed, &mut rng));
            }
            replayed += 1;
        }
    }
    assert!(
        replayed >= 8 * 49,
        "every target has its seeds and minimized corpus ({replayed} entries replayed)"
    );
}
