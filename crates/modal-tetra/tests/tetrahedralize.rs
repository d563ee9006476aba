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
