//! Files a render produces: the WAV (through `modal_synth::write_wav`), the
//! impact events (JSON) and a spectrogram (PNG). Every file is written to a
//! temporary file in the target directory and renamed into place, so an
//! interrupted or failed run never leaves a half-written file.
//!
//! Spectrogram: the mean of the channels, Hann windows of [`SPECTROGRAM_WINDOW`]
//! samples, hop a quarter window; time [s] along x (a pixel column shows the
//! loudest of the frames it covers), frequency 0 .. fs/2 [kHz] linearly along
//! y (low at the bottom), level in dB relative to the loudest bin over the top
//! [`SPECTROGRAM_RANGE_DB`], dark → bright, explained by a colour bar. Axes,
//! ticks, units and labels use the embedded font of `modal-plot`.

use std::io::Write;
use std::path::Path;

use modal_synth::{WavFormat, WavGain, WavReport};
use plotters::prelude::*;
use realfft::RealFftPlanner;

use crate::excite::ImpactEvent;
use crate::{Rendered, SceneError};

/// FFT length of the spectrogram [samples].
pub const SPECTROGRAM_WINDOW: usize = 1024;
/// Dynamic range shown by the spectrogram [dB].
pub const SPECTROGRAM_RANGE_DB: f64 = 100.0;
const SPECTROGRAM_SIZE: (u32, u32) = (1100, 560);
/// Width of the colour-bar strip at the right [px].
const COLORBAR_WIDTH: u32 = 110;

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

/// Writes the impact events as a JSON array.
pub fn write_events_json(events: &[ImpactEvent], path: &Path) -> Result<(), SceneError> {
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

/// Draws a spectrogram of the channels, sampled at `sample_rate` Hz, as a PNG image.
pub fn write_spectrogram_png(channels: &[Vec<f32>], sample_rate: u32, path: &Path) -> Result<(), SceneError> {
    let dir = parent_dir(path)?;
    let frames = stft_db(channels);
    let top = frames.iter().flatten().cloned().fold(f64::NEG_INFINITY, f64::max);
    let mut builder = tempfile::Builder::new();
    builder.prefix(".modal-spectrogram-").suffix(".png");
    // Like a plain `File::create` (0o666 minus the umask), not 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let tmp = builder.tempfile_in(dir).map_err(|e| io_error(path, e))?;
    let samples = channels.first().map_or(0, Vec::len);
    let fs = f64::from(sample_rate.max(1));
    let axes = SpectrogramAxes { seconds: (samples as f64 / fs).max(1.0 / fs), nyquist_khz: fs / 2000.0 };
    draw_spectrogram(tmp.path(), &frames, top, axes).map_err(|e| io_error(path, e))?;
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}

/// Extent of the spectrogram's axes.
#[derive(Clone, Copy)]
struct SpectrogramAxes {
    seconds: f64,
    nyquist_khz: f64,
}

fn draw_spectrogram(png: &Path, frames: &[Vec<f64>], top: f64, axes: SpectrogramAxes) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let root = BitMapBackend::new(png, SPECTROGRAM_SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let (main, bar) = root.split_horizontally(SPECTROGRAM_SIZE.0 - COLORBAR_WIDTH);
    let mut chart = ChartBuilder::on(&main)
        .caption("Spectrogram", modal_plot::font(22))
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(0.0..axes.seconds, 0.0..axes.nyquist_khz)
        .map_err(e)?;
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let (width, height) = (xs.len(), ys.len());
    let bins = SPECTROGRAM_WINDOW / 2 + 1;
    for x in 0..width {
        let f0 = x * frames.len() / width;
        let f1 = ((x + 1) * frames.len() / width).max(f0 + 1).min(frames.len());
        for y in 0..height {
            let b0 = (height - 1 - y) * bins / height;
            let b1 = ((height - y) * bins / height).max(b0 + 1).min(bins);
            let mut v = f64::NEG_INFINITY;
            for frame in frames.get(f0..f1).unwrap_or(&[]) {
                for m in &frame[b0..b1] {
                    v = v.max(*m);
                }
            }
            let level = 1.0 - (top - v) / SPECTROGRAM_RANGE_DB;
            let pixel = (xs.start + x as i32, ys.start + y as i32);
            root.draw_pixel(pixel, &modal_plot::heat(level)).map_err(e)?;
        }
    }
    chart
        .configure_mesh()
        .disable_mesh()
        .x_label_formatter(&|t| format!("{}", (t * 1e6).round() / 1e6))
        .y_label_formatter(&|f| format!("{}", (f * 1e6).round() / 1e6))
        .x_desc("time [s]")
        .y_desc("frequency [kHz]")
        .label_style(modal_plot::font(15))
        .axis_desc_style(modal_plot::font(17))
        .draw()
        .map_err(e)?;
    let range = (-SPECTROGRAM_RANGE_DB, 0.0);
    let rows = (ys.start, ys.end - 1);
    modal_plot::draw_colorbar(&bar, range, 20.0, rows, "level [dB re. loudest]").map_err(e)?;
    root.present().map_err(e)
}
