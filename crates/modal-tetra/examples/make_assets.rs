//! Writes the example surface meshes under `meshes/` (OBJ, metres):
//! `cargo run -p modal-tetra --example make_assets [OUT_DIR]`.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;

use modal_tetra::{shapes, write_obj, TriSurface};

fn main() -> std::io::Result<()> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "meshes".into()));
    std::fs::create_dir_all(&dir)?;
    let assets: [(&str, TriSurface); 4] = [
        // Hemispherical bowl, 8 cm radius, 6 mm wall.
        ("bowl.obj", shapes::bowl(0.08, 0.006, 40)),
        // Bell-like shell, 15 cm tall, 8 cm mouth radius, 8 mm wall.
        ("bell.obj", shapes::bell(0.15, 0.08, 0.008, 40)),
        // The steel bar of shared/reference/analytic.md §1: 0.3 × 0.02 × 0.01 m.
        ("bar.obj", shapes::cuboid(0.3, 0.02, 0.01)),
        // Mug: cup (4 cm radius, 10 cm tall, 5 mm wall) and a torus handle, two overlapping parts.
        ("mug.obj", shapes::mug(0.04, 0.1, 0.005, 40)),
    ];
    for (name, surface) in assets {
        let path = dir.join(name);
        write_obj(&surface, BufWriter::new(File::create(&path)?))?;
        println!("{} ({} triangles)", path.display(), surface.triangles.len());
    }
    Ok(())
}
