//! WAV output (hound): 16-bit PCM or 32-bit float, mono or stereo, written
//! atomically (temporary file in the destination directory, then rename; the
//! temporary file is removed on any error).
//!
//! Level: a FIXED gain by default, [`DEFAULT_WAV_GAIN`] = 1 full scale per
//! output unit (1 m/s of normal surface velocity for the contact microphone),
//! so the file is linear in the impulse. `Normalize` scales the peak to a
//! given level instead. Float files are written unclipped; PCM samples
//! beyond full scale are clipped and counted.

use crate::error::SynthError;
use crate::options::check_sample_rate;
use std::io::BufWriter;
use std::path::Path;

/// Default fixed gain: full scale per output unit (1 m/s ↦ 1.0).
pub const DEFAULT_WAV_GAIN: f64 = 1.0;

/// Sample encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WavFormat {
    /// 16-bit signed PCM (clipped at full scale).
    #[default]
    Pcm16,
    /// 32-bit IEEE float (unclipped).
    Float32,
}

/// Level applied before encoding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WavGain {
    /// Multiply by this constant.
    Fixed(f64),
    /// Scale so the largest |sample| equals `peak` (full scale = 1).
    Normalize {
        /// Target peak, e.g. 0.891 (−1 dBFS).
        peak: f64,
    },
}

impl Default for WavGain {
    fn default() -> Self {
        WavGain::Fixed(DEFAULT_WAV_GAIN)
    }
}

/// Frames per block of the 16-bit writer.
const PCM_BLOCK_FRAMES: usize = 16_384;

/// The smallest |sample| (full scale = 1) that [`pcm16`] does not write as 0: it
/// rounds `x · 32767` half away from zero.
pub const PCM16_SMALLEST_NONZERO: f64 = 0.5 / 32767.0;

/// A sample (full scale = 1) as 16-bit PCM: clamped to ±1, times 32767,
/// rounded half away from zero — `(x.clamp(-1, 1) · 32767).round()` exactly,
/// without the libm call: truncation is exact, and so is the remainder
/// `y − trunc(y)` for |y| ≤ 32767.
fn pcm16(x: f64) -> i16 {
    let y = x.clamp(-1.0, 1.0) * 32767.0;
    let t = y as i32;
    let r = y - t as f64;
    (t + i32::from(r >= 0.5) - i32::from(r <= -0.5)) as i16
}

/// What [`write_wav`] wrote.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WavReport {
    /// Channels (1 or 2).
    pub channels: u16,
    /// Frames (samples per channel).
    pub frames: usize,
    /// Sample rate \[Hz\].
    pub sample_rate: u32,
    /// Gain that was applied.
    pub gain: f64,
    /// Largest |sample| after the gain (full scale = 1).
    pub peak: f64,
    /// PCM samples clipped at full scale (always 0 for float).
    pub clipped: usize,
}

