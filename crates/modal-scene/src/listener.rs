//! What the listener hears of one object: `y(t) = g · s(t − τ) / max(r, r_min)`,
//! with the retarded distance `r = c·τ = |ear − p(t − τ)|`.
//!
//! `s` is the object's radiated signal (emission time), `p` the object's
//! centre of mass, `c` = [`SPEED_OF_SOUND_M_S`]. The sound heard at `t` left
//! the body where it was at the retarded time `t − τ`, so a receding source
//! is heard at `f / (1 + v/c)`, not at the moving observer's `f (1 − v/c)`;
//! `τ` is found by [`RETARDATION_STEPS`] fixed-point steps from the distance
//! at `t`, each shrinking the error by `v/c` (a body faster than sound, up to
//! the scene's 1 km/s, gets a distance it held during the last steps: finite,
//! not the retarded one).
//! Gain and delay are evaluated at the edges of blocks of [`BLOCK`] samples
//! from the physics trajectory (linear between physics steps) and linearly
//! interpolated inside a block, so moving bodies glide without zipper noise.
//! The fractional delay reads `s` with 4-point Catmull-Rom interpolation.
//! An object heard through its acoustic transfer has one `s` per listening
//! point (each ear and, with `ground_reflection`, its image; [`mix`]).

use std::sync::Arc;

use rayon::prelude::*;

use crate::spec::{Channels, Scene};
use crate::transfer::image;

/// Speed of sound in air [m/s].
pub const SPEED_OF_SOUND_M_S: f64 = 343.0;
/// Distances below this are clamped in the 1/r law [m].
pub const MIN_DISTANCE_M: f64 = 0.1;
/// Samples per gain/delay update.
pub const BLOCK: usize = 64;
/// Fixed-point steps for the retarded distance: at 20 m/s the error after
/// three is `(v/c)³ ≈ 2·10⁻⁴` of the first guess's (itself `v·r/c` off).
pub const RETARDATION_STEPS: usize = 3;

/// An object's centre of mass and orientation sampled every physics step.
#[derive(Clone, Debug, Default)]
pub(crate) struct Trajectory {
    /// Time between samples [s].
    pub dt: f64,
    /// Positions at `k · dt` [m].
    pub positions: Vec<[f32; 3]>,
    /// World-to-body rotation matrices at `k · dt` (rows: the body axes in
    /// world coordinates); empty when not recorded.
    pub rotations: Vec<[[f32; 3]; 3]>,
}

impl Trajectory {
    /// Position at time `t` (held constant outside the sampled range).
    pub fn at(&self, t: f64) -> [f64; 3] {
        let n = self.positions.len();
        if n == 0 {
            return [0.0; 3];
        }
        let x = (t / self.dt).max(0.0);
        let k = (x.floor() as usize).min(n - 1);
        let f = if k + 1 < n { x - k as f64 } else { 0.0 };
        let a = self.positions[k];
        let b = self.positions[(k + 1).min(n - 1)];
        [0, 1, 2].map(|c| a[c] as f64 + f * (b[c] as f64 - a[c] as f64))
    }
}

impl Trajectory {
    /// `ear − p(t)` rotated into the body's frame at time `t` [m]: the
    /// rotation is interpolated linearly between physics steps (a step turns
    /// a body by at most a few hundredths of a radian, so the
    /// interpolated matrix is orthogonal to ~1e-4) and the result rescaled
    /// to the exact distance. Without recorded rotations, the world offset.
    pub fn to_body_at(&self, t: f64, ear: [f64; 3]) -> [f64; 3] {
        let p = self.at(t);
        let w = [0, 1, 2].map(|c| ear[c] - p[c]);
        let n = self.rotations.len();
        if n == 0 {
            return w;
        }
        let x = (t / self.dt).max(0.0);
        let k = (x.floor() as usize).min(n - 1);
        let f = if k + 1 < n { x - k as f64 } else { 0.0 };
        let (a, b) = (self.rotations[k], self.rotations[(k + 1).min(n - 1)]);
        let mut d = [0.0; 3];
        for (r, row) in d.iter_mut().enumerate() {
            *row = (0..3)
                .map(|c| {
                    let m = a[r][c] as f64 + f * (b[r][c] as f64 - a[r][c] as f64);
                    m * w[c]
                })
                .sum();
        }
        let (len_w, len_d) = (norm(w), norm(d));
        if len_d > 0.0 {
            d.map(|v| v * len_w / len_d)
        } else {
            d
        }
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The 4 taps of `s` around `floor(x)`: `s[i−1..=i+2]` (zero outside) and
/// the fraction `x − i`.
#[inline(always)]
fn taps(s: &[f32], x: f64) -> ([f64; 4], f64) {
    let i = floor_i64(x);
    let f = x - i as f64;
    let p = match s.get(i.wrapping_sub(1) as usize..).and_then(|t| t.get(..4)) {
        // The interior (every tap inside `s`) without per-tap checks.
        Some(t) if i >= 1 => [t[0] as f64, t[1] as f64, t[2] as f64, t[3] as f64],
        _ => {
            let at = |k: i64| if k >= 0 && (k as usize) < s.len() { s[k as usize] as f64 } else { 0.0 };
            [at(i - 1), at(i), at(i + 1), at(i + 2)]
        }
    };
    (p, f)
}

/// Catmull-Rom interpolation between `p[1]` and `p[2]` at fraction `f`.
#[inline(always)]
fn catmull_rom([p0, p1, p2, p3]: [f64; 4], f: f64) -> f64 {
    p1 + 0.5 * f * (p2 - p0 + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0)))
}

