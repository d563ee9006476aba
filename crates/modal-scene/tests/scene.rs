//! Issue 5 acceptance: both bodies of a contact ring, assets are solved once,
//! bad scenes name their field, renders are deterministic, the demo parses.

mod common;

use std::path::Path;

use modal_scene::{render, InMemoryProvider, RenderOptions, Scene, SceneError};

/// A steel ball (modes 1500/3100 Hz) dropped onto a fixed wooden slab (modes
/// 700/2300 Hz) — no ground; the slab is a sounding fixed body.
const BALL_ON_SLAB: &str = r#"
duration = 1.0
sample_rate = 16000
[listener]
position = [0.0, 0.3, 0.5]
channels = "mono"
[[objects]]
name = "ball"
mesh = { generate = "sphere", radius = 0.02 }
material = "steel"
position = [0.0, 0.12, 0.0]
[[objects]]
name = "slab"
mesh = { generate = "box", size = [0.3, 0.04, 0.3] }
material = "wood"
body = "fixed"
position = [0.0, -0.02, 0.0]
"#;

fn slab_provider() -> InMemoryProvider {
    let mut p = InMemoryProvider::new();
    p.insert("sphere", common::ball(0.02, &[1500.0, 3100.0]));
    p.insert("box", common::block([0.3, 0.04, 0.3], &[700.0, 2300.0]));
    p
}

#[test]
fn both_bodies_of_a_contact_ring_at_their_own_frequencies() {
    let scene = Scene::from_toml_str(BALL_ON_SLAB, Path::new(".")).expect("scene");
    let out = render(&scene, &mut slab_provider(), &RenderOptions::default()).expect("render");
    assert!(out.report.objects.iter().all(|o| o.impacts >= 1), "{:?}", out.report.objects);
    // The fixed slab is where the scene put its centre of mass (its mesh's corner is
    // at the origin of its frame, which rapier reports for a body without mass), and
    // the listener hears it from there.
    let slab = out.report.objects[1].final_position_m;
    assert!(slab.iter().zip([0.0, -0.02, 0.0]).all(|(a, b)| (a - b).abs() < 1e-7), "{slab:?}");
    let spectrum = common::Spectrum::after_onset(&out.channels[0], 8192, 16000.0);
    let (level, floor) = (|f| spectrum.level(f), spectrum.median());
    // The slab's 2300 Hz mode decays within ~20 ms (wood, β ω²/2 ≈ 210/s):
    // check each body's lowest mode and the ball's second.
    for f in [700.0, 1500.0, 3100.0] {
        assert!(level(f) > 100.0 * floor, "no spectral peak at {f} Hz: {} vs median {floor}", level(f));
    }
    // Neither body rings where it has no mode (wood's 700 Hz peak is ~8 Hz wide).
    assert!(level(1100.0) < 0.05 * level(700.0).min(level(1500.0)));
}

#[test]
fn instances_of_one_asset_ask_the_provider_once() {
    let text = r#"
duration = 0.1
sample_rate = 16000
[[objects]]
mesh = { generate = "sphere", radius = 0.02 }
material = "steel"
position = [0.0, 0.1, 0.0]
[[objects]]
mesh = { generate = "sphere", radius = 0.02 }
material = "steel"
position = [0.2, 0.1, 0.0]
[[objects]]
mesh = { generate = "sphere", radius = 0.02 }
material = "glass"
position = [0.4, 0.1, 0.0]
"#;
    let scene = Scene::from_toml_str(text, Path::new(".")).expect("scene");
    let mut p = InMemoryProvider::new();
    p.insert("sphere", common::ball(0.02, &[1500.0]));
    let out = render(&scene, &mut p, &RenderOptions::default()).expect("render");
    // Two distinct assets (steel, glass) for three instances.
    assert_eq!(p.requests.len(), 2);
    assert_eq!(out.report.banks_requested, 2);
    assert_eq!(p.requests[0].max_frequency_hz, 8000.0);
}

#[test]
fn renders_are_bit_identical_for_any_thread_count() {
    let scene = Scene::from_toml_str(BALL_ON_SLAB, Path::new(".")).expect("scene");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| render(&scene, &mut slab_provider(), &RenderOptions::default()).expect("render"))
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.channels, b.channels);
    assert_eq!(run(2).channels, b.channels);
}

