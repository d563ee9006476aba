//! Times the mesh stage on a given file and on generated spheres.
//!
//! usage: cargo run --release -p modal-mesh --example mesh_bench -- FILE.msh [H_M]
//! Prints seconds and throughput (tets/s, MB/s) for read, check, surface,
//! write, and for `generate(Sphere { radius: 0.05 }, H, order)`.

use std::path::PathBuf;
use std::time::Instant;

use modal_mesh::generate::{generate, Shape};
use modal_mesh::{boundary_surface, check, read_mesh, write_msh41};

fn timed<T>(label: &str, work: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let out = work();
    let seconds = start.elapsed().as_secs_f64();
    println!("{label:<40} {seconds:>8.3} s");
    (out, seconds)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().ok_or("usage: mesh_bench FILE.msh [H_M]")?);
    let h: f64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(0.0025);
    let megabytes = std::fs::metadata(&path)?.len() as f64 / 1e6;
    let (mesh, read_s) = timed("read", || read_mesh(&path, 1.0));
    let mesh = mesh?;
    let tets = mesh.cells.len() as f64;
    println!(
        "  {} nodes, {} tets, {megabytes:.1} MB: {:.1} MB/s, {:.2e} tets/s",
        mesh.nodes.len(),
        tets,
        megabytes / read_s,
        tets / read_s
    );
    let (checked, check_s) = timed("check", || check(mesh));
    let (mesh, report) = checked?;
    println!("  {:.2e} tets/s, {} parts, {} reoriented", tets / check_s, report.parts, report.reoriented);
    let (surface, _) = timed("boundary_surface", || boundary_surface(&mesh));
    println!("  {} triangles", surface.triangles.len());
    let (bytes, _) = timed("write_msh41 (to memory)", || {
        let mut bytes = Vec::new();
        write_msh41(&mesh, &mut bytes).map(|_| bytes)
    });
    println!("  {:.1} MB", bytes?.len() as f64 / 1e6);
    for order in [1, 2] {
        let (generated, s) = timed(&format!("generate sphere R=0.05 h={h} order {order}"), || {
            generate(&Shape::Sphere { radius: 0.05 }, h, order)
        });
        let generated = generated?;
        println!(
            "  {} nodes, {} tets, {:.2e} tets/s",
            generated.nodes.len(),
            generated.cells.len(),
            generated.cells.len() as f64 / s
        );
    }
    Ok(())
}
