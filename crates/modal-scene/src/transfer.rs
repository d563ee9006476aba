//! Per-mode acoustic transfer from a moving, rotating body to an ear.
//!
//! A bank's radiation table (`modal_bank::RadiationTable`, written by
//! `modal radiation --store` or solved on demand by the provider) gives, for
//! mode `i` vibrating with unit modal velocity amplitude, the pressure at a
//! point `x` of the bank's frame (convention `e^{−iωt}`, centre `c`,
//! `r = |x − c|`, `x̂ = (x − c)/r`):
//!
//! `P_i(x) = Σ_{l ≤ L_i} Σ_m a_lm h_l(k_i r) Y_l^m(x̂)`.
//!
//! **What the transfer replaces.** The listener ([`crate::listener`])
//! already applies, per object and ear, the propagation delay `r/c` and the
//! spreading `1/max(r, r_min)`. Those are the factor `e^{ikr}/r` of every
//! outgoing wave, so the per-mode voice weight is the *reduced* transfer
//!
//! `D_i(x̂, r) = r e^{−ik_i r} P_i(x) = (1/k_i) Σ_l η_l(k_i r) Σ_m a_lm Y_l^m(x̂)` [Pa·m],
//!
//! `η_l(x) = x e^{−ix} h_l(x)`: `η_0 = −i`, `η_1 = −1 − i/x`,
//! `η_{l+1} = (2l+1)/x · η_l − η_{l−1}` (no exponential; `η_l → (−i)^{l+1}`
//! far away, where `D_i` is the far-field pattern). It replaces the old
//! direction-free level estimate (a pulsating sphere of the object's area,
//! `render`'s module doc) and nothing else: the delay and `1/r` stay where
//! they were, so nothing is counted twice. `D_i` is evaluated at
//! `r_eval = max(r, fit_radius)`, the radius beyond which the table is
//! accurate (closer ears get the field at the fit sphere, then `1/r`).
//!
//! **In the synthesizer** (convention `e^{+iωt}`, modal velocity
//! `q̇_i = Re(−i s_i z_i)`), the heard pressure of mode `i` at emission time
//! `t` is `Re(conj(D_i) (−i s_i) z_i)`, then delayed by `r/c` and divided
//! by `r` in the mix. The voice's real gain is the direction-averaged level
//! `g_i = √(Σ_lm |a_lm|² / 4π) / k_i` (the RMS of the far-field `|D_i|` over
//! all directions; culling and silence decisions use it), and its
//! modulation ([`modal_synth::modulation`]) is `m_i(t) = conj(D_i(t)) / g_i`,
//! evaluated every synthesizer block (256 samples) from the body's pose at
//! that emission time: the direction `x̂` is the ear seen in the body's own
//! rotating frame, `R(t)ᵀ (ear − p(t))`, so rotating and moving bodies
//! change timbre. Modes without a table entry keep the estimate as `g_i`
//! and `m_i = 1`. Torsional-like modes with `a_lm = 0` are silent.
//!
//! **Ground reflection** (`[listener] ground_reflection = true`): a rigid
//! plane `y = height` adds one image path per ear, the ear mirrored in the
//! plane, `ear' = (x, 2h − y, z)`: `p = p_free(ear) + p_free(ear')`
//! (reflection coefficient +1), each path with its own delay, `1/r` and
//! direction.

use std::sync::{Arc, Mutex};

use modal_bank::{ModeBank, RadiationTable};
use modal_radiation::special::Harmonics;
use modal_synth::{OutputModulation, C64};

use crate::listener::Trajectory;
use crate::render::{equivalent_radius, SharedModel, AIR_IMPEDANCE_PA_S_M};
use crate::{BankProvider, SceneError};

/// One mode's stored expansion, ready for evaluation.
#[derive(Clone, Debug)]
struct ModeExpansion {
    /// Wavenumber [1/m].
    k: f64,
    /// Highest degree.
    order: usize,
    /// `a_lm / (k g)` at `l² + l + m` (so the sum is `m_i` directly, conjugated).
    scaled: Vec<C64>,
}

