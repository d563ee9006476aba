//! Issue 6 acceptance and robustness corpus for the tetrahedralizer. Every
//! output is checked by `common::assert_good` (orientation, no unused nodes,
//! every dihedral angle within [9°, 166°]).

mod common;

use common::{assert_good, rel, temp_obj, translate, union};
use modal_tetra::{read_surface, shapes, tetrahedralize, TetOptions, TetReport, TetraError, TriSurface};

const R: f64 = 0.05;

fn mesh(s: &TriSurface) -> TetReport {
    let (m, r) = tetrahedralize(s, &TetOptions::default()).expect("meshes");
    assert_good(&m, &r);
    r
}

fn sphere() -> TriSurface {
    shapes::icosphere(R, 4)
}

#[test]
fn issue_6_icosphere_obj_default_settings_volume_within_1_percent() {
    let path = temp_obj(&sphere());
    let (s, report) = read_surface(&path, 1.0, None).unwrap();
    assert!(report.is_clean(), "{report:?}");
    let (m, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert_good(&m, &r);
    assert!(rel(r.volume_m3, r.surface_volume_m3).abs() < 0.01, "{r:?}");
    let ball = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
    assert!(rel(r.volume_m3, ball).abs() < 0.015, "{r:?}");
    // The stuffed boundary lies on the input surface.
    assert!(r.max_surface_deviation_m < 1e-9, "{r:?}");
    assert!((10_000..40_000).contains(&r.tets), "{r:?}");
}

#[test]
fn issue_6_box_obj_matches_the_structured_box_volume() {
    let size = [0.3, 0.02, 0.01];
    let path = temp_obj(&shapes::cuboid(size[0], size[1], size[2]));
    let (s, _) = read_surface(&path, 1.0, None).unwrap();
    let (m, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert_good(&m, &r);
    let structured =
        modal_mesh::generate::generate(&modal_mesh::generate::Shape::Box { size }, 0.004, 1).unwrap();
    let (_, reference) = modal_mesh::check(structured).unwrap();
    assert!((reference.volume - 6e-5).abs() < 1e-12);
    // Stuffing alone rounds the 12 sharp edges off (−4.1 % volume at this
    // cell size); feature snapping puts boundary nodes back on them.
    assert!(rel(r.volume_m3, reference.volume).abs() < 0.005, "{r:?}");
    assert!(r.feature_nodes_snapped > 0);
    let (lo, hi) = bbox(&m.nodes);
    for c in 0..3 {
        assert!(lo[c] > -1e-9 && hi[c] < size[c] + 1e-9, "mesh inside the box");
        assert!(hi[c] - lo[c] > size[c] - 1e-9, "mesh spans the box along axis {c}");
    }
}

fn bbox(p: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in p {
        for c in 0..3 {
            lo[c] = lo[c].min(q[c]);
            hi[c] = hi[c].max(q[c]);
        }
    }
    (lo, hi)
}

#[test]
fn options_control_resolution_and_guard_size() {
    let s = sphere();
    let coarse = tetrahedralize(&s, &TetOptions { cell: Some(0.02), ..Default::default() }).unwrap().1;
    assert_eq!(coarse.cell_m, 0.02);
    let target = tetrahedralize(&s, &TetOptions { target_tets: Some(5000), ..Default::default() }).unwrap().1;
    assert!((3000..8000).contains(&target.tets), "{target:?}");
    let err = tetrahedralize(&s, &TetOptions { cell: Some(1e-5), ..Default::default() }).unwrap_err();
    assert!(matches!(err, TetraError::TooManyTets { .. }), "{err}");
    // The refusal names a cell that passes the same check, near the limit.
    let capped = TetOptions { cell: Some(0.004), max_tets: 3000, ..Default::default() };
    let text = tetrahedralize(&s, &capped).unwrap_err().to_string();
    let suggested: f64 =
        text.split("--cell ").nth(1).and_then(|t| t.split(' ').next()).unwrap().parse().unwrap();
    assert!(suggested > 0.004, "{text}");
    let fits = tetrahedralize(&s, &TetOptions { cell: Some(suggested), ..capped }).unwrap().1;
    assert!(fits.tets > 2000 && fits.tets < 4000, "{} tets at the suggested {suggested}", fits.tets);
    for bad in [0.0, -1.0, f64::NAN] {
        let e = tetrahedralize(&s, &TetOptions { cell: Some(bad), ..Default::default() }).unwrap_err();
        assert!(matches!(e, TetraError::InvalidOption { name: "cell", .. }), "{e}");
    }
    let e = tetrahedralize(&s, &TetOptions { target_tets: Some(0), ..Default::default() }).unwrap_err();
    assert!(matches!(e, TetraError::InvalidOption { .. }));
    let half = tetrahedralize(&s, &TetOptions { cell: Some(0.02), size_factor: 0.5, ..Default::default() })
        .unwrap()
        .1;
    assert_eq!(half.cell_m, 0.01);
    assert!(half.tets > 6 * coarse.tets, "{half:?} vs {coarse:?}");
    let e = tetrahedralize(&s, &TetOptions { size_factor: 0.0, ..Default::default() }).unwrap_err();
    assert!(matches!(e, TetraError::InvalidOption { name: "size_factor", .. }), "{e}");
    let a = TetOptions::default().cache_key_fields();
    assert_ne!(a, TetOptions { size_factor: 0.5, ..Default::default() }.cache_key_fields());
    assert_ne!(a, TetOptions { curved: false, ..Default::default() }.cache_key_fields());
    let b = TetOptions { cell: Some(0.01), ..Default::default() }.cache_key_fields();
    assert_ne!(a, b);
    // A sheet thickness changes the mesh, so the key; without one the key is the old one.
    assert_ne!(a, TetOptions { sheet_thickness: Some(0.002), ..Default::default() }.cache_key_fields());
    assert!(!a.contains("sheet"), "{a}");
    // A bank of more than 128 modes changes a plate's mesh, so the key; 128 or fewer
    // are the default mesh and keep the old key.
    let modes = |n| TetOptions { resolved_modes: n, ..Default::default() }.cache_key_fields();
    assert_ne!(a, modes(129));
    // Banks of 129 and 130 modes size plates for the same (65th) mode: one mesh, one key.
    assert_eq!(modes(129), modes(130));
    assert_eq!(a, modes(128));
    assert_eq!(a, modes(64));
    assert_eq!(a, modes(10));
}

#[test]
fn robust_small_hole_gives_nearly_the_clean_volume() {
    let clean = mesh(&sphere());
    let mut holed = sphere();
    holed.triangles.drain(0..6);
    let report = modal_tetra::diagnose(&holed);
    assert!(report.open_boundary_edges > 0);
    // Said, since capping a hole (or filling an open shell) may not be the object meant.
    assert!(
        report.warnings.iter().any(|w| w.contains("open") && w.contains("capped")),
        "{:?}",
        report.warnings
    );
    assert!(!modal_tetra::diagnose(&sphere()).warnings.iter().any(|w| w.contains("open")));
    let r = mesh(&holed);
    assert!(rel(r.volume_m3, clean.volume_m3).abs() < 0.01, "{r:?} vs {clean:?}");
}

#[test]
fn robust_all_faces_flipped() {
    let clean = mesh(&sphere());
    let mut s = sphere();
    for t in &mut s.triangles {
        t.swap(1, 2);
    }
    let report = modal_tetra::diagnose(&s);
    assert_eq!(report.flipped_faces, s.triangles.len());
    let r = mesh(&s);
    assert_eq!(r.tets, clean.tets);
    assert!(rel(r.volume_m3, clean.volume_m3).abs() < 1e-12);
}

#[test]
fn robust_random_orientation_per_face() {
    let clean = mesh(&sphere());
    let mut s = sphere();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut flipped = 0;
    for t in &mut s.triangles {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        if state & 1 == 1 {
            t.swap(1, 2);
            flipped += 1;
        }
    }
    let report = modal_tetra::diagnose(&s);
    assert!(report.inconsistent_edges > 0);
    assert_eq!(report.flipped_faces, flipped);
    let r = mesh(&s);
    assert!(rel(r.volume_m3, clean.volume_m3).abs() < 1e-12);
}

#[test]
fn robust_duplicate_vertices_and_degenerate_triangles() {
    let clean = mesh(&sphere());
    let base = sphere();
    // Every triangle with its own three vertices (an unwelded soup).
    let mut soup = TriSurface::default();
    for t in &base.triangles {
        let first = soup.vertices.len();
        soup.vertices.extend(t.map(|v| base.vertices[v]));
        soup.triangles.push([first, first + 1, first + 2]);
    }
    let report = modal_tetra::diagnose(&soup);
    assert_eq!(report.duplicate_vertices, soup.vertices.len() - base.vertices.len());
    let r = mesh(&soup);
    assert!(rel(r.volume_m3, clean.volume_m3).abs() < 1e-12);
    // Zero-area triangles: repeated corners and collinear corners.
    let mut degenerate = base.clone();
    degenerate.triangles.extend([[0, 0, 1], [5, 7, 5]]);
    let a = degenerate.vertices[0];
    let b = degenerate.vertices[1];
    let n = degenerate.vertices.len();
    degenerate.vertices.push(std::array::from_fn(|c| 0.5 * (a[c] + b[c])));
    degenerate.triangles.push([0, n, 1]);
    assert_eq!(modal_tetra::diagnose(&degenerate).degenerate_triangles, 3);
    let r = mesh(&degenerate);
    assert!(rel(r.volume_m3, clean.volume_m3).abs() < 1e-12);
}

/// Exporters write faces twice: repeated (a duplicated export), or once per
/// side (a double-sided export, whose winding number is 0 everywhere, so it
/// enclosed nothing and was refused). Each meshes as the one-sided sphere,
/// node for node, and says what it ignored.
#[test]
fn robust_faces_written_twice_mesh_like_the_one_sided_surface() {
    let base = sphere();
    let (clean, _) = tetrahedralize(&base, &TetOptions::default()).unwrap();
    let front = base.triangles.clone();
    let back: Vec<[usize; 3]> = front.iter().map(|&[a, b, c]| [a, c, b]).collect();
    let with = |triangles: Vec<[usize; 3]>, vertices: Vec<[f64; 3]>| TriSurface {
        parts: vec![("twice".into(), 0..triangles.len())],
        vertices,
        triangles,
    };
    let n = base.vertices.len();
    let doubled_vertices = [base.vertices.clone(), base.vertices.clone()].concat();
    let cases = [
        ("repeated", with([front.clone(), front.clone()].concat(), base.vertices.clone()), (front.len(), 0)),
        (
            "double-sided",
            with([front.clone(), back.clone()].concat(), base.vertices.clone()),
            (0, front.len()),
        ),
        (
            "double-sided, back first, on its own vertices",
            with(
                back.iter().map(|t| t.map(|v| v + n)).chain(front.iter().copied()).collect(),
                doubled_vertices,
            ),
            (0, front.len()),
        ),
    ];
    for (name, surface, (repeated, double_sided)) in cases {
        let report = modal_tetra::diagnose(&surface);
        assert_eq!(
            (report.repeated_triangles, report.double_sided_faces),
            (repeated, double_sided),
            "{name}"
        );
        assert_eq!((report.open_boundary_edges, report.non_manifold_edges), (0, 0), "{name}");
        assert!(report.warnings.iter().any(|w| w.contains("each face is meshed once")), "{name}: {report:?}");
        let (m, _) = tetrahedralize(&surface, &TetOptions::default()).unwrap();
        assert_eq!((m.nodes.len(), m.cells.len()), (clean.nodes.len(), clean.cells.len()), "{name}");
        assert_eq!(m.nodes, clean.nodes, "{name}");
    }
}

/// A double-sided open sheet (a flag or a sign beside a body, written once
/// per side) encloses nothing: one side alone would make the winding number
/// ±½ around it and stuff an arbitrary slab, so both are left out, with a
/// warning, unless the sheet is given a thickness, when one side is kept
/// and thickened like any sheet.
#[test]
fn robust_a_double_sided_sheet_is_left_out_unless_given_a_thickness() {
    let body = shapes::cuboid(0.1, 0.06, 0.04);
    let mut sheet = TriSurface {
        vertices: vec![[0.15, 0.0, 0.0], [0.25, 0.0, 0.0], [0.25, 0.06, 0.0], [0.15, 0.06, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]],
        parts: Vec::new(),
    };
    sheet.parts = vec![("flag".into(), 0..4)];
    let s = union(&body, &sheet);
    let report = modal_tetra::diagnose(&s);
    assert_eq!(report.double_sided_sheet_faces, 2, "{report:?}");
    assert!(report.warnings.iter().any(|w| w.contains("--sheet-thickness")), "{:?}", report.warnings);
    // The flag alone is refused, saying why.
    let err = tetrahedralize(&sheet, &TetOptions::default()).unwrap_err().to_string();
    assert!(err.contains("written once for each side") && err.contains("--sheet-thickness"), "{err}");
    let (with_flag, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert!(rel(r.volume_m3, 0.1 * 0.06 * 0.04).abs() < 1e-12, "the body alone: {r:?}");
    assert_eq!(modal_mesh::check(with_flag).unwrap().1.parts, 1);
    let thick = TetOptions { sheet_thickness: Some(0.002), ..TetOptions::default() };
    let (two_sides, _) = tetrahedralize(&s, &thick).unwrap();
    sheet.triangles.truncate(2);
    let (one_side, r) = tetrahedralize(&union(&body, &sheet), &thick).unwrap();
    assert!(rel(r.surface_volume_m3, 0.1 * 0.06 * (0.04 + 0.002)).abs() < 1e-12, "{r:?}");
    assert_eq!(two_sides.nodes, one_side.nodes);
}

/// A separate part much thinner than the body's cell (a 2 mm plate beside a
/// 10 × 6 × 4 cm box) got no tets, or slivers hanging on edges: the mesh lost
/// a body. It is meshed on its own now, at its own size or an explicit cell,
/// and the two parts together hold both volumes.
#[test]
fn robust_a_thin_separate_part_is_meshed_on_its_own() {
    let body = shapes::cuboid(0.1, 0.06, 0.04);
    let mut plate = shapes::cuboid(0.1, 0.06, 0.002);
    translate(&mut plate, [0.15, 0.0, 0.0]);
    let s = union(&body, &plate);
    let both = 0.1 * 0.06 * (0.04 + 0.002);
    for options in [TetOptions::default(), TetOptions { cell: Some(0.0039), ..TetOptions::default() }] {
        let (m, r) = tetrahedralize(&s, &options).unwrap();
        assert!(rel(r.volume_m3, both).abs() < 2e-3, "{options:?}: {r:?}");
        assert!(r.warnings.iter().any(|w| w.contains("meshed on its own")), "{:?}", r.warnings);
        assert_eq!(modal_mesh::check(m).unwrap().1.parts, 2, "{options:?}");
    }
}

/// Floating specks beside a body (a scan's debris, 0.2 mm cubes beside a
/// 10 cm block) get no tet and are left out: said as specks, not as a gap
/// in the body's mesh that a smaller cell would close.
#[test]
fn robust_floating_specks_are_left_out_and_said_to_be() {
    let body = shapes::cuboid(0.1, 0.06, 0.04);
    let mut s = body.clone();
    for k in 0..3 {
        let mut speck = shapes::cuboid(2e-4, 2e-4, 2e-4);
        translate(&mut speck, [0.11, 0.02 * k as f64, 0.02]);
        s = union(&s, &speck);
    }
    // A given cell (the default one follows the bounding box, which the
    // specks widen).
    let options = TetOptions { cell: Some(0.005), ..TetOptions::default() };
    let (m, r) = tetrahedralize(&s, &options).unwrap();
    assert_eq!(modal_mesh::check(m).unwrap().1.parts, 1);
    assert!(rel(r.volume_m3, 0.1 * 0.06 * 0.04).abs() < 1e-3, "{r:?}");
    assert!(r.warnings.iter().any(|w| w.starts_with("3 separate speck(s)")), "{:?}", r.warnings);
    assert!(!r.warnings.iter().any(|w| w.contains("misses part of the surface")), "{:?}", r.warnings);
}

/// Two bricks modelled touching face to face (a stack): the shared face is
/// written by each, facing opposite ways. Both are dropped, which leaves the
/// winding number as it was and the stack's closed, manifold surface.
#[test]
fn robust_bricks_touching_face_to_face_are_one_body() {
    let a = shapes::cuboid(0.2, 0.1, 0.05);
    let mut b = a.clone();
    translate(&mut b, [0.0, 0.0, 0.05]);
    let s = union(&a, &b);
    let report = modal_tetra::diagnose(&s);
    assert_eq!(report.touching_triangles, 4);
    assert_eq!((report.open_boundary_edges, report.non_manifold_edges, report.components), (0, 0, 1));
    assert!(rel(report.enclosed_volume_m3, 2e-3).abs() < 1e-12, "{report:?}");
    let r = mesh(&s);
    assert!(rel(r.volume_m3, 2e-3).abs() < 1e-12, "{r:?}");
    let (m, _) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert_eq!(modal_mesh::check(m).unwrap().1.parts, 1);
}

/// A corner of one triangle on another's edge (a T-junction, as CAD and
/// level-editor exports leave them) made the box open along that edge: its
/// sharp edge was not found and the mesh missed it by 1 mm, with a false
/// "thinner than the cells" warning. Stitched, the box meshes node for node
/// like the clean one.
#[test]
fn robust_a_t_junction_meshes_like_the_closed_surface() {
    let clean = shapes::cuboid(0.1, 0.06, 0.04);
    let mut s = clean.clone();
    // Corner 8 half-way along the top face's edge 4-5; the front face keeps 4-5 whole.
    s.vertices.push([0.05, 0.0, 0.04]);
    s.triangles.retain(|t| *t != [4, 5, 6] && *t != [5, 7, 6]);
    assert_eq!(s.triangles.len(), 10);
    s.triangles.extend([[4, 8, 6], [8, 7, 6], [8, 5, 7]]);
    s.parts = vec![("box".into(), 0..s.triangles.len())];
    let report = modal_tetra::diagnose(&s);
    assert_eq!((report.t_junctions, report.open_boundary_edges), (1, 0), "{report:?}");
    let (a, _) = tetrahedralize(&clean, &TetOptions::default()).unwrap();
    let (b, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!((a.nodes.len(), a.cells.len()), (b.nodes.len(), b.cells.len()));
    let moved =
        a.nodes.iter().zip(&b.nodes).map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f64::max));
    let moved = moved.fold(0.0, f64::max);
    assert!(moved < 1e-12 && r.max_surface_deviation_m < 1e-9, "{moved:e}, {r:?}");
}

#[test]
fn robust_two_overlapping_spheres_make_one_solid() {
    let a = shapes::icosphere(R, 3);
    let mut b = a.clone();
    translate(&mut b, [R, 0.0, 0.0]);
    let s = union(&a, &b);
    let r = mesh(&s);
    // Union volume of two balls at distance d = R: 2·(4/3)πR³ − lens (5/12)πR³.
    let pi = std::f64::consts::PI;
    let union_volume = (8.0 / 3.0 - 5.0 / 12.0) * pi * R.powi(3);
    assert!(rel(r.volume_m3, union_volume).abs() < 0.03, "{r:?}");
    let (m, _) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    let (_, checked) = modal_mesh::check(m).unwrap();
    assert_eq!(checked.parts, 1);
}

#[test]
fn robust_two_disjoint_parts() {
    let a = shapes::icosphere(R, 3);
    let mut b = a.clone();
    translate(&mut b, [3.0 * R, 0.0, 0.0]);
    let s = union(&a, &b);
    let (m, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
    assert_good(&m, &r);
    assert!(rel(r.volume_m3, r.surface_volume_m3).abs() < 0.02, "{r:?}");
    let (_, checked) = modal_mesh::check(m).unwrap();
    assert_eq!(checked.parts, 2);
}

#[test]
fn robust_millimetre_and_ten_metre_scale() {
    for radius in [0.0005, 5.0] {
        let s = shapes::icosphere(radius, 3);
        let r = mesh(&s);
        assert!(rel(r.volume_m3, r.surface_volume_m3).abs() < 0.01, "{radius}: {r:?}");
        assert!(r.cell_m > radius / 20.0 && r.cell_m < radius / 2.0, "resolution is scale-free");
    }
}

#[test]
fn robust_20k_triangles() {
    let s = shapes::icosphere(R, 5);
    assert_eq!(s.triangles.len(), 20_480);
    let r = mesh(&s);
    assert!(rel(r.volume_m3, r.surface_volume_m3).abs() < 0.01, "{r:?}");
}

#[test]
fn robust_thin_bowl_bell_and_mug() {
    for s in
        [shapes::bowl(0.1, 0.01, 48), shapes::bell(0.2, 0.1, 0.012, 48), shapes::mug(0.04, 0.1, 0.005, 48)]
    {
        let (m, r) = tetrahedralize(&s, &TetOptions::default()).unwrap();
        assert_good(&m, &r);
        assert!(
            rel(r.volume_m3, r.surface_volume_m3).abs() < 0.04 || s.parts.len() > 1,
            "{:?}: {r:?}",
            s.parts
        );
    }
}

#[test]
fn open_sheet_fails_with_a_clear_reason() {
    // A single flat square encloses nothing.
    let s = TriSurface {
        vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        parts: vec![],
    };
    let e = tetrahedralize(&s, &TetOptions::default()).unwrap_err();
    assert!(matches!(e, TetraError::NoVolume { .. }), "{e}");
    assert!(!e.to_string().contains('\n'));
    assert!(e.to_string().contains("open sheet"), "{e}");
    let empty = TriSurface::default();
    assert!(matches!(tetrahedralize(&empty, &TetOptions::default()), Err(TetraError::Empty)));
    let mut nan = sphere();
    nan.vertices[3][1] = f64::NAN;
    assert!(matches!(
        tetrahedralize(&nan, &TetOptions::default()),
        Err(TetraError::NonFiniteVertex { vertex: 3 })
    ));
}

#[test]
#[ignore = "200k-triangle input, several seconds"]
fn robust_200k_triangles() {
    let s = shapes::icosphere(R, 7);
    assert!(s.triangles.len() > 200_000);
    let r = mesh(&s);
    assert!(rel(r.volume_m3, r.surface_volume_m3).abs() < 0.01, "{r:?}");
}

#[test]
fn issue_14_corpus_meshes_keep_no_small_hinged_piece_and_pass_the_check() {
    use modal_tetra::{corpus, HINGED_DROP_FRACTION};
    for name in ["teapot", "nonmanifold", "vessel", "animal", "holed_sphere"] {
        let s = corpus::asset(name).unwrap();
        let (m, r) = tetrahedralize(&s, &TetOptions { cell: Some(0.01), ..Default::default() }).unwrap();
        let parts = modal_mesh::face_parts(&m);
        assert!(parts.hinges.is_empty(), "{name}: hinges left in the output: {:?}", parts.hinges);
        assert_good(&m, &r);
        for h in &parts.hinges {
            let small = h.parts.map(|p| parts.tets[p]).into_iter().min().unwrap();
            assert!(
                small as f64 > HINGED_DROP_FRACTION * r.tets as f64,
                "{name}: a hinged piece of {small} tets of {} was kept at {:?}",
                r.tets,
                h.at
            );
        }
        assert_eq!(
            r.hinged_tets_dropped > 0,
            r.warnings.iter().any(|w| w.contains("hung on the rest")),
            "{name}"
        );
        let (checked, report) = modal_mesh::check(m).unwrap();
        // After the check, node-connected parts are the face-connected ones.
        assert_eq!(modal_mesh::connected_parts(&checked).0, modal_mesh::face_parts(&checked).count, "{name}");
        assert_eq!(report.parts, modal_mesh::face_parts(&checked).count, "{name}");
        assert!(modal_mesh::face_parts(&checked).hinges.is_empty() || report.hinge_nodes_split > 0);
    }
}

#[test]
fn issue_14_a_thin_solid_falls_back_to_a_finer_cell_or_names_one() {
    // A 2 mm square rod, 10 cm long (no shell: its one skin faces itself): an
    // explicit uniform 8 mm cell finds nothing inside and names a cell that works.
    let rod = shapes::cuboid(0.1, 0.002, 0.002);
    let uniform = TetOptions { cell: Some(0.008), graded: false, ..Default::default() };
    let e = tetrahedralize(&rod, &uniform).unwrap_err();
    let text = e.to_string();
    assert!(matches!(e, TetraError::NoVolume { .. }), "{text}");
    assert!(text.contains("--cell") && text.contains("works"), "{text}");
    let cell: f64 = text.split("--cell ").nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap();
    let (_, r) = tetrahedralize(&rod, &TetOptions { cell: Some(cell), ..uniform.clone() }).unwrap();
    assert!(r.tets > 0 && r.wall_layers == 0, "{r:?}");
    // A 2 mm plate 10 cm wide is a shell: the same 8 mm cell gives one layer
    // of tets across it with edges along it of at most 8 mm.
    let plate = shapes::cuboid(0.1, 0.1, 0.002);
    let (m, r) = tetrahedralize(&plate, &uniform).unwrap();
    assert_good(&m, &r);
    assert_eq!(r.wall_layers, 1, "{r:?}");
    assert!(r.cell_m <= 0.008 && rel(r.volume_m3, r.surface_volume_m3).abs() < 1e-6, "{r:?}");
    // Graded, the same bulk cell refines the plate to its thickness.
    let (m, r) =
        tetrahedralize(&plate, &TetOptions { cell: Some(0.008), graded: true, ..Default::default() })
            .unwrap();
    assert_good(&m, &r);
    assert!(rel(r.volume_m3, r.surface_volume_m3).abs() < 0.01, "{r:?}");
}

/// A 2 cm block through a 10 cm plate 1 mm thick: at a 1 cm cell the plate is
/// lost, and with it over half the volume (and mass) the surface encloses.
/// Said in so many words, beside the gap's place; at the defaults it is kept.
#[test]
fn robust_a_mesh_that_loses_most_of_the_volume_says_how_much() {
    let mut plate = shapes::cuboid(0.1, 0.001, 0.1);
    translate(&mut plate, [-0.04, 0.0095, -0.04]);
    let s = union(&shapes::cuboid(0.02, 0.02, 0.02), &plate);
    let lost =
        |r: &TetReport| r.warnings.iter().find(|w| w.contains("of the volume the surface encloses")).cloned();
    let options = TetOptions { cell: Some(0.01), ..TetOptions::default() };
    let (m, r) = tetrahedralize(&s, &options).unwrap();
    assert_good(&m, &r);
    assert!(r.volume_m3 < 0.5 * r.surface_volume_m3, "{r:?}");
    let said = lost(&r).expect("a warning");
    let pct = 100.0 * r.volume_m3 / r.surface_volume_m3;
    assert!(said.starts_with(&format!("the tet mesh holds {pct:.0} %")), "{said}");
    let r = mesh(&s);
    assert!(r.volume_m3 > modal_tetra::VOLUME_KEPT_WARNING * r.surface_volume_m3, "{r:?}");
    assert_eq!(lost(&r), None, "{:?}", r.warnings);
}
