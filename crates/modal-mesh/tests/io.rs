//! Reader/writer tests on the committed meshes in `meshes/` (made with
//! `../shared/tools/make_mesh.py box OUT 0.3 0.02 0.01 --h 0.01 [--order 2]
//! [--binary] [--v22]` (bar_p1_v22_binary: `--v22 --binary`) and `sphere OUT 0.05 --h 0.02`, Gmsh 4.x) and on small
//! files written by the tests. Node/tet counts were cross-checked with
//! meshio: `meshio.read(f)` → bar: 256 points, 618 tetra; bar_p2: 1383
//! points, 618 tetra10; sphere: 208 points, 672 tetra.

use std::path::PathBuf;

use modal_mesh::io::{read_medit, read_msh, read_tetgen};
use modal_mesh::{
    check, read_mesh, write_msh41, write_msh41_file, Cells, MeshError, PhysicalGroup, TetMesh, TET10_EDGES,
};

fn mesh_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../meshes").join(name)
}

fn load(name: &str) -> TetMesh {
    read_mesh(&mesh_path(name), 1.0).unwrap_or_else(|e| panic!("{e}"))
}

const BAR_VOLUME: f64 = 0.3 * 0.02 * 0.01;

fn assert_close(a: f64, b: f64, rel: f64) {
    assert!((a - b).abs() <= rel * b.abs(), "{a} vs {b} (rel {rel})");
}

#[test]
fn bar_p1_ascii_counts_and_volume() {
    let mesh = load("bar_p1.msh");
    assert_eq!((mesh.nodes.len(), mesh.cells.len(), mesh.order()), (256, 618, 1));
    let (_, report) = check(mesh).unwrap();
    assert_close(report.volume, BAR_VOLUME, 1e-12);
    assert_eq!(report.parts, 1);
}

#[test]
fn binary_and_v22_files_read_the_same_mesh_as_ascii() {
    // ASCII files print 16 significant digits, so coordinates agree to
    // round-off only; the connectivity must be identical.
    let ascii = load("bar_p1.msh");
    for name in ["bar_p1_binary.msh", "bar_p1_v22.msh", "bar_p1_v22_binary.msh"] {
        let other = load(name);
        assert!(other.cells == ascii.cells, "{name}: connectivity differs");
        assert_eq!(other.nodes.len(), ascii.nodes.len());
        let worst = other
            .nodes
            .iter()
            .zip(&ascii.nodes)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0, f64::max);
        assert!(worst < 1e-15, "{name}: coordinates differ by {worst}");
    }
}

#[test]
fn gmsh_tet10_edge_nodes_sit_on_the_matching_edges() {
    // A straight-sided Gmsh order-2 mesh: every mid-edge node is exactly the
    // midpoint of the corners TET10_EDGES names. Without the 8 <-> 9 swap
    // edges (1,3) and (2,3) would be wrong.
    let mesh = load("bar_p2.msh");
    assert_eq!((mesh.nodes.len(), mesh.cells.len(), mesh.order()), (1383, 618, 2));
    let Cells::Tet10(tets) = &mesh.cells else { unreachable!() };
    for t in tets {
        for (e, [a, b]) in TET10_EDGES.iter().enumerate() {
            let (p, q, m) = (mesh.nodes[t[*a]], mesh.nodes[t[*b]], mesh.nodes[t[4 + e]]);
            for c in 0..3 {
                assert!((m[c] - 0.5 * (p[c] + q[c])).abs() < 1e-12, "edge {e} of {t:?}");
            }
        }
    }
    let (_, report) = check(mesh).unwrap();
    assert_close(report.volume, BAR_VOLUME, 1e-12);
}

#[test]
fn sphere_volume_is_close_to_the_ball() {
    let mesh = load("sphere_p1.msh");
    assert_eq!((mesh.nodes.len(), mesh.cells.len()), (208, 672));
    let (_, report) = check(mesh).unwrap();
    let ball = 4.0 / 3.0 * std::f64::consts::PI * 0.05f64.powi(3);
    // A faceted inscribed polyhedron at h = R/2.5 loses a few per cent.
    assert!(report.volume < ball && report.volume > 0.85 * ball, "{}", report.volume);
}