/// The transfer of every mode of one bank (shared by its instances).
#[derive(Clone, Debug)]
pub(crate) struct BankTransfer {
    /// Expansion centre minus the bank's centre of mass (bank frame) [m].
    centre_offset: [f64; 3],
    /// Radius beyond which the expansions are accurate [m].
    fit_radius: f64,
    modes: Vec<Option<ModeExpansion>>,
    /// Spherical harmonics up to the highest expansion order.
    harmonics: Harmonics,
    /// Per mode: the voice's real gain `g_i` [Pa·m per m/s of modal velocity].
    pub gains: Vec<f64>,
    /// Modes with a table entry.
    pub with_transfer: usize,
    /// Per mode with a table entry: the estimate's level and the transfer's
    /// direction-averaged level [Pa·m per m/s].
    pub levels: Vec<ModeLevel>,
}

/// One mode's level at 1 m by the estimate and by its transfer (the RMS
/// over directions of the far field), per unit modal velocity.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ModeLevel {
    /// Mode index in the bank.
    pub mode: usize,
    /// Undamped frequency [Hz].
    pub frequency_hz: f64,
    /// The pulsating-sphere estimate [Pa·m per m/s].
    pub estimate_pa_m: f64,
    /// The transfer, RMS over directions [Pa·m per m/s].
    pub transfer_pa_m: f64,
}

impl BankTransfer {
    /// From a bank's table; modes the table lacks keep `estimate[i]`.
    pub fn new(bank: &ModeBank, table: &RadiationTable, estimate: &[f64]) -> BankTransfer {
        let n = bank.mode_count();
        let mut modes = vec![None; n];
        let mut gains = estimate.to_vec();
        let mut with_transfer = 0;
        let mut levels = Vec::new();
        for entry in &table.modes {
            if entry.mode >= n {
                continue;
            }
            let k = entry.wavenumber;
            let g = modal_radiation::modes::stored_multipole(table, entry).far_field_rms();
            gains[entry.mode] = g;
            with_transfer += 1;
            levels.push(ModeLevel {
                mode: entry.mode,
                frequency_hz: bank.frequencies_hz[entry.mode],
                estimate_pa_m: estimate.get(entry.mode).copied().unwrap_or(0.0),
                transfer_pa_m: if g.is_finite() { g } else { 0.0 },
            });
            if !(g > 0.0 && g.is_finite()) {
                // Radiates nothing: silent whatever the direction.
                gains[entry.mode] = 0.0;
                continue;
            }
            let scaled =
                entry.coefficients.iter().map(|c| C64::new(c[0], c[1]).scale(1.0 / (k * g))).collect();
            modes[entry.mode] = Some(ModeExpansion { k, order: entry.order, scaled });
        }
        let com = bank.mass.center_of_mass_m;
        let top = modes.iter().flatten().map(|m| m.order).max().unwrap_or(0);
        BankTransfer {
            centre_offset: [0, 1, 2].map(|q| table.centre_m[q] - com[q]),
            fit_radius: table.fit_radius_m,
            modes,
            harmonics: Harmonics::new(top),
            gains,
            with_transfer,
            levels,
        }
    }

    /// `m_i = conj(D_i)/g_i` for `modes` at body-frame offset `d` from the
    /// centre of mass (the ear relative to the body, in the body's frame).
    pub fn factors(&self, d: [f64; 3], modes: &[usize], out: &mut [C64]) {
        let x = [0, 1, 2].map(|q| d[q] - self.centre_offset[q]);
        let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        let order = modes.iter().filter_map(|&i| self.modes[i].as_ref().map(|m| m.order)).max();
        let Some(order) = order.filter(|_| r > 0.0) else {
            out.iter_mut().zip(modes).for_each(|(o, &i)| *o = self.fallback(i));
            return;
        };
        let mut y = vec![modal_radiation::c64::new(0.0, 0.0); (order + 1) * (order + 1)];
        self.harmonics.evaluate_to(order, x, &mut y);
        let r_eval = r.max(self.fit_radius);
        let mut eta = Vec::with_capacity(order + 1);
        for (o, &i) in out.iter_mut().zip(modes) {
            let Some(m) = &self.modes[i] else {
                *o = self.fallback(i);
                continue;
            };
            reduced_hankel(m.order, m.k * r_eval, &mut eta);
            let mut sum = C64::ZERO;
            for (l, e) in eta.iter().enumerate() {
                let mut part = C64::ZERO;
                let range = l * l..(l + 1) * (l + 1);
                for (a, yj) in m.scaled[range.clone()].iter().zip(&y[range]) {
                    part += *a * C64::new(yj.re, yj.im);
                }
                sum += *e * part;
            }
            *o = C64::new(sum.re, -sum.im);
        }
    }

