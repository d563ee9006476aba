//! Issue 6 through the whole pipeline: surface meshes (OBJ) are
//! tetrahedralized, solved and compared by frequency with structured meshes
//! and with repaired versions of themselves.

use modal_fem::Material;
use modal_precompute::{precompute, MeshSource, Request, SurfaceMeshing};
use modal_tetra::{shapes, write_obj, TriSurface};

fn steel() -> Material {
    Material::custom(200e9, 0.3, 7850.0, 0.0, 0.0).unwrap()
}

/// The first `n` frequencies [Hz] of `source` (no cache, band wide open).
fn frequencies(source: MeshSource, cell: Option<f64>, n: usize) -> Vec<f64> {
    let mut request = Request::new(source, steel());
    request.surface = SurfaceMeshing { cell, ..Default::default() };
    request.max_freq_hz = 1e7;
    request.max_modes = n;
    let outcome = precompute(&request, None, true, &mut |_| {}).expect("precompute");
    assert_eq!(outcome.bank.info.inertia_expected, outcome.bank.info.inertia_found);
    outcome.bank.frequencies_hz
}

fn obj_file(dir: &tempfile::TempDir, name: &str, surface: &TriSurface) -> MeshSource {
    let path = dir.path().join(name);
    write_obj(surface, std::fs::File::create(&path).unwrap()).unwrap();
    MeshSource::File(path)
}

fn assert_close(what: &str, got: &[f64], want: &[f64], tolerance: f64) {
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((g / w - 1.0).abs() < tolerance, "{what}: mode {} {g} Hz vs {w} Hz", k + 1);
    }
}

#[test]
fn issue_6_box_obj_matches_the_structured_box() {
    let dir = tempfile::tempdir().unwrap();
    let size = [0.1, 0.06, 0.04];
    let from_obj =
        frequencies(obj_file(&dir, "box.obj", &shapes::cuboid(size[0], size[1], size[2])), Some(0.008), 10);
    let structured = modal_mesh::generate::box_mesh(size, [13, 8, 5]);
    let reference =
        frequencies(MeshSource::Memory { mesh: structured, identity: "box 13x8x5".into() }, None, 10);
    assert_close("box OBJ vs structured box", &from_obj, &reference, 0.01);
}

#[test]
fn issue_6_holed_and_flipped_spheres_ring_like_the_clean_one() {
    let dir = tempfile::tempdir().unwrap();
    let clean = shapes::icosphere(0.05, 3);
    let mut holed = clean.clone();
    holed.triangles.drain(0..6);
    holed.parts.clear();
    let mut flipped = clean.clone();
    flipped.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    let cell = Some(0.01);
    let f_clean = frequencies(obj_file(&dir, "clean.obj", &clean), cell, 1);
    let f_holed = frequencies(obj_file(&dir, "holed.obj", &holed), cell, 1);
    let f_flipped = frequencies(obj_file(&dir, "flipped.obj", &flipped), cell, 1);
    assert_close("holed sphere", &f_holed, &f_clean, 0.02);
    assert_close("flipped sphere", &f_flipped, &f_clean, 0.02);
    // And the clean one is Lamb's T2 mode of a steel sphere, a = 5 cm: 24 921.9 Hz.
    assert_close("clean sphere vs Lamb T2", &f_clean, &[24_921.9], 0.03);
}