#[test]
fn scale_multiplies_coordinates() {
    let mm = read_mesh(&mesh_path("bar_p1.msh"), 1e-3).unwrap();
    let m = load("bar_p1.msh");
    for (a, b) in mm.nodes.iter().zip(&m.nodes) {
        assert_eq!(*a, b.map(|c| c * 1e-3));
    }
    assert!(read_mesh(&mesh_path("bar_p1.msh"), 0.0).is_err());
    assert!(read_mesh(&mesh_path("bar_p1.msh"), f64::NAN).is_err());
}

fn with_groups(mut mesh: TetMesh) -> TetMesh {
    let n = mesh.cells.len();
    mesh.groups = vec![
        PhysicalGroup { name: "left half".into(), tag: 7, cells: (0..n / 2).collect() },
        PhysicalGroup { name: "all".into(), tag: 9, cells: (0..n).collect() },
    ];
    mesh
}

/// The written files were also opened with the reference tools while
/// developing (`/work/.venv-ref/bin/python`): `meshio.read` gives 256 points,
/// `tetra` 309 + 309 cells and cell sets `left half`, `all` (bar_p2:
/// `tetra10`); `gmsh.open` gives 618 elements of type 4 (11) and physical
/// groups (3, 7), (3, 9) named `left half`, `all`, and Gmsh's node 8 / 9 of
/// the written 10-node tets sit on edges (2,3) / (1,3).
#[test]
fn msh41_round_trip_is_exact_with_groups() {
    for name in ["bar_p1.msh", "bar_p2.msh"] {
        let mesh = with_groups(load(name));
        let mut bytes = Vec::new();
        write_msh41(&mesh, &mut bytes).unwrap();
        assert_eq!(read_msh(&bytes, 1.0).unwrap(), mesh, "{name}");
    }
}

#[test]
fn atomic_file_writer_replaces_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.msh");
    std::fs::write(&path, "old").unwrap();
    let mesh = load("bar_p1.msh");
    write_msh41_file(&path, &mesh).unwrap();
    assert_eq!(read_mesh(&path, 1.0).unwrap(), mesh);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "temporary file left behind");
    let missing_dir = dir.path().join("no/such/dir/out.msh");
    assert!(matches!(write_msh41_file(&missing_dir, &mesh), Err(MeshError::Io { .. })));
}

/// Two tets sharing a face, in 2.2 ASCII with sparse node tags, a physical
/// name and boundary triangles that must be ignored.
const V22_SPARSE: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"skin\"\n3 5 \"steel part\"\n$EndPhysicalNames\n\
$Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n99 1 1 1\n$EndNodes\n\
$Elements\n3\n1 2 2 1 1 10 20 30\n2 4 2 5 1 10 20 30 40\n3 4 2 0 1 20 30 40 99\n$EndElements\n";

#[test]
fn v22_sparse_tags_groups_and_ignored_triangles() {
    let mesh = read_msh(V22_SPARSE.as_bytes(), 1.0).unwrap();
    assert_eq!(mesh.nodes.len(), 5);
    assert_eq!(mesh.cells, Cells::Tet4(vec![[0, 1, 2, 3], [1, 2, 3, 4]]));
    assert_eq!(mesh.groups, vec![PhysicalGroup { name: "steel part".into(), tag: 5, cells: vec![0] }]);
}

#[test]
fn msh41_groups_come_from_volume_entities() {
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 3 \"Body\"\n$EndPhysicalNames\n\
$Entities\n0 0 0 2\n1 0 0 0 1 1 1 1 3 0\n2 0 0 0 1 1 1 0 0\n$EndEntities\n\
$Nodes\n1 5 3 11\n3 1 0 5\n3\n5\n7\n9\n11\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n$EndNodes\n\
$Elements\n2 2 1 2\n3 1 4 1\n1 3 5 7 9\n3 2 4 1\n2 5 7 9 11\n$EndElements\n";
    let mesh = read_msh(text.as_bytes(), 1.0).unwrap();
    assert_eq!(mesh.cells, Cells::Tet4(vec![[0, 1, 2, 3], [1, 2, 3, 4]]));
    assert_eq!(mesh.groups, vec![PhysicalGroup { name: "Body".into(), tag: 3, cells: vec![0] }]);
}