    /// The constant phases of a voice that hears this transfer: 1 for modes
    /// with a table entry (their phase is in the modulation), and
    /// `direction_free[i]` ([`modal_synth::degenerate_phases`]) for modes
    /// heard through the estimate.
    pub fn voice_phases(&self, direction_free: &[C64]) -> Vec<C64> {
        self.modes
            .iter()
            .zip(direction_free)
            .map(|(m, &p)| if m.is_some() { C64::new(1.0, 0.0) } else { p })
            .collect()
    }

    fn fallback(&self, i: usize) -> C64 {
        C64::new(if self.modes[i].is_some() { 0.0 } else { 1.0 }, 0.0)
    }
}

/// `η_l(x) = x e^{−ix} h_l(x)` for `l = 0..=order` (module doc).
pub(crate) fn reduced_hankel(order: usize, x: f64, out: &mut Vec<C64>) {
    out.clear();
    out.push(C64::new(0.0, -1.0));
    if order >= 1 {
        out.push(C64::new(-1.0, -1.0 / x));
    }
    for l in 1..order {
        let next = out[l].scale((2 * l + 1) as f64 / x) - out[l - 1];
        out.push(next);
    }
}

/// What one path (an ear, or its ground image) hears of one object: the
/// voice modulation of [`BankTransfer`] along the object's trajectory.
pub(crate) struct EarTransfer {
    pub transfer: Arc<BankTransfer>,
    pub path: Arc<Trajectory>,
    pub ear: [f64; 3],
    /// The body-frame offset of the last evaluation and its factors for
    /// every mode evaluated there (NaN: not yet).
    cache: Mutex<(Option<[f64; 3]>, Vec<C64>)>,
}

impl EarTransfer {
    pub fn new(transfer: Arc<BankTransfer>, path: Arc<Trajectory>, ear: [f64; 3]) -> EarTransfer {
        let n = transfer.gains.len();
        EarTransfer { transfer, path, ear, cache: Mutex::new((None, vec![C64::new(f64::NAN, 0.0); n])) }
    }
}

impl OutputModulation for EarTransfer {
    fn factors(&self, time_s: f64, modes: &[usize], out: &mut [C64]) {
        let d = self.path.to_body_at(time_s, self.ear);
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        let (at, values) = &mut *cache;
        if *at != Some(d) {
            // A new pose: forget every cached factor.
            values.iter_mut().for_each(|v| *v = C64::new(f64::NAN, 0.0));
            *at = Some(d);
        }
        let missing: Vec<usize> = modes.iter().copied().filter(|&i| values[i].re.is_nan()).collect();
        if !missing.is_empty() {
            let mut found = vec![C64::ZERO; missing.len()];
            self.transfer.factors(d, &missing, &mut found);
            for (&i, v) in missing.iter().zip(found) {
                values[i] = v;
            }
        }
        for (o, &i) in out.iter_mut().zip(modes) {
            *o = values[i];
        }
    }
}

/// The ear mirrored in the ground plane `y = height`.
pub(crate) fn image(ear: [f64; 3], height: f64) -> [f64; 3] {
    [ear[0], 2.0 * height - ear[1], ear[2]]
}

