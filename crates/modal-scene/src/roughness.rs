//! Surface finishes and the fractal roughness track a sustained contact reads.
//!
//! **Finish** (names of the draft glTF extension `KHR_audio_rigid_bodies`,
//! "Acoustic surfaces"): RMS asperity height σ = `roughness` \[m\], lateral
//! asperity spacing ℓ = `correlation_length` \[m\] and the exponent `p` =
//! `spectral_slope` of the one-dimensional height power spectrum
//! `S(q) ∝ min(1, (q ℓ)^p)` (flat below the corner `q = 1/ℓ`, a power law
//! above; Hurst exponent `H = −(1 + p)/2`, so `p ∈ [−3, −1]`). Two surfaces in
//! contact combine as in the draft: `σ* = √(σ₁² + σ₂²)`, `ℓ* = (ℓ₁ + ℓ₂)/2`,
//! `p* = (p₁ + p₂)/2`.
//!
//! **Track.** The unit-RMS height track `r(x)` (x the distance travelled
//! over the surface \[m\]) is synthesized procedurally, octave by octave, as
//! the draft's scope section suggests ("synthesizes only the octaves the
//! current speed and load resolve"):
//!
//! `r(x) = Σ_o A_o G_o n_o(q_o x)`,  `q_o = 2^o / ℓ`,  `o = −6 … 12`,
//!
//! where `n_o` is seeded value noise (unit-variance lattice values at the
//! integers, smoothstep interpolation) and the octave amplitudes follow the
//! spectrum, `A_o² ∝ q_o min(1, (q_o ℓ)^p)`, normalized to `Σ A_o² = 1`.
//! `G_o` is the **contact filter**: `1/√(1 + (q_o w)^4)` for a contact patch
//! of width `w` (wavelengths shorter than the patch are averaged out), times
//! an anti-alias fade that removes octaves whose temporal frequency `v q_o`
//! approaches the Nyquist frequency (1 below `fs/8`, 0 above `fs/4`).
//! Octaves with `G_o < 10⁻³` are skipped. The same distance always reads the
//! same height, so the spectrum scales with speed: a contact sliding twice
//! as fast sounds an octave higher.

use modal_bank::ModeBank;
use serde::Deserialize;

use crate::spec::{MaterialSpec, ObjectSpec, SurfaceSpec};

/// One surface finish (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
pub struct SurfaceFinish {
    /// RMS asperity height σ \[m\] (`roughness`).
    pub roughness_m: f64,
    /// Lateral asperity spacing ℓ \[m\] (`correlation_length`).
    pub correlation_length_m: f64,
    /// Exponent `p` of the height power spectrum above `1/ℓ` (`spectral_slope`).
    pub spectral_slope: f64,
}

/// Finish of a surface with no preset (the draft's defaults: machined).
pub const DEFAULT_FINISH: SurfaceFinish =
    SurfaceFinish { roughness_m: 2e-6, correlation_length_m: 5e-5, spectral_slope: -2.4 };

/// Named finishes. The first four rows are the draft extension's
/// illustrative table ("Authoring notes"; its machined row is anchored on
/// fractal dimensions 1.17–1.39 reported for machined surfaces, cited there
/// from van den Doel et al. 2001), `glazed` is the draft's glazed-ceramic
/// example, `sawn` and `moulded` are our own starting points for wood and
/// plastics (not measurements).
pub const FINISHES: [(&str, SurfaceFinish); 7] = [
    ("polished", SurfaceFinish { roughness_m: 1e-7, correlation_length_m: 1e-5, spectral_slope: -2.8 }),
    ("machined", DEFAULT_FINISH),
    ("sandblasted", SurfaceFinish { roughness_m: 1e-5, correlation_length_m: 1e-4, spectral_slope: -2.2 }),
    ("cast", SurfaceFinish { roughness_m: 1e-4, correlation_length_m: 1e-3, spectral_slope: -2.0 }),
    ("glazed", SurfaceFinish { roughness_m: 3e-7, correlation_length_m: 2e-5, spectral_slope: -2.7 }),
    ("sawn", SurfaceFinish { roughness_m: 8e-6, correlation_length_m: 2e-4, spectral_slope: -2.2 }),
    ("moulded", SurfaceFinish { roughness_m: 5e-7, correlation_length_m: 3e-5, spectral_slope: -2.6 }),
];

