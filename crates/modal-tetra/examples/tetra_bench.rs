//! Benchmark: triangles in → tets out → time, on icospheres of 1k / 20k
//! (and with `--big` 327k) triangles at the default resolution.
//! `cargo run --release -p modal-tetra --example tetra_bench [--big]`

use std::time::Instant;

use modal_tetra::{shapes, tetrahedralize, TetOptions};

fn main() {
    let big = std::env::args().any(|a| a == "--big");
    let fine = TetOptions { target_tets: Some(200_000), ..Default::default() };
    let mut cases = vec![
        ("icosphere 3", shapes::icosphere(0.05, 3), TetOptions::default()),
        ("icosphere 5", shapes::icosphere(0.05, 5), TetOptions::default()),
        ("icosphere 5, target 200k tets", shapes::icosphere(0.05, 5), fine),
    ];
    cases.push(("bowl (meshes/bowl.obj)", shapes::bowl(0.08, 0.006, 40), TetOptions::default()));
    cases.push(("mug (meshes/mug.obj)", shapes::mug(0.04, 0.1, 0.005, 40), TetOptions::default()));
    if big {
        cases.push(("icosphere 7", shapes::icosphere(0.05, 7), TetOptions::default()));
    }
    println!("| input | triangles | tets | nodes | min/max dihedral (°) | time (s) |");
    println!("|---|---|---|---|---|---|");
    for (name, surface, options) in cases {
        let start = Instant::now();
        match tetrahedralize(&surface, &options) {
            Ok((_, r)) => println!(
                "| {name} | {} | {} | {} | {:.1} / {:.1} | {:.2} |",
                surface.triangles.len(),
                r.tets,
                r.nodes,
                r.min_dihedral_deg,
                r.max_dihedral_deg,
                start.elapsed().as_secs_f64()
            ),
            Err(e) => println!("| {name} | {} | error: {e} | | | |", surface.triangles.len()),
        }
    }
}
