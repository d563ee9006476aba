//! The scene file: plain data read from TOML (documented in `docs/scene-format.md`).
//!
//! Conventions: SI units (metres, seconds, kg, rad/s), `+y` is up, the ground
//! is the plane `y = ground.height`. An object's `position` is where its
//! **centre of mass** goes; `rotation` turns the mesh about its centre of mass.
//! Rotations are given in degrees, either as an axis and angle or as Euler
//! angles `[x, y, z]` applied about the fixed world axes X, then Y, then Z
//! (`R = Rz · Ry · Rx`).

use std::path::{Path, PathBuf};

use modal_mesh::generate::Shape;
use serde::Deserialize;

use crate::SceneError;

mod either;

/// A whole scene: objects, ground, listener and render settings.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Rendered length [s] (TOML key `duration`).
    #[serde(rename = "duration", default = "defaults::duration")]
    pub duration_s: f64,
    /// Audio sample rate [Hz] (`sample_rate`).
    #[serde(rename = "sample_rate", default = "defaults::sample_rate")]
    pub sample_rate_hz: u32,
    /// Physics steps per second [Hz] (`physics_rate`).
    #[serde(rename = "physics_rate", default = "defaults::physics_rate")]
    pub physics_rate_hz: f64,
    /// Contact prediction distance [m] (`contact_prediction`): rapier builds
    /// speculative contacts between shapes closer than this (default 0.02,
    /// rapier's, sized for metre-scale bodies; see `crate::physics`).
    #[serde(rename = "contact_prediction", default = "defaults::contact_prediction")]
    pub contact_prediction_m: f64,
    /// Gravity [m/s²] (`gravity`).
    #[serde(rename = "gravity", default = "defaults::gravity")]
    pub gravity_m_s2: [f64; 3],
    /// Output WAV path, relative to the scene file (`output`), if any.
    #[serde(default)]
    pub output: Option<PathBuf>,
    /// Where the sound is heard.
    #[serde(default)]
    pub listener: ListenerSpec,
    /// The floor plane, if any.
    #[serde(default)]
    pub ground: Option<GroundSpec>,
    /// Sounding objects.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Render sustained contact (sliding, scraping, rolling; `sustained`,
    /// default true). False keeps only impacts.
    #[serde(default = "defaults::yes")]
    pub sustained: bool,
    /// Directory relative paths are resolved against (not a TOML key).
    #[serde(skip)]
    pub base_dir: PathBuf,
}

/// Mono or stereo output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Channels {
    /// One channel heard at the listener position.
    Mono,
    /// Two ears `ear_spacing` apart along `right`.
    #[default]
    Stereo,
}

/// The listener (TOML table `[listener]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ListenerSpec {
    /// Head centre [m] (`position`, default `[0, 0.4, 1.2]`).
    #[serde(rename = "position", default = "defaults::listener_position")]
    pub position_m: [f64; 3],
    /// `"mono"` or `"stereo"` (default).
    #[serde(default)]
    pub channels: Channels,
    /// Distance between the two ears [m] (`ear_spacing`, default 0.2).
    #[serde(rename = "ear_spacing", default = "defaults::ear_spacing")]
    pub ear_spacing_m: f64,
    /// Direction from the left to the right ear (`right`, default `[1, 0, 0]`).
    #[serde(default = "defaults::right")]
    pub right: [f64; 3],
    /// Extra linear output gain (`gain`, default 1).
    #[serde(default = "defaults::one")]
    pub gain: f64,
    /// How each mode's level at an ear is found (`radiation`, default
    /// `"transfer"`): see [`Radiation`].
    #[serde(default)]
    pub radiation: Radiation,
    /// Add the ground plane's reflection as one image source per ear
    /// (`ground_reflection`, default false; needs a `[ground]` plane).
    #[serde(default)]
    pub ground_reflection: bool,
}