/// Catmull-Rom interpolation of `s` at fractional index `x` (zero outside).
#[cfg(test)]
fn read(s: &[f32], x: f64) -> f64 {
    let (p, f) = taps(s, x);
    catmull_rom(p, f)
}

/// `x.floor()` as an integer, exactly, without the libm call (`x` finite,
/// |x| < 2⁶³): truncation toward zero, one less for negative non-integers.
#[inline(always)]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    t - i64::from((t as f64) > x)
}

/// Adds what an ear at `ear` hears of signal `s` (whose sample 0 is emitted
/// at output sample `start`) into `out`, scaled by `gain`.
pub(crate) fn add_heard(
    s: &[f32],
    start: usize,
    path: &Trajectory,
    ear: [f64; 3],
    sample_rate: f64,
    gain: f64,
    out: &mut [f32],
) {
    if s.is_empty() {
        return;
    }
    let params = |n: usize| heard_at(path, ear, n as f64 / sample_rate, sample_rate, gain);
    let mut n0 = start - start % BLOCK;
    let (mut g0, mut d0) = params(n0);
    while n0 < out.len() {
        let n1 = n0 + BLOCK;
        let (g1, d1) = params(n1);
        // Signal indices read in this block.
        let lo = n0 as f64 - d0.max(d1) - start as f64;
        if lo > s.len() as f64 + 2.0 {
            break;
        }
        let hi = n1 as f64 - d0.min(d1) - start as f64;
        if hi >= -2.0 {
            let end = n1.min(out.len());
            let block = Block { n0, start, delay: (d0, d1), gain: (g0, g1) };
            block.add(s, &mut out[n0..end]);
        }
        (n0, g0, d0) = (n1, g1, d1);
    }
}

/// Gain and delay [samples] of what an ear at `ear` hears at time `t` [s]:
/// `gain / r` and `r / c · fs` at the retarded distance `r` (module doc).
fn heard_at(path: &Trajectory, ear: [f64; 3], t: f64, sample_rate: f64, gain: f64) -> (f64, f64) {
    let mut r = distance(path.at(t), ear);
    for _ in 0..RETARDATION_STEPS {
        r = distance(path.at(t - r / SPEED_OF_SOUND_M_S), ear);
    }
    (gain / r.max(MIN_DISTANCE_M), r / SPEED_OF_SOUND_M_S * sample_rate)
}

/// One block of [`BLOCK`] output samples from `n0` on, with delay [samples]
/// and gain going linearly from the block's first value to the next block's.
struct Block {
    n0: usize,
    start: usize,
    delay: (f64, f64),
    gain: (f64, f64),
}

