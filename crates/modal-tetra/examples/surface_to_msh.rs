//! Tetrahedralizes a surface file and writes Gmsh MSH 4.1 (for cross-checks
//! with external FEM tools): `cargo run -p modal-tetra --example surface_to_msh
//! -- IN.(obj|stl|ply) OUT.msh [CELLS_PER_DIAGONAL]`. With IN = `icosphere`
//! a 5120-triangle sphere of radius 0.05 m is used.

use modal_tetra::{read_surface, shapes, tetrahedralize, TetOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(input), Some(output)) = (args.get(1), args.get(2)) else {
        return Err("usage: surface_to_msh IN.(obj|stl|ply)|icosphere OUT.msh [CELLS_PER_DIAGONAL]".into());
    };
    let surface =
        if input == "icosphere" { shapes::icosphere(0.05, 4) } else { read_surface(input, 1.0, None)?.0 };
    let mut options = TetOptions::default();
    if let Some(c) = args.get(3) {
        options.cells_per_diagonal = c.parse()?;
    }
    let (mesh, report) = tetrahedralize(&surface, &options)?;
    modal_mesh::write_msh41_file(std::path::Path::new(output), &mesh)?;
    println!("{report:?}");
    Ok(())
}