/// How the listener hears each mode (`[listener] radiation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Radiation {
    /// Each mode's complex acoustic transfer (the bank's radiation table,
    /// from the provider: stored, cached or solved on demand), per ear, in
    /// the body's rotating frame, updated every block; the estimate for
    /// banks the provider has no table for.
    #[default]
    Transfer,
    /// The direction-free level estimate (a pulsating sphere of the
    /// object's area with the mode's RMS normal velocity).
    Estimate,
}

impl Default for ListenerSpec {
    fn default() -> Self {
        ListenerSpec {
            position_m: defaults::listener_position(),
            channels: Channels::Stereo,
            ear_spacing_m: defaults::ear_spacing(),
            right: defaults::right(),
            gain: 1.0,
            radiation: Radiation::default(),
            ground_reflection: false,
        }
    }
}

/// The floor (TOML table `[ground]`): a silent, infinite plane `y = height`,
/// or, when `size` is given, a finite sounding slab whose top face lies at
/// `y = height` (a fixed box whose mode bank comes from the provider).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundSpec {
    /// Height of the plane [m] (`height`, default 0).
    #[serde(rename = "height", default)]
    pub height_m: f64,
    /// Material, used for the Hertz contact time (default `"wood"`).
    #[serde(default = "defaults::ground_material")]
    pub material: MaterialSpec,
    /// Coulomb friction coefficient (default 0.6).
    #[serde(default = "defaults::ground_friction")]
    pub friction: f64,
    /// Restitution coefficient (default 0.3).
    #[serde(default = "defaults::restitution")]
    pub restitution: f64,
    /// Slab extents along x and z [m] (`size`); absent = infinite silent plane.
    #[serde(rename = "size", default)]
    pub size_m: Option<[f64; 2]>,
    /// Slab thickness [m] (`thickness`, default [`DEFAULT_SLAB_THICKNESS_M`]).
    #[serde(rename = "thickness", default = "defaults::slab_thickness")]
    pub thickness_m: f64,
    /// Centre of the slab's top face in x and z [m] (`center`, default `[0, 0]`).
    #[serde(rename = "center", default)]
    pub center_m: [f64; 2],
    /// Target element edge length of the slab's mesh [m] (`element_size`,
    /// default: the thickness).
    #[serde(rename = "element_size", default)]
    pub element_size_m: Option<f64>,
    /// Surface finish for sustained contact (default: the material's).
    #[serde(default)]
    pub surface: Option<SurfaceSpec>,
    /// Most modes kept in a sounding slab's bank (`modes`, as for an object).
    #[serde(default)]
    pub modes: Option<usize>,
}

/// A surface finish (TOML table `surface`, all keys optional): a named
/// `finish` (`polished`, `machined`, `sandblasted`, `cast`, `glazed`,
/// `sawn`, `moulded`; default: the material's), overridden key by key.
/// Names follow the draft glTF extension `KHR_audio_rigid_bodies`.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    /// A named finish.
    #[serde(default)]
    pub finish: Option<String>,
    /// RMS asperity height σ [m] (`roughness`).
    #[serde(default)]
    pub roughness: Option<f64>,
    /// Lateral asperity spacing ℓ [m] (`correlation_length`).
    #[serde(default)]
    pub correlation_length: Option<f64>,
    /// Exponent of the height power spectrum, −3 ..= −1 (`spectral_slope`).
    #[serde(default)]
    pub spectral_slope: Option<f64>,
}

/// Default thickness of a sounding ground slab [m].
pub const DEFAULT_SLAB_THICKNESS_M: f64 = 0.02;

/// Whether a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum BodyKind {
    /// Moves under gravity and contacts.
    #[default]
    Dynamic,
    /// Never moves (a table, a floor that sounds).
    Fixed,
}

