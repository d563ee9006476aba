//! Checks a parsed scene before any work: ranges, finiteness, exclusive keys,
//! materials and files. Every error names its key path.

use crate::material::resolve_material;
use crate::roughness::{check_surface, resolve_surface};
use crate::spec::{MeshSource, ObjectSpec, RotationSpec, Scene, MAX_SCENE_MODES};
use crate::SceneError;

/// Longest scene accepted [s] (guards against giant allocations).
pub const MAX_DURATION_S: f64 = 3600.0;
/// Most mesh cells (element-size cubes) of a sounding ground slab: guards the
/// bank provider against a giant mesh.
pub const MAX_SLAB_CELLS: f64 = 1e6;
/// Most objects accepted in one scene.
pub const MAX_OBJECTS: usize = 100_000;
/// Fastest accepted initial speed of an object [m/s] (beyond it rapier's
/// contacts and the sustained-contact model are meaningless).
pub const MAX_SPEED_M_S: f64 = 1000.0;
/// Fastest accepted initial spin of an object [rad/s].
pub const MAX_ANGULAR_SPEED_RAD_S: f64 = 10_000.0;

/// Farthest accepted object position from the origin, per coordinate [m].
/// rapier computes in f32: at 1 km a position resolves 61 µm, at 10⁹ m 64 m
/// (a box set there hovered and struck 16 times).
pub const MAX_POSITION_M: f64 = 1000.0;

/// Shortest accepted scene [s]: one millisecond (a shorter one holds no sound).
pub const MIN_DURATION_S: f64 = 1e-3;

pub(crate) fn validate(scene: &Scene) -> Result<(), SceneError> {
    positive("duration", scene.duration_s)?;
    if scene.duration_s > MAX_DURATION_S {
        return Err(SceneError::invalid(
            "duration",
            format!("at most {MAX_DURATION_S} s, got {}", scene.duration_s),
        ));
    }
    if !(8_000..=192_000).contains(&scene.sample_rate_hz) {
        return Err(SceneError::invalid(
            "sample_rate",
            format!("must lie in 8000..=192000 Hz, got {}", scene.sample_rate_hz),
        ));
    }
    if scene.duration_s < MIN_DURATION_S {
        // 1e-9 s wrote a WAV of no frame with exit 0.
        return Err(SceneError::invalid(
            "duration",
            format!("at least {MIN_DURATION_S} s, got {}", modal_mesh::readable(scene.duration_s)),
        ));
    }
    positive("physics_rate", scene.physics_rate_hz)?;
    if !(30.0..=20_000.0).contains(&scene.physics_rate_hz) {
        return Err(SceneError::invalid(
            "physics_rate",
            format!("must lie in 30..=20000 Hz, got {}", scene.physics_rate_hz),
        ));
    }
    if !(1e-4..=0.1).contains(&scene.contact_prediction_m) {
        return Err(SceneError::invalid(
            "contact_prediction",
            format!("must lie in 0.0001..=0.1 m, got {}", scene.contact_prediction_m),
        ));
    }
    finite3("gravity", scene.gravity_m_s2)?;
    let l = &scene.listener;
    finite3("listener.position", l.position_m)?;
    non_negative("listener.ear_spacing", l.ear_spacing_m)?;
    nonzero3("listener.right", l.right)?;
    non_negative("listener.gain", l.gain)?;
    if l.ground_reflection && scene.ground.as_ref().is_none_or(|g| g.size_m.is_some()) {
        return Err(SceneError::invalid(
            "listener.ground_reflection",
            "needs a [ground] plane (a ground without `size`): the reflection is that of an infinite rigid plane",
        ));
    }
    if let Some(g) = &scene.ground {
        finite("ground.height", g.height_m)?;
        resolve_material(&g.material).map_err(|m| SceneError::invalid("ground.material", m))?;
        resolve_surface(g.surface.as_ref(), &g.material)
            .map_err(|(k, m)| SceneError::invalid(format!("ground.surface.{k}"), m))?;
        non_negative("ground.friction", g.friction)?;
        unit_interval("ground.restitution", g.restitution)?;
        positive("ground.thickness", g.thickness_m)?;
        if let Some(size) = g.size_m {
            for (c, v) in size.iter().enumerate() {
                positive(&format!("ground.size[{c}]"), *v)?;
            }
        }
        finite("ground.center[0]", g.center_m[0])?;
        finite("ground.center[1]", g.center_m[1])?;
        if let Some(h) = g.element_size_m {
            positive("ground.element_size", h)?;
        }
        mode_count("ground.modes", g.modes)?;
        if g.modes.is_some() && g.size_m.is_none() {
            return Err(SceneError::invalid(
                "ground.modes",
                "applies to a sounding slab (a ground with `size`) only",
            ));
        }
        if let Some(size) = g.size_m {
            let h = g.element_size_m.unwrap_or(g.thickness_m);
            let cells =
                [size[0], size[1], g.thickness_m].iter().map(|l| (l / h).ceil().max(1.0)).product::<f64>();
            if cells > MAX_SLAB_CELLS {
                return Err(SceneError::invalid(
                    "ground.size",
                    format!("the slab would need ≈ {cells:.0} mesh cells (at most {MAX_SLAB_CELLS:.0}); raise ground.element_size"),
                ));
            }
        }
    }
    if scene.objects.len() > MAX_OBJECTS {
        return Err(SceneError::invalid("objects", format!("at most {MAX_OBJECTS} objects")));
    }
    for (i, object) in scene.objects.iter().enumerate() {
        validate_object(&format!("objects[{i}]"), object)?;
    }
    unique_names(scene)
}

