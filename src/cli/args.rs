//! The command-line contract. Subcommand and flag names written in the issues
//! are relied on by outside checks: add, never rename.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Turn a 3D object into its sound: tetrahedral FEM modes, rigid-body impacts, WAV.
///
/// With no subcommand, renders the built-in demo scene to audio_out/demo.wav.
#[derive(Debug, Parser)]
#[command(
    name = "modal",
    version,
    about,
    long_about = None,
    after_help = "With no command, modal renders the built-in demo scene to audio_out/demo.wav (what \
                  `cargo run --release` does)."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Generate a tet mesh (box, cylinder, tube, sphere, bowl) or tetrahedralize a surface mesh.
    Mesh(MeshArgs),
    /// Write K.mtx, M.mtx (MatrixMarket, lower triangle) and nodes.csv for a mesh.
    ExportMatrices(ExportMatricesArgs),
    /// Compute the audible modes of a mesh and store them in a mode bank.
    Precompute(PrecomputeArgs),
    /// Precompute the banks of every asset in a manifest (sharded for Slurm/Kubernetes), with a catalogue.
    PrecomputeBatch(crate::cli::batch::PrecomputeBatchArgs),
    /// Work with batch catalogues (merge the shards' catalogues).
    #[command(subcommand)]
    Catalogue(crate::cli::catalogue::CatalogueCommand),
    /// Show what a mode bank holds.
    Info(InfoArgs),
    /// Change a bank's material (same Poisson's ratio) or size without a new eigen solve.
    Retune(RetuneArgs),
    /// Export a bank's surface and mode shapes for viewing (ParaView .vtu).
    Export(ExportArgs),
    /// Strike a bank at surface points and write the sound as WAV.
    Strike(StrikeArgs),
    /// Simulate a rigid-body scene and render its sound (no scene: the built-in demo).
    Render(RenderArgs),
    /// Pressure each audible mode radiates to points around the object, and its radiated power.
    Radiation(crate::cli::radiation::RadiationArgs),
    /// Reproduce the measurements in BENCHMARKS.md (eigen vs scipy, accuracy vs time, synthesis).
    #[command(subcommand)]
    Bench(crate::cli::bench::BenchCommand),
}

/// Material selection shared by every command that builds matrices.
#[derive(Debug, Args, Clone, Default)]
pub struct MaterialArgs {
    /// Material preset (steel, glass, wood, plastic, iron, ceramic, polycarbonate, tin, aluminium, brass).
    #[arg(long)]
    pub material: Option<String>,
    /// Young's modulus E [Pa] (overrides the preset's).
    #[arg(long, value_name = "PA", allow_negative_numbers = true)]
    pub youngs: Option<f64>,
    /// Poisson's ratio ν (overrides the preset's).
    #[arg(long, value_name = "NU", allow_negative_numbers = true)]
    pub poisson: Option<f64>,
    /// Density ρ [kg/m³] (overrides the preset's).
    #[arg(long, value_name = "KG_M3", allow_negative_numbers = true)]
    pub density: Option<f64>,
    /// Rayleigh mass-proportional damping α [1/s] in C = αM + βK.
    #[arg(long, value_name = "A", allow_negative_numbers = true)]
    pub alpha: Option<f64>,
    /// Rayleigh stiffness-proportional damping β [s] in C = αM + βK.
    #[arg(long, value_name = "B", allow_negative_numbers = true)]
    pub beta: Option<f64>,
}

/// Options that turn an input file into the tet mesh the FEM sees.
#[derive(Debug, Args, Clone)]
pub struct MeshInputArgs {
    /// Element order: 2 = quadratic 10-node tets (default), 1 = linear 4-node tets.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub order: u8,
    /// Multiply all coordinates by S (e.g. 0.001 for a file in millimetres) [default: 1]. Files
    /// carry no unit: an object more than 20 m across is refused as millimetres unless S is given.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub scale: Option<f64>,
    /// Lattice cell size [m] when tetrahedralizing a surface mesh (OBJ/STL/PLY/OFF/glTF); on a thin
    /// shell (a wall thinner than the cell / 1.5), the longest tet edge along the wall.
    #[arg(long, value_name = "H")]
    pub cell: Option<f64>,
    /// Object of a multi-object surface file to mesh (default: all, as one body).
    #[arg(long, value_name = "NAME")]
    pub part: Option<String>,
    /// Give every open part of a surface mesh (a sheet modelled as one surface: a cymbal, a sign)
    /// this wall thickness [m], so it is meshed as a closed thin shell; closed parts are kept.
    #[arg(long, value_name = "M")]
    pub sheet_thickness: Option<f64>,
}

