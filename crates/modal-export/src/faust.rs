//! A Faust modal model of a bank, in the form mesh2faust writes.
//!
//! For every underdamped mode `i` of the bank (ascending frequency) and every
//! excitation position `p`:
//!
//! ```text
//! f_i     = f_i,undamped · √(1 − ξ_i²)                  damped frequency [Hz]
//! T60_i   = ln(1000) / d_i                              60 dB decay time [s]
//! g_p,i   = |φ_i(x_p) · n_p| / s_p,   s_p = max_j |φ_j(x_p) · n_p|
//! ```
//!
//! `x_p` is the requested point snapped to the nearest surface point (as
//! `modal strike` does), `n_p` the outward unit normal there and `φ_i(x_p)`
//! the mass-normalized shape [1/√kg] interpolated by the surface's shape
//! functions. Dividing by `s_p` makes each position's loudest mode 1: mesh2faust
//! normalizes every excitation position's gains by their maximum in the same
//! way (it uses `|φ|` at a mesh vertex; we use the normal component at the
//! struck point, the part an impulse into the surface excites). `s_p` is kept
//! in [`Excitation::scale`] and written in a comment, so absolute levels are
//! not lost. A position where every `φ_i · n_p` is 0 keeps gains 0 (`s_p = 0`).
//!
//! On the Faust side `pm.modeFilter(f, t60, g)` is a two-pole resonator with
//! pole radius `r = 0.001^(1/(t60·SR))`, whose impulse response decays as
//! `e^{−d t}` exactly; the model sums its modes and divides by `nModes`
//! (mesh2faust's `:> /(nModes)`), and silences modes at or above `SR/2` with
//! mesh2faust's `select2` guard. Undamped modes (`d = 0`) get
//! `T60 = ma.INFINITY`; overdamped ones (`ξ ≥ 1`, no oscillation) are left
//! out and counted in [`FaustModel::skipped_modes`].

use std::io::Write;

use modal_bank::ModeBank;
use modal_synth::SynthModel;

use crate::ExportError;

/// The name mesh2faust gives its model.
pub const DEFAULT_NAME: &str = "modalModel";

/// The words Faust's lexer keeps for its keywords and primitives (the
/// quoted words of `compiler/parser/faustlexer.l`, Faust 2.83; older
/// releases keep a subset), which no definition can be named after, and
/// `process`, the program's entry point, which the user's `.dsp` defines.
const KEYWORDS: &str = "\
    process with letrec where import component library environment waveform route declare case seq par \
    sum prod inputs outputs mem prefix int float any rdtable rwtable select2 select3 ffunction fconstant \
    fvariable button checkbox vslider hslider nentry vgroup hgroup tgroup vbargraph hbargraph soundfile \
    attach minput enable control acos asin atan atan2 cos sin tan exp log log10 pow sqrt abs min max \
    fmod remainder floor ceil rint round xor assertbounds lowest highest singleprecision doubleprecision \
    quadprecision fixedpointprecision";

/// The environments `import("stdfaust.lib")` defines (Faust libraries'
/// `stdfaust.lib`, 2026; older releases define a subset). The generated
/// library imports it, so a model named after one is a redefinition.
const ENVIRONMENTS: &str = "\
    aa sf an ba co db de dm dx en fd fi ho hy it la ma mi mo ef no os pf pl pm qu rm re ro sp si so sy \
    ve vl wa wd";

/// One excitation position: where it was asked for and where it landed.
#[derive(Clone, Debug, PartialEq)]
pub struct Excitation {
    /// The requested point \[m\].
    pub requested: [f64; 3],
    /// The nearest surface point \[m\].
    pub surface_point: [f64; 3],
    /// Distance between the two \[m\].
    pub distance_m: f64,
    /// Outward unit normal of the surface there.
    pub normal: [f64; 3],
    /// The divisor `s_p` of this position's gains [1/√kg].
    pub scale: f64,
}

