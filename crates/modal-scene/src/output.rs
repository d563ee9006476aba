//! Files a render produces: the WAV (through `modal_synth::write_wav`), the
//! impact events (JSON) and a spectrogram (PNG). Every file is written to a
//! temporary file in the target directory and renamed into place, so an
//! interrupted or failed run never leaves a half-written file.
//!
//! Spectrogram: the mean of the channels, Hann windows of [`SPECTROGRAM_WINDOW`]
//! samples, time along x (columns merge frames by their maximum), frequency
//! 0 .. fs/2 linearly along y (low at the bottom), magnitude in dB over the
//! top [`SPECTROGRAM_RANGE_DB`] below the loudest bin, dark → bright. No text
//! is drawn, so no font is needed.

use std::io::Write;
use std::path::Path;

use modal_synth::{WavFormat, WavGain, WavReport};
use plotters::prelude::*;
use realfft::RealFftPlanner;

use crate::sustain::ContactEvent;
use crate::{Rendered, SceneError};

/// FFT length of the spectrogram [samples].
pub const SPECTROGRAM_WINDOW: usize = 1024;
/// Dynamic range shown by the spectrogram [dB].
pub const SPECTROGRAM_RANGE_DB: f64 = 100.0;
const SPECTROGRAM_SIZE: (u32, u32) = (1000, 512);

fn io_error(path: &Path, e: impl std::fmt::Display) -> SceneError {
    SceneError::Io { path: path.to_path_buf(), message: e.to_string() }
}

fn parent_dir(path: &Path) -> Result<&Path, SceneError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).map_err(|e| io_error(path, e))?;
    Ok(dir)
}

/// Writes the channels as a WAV file at the fixed gain 1 (full scale = 1.0,
/// see [`crate::FULL_SCALE_PA`]); 16-bit PCM clips, float does not.
pub fn write_wav(rendered: &Rendered, path: &Path, format: WavFormat) -> Result<WavReport, SceneError> {
    parent_dir(path)?;
    let channels: Vec<&[f32]> = rendered.channels.iter().map(Vec::as_slice).collect();
    modal_synth::write_wav(path, &channels, rendered.sample_rate, format, WavGain::Fixed(1.0))
        .map_err(|e| io_error(path, e))
}

/// Writes the events (impacts and sustained-contact segments, each tagged
/// by `"kind"`) as a JSON array.
pub fn write_events_json(events: &[ContactEvent], path: &Path) -> Result<(), SceneError> {
    let dir = parent_dir(path)?;
    let mut builder = tempfile::Builder::new();
    builder.prefix(".modal-events-").suffix(".tmp");
    // Like a plain `File::create` (0o666 minus the umask), not 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(dir).map_err(|e| io_error(path, e))?;
    serde_json::to_writer_pretty(&mut tmp, events).map_err(|e| io_error(path, e))?;
    tmp.write_all(b"\n").map_err(|e| io_error(path, e))?;
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}

/// Magnitudes in dB, `frames × (window/2 + 1)`, of the channel mean.
fn stft_db(channels: &[Vec<f32>]) -> Vec<Vec<f64>> {
    let n = channels.first().map_or(0, Vec::len);
    let w = SPECTROGRAM_WINDOW;
    let hop = w / 4;
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(w);
    let window: Vec<f64> =
        (0..w).map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / w as f64).cos()).collect();
    let mut input = fft.make_input_vec();
    let mut output = fft.make_output_vec();
    let mut frames = Vec::new();
    let mut start = 0;
    while start < n.max(1) {
        for (i, x) in input.iter_mut().enumerate() {
            let k = start + i;
            let mean = channels.iter().map(|c| c.get(k).copied().unwrap_or(0.0) as f64).sum::<f64>();
            *x = window[i] * mean / channels.len().max(1) as f64;
        }
        // Lengths match the plan, so the transform cannot fail.
        if fft.process(&mut input, &mut output).is_ok() {
            frames.push(output.iter().map(|c| 20.0 * (c.norm() + 1e-300).log10()).collect());
        }
        start += hop;
    }
    frames
}

/// A dark-blue → magenta → yellow ramp for `x` in [0, 1].
fn color(x: f64) -> RGBColor {
    let x = x.clamp(0.0, 1.0);
    let r = (255.0 * (1.5 * x).min(1.0)) as u8;
    let g = (255.0 * (2.0 * x - 1.0).clamp(0.0, 1.0)) as u8;
    let b = (255.0 * (0.35 + 0.65 * (1.0 - (2.0 * x - 0.6).abs()).clamp(0.0, 1.0)) * (1.0 - x * x)) as u8;
    RGBColor(r, g, b)
}

/// Draws a spectrogram of the channels as a PNG image.
pub fn write_spectrogram_png(channels: &[Vec<f32>], path: &Path) -> Result<(), SceneError> {
    let dir = parent_dir(path)?;
    let frames = stft_db(channels);
    let top = frames.iter().flatten().cloned().fold(f64::NEG_INFINITY, f64::max);
    let (width, height) = SPECTROGRAM_SIZE;
    let bins = SPECTROGRAM_WINDOW / 2 + 1;
    let mut builder = tempfile::Builder::new();
    builder.prefix(".modal-spectrogram-").suffix(".png");
    // Like a plain `File::create` (0o666 minus the umask), not 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let tmp = builder.tempfile_in(dir).map_err(|e| io_error(path, e))?;
    {
        let root = BitMapBackend::new(tmp.path(), (width, height)).into_drawing_area();
        for x in 0..width {
            let f0 = x as usize * frames.len() / width as usize;
            let f1 = ((x as usize + 1) * frames.len() / width as usize).max(f0 + 1).min(frames.len());
            for y in 0..height {
                let b0 = (height - 1 - y) as usize * bins / height as usize;
                let b1 = ((height - y) as usize * bins / height as usize).max(b0 + 1).min(bins);
                let mut v = f64::NEG_INFINITY;
                for frame in frames.get(f0..f1).unwrap_or(&[]) {
                    for m in &frame[b0..b1] {
                        v = v.max(*m);
                    }
                }
                let level = 1.0 - (top - v) / SPECTROGRAM_RANGE_DB;
                root.draw_pixel((x as i32, y as i32), &color(level)).map_err(|e| io_error(path, e))?;
            }
        }
        root.present().map_err(|e| io_error(path, e))?;
    }
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}
