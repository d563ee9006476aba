//! Hostile and broken input: every case must give a typed error whose
//! message is one line naming the position, element or node — never a
//! panic, hang or huge allocation.

use std::path::PathBuf;

use modal_mesh::io::{read_medit, read_msh, read_tetgen};
use modal_mesh::{read_mesh, Location, MeshError};

fn mesh_bytes(name: &str) -> Vec<u8> {
    std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../meshes").join(name)).unwrap()
}

/// Asserts an error whose one-line message contains `needle`.
fn assert_error(result: Result<modal_mesh::TetMesh, MeshError>, needle: &str) -> MeshError {
    let err = result.expect_err("expected an error");
    let text = err.to_string();
    assert!(!text.contains('\n'), "multi-line message: {text}");
    assert!(text.contains(needle), "`{text}` does not mention `{needle}`");
    err
}

const TWO_TETS_V22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n\
$Elements\n2\n1 4 0 1 2 3 4\n2 4 0 2 3 4 5\n$EndElements\n";

#[test]
fn the_valid_template_reads() {
    assert_eq!(read_msh(TWO_TETS_V22.as_bytes(), 1.0).unwrap().cells.len(), 2);
}

#[test]
fn empty_garbage_and_binary_junk() {
    assert_error(read_msh(b"", 1.0), "not a Gmsh file");
    assert_error(read_msh(b"hello world\n", 1.0), "not a Gmsh file");
    let junk: Vec<u8> = (0..4096u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    assert!(read_msh(&junk, 1.0).is_err());
    let mut header_then_junk = b"$MeshFormat\n4.1 1 8\n".to_vec();
    header_then_junk.extend(&junk);
    assert_error(read_msh(&header_then_junk, 1.0), "endianness");
    assert_error(read_msh(b"$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", 1.0), "unsupported MSH version 4.0");
    assert_error(read_medit(b"", 1.0), "not a Medit file");
    assert_error(read_medit(&junk, 1.0), "");
    assert_error(read_tetgen(b"", b"", 1.0), "unexpected end of file");
}

#[test]
fn truncated_files_fail_cleanly_at_every_cut() {
    for name in ["bar_p1.msh", "bar_p1_binary.msh", "bar_p1_v22.msh", "bar_p1_v22_binary.msh", "bar_p2.msh"] {
        let bytes = mesh_bytes(name);
        for cut in (0..bytes.len()).step_by(397) {
            // Cutting inside the trailing sections after $Elements may still
            // leave a complete mesh; anything else must be an error.
            if let Err(e) = read_msh(&bytes[..cut], 1.0) {
                assert!(!e.to_string().contains('\n'));
            } else {
                assert!(cut > bytes.len() / 2, "{name} cut at {cut} read fine");
            }
        }
        let half = read_msh(&bytes[..bytes.len() / 2], 1.0).unwrap_err();
        assert!(matches!(half, MeshError::Syntax { .. }), "{name}: {half}");
    }
}

#[test]
fn corrupted_bytes_never_panic() {
    for name in ["bar_p1.msh", "bar_p1_binary.msh", "bar_p1_v22_binary.msh"] {
        let original = mesh_bytes(name);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..300 {
            let mut bytes = original.clone();
            for _ in 0..4 {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let at = (state >> 33) as usize % bytes.len();
                bytes[at] = (state >> 17) as u8;
            }
            let _ = read_msh(&bytes, 1.0);
        }
    }
}

#[test]
fn absurd_counts_are_rejected_before_allocating() {
    let text = TWO_TETS_V22.replace("$Nodes\n5\n", "$Nodes\n999999999999999\n");
    assert_error(read_msh(text.as_bytes(), 1.0), "does not fit in the rest of the file");
    let text = TWO_TETS_V22.replace("$Elements\n2\n", "$Elements\n18446744073709551615\n");
    assert_error(read_msh(text.as_bytes(), 1.0), "does not fit in the rest of the file");
    let v41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4000000000000 1 4000000000000\n";
    assert_error(read_msh(v41.as_bytes(), 1.0), "line 5");
    // Binary 4.1: overwrite numNodes (second size_t after "$Nodes\n").
    let mut binary = mesh_bytes("bar_p1_binary.msh");
    let at = binary.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7 + 8;
    binary[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    let err = assert_error(read_msh(&binary, 1.0), "does not fit in the rest of the file");
    assert!(matches!(err, MeshError::Syntax { at: Location::Byte(_), .. }));
    assert_error(read_tetgen(b"99999999999 3 0 0\n", b"", 1.0), "does not fit");
    assert_error(read_tetgen(b"1 3 99999999999999 0\n0 0 0 0\n", b"", 1.0), "does not fit");
    assert_error(read_medit(b"MeshVersionFormatted 1\nVertices\n99999999999\n", 1.0), "does not fit");
}

#[test]
fn non_finite_coordinates_name_the_node() {
    for bad in ["nan", "inf", "-inf", "NaN"] {
        let text = TWO_TETS_V22.replace("3 0 1 0", &format!("3 0 {bad} 0"));
        assert_error(read_msh(text.as_bytes(), 1.0), "node tag 3 has a non-finite coordinate");
    }
    let text = TWO_TETS_V22.replace("3 0 1 0", "3 0 1e999 0");
    assert_error(read_msh(text.as_bytes(), 1.0), "node tag 3");
    assert_error(
        read_tetgen(b"4 3 0 0\n1 0 0 0\n2 nan 0 0\n3 0 1 0\n4 0 0 1\n", b"1 4 0\n1 1 2 3 4\n", 1.0),
        "point number 2 has a non-finite coordinate",
    );
    assert_error(
        read_medit(b"MeshVersionFormatted 1\nVertices\n1\n0 inf 0 1\n", 1.0),
        "vertex 1 has a non-finite",
    );
}

#[test]
fn broken_connectivity_names_the_element() {
    let text = TWO_TETS_V22.replace("2 4 0 2 3 4 5", "2 4 0 2 3 4 77");
    assert_error(read_msh(text.as_bytes(), 1.0), "element tag 2 references node tag 77");
    let mixed = TWO_TETS_V22
        .replace("$Elements\n2\n", "$Elements\n3\n")
        .replace("$EndElements", "3 11 0 1 2 3 4 1 2 3 4 5 1\n$EndElements");
    assert_eq!(read_msh(mixed.as_bytes(), 1.0), Err(MeshError::MixedOrders));
    let unknown = TWO_TETS_V22.replace("1 4 0 1 2 3 4", "1 77 0 1 2 3 4");
    assert_error(read_msh(unknown.as_bytes(), 1.0), "unknown element type 77");
    let only_triangles = TWO_TETS_V22.replace("1 4 0 1 2 3 4\n2 4 0 2 3 4 5", "1 2 0 1 2 3\n2 2 0 2 3 4");
    assert_eq!(read_msh(only_triangles.as_bytes(), 1.0), Err(MeshError::NoTets));
    let twice = TWO_TETS_V22.replace("5 1 1 1", "4 1 1 1");
    assert_error(read_msh(twice.as_bytes(), 1.0), "node tag 4 appears twice");
    let node = b"4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
    assert_error(read_tetgen(node, b"1 4 0\n1 1 2 3 9\n", 1.0), "tetrahedron 0 references node number 9");
    assert_error(read_tetgen(node, b"1 6 0\n", 1.0), "6 nodes per tetrahedron");
    assert_error(read_tetgen(node, b"1 4 0\n1 1 2 x 4\n", 1.0), "expected a node number, found `x`");
    let medit = b"MeshVersionFormatted 1\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTetrahedra\n1\n1 2 3 5 0\n";
    assert_eq!(read_medit(medit, 1.0), Err(MeshError::NodeOutOfRange { element: 0, node: 4, node_count: 4 }));
    let zero = b"MeshVersionFormatted 1\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTetrahedra\n1\n0 2 3 4 0\n";
    assert_error(read_medit(zero, 1.0), "vertex 0");
}

#[test]
fn syntax_errors_give_the_line() {
    let text = TWO_TETS_V22.replace("2 1 0 0", "2 1 zero 0");
    let err = assert_error(read_msh(text.as_bytes(), 1.0), "expected a y coordinate, found `zero`");
    assert_eq!(
        err,
        MeshError::Syntax { at: Location::Line(7), message: "expected a y coordinate, found `zero`".into() }
    );
    let missing_end = TWO_TETS_V22.replace("$EndNodes", "$EndNotes");
    assert_error(read_msh(missing_end.as_bytes(), 1.0), "expected `$EndNodes`");
}

#[test]
fn file_level_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.msh");
    let err = read_mesh(&missing, 1.0).unwrap_err();
    assert!(matches!(err, MeshError::Io { .. }) && err.to_string().contains("nope.msh"), "{err}");
    let stl = dir.path().join("part.stl");
    std::fs::write(&stl, "solid x").unwrap();
    assert_error(read_mesh(&stl, 1.0), "unknown mesh format `stl`");
    let bad = dir.path().join("bad.msh");
    std::fs::write(&bad, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0\n").unwrap();
    let err = assert_error(read_mesh(&bad, 1.0), "bad.msh: line 5: node count 1 does not fit");
    assert!(matches!(err, MeshError::InFile { .. }));
    std::fs::write(dir.path().join("lonely.node"), "4 3 0 0\n").unwrap();
    assert_error(read_mesh(&dir.path().join("lonely.node"), 1.0), "lonely.ele");
}
