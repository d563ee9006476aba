//! Prints the tet report and time for the example shapes (development aid).
use modal_tetra::{shapes, tetrahedralize, TetOptions};

fn main() {
    for s in
        [shapes::bowl(0.1, 0.01, 48), shapes::bell(0.2, 0.1, 0.012, 48), shapes::mug(0.04, 0.1, 0.005, 48)]
    {
        let t = std::time::Instant::now();
        let (_, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
        println!(
            "{:?} {} tris -> {} tets, h {:.4}, {:.2}..{:.2}, vol {:.3}%, {:?}",
            s.parts[0].0,
            s.triangles.len(),
            r.tets,
            r.cell_m,
            r.min_dihedral_deg,
            r.max_dihedral_deg,
            100.0 * (r.volume_m3 / r.surface_volume_m3 - 1.0),
            t.elapsed()
        );
    }
}