impl Block {
    /// Adds the block into `out` (at most [`BLOCK`] samples).
    fn add(&self, s: &[f32], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { self.add_avx2(s, out) };
        }
        self.add_lanes(s, out)
    }

    /// [`Block::add`] compiled for AVX2 (no FMA: every operation rounds as
    /// in the portable path, so the output is bit-identical).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn add_avx2(&self, s: &[f32], out: &mut [f32]) {
        self.add_lanes(s, out)
    }

    /// Three passes over the block — read positions and gains, the taps,
    /// then the interpolation — so the first and last vectorize.
    #[inline(always)]
    fn add_lanes(&self, s: &[f32], out: &mut [f32]) {
        let (d0, d1) = self.delay;
        let (g0, g1) = self.gain;
        let m = out.len().min(BLOCK);
        let (mut x, mut g) = ([0.0f64; BLOCK], [0.0f64; BLOCK]);
        for j in 0..m {
            let f = j as f64 / BLOCK as f64;
            let d = d0 + f * (d1 - d0);
            g[j] = g0 + f * (g1 - g0);
            x[j] = (self.n0 + j) as f64 - d - self.start as f64;
        }
        let (mut p, mut f) = ([[0.0f64; 4]; BLOCK], [0.0f64; BLOCK]);
        for j in 0..m {
            (p[j], f[j]) = taps(s, x[j]);
        }
        for j in 0..m {
            out[j] += (g[j] * catmull_rom(p[j], f[j])) as f32;
        }
    }
}

/// Where the listener hears: each ear, followed by its image in the ground
/// plane when `ground_reflection` is on (see [`crate::transfer`]).
pub(crate) fn listening_points(scene: &Scene) -> Vec<[f64; 3]> {
    let reflect = scene.ground.as_ref().filter(|_| scene.listener.ground_reflection);
    ears(scene)
        .into_iter()
        .flat_map(|ear| std::iter::once(ear).chain(reflect.map(|g| image(ear, g.height_m))))
        .collect()
}

/// Ear positions of the listener.
pub(crate) fn ears(scene: &Scene) -> Vec<[f64; 3]> {
    let l = &scene.listener;
    match l.channels {
        Channels::Mono => vec![l.position_m],
        Channels::Stereo => {
            let r = l.right;
            let n = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
            let h = 0.5 * l.ear_spacing_m / n;
            let p = l.position_m;
            vec![
                [p[0] - h * r[0], p[1] - h * r[1], p[2] - h * r[2]],
                [p[0] + h * r[0], p[1] + h * r[1], p[2] + h * r[2]],
            ]
        }
    }
}