/// The finish a material preset gets by default: metals `machined`, glass
/// `polished`, ceramic `glazed`, wood `sawn`, plastics `moulded`; anything
/// else (explicit constants) the draft's default ([`DEFAULT_FINISH`]).
pub fn material_finish(material: Option<&str>) -> SurfaceFinish {
    let name = match material.map(|m| m.trim().to_ascii_lowercase()).as_deref() {
        Some("steel" | "iron" | "tin" | "aluminium" | "aluminum" | "brass") => "machined",
        Some("glass") => "polished",
        Some("ceramic") => "glazed",
        Some("wood") => "sawn",
        Some("plastic" | "abs" | "polycarbonate") => "moulded",
        _ => return DEFAULT_FINISH,
    };
    finish(name).unwrap_or(DEFAULT_FINISH)
}

/// A named finish.
pub fn finish(name: &str) -> Option<SurfaceFinish> {
    let name = name.trim().to_ascii_lowercase();
    FINISHES.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
}

/// Names of the finishes, comma separated.
pub fn finish_names() -> String {
    FINISHES.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// Largest accepted `roughness` \[m\] (1 cm: a surface rougher than that is geometry).
pub const MAX_ROUGHNESS_M: f64 = 1e-2;
/// Largest accepted `correlation_length` \[m\].
pub const MAX_CORRELATION_LENGTH_M: f64 = 0.1;

impl SurfaceFinish {
    /// Checks the ranges; the error names the offending key (`roughness`,
    /// `correlation_length`, `spectral_slope`) and the value.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let r = self.roughness_m;
        if !(r.is_finite() && r > 0.0 && r <= MAX_ROUGHNESS_M) {
            return Err(("roughness", format!("must lie in (0, {MAX_ROUGHNESS_M}] m, got {r}")));
        }
        let l = self.correlation_length_m;
        if !(l.is_finite() && l > 0.0 && l <= MAX_CORRELATION_LENGTH_M) {
            return Err((
                "correlation_length",
                format!("must lie in (0, {MAX_CORRELATION_LENGTH_M}] m, got {l}"),
            ));
        }
        let p = self.spectral_slope;
        if !(p.is_finite() && (-3.0..=-1.0).contains(&p)) {
            return Err(("spectral_slope", format!("must lie in [-3, -1] (Hurst exponent 0..1), got {p}")));
        }
        Ok(())
    }

    /// Composite finish of two surfaces in contact (module doc).
    pub fn composite(&self, other: &SurfaceFinish) -> SurfaceFinish {
        SurfaceFinish {
            roughness_m: self.roughness_m.hypot(other.roughness_m),
            correlation_length_m: 0.5 * (self.correlation_length_m + other.correlation_length_m),
            spectral_slope: 0.5 * (self.spectral_slope + other.spectral_slope),
        }
    }

    /// Characteristic slope σ/ℓ of the finish.
    pub fn slope(&self) -> f64 {
        self.roughness_m / self.correlation_length_m
    }
}

/// The finish a `surface` table describes on a body of `material`: the named
/// `finish` or the material's default, then the explicit keys. The error
/// names the key (`finish`, `roughness`, `correlation_length`, `spectral_slope`).
pub fn resolve_surface(
    spec: Option<&SurfaceSpec>,
    material: &MaterialSpec,
) -> Result<SurfaceFinish, (&'static str, String)> {
    let name = match material {
        MaterialSpec::Preset(name) => Some(name.as_str()),
        MaterialSpec::Explicit(_) => None,
    };
    resolve_named(spec, name)
}

