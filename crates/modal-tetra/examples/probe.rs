//! Prints the tet report for a few generated shapes (development aid).
use modal_tetra::{shapes, tetrahedralize, TetOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cpd: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(25.0);
    let opts = TetOptions { cells_per_diagonal: cpd, ..Default::default() };
    let mut worst = (180.0f64, 0.0f64);
    for k in 0..20 {
        let r = 0.05 * (1.0 + 0.037 * k as f64);
        let mut s = shapes::icosphere(r, 4);
        let off = [0.0013 * k as f64, 0.0007 * k as f64, -0.0011 * k as f64];
        for p in &mut s.vertices {
            for c in 0..3 {
                p[c] += off[c];
            }
        }
        let t = std::time::Instant::now();
        let o = TetOptions { cells_per_diagonal: cpd + 0.713 * k as f64, ..opts.clone() };
        let s = if k % 3 == 1 {
            shapes::torus(0.05, 0.02 + 0.001 * k as f64, 64, 24)
        } else if k % 3 == 2 {
            shapes::bowl(0.1, 0.012, 48)
        } else {
            s
        };
        let (_, rep) = tetrahedralize(&s, &o).unwrap();
        worst = (worst.0.min(rep.min_dihedral_deg), worst.1.max(rep.max_dihedral_deg));
        println!(
            "{k} tets {} nodes {} dihedral {:.2}..{:.2} vol err {:.3}% dev {:.2e} drop {} {:?}",
            rep.tets,
            rep.nodes,
            rep.min_dihedral_deg,
            rep.max_dihedral_deg,
            100.0 * (rep.volume_m3 / rep.surface_volume_m3 - 1.0),
            rep.max_surface_deviation_m / rep.cell_m,
            rep.dropped_degenerate,
            t.elapsed()
        );
    }
    println!("worst {worst:?}");
}
