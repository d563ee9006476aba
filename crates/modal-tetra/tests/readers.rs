//! Reader tests: OBJ/STL/PLY/OFF round trips, parts, scale and unit warnings,
//! and hostile input that must give a typed error, never a panic.

mod common;

use modal_tetra::{parse_surface, read_surface, shapes, write_obj, SurfaceFormat, TetraError, TriSurface};

fn obj_bytes(s: &TriSurface) -> Vec<u8> {
    let mut out = Vec::new();
    write_obj(s, &mut out).unwrap();
    out
}

fn stl_ascii(s: &TriSurface) -> Vec<u8> {
    let mut out = String::from("solid test\n");
    for t in &s.triangles {
        out += " facet normal 0 0 0\n  outer loop\n";
        for &v in t {
            let p = s.vertices[v];
            out += &format!("   vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        out += "  endloop\n endfacet\n";
    }
    out += "endsolid test\n";
    out.into_bytes()
}

fn stl_binary(s: &TriSurface) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out.extend((s.triangles.len() as u32).to_le_bytes());
    for t in &s.triangles {
        out.extend([0u8; 12]);
        for &v in t {
            for c in s.vertices[v] {
                out.extend((c as f32).to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

/// A binary STL whose free-form header begins with "solid", as SolidWorks
/// and other CAD exporters write it: not ASCII for all that. The line break
/// makes its first line read as text (a corner coordinate whose first byte
/// is 0x0A, 0.04 as f32, does the same in real files).
fn stl_binary_solid_header(s: &TriSurface) -> Vec<u8> {
    let mut out = stl_binary(s);
    let header = b"solid Part1 exported as binary\n";
    out[..header.len()].copy_from_slice(header);
    out
}

fn ply_ascii(s: &TriSurface) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        s.vertices.len(),
        s.triangles.len()
    );
    for p in &s.vertices {
        out += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &s.triangles {
        out += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    out.into_bytes()
}

fn ply_binary(s: &TriSurface) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        s.vertices.len(),
        s.triangles.len()
    )
    .into_bytes();
    for p in &s.vertices {
        for c in p {
            out.extend(c.to_le_bytes());
        }
    }
    for t in &s.triangles {
        out.push(3);
        for &v in t {
            out.extend((v as u32).to_le_bytes());
        }
    }
    out
}

/// ASCII OFF as ModelNet writes it: the keyword fused with the counts.
fn off_modelnet(s: &TriSurface) -> Vec<u8> {
    let mut out = format!("OFF{} {} 0\n", s.vertices.len(), s.triangles.len());
    for p in &s.vertices {
        out += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &s.triangles {
        out += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    out.into_bytes()
}

fn parse(bytes: &[u8], format: SurfaceFormat) -> Result<TriSurface, TetraError> {
    parse_surface(bytes, format, 1.0, None).map(|(s, _)| s)
}

#[test]
fn all_formats_read_the_same_sphere() {
    let sphere = shapes::icosphere(0.05, 2);
    let volume = modal_tetra::diagnose(&sphere).enclosed_volume_m3;
    for (bytes, format) in [
        (obj_bytes(&sphere), SurfaceFormat::Obj),
        (stl_ascii(&sphere), SurfaceFormat::Stl),
        (stl_binary(&sphere), SurfaceFormat::Stl),
        (stl_binary_solid_header(&sphere), SurfaceFormat::Stl),
        (ply_ascii(&sphere), SurfaceFormat::Ply),
        (ply_binary(&sphere), SurfaceFormat::Ply),
        (off_modelnet(&sphere), SurfaceFormat::Off),
    ] {
        let (s, report) = parse_surface(&bytes, format, 1.0, None).unwrap();
        assert_eq!(s.triangles.len(), 320, "{format:?}");
        assert!(report.is_clean(), "{format:?}: {report:?}");
        // f32 formats (binary STL, float PLY) round to ~1e-7 relative.
        assert!((report.enclosed_volume_m3 / volume - 1.0).abs() < 1e-5, "{format:?}");
    }
    // OFF keeps every f64 bit (Rust prints the shortest string that reads back).
    assert_eq!(parse(&off_modelnet(&sphere), SurfaceFormat::Off).unwrap().vertices, sphere.vertices);
}

#[test]
fn read_surface_from_files_and_scale_multiplies() {
    let sphere = shapes::icosphere(50.0, 1); // "millimetres"
    let path = common::temp_obj(&sphere);
    let (_, raw) = read_surface(&path, 1.0, None).unwrap();
    assert!(raw.warnings.iter().any(|w| w.contains("--scale 0.001")), "{:?}", raw.warnings);
    let (s, scaled) = read_surface(&path, 1e-3, None).unwrap();
    assert!(scaled.warnings.is_empty(), "{:?}", scaled.warnings);
    assert!((s.diagonal() - raw.diagonal_m * 1e-3).abs() < 1e-12);
    let tiny = shapes::icosphere(0.001, 1);
    let (_, r) = parse_surface(&obj_bytes(&tiny), SurfaceFormat::Obj, 1.0, None).unwrap();
    assert!(r.warnings.iter().any(|w| w.contains("units")), "{:?}", r.warnings);
    assert!(matches!(read_surface("x.3ds", 1.0, None), Err(TetraError::UnsupportedFormat { .. })));
    assert!(matches!(read_surface("/nonexistent/a.obj", 1.0, None), Err(TetraError::Io { .. })));
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            read_surface(&path, bad, None),
            Err(TetraError::InvalidOption { name: "scale", .. })
        ));
    }
}

#[test]
fn parts_are_kept_together_unless_one_is_chosen() {
    let mug = shapes::mug(0.04, 0.1, 0.005, 24);
    let bytes = obj_bytes(&mug);
    let (all, report) = parse_surface(&bytes, SurfaceFormat::Obj, 1.0, None).unwrap();
    assert_eq!(report.parts, ["cup", "handle"]);
    assert_eq!(all.triangles.len(), mug.triangles.len());
    let (handle, _) = parse_surface(&bytes, SurfaceFormat::Obj, 1.0, Some("handle")).unwrap();
    assert_eq!(handle.triangles.len(), mug.parts[1].1.len());
    match parse_surface(&bytes, SurfaceFormat::Obj, 1.0, Some("saucer")) {
        Err(e @ TetraError::UnknownPart { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("saucer") && msg.contains("cup, handle"), "{msg}");
        }
        other => panic!("expected UnknownPart, got {other:?}"),
    }
}

#[test]
fn hostile_input_gives_typed_errors() {
    let sphere = shapes::icosphere(0.05, 1);
    let garbage: Vec<u8> = (0..4000u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    for format in [SurfaceFormat::Obj, SurfaceFormat::Stl, SurfaceFormat::Ply, SurfaceFormat::Off] {
        assert!(parse(&garbage, format).is_err(), "{format:?} garbage");
        assert!(parse(b"", format).is_err(), "{format:?} empty");
    }
    // Truncated binary STL and PLY; a binary STL header claiming 4 billion triangles.
    let stl = stl_binary(&sphere);
    assert!(parse(&stl[..stl.len() - 7], SurfaceFormat::Stl).is_err());
    let mut lying = stl.clone();
    lying[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(parse(&lying, SurfaceFormat::Stl).is_err());
    let ply = ply_binary(&sphere);
    assert!(parse(&ply[..ply.len() - 5], SurfaceFormat::Ply).is_err());
    // Every truncation of an OFF file is an error, none a panic.
    let off = off_modelnet(&sphere);
    for end in (0..off.len() - 1).step_by(37) {
        assert!(parse(&off[..end], SurfaceFormat::Off).is_err(), "OFF cut at {end}");
    }
    let huge = b"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n";
    assert!(parse(huge, SurfaceFormat::Ply).is_err());
    // NaN coordinate, index out of range, no triangles.
    let nan = b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n";
    assert!(matches!(parse(nan, SurfaceFormat::Obj), Err(TetraError::NonFiniteVertex { vertex: 2 })));
    let oob = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    assert!(matches!(parse(oob, SurfaceFormat::Ply), Err(TetraError::IndexOutOfRange { vertex: 7, .. })));
    let neg = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -5\n";
    assert!(matches!(parse(neg, SurfaceFormat::Ply), Err(TetraError::IndexOutOfRange { .. })));
    let obj_oob = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
    assert!(parse(obj_oob, SurfaceFormat::Obj).is_err());
    assert!(matches!(parse(b"v 0 0 0\nv 1 0 0\n", SurfaceFormat::Obj), Err(TetraError::Empty)));
    let text = String::from_utf8(stl_ascii(&sphere)).unwrap().replacen("vertex ", "vertex NaN ", 1);
    assert!(parse(text.as_bytes(), SurfaceFormat::Stl).is_err());
}

/// The JSON and binary chunks of a `.glb` of one mesh (`s`, f32 positions,
/// u32 indices) and the given scene `nodes` (JSON) and root nodes.
fn glb_chunks(s: &TriSurface, nodes: &str, roots: &str) -> (String, Vec<u8>) {
    let mut bin: Vec<u8> = s.vertices.iter().flatten().flat_map(|&c| (c as f32).to_le_bytes()).collect();
    let positions = bin.len();
    bin.extend(s.triangles.iter().flatten().flat_map(|&v| (v as u32).to_le_bytes()));
    let fold = |pick: fn(f64, f64) -> f64, from: f64| {
        s.vertices.iter().fold([from; 3], |acc, p| std::array::from_fn(|k| pick(acc[k], p[k])))
    };
    let (lo, hi) = (fold(f64::min, f64::INFINITY), fold(f64::max, f64::NEG_INFINITY));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{roots}}}],"nodes":{nodes},
        "meshes":[{{"name":"sphere","primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":{}}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{positions}}},
                       {{"buffer":0,"byteOffset":{positions},"byteLength":{}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{:?},"max":{:?}}},
                     {{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - positions,
        s.vertices.len(),
        lo.map(|x| x as f32),
        hi.map(|x| x as f32),
        3 * s.triangles.len()
    );
    (json, bin)
}

/// The GLB container of the chunks of [`glb_chunks`].
fn pack((json, bin): (String, Vec<u8>)) -> Vec<u8> {
    let document: serde_json::Value = serde_json::from_str(&json).unwrap();
    modal_export::gltf::glb_container(&document, bin).unwrap()
}

fn glb(s: &TriSurface, nodes: &str, roots: &str) -> Vec<u8> {
    pack(glb_chunks(s, nodes, roots))
}

#[test]
fn a_glb_scene_places_its_meshes_in_world_coordinates() {
    // One sphere mesh placed twice: under a shifted parent and mirrored
    // (scale z = −1, so its winding must be reversed to face out), and alone.
    let sphere = shapes::icosphere(0.05, 2);
    let nodes = r#"[{"name":"parent","translation":[1,0,0],"children":[1]},
                    {"name":"mirrored","scale":[1,1,-1],"mesh":0},
                    {"name":"lifted","translation":[0,0.3,0],"mesh":0}]"#;
    let bytes = glb(&sphere, nodes, "[0,2]");
    let (s, report) = parse_surface(&bytes, SurfaceFormat::Gltf, 1.0, None).unwrap();
    assert_eq!(report.parts, ["mirrored", "lifted"]);
    assert_eq!(s.triangles.len(), 2 * sphere.triangles.len());
    assert_eq!(report.flipped_faces, 0, "both copies face out as read");
    let one = modal_tetra::diagnose(&sphere).enclosed_volume_m3;
    assert!((report.enclosed_volume_m3 / (2.0 * one) - 1.0).abs() < 1e-5, "{report:?}");
    let (lo, hi) = s.bounding_box().unwrap();
    assert!((lo[0] + 0.05).abs() < 1e-6 && (hi[0] - 1.05).abs() < 1e-6, "{lo:?} {hi:?}");
    assert!((hi[1] - 0.35).abs() < 1e-6, "{hi:?}");
    // A file of the format, with parts picked like an OBJ's.
    let path = tempfile::Builder::new().suffix(".glb").tempfile().unwrap();
    std::fs::write(path.path(), &bytes).unwrap();
    let (picked, _) = read_surface(path.path(), 1.0, Some("lifted")).unwrap();
    assert_eq!(picked.triangles.len(), sphere.triangles.len());
}

#[test]
fn a_gltf_reads_its_buffer_from_a_percent_encoded_relative_path() {
    // Exporters percent-encode a space and point to shared buffers with `..`.
    let sphere = shapes::icosphere(0.05, 1);
    let (json, bin) = glb_chunks(&sphere, r#"[{"mesh":0}]"#, "[0]");
    let json = json.replacen(r#""buffers":[{"#, r#""buffers":[{"uri":"../bins/bar%20data.bin","#, 1);
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("model")).unwrap();
    std::fs::create_dir_all(dir.path().join("bins")).unwrap();
    std::fs::write(dir.path().join("bins/bar data.bin"), &bin).unwrap();
    std::fs::write(dir.path().join("model/sphere.gltf"), json).unwrap();
    let (s, _) = read_surface(dir.path().join("model/sphere.gltf"), 1.0, None).unwrap();
    assert_eq!(s.triangles.len(), sphere.triangles.len());
}

#[test]
fn a_quantized_glb_reads_like_the_float_one() {
    // gltfpack's default output: positions as normalized 16-bit integers
    // (KHR_mesh_quantization), scaled back by the node; and a required
    // texture extension that has nothing to do with the geometry.
    let sphere = shapes::icosphere(0.05, 2);
    let mut bin: Vec<u8> = Vec::new();
    for p in &sphere.vertices {
        for c in p {
            bin.extend(((c / 0.05 * 32767.0).round() as i16).to_le_bytes());
        }
        bin.extend([0, 0]); // each element padded to 4 bytes: stride 8
    }
    let positions = bin.len();
    bin.extend(sphere.triangles.iter().flatten().flat_map(|&v| (v as u32).to_le_bytes()));
    let document = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_mesh_quantization", "KHR_texture_basisu"],
        "extensionsRequired": ["KHR_mesh_quantization", "KHR_texture_basisu"],
        "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "scale": [0.05, 0.05, 0.05]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": positions, "byteStride": 8},
                        {"buffer": 0, "byteOffset": positions, "byteLength": bin.len() - positions}],
        "accessors": [
            {"bufferView": 0, "componentType": 5122, "normalized": true, "count": sphere.vertices.len(),
             "type": "VEC3", "min": [-32767, -32767, -32767], "max": [32767, 32767, 32767]},
            {"bufferView": 1, "componentType": 5125, "count": 3 * sphere.triangles.len(), "type": "SCALAR"}
        ]
    });
    let bytes = modal_export::gltf::glb_container(&document, bin).unwrap();
    let (s, report) = parse_surface(&bytes, SurfaceFormat::Gltf, 1.0, None).unwrap();
    assert_eq!(s.triangles.len(), sphere.triangles.len());
    let volume = modal_tetra::diagnose(&sphere).enclosed_volume_m3;
    // 16-bit steps of 1.5 µm on 5 cm.
    assert!((report.enclosed_volume_m3 / volume - 1.0).abs() < 1e-4, "{report:?}");
    let worst = s
        .vertices
        .iter()
        .zip(&sphere.vertices)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    assert!(worst < 1e-6, "{worst} m");
}

