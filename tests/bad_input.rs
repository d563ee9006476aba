//! Bad input of every kind gives one clear error line and exit code 1, never
//! a panic, and leaves no output file behind.

mod common;
use common::*;

/// A valid 2-tet mesh in Gmsh 4.1 ASCII; tests corrupt it in different ways.
const GOOD_MSH: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n\
0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n$EndNodes\n$Elements\n1 2 1 2\n3 1 4 2\n1 1 2 3 4\n2 2 3 4 5\n$EndElements\n";

fn precompute_fails(name: &str, contents: &[u8], needle: &str) {
    let dir = temp_dir();
    std::fs::write(dir.path().join(name), contents).unwrap();
    let mut args = vec!["precompute", name, "-o", "out.bank"];
    args.extend(STEEL);
    modal(dir.path(), &args).fails_with(needle);
    assert!(!dir.path().join("out.bank").exists(), "no partial bank");
    let leftovers: Vec<String> = files_in(dir.path()).into_iter().filter(|f| f.ends_with(".tmp")).collect();
    assert!(leftovers.is_empty(), "temp files left: {leftovers:?}");
}

#[test]
fn good_mesh_is_accepted_by_export() {
    let dir = temp_dir();
    std::fs::write(dir.path().join("good.msh"), GOOD_MSH).unwrap();
    let mut args = vec!["export-matrices", "good.msh", "--out", "mats", "--order", "1"];
    args.extend(STEEL);
    modal(dir.path(), &args).ok();
    assert_eq!(files_in(&dir.path().join("mats")), ["K.mtx", "M.mtx", "nodes.csv"]);
}

#[test]
fn truncated_mesh() {
    precompute_fails("t.msh", &GOOD_MSH.as_bytes()[..GOOD_MSH.len() / 2], "t.msh");
}

#[test]
fn nan_coordinate() {
    precompute_fails("n.msh", GOOD_MSH.replace("1 1 1\n", "1 nan 1\n").as_bytes(), "n.msh");
}

#[test]
fn node_index_out_of_range() {
    precompute_fails("o.msh", GOOD_MSH.replace("2 2 3 4 5", "2 2 3 4 9").as_bytes(), "o.msh");
}

#[test]
fn zero_volume_tet() {
    // Node 5 moved into the plane of nodes 2, 3, 4: the second tet is flat.
    precompute_fails("z.msh", GOOD_MSH.replace("1 1 1\n", "0.5 0.5 0\n").as_bytes(), "z.msh");
}

#[test]
fn empty_file() {
    precompute_fails("e.msh", b"", "e.msh");
}

#[test]
fn binary_garbage() {
    let garbage: Vec<u8> = (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect();
    precompute_fails("g.msh", &garbage, "g.msh");
}

#[test]
fn missing_file() {
    let dir = temp_dir();
    let mut args = vec!["precompute", "absent.msh", "-o", "out.bank"];
    args.extend(STEEL);
    modal(dir.path(), &args).fails_with("absent.msh");
}

#[test]
fn impossible_materials() {
    let dir = temp_dir();
    std::fs::write(dir.path().join("good.msh"), GOOD_MSH).unwrap();
    for (flags, needle) in [
        (vec!["--youngs", "200e9", "--poisson", "0.5", "--density", "7850"], "poisson"),
        (vec!["--youngs", "-1", "--poisson", "0.3", "--density", "7850"], "young"),
        (vec!["--youngs", "200e9", "--poisson", "0.3", "--density", "0"], "density"),
        (vec!["--material", "unobtainium"], "unobtainium"),
        (vec!["--youngs", "200e9"], "material"),
        // A unit mistake (GPa given as Pa, g/cm³ as kg/m³) or a typo: said, not solved.
        (vec!["--youngs", "200", "--poisson", "0.3", "--density", "7850"], "is it in Pa"),
        (vec!["--youngs", "200e9", "--poisson", "0.3", "--density", "1e-300"], "is it in kg/m³"),
    ] {
        let mut args = vec!["precompute", "good.msh", "-o", "out.bank"];
        args.extend(flags);
        let run = modal(dir.path(), &args).fails_with(needle);
        assert!(run.stderr.matches("invalid material").count() <= 1, "said twice: {}", run.stderr);
    }
    // An impossible value is said once; the usage comes with a missing one only.
    let mut args =
        vec!["precompute", "good.msh", "-o", "out.bank", "--material", "steel", "--poisson", "0.7"];
    let run = modal(dir.path(), &args).fails_with("invalid material: Poisson's ratio ν = 0.7");
    assert!(!run.stderr.contains("use --material NAME"), "{}", run.stderr);
    args.truncate(4);
    args.extend(["--youngs", "200e9"]);
    modal(dir.path(), &args).fails_with("is required when no preset material is given (use --material NAME");
    // A bank written over its own mesh would destroy it.
    modal(dir.path(), &["precompute", "good.msh", "-o", "good.msh", "--material", "steel"])
        .fails_with("input file itself");
    assert_eq!(std::fs::read_to_string(dir.path().join("good.msh")).unwrap(), GOOD_MSH);
}

#[test]
fn a_failure_asked_for_in_json_is_json_on_stdout() {
    // Scripts read stdout; a failing `--json` command used to print nothing there.
    let dir = temp_dir();
    let run = modal(dir.path(), &["info", "missing.bank", "--json"]);
    assert!(!run.success, "{}", run.stderr);
    let json: serde_json::Value = serde_json::from_str(run.stdout.trim()).expect("one JSON document");
    let error = json["error"].as_str().expect("an error string");
    assert!(error.contains("missing.bank") && run.stderr.contains(error), "{error} / {}", run.stderr);
    // Without --json, stdout stays empty.
    assert!(modal(dir.path(), &["info", "missing.bank"]).stdout.is_empty());
}
