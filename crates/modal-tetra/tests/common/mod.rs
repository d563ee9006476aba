//! Helpers shared by the integration tests.
#![allow(dead_code)]

use modal_mesh::{Cells, TetMesh};
use modal_tetra::{
    dihedral_angles_deg, TetReport, TriSurface, DIHEDRAL_BOUNDS_DEG, GRADED_DIHEDRAL_BOUNDS_DEG,
};

/// Checks the output contract of `tetrahedralize` with `modal_mesh::check`
/// (independent code) and the dihedral-angle bounds on every tet.
pub fn assert_good(mesh: &TetMesh, report: &TetReport) {
    let (checked, r) = modal_mesh::check(mesh.clone()).expect("mesh passes modal_mesh::check");
    assert_eq!(r.reoriented, 0, "all tets positively oriented");
    assert_eq!(r.unused_nodes_dropped, 0, "no unused nodes");
    assert_eq!(checked.nodes.len(), report.nodes);
    assert_eq!(r.tets, report.tets);
    let volume = modal_mesh::mesh_volume(&checked);
    assert!((volume - report.volume_m3).abs() <= 1e-9 * volume);
    match &mesh.cells {
        Cells::Tet4(_) => assert_eq!(report.curved_edges, 0),
        Cells::Tet10(_) => {
            // Mid-edge nodes lie on their edge or, on the boundary, on the surface.
            assert!(report.max_surface_deviation_m.is_finite());
        }
    }
    // A thin shell's layers take their shapes from the input's own triangles
    // (a fan at a bell's axis gives 7.5° corners): no angle bound holds there.
    if report.wall_layers > 0 {
        return;
    }
    // Graded meshes (background refined below the lattice cell) have their own bounds.
    let (lo, hi) = if report.min_cell_m < 0.8 * report.cell_m {
        GRADED_DIHEDRAL_BOUNDS_DEG
    } else {
        DIHEDRAL_BOUNDS_DEG
    };
    for e in 0..mesh.cells.len() {
        let t = mesh.cells.corners(e);
        for a in dihedral_angles_deg(t.map(|i| mesh.nodes[i])) {
            assert!((lo..=hi).contains(&a), "tet {e}: dihedral angle {a:.2}° outside [{lo}, {hi}]");
        }
    }
    assert!(report.min_dihedral_deg >= lo && report.max_dihedral_deg <= hi, "{report:?}");
}

/// Relative difference a/b − 1.
pub fn rel(a: f64, b: f64) -> f64 {
    a / b - 1.0
}

/// Writes `surface` as OBJ into a temporary file and returns its path guard.
pub fn temp_obj(surface: &TriSurface) -> tempfile::TempPath {
    let file = tempfile::Builder::new().suffix(".obj").tempfile().expect("temp file");
    modal_tetra::write_obj(surface, std::io::BufWriter::new(file.as_file())).expect("write obj");
    file.into_temp_path()
}

/// Translates every vertex by `d` [m].
pub fn translate(surface: &mut TriSurface, d: [f64; 3]) {
    for p in &mut surface.vertices {
        for c in 0..3 {
            p[c] += d[c];
        }
    }
}

/// Concatenates two surfaces as two parts.
pub fn union(a: &TriSurface, b: &TriSurface) -> TriSurface {
    let mut out = a.clone();
    let offset = out.vertices.len();
    let first = out.triangles.len();
    out.vertices.extend(&b.vertices);
    out.triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + offset)));
    out.parts.push(("second".into(), first..out.triangles.len()));
    out
}