/// Reports, events and errors name objects: two objects of one name (given,
/// or a default `object<i>`), or an object called like the ground, could not
/// be told apart.
fn unique_names(scene: &Scene) -> Result<(), SceneError> {
    let mut first: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for i in 0..scene.objects.len() {
        let name = scene.object_name(i);
        if scene.ground.is_some() && name == crate::GROUND_NAME {
            return Err(SceneError::invalid(
                format!("objects[{i}].name"),
                "\"ground\" names the [ground] in reports and events: choose another name",
            ));
        }
        if let Some(j) = first.insert(name.clone(), i) {
            return Err(SceneError::invalid(
                format!("objects[{i}].name"),
                format!(
                    "'{name}' is also the name of objects[{j}]: reports and events could not tell them apart"
                ),
            ));
        }
    }
    Ok(())
}

fn validate_object(at: &str, o: &ObjectSpec) -> Result<(), SceneError> {
    let key = |k: &str| format!("{at}.{k}");
    match (&o.mesh, &o.bank) {
        (Some(_), Some(_)) => return Err(SceneError::invalid(at, "give either `mesh` or `bank`, not both")),
        (None, None) => return Err(SceneError::invalid(at, "needs a `mesh` or a `bank`")),
        (Some(MeshSource::File(p)), None) | (None, Some(p)) => {
            let k = if o.mesh.is_some() { key("mesh") } else { key("bank") };
            if !p.is_file() {
                return Err(SceneError::invalid(k, format!("file not found: {}", p.display())));
            }
        }
        (Some(MeshSource::Generate(g)), None) => {
            if let Some((unused, why)) = g.unused_key() {
                return Err(SceneError::invalid(key(&format!("mesh.{unused}")), why));
            }
            g.shape().map_err(|m| SceneError::invalid(key("mesh"), m))?;
            let lengths = [g.radius, g.inner_radius, g.length, g.thickness, g.element_size];
            let names = ["radius", "inner_radius", "length", "thickness", "element_size"];
            for (v, n) in lengths.iter().zip(names) {
                if let Some(v) = v {
                    positive(&key(&format!("mesh.{n}")), *v)?;
                }
            }
            if let Some(size) = g.size {
                for (c, v) in size.iter().enumerate() {
                    positive(&key(&format!("mesh.size[{c}]")), *v)?;
                }
            }
        }
    }
    match &o.material {
        Some(m) => {
            resolve_material(m).map_err(|msg| SceneError::invalid(key("material"), msg))?;
        }
        None if o.mesh.is_some() => return Err(SceneError::invalid(key("material"), "required with `mesh`")),
        None => {}
    }
    if o.order.is_some_and(|n| n != 1 && n != 2) {
        return Err(SceneError::invalid(key("order"), "must be 1 or 2"));
    }
    if let Some(why) = o.scale.and_then(modal_mesh::scale_refusal) {
        return Err(SceneError::invalid(key("scale"), why));
    }
    if let Some(t) = o.sheet_thickness {
        positive(&key("sheet_thickness"), t)?;
        if !matches!(&o.mesh, Some(MeshSource::File(_))) {
            return Err(SceneError::invalid(
                key("sheet_thickness"),
                "applies to a `mesh` file (a surface mesh) only",
            ));
        }
    }
    mode_count(&key("modes"), o.modes)?;
    finite3(&key("position"), o.position_m)?;
    within_world(&key("position"), o.position_m)?;
    match &o.rotation {
        RotationSpec::AxisAngle { axis, angle } => {
            nonzero3(&key("rotation.axis"), *axis)?;
            finite(&key("rotation.angle"), *angle)?;
        }
        RotationSpec::Euler { euler } => finite3(&key("rotation.euler"), *euler)?,
    }
    finite3(&key("linear_velocity"), o.linear_velocity_m_s)?;
    finite3(&key("angular_velocity"), o.angular_velocity_rad_s)?;
    non_negative(&key("friction"), o.friction)?;
    unit_interval(&key("restitution"), o.restitution)?;
    non_negative(&key("rolling_resistance"), o.rolling_resistance_m)?;
    if let Some(r) = o.contact_radius_m {
        positive(&key("contact_radius"), r)?;
    }
    speed_limit(&key("linear_velocity"), o.linear_velocity_m_s, MAX_SPEED_M_S, "m/s")?;
    speed_limit(&key("angular_velocity"), o.angular_velocity_rad_s, MAX_ANGULAR_SPEED_RAD_S, "rad/s")?;
    if let Some(s) = &o.surface {
        // The material's default finish is resolved with the bank; the
        // finish name and explicit keys are checked here.
        check_surface(s).map_err(|(k, msg)| SceneError::invalid(key(&format!("surface.{k}")), msg))?;
    }
    Ok(())
}

