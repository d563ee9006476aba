//! `modal-scene`: rigid-body scenes whose contacts strike mode banks.
//!
//! Input: a [`Scene`] (TOML, see `docs/scene-format.md`) and a
//! [`BankProvider`] that supplies one [`modal_bank::ModeBank`] per distinct
//! asset. Work: a rapier3d simulation whose bodies carry the banks' FEM mass
//! properties; after every physics step each contact's impulse (normal and
//! friction) strikes both bodies' modes at the contact point, with a Hertz
//! contact time and a sub-step onset time. Output: audio channels (mono or
//! stereo) heard at a listener with 1/r attenuation, r/c delay and each
//! mode's acoustic transfer in the body's rotating frame (module
//! `transfer`; optionally a ground reflection), a
//! [`RenderReport`], optional impact events (JSON) and a spectrogram (PNG).
//!
//! Dynamic bodies collide through a reduced convex hull or, per object, a
//! convex decomposition (module `collider`); a rolling-resistance couple
//! lets them come to rest and sleep, after which the physics stops (module
//! `physics`); sliding, scraping and rolling contacts drive both bodies'
//! modes with a continuous roughness force (module `sustain`, surface
//! finishes in [`roughness`]); the ground is a silent plane or a sounding slab whose bank
//! comes from the same provider (module `ground`).

mod collider;
mod error;
mod excite;
mod face_hull;
mod ground;
mod listener;
mod material;
mod output;
mod physics;
mod provider;
mod render;
mod report;
pub mod roughness;
mod spec;
pub mod stand_in;
mod sustain;
pub mod transfer;
mod validate;

pub use collider::{DECOMPOSITION_CONCAVITY, DECOMPOSITION_RESOLUTION, MAX_HULL_VERTICES};
pub use error::SceneError;
pub use excite::{
    hertz_contact_time, ImpactEvent, Strike, MAX_CONTACT_TIME_S, MIN_APPROACH_CONTINUING_M_S,
    MIN_APPROACH_M_S, MIN_CONTACT_TIME_S, MIN_IMPULSE_NS, RECONTACT_WINDOW_S, SUSTAIN_DEADBAND,
};
pub use ground::GROUND_NAME;
pub use listener::{MIN_DISTANCE_M, SPEED_OF_SOUND_M_S};
pub use material::{preset_names, resolve_material};
pub use modal_synth::WavFormat;
pub use output::{
    write_events_json, write_spectrogram_png, write_wav, SPECTROGRAM_RANGE_DB, SPECTROGRAM_WINDOW,
};
pub use physics::{ContactSide, ROLLING_LOAD_CAP, SLEEP_AFTER_S, SLEEP_SPEED_M_S, START_OVERLAP_TOLERANCE_M};
pub use provider::{
    BankCompletion, BankProvider, BankRequest, InMemoryProvider, ProvidedBank, ProviderError,
};
pub use render::{
    render, ObjectReport, RenderOptions, RenderReport, Rendered, AIR_IMPEDANCE_PA_S_M, FADE_OUT_S,
    FULL_SCALE_PA, SILENCE_DB,
};
pub use spec::{
    BodyKind, Channels, ColliderKind, ExplicitMaterial, GeneratorSpec, GroundSpec, ListenerSpec,
    MaterialSpec, MeshSource, ObjectSpec, Radiation, RotationSpec, Scene, SurfaceSpec,
    AUTO_DECOMPOSITION_RATIO, DEFAULT_ROLLING_RESISTANCE_M, DEFAULT_SCENE_MODES, DEFAULT_SLAB_THICKNESS_M,
    DEMO_TOML, GENERATORS, MAX_SCENE_MODES,
};
pub use sustain::{
    speed_gate, ContactEvent, SustainedEvent, SCRAPE_REFERENCE_SPEED_M_S, SUSTAIN_MIN_SPEED_M_S,
    SUSTAIN_SMOOTHING_S,
};
pub use validate::{
    MAX_ANGULAR_SPEED_RAD_S, MAX_DURATION_S, MAX_OBJECTS, MAX_POSITION_M, MAX_SLAB_CELLS, MAX_SPEED_M_S,
};