/// The numbers of a Faust modal model (see the module doc for the formulas).
#[derive(Clone, Debug, PartialEq)]
pub struct FaustModel {
    /// The Faust function name.
    pub name: String,
    /// Damped frequencies \[Hz\], one per exported mode.
    pub frequencies_hz: Vec<f64>,
    /// T60 decay times \[s\] (infinite for undamped modes).
    pub t60_s: Vec<f64>,
    /// Gains `[position][mode]`, each position's largest 1.
    pub gains: Vec<Vec<f64>>,
    /// The excitation positions, in `exPos` order.
    pub positions: Vec<Excitation>,
    /// Index in the bank of each exported mode.
    pub bank_modes: Vec<usize>,
    /// Overdamped modes left out.
    pub skipped_modes: usize,
}

/// Whether `name` can name the model's Faust definition (see [`check_name`]).
pub fn is_identifier(name: &str) -> bool {
    check_name(name).is_ok()
}

/// Why `name` cannot name the model's Faust definition, if it cannot: not a
/// Faust identifier (`_*[a-zA-Z][_a-zA-Z0-9]*`, as Faust's lexer reads
/// one), a keyword, or an environment of the standard library.
pub fn check_name(name: &str) -> Result<(), ExportError> {
    let letters = name.trim_start_matches('_');
    let identifier = letters.starts_with(|c: char| c.is_ascii_alphabetic())
        && letters.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !identifier {
        Err(ExportError::Identifier(name.to_string()))
    } else if listed(KEYWORDS, name) {
        Err(ExportError::FaustKeyword(name.to_string()))
    } else if listed(ENVIRONMENTS, name) {
        Err(ExportError::FaustEnvironment(name.to_string()))
    } else {
        Ok(())
    }
}

