//! Unknown or misplaced keys inside a scene's either-or values (a rotation, a
//! mesh generator, a material table) are refused with their full key path,
//! as in every other table; valid rotations keep their orientation.

use std::path::Path;

use modal_scene::{GeneratorSpec, RotationSpec, Scene, GENERATORS};

/// A scene of one box whose object lines are replaced by `mesh`, `material`
/// and `rotation` (each a whole `key = value` line).
fn scene(mesh: &str, material: &str, rotation: &str) -> String {
    format!(
        "duration = 0.05\n[ground]\n[[objects]]\nname = \"bar\"\n{mesh}\n{material}\n\
         position = [0.0, 0.5, 0.0]\n{rotation}\n"
    )
}

const BOX: &str = "mesh = { generate = \"box\", size = [0.3, 0.02, 0.03], element_size = 0.01 }";
const STEEL: &str = "material = \"steel\"";

/// The one-line error of a scene that must be refused.
fn error_of(text: &str) -> String {
    match Scene::from_toml_str(text, Path::new(".")) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => {
            let message = e.to_string();
            assert!(!message.contains('\n'), "multi-line error: {message}");
            message
        }
    }
}

fn rotation_of(rotation: &str) -> RotationSpec {
    let text = scene(BOX, STEEL, rotation);
    let parsed = Scene::from_toml_str(&text, Path::new(".")).unwrap_or_else(|e| panic!("{e}\n{text}"));
    parsed.objects[0].rotation.clone()
}

#[test]
fn a_rotation_with_an_unknown_key_is_refused_naming_it() {
    // `units = "radians"` was ignored and the angles taken as degrees.
    let e = error_of(&scene(BOX, STEEL, "rotation = { euler = [0.0, 0.0, 90.0], units = \"radians\" }"));
    assert!(e.contains("objects[0].rotation.units: unknown key; a rotation is { axis"), "{e}");
}

#[test]
fn a_rotation_mixing_axis_angle_and_euler_is_refused_naming_the_key() {
    // Axis and angle won and `euler` was dropped without a word.
    let e = error_of(&scene(
        BOX,
        STEEL,
        "rotation = { axis = [0.0, 0.0, 1.0], angle = 90.0, euler = [0.0, 0.0, 0.0] }",
    ));
    assert!(
        e.contains("objects[0].rotation.euler: `euler` cannot be combined with `axis` and `angle`"),
        "{e}"
    );
    let e = error_of(&scene(BOX, STEEL, "rotation = { euler = [0.0, 0.0, 0.0], angle = 90.0 }"));
    assert!(e.contains("objects[0].rotation.") && e.contains("cannot be combined"), "{e}");
}

#[test]
fn an_incomplete_or_mistyped_rotation_names_the_rotation() {
    let cases = [
        ("rotation = { axis = [0.0, 0.0, 1.0] }", "objects[0].rotation: `axis` needs `angle`"),
        ("rotation = { angle = 90.0 }", "objects[0].rotation: `angle` needs `axis`"),
        ("rotation = {}", "objects[0].rotation: empty table; a rotation is"),
        ("rotation = { euler = [0.0, 90.0] }", "objects[0].rotation.euler: invalid length 2"),
        ("rotation = 90.0", "objects[0].rotation: invalid type"),
    ];
    for (rotation, expected) in cases {
        let e = error_of(&scene(BOX, STEEL, rotation));
        assert!(e.contains(expected), "{rotation}: {e}");
    }
}

#[test]
fn a_generator_key_its_shape_does_not_take_is_refused_naming_it() {
    // `radius` on a box was ignored.
    let mesh = "mesh = { generate = \"box\", size = [0.3, 0.02, 0.03], element_size = 0.01, radius = 0.5 }";
    let e = error_of(&scene(mesh, STEEL, ""));
    assert!(
        e.contains(
            "objects[0].mesh.radius: `box` does not take `radius`; it takes `size` and `element_size`"
        ),
        "{e}"
    );
    let mesh = "mesh = { generate = \"sphere\", radius = 0.02, length = 0.1 }";
    let e = error_of(&scene(mesh, STEEL, ""));
    assert!(e.contains("objects[0].mesh.length: `sphere` does not take `length`"), "{e}");
}

#[test]
fn a_misspelt_generator_key_is_named() {
    let mesh = "mesh = { generate = \"box\", sise = [0.3, 0.02, 0.03], element_size = 0.01 }";
    let e = error_of(&scene(mesh, STEEL, ""));
    assert!(e.contains("objects[0].mesh.sise: unknown field `sise`"), "{e}");
}

#[test]
fn a_misspelt_material_key_is_named() {
    let material = "material = { youngs = 2e11, poisson = 0.3, density = 7800, alpah = 5 }";
    let e = error_of(&scene(BOX, material, ""));
    assert!(e.contains("objects[0].material.alpah: unknown field `alpah`"), "{e}");
    let e = error_of(&scene(BOX, "material = { youngs = 2e11, poisson = 0.3 }", ""));
    assert!(e.contains("objects[0].material: missing field `density`"), "{e}");
    let e = error_of("[ground]\nmaterial = { youngs = 2e11, poisson = 0.3, density = 7800, bta = 1e-7 }\n");
    assert!(e.contains("ground.material.bta: unknown field `bta`"), "{e}");
}

