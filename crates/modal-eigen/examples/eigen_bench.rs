//! Eigensolver benchmark on generated TET10 meshes; optionally writes K and M as
//! MatrixMarket for `/work/shared/tools/scipy_eigs.py`.
//!
//! `cargo run --release -p modal-eigen --example eigen_bench -- <box|bowl|bar|plate|cantilever> <h_m> <modes> [outdir]`

use modal_eigen::{solve, EigenOptions, Progress};
use modal_fem::{assemble, fix_box, node_parts, restrict, rigid_body_fields, write_matrix_market, Material};
use modal_mesh::generate::{bowl, box_mesh};
use modal_mesh::to_quadratic;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map(String::as_str).unwrap_or("box");
    let h: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.01);
    let modes: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(50);
    let cells = |l: f64| ((l / h).round() as usize).max(1);
    let mesh = match kind {
        "bowl" => bowl(0.1, 0.005, h, 2).expect("bowl mesh"),
        "bar" | "cantilever" => {
            to_quadratic(&box_mesh([0.3, 0.02, 0.01], [cells(0.3), cells(0.02), cells(0.01)]))
        }
        "plate" => to_quadratic(&box_mesh([0.2, 0.2, 0.001], [cells(0.2), cells(0.2), 1])),
        _ => to_quadratic(&box_mesh([0.2, 0.15, 0.1], [cells(0.2), cells(0.15), cells(0.1)])),
    };
    let mat = Material::custom(200e9, 0.3, 7850.0, 0.0, 0.0).expect("material");
    let t = Instant::now();
    let a = assemble(&mesh, &mat).expect("assembly");
    let t_asm = t.elapsed().as_secs_f64();
    let (k, m, rigid) = if kind == "cantilever" {
        let r = restrict(&a.k, &a.m, &fix_box(&mesh.nodes, [-1.0, -1.0, -1.0, 1e-9, 1.0, 1.0]))
            .expect("restrict");
        (r.k, r.m, None)
    } else {
        let (part, np) = node_parts(&mesh);
        (a.k, a.m, Some(rigid_body_fields(&mesh.nodes, &part, np, &[])))
    };
    if let Some(dir) = args.get(4) {
        std::fs::create_dir_all(dir).expect("outdir");
        for (name, mat) in [("K.mtx", &k), ("M.mtx", &m)] {
            let f = std::fs::File::create(format!("{dir}/{name}")).expect("create");
            write_matrix_market(mat, std::io::BufWriter::new(f)).expect("write");
        }
    }
    let mut opts = EigenOptions { max_modes: modes, ..Default::default() };
    if let Ok(o) = std::env::var("ORDER") {
        opts.ordering = if o == "amd" { modal_eigen::Ordering::Amd } else { modal_eigen::Ordering::Metis };
    }
    if let Ok(f) = std::env::var("MINF") {
        opts.min_freq_hz = f.parse().expect("MINF");
    }
    if let Ok(f) = std::env::var("MAXF") {
        opts.max_freq_hz = f.parse().expect("MAXF");
    }
    if let Ok(t) = std::env::var("THREADS") {
        opts.threads = t.parse().expect("THREADS");
    }
    if let Ok(b) = std::env::var("BLOCK") {
        opts.block_size = b.parse().expect("BLOCK");
    }
    let t = Instant::now();
    let mut log = |p: Progress| {
        if std::env::var_os("VERBOSE").is_some() {
            eprintln!("{:8.3} {p:?}", t.elapsed().as_secs_f64());
        }
    };
    let sol = solve(&k, &m, rigid.as_ref().map(|r| r.as_ref()), &opts, &mut log).expect("solve");
    let total = t.elapsed().as_secs_f64();
    let s = &sol.stats;
    let f = sol.frequencies_hz();
    let worst = sol.residuals.iter().cloned().fold(0.0, f64::max);
    // FNV-1a over the bits of every eigenvalue and vector entry: equal across runs
    // (e.g. THREADS=1 vs 2) iff the results are bit-identical.
    let mut bits = 0xcbf2_9ce4_8422_2325u64;
    let vectors = (0..sol.vectors.ncols()).flat_map(|j| (0..sol.vectors.nrows()).map(move |i| (i, j)));
    for v in sol.eigenvalues.iter().copied().chain(vectors.map(|(i, j)| sol.vectors[(i, j)])) {
        bits = (bits ^ v.to_bits()).wrapping_mul(0x100_0000_01b3);
    }
    println!(
        "{kind} h={h} dofs={} modes={} assemble={t_asm:.3}s symbolic={:.3}s factor={:.3}s iterate={:.3}s (block_solves {:.3}s orth {:.3}s checks {:.3}s) check={:.3}s total_solve={total:.3}s nnzL={} ordering={:?} restarts={} block_solves={} residual_checks={} factorizations={} inertia={}/{} max_res={worst:.2e} f1={:.2} f_last={:.2} bits={bits:016x} mem_estimate={}MB",
        k.nrows(), f.len(), s.symbolic_s, s.factor_s, s.solve_s, s.block_solve_s, s.orthogonalize_s, s.residual_check_s, s.check_s, s.factor_nnz, s.ordering.unwrap(), s.iterations, s.block_solves, s.residual_checks, s.factorizations,
        s.inertia_expected, s.inertia_found, f.first().unwrap_or(&0.0), f.last().unwrap_or(&0.0),
        s.memory_estimate_bytes >> 20
    );
}