#[test]
fn hostile_glb_gives_typed_errors() {
    let sphere = shapes::icosphere(0.05, 1);
    let placed = r#"[{"mesh":0}]"#;
    let good = glb(&sphere, placed, "[0]");
    let parse_err = |bytes: &[u8]| match parse(bytes, SurfaceFormat::Gltf) {
        Err(TetraError::Parse { format: "glTF", message }) => message,
        other => panic!("expected a glTF parse error, got {other:?}"),
    };
    // Truncated, garbage, no mesh placed, an index beyond the positions,
    // positions compressed away (no buffer view), a cyclic hierarchy.
    parse_err(&good[..good.len() / 2]);
    parse_err(b"glTF\x02\0\0\0garbage");
    assert!(parse_err(&glb(&sphere, r#"[{"name":"empty"}]"#, "[0]")).contains("no triangles"));
    let mut wild = sphere.clone();
    wild.triangles[0][0] = sphere.vertices.len();
    parse_err(&glb(&wild, placed, "[0]"));
    let (json, bin) = glb_chunks(&sphere, placed, "[0]");
    let draco = json.replacen(r#""bufferView":0,"#, "", 1).replacen(
        r#""scene":0"#,
        r#""extensionsUsed":["KHR_draco_mesh_compression"],"scene":0"#,
        1,
    );
    let compressed = pack((draco, bin));
    let message = parse_err(&compressed);
    assert!(message.contains("decompress"), "{message}");
    parse_err(&glb(&sphere, r#"[{"mesh":0,"children":[1]},{"children":[0]}]"#, "[0]"));
}

/// An L-shaped prism whose two caps are single hexagons, as Blender's OBJ
/// export writes n-gons; each cap listed from a corner that does not see the
/// whole L, so a fan from it would cover the notch. The same prism in OBJ,
/// PLY and OFF reads as a clean closed surface of the L's volume.
#[test]
fn concave_polygons_are_triangulated_inside_their_outline() {
    let l = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.03], [0.03, 0.03], [0.03, 0.08], [0.0, 0.08]];
    let vertices: Vec<[f64; 3]> =
        [0.0, 0.02].iter().flat_map(|&z| l.iter().map(move |&[x, y]| [x, y, z])).collect();
    let top: Vec<usize> = vec![7, 8, 9, 10, 11, 6];
    let bottom: Vec<usize> = vec![5, 4, 3, 2, 1, 0];
    let mut faces = vec![top, bottom];
    faces.extend((0..6).map(|i| vec![i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6]));
    let corners =
        |f: &[usize], base: usize| f.iter().map(|v| (v + base).to_string()).collect::<Vec<_>>().join(" ");
    let points: String = vertices.iter().map(|p| format!("{} {} {}\n", p[0], p[1], p[2])).collect();
    let obj = vertices.iter().map(|p| format!("v {} {} {}\n", p[0], p[1], p[2])).collect::<String>()
        + &faces.iter().map(|f| format!("f {}\n", corners(f, 1))).collect::<String>();
    let off = format!("OFF\n12 {} 0\n{points}", faces.len())
        + &faces.iter().map(|f| format!("{} {}\n", f.len(), corners(f, 0))).collect::<String>();
    let ply = format!(
        "ply\nformat ascii 1.0\nelement vertex 12\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n{points}",
        faces.len()
    ) + &faces.iter().map(|f| format!("{} {}\n", f.len(), corners(f, 0))).collect::<String>();
    for (bytes, format) in [(obj, SurfaceFormat::Obj), (off, SurfaceFormat::Off), (ply, SurfaceFormat::Ply)] {
        let (s, report) = parse_surface(bytes.as_bytes(), format, 1.0, None).unwrap();
        assert_eq!(s.triangles.len(), 2 * 4 + 6 * 2, "{format:?}");
        assert!(report.is_clean(), "{format:?}: {report:?}");
        assert!((report.enclosed_volume_m3 - 0.02 * (0.1 * 0.03 + 0.03 * 0.05)).abs() < 1e-15, "{format:?}");
        // A fan folds over the notch: its triangles' areas, unsigned, add up
        // to more than the prism's surface (two caps and the sides).
        let unsigned_area: f64 = s.triangles.iter().map(|t| area(t.map(|v| s.vertices[v]))).sum();
        let surface = 2.0 * (0.1 * 0.03 + 0.03 * 0.05) + 0.36 * 0.02;
        assert!(
            (unsigned_area - surface).abs() < 1e-15,
            "{format:?}: {unsigned_area} m² against {surface} m²"
        );
    }
}

fn area([a, b, c]: [[f64; 3]; 3]) -> f64 {
    let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
}