/// The collision shape of a dynamic body (TOML key `collider`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ColliderKind {
    /// The convex hull of the surface (cheap; fills every cavity).
    #[default]
    Hull,
    /// An approximate convex decomposition of the surface (parry's VHACD):
    /// cavities stay open, so a bowl can hold a ball. Costs time at set-up.
    Decomposition,
    /// `decomposition` when the hull's volume exceeds the mesh volume by
    /// more than [`AUTO_DECOMPOSITION_RATIO`], else `hull`.
    Auto,
}

/// Modes a scene object's bank keeps when its `modes` is not given (the
/// precompute default).
pub const DEFAULT_SCENE_MODES: usize = 64;

/// Most modes a scene object's bank may keep (`modes`): each is a voice.
pub const MAX_SCENE_MODES: usize = 5000;

/// `collider = "auto"` decomposes a body whose convex hull is more than this
/// many times its own volume (a bowl: ≈ 5; a box or sphere: ≈ 1).
pub const AUTO_DECOMPOSITION_RATIO: f64 = 1.5;

/// A mesh asset: a file path or a generator recipe (deserialized by hand in
/// `either`, so that a bad key in the table is named).
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSource {
    /// A mesh file, relative to the scene file (resolved when loading).
    File(PathBuf),
    /// A generated mesh.
    Generate(GeneratorSpec),
}

/// A generated mesh, as plain data (`modal_mesh::generate`): which keys a
/// generator needs is listed in `docs/scene-format.md`; a key its shape does
/// not read is refused ([`GeneratorSpec::unused_key`]); lengths in metres.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeneratorSpec {
    /// Generator name: `box`, `cylinder`, `tube`, `sphere`, `bowl`.
    pub generate: String,
    /// Box edge lengths [m] (`box`).
    #[serde(default)]
    pub size: Option<[f64; 3]>,
    /// Outer radius [m] (`cylinder`, `tube`, `sphere`, `bowl`); also
    /// `outer_radius`, the name `modal mesh tube --outer-radius` gives it.
    #[serde(default, alias = "outer_radius")]
    pub radius: Option<f64>,
    /// Inner radius [m] (`tube`).
    #[serde(default)]
    pub inner_radius: Option<f64>,
    /// Length along the mesh z axis [m] (`cylinder`, `tube`).
    #[serde(default)]
    pub length: Option<f64>,
    /// Wall thickness [m] (`bowl`).
    #[serde(default)]
    pub thickness: Option<f64>,
    /// Target element edge length [m] (provider default if absent).
    #[serde(default)]
    pub element_size: Option<f64>,
}

impl GeneratorSpec {
    /// The `modal_mesh` shape this recipe describes; the error names the
    /// missing, unused or unknown key.
    pub fn shape(&self) -> Result<Shape, String> {
        if let Some((_, why)) = self.unused_key() {
            return Err(why);
        }
        let need = |v: Option<f64>, key: &str| v.ok_or_else(|| format!("`{}` needs `{key}`", self.generate));
        Ok(match self.generate.as_str() {
            "box" => Shape::Box { size: self.size.ok_or_else(|| "`box` needs `size`".to_string())? },
            "cylinder" => {
                Shape::Cylinder { radius: need(self.radius, "radius")?, length: need(self.length, "length")? }
            }
            "tube" => Shape::Tube {
                inner_radius: need(self.inner_radius, "inner_radius")?,
                outer_radius: need(self.radius, "radius")?,
                length: need(self.length, "length")?,
            },
            "sphere" => Shape::Sphere { radius: need(self.radius, "radius")? },
            "bowl" => Shape::Bowl {
                radius: need(self.radius, "radius")?,
                thickness: need(self.thickness, "thickness")?,
            },
            other => return Err(format!("unknown generator '{other}' (known: {})", GENERATORS.join(", "))),
        })
    }