#[derive(Debug, Args)]
pub struct MeshArgs {
    #[command(subcommand)]
    pub shape: MeshShape,
}

#[derive(Debug, Subcommand)]
pub enum MeshShape {
    /// Box [0,X]×[0,Y]×[0,Z] of structured tets.
    Box {
        /// Edge lengths X,Y,Z [m].
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
        size: [f64; 3],
        #[command(flatten)]
        common: GenerateArgs,
    },
    /// Solid cylinder along z.
    Cylinder {
        /// Radius [m].
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// Length [m].
        #[arg(long, allow_negative_numbers = true)]
        length: f64,
        #[command(flatten)]
        common: GenerateArgs,
    },
    /// Tube (hollow cylinder) along z.
    Tube {
        /// Inner radius [m].
        #[arg(long, allow_negative_numbers = true)]
        inner_radius: f64,
        /// Outer radius [m].
        #[arg(long, allow_negative_numbers = true)]
        outer_radius: f64,
        /// Length [m].
        #[arg(long, allow_negative_numbers = true)]
        length: f64,
        #[command(flatten)]
        common: GenerateArgs,
    },
    /// Solid sphere centred at the origin.
    Sphere {
        /// Radius [m].
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        #[command(flatten)]
        common: GenerateArgs,
    },
    /// Hemispherical shell (a bowl), opening upwards.
    Bowl {
        /// Outer radius [m].
        #[arg(long, allow_negative_numbers = true)]
        radius: f64,
        /// Wall thickness [m].
        #[arg(long, allow_negative_numbers = true)]
        thickness: f64,
        #[command(flatten)]
        common: GenerateArgs,
    },
    /// Write the generated corpus of real-world-like surface assets (OBJ).
    Corpus(crate::cli::corpus::CorpusArgs),
    /// Tetrahedralize a surface mesh (OBJ, STL, PLY, OFF, glTF).
    Tet {
        /// Surface mesh to fill with tets (.obj, .stl, .ply, .off, .glb, .gltf).
        input: PathBuf,
        /// Output .msh file (Gmsh 4.1).
        #[arg(short, long)]
        out: PathBuf,
        /// Lattice cell size [m]; on a thin shell (a wall thinner than the cell / 1.5), the
        /// longest tet edge along the wall.
        #[arg(long, value_name = "H")]
        cell: Option<f64>,
        /// Multiply all coordinates by S.
        #[arg(long, value_name = "S", default_value_t = 1.0, allow_negative_numbers = true)]
        scale: f64,
        /// Object of a multi-object file to mesh.
        #[arg(long)]
        part: Option<String>,
        /// Give every open part (a sheet modelled as one surface) this wall thickness [m].
        #[arg(long, value_name = "M")]
        sheet_thickness: Option<f64>,
        /// Size flat walls (plates, cymbals) for a bank of N modes, as `precompute --modes N`
        /// does: for the (N/2)-th mode, at least the 64th.
        #[arg(long, value_name = "N", default_value_t = modal_tetra::FLAT_RESOLVED_MODES)]
        modes: usize,
        /// Print a JSON report on stdout.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Target element size [m] (default at order 2: min(D_min/2, D_max/4), coarsened for thin plates,
    /// discs and bowls, and along long tubes, to about 12 000 tets; at order 1: min(D_min/8, D_max/20);
    /// docs/scene-format.md). A given size is used in every direction.
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    pub h: Option<f64>,
    /// Element order of the written mesh: 2 (the solver's default, with curved mid-edge nodes on
    /// curved surfaces) or 1 (linear tets, sized for linear elements).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub order: u8,
    /// Output .msh file (Gmsh 4.1 ASCII).
    #[arg(short, long)]
    pub out: PathBuf,
    /// Print a JSON report on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct ExportMatricesArgs {
    /// Tet mesh (.msh, .node/.ele, .mesh) or surface mesh (.obj, .stl, .ply, .off, .glb, .gltf).
    pub mesh: PathBuf,
    /// Output directory (created).
    #[arg(long, short)]
    pub out: PathBuf,
    #[command(flatten)]
    pub material: MaterialArgs,
    #[command(flatten)]
    pub input: MeshInputArgs,
    /// Print a JSON report on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct PrecomputeArgs {
    /// Tet mesh (.msh, .node/.ele, .mesh), surface mesh (.obj, .stl, .ply, .off, or a .glb/.gltf
    /// scene's meshes), or a .glb holding a modal model (read as the bank, no solve).
    pub mesh: PathBuf,
    /// Output mode bank (safetensors).
    #[arg(short, long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub material: MaterialArgs,
    #[command(flatten)]
    pub input: MeshInputArgs,
    /// Keep at most N modes (the lowest in the band).
    #[arg(long, value_name = "N", default_value_t = 64)]
    pub modes: usize,
    /// Lowest frequency kept [Hz].
    #[arg(long, value_name = "HZ", default_value_t = 20.0)]
    pub min_freq: f64,
    /// Highest frequency kept [Hz] (no upper cap: ultrasonic bands are legal).
    #[arg(long, value_name = "HZ", default_value_t = modal_precompute::DEFAULT_MAX_FREQ_HZ)]
    pub max_freq: f64,
    /// Clamp every node inside the box X0,Y0,Z0,X1,Y1,Z1 [m].
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = parse_box, allow_hyphen_values = true)]
    pub fix_box: Option<[f64; 6]>,
    /// Recompute even when the cache holds the result.
    #[arg(long)]
    pub force: bool,
    /// Cache directory (default $MODAL_CACHE_DIR, $XDG_CACHE_HOME/modal or ~/.cache/modal).
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Do not read or write the cache.
    #[arg(long)]
    pub no_cache: bool,
    /// Solver threads (default: one per core); the modes do not depend on the count.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Surface meshes: estimate each mode's error from a second, coarser mesh and refine
    /// until the lowest --accuracy-modes modes are estimated within PCT percent (or the
    /// memory guard stops it, saying what was reached); `off`: one solve, no estimate.
    /// An explicit --cell is kept (estimate only). Tet mesh files get no estimate.
    #[arg(long, value_name = "PCT|off", default_value = "1", value_parser = parse_accuracy, allow_negative_numbers = true)]
    pub accuracy: Accuracy,
    /// The --accuracy target applies to the lowest N modes (all modes get an estimate).
    #[arg(long, value_name = "N", default_value_t = modal_precompute::DEFAULT_ACCURACY_MODES)]
    pub accuracy_modes: usize,
    /// Also solve each audible mode's acoustic transfer up to HZ and store it in the bank
    /// (format 2), as `modal radiation BANK --max-freq HZ --store` does (default air).
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub transfer_max_freq: Option<f64>,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `--accuracy`: a target in percent, or off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy(pub Option<f64>);

