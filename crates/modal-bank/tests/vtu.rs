//! ParaView export.

mod common;

use common::{linear_bank, quadratic_bank};
use modal_bank::{export_vtu, export_vtu_file, mode_array_name, ModeBank};

fn vtu(bank: &ModeBank) -> String {
    let mut out = Vec::new();
    export_vtu(bank, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

/// Checks that every tag is closed in order; returns the element names.
fn check_well_formed(xml: &str) -> Vec<String> {
    let mut stack: Vec<String> = Vec::new();
    let mut names = Vec::new();
    let body = xml.strip_prefix("<?xml version=\"1.0\"?>").expect("XML declaration");
    let mut rest = body;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unterminated tag") + start;
        let tag = &rest[start + 1..end];
        assert!(!rest[..start].contains('>'), "stray '>'");
        if let Some(close) = tag.strip_prefix('/') {
            assert_eq!(stack.pop().as_deref(), Some(close), "mismatched </{close}>");
        } else {
            let name = tag.split_whitespace().next().unwrap().trim_end_matches('/').to_string();
            assert_eq!(tag.matches('"').count() % 2, 0, "unbalanced quotes in <{tag}>");
            names.push(name.clone());
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        rest = &rest[end + 1..];
    }
    assert!(stack.is_empty(), "unclosed: {stack:?}");
    names
}

/// The whitespace-separated values of the DataArray whose attributes contain `attr`.
fn array<'a>(xml: &'a str, attr: &str) -> Vec<&'a str> {
    let start = xml.find(attr).unwrap_or_else(|| panic!("no {attr}"));
    let open = xml[start..].find('>').unwrap() + start + 1;
    let close = xml[open..].find("</DataArray>").unwrap() + open;
    xml[open..close].split_whitespace().collect()
}

#[test]
fn linear_bank_exports_triangles_and_every_mode() {
    let bank = linear_bank(4);
    let xml = vtu(&bank);
    let names = check_well_formed(&xml);
    assert_eq!(names.iter().filter(|n| *n == "DataArray").count(), 1 + 4 + 1 + 1 + 3);
    assert!(xml.contains("NumberOfPoints=\"8\" NumberOfCells=\"12\""));
    assert_eq!(array(&xml, "Name=\"connectivity\"").len(), 36);
    assert_eq!(array(&xml, "Name=\"offsets\"").last(), Some(&"36"));
    assert!(array(&xml, "Name=\"types\"").iter().all(|t| *t == "5"));
    assert_eq!(array(&xml, "Name=\"Points\"").len(), 24);
    for i in 0..4 {
        let name = mode_array_name(&bank, i);
        let values = array(&xml, &format!("Name=\"{name}\""));
        assert_eq!(values.len(), 24);
        let parsed: Vec<f32> = values.iter().map(|v| v.parse().unwrap()).collect();
        assert_eq!(parsed, bank.shapes[i * 24..(i + 1) * 24], "mode {i} values round-trip");
    }
    assert_eq!(mode_array_name(&bank, 0), "mode_000_440.00Hz");
}

#[test]
fn quadratic_bank_exports_six_node_triangles() {
    let bank = quadratic_bank(2);
    let xml = vtu(&bank);
    check_well_formed(&xml);
    assert!(xml.contains("NumberOfPoints=\"10\" NumberOfCells=\"4\""));
    let conn = array(&xml, "Name=\"connectivity\"");
    assert_eq!(conn.len(), 24);
    let edges = bank.surface.triangle_edge_nodes.as_ref().unwrap();
    let first: Vec<usize> = conn[..6].iter().map(|v| v.parse().unwrap()).collect();
    let t = bank.surface.triangles[0];
    assert_eq!(first, [t[0], t[1], t[2], edges[0][0], edges[0][1], edges[0][2]]);
    assert!(array(&xml, "Name=\"types\"").iter().all(|t| *t == "22"));
}

#[test]
fn empty_bank_exports_and_file_variant_is_atomic() {
    let xml = vtu(&linear_bank(0));
    check_well_formed(&xml);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modes.vtu");
    export_vtu_file(&linear_bank(2), &path).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), vtu(&linear_bank(2)));
    assert!(export_vtu_file(&linear_bank(2), dir.path()).is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