/// Checks a `surface` table on its own (finish name and explicit keys).
pub fn check_surface(spec: &SurfaceSpec) -> Result<SurfaceFinish, (&'static str, String)> {
    resolve_named(Some(spec), None)
}

fn resolve_named(
    spec: Option<&SurfaceSpec>,
    material: Option<&str>,
) -> Result<SurfaceFinish, (&'static str, String)> {
    let Some(spec) = spec else {
        return Ok(material_finish(material));
    };
    let mut f = match &spec.finish {
        Some(name) => finish(name)
            .ok_or_else(|| ("finish", format!("unknown finish '{name}' (known: {})", finish_names())))?,
        None => material_finish(material),
    };
    if let Some(r) = spec.roughness {
        f.roughness_m = r;
    }
    if let Some(l) = spec.correlation_length {
        f.correlation_length_m = l;
    }
    if let Some(p) = spec.spectral_slope {
        f.spectral_slope = p;
    }
    f.check()?;
    Ok(f)
}

/// The finish of an object: its `surface` table over the default of its
/// material (the scene's preset name, else the bank's material name).
pub fn object_surface(o: &ObjectSpec, bank: &ModeBank) -> Result<SurfaceFinish, (&'static str, String)> {
    let name = match &o.material {
        Some(MaterialSpec::Preset(name)) => Some(name.as_str()),
        Some(MaterialSpec::Explicit(_)) => None,
        None => bank.material.name.as_deref(),
    };
    resolve_named(o.surface.as_ref(), name)
}

const OCTAVE_MIN: i32 = -6;
const OCTAVE_MAX: i32 = 12;
/// Octaves of the track.
pub const OCTAVES: usize = (OCTAVE_MAX - OCTAVE_MIN + 1) as usize;
/// Octaves whose filter gain is below this are not evaluated.
const MIN_OCTAVE_GAIN: f64 = 1e-3;

/// SplitMix64 finalizer: a well-mixed hash of 64 bits.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Unit-variance lattice value (uniform on [−√3, √3]).
fn lattice(seed: u64, i: i64) -> f64 {
    let u = (mix(seed ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03)) >> 11) as f64 / (1u64 << 53) as f64;
    (2.0 * u - 1.0) * 3f64.sqrt()
}

/// Value noise at `x` (lattice spacing 1), smoothstep-interpolated.
fn value_noise(seed: u64, x: f64) -> f64 {
    let i = x.floor();
    let t = x - i;
    let i = i as i64;
    let (a, b) = (lattice(seed, i), lattice(seed, i + 1));
    let s = t * t * (3.0 - 2.0 * t);
    a + (b - a) * s
}

/// The roughness track of one contact (module doc).
#[derive(Clone, Debug)]
pub struct Track {
    seeds: [u64; OCTAVES],
    /// Spatial frequency of each octave [1/m].
    q: [f64; OCTAVES],
    /// Octave amplitude `A_o` (Σ A² = 1).
    amp: [f64; OCTAVES],
}

impl Track {
    /// The track of composite finish `finish`, seeded by `seed`.
    pub fn new(finish: &SurfaceFinish, seed: u64) -> Track {
        let mut q = [0.0; OCTAVES];
        let mut amp = [0.0; OCTAVES];
        let mut seeds = [0u64; OCTAVES];
        let l = finish.correlation_length_m;
        for k in 0..OCTAVES {
            let o = OCTAVE_MIN + k as i32;
            q[k] = 2f64.powi(o) / l;
            let shape = (q[k] * l).powf(finish.spectral_slope).min(1.0);
            amp[k] = (q[k] * l * shape).sqrt();
            seeds[k] = mix(seed.wrapping_mul(0x9E37_79B9).wrapping_add(k as u64));
        }
        let norm = amp.iter().map(|a| a * a).sum::<f64>().sqrt();
        amp.iter_mut().for_each(|a| *a /= norm);
        Track { seeds, q, amp }
    }