    /// A key given that this generator does not read, with a message naming
    /// the keys it takes: a `radius` on a box was ignored without a word.
    /// `None` for an unknown generator ([`GeneratorSpec::shape`] names it).
    pub fn unused_key(&self) -> Option<(&'static str, String)> {
        let (_, takes) = GENERATOR_KEYS.iter().find(|(name, _)| *name == self.generate)?;
        let (unused, _) =
            self.shape_keys_given().into_iter().find(|(key, given)| *given && !takes.contains(key))?;
        let takes: Vec<String> = takes.iter().map(|key| format!("`{key}`")).collect();
        let why = format!(
            "`{}` does not take `{unused}`; it takes {} and `element_size`",
            self.generate,
            takes.join(", ")
        );
        Some((unused, why))
    }

    /// Each key that only some generators read, and whether it was given.
    fn shape_keys_given(&self) -> [(&'static str, bool); 5] {
        [
            ("size", self.size.is_some()),
            ("radius", self.radius.is_some()),
            ("inner_radius", self.inner_radius.is_some()),
            ("length", self.length.is_some()),
            ("thickness", self.thickness.is_some()),
        ]
    }
}

/// Generator names accepted in `mesh = { generate = NAME, .. }`.
pub const GENERATORS: [&str; 5] = ["box", "cylinder", "tube", "sphere", "bowl"];

/// The keys each generator reads in [`GeneratorSpec::shape`], besides
/// `generate` and `element_size`, which every generator takes.
const GENERATOR_KEYS: [(&str, &[&str]); 5] = [
    ("box", &["size"]),
    ("cylinder", &["radius", "length"]),
    ("tube", &["inner_radius", "radius", "length"]),
    ("sphere", &["radius"]),
    ("bowl", &["radius", "thickness"]),
];

/// A material: a preset name or explicit constants (deserialized by hand in
/// `either`, so that a bad key in the table is named).
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialSpec {
    /// A preset such as `"steel"` (see `docs/scene-format.md`).
    Preset(String),
    /// Explicit constants.
    Explicit(ExplicitMaterial),
}

/// Explicit material constants, SI units.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplicitMaterial {
    /// Young's modulus E [Pa].
    pub youngs: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Density ρ [kg/m³].
    pub density: f64,
    /// Rayleigh α [1/s] (default 0).
    #[serde(default)]
    pub alpha: f64,
    /// Rayleigh β [s] (default 0).
    #[serde(default)]
    pub beta: f64,
}

/// An orientation, in degrees: exactly one of the two forms, no other key
/// (deserialized by hand in `either`).
#[derive(Clone, Debug, PartialEq)]
pub enum RotationSpec {
    /// Rotation by `angle` degrees about `axis` (right-hand rule).
    AxisAngle {
        /// Rotation axis (any non-zero length).
        axis: [f64; 3],
        /// Angle [degrees].
        angle: f64,
    },
    /// Euler angles [degrees] about the world X, then Y, then Z axes.
    Euler {
        /// `[x, y, z]` angles [degrees].
        euler: [f64; 3],
    },
}

impl Default for RotationSpec {
    fn default() -> Self {
        RotationSpec::Euler { euler: [0.0; 3] }
    }
}

impl RotationSpec {
    /// The unit quaternion `[w, x, y, z]`.
    pub fn quaternion(&self) -> [f64; 4] {
        match self {
            RotationSpec::AxisAngle { axis, angle } => axis_angle(*axis, angle.to_radians()),
            RotationSpec::Euler { euler } => {
                let qx = axis_angle([1.0, 0.0, 0.0], euler[0].to_radians());
                let qy = axis_angle([0.0, 1.0, 0.0], euler[1].to_radians());
                let qz = axis_angle([0.0, 0.0, 1.0], euler[2].to_radians());
                quat_mul(qz, quat_mul(qy, qx))
            }
        }
    }
}

fn axis_angle(axis: [f64; 3], angle: f64) -> [f64; 4] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if n == 0.0 || angle == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let (s, c) = (angle / 2.0).sin_cos();
    [c, s * axis[0] / n, s * axis[1] / n, s * axis[2] / n]
}

fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// One object (TOML array of tables `[[objects]]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Display name (default `object<i>`).
    #[serde(default)]
    pub name: Option<String>,
    /// Tet mesh asset (exclusive with `bank`).
    #[serde(default)]
    pub mesh: Option<MeshSource>,
    /// Precomputed mode bank file (exclusive with `mesh`).
    #[serde(default)]
    pub bank: Option<PathBuf>,
    /// Material (required with `mesh`; with `bank` it asks for a retune).
    #[serde(default)]
    pub material: Option<MaterialSpec>,
    /// FEM element order 1 or 2 (provider default if absent).
    #[serde(default)]
    pub order: Option<u8>,
    /// Uniform scale applied to the mesh (`None`: 1, unstated: a mesh file whose
    /// object is more than 20 m across is then refused as millimetres).
    #[serde(default)]
    pub scale: Option<f64>,
    /// Wall thickness [m] given to every open part of a surface mesh file (a
    /// sheet modelled as one surface: a cymbal, a sign), as `modal precompute
    /// --sheet-thickness`; `None` (default): open parts are filled as their
    /// winding number encloses.
    #[serde(default)]
    pub sheet_thickness: Option<f64>,
    /// Most modes kept in the bank, the lowest first (`None`: the precompute
    /// default, [`DEFAULT_SCENE_MODES`]); a large or soft object may have more
    /// below the scene's Nyquist frequency.
    #[serde(default)]
    pub modes: Option<usize>,
    /// World position of the centre of mass [m].
    #[serde(rename = "position", default)]
    pub position_m: [f64; 3],
    /// Orientation about the centre of mass (default identity).
    #[serde(default)]
    pub rotation: RotationSpec,
    /// Initial velocity of the centre of mass [m/s].
    #[serde(rename = "linear_velocity", default)]
    pub linear_velocity_m_s: [f64; 3],
    /// Initial angular velocity [rad/s], world frame.
    #[serde(rename = "angular_velocity", default)]
    pub angular_velocity_rad_s: [f64; 3],
    /// `"dynamic"` (default) or `"fixed"`.
    #[serde(default)]
    pub body: BodyKind,
    /// Collision shape of a dynamic body (`collider`, default `"hull"`);
    /// fixed bodies always collide with their surface triangle mesh.
    #[serde(default)]
    pub collider: ColliderKind,
    /// Coulomb friction coefficient (default 0.5; a contact uses the mean of both).
    #[serde(default = "defaults::friction")]
    pub friction: f64,
    /// Restitution (default 0.3; a contact uses the mean of both).
    #[serde(default = "defaults::restitution")]
    pub restitution: f64,
    /// Hertz contact radius [m] (default: half the smallest bounding-box extent).
    #[serde(rename = "contact_radius", default)]
    pub contact_radius_m: Option<f64>,
    /// Rolling-resistance lever arm `b` [m] (`rolling_resistance`, default
    /// [`DEFAULT_ROLLING_RESISTANCE_M`]): while touching, the body feels a
    /// torque `b·N` opposing its rotation (module `physics`).
    #[serde(rename = "rolling_resistance", default = "defaults::rolling_resistance")]
    pub rolling_resistance_m: f64,
    /// Surface finish for sustained contact (default: the material's).
    #[serde(default)]
    pub surface: Option<SurfaceSpec>,
}

/// Default rolling-resistance lever arm [m]: 1 mm, a rolling-resistance
/// coefficient `b/R` ≈ 0.01–0.02 for bodies of 5–10 cm radius, the range
/// quoted for hard objects (glass, ceramic, metal) rolling on a wooden table.
pub const DEFAULT_ROLLING_RESISTANCE_M: f64 = 1e-3;

