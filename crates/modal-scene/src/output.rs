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

use crate::sustain::ContactEvent;
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
    let root = BitMapBackend::new(tmp.path(), SPECTROGRAM_SIZE).into_drawing_area();
    draw_spectrogram(&root, &frames, top, axes).map_err(|e| io_error(path, e))?;
    drop(root);
    tmp.persist(path).map_err(|e| io_error(path, e.error))?;
    Ok(())
}

/// Extent of the spectrogram's axes.
#[derive(Clone, Copy)]
struct SpectrogramAxes {
    seconds: f64,
    nyquist_khz: f64,
}

/// Plot frame inside the image, pixels: left, top, right, bottom.
const SPECTROGRAM_FRAME: (i32, i32, i32, i32) =
    (84, 44, SPECTROGRAM_SIZE.0 as i32 - COLORBAR_WIDTH as i32 - 14, 496);

fn draw_spectrogram<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    frames: &[Vec<f64>],
    top: f64,
    axes: SpectrogramAxes,
) -> Result<(), String> {
    use modal_plot::{draw_text, nice_ticks, HPos, Text, VPos};
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let (l, t, r, b) = SPECTROGRAM_FRAME;
    let (width, height) = ((r - l) as usize, (b - t) as usize);
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
            root.draw_pixel((l + x as i32, t + y as i32), &modal_plot::heat(level)).map_err(e)?;
        }
    }
    root.draw(&Rectangle::new([(l, t), (r, b)], BLACK.stroke_width(1))).map_err(e)?;
    let tick = Text::new(15.0);
    for s in nice_ticks(0.0, axes.seconds, 10) {
        let x = l + (s / axes.seconds * (r - l) as f64).round() as i32;
        root.draw(&PathElement::new(vec![(x, b), (x, b + 6)], BLACK)).map_err(e)?;
        draw_text(root, &format!("{s}"), (x, b + 9), &tick.at(HPos::Center, VPos::Top)).map_err(e)?;
    }
    for f in nice_ticks(0.0, axes.nyquist_khz, 8) {
        let y = b - (f / axes.nyquist_khz * (b - t) as f64).round() as i32;
        root.draw(&PathElement::new(vec![(l - 6, y), (l, y)], BLACK)).map_err(e)?;
        draw_text(root, &format!("{f}"), (l - 9, y), &tick.at(HPos::Right, VPos::Center)).map_err(e)?;
    }
    let label = Text::new(17.0);
    draw_text(root, "time [s]", ((l + r) / 2, b + 32), &label.at(HPos::Center, VPos::Top)).map_err(e)?;
    let up = label.at(HPos::Center, VPos::Top).upwards();
    draw_text(root, "frequency [kHz]", (14, (t + b) / 2), &up).map_err(e)?;
    let title = Text::new(21.0).at(HPos::Center, VPos::Bottom);
    draw_text(root, "Spectrogram (mean of the channels)", ((l + r) / 2, t - 12), &title).map_err(e)?;
    let (bar_x, bar_w) = (SPECTROGRAM_SIZE.0 - COLORBAR_WIDTH, COLORBAR_WIDTH);
    let bar = root.clone().shrink((bar_x, 0), (bar_w, SPECTROGRAM_SIZE.1));
    let range = (-SPECTROGRAM_RANGE_DB, 0.0);
    modal_plot::draw_colorbar(&bar, range, 20.0, (t, b), "level [dB re. loudest bin]").map_err(e)?;
    root.present().map_err(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tone_is_drawn_at_its_frequency_and_the_axes_are_labelled() {
        // 1 s of a 3 kHz tone at 16 kHz: Nyquist 8 kHz, so the tone sits 3/8 up the frame.
        let fs = 16_000u32;
        let tone: Vec<f32> = (0..fs)
            .map(|i| (2.0 * std::f64::consts::PI * 3000.0 * i as f64 / fs as f64).sin() as f32)
            .collect();
        let frames = stft_db(&[tone]);
        let top = frames.iter().flatten().cloned().fold(f64::NEG_INFINITY, f64::max);
        let (w, h) = (SPECTROGRAM_SIZE.0 as usize, SPECTROGRAM_SIZE.1 as usize);
        let mut pixels = vec![0u8; w * h * 3];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, SPECTROGRAM_SIZE).into_drawing_area();
            let axes = SpectrogramAxes { seconds: 1.0, nyquist_khz: 8.0 };
            draw_spectrogram(&root, &frames, top, axes).unwrap();
            root.present().unwrap();
        }
        let px = |x: i32, y: i32| {
            let i = (y as usize * w + x as usize) * 3;
            [pixels[i], pixels[i + 1], pixels[i + 2]]
        };
        let (l, t, r, b) = SPECTROGRAM_FRAME;
        // The brightest row of the middle column is the tone's.
        let x = (l + r) / 2;
        let luma = |p: [u8; 3]| p[0] as u32 * 3 + p[1] as u32 * 6 + p[2] as u32;
        let brightest = (t + 1..b).max_by_key(|&y| luma(px(x, y))).unwrap();
        let expected = b as f64 - 3.0 / 8.0 * (b - t) as f64;
        assert!((brightest as f64 - expected).abs() <= 2.0, "tone at row {brightest}, expected {expected}");
        assert_eq!(px(x, brightest), [255, 255, 0], "the loudest bin is the top of the colour map");
        // Text in the margins (tick labels and axis titles) is dark on white.
        let dark = |x0: i32, x1: i32, y0: i32, y1: i32| {
            (x0..x1)
                .flat_map(|x| (y0..y1).map(move |y| (x, y)))
                .filter(|&(x, y)| luma(px(x, y)) < 500)
                .count()
        };
        assert!(dark(0, l - 2, t, b) > 200, "frequency ticks and label");
        assert!(dark(l, r, b + 2, h as i32) > 200, "time ticks and label");
        assert!(dark(0, w as i32, 0, t - 2) > 100, "title");
        let ramp_end = (SPECTROGRAM_SIZE.0 - COLORBAR_WIDTH) as i32 + 6 + 22;
        assert!(dark(ramp_end + 6, w as i32, t, b) > 200, "colour bar tick labels and title");
        // The ramp itself: dark at the bottom, yellow at the top.
        let top_of_ramp = px(ramp_end - 5, t + 1);
        assert!(top_of_ramp[0] == 255 && top_of_ramp[1] > 240 && top_of_ramp[2] < 10, "{top_of_ramp:?}");
        assert!(luma(px(ramp_end - 5, b - 1)) < 300);
    }
}