fn error_of(text: &str, dir: &Path) -> String {
    match Scene::from_toml_str(text, dir) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_scenes_name_the_offending_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let obj =
        |extra: &str| format!("[[objects]]\nmesh = {{ generate = \"sphere\", radius = 0.02 }}\n{extra}\n");
    let cases = [
        ("duration = -1.0\n".to_string(), "duration"),
        (obj("material = \"unobtainium\""), "objects[0].material"),
        (obj("material = \"steel\"\nposition = [0.0, nan, 0.0]"), "objects[0].position[1]"),
        (obj("material = \"steel\"\nrotation = { euler = [0.0, inf, 0.0] }"), "objects[0].rotation.euler[1]"),
        (obj("material = \"steel\"\ncolour = \"red\""), "objects[0]"),
        ("[[objects]]\nmesh = \"missing.msh\"\nmaterial = \"steel\"\n".to_string(), "objects[0].mesh"),
        (obj("material = \"steel\"\nbody = \"floating\""), "objects[0].body"),
        (obj(""), "objects[0].material"),
        ("sample_rate = 100\n".to_string(), "sample_rate"),
        ("[listener]\nposition = [0.0, 1.0]\n".to_string(), "listener.position"),
        ("[ground]\nsize = [1e6, 1e6]\n".to_string(), "ground.size"),
        ("[ground]\nsize = [1.0, -1.0]\n".to_string(), "ground.size[1]"),
        (obj("material = \"steel\"\ncollider = \"mesh\""), "objects[0].collider"),
    ];
    for (text, path) in cases {
        let e = error_of(&text, dir.path());
        assert!(e.contains(path), "error for\n{text}\ndoes not name `{path}`: {e}");
        assert!(!e.contains('\n'), "multi-line error: {e}");
    }
    let e = error_of("[[objects]]\nmesh = \"missing.msh\"\nmaterial = \"steel\"\n", dir.path());
    assert!(e.contains("missing.msh"), "{e}");
}

#[test]
fn an_object_intersecting_the_ground_is_an_error() {
    let text = r#"
[ground]
[[objects]]
mesh = { generate = "sphere", radius = 0.02 }
material = "steel"
position = [0.0, 0.01, 0.0]
"#;
    let scene = Scene::from_toml_str(text, Path::new(".")).expect("scene parses");
    let mut p = InMemoryProvider::new();
    p.insert("sphere", common::ball(0.02, &[1500.0]));
    match render(&scene, &mut p, &RenderOptions::default()) {
        Err(e @ SceneError::Invalid { .. }) => {
            let m = e.to_string();
            assert!(m.contains("objects[0].position") && m.contains("intersects the ground"), "{m}");
        }
        other => panic!("expected an intersection error, got {other:?}"),
    }
}

#[test]
fn objects_overlapping_at_the_start_are_an_error_and_touching_ones_are_not() {
    // Two 4 cm blocks, the upper one at `x` and set `gap` above the lower one's top face.
    let place = |x: f64, gap: f64| {
        let text = format!(
            "duration = 0.1\nsample_rate = 16000\n[ground]\n\
             [[objects]]\nname = \"low\"\nmesh = {{ generate = \"box\", size = [0.04, 0.02, 0.04] }}\n\
             material = \"wood\"\nposition = [0.0, 0.01, 0.0]\n\
             [[objects]]\nname = \"up\"\nmesh = {{ generate = \"box\", size = [0.04, 0.02, 0.04] }}\n\
             material = \"wood\"\nposition = [{x}, {}, 0.0]\n",
            0.03 + gap
        );
        let scene = Scene::from_toml_str(&text, Path::new(".")).expect("scene parses");
        let mut p = InMemoryProvider::new();
        p.insert("box", common::block([0.04, 0.02, 0.04], &[2000.0]));
        render(&scene, &mut p, &RenderOptions::default())
    };
    let stack = |gap: f64| place(0.005, gap);
    match stack(-0.002) {
        Err(e @ SceneError::Invalid { .. }) => {
            let m = e.to_string();
            assert!(
                m.contains("objects[1].position") && m.contains("'up' overlaps object 'low' by 0.0020 m"),
                "{m}"
            );
        }
        other => panic!("expected an overlap error, got {other:?}"),
    }
    let copy = place(0.0, -0.02).expect_err("a copy at the same place is an overlap").to_string();
    assert!(copy.contains("'up' overlaps object 'low' by"), "{copy}");
    stack(0.0).expect("blocks exactly touching render");
    stack(-0.5 * modal_scene::START_OVERLAP_TOLERANCE_M).expect("an overlap within the tolerance renders");
}