mod defaults {
    use super::MaterialSpec;
    pub fn duration() -> f64 {
        3.0
    }
    pub fn sample_rate() -> u32 {
        48_000
    }
    pub fn physics_rate() -> f64 {
        1000.0
    }
    pub fn contact_prediction() -> f64 {
        0.02
    }
    pub fn gravity() -> [f64; 3] {
        [0.0, -9.81, 0.0]
    }
    pub fn listener_position() -> [f64; 3] {
        [0.0, 0.4, 1.2]
    }
    pub fn ear_spacing() -> f64 {
        0.2
    }
    pub fn right() -> [f64; 3] {
        [1.0, 0.0, 0.0]
    }
    pub fn yes() -> bool {
        true
    }
    pub fn one() -> f64 {
        1.0
    }
    pub fn ground_material() -> MaterialSpec {
        MaterialSpec::Preset("wood".into())
    }
    pub fn ground_friction() -> f64 {
        0.6
    }
    pub fn friction() -> f64 {
        0.5
    }
    pub fn restitution() -> f64 {
        0.3
    }
    pub fn slab_thickness() -> f64 {
        super::DEFAULT_SLAB_THICKNESS_M
    }
    pub fn rolling_resistance() -> f64 {
        super::DEFAULT_ROLLING_RESISTANCE_M
    }
}

/// The built-in demo scene (`meshes/demo.toml`).
pub const DEMO_TOML: &str = include_str!("../../../meshes/demo.toml");

impl Scene {
    /// Parses and validates a scene; relative paths resolve against `base_dir`
    /// (and must exist).
    pub fn from_toml_str(text: &str, base_dir: &Path) -> Result<Scene, SceneError> {
        let de = toml::Deserializer::parse(text)
            .map_err(|e| SceneError::Parse { path: String::new(), message: one_line(&e.to_string()) })?;
        let mut scene: Scene = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            SceneError::Parse {
                path: if path == "." { String::new() } else { path },
                message: one_line(&e.into_inner().to_string()),
            }
        })?;
        scene.base_dir = base_dir.to_path_buf();
        scene.resolve_paths();
        crate::validate::validate(&scene)?;
        Ok(scene)
    }

    /// Reads a scene file; relative paths resolve against its directory.
    pub fn from_file(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::Io { path: path.to_path_buf(), message: e.to_string() })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Scene::from_toml_str(&text, &base)
    }

    /// The built-in demo scene (generated meshes only, no files needed).
    pub fn demo() -> Scene {
        match Scene::from_toml_str(DEMO_TOML, Path::new(".")) {
            Ok(scene) => scene,
            // The demo is compiled in and covered by a test.
            Err(e) => panic!("built-in demo scene is invalid: {e}"),
        }
    }

    /// Display name of object `i`.
    pub fn object_name(&self, i: usize) -> String {
        self.objects[i].name.clone().unwrap_or_else(|| format!("object{i}"))
    }

    fn resolve_paths(&mut self) {
        let base = self.base_dir.clone();
        let join = |p: &mut PathBuf| {
            if p.is_relative() {
                *p = base.join(&*p);
            }
        };
        if let Some(out) = self.output.as_mut() {
            join(out);
        }
        for object in &mut self.objects {
            if let Some(MeshSource::File(p)) = object.mesh.as_mut() {
                join(p);
            }
            if let Some(p) = object.bank.as_mut() {
                join(p);
            }
        }
    }
}

/// Keeps the first line of a parser message that carries the useful text.
fn one_line(message: &str) -> String {
    let lines: Vec<&str> = message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    // toml errors look like "TOML parse error at line 3, column 1 | ... | unknown field ..."
    let location = lines.first().copied().unwrap_or_default();
    let last = lines.last().copied().unwrap_or_default();
    if lines.len() > 1 && location.starts_with("TOML parse error") {
        format!("{last} ({})", location.trim_start_matches("TOML parse error ").trim_end_matches(':'))
    } else {
        lines.join(" ")
    }
}