impl Default for Accuracy {
    /// 1 %, as the flags' `default_value` (`render` without a command is built from this).
    fn default() -> Self {
        Accuracy(Some(1.0))
    }
}

/// `--transfer-max-freq` (precompute, render, strike) when given: a finite, positive frequency.
pub fn check_transfer_max_freq(hz: Option<f64>) -> anyhow::Result<()> {
    if let Some(f) = hz {
        anyhow::ensure!(
            f.is_finite() && f > 0.0,
            "--transfer-max-freq must be a positive frequency in Hz, got {f}"
        );
    }
    Ok(())
}

fn parse_accuracy(s: &str) -> Result<Accuracy, String> {
    if s.eq_ignore_ascii_case("off") {
        return Ok(Accuracy(None));
    }
    match s.trim_end_matches('%').parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(Accuracy(Some(v))),
        _ => Err(format!("expected a positive percentage (e.g. 1 or 0.5) or `off`, got {s:?}")),
    }
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mode bank file.
    pub bank: PathBuf,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct RetuneArgs {
    /// Mode bank to retune.
    pub bank: PathBuf,
    #[command(flatten)]
    pub material: MaterialArgs,
    /// Scale every length by S (frequencies scale by 1/S).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub scale: Option<f64>,
    /// Output mode bank.
    #[arg(short, long)]
    pub out: PathBuf,
    /// Print one JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("format").required(true).multiple(true).args(["vtk", "faust", "gltf"])))]
pub struct ExportArgs {
    /// Mode bank (or a glTF with a modal model).
    pub bank: PathBuf,
    /// VTK XML unstructured grid to write (ParaView).
    #[arg(long, value_name = "OUT.vtu")]
    pub vtk: Option<PathBuf>,
    /// Binary glTF to write: the surface mesh with the modes in the KHR_audio_rigid_bodies extension.
    #[arg(long, value_name = "OUT.glb")]
    pub gltf: Option<PathBuf>,
    /// Faust library to write: a mesh2faust-style modal model excited at the --at points.
    #[arg(long, value_name = "OUT.lib", requires = "at")]
    pub faust: Option<PathBuf>,
    /// Excitation position X,Y,Z [m] of the Faust model (snapped to the surface); repeat: exPos 0, 1, …
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, requires = "faust")]
    pub at: Vec<[f64; 3]>,
    /// Name of the Faust model function (default: modalModel, as mesh2faust).
    #[arg(long, value_name = "NAME", requires = "faust")]
    pub faust_name: Option<String>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct StrikeArgs {
    /// Mode bank.
    pub bank: PathBuf,
    /// Struck point X,Y,Z [m] (snapped to the nearest surface point); repeat for several strikes.
    /// Default: one strike along the normal where the lowest modes move most along it (a bar
    /// across its broad face near an end, a bowl radially at the rim), printed on stderr.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub at: Vec<[f64; 3]>,
    /// Impulse direction X,Y,Z (default: into the surface); one, or one per --at.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub dir: Vec<[f64; 3]>,
    /// Impulse magnitude [N·s]; one, or one per --at.
    #[arg(long, value_name = "NS", allow_negative_numbers = true)]
    pub impulse: Vec<f64>,
    /// Strike time [s]; one, or one per --at.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub time: Vec<f64>,
    /// Contact time τ [s] of the half-sine force. Default: 1e-4 s, or half the period of the bank's
    /// lowest mode when that is shorter (a body ringing above 5 kHz), so that mode is excited.
    #[arg(long, value_name = "S", conflicts_with = "hertz", allow_negative_numbers = true)]
    pub contact_time: Option<f64>,
    /// Hertz contact of a sphere of MASS_KG and RADIUS_M of the bank's material, striking at the speed
    /// --impulse / MASS_KG (the impulse it delivers when it stops; 1 m/s for a zero impulse).
    #[arg(long, value_name = "MASS_KG,RADIUS_M", value_parser = parse_pair, allow_hyphen_values = true)]
    pub hertz: Option<[f64; 2]>,
    /// Contact microphone position X,Y,Z [m]: output the normal surface velocity there [m/s, full scale 1]
    /// instead of the pressure at a listener.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub mic: Option<[f64; 3]>,
    /// Listener position X,Y,Z [m] in the bank's frame: output the pressure there (full scale 20 Pa).
    /// Default: 0.5 m from the first struck point along its outward normal, farther along it for a large
    /// body (to 2 bounding radii from the centre of mass, where the stored far field is accurate).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, conflicts_with = "mic")]
    pub listener: Option<[f64; 3]>,
    /// Solve the radiation now when the bank has none stored (slow; see `modal radiation --store`).
    #[arg(long, conflicts_with = "mic")]
    pub solve_radiation: bool,
    /// With --solve-radiation: solve only the modes up to HZ; those above keep the level estimate
    /// (said on stderr), as `render --transfer-max-freq` (default: every audible mode).
    #[arg(long, value_name = "HZ", requires = "solve_radiation", allow_negative_numbers = true)]
    pub transfer_max_freq: Option<f64>,
    /// Duration [s], at least one sample and at most 3600; it ends with a 5 ms fade (default: until
    /// the sound decayed by 60 dB, at most 30 s after the last strike).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Sample rate [Hz].
    #[arg(long, value_name = "HZ", default_value_t = 48_000)]
    pub rate: u32,
    /// Write 32-bit float samples (unclipped) instead of 16-bit PCM.
    #[arg(long)]
    pub float: bool,
    /// Scale the output so its peak is at -1 dBFS.
    #[arg(long)]
    pub normalize: bool,
    /// Output WAV file.
    #[arg(short, long)]
    pub out: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args, Default)]
