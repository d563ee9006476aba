//! What `modal render` tells the user about a finished render that its
//! numbers alone would not: a listener inside a body, strikes that could
//! not be heard, bodies deep in the ground plane, and clipping with the gain
//! that would have fitted.

use modal_scene::Scene;

/// Every warning about a finished render of `scene`, in the order said.
pub fn after_render(scene: &Scene, report: &modal_scene::RenderReport) -> Vec<String> {
    let mut said = listener_warnings(scene, report);
    said.extend(dropped_warnings(report));
    said.extend(ground_depth_warnings(scene, report));
    said
}

/// Widest ear spacing taken for a head [m]; wider pairs are warned about.
const MAX_HEAD_EAR_SPACING_M: f64 = 1.0;

/// One warning per object some of whose strikes could not be synthesized.
/// None are in a sound scene; a silent rod (its contacts read in the wrong
/// frame, every strike dropped) said nothing but a count in `--json`.
fn dropped_warnings(report: &modal_scene::RenderReport) -> Vec<String> {
    report
        .objects
        .iter()
        .filter(|o| o.strikes_dropped > 0)
        .map(|o| {
            format!(
                "{} of {} impacts on '{}' were not heard: their contact point lay off its mesh's surface, or \
                 the impulse beyond the output's range (please report it with the scene)",
                o.strikes_dropped, o.strikes, o.name
            )
        })
        .collect()
}

/// Deeper into the `[ground]` plane than this, an object is warned about
/// [m]: a body at rest sinks ≈ 0.1 mm into rapier's soft contact, and the
/// example scenes' landings reach 3 mm (`meshes/rain100.toml`'s bowls at
/// 3–5 m/s, under a millisecond late).
const GROUND_DEPTH_WARNING_M: f64 = 5e-3;

/// One warning per object that went deep into the ground plane: its contacts
/// there came late (the plane is not swept for fast bodies: a 3 m/s ball at
/// 30 steps/s was struck 33 mm below it) or gave under a load.
fn ground_depth_warnings(scene: &Scene, report: &modal_scene::RenderReport) -> Vec<String> {
    report
        .objects
        .iter()
        .filter(|o| o.ground_depth_m > GROUND_DEPTH_WARNING_M)
        .map(|o| {
            format!(
                "'{}' went {:.1} mm into the [ground] plane: its contacts there came late or gave (at {} physics \
                 steps/s a fast body is not stopped by the plane in time, and a heavy body presses a light one \
                 in), so its impacts there are late and low: raise physics_rate",
                o.name,
                1e3 * o.ground_depth_m,
                scene.physics_rate_hz
            )
        })
        .collect()
}

/// A scene with nothing to sound, a listener set inside a body or under a
/// solid ground plane, or ears metres apart: what it hears is silence, not
/// physical or not a head, and nothing else would say so.
fn listener_warnings(scene: &Scene, report: &modal_scene::RenderReport) -> Vec<String> {
    let at = scene.listener.position_m;
    let mut warnings = Vec::new();
    if scene.objects.is_empty() && scene.ground.as_ref().is_none_or(|g| g.size_m.is_none()) {
        warnings.push("the scene has no object and no sounding ground: the WAV is silence".to_string());
    }
    if let Some(name) = &report.listener_inside {
        warnings.push(format!(
            "the listener at {at:?} m starts inside object '{name}' (its collider): move [listener] position"
        ));
    }
    let spacing = scene.listener.ear_spacing_m;
    // A mono listener is one point: its spacing is not used.
    if scene.listener.channels == modal_scene::Channels::Stereo && spacing > MAX_HEAD_EAR_SPACING_M {
        // A unit slip (50 meant as cm) would otherwise pass silently: the
        // channels would be two microphones 50 m apart, 146 ms out of step.
        warnings.push(format!(
            "[listener] ear_spacing = {spacing} m puts the ears {spacing} m apart (a head is ≈ 0.2 m): \
             the channels are two microphones that far apart; ear_spacing is in metres"
        ));
    }
    if let Some(ground) = scene.ground.as_ref().filter(|g| g.size_m.is_none() && at[1] < g.height_m) {
        warnings.push(format!(
            "the listener at {at:?} m is below the ground plane (y = {} m), which is solid: move [listener] \
             position",
            ground.height_m
        ));
    }
    warnings
}

/// The clipping warning, with the `[listener] gain` that would have fitted
/// the peak (sample 1.0 is `20 Pa / gain`, so the peak scales with the gain).
pub fn clipping_advice(clipped: usize, peak: f64, gain: f64) -> String {
    // Two significant digits, rounded down so the advice does fit.
    let fitting = gain * 0.9 / peak;
    let exponent = fitting.log10().floor() - 1.0;
    let fitting = (fitting / 10f64.powf(exponent)).floor() * 10f64.powf(exponent);
    let decimals = (-exponent).max(0.0) as usize;
    format!(
        "{clipped} samples clipped at full scale: the peak is {peak:.2}× full scale (≈ {:.0} Pa); \
         [listener] gain = {fitting:.decimals$} (now {gain}) would fit it, or --float keeps it unclipped",
        peak * 20.0 / gain
    )
}

#[cfg(test)]
mod tests {
    use super::{clipping_advice, dropped_warnings, ground_depth_warnings, GROUND_DEPTH_WARNING_M};

    #[test]
    fn dropped_strikes_are_said_per_object() {
        let object = |name: &str, strikes, strikes_dropped| modal_scene::ObjectReport {
            name: name.into(),
            strikes,
            strikes_dropped,
            ..Default::default()
        };
        let report = modal_scene::RenderReport {
            objects: vec![object("bar", 4, 0), object("rod", 3, 3)],
            ..Default::default()
        };
        let said = dropped_warnings(&report);
        assert_eq!(said.len(), 1, "{said:?}");
        assert!(said[0].starts_with("3 of 3 impacts on 'rod' were not heard"), "{}", said[0]);
    }

    #[test]
    fn a_body_deep_in_the_ground_plane_is_said_with_the_step_rate() {
        let object = |name: &str, ground_depth_m| modal_scene::ObjectReport {
            name: name.into(),
            ground_depth_m,
            ..Default::default()
        };
        let report = modal_scene::RenderReport {
            objects: vec![
                object("resting", 1e-4),
                object("edge", GROUND_DEPTH_WARNING_M),
                object("ball", 0.033),
            ],
            ..Default::default()
        };
        let scene =
            modal_scene::Scene::from_toml_str("physics_rate = 30", std::path::Path::new(".")).unwrap();
        let said = ground_depth_warnings(&scene, &report);
        assert_eq!(said.len(), 1, "{said:?}");
        assert!(said[0].starts_with("'ball' went 33.0 mm into the [ground] plane"), "{}", said[0]);
        assert!(said[0].contains("at 30 physics steps/s"), "{}", said[0]);
    }

    #[test]
    fn the_clipping_advice_names_a_gain_that_fits_the_peak() {
        // Peak 11.12× at gain 1: 0.9/11.12 = 0.0809… → 0.080, which fits.
        let advice = clipping_advice(10_062, 11.12, 1.0);
        assert!(advice.contains("gain = 0.080 (now 1)"), "{advice}");
        assert!(advice.contains("≈ 222 Pa"), "{advice}");
        // At gain 20 a peak of 1.5× fits at 12.
        assert!(clipping_advice(3, 1.5, 20.0).contains("gain = 12 (now 20)"));
    }
}