pub(crate) fn mix(
    scene: &Scene,
    signals: &[(usize, &[Vec<f32>])],
    paths: &[Arc<Trajectory>],
    total: usize,
) -> Vec<Vec<f32>> {
    let fs = scene.sample_rate_hz as f64;
    let points = listening_points(scene);
    let per_ear = points.len() / ears(scene).len();
    (0..points.len() / per_ear)
        .into_par_iter()
        .map(|e| {
            let mut out = vec![0.0f32; total];
            for ((start, samples), path) in signals.iter().zip(paths) {
                for k in e * per_ear..(e + 1) * per_ear {
                    // A single signal is heard at every point; else each point has its own.
                    let s = if samples.len() == 1 { &samples[0] } else { &samples[k] };
                    add_heard(s, *start, path, points[k], fs, scene.listener.gain, &mut out);
                }
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn catmull_rom_reproduces_samples_and_cubics() {
        let s: Vec<f32> = (0..10).map(|k| (k as f32 * 0.5).powi(2)).collect();
        for k in 1..8 {
            assert_eq!(read(&s, k as f64), s[k] as f64);
        }
        // Exact for quadratics inside the support.
        let x: f64 = 4.3;
        assert!((read(&s, x) - (x * 0.5).powi(2)).abs() < 1e-5);
    }

    /// The definition [`read`] must reproduce, bit for bit.
    fn read_reference(s: &[f32], x: f64) -> f64 {
        let i = x.floor();
        let f = x - i;
        let i = i as i64;
        let at = |k: i64| if k >= 0 && (k as usize) < s.len() { s[k as usize] as f64 } else { 0.0 };
        let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
        p1 + 0.5 * f * (p2 - p0 + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0)))
    }

    #[test]
    fn read_equals_the_reference_inside_at_and_beyond_the_edges() {
        let s: Vec<f32> = (0..37).map(|k| ((k * 7919) % 101) as f32 / 50.0 - 1.0).collect();
        let mut x: f64 = -5.0;
        while x < 45.0 {
            for v in [x, -x, x.floor(), x.floor() - f64::EPSILON, f64::from_bits(x.to_bits() + 1)] {
                assert_eq!(read(&s, v).to_bits(), read_reference(&s, v).to_bits(), "x = {v}");
            }
            x += 0.0371;
        }
        for v in [-1e12, -2.5, -0.5, -0.0, 0.0, 1e-300, -1e-300, 35.0, 36.0, 36.5, 1e15] {
            assert_eq!(read(&s, v).to_bits(), read_reference(&s, v).to_bits(), "x = {v}");
        }
        assert_eq!(read(&[], 0.5), 0.0);
    }

    #[test]
    fn blocks_equal_the_per_sample_reference_for_a_moving_source() {
        // The plain per-sample loop the block passes must reproduce bit for bit.
        let (fs, gain, ear) = (48_000.0, 0.7, [0.3, 0.2, 1.0]);
        let path = Trajectory {
            dt: 0.001,
            positions: (0..40).map(|k| [0.02 * k as f32, 0.5 - 0.01 * k as f32, 0.0]).collect(),
            rotations: Vec::new(),
        };
        let s: Vec<f32> =
            (0..3000).map(|k| ((k as f32) * 0.05).sin() * (-(k as f32) / 900.0).exp()).collect();
        let start = 1234;
        let mut out = vec![0.0f32; 6000];
        add_heard(&s, start, &path, ear, fs, gain, &mut out);
        let mut expected = vec![0.0f32; 6000];
        let params = |n: usize| heard_at(&path, ear, n as f64 / fs, fs, gain);
        for (n, y) in expected.iter_mut().enumerate().skip(start - start % BLOCK) {
            let n0 = n - n % BLOCK;
            let ((g0, d0), (g1, d1)) = (params(n0), params(n0 + BLOCK));
            let f = (n - n0) as f64 / BLOCK as f64;
            let (d, g) = (d0 + f * (d1 - d0), g0 + f * (g1 - g0));
            *y += (g * read_reference(&s, n as f64 - d - start as f64)) as f32;
        }
        assert!(out.iter().any(|y| y.abs() > 1e-3));
        let bits = |v: &[f32]| v.iter().map(|y| y.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&out), bits(&expected));
    }

    #[test]
    fn a_receding_source_is_heard_at_the_moving_source_doppler_shift() {
        // A 1 kHz tone leaving the ear at 20 m/s: sound emitted at t' arrives
        // at t' + r(t')/c, so the ear hears f / (1 + v/c) = 944.88 Hz. The
        // distance at reception instead gives f (1 − v/c) = 941.69 Hz.
        let (fs, f, v) = (48_000.0, 1000.0, 20.0);
        let path = Trajectory {
            dt: 1e-3,
            positions: (0..2000).map(|k| [(1.0 + v * 1e-3 * k as f64) as f32, 0.0, 0.0]).collect(),
            rotations: Vec::new(),
        };
        let s: Vec<f32> = (0..96_000).map(|n| (2.0 * PI * f * n as f64 / fs).sin() as f32).collect();
        let mut out = vec![0.0f32; 96_000];
        add_heard(&s, 0, &path, [0.0; 3], fs, 1.0, &mut out);
        // Upward zero crossings between 0.5 s and 1.5 s, interpolated.
        let crossings: Vec<f64> = (24_000..72_000)
            .filter(|&n| out[n] <= 0.0 && out[n + 1] > 0.0)
            .map(|n| n as f64 + out[n] as f64 / (out[n] as f64 - out[n + 1] as f64))
            .collect();
        let periods = (crossings.len() - 1) as f64;
        let heard = periods * fs / (crossings[crossings.len() - 1] - crossings[0]);
        let expected = f / (1.0 + v / SPEED_OF_SOUND_M_S);
        assert!((heard / expected - 1.0).abs() < 2e-5, "heard {heard} Hz, expected {expected} Hz");
    }

    #[test]
    fn static_source_is_delayed_and_attenuated() {
        let fs = 48_000.0;
        let mut s = vec![0.0f32; 100];
        s[0] = 1.0;
        let path = Trajectory { dt: 0.01, positions: vec![[0.0, 0.0, 0.0]; 3], rotations: Vec::new() };
        let ear = [3.43, 0.0, 0.0]; // 10 ms, 480 samples
        let mut out = vec![0.0f32; 2000];
        add_heard(&s, 100, &path, ear, fs, 1.0, &mut out);
        let peak = out.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map(|(i, _)| i);
        assert_eq!(peak, Some(580));
        assert!((out[580] as f64 - 1.0 / 3.43).abs() < 1e-6);
    }
}