pub struct RenderArgs {
    /// Scene file (TOML); omitted: the built-in demo scene.
    pub scene: Option<PathBuf>,
    /// Output WAV (default: the scene's `output`, or audio_out/demo.wav for the demo).
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// Also write the impact events as JSON.
    #[arg(long, value_name = "FILE")]
    pub events: Option<PathBuf>,
    /// Also write a spectrogram PNG.
    #[arg(long, value_name = "FILE")]
    pub spectrogram: Option<PathBuf>,
    /// Write 32-bit float samples.
    #[arg(long)]
    pub float: bool,
    /// Cache directory for mode banks.
    #[arg(long, value_name = "DIR")]
    pub cache_dir: Option<PathBuf>,
    /// Print one JSON report on stdout.
    #[arg(long)]
    pub json: bool,
    /// Solver threads (default: one per core); the modes do not depend on the count.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// How each mode is heard: `transfer` (default: each mesh asset's
    /// acoustic transfer, solved once by boundary elements and cached with
    /// its bank, per ear in the body's rotating frame) or `estimate` (the
    /// direction-free pulsating-sphere level; nothing solved). Overrides the
    /// scene's `[listener] radiation`.
    #[arg(long, value_enum, value_name = "HOW")]
    pub radiation: Option<RadiationChoice>,
    /// Highest mode frequency [Hz] whose acoustic transfer is solved when a
    /// mesh asset has none cached; modes above it keep the level estimate
    /// (said on stderr). The default, 6 kHz, solves the modes the estimate
    /// gets most wrong (low `ka`) at a cost of seconds per asset (the demo:
    /// ≈ 15 s for all three); `--transfer-max-freq 24000` solves every
    /// playable mode (the demo's three: ≈ 2 minutes on 2 cores, most of it
    /// the thin bowl; BENCHMARKS.md, "Cost today").
    #[arg(long, value_name = "HZ", allow_negative_numbers = true)]
    pub transfer_max_freq: Option<f64>,
    /// Accepted for old scripts: solving the transfer is now the default.
    #[arg(long, hide = true)]
    pub solve_radiation: bool,
    /// Objects given as surface meshes (OBJ, STL, PLY, OFF, glTF) are solved to this accuracy
    /// of their lowest 10 modes, as `modal precompute --accuracy` (so both give one object the
    /// same modes); `off`: one solve at the default cells, no estimate (faster, coarser).
    #[arg(long, value_name = "PCT|off", default_value = "1", value_parser = parse_accuracy, allow_negative_numbers = true)]
    pub accuracy: Accuracy,
}

