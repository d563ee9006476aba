//! Synthesis throughput in mode-samples/s, side by side in one run:
//! our f32 SIMD kernel through `ModalVoice` (one thread, and the rayon
//! chunked path), against (a) naive `exp()·sin()` per sample, (b) a per-mode
//! biquad resonator (Faust `modeFilter` style, direct form I), and (c) the
//! scalar f64 complex recurrence; and the force-driven path (`DrivenVoice`,
//! exact first-order hold, f64). Run: `cargo bench -p modal-synth`.

use divan::counter::ItemsCount;
use divan::Bencher;
use modal_bank::{ModeBank, SolveInfo};
use modal_fem::{MassProperties, Material};
use modal_mesh::Surface;
use modal_synth::{kernel, ModalVoice, SynthOptions};
use std::f64::consts::PI;

const FS: f64 = 48_000.0;
const MODES: [usize; 3] = [64, 1024, 16_384];

fn main() {
    divan::main();
}

/// Samples per iteration so that each iteration does ≈ `work` mode-samples.
fn samples_for(modes: usize, work: usize) -> usize {
    (work / modes).max(256)
}

fn frequencies(n: usize) -> Vec<f64> {
    (0..n).map(|i| 50.0 + 20_000.0 * (i as f64 + 0.5) / n as f64).collect()
}

/// Undamped bank (never culled) on one triangle, shapes of order 1.
fn bank(n: usize) -> ModeBank {
    let surface = Surface {
        node_ids: vec![0, 1, 2],
        positions: vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0]],
        triangles: vec![[0, 1, 2]],
        triangle_edge_nodes: None,
    };
    let shapes = (0..n * 9).map(|k| ((k as f64 * 0.7).sin() + 1.1) as f32).collect();
    ModeBank {
        frequencies_hz: frequencies(n),
        damping_ratios: vec![0.0; n],
        decay_rates: vec![0.0; n],
        residuals: vec![0.0; n],
        shapes,
        surface,
        material: Material {
            name: None,
            youngs_pa: 2e11,
            poisson: 0.3,
            density_kg_m3: 7850.0,
            alpha: 0.0,
            beta: 0.0,
        },
        mass: MassProperties {
            volume_m3: 1.0,
            mass_kg: 1.0,
            center_of_mass_m: [0.0; 3],
            inertia_kg_m2: [[0.0; 3]; 3],
        },
        info: SolveInfo::default(),
    }
}

fn voice(n: usize, parallel: bool) -> ModalVoice {
    let o = SynthOptions { cull_db: None, parallel, ..SynthOptions::default() };
    let mut v = ModalVoice::new(&bank(n), o).expect("bench bank");
    v.add_impulse(0.0, [0.02, 0.02, 0.0], [0.0, 0.0, 0.01], 0.0).expect("bench strike");
    v
}

fn run_voice(bencher: Bencher, n: usize, parallel: bool) {
    let samples = samples_for(n, 1 << 24);
    let mut v = voice(n, parallel);
    let mut out = vec![0.0f32; samples];
    let mut pos = 0u64;
    bencher.counter(ItemsCount::new(n * samples)).bench_local(|| {
        v.render(&mut out, pos);
        pos += samples as u64;
        divan::black_box(&out);
    });
}

/// Our kernel, one thread.
#[divan::bench(args = MODES, sample_count = 10)]
fn ours_simd_1_thread(bencher: Bencher, n: usize) {
    run_voice(bencher, n, false);
}

/// Our kernel, mode chunks on the rayon pool (2 cores here).
#[divan::bench(args = [16_384], sample_count = 10)]
fn ours_simd_parallel(bencher: Bencher, n: usize) {
    run_voice(bencher, n, true);
}

/// (a) `A e^{−dt} sin(ωt)` evaluated per mode and sample in f64.
#[divan::bench(args = MODES, sample_count = 5)]
fn naive_exp_sin(bencher: Bencher, n: usize) {
    let samples = samples_for(n, 1 << 20);
    let w: Vec<f64> = frequencies(n).iter().map(|f| 2.0 * PI * f).collect();
    let d: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 * 1e-3).collect();
    let mut out = vec![0.0f32; samples];
    let mut start = 0usize;
    bencher.counter(ItemsCount::new(n * samples)).bench_local(|| {
        for (s, o) in out.iter_mut().enumerate() {
            let t = (start + s) as f64 / FS;
            let mut acc = 0.0;
            for (di, wi) in d.iter().zip(&w) {
                acc += (-di * t).exp() * (wi * t).sin();
            }
            *o = acc as f32;
        }
        start += samples;
        divan::black_box(&out);
    });
}