/// Per object, the acoustic transfer of its bank (built once per distinct
/// asset from the provider's table), `None` where the provider has none or
/// the object is never struck.
pub(crate) fn object_transfers(
    provider: &mut dyn BankProvider,
    requests: &[crate::BankRequest],
    asset_of: &[usize],
    banks: &[Arc<ModeBank>],
    per_object: &[Option<SharedModel>],
) -> Result<Vec<Option<Arc<BankTransfer>>>, SceneError> {
    let mut per_asset: Vec<Option<Option<Arc<BankTransfer>>>> = vec![None; requests.len()];
    let mut out = Vec::with_capacity(banks.len());
    for (i, bank) in banks.iter().enumerate() {
        let Some((_, gains)) = &per_object[i] else {
            out.push(None);
            continue;
        };
        let a = asset_of[i];
        if per_asset[a].is_none() {
            let table = provider
                .radiation(&requests[a], bank)
                .map_err(|source| SceneError::Bank { path: format!("objects[{i}]"), source })?;
            let scale = AIR_IMPEDANCE_PA_S_M * equivalent_radius(bank);
            let estimate: Vec<f64> = gains.iter().map(|g| g * scale).collect();
            per_asset[a] = Some(table.map(|t| Arc::new(BankTransfer::new(bank, &t, &estimate))));
        }
        out.push(per_asset[a].clone().flatten());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use modal_radiation::special::spherical_hankel;

    #[test]
    fn reduced_hankel_is_x_exp_minus_ix_h() {
        for x in [0.05, 0.7, 3.0, 25.0] {
            let h = spherical_hankel(8, x);
            let mut eta = Vec::new();
            reduced_hankel(8, x, &mut eta);
            let e = C64::new(0.0, -x).exp().scale(x);
            for l in 0..=8 {
                let want = e * C64::new(h[l].re, h[l].im);
                assert!((eta[l] - want).abs() <= 1e-10 * want.abs(), "l = {l}, x = {x}");
            }
        }
        // Far field: (−i)^{l+1}.
        let mut eta = Vec::new();
        reduced_hankel(3, 1e7, &mut eta);
        let want = [C64::new(0.0, -1.0), C64::new(-1.0, 0.0), C64::new(0.0, 1.0), C64::new(1.0, 0.0)];
        for (a, b) in eta.iter().zip(want) {
            assert!((*a - b).abs() < 1e-5);
        }
    }

    /// A one-mode bank (on a small box) with the given table entries.
    fn bank_with(coefficients: Vec<[f64; 2]>, order: usize, k: f64) -> (ModeBank, RadiationTable) {
        let mut bank = stand_in_bank();
        bank.frequencies_hz = vec![k * crate::SPEED_OF_SOUND_M_S / (2.0 * std::f64::consts::PI)];
        bank.decay_rates = vec![2.0];
        bank.damping_ratios = vec![2.0 / (2.0 * std::f64::consts::PI * bank.frequencies_hz[0])];
        bank.residuals = vec![0.0];
        let nodes = bank.surface.positions.len();
        bank.shapes = (0..3 * nodes).map(|j| if j % 3 == 1 { 1.0 } else { 0.0 }).collect();
        let table = RadiationTable {
            centre_m: bank.mass.center_of_mass_m,
            fit_radius_m: 0.1,
            air_density_kg_m3: 1.21,
            sound_speed_m_s: 343.0,
            tolerance: 0.01,
            modes: vec![modal_bank::ModeTransfer {
                mode: 0,
                wavenumber: k,
                order,
                coefficients,
                power_w: 1.0,
                efficiency: 1.0,
            }],
        };
        (bank, table)
    }

    fn stand_in_bank() -> ModeBank {
        let mesh = modal_mesh::generate::box_mesh([0.04, 0.03, 0.02], [2, 2, 2]);
        let steel = modal_fem::Material::preset("steel").expect("steel");
        crate::stand_in::synthetic_bank(&mesh, steel, &[1000.0])
    }

    #[test]
    fn factors_are_the_conjugated_reduced_stored_expansion() {
        // Random coefficients up to degree 4: compare with the expansion
        // evaluated by modal-radiation at points around the centre.
        let order = 4;
        let coefficients: Vec<[f64; 2]> = (0..25)
            .map(|j| [((j * 37 % 11) as f64 - 5.0) / 5.0, ((j * 17 % 7) as f64 - 3.0) / 4.0])
            .collect();
        let k = 2.0 * std::f64::consts::PI * 1500.0 / 343.0;
        let (bank, table) = bank_with(coefficients, order, k);
        let t = BankTransfer::new(&bank, &table, &[0.0]);
        let mp = modal_radiation::modes::stored_multipole(&table, &table.modes[0]);
        let g = t.gains[0];
        assert!(g > 0.0);
        for d in [[0.3, 0.1, -0.2], [0.0, 0.0, 0.5], [-1.0, 2.0, 0.5], [0.05, 0.1, 0.0]] {
            let x = [0, 1, 2].map(|q| table.centre_m[q] + d[q]);
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let r_eval = r.max(table.fit_radius_m);
            let x_eval = [0, 1, 2].map(|q| table.centre_m[q] + d[q] * r_eval / r);
            let p = mp.pressure_at(x_eval);
            let want = C64::new(p.re, p.im) * C64::new(0.0, -k * r_eval).exp().scale(r_eval / g);
            let want = C64::new(want.re, -want.im);
            let mut got = [C64::ZERO];
            // The body-frame offset is from the centre of mass (= centre here).
            let from_com = [0, 1, 2].map(|q| x[q] - bank.mass.center_of_mass_m[q]);
            t.factors(from_com, &[0], &mut got);
            assert!((got[0] - want).abs() < 1e-9 * want.abs(), "{d:?}: {:?} vs {want:?}", got[0]);
        }
        // The direction-averaged gain is the RMS of the far-field |D|.
        let sum2: f64 = table.modes[0].coefficients.iter().map(|c| c[0] * c[0] + c[1] * c[1]).sum();
        assert!((g - (sum2 / (4.0 * std::f64::consts::PI)).sqrt() / k).abs() < 1e-12 * g);
    }

    #[test]
    fn a_spinning_dipole_is_heard_with_its_cosine_directivity() {
        use modal_synth::{ModalVoice, OutputGain, SynthModel, SynthOptions};
        // A pure dipole along the body's z axis (a_10 only): |D| ∝ |cos θ|.
        let k = 2.0 * std::f64::consts::PI * 1000.0 / 343.0;
        let mut coefficients = vec![[0.0; 2]; 4];
        coefficients[2] = [0.0, 0.3];
        let (bank, table) = bank_with(coefficients, 1, k);
        let bank = Arc::new(bank);
        let t = Arc::new(BankTransfer::new(&bank, &table, &[0.0]));
        // The body spins about the world y axis at Ω: its z axis points at
        // (sin Ωt, 0, cos Ωt); the ear is on the world z axis, 1 m away.
        let (dt, spin, seconds) = (1e-3, std::f64::consts::PI / 2.0, 1.0); // 90° per second
        let steps = (seconds / dt) as usize + 1;
        let com = [0.0f32, 0.5, 0.0];
        let rotations = (0..steps)
            .map(|s| {
                let a = spin * s as f64 * dt;
                let (sn, c) = (a.sin() as f32, a.cos() as f32);
                // Body-from-world: rows are the body axes in world coordinates.
                [[c, 0.0, -sn], [0.0, 1.0, 0.0], [sn, 0.0, c]]
            })
            .collect();
        let path = Arc::new(Trajectory { dt, positions: vec![com; steps], rotations });
        let ear = [0.0, 0.5, 1.0];
        let fs = 48_000.0;
        let opts = SynthOptions {
            sample_rate: fs,
            gain: OutputGain::PerMode(t.gains.clone()),
            cull_db: None,
            parallel: false,
            ..SynthOptions::default()
        };
        let model = Arc::new(SynthModel::shared(Arc::clone(&bank)).expect("model"));
        let mut voice = ModalVoice::from_model(model, opts).expect("voice");
        voice.set_modulation(Arc::new(EarTransfer::new(Arc::clone(&t), path, ear)));
        voice.add_impulse(0.0, bank.surface.positions[0], [0.0, 1.0, 0.0], 0.0).expect("strike");
        let mut y = vec![0.0f32; (seconds * fs) as usize];
        voice.render(&mut y, 0);
        // Envelope: the peak over one period (48 samples), undone of the decay.
        let d = bank.decay_rates[0];
        let level = |t_s: f64| {
            let n = (t_s * fs) as usize;
            let peak = y[n - 24..n + 24].iter().fold(0.0f32, |m, v| m.max(v.abs())) as f64;
            peak * (d * t_s).exp()
        };
        let reference = level(0.02) / (spin * 0.02).cos();
        for deg in [20.0f64, 45.0, 60.0, 75.0] {
            let t_s = deg / 90.0;
            let want = deg.to_radians().cos();
            let got = level(t_s) / reference;
            let db = 20.0 * (got / want).log10();
            assert!(db.abs() < 0.1, "{deg}°: {got} vs cos = {want} ({db:.3} dB)");
        }
        // 90° apart: the null of the dipole (the geometric ramp leaves
        // ≈ Ω·block/2 of the level near a zero crossing).
        let null = level(0.999) / reference;
        assert!(null < 0.02, "null at 90°: {null}");
    }

    #[test]
    fn image_mirrors_in_the_plane() {
        assert_eq!(image([0.3, 0.5, -1.0], 0.1), [0.3, -0.3, -1.0]);
    }
}