fn speed_limit(path: &str, v: [f64; 3], max: f64, unit: &str) -> Result<(), SceneError> {
    let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if speed <= max {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("speed {speed} {unit} is absurd (at most {max} {unit})")))
    }
}

fn finite(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be a finite number, got {v}")))
    }
}

fn finite3(path: &str, v: [f64; 3]) -> Result<(), SceneError> {
    for (c, x) in v.iter().enumerate() {
        finite(&format!("{path}[{c}]"), *x)?;
    }
    Ok(())
}

fn nonzero3(path: &str, v: [f64; 3]) -> Result<(), SceneError> {
    finite3(path, v)?;
    if v.iter().all(|x| *x == 0.0) {
        return Err(SceneError::invalid(path, "must not be the zero vector"));
    }
    Ok(())
}

fn positive(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be finite and > 0, got {v}")))
    }
}

fn non_negative(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must be finite and >= 0, got {v}")))
    }
}

fn unit_interval(path: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(SceneError::invalid(path, format!("must lie in [0, 1], got {v}")))
    }
}

/// A bank's mode count (`modes`), if given, must be 1 ..= [`MAX_SCENE_MODES`].
fn mode_count(key: &str, modes: Option<usize>) -> Result<(), SceneError> {
    match modes {
        Some(n) if !(1..=MAX_SCENE_MODES).contains(&n) => {
            Err(SceneError::invalid(key, format!("must be between 1 and {MAX_SCENE_MODES}, got {n}")))
        }
        _ => Ok(()),
    }
}

/// Refuses a position beyond [`MAX_POSITION_M`] in any coordinate.
fn within_world(path: &str, p: [f64; 3]) -> Result<(), SceneError> {
    match p.iter().find(|c| c.abs() > MAX_POSITION_M) {
        Some(c) => Err(SceneError::invalid(
            path,
            format!(
                "{} m is beyond ±{MAX_POSITION_M} m, where the physics (f32) cannot resolve a contact; \
                 move the scene near the origin",
                modal_mesh::readable(*c)
            ),
        )),
        None => Ok(()),
    }
}