/// (b) Per-mode biquad resonator `y = b0 x + b1 x1 + b2 x2 − a1 y1 − a2 y2` in f32.
#[divan::bench(args = MODES, sample_count = 10)]
fn biquad_resonator(bencher: Bencher, n: usize) {
    let samples = samples_for(n, 1 << 22);
    let (mut a1, mut a2) = (vec![0f32; n], vec![0f32; n]);
    for (i, f) in frequencies(n).iter().enumerate() {
        let r = (-1.0f64 / FS).exp();
        a1[i] = (-2.0 * r * (2.0 * PI * f / FS).cos()) as f32;
        a2[i] = (r * r) as f32;
    }
    let (b0, b1, b2) = (1.0f32, 0.0f32, -1.0f32);
    let (mut y1, mut y2) = (vec![0f32; n], vec![0f32; n]);
    let mut input = vec![0.0f32; samples];
    input[0] = 1.0;
    let mut out = vec![0.0f32; samples];
    bencher.counter(ItemsCount::new(n * samples)).bench_local(|| {
        out.iter_mut().for_each(|o| *o = 0.0);
        for i in 0..n {
            let (mut x1, mut x2, mut p1, mut p2) = (0.0f32, 0.0f32, y1[i], y2[i]);
            for (o, &x) in out.iter_mut().zip(&input) {
                let y = b0 * x + b1 * x1 + b2 * x2 - a1[i] * p1 - a2[i] * p2;
                (x2, x1, p2, p1) = (x1, x, p1, y);
                *o += y;
            }
            (y1[i], y2[i]) = (p1, p2);
        }
        divan::black_box(&out);
    });
}

/// (c) The scalar f64 complex recurrence (our reference kernel).
#[divan::bench(args = MODES, sample_count = 10)]
fn scalar_f64_recurrence(bencher: Bencher, n: usize) {
    let samples = samples_for(n, 1 << 22);
    let (mut ur, mut ui) = (vec![1e-3f64; n], vec![0f64; n]);
    let (mut pr, mut pi) = (vec![0f64; n], vec![0f64; n]);
    for (i, f) in frequencies(n).iter().enumerate() {
        let th = 2.0 * PI * f / FS;
        (pr[i], pi[i]) = (th.cos(), th.sin());
    }
    let mut out = vec![0.0f64; samples];
    bencher.counter(ItemsCount::new(n * samples)).bench_local(|| {
        out.iter_mut().for_each(|o| *o = 0.0);
        kernel::render_reference(&mut ur, &mut ui, &pr, &pi, &mut out);
        divan::black_box(&out);
    });
}

/// The force-driven path (`DrivenVoice`, exact first-order hold) with
/// `kernel`: contact force segments of `segment` knots (chained, at a point
/// moving along the surface) acting over the whole render, a knot per sample.
fn driven(bencher: Bencher, n: usize, kernel: modal_synth::Kernel, segment: usize) {
    use modal_synth::{DrivenVoice, ForceSegment, ImpactPoint, SynthModel};
    let samples = samples_for(n, 1 << 22);
    let iterations = 12;
    let o = SynthOptions { cull_db: None, kernel, ..SynthOptions::default() };
    let model = std::sync::Arc::new(SynthModel::new(&bank(n)).expect("bench bank"));
    let mut v = DrivenVoice::from_model(model, o).expect("bench voice");
    let knots = samples * iterations + 1;
    let mut start = 0;
    while start + 1 < knots {
        let end = (start + segment).min(knots - 1);
        let x = 0.02 + 0.01 * ((start / segment) % 4) as f64;
        let forces = (start..=end).map(|k| [0.0, 0.0, (k as f64 * 0.37).sin()]).collect();
        v.add_segment(ForceSegment {
            start: start as u64,
            oversample: 1,
            point: ImpactPoint::Position([x, 0.02, 0.0]),
            forces,
        })
        .expect("bench segment");
        start = end;
    }
    let mut out = vec![0.0f32; samples];
    let mut pos = 0u64;
    bencher.counter(ItemsCount::new(n * samples)).bench_local(|| {
        // Past the segments the modes ring freely: the cost is the same.
        v.render(&mut out, pos);
        pos += samples as u64;
        divan::black_box(&out);
    });
}

/// f32 tile kernel, one segment acting throughout.
#[divan::bench(args = [64, 1024], sample_count = 10)]
fn driven_force_path(bencher: Bencher, n: usize) {
    driven(bencher, n, modal_synth::Kernel::Auto, usize::MAX / 4);
}

/// f32 tile kernel, a new 1 ms segment every 48 samples (a physics step at
/// 1 kHz, as in the sustained-contact scenes).
#[divan::bench(args = [64, 1024], sample_count = 10)]
fn driven_force_path_1ms_segments(bencher: Bencher, n: usize) {
    driven(bencher, n, modal_synth::Kernel::Auto, 48);
}

/// The f64 reference kernel, one segment acting throughout.
#[divan::bench(args = [64, 1024], sample_count = 10)]
fn driven_force_path_f64(bencher: Bencher, n: usize) {
    driven(bencher, n, modal_synth::Kernel::Reference, usize::MAX / 4);
}
