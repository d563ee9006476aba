//! Benchmark: triangles in → tets out → time, on icospheres of 1k / 20k
//! (and with `--big` 327k) triangles at the default resolution.
//! `cargo run --release -p modal-tetra --example tetra_bench [--big]`

use std::time::Instant;

use modal_tetra::{shapes, tetrahedralize, TetOptions};

fn main() {
    let big = std::env::args().any(|a| a == "--big");
    let mut cases =
        vec![("icosphere 3", shapes::icosphere(0.05, 3)), ("icosphere 5", shapes::icosphere(0.05, 5))];
    cases.push(("bowl", shapes::bowl(0.08, 0.006, 40)));
    cases.push(("mug", shapes::mug(0.04, 0.1, 0.005, 40)));
    if big {
        cases.push(("icosphere 7", shapes::icosphere(0.05, 7)));
    }
    println!("| input | triangles | tets | nodes | min/max dihedral (°) | time (s) |");
    println!("|---|---|---|---|---|---|");
    for (name, surface) in cases {
        let start = Instant::now();
        match tetrahedralize(&surface, &TetOptions::default()) {
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
