//! A sounding ground: `[ground]` with a `size` becomes a finite slab, a fixed
//! box `size[0] × thickness × size[1]` (x, y, z) whose top face lies at
//! `y = height`, centred on `center = [x, z]`.
//!
//! The slab is rendered as one more object, appended after the scene's own
//! objects and named [`GROUND_NAME`]: its bank is asked from the same
//! [`crate::BankProvider`] (a generated `box` of the ground's material; its
//! element size defaults to the thickness), it collides through its surface
//! triangle mesh like every fixed body, and its contacts strike its modes.
//! Its Hertz radius is infinite (a flat top face), like the plane's. Objects
//! that leave the slab fall past its edge: there is no plane beneath it.

use std::borrow::Cow;

use crate::spec::{BodyKind, ColliderKind, GeneratorSpec, MeshSource, ObjectSpec, RotationSpec, Scene};

/// Name of the slab object in reports and events.
pub const GROUND_NAME: &str = "ground";

/// The scene as rendered: unchanged for a plane (or no ground); with the
/// slab appended as a fixed object, and no plane, for a sounding ground.
pub(crate) fn with_slab(scene: &Scene) -> Cow<'_, Scene> {
    let Some(g) = scene.ground.as_ref() else { return Cow::Borrowed(scene) };
    let Some(size) = g.size_m else { return Cow::Borrowed(scene) };
    let t = g.thickness_m;
    let slab = ObjectSpec {
        name: Some(GROUND_NAME.to_string()),
        mesh: Some(MeshSource::Generate(GeneratorSpec {
            generate: "box".into(),
            size: Some([size[0], t, size[1]]),
            radius: None,
            inner_radius: None,
            length: None,
            thickness: None,
            element_size: Some(g.element_size_m.unwrap_or(t)),
        })),
        bank: None,
        material: Some(g.material.clone()),
        order: None,
        scale: None,
        sheet_thickness: None,
        modes: g.modes,
        position_m: [g.center_m[0], g.height_m - 0.5 * t, g.center_m[1]],
        rotation: RotationSpec::default(),
        linear_velocity_m_s: [0.0; 3],
        angular_velocity_rad_s: [0.0; 3],
        body: BodyKind::Fixed,
        collider: ColliderKind::Hull,
        friction: g.friction,
        restitution: g.restitution,
        contact_radius_m: Some(f64::INFINITY),
        rolling_resistance_m: 0.0,
        surface: g.surface.clone(),
    };
    let mut rendered = scene.clone();
    rendered.ground = None;
    rendered.objects.push(slab);
    Cow::Owned(rendered)
}