    /// Per-octave gains `A_o G_o` for patch width `w_m` \[m\], speed `v` \[m/s\]
    /// and sample rate `fs` \[Hz\] (module doc), into `gains`.
    pub fn gains(&self, w_m: f64, v: f64, fs: f64, gains: &mut [f64; OCTAVES]) {
        for ((gain, q), amp) in gains.iter_mut().zip(&self.q).zip(&self.amp) {
            let qw = q * w_m;
            let patch = 1.0 / (1.0 + qw * qw * qw * qw).sqrt();
            let alias = ((fs / 4.0 - v * q) / (fs / 8.0)).clamp(0.0, 1.0);
            let g = patch * alias;
            *gain = if g < MIN_OCTAVE_GAIN { 0.0 } else { amp * g };
        }
    }

    /// The filtered track at distance `x_m` with per-octave `gains` from [`Track::gains`].
    pub fn height(&self, x_m: f64, gains: &[f64; OCTAVES]) -> f64 {
        let mut h = 0.0;
        for ((gain, seed), q) in gains.iter().zip(&self.seeds).zip(&self.q) {
            if *gain != 0.0 {
                h += gain * value_noise(*seed, x_m * q);
            }
        }
        h
    }
}

/// Scratch gains of [`Track::gains`].
pub type OctaveGains = [f64; OCTAVES];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_bad_values_name_their_key() {
        for (_, f) in FINISHES {
            f.check().unwrap();
        }
        let bad = SurfaceFinish { roughness_m: -1e-6, ..DEFAULT_FINISH };
        assert_eq!(bad.check().unwrap_err().0, "roughness");
        let bad = SurfaceFinish { correlation_length_m: f64::NAN, ..DEFAULT_FINISH };
        assert_eq!(bad.check().unwrap_err().0, "correlation_length");
        let bad = SurfaceFinish { spectral_slope: -5.0, ..DEFAULT_FINISH };
        assert_eq!(bad.check().unwrap_err().0, "spectral_slope");
        assert_eq!(material_finish(Some("Glass")), finish("polished").unwrap());
        assert_eq!(material_finish(None), DEFAULT_FINISH);
        let c = DEFAULT_FINISH.composite(&finish("polished").unwrap());
        assert!((c.roughness_m - (4e-12f64 + 1e-14).sqrt()).abs() < 1e-18);
    }

    /// The unfiltered track has (about) unit RMS, zero mean, and reads the
    /// same height at the same distance.
    #[test]
    fn track_statistics_and_repeatability() {
        let t = Track::new(&DEFAULT_FINISH, 42);
        let mut g = [0.0; OCTAVES];
        t.gains(0.0, 0.0, 48_000.0, &mut g);
        let n = 200_000;
        let dx = 3e-7;
        let (mut s1, mut s2) = (0.0, 0.0);
        for k in 0..n {
            let h = t.height(k as f64 * dx, &g);
            s1 += h;
            s2 += h * h;
        }
        let (mean, rms) = (s1 / n as f64, (s2 / n as f64).sqrt());
        assert!(mean.abs() < 0.1 && (0.5..1.2).contains(&rms), "mean {mean}, rms {rms}");
        assert_eq!(t.height(0.0123, &g), t.height(0.0123, &g));
        // A wide patch removes the short wavelengths: the RMS falls.
        let mut gw = [0.0; OCTAVES];
        t.gains(1e-3, 0.0, 48_000.0, &mut gw);
        let rms_w = ((0..n).map(|k| t.height(k as f64 * dx, &gw).powi(2)).sum::<f64>() / n as f64).sqrt();
        assert!(rms_w < 0.5 * rms, "{rms_w} vs {rms}");
    }
}