/// `render --radiation`.
#[derive(Debug, Clone, Copy, ValueEnum, PartialEq, Eq)]
pub enum RadiationChoice {
    /// Per-mode acoustic transfer (solved and cached when missing).
    Transfer,
    /// The direction-free level estimate.
    Estimate,
}

/// Output format of a WAV file.
#[derive(Debug, Clone, Copy, ValueEnum, PartialEq, Eq)]
pub enum SampleFormat {
    Pcm16,
    Float32,
}

fn parse_floats<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != N {
        return Err(format!("expected {N} comma-separated numbers, got '{text}'"));
    }
    let mut values = [0.0; N];
    for (value, part) in values.iter_mut().zip(&parts) {
        *value = part.parse::<f64>().map_err(|_| format!("'{part}' is not a number"))?;
        if !value.is_finite() {
            return Err(format!("'{part}' is not a finite number"));
        }
    }
    Ok(values)
}

fn parse_vec3(text: &str) -> Result<[f64; 3], String> {
    parse_floats::<3>(text)
}

fn parse_pair(text: &str) -> Result<[f64; 2], String> {
    parse_floats::<2>(text)
}

fn parse_box(text: &str) -> Result<[f64; 6], String> {
    let b = parse_floats::<6>(text)?;
    if (0..3).any(|c| b[c] > b[c + 3]) {
        return Err("the box's first corner must be below the second in every coordinate".into());
    }
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_and_reject_garbage() {
        assert_eq!(parse_vec3("1, 2,3e-1").unwrap(), [1.0, 2.0, 0.3]);
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,2,nan").is_err());
        assert!(parse_box("0,0,0,1,1,1").is_ok());
        assert!(parse_box("1,0,0,0,1,1").is_err());
    }

    #[test]
    fn cli_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
