//! Time-varying complex output weights: `y(t) = Σ_i Re(m_i(t) W_i z_i(t))`.
//!
//! A [`crate::ModalVoice`] given an [`OutputModulation`] multiplies mode `i`'s
//! output weight `W_i` (velocity or displacement times its real gain `g_i`,
//! see `voice`) by a complex factor `m_i(t)`: the acoustic transfer of a
//! moving, rotating body to an ear divided by its direction-averaged level,
//! for example. The factor is evaluated at block edges `n₀ < n₁` (a load at
//! `n₀` — a grid point, an event or a jump — and the next grid point
//! `n₁`, a multiple of [`crate::BLOCK`]) and follows, in between, the complex
//! geometric path
//!
//! `m(n) = m(n₀) ρⁿ⁻ⁿ⁰`, `ρ = (m(n₁)/m(n₀))^{1/(n₁−n₀)}` (principal branch),
//!
//! i.e. the modulus is interpolated log-linearly and the phase linearly, and
//! both edges are hit exactly. Since `m(n) u(n)` with `u(n+1) = p u(n)` is
//! again a one-pole sequence, with pole `ρ p`, the kernel is unchanged: the
//! voice loads `m(n₀) u(n₀)` and the pole `ρ p` (one complex `ln`/`exp`
//! per active mode and block, and one evaluation of the factors per block:
//! the end of a block is the start of the next).
//!
//! Factors whose modulus is below [`MIN_FACTOR`] are raised to it (phase
//! kept, or real for an exact zero) so the logarithm stays finite: −120 dB
//! relative to the mode's weight `W_i`. Phase changes of more than π within
//! one block (5 ms at 48 kHz) are taken modulo 2π.

use std::sync::Arc;

use crate::complex::C64;
use crate::voice::BLOCK;

/// Smallest modulus of a factor `m_i` (smaller ones are raised to it).
pub const MIN_FACTOR: f64 = 1e-6;

/// Complex per-mode factors on a voice's output weights, as a function of
/// time (see the module doc).
pub trait OutputModulation: Send + Sync {
    /// Writes into `out[k]` the factor `m_i(t)` of bank mode `i = modes[k]`
    /// at time `time_s` [s] (the voice's sample `n` is at `n / fs`).
    /// `modes` is ascending; `out.len() == modes.len()`. Must be
    /// deterministic.
    fn factors(&self, time_s: f64, modes: &[usize], out: &mut [C64]);
}

/// A voice's modulation: the source and the factors at the end of the
/// block last loaded.
#[derive(Clone)]
pub(crate) struct Modulation {
    source: Arc<dyn OutputModulation>,
    /// Sample of `values` (the grid point ending the block last loaded).
    at: Option<u64>,
    /// Modes of `values`, ascending.
    idx: Vec<usize>,
    values: Vec<C64>,
    start: Vec<C64>,
    missing: Vec<usize>,
    slots: Vec<usize>,
    found: Vec<C64>,
}

impl std::fmt::Debug for Modulation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Modulation").field("at", &self.at).field("modes", &self.idx.len()).finish()
    }
}

impl Modulation {
    pub(crate) fn new(source: Arc<dyn OutputModulation>) -> Modulation {
        Modulation {
            source,
            at: None,
            idx: Vec::new(),
            values: Vec::new(),
            start: Vec::new(),
            missing: Vec::new(),
            slots: Vec::new(),
            found: Vec::new(),
        }
    }

    /// For the modes `idx` (ascending) loaded at sample `pos`: writes
    /// `(m(pos), ρ)` per mode into `out` (module doc).
    pub(crate) fn ramp(&mut self, pos: u64, fs: f64, idx: &[usize], out: &mut Vec<(C64, C64)>) {
        let b = BLOCK as u64;
        let end = (pos / b + 1) * b;
        // m(pos): from the previous block's end where it covers the mode.
        self.start.clear();
        self.start.resize(idx.len(), C64::ZERO);
        self.missing.clear();
        self.slots.clear();
        let cached = self.at == Some(pos);
        for (k, &i) in idx.iter().enumerate() {
            match self.idx.binary_search(&i) {
                Ok(j) if cached => self.start[k] = self.values[j],
                _ => {
                    self.missing.push(i);
                    self.slots.push(k);
                }
            }
        }
        if !self.missing.is_empty() {
            self.found.clear();
            self.found.resize(self.missing.len(), C64::ZERO);
            self.source.factors(pos as f64 / fs, &self.missing, &mut self.found);
            for (&k, &v) in self.slots.iter().zip(&self.found) {
                self.start[k] = v;
            }
        }
        // m(end), kept for the next load.
        self.values.clear();
        self.values.resize(idx.len(), C64::ZERO);
        self.source.factors(end as f64 / fs, idx, &mut self.values);
        self.idx.clear();
        self.idx.extend_from_slice(idx);
        self.at = Some(end);
        let len = (end - pos) as f64;
        out.clear();
        out.extend(self.start.iter().zip(&self.values).map(|(&a, &b)| {
            let (a, b) = (floor(a), floor(b));
            (a, ratio_root(b.quot(a), len))
        }));
    }
}

/// `z` with its modulus raised to [`MIN_FACTOR`] (phase kept; real when
/// `z` is zero or not finite).
fn floor(z: C64) -> C64 {
    let r = z.abs();
    if !r.is_finite() || r == 0.0 {
        return C64::new(MIN_FACTOR, 0.0);
    }
    if r < MIN_FACTOR {
        z.scale(MIN_FACTOR / r)
    } else {
        z
    }
}

/// `q^{1/len}` on the principal branch.
fn ratio_root(q: C64, len: f64) -> C64 {
    let ln_abs = 0.5 * q.norm2().ln();
    let arg = q.im.atan2(q.re);
    C64::new(ln_abs / len, arg / len).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_root_composes_back_to_the_ratio() {
        for q in [C64::new(2.0, 0.0), C64::new(-1.0, 0.5), C64::new(0.3, -0.9), C64::new(1.0, 1e-12)] {
            let r = ratio_root(q, 37.0);
            let mut p = C64::new(1.0, 0.0);
            for _ in 0..37 {
                p = p * r;
            }
            assert!((p - q).abs() < 1e-12 * q.abs(), "{q:?} -> {p:?}");
        }
    }

    #[test]
    fn floor_keeps_phase_and_raises_tiny_factors() {
        assert_eq!(floor(C64::ZERO), C64::new(MIN_FACTOR, 0.0));
        let z = floor(C64::new(0.0, -1e-9));
        assert!((z.im + MIN_FACTOR).abs() < 1e-18 && z.re == 0.0);
        assert_eq!(floor(C64::new(0.5, 0.5)), C64::new(0.5, 0.5));
    }
}