#[test]
fn mesh_paths_presets_and_material_tables_still_parse() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("bar.msh"), "").expect("write");
    let text =
        "[[objects]]\nmesh = \"bar.msh\"\nmaterial = { youngs = 2e11, poisson = 0.3, density = 7800 }\n\
                position = [0.0, 0.5, 0.0]\n[ground]\nmaterial = \"Glass\"\n";
    let parsed = Scene::from_toml_str(text, dir.path()).expect("scene parses");
    assert!(
        matches!(&parsed.objects[0].mesh, Some(modal_scene::MeshSource::File(p)) if p.ends_with("bar.msh"))
    );
    let expected =
        modal_scene::ExplicitMaterial { youngs: 2e11, poisson: 0.3, density: 7800.0, alpha: 0.0, beta: 0.0 };
    assert_eq!(parsed.objects[0].material, Some(modal_scene::MaterialSpec::Explicit(expected)));
    let ground = parsed.ground.expect("ground");
    assert_eq!(ground.material, modal_scene::MaterialSpec::Preset("Glass".into()));
}

/// `modal mesh tube --outer-radius` names the key `radius` of a scene's
/// tube: both spellings give one tube; both at once is a duplicate.
#[test]
fn a_tube_takes_the_cli_name_of_its_outer_radius() {
    let tube = |keys: &str| {
        let mesh = format!("mesh = {{ generate = \"tube\", inner_radius = 0.01, {keys}, length = 0.3 }}");
        Scene::from_toml_str(&scene(&mesh, STEEL, ""), Path::new("."))
    };
    let (a, b) = (tube("radius = 0.015").unwrap(), tube("outer_radius = 0.015").unwrap());
    assert_eq!(a.objects[0].mesh, b.objects[0].mesh);
    assert!(tube("radius = 0.015, outer_radius = 0.015").is_err());
}

#[test]
fn valid_rotations_parse_to_the_same_quaternion_as_before() {
    let close = |a: [f64; 4], b: [f64; 4]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    let quarter_turn_about_z = [std::f64::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2];
    // Integers are numbers too, as before.
    let axis_angle = rotation_of("rotation = { axis = [0, 0, 1], angle = 90 }");
    assert_eq!(axis_angle, RotationSpec::AxisAngle { axis: [0.0, 0.0, 1.0], angle: 90.0 });
    assert!(close(axis_angle.quaternion(), quarter_turn_about_z), "{:?}", axis_angle.quaternion());
    let euler = rotation_of("rotation = { euler = [0.0, 0.0, 90.0] }");
    assert_eq!(euler, RotationSpec::Euler { euler: [0.0, 0.0, 90.0] });
    assert!(close(euler.quaternion(), quarter_turn_about_z), "{:?}", euler.quaternion());
    // Values of the code before this change (R = Rz·Ry·Rx for Euler angles).
    let tilted = rotation_of("rotation = { angle = 40.0, axis = [1.0, 2.0, 3.0] }").quaternion();
    assert!(close(tilted, [0.9396926207859084, 0.0914087282642836, 0.1828174565285672, 0.2742261847928508]));
    let euler = rotation_of("rotation = { euler = [30.0, 45.0, 60.0] }").quaternion();
    assert!(close(
        euler,
        [0.8223631719059994, 0.022260026714733816, 0.43967973954090955, 0.3604234056503559]
    ));
    assert_eq!(rotation_of(""), RotationSpec::default());
}

#[test]
fn every_generator_takes_exactly_the_keys_its_shape_reads() {
    // Each shape's keys, as `docs/scene-format.md` lists them.
    let keys: [(&str, &[&str]); 5] = [
        ("box", &["size"]),
        ("cylinder", &["radius", "length"]),
        ("tube", &["inner_radius", "radius", "length"]),
        ("sphere", &["radius"]),
        ("bowl", &["radius", "thickness"]),
    ];
    assert_eq!(keys.map(|(name, _)| name), GENERATORS);
    let all = ["size", "radius", "inner_radius", "length", "thickness", "element_size"];
    for (name, needed) in keys {
        let with = |given: &[&str]| {
            let has = |k: &str| given.contains(&k);
            GeneratorSpec {
                generate: name.to_string(),
                size: has("size").then_some([0.1, 0.2, 0.3]),
                radius: has("radius").then_some(0.05),
                inner_radius: has("inner_radius").then_some(0.04),
                length: has("length").then_some(0.2),
                thickness: has("thickness").then_some(0.004),
                element_size: has("element_size").then_some(0.01),
            }
        };
        with(needed).shape().unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut with_element_size = needed.to_vec();
        with_element_size.push("element_size");
        with(&with_element_size).shape().unwrap_or_else(|e| panic!("{name}: {e}"));
        for missing in needed {
            let fewer: Vec<&str> = needed.iter().copied().filter(|k| k != missing).collect();
            let e = with(&fewer).shape().expect_err("a needed key is missing");
            assert!(e.contains(missing), "{name} without {missing}: {e}");
        }
        for extra in all.iter().filter(|k| !with_element_size.contains(k)) {
            let mut more = needed.to_vec();
            more.push(extra);
            let spec = with(&more);
            assert_eq!(spec.unused_key().map(|(key, _)| key), Some(*extra), "{name} with {extra}");
            let e = spec.shape().expect_err("an unused key is refused");
            assert!(e.contains(extra), "{name} with {extra}: {e}");
        }
    }
}

#[test]
fn the_example_scenes_still_parse() {
    let meshes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../meshes");
    let mut parsed = 0;
    for entry in std::fs::read_dir(&meshes).expect("meshes/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            Scene::from_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            parsed += 1;
        }
    }
    assert!(parsed >= 5, "only {parsed} scenes in {}", meshes.display());
    Scene::demo();
}