#[test]
fn tetgen_zero_and_one_based_with_attributes_markers_and_comments() {
    for base in [0i64, 1] {
        let node = format!(
            "# comment\n5 3 1 1\n{} 0 0 0 9.5 1\n{} 1 0 0 9.5 1\n# mid comment\n{} 0 1 0 9.5 0\n{} 0 0 1 9.5 1\n{} 1 1 1 9.5 1\n",
            base,
            base + 1,
            base + 2,
            base + 3,
            base + 4
        );
        let ele = format!(
            "2 4 1\n{b} {b} {} {} {} 3.0\n{} {} {} {} {} 3.0\n",
            base + 1,
            base + 2,
            base + 3,
            base + 1,
            base + 1,
            base + 2,
            base + 3,
            base + 4,
            b = base
        );
        let mesh = read_tetgen(node.as_bytes(), ele.as_bytes(), 2.0).unwrap();
        assert_eq!(mesh.cells, Cells::Tet4(vec![[0, 1, 2, 3], [1, 2, 3, 4]]));
        assert_eq!(mesh.nodes[4], [2.0, 2.0, 2.0]);
    }
}

#[test]
fn tetgen_ten_node_extras_are_matched_to_their_edges() {
    // Corners 1..4 then edge midpoints listed in a scrambled order.
    let node = "10 3 0 0\n1 0 0 0\n2 2 0 0\n3 0 2 0\n4 0 0 2\n\
5 1 0 0\n6 1 1 0\n7 0 1 0\n8 0 0 1\n9 1 0 1\n10 0 1 1\n";
    let ele = "1 10 0\n1 1 2 3 4 10 9 8 7 6 5\n";
    let mesh = read_tetgen(node.as_bytes(), ele.as_bytes(), 1.0).unwrap();
    assert_eq!(mesh.cells, Cells::Tet10(vec![[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]]));
    let bad = "1 10 0\n1 1 2 3 4 10 9 8 7 6 6\n";
    let err = read_tetgen(node.as_bytes(), bad.as_bytes(), 1.0).unwrap_err();
    assert!(err.to_string().contains("tetrahedron 0"), "{err}");
}

#[test]
fn tetgen_files_found_from_either_extension() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.node"), "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n").unwrap();
    std::fs::write(dir.path().join("m.ele"), "1 4 0\n0 0 1 2 3\n").unwrap();
    let a = read_mesh(&dir.path().join("m.node"), 1.0).unwrap();
    let b = read_mesh(&dir.path().join("m.ele"), 1.0).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.cells.len(), 1);
}

#[test]
fn medit_reads_vertices_and_tetrahedra_and_skips_the_rest() {
    let text = "MeshVersionFormatted 2\nDimension\n3\n# comment\nVertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n1 1 1 0\n\
Triangles\n1\n1 2 3 4\nCorners 2 1 2\nTetrahedra\n2\n1 2 3 4 0\n2 3 4 5 0\nEnd\n";
    let mesh = read_medit(text.as_bytes(), 1.0).unwrap();
    assert_eq!(mesh.cells, Cells::Tet4(vec![[0, 1, 2, 3], [1, 2, 3, 4]]));
    assert_eq!(mesh.nodes.len(), 5);
}

#[test]
fn medit_file_matches_meshio_conversion_of_the_bar() {
    // Written by hand from the reader's own view of bar_p1.msh; the same
    // numbers meshio would write (`meshio convert bar_p1.msh bar.mesh`).
    let bar = load("bar_p1.msh");
    let mut text = format!("MeshVersionFormatted 1\nDimension 3\nVertices\n{}\n", bar.nodes.len());
    for p in &bar.nodes {
        text += &format!("{:e} {:e} {:e} 0\n", p[0], p[1], p[2]);
    }
    text += &format!("Tetrahedra\n{}\n", bar.cells.len());
    for e in 0..bar.cells.len() {
        let t = bar.cells.corners(e).map(|n| n + 1);
        text += &format!("{} {} {} {} 1\n", t[0], t[1], t[2], t[3]);
    }
    text += "End\n";
    assert_eq!(read_medit(text.as_bytes(), 1.0).unwrap(), bar);
}