/// Whether `word` is one of the space-separated `words`.
fn listed(words: &str, word: &str) -> bool {
    words.split_whitespace().any(|w| w == word)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl FaustModel {
    /// The model of `bank` excited at the points `at` \[m\], named `name`.
    pub fn new(bank: &ModeBank, at: &[[f64; 3]], name: &str) -> Result<FaustModel, ExportError> {
        check_name(name)?;
        if at.is_empty() {
            return Err(ExportError::NoPositions);
        }
        let model = SynthModel::new(bank).map_err(ExportError::Bank)?;
        let bank_modes: Vec<usize> =
            (0..bank.mode_count()).filter(|&i| bank.damped_frequency_hz(i) > 0.0).collect();
        if bank_modes.is_empty() {
            return Err(ExportError::NoModes);
        }
        let mut dots = vec![0.0; bank.mode_count()];
        let mut gains = Vec::with_capacity(at.len());
        let mut positions = Vec::with_capacity(at.len());
        for (index, &point) in at.iter().enumerate() {
            let hit = model.locate(point).map_err(|source| ExportError::Position { index, point, source })?;
            model.shapes_dot(&hit, hit.normal, &mut dots);
            let row: Vec<f64> = bank_modes.iter().map(|&i| dots[i].abs()).collect();
            let scale = row.iter().cloned().fold(0.0, f64::max);
            gains.push(if scale > 0.0 { row.iter().map(|g| g / scale).collect() } else { row });
            positions.push(Excitation {
                requested: point,
                surface_point: hit.position,
                distance_m: hit.distance,
                normal: hit.normal,
                scale,
            });
        }
        debug_assert!(positions.iter().all(|p| dot(p.normal, p.normal) <= 1.0 + 1e-9));
        Ok(FaustModel {
            name: name.to_string(),
            frequencies_hz: bank_modes.iter().map(|&i| bank.damped_frequency_hz(i)).collect(),
            t60_s: bank_modes.iter().map(|&i| bank.t60_s(i)).collect(),
            skipped_modes: bank.mode_count() - bank_modes.len(),
            gains,
            positions,
            bank_modes,
        })
    }

    /// Number of exported modes.
    pub fn mode_count(&self) -> usize {
        self.frequencies_hz.len()
    }

    /// Writes the Faust library text; `source` names the bank in the header comment.
    pub fn write(&self, out: &mut dyn Write, source: &str) -> std::io::Result<()> {
        let n = self.mode_count();
        let p = self.positions.len();
        let name = &self.name;
        writeln!(out, "// {name}: modal model of {source}, written by modal {}.", env!("CARGO_PKG_VERSION"))?;
        let (lo, hi) = (self.frequencies_hz[0], self.frequencies_hz[n - 1]);
        writeln!(out, "// {n} modes, damped frequencies {lo:.6} .. {hi:.6} Hz; {p} excitation positions:")?;
        for (k, e) in self.positions.iter().enumerate() {
            let [x, y, z] = e.requested;
            let [sx, sy, sz] = e.surface_point;
            let [nx, ny, nz] = e.normal;
            writeln!(
                out,
                "//   exPos {k}: at ({x}, {y}, {z}) m -> surface point ({sx}, {sy}, {sz}) m, \
                 normal ({nx:.6}, {ny:.6}, {nz:.6}), gain scale {:e} 1/sqrt(kg)",
                e.scale
            )?;
        }
        if self.skipped_modes > 0 {
            writeln!(out, "// {} overdamped modes (no oscillation) are left out.", self.skipped_modes)?;
        }
        writeln!(out, "// Frequencies: damped [Hz]. T60 = ln(1000)/decay rate [s].")?;
        writeln!(
            out,
            "// Gains: |phi(x).n| at each position divided by that position's largest (as mesh2faust)."
        )?;
        writeln!(
            out,
            "// Usage: excitation : {name}(exPos,t60Scale) : _   (exPos 0..{}, t60Scale 1 = the bank's T60s)",
            p - 1
        )?;
        writeln!(out, "import(\"stdfaust.lib\");")?;
        writeln!(out)?;
        writeln!(
            out,
            "{name}(exPos,t60Scale) = _ <: par(i,nModes,pm.modeFilter(modesFreqs(i),modesT60s(i),modesGains(int(exPos),i))) :> /(nModes)"
        )?;
        writeln!(out, "with{{")?;
        writeln!(out, "    nModes = {n};")?;
        writeln!(out, "    nExPos = {p};")?;
        writeln!(out, "    modesFreqs(n) = ba.take(n+1,({}));", join(&self.frequencies_hz))?;
        let all_gains: Vec<f64> = self.gains.iter().flatten().copied().collect();
        writeln!(
            out,
            "    modesGains(p,n) = waveform{{{}}},int(min(max(p,0),nExPos-1)*nModes+n) : rdtable : select2(modesFreqs(n)<(ma.SR/2-1),0);",
            join(&all_gains)
        )?;
        writeln!(out, "    modesT60s(n) = t60Scale*ba.take(n+1,({}));", join(&self.t60_s))?;
        writeln!(out, "}};")?;
        Ok(())
    }

    /// The Faust library text (see [`FaustModel::write`]).
    pub fn to_lib(&self, source: &str) -> String {
        let mut text = Vec::new();
        // Writing to a Vec cannot fail.
        let _ = self.write(&mut text, source);
        String::from_utf8_lossy(&text).into_owned()
    }
}

/// A Faust real literal that reads back as exactly `x`: Rust's shortest
/// round-trip decimal (never an exponent), with a decimal point so Faust
/// types it as a float; infinity is `ma.INFINITY`.
pub fn number(x: f64) -> String {
    if x == f64::INFINITY {
        return "ma.INFINITY".into();
    }
    let s = format!("{x}");
    if s.contains('.') {
        s
    } else {
        s + ".0"
    }
}

fn join(values: &[f64]) -> String {
    values.iter().map(|&v| number(v)).collect::<Vec<_>>().join(",")
}

#[cfg(test)]
mod tests {
    use super::*;
    use modal_synth::synthetic::SyntheticBank;

    #[test]
    fn numbers_are_faust_reals_that_round_trip() {
        for x in [1.0, 574.4807123, 1e-9, 3e12, 0.1 + 0.2, 123456789.0] {
            let s = number(x);
            assert!(s.contains('.'), "{s}");
            assert!(!s.contains('e'), "{s}");
            assert_eq!(s.parse::<f64>().unwrap(), x);
        }
        assert_eq!(number(f64::INFINITY), "ma.INFINITY");
    }

    #[test]
    fn identifiers_follow_faust_rules() {
        assert!(is_identifier("modalModel"));
        assert!(is_identifier("_bar2"));
        assert!(!is_identifier("2bar"));
        assert!(!is_identifier("bar-1"));
        assert!(!is_identifier(""));
        assert!(!is_identifier("process"));
    }

    #[test]
    fn keywords_and_standard_environments_are_refused_with_their_reason() {
        assert!(is_identifier("__bar") && is_identifier("bar_") && is_identifier("bass"));
        for name in ["_", "__", "_2", "a.b"] {
            assert!(matches!(check_name(name), Err(ExportError::Identifier(_))), "{name}");
        }
        for name in ["process", "with", "min", "select2", "hslider", "waveform", "xor"] {
            let error = check_name(name).unwrap_err();
            assert!(matches!(error, ExportError::FaustKeyword(_)), "{name}");
            assert_eq!(error.to_string(), format!("`{name}` is a Faust keyword; choose another name"));
        }
        for name in ["ba", "ma", "pm", "fi", "os", "sf", "wd", "la"] {
            let error = check_name(name).unwrap_err();
            assert!(matches!(error, ExportError::FaustEnvironment(_)), "{name}");
            assert!(
                error.to_string().contains("Faust standard library environment (stdfaust.lib)"),
                "{error}"
            );
        }
        let bank = SyntheticBank::preset("steel", 2).build();
        assert!(matches!(FaustModel::new(&bank, &[[0.0; 3]], "ba"), Err(ExportError::FaustEnvironment(_))));
    }

    #[test]
    fn gains_are_normal_shape_components_normalized_per_position() {
        let bank = SyntheticBank::preset("steel", 6).build();
        // Corner region of the 0.2 x 0.1 x 0.05 box: a point just above the top face.
        let at = [[0.05, 0.05, 0.06], [0.2, 0.02, 0.02]];
        let model = FaustModel::new(&bank, &at, "m").unwrap();
        assert_eq!(model.mode_count(), 6);
        assert_eq!(model.gains.len(), 2);
        let synth = SynthModel::new(&bank).unwrap();
        for (row, (e, &p)) in model.gains.iter().zip(model.positions.iter().zip(&at)) {
            let hit = synth.locate(p).unwrap();
            assert_eq!(hit.position, e.surface_point);
            // Independent evaluation: linear interpolation of φ·n at the corners.
            let tri = bank.surface.triangles[hit.triangle];
            for (i, &g) in row.iter().enumerate() {
                let raw: f64 = (0..3)
                    .map(|k| {
                        let s = bank.shape_at(i, tri[k]);
                        hit.bary[k] * dot([s[0] as f64, s[1] as f64, s[2] as f64], hit.normal)
                    })
                    .sum::<f64>()
                    .abs();
                assert!((g * e.scale - raw).abs() <= 1e-12 * e.scale.max(1.0), "mode {i}");
            }
            let max = row.iter().cloned().fold(0.0, f64::max);
            assert_eq!(max, 1.0);
        }
        // The top face's normal is +z.
        assert_eq!(model.positions[0].normal, [0.0, 0.0, 1.0]);
        for i in 0..6 {
            assert_eq!(model.frequencies_hz[i], bank.damped_frequency_hz(i));
            assert_eq!(model.t60_s[i], 1000f64.ln() / bank.decay_rates[i]);
        }
    }

    #[test]
    fn bad_inputs_are_refused() {
        let bank = SyntheticBank::preset("steel", 3).build();
        assert!(matches!(FaustModel::new(&bank, &[], "m"), Err(ExportError::NoPositions)));
        assert!(matches!(FaustModel::new(&bank, &[[0.0; 3]], "1m"), Err(ExportError::Identifier(_))));
        let far = FaustModel::new(&bank, &[[0.0, 0.0, 5.0]], "m");
        assert!(matches!(far, Err(ExportError::Position { index: 0, .. })), "{far:?}");
    }

    #[test]
    fn overdamped_modes_are_left_out_and_undamped_ones_ring_forever() {
        let mut bank = SyntheticBank::preset("steel", 4).build();
        bank.material.alpha = 0.0;
        bank.material.beta = 0.0;
        bank.recompute_damping();
        bank.damping_ratios[0] = 1.5;
        bank.decay_rates[0] = 1.5 * 2.0 * std::f64::consts::PI * bank.frequencies_hz[0];
        let model = FaustModel::new(&bank, &[[0.1, 0.05, 0.05]], "m").unwrap();
        assert_eq!(model.skipped_modes, 1);
        assert_eq!(model.bank_modes, vec![1, 2, 3]);
        assert!(model.t60_s.iter().all(|t| t.is_infinite()));
        assert!(model.to_lib("x").contains("ba.take(n+1,(ma.INFINITY,ma.INFINITY,ma.INFINITY))"));
    }
}
