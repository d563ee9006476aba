//! What a render did: per-object statistics and stage timings ([`RenderReport`]),
//! as `modal render --json` prints them.

use serde::Serialize;

use crate::transfer::ModeLevel;

/// Per-object statistics.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ObjectReport {
    /// Object name.
    pub name: String,
    /// Impacts (contact-pair excitations) the object took part in.
    pub impacts: usize,
    /// Strikes (contact points) applied to its modes.
    pub strikes: usize,
    /// Strikes dropped because the contact point lay off the bank's surface.
    pub strikes_dropped: usize,
    /// Sustained-contact force segments (one per contact and physics step).
    pub force_segments: usize,
    /// Force segments dropped because the contact point lay off the bank's surface.
    pub force_segments_dropped: usize,
    /// Modes in the bank.
    pub modes_total: usize,
    /// Modes that can sound (not overdamped, inside 20 Hz .. 0.45 fs).
    pub modes_synthesized: usize,
    /// Σ over samples of active modes (the synthesis work).
    pub mode_samples: u64,
    /// Samples of the object's signal computed (0 if never hit).
    pub samples_computed: u64,
    /// Peak of the object's radiated pressure at 1 m [Pa] (with the
    /// transfer: the largest over its paths to the ears).
    pub peak_pa_at_1m: f64,
    /// Modes heard through their acoustic transfer (the rest, if the object
    /// sounded, through the level estimate).
    pub modes_with_transfer: usize,
    /// Per mode with a transfer: its level by the estimate and by the
    /// transfer (what the transfer changed).
    pub mode_levels: Vec<ModeLevel>,
    /// Centre of mass when the simulation ended (end of the scene, or when
    /// every body fell asleep) [m].
    pub final_position_m: [f64; 3],
    /// Deepest the object went into the `[ground]` plane [m] (contacts' own
    /// separation; a resting body ≈ 0.1 mm). Deep means late or soft
    /// contacts: the plane is not swept for fast bodies (a 3 m/s ball at
    /// 30 steps/s: 33 mm), and a heavy body presses a light one in.
    pub ground_depth_m: f64,
}

/// What a render did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RenderReport {
    /// Per object, in scene order.
    pub objects: Vec<ObjectReport>,
    /// Distinct banks asked from the provider.
    pub banks_requested: usize,
    /// Physics steps simulated (the rest were skipped: everything asleep).
    pub physics_steps: usize,
    /// Total impacts.
    pub impacts: usize,
    /// Seconds getting banks before the physics can start (solves, cache
    /// look-ups; the shapes of cached banks are then read and verified on the
    /// second core while the physics runs, see [`crate::ProvidedBank`]).
    pub banks_s: f64,
    /// Seconds building bodies and colliders (convex hulls, decompositions).
    pub colliders_s: f64,
    /// Seconds in rapier.
    pub physics_s: f64,
    /// Seconds turning contacts into strikes.
    pub excitation_s: f64,
    /// Seconds synthesizing the sustained-contact forces (roughness tracks).
    pub sustained_s: f64,
    /// Seconds getting the banks' acoustic transfer from the provider
    /// (stored, cached or solved now).
    pub radiation_s: f64,
    /// Seconds in modal synthesis.
    pub synthesis_s: f64,
    /// Seconds in the listener mix.
    pub mix_s: f64,
    /// Output length [s].
    pub duration_s: f64,
    /// Output sample rate [Hz].
    pub sample_rate: u32,
    /// Largest |sample| (full scale = 1).
    pub peak: f64,
    /// Samples beyond full scale.
    pub clipped_samples: usize,
    /// The object whose collider holds the listener's position at the start,
    /// if any (an authoring slip: a listener inside a body hears nothing
    /// physical).
    pub listener_inside: Option<String>,
}

impl RenderReport {
    /// Audio seconds per wall-clock second of the per-render work: collider
    /// set-up, physics, excitation, synthesis and mix (bank loading or
    /// solving is reported separately in `banks_s`).
    pub fn real_time_factor(&self) -> f64 {
        self.per_second_of(self.stages_s())
    }

    /// Audio seconds per wall-clock second of the whole render, the banks and their
    /// acoustic transfer included: what a user waiting for a new scene gets (a sounding
    /// slab's first render: 0.05 against 36 for [`Self::real_time_factor`]).
    pub fn whole_real_time_factor(&self) -> f64 {
        self.per_second_of(self.stages_s() + self.banks_s + self.radiation_s)
    }

    /// Wall seconds of the per-render stages.
    fn stages_s(&self) -> f64 {
        self.colliders_s
            + self.physics_s
            + self.excitation_s
            + self.sustained_s
            + self.synthesis_s
            + self.mix_s
    }

    fn per_second_of(&self, wall_s: f64) -> f64 {
        if wall_s > 0.0 {
            self.duration_s / wall_s
        } else {
            f64::INFINITY
        }
    }
}