#[test]
fn an_objects_mode_count_reaches_its_bank_request_and_is_bounded() {
    let scene = |modes: &str| {
        format!(
            "duration = 0.1\nsample_rate = 16000\n[[objects]]\nmesh = {{ generate = \"box\", size = [0.04, 0.02, 0.04] }}\n\
             material = \"wood\"\nposition = [0.0, 0.5, 0.0]\n{modes}"
        )
    };
    let text = scene("modes = 200\n");
    let parsed = Scene::from_toml_str(&text, Path::new(".")).expect("scene parses");
    let mut p = InMemoryProvider::new();
    p.insert("box", common::block([0.04, 0.02, 0.04], &[2000.0]));
    render(&parsed, &mut p, &RenderOptions::default()).expect("render");
    assert_eq!(p.requests[0].max_modes, Some(200));
    for bad in ["modes = 0\n", "modes = 5001\n"] {
        let e = Scene::from_toml_str(&scene(bad), Path::new(".")).expect_err("out of range").to_string();
        assert!(e.contains("objects[0].modes: must be between 1 and 5000"), "{e}");
    }
}

#[test]
fn a_listener_set_inside_an_object_is_reported() {
    let scene = |listener: &str| {
        let text = format!(
            "duration = 0.1\nsample_rate = 16000\n[listener]\nposition = {listener}\nchannels = \"mono\"\n[ground]\n\
             [[objects]]\nname = \"crate\"\nbody = \"fixed\"\nmesh = {{ generate = \"box\", size = [0.4, 0.2, 0.4] }}\n\
             material = \"wood\"\nposition = [0.0, 0.1, 0.0]\n"
        );
        let scene = Scene::from_toml_str(&text, Path::new(".")).expect("scene parses");
        let mut p = InMemoryProvider::new();
        p.insert("box", common::block([0.4, 0.2, 0.4], &[900.0]));
        render(&scene, &mut p, &RenderOptions::default()).expect("render").report.listener_inside
    };
    assert_eq!(scene("[0.05, 0.1, 0.0]"), Some("crate".to_string()));
    assert_eq!(scene("[0.0, 0.3, 0.5]"), None);
}

#[test]
fn two_objects_of_one_name_are_refused() {
    let object = |name: &str, x: f64| {
        format!(
            "[[objects]]\n{name}mesh = {{ generate = \"box\", size = [0.04, 0.02, 0.04] }}\n\
             material = \"wood\"\nposition = [{x}, 0.5, 0.0]\n"
        )
    };
    let parse = |objects: String| Scene::from_toml_str(&format!("[ground]\n{objects}"), Path::new("."));
    let twice = parse(object("name = \"cup\"\n", 0.0) + &object("name = \"cup\"\n", 0.2));
    let e = twice.expect_err("duplicate").to_string();
    assert!(e.contains("objects[1].name: 'cup' is also the name of objects[0]"), "{e}");
    // A given name equal to another object's default one.
    let e = parse(object("", 0.0) + &object("name = \"object0\"\n", 0.2)).expect_err("clash").to_string();
    assert!(e.contains("objects[1].name: 'object0'"), "{e}");
    let e = parse(object("name = \"ground\"\n", 0.0)).expect_err("the ground's name").to_string();
    assert!(e.contains("objects[0].name: \"ground\" names the [ground]"), "{e}");
    parse(object("name = \"a\"\n", 0.0) + &object("", 0.2)).expect("distinct names");
    // Far from the origin f32 physics cannot resolve a contact.
    let e = parse(object("", 1e9)).expect_err("too far").to_string();
    assert!(e.contains("objects[0].position: 1e9 m is beyond ±1000 m"), "{e}");
}