/// Writes `channels` (1 or 2 equally long slices; stereo is interleaved in
/// the file) to `path` at `sample_rate` Hz (8 000 ..= 192 000).
pub fn write_wav(
    path: &Path,
    channels: &[&[f32]],
    sample_rate: u32,
    format: WavFormat,
    gain: WavGain,
) -> Result<WavReport, SynthError> {
    check_sample_rate(sample_rate as f64)?;
    let frames = match channels {
        [a] => a.len(),
        [a, b] if a.len() == b.len() => a.len(),
        [a, b] => {
            return Err(SynthError::WavChannels(format!("left has {} samples, right {}", a.len(), b.len())))
        }
        _ => {
            return Err(SynthError::WavChannels(format!(
                "{} channels given, 1 or 2 supported",
                channels.len()
            )))
        }
    };
    // Branch-free passes (they vectorize); the error is rare.
    if !channels.iter().all(|c| c.iter().fold(true, |ok, x| ok & x.is_finite())) {
        return Err(SynthError::WavChannels("a sample is NaN or infinite".into()));
    }
    // Finite samples: a plain compare finds the largest magnitude (exact in f32).
    let raw_peak =
        channels.iter().flat_map(|c| c.iter()).fold(0.0f32, |m, &x| if x.abs() > m { x.abs() } else { m });
    let raw_peak = raw_peak as f64;
    let g = match gain {
        WavGain::Fixed(g) if g.is_finite() => g,
        WavGain::Normalize { peak } if peak.is_finite() && peak > 0.0 => {
            if raw_peak > 0.0 {
                peak / raw_peak
            } else {
                1.0
            }
        }
        WavGain::Fixed(v) | WavGain::Normalize { peak: v } => {
            return Err(SynthError::InvalidOption { name: "wav gain", value: v })
        }
    };
    let fail = |e: &dyn std::fmt::Display| SynthError::WavWrite {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let spec = hound::WavSpec {
        channels: channels.len() as u16,
        sample_rate,
        bits_per_sample: if format == WavFormat::Pcm16 { 16 } else { 32 },
        sample_format: if format == WavFormat::Pcm16 {
            hound::SampleFormat::Int
        } else {
            hound::SampleFormat::Float
        },
    };
    let mut clipped = 0;
    // hound errors travel through io::Error to the one atomic writer.
    let hound_io = |e: hound::Error| std::io::Error::other(e.to_string());
    modal_bank::write_file_atomically(path, |file| {
        let mut w = hound::WavWriter::new(BufWriter::new(file), spec).map_err(hound_io)?;
        match format {
            WavFormat::Float32 => {
                for f in 0..frames {
                    for c in channels {
                        w.write_sample((c[f] as f64 * g) as f32).map_err(hound_io)?;
                    }
                }
            }
            WavFormat::Pcm16 => {
                // Blocks of frames: each channel converted in one branch-free
                // pass, then interleaved through hound's 16-bit writer.
                let mut pcm = vec![vec![0i16; PCM_BLOCK_FRAMES.min(frames)]; channels.len()];
                for first in (0..frames).step_by(PCM_BLOCK_FRAMES) {
                    let len = PCM_BLOCK_FRAMES.min(frames - first);
                    for (c, out) in channels.iter().zip(&mut pcm) {
                        for (y, &x) in out.iter_mut().zip(&c[first..first + len]) {
                            let x = x as f64 * g;
                            clipped += usize::from(x.abs() > 1.0);
                            *y = pcm16(x);
                        }
                    }
                    let mut block = w.get_i16_writer((len * channels.len()) as u32);
                    for f in 0..len {
                        for c in &pcm {
                            block.write_sample(c[f]);
                        }
                    }
                    block.flush().map_err(hound_io)?;
                }
            }
        }
        w.finalize().map_err(hound_io)
    })
    .map_err(|e| fail(&e))?;
    Ok(WavReport {
        channels: channels.len() as u16,
        frames,
        sample_rate,
        gain: g,
        peak: raw_peak * g,
        clipped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition [`pcm16`] must reproduce.
    fn pcm16_reference(x: f64) -> i16 {
        (x.clamp(-1.0, 1.0) * 32767.0).round() as i16
    }

    #[test]
    fn pcm16_rounds_like_f64_round() {
        // Exact halves (ties away from zero), their neighbours, the clamp,
        // and a dense sweep of full scale.
        let mut xs = vec![0.0, -0.0, 1.0, -1.0, 1.5, -7.0, 0.5 / 32767.0, -0.5 / 32767.0];
        for k in -32767i32..=32767 {
            let half = (k as f64 + 0.5) / 32767.0;
            xs.extend([half, f64::from_bits(half.to_bits() + 1), f64::from_bits(half.to_bits() - 1)]);
        }
        xs.extend((0..200_001).map(|i| -1.0 + i as f64 * 1e-5));
        for x in xs {
            assert_eq!(pcm16(x), pcm16_reference(x), "x = {x:e}");
        }
    }

    #[test]
    fn the_smallest_nonzero_sample_is_where_pcm16_leaves_zero() {
        let at = PCM16_SMALLEST_NONZERO;
        assert_eq!(pcm16(at), 1);
        assert_eq!(pcm16(-at), -1);
        assert_eq!(pcm16(f64::from_bits(at.to_bits() - 1)), 0);
    }
}