#[test]
fn an_exact_copy_of_an_object_at_its_place_is_an_overlap() {
    // parry's query read these two boxes (hulls of 94 surface nodes) as
    // touching, and the render blew them apart with 9 impacts.
    let text = "duration = 0.1\nsample_rate = 16000\n[ground]\n\
                [[objects]]\nname = \"b\"\nmesh = { generate = \"box\", size = [0.05, 0.03, 0.04] }\n\
                material = \"steel\"\nposition = [0.0, 0.1, 0.0]\n\
                [[objects]]\nname = \"c\"\nmesh = { generate = \"box\", size = [0.05, 0.03, 0.04] }\n\
                material = \"steel\"\nposition = [0.0, 0.1, 0.0]\n";
    let scene = Scene::from_toml_str(text, Path::new(".")).expect("scene parses");
    let mesh = modal_mesh::generate::box_mesh([0.05, 0.03, 0.04], [5, 3, 4]);
    let mut p = InMemoryProvider::new();
    p.insert("box", common::bank_on(&mesh, modal_fem::Material::preset("steel").expect("steel"), &[9000.0]));
    let error = render(&scene, &mut p, &RenderOptions::default()).expect_err("an overlap").to_string();
    // The centre of one lies 1.5 cm (half the height) inside the other.
    assert!(error.contains("objects[1].position: object 'c' overlaps object 'b' by 0.0150 m"), "{error}");
}

#[test]
fn demo_scene_parses_with_generated_meshes() {
    let demo = Scene::demo();
    assert!(demo.objects.len() >= 3);
    assert!(demo.ground.is_some());
    for o in &demo.objects {
        match &o.mesh {
            Some(modal_scene::MeshSource::Generate(g)) => {
                g.shape().expect("generator recipe");
            }
            other => panic!("demo object without a generated mesh: {other:?}"),
        }
    }
}

/// Serves the slab provider's banks as pending ones (surface and mass first,
/// the rest later), optionally completing the ball with another bank.
struct PendingProvider {
    inner: InMemoryProvider,
    ball_completes_as: Option<modal_bank::ModeBank>,
}

impl modal_scene::BankProvider for PendingProvider {
    fn bank(
        &mut self,
        request: &modal_scene::BankRequest,
    ) -> Result<std::sync::Arc<modal_bank::ModeBank>, modal_scene::ProviderError> {
        self.inner.bank(request)
    }

    fn provide(
        &mut self,
        request: &modal_scene::BankRequest,
    ) -> Result<modal_scene::ProvidedBank, modal_scene::ProviderError> {
        let full = (*self.inner.bank(request)?).clone();
        let is_ball =
            matches!(&request.mesh, Some(modal_scene::MeshSource::Generate(g)) if g.generate == "sphere");
        let completed = match (&self.ball_completes_as, is_ball) {
            (Some(other), true) => other.clone(),
            _ => full.clone(),
        };
        let light = modal_bank::ModeBank { shapes: Vec::new(), ..full };
        Ok(modal_scene::ProvidedBank::Pending {
            light: Box::new(light),
            rest: Box::new(move || Ok(completed)),
        })
    }
}

#[test]
fn pending_banks_render_the_same_and_must_complete_as_announced() {
    let scene = Scene::from_toml_str(BALL_ON_SLAB, Path::new(".")).expect("scene");
    let ready = render(&scene, &mut slab_provider(), &RenderOptions::default()).expect("render");
    let mut pending = PendingProvider { inner: slab_provider(), ball_completes_as: None };
    let deferred = render(&scene, &mut pending, &RenderOptions::default()).expect("render");
    assert_eq!(deferred.channels, ready.channels);
    // A completion whose surface differs from the one the physics used is refused.
    let other_ball = common::ball(0.025, &[1500.0, 3100.0]);
    let mut changed = PendingProvider { inner: slab_provider(), ball_completes_as: Some(other_ball) };
    match render(&scene, &mut changed, &RenderOptions::default()) {
        Err(e) => assert!(e.to_string().contains("changed while it was being loaded"), "{e}"),
        Ok(_) => panic!("a bank that changed while loading was accepted"),
    }
}
