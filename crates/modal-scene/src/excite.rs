//! Contacts → impacts: which part of a contact's impulse strikes the modes,
//! when, and for how long.
//!
//! **Rule against buzzing (excite with the rise of the contact impulse).**
//! Per collider pair, let `J_k` be the total normal impulse of step `k`. A
//! sustained contact carries a slowly varying force (a body at rest: `J_k ≈
//! m g dt` every step); its spectrum sits far below the audible modes, so it
//! must not strike them. Only the *rise* `ΔJ_k = J_k − J_{k−1}` (with
//! `J_{k−1} = 0` when the pair did not touch in the previous step) excites,
//! and only when it exceeds [`SUSTAIN_DEADBAND`] × `J_{k−1}` (solver jitter of
//! a resting contact) and [`MIN_IMPULSE_NS`], and only when the contact
//! closes fast enough: [`MIN_APPROACH_M_S`] for a new contact,
//! [`MIN_APPROACH_CONTINUING_M_S`] for a rise on a contact that already
//! touched (within [`RECONTACT_WINDOW_S`]). The contact point of a resting, rolling or rocking body has no
//! normal approach speed, whereas an impact (also a second corner landing
//! while the first still touches, at ~1 m/s) has. The faceted convex hull of
//! a curved body (a bowl) rocks across facet edges at up to ~0.1 m/s; the
//! continuing-contact threshold treats that as the rolling it stands for. The rise is shared among the
//! pair's points in proportion to their impulse: point `i` with impulse
//! vector `p_i` (normal + friction) strikes with `(ΔJ_k / J_k) · p_i`. A new
//! impact therefore sounds with its full impulse, a resting or rolling
//! contact sounds nothing, and a contact that is pressed harder sounds with
//! the increase only. Steady sliding friction (scraping) is not modelled.
//!
//! **Bodies set on each other** (a stack at rest, a block on a table) touch
//! from the start: their pair's first touch is a continuing contact (as if
//! it touched at t = 0, so within [`RECONTACT_WINDOW_S`]), not a new one.
//! The solver's settling under the stack's load closes such a pair at a few
//! cm/s (a tower of five 5 cm wooden blocks at 0.056 m/s after 6 ms, a
//! click); a new contact strikes from [`MIN_APPROACH_M_S`], a continuing one
//! only from [`MIN_APPROACH_CONTINUING_M_S`].
//!
//! **Onset time.** For a pair that was not touching, the contact begins
//! within the step at `t_k + clamp(s / v_n, 0, dt)`, with `s` the separation
//! at the start of the step and `v_n` the normal approach speed (velocities
//! at the start of the step advanced by half a step of gravity). A rise on a
//! continuing contact is placed mid-step.
//!
//! **Contact time (Hertz, sphere on sphere).** `1/R = 1/R₁ + 1/R₂`,
//! `1/m = 1/m₁ + 1/m₂`, `1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`,
//! `τ = 2.8683 (m² / (R E*² v))^{1/5}`, clamped to
//! [[`MIN_CONTACT_TIME_S`], [`MAX_CONTACT_TIME_S`]]; a fixed body or the
//! ground has infinite mass, the ground infinite radius.

use std::collections::HashMap;

use serde::Serialize;

use crate::physics::{ContactSide, PairContacts};

/// A rise below this fraction of the previous step's impulse is jitter of a
/// sustained contact, not an impact.
pub const SUSTAIN_DEADBAND: f64 = 0.25;
/// New contacts closing slower than this never strike [m/s].
pub const MIN_APPROACH_M_S: f64 = 0.05;
/// A rise on a contact that already touched strikes only when some point
/// closes at least this fast [m/s] (a second corner landing does; a body
/// rocking across the facets of its hull does not).
pub const MIN_APPROACH_CONTINUING_M_S: f64 = 0.25;
/// A pair that touched within this time counts as a continuing contact [s]
/// (a hull rocking across facets loses contact for a step or two).
pub const RECONTACT_WINDOW_S: f64 = 0.02;
/// Rises below this impulse are ignored [N·s].
pub const MIN_IMPULSE_NS: f64 = 1e-9;
/// Shortest contact time [s].
pub const MIN_CONTACT_TIME_S: f64 = 1e-5;
/// Longest contact time [s] (also the value for a vanishing approach speed).
pub const MAX_CONTACT_TIME_S: f64 = 5e-3;

/// One strike of one object's modes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Strike {
    /// Time of the impact [s] from the start of the scene.
    pub time_s: f64,
    /// Point in the object's mesh frame [m].
    pub point_m: [f64; 3],
    /// Impulse on the object, mesh frame [N·s].
    pub impulse_ns: [f64; 3],
    /// Contact time τ [s].
    pub contact_time_s: f64,
}

/// One impact between two bodies, as written to the events file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImpactEvent {
    /// Time of the impact [s].
    pub time_s: f64,
    /// Names of the two bodies (`"ground"` for the floor).
    pub bodies: [String; 2],
    /// Contact point, world frame [m].
    pub point_m: [f64; 3],
    /// Impulse on the first body, world frame [N·s] (the second gets the opposite).
    pub impulse_ns: [f64; 3],
    /// Normal approach speed [m/s].
    pub approach_speed_m_s: f64,
    /// Hertz contact time τ [s].
    pub contact_time_s: f64,
}

/// Hertz contact time of two sides at approach speed `v` [m/s], clamped.
pub fn hertz_contact_time(a: &ContactSide, b: &ContactSide, v: f64) -> f64 {
    let inv = |x: f64| if x.is_finite() { 1.0 / x } else { 0.0 };
    let m = 1.0 / (inv(a.mass_kg) + inv(b.mass_kg));
    let r = 1.0 / (inv(a.radius_m) + inv(b.radius_m));
    let e = 1.0 / (1.0 / a.plane_strain_pa + 1.0 / b.plane_strain_pa);
    if !(m.is_finite() && r.is_finite() && v > 0.0) {
        return MAX_CONTACT_TIME_S;
    }
    let tau = 2.8683 * (m * m / (r * e * e * v)).powf(0.2);
    tau.clamp(MIN_CONTACT_TIME_S, MAX_CONTACT_TIME_S)
}

/// Turns per-step contacts into strikes, remembering each pair's last impulse.
#[derive(Default)]
pub(crate) struct Exciter {
    /// Per pair: total normal impulse of the previous step.
    previous: HashMap<(u32, u32), f64>,
    current: HashMap<(u32, u32), f64>,
    /// Per pair: start time of the last step it touched in [s].
    last_touch: HashMap<(u32, u32), f64>,
    /// Object pairs set on each other at the start (module doc), as
    /// (lower index, higher index); each is dropped at its first touch.
    placed: Vec<(usize, usize)>,
}

/// What one step saw.
#[derive(Clone, Copy)]
pub(crate) struct StepInput<'a> {
    /// Start time of the step [s].
    pub t0: f64,
    /// Step length [s].
    pub dt: f64,
    /// Contacts after the step.
    pub pairs: &'a [PairContacts],
    /// Contact sides (objects, then the ground).
    pub sides: &'a [ContactSide],
    /// Object names.
    pub names: &'a [String],
    /// Rotates a world vector into an object's mesh frame.
    pub to_body: &'a dyn Fn(usize, [f64; 3]) -> [f64; 3],
}

/// What one step produced.
pub(crate) struct StepStrikes<'a> {
    /// Per object: strikes to add.
    pub strikes: &'a mut [Vec<Strike>],
    /// Per object: number of impacts (pair events) it took part in.
    pub impacts: &'a mut [usize],
    /// Events for the JSON output, if collected.
    pub events: Option<&'a mut Vec<ImpactEvent>>,
    /// Impacts between pairs (incremented once per pair excitation).
    pub pair_impacts: &'a mut usize,
}

impl Exciter {
    /// An exciter for a scene whose objects `placed` (pairs of object
    /// indices) were set on each other: they touch from the start.
    pub fn with_placed(placed: &[(usize, usize)]) -> Exciter {
        let placed = placed.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
        Exciter { placed, ..Exciter::default() }
    }

    /// Whether the collider pair `pair` first touches as objects set on each
    /// other (then forgotten: a later touch after a parting is new).
    fn first_touch_of_placed(&mut self, pair: &PairContacts, sides: &[ContactSide]) -> bool {
        let (Some(a), Some(b)) = (sides[pair.sides[0]].object, sides[pair.sides[1]].object) else {
            return false;
        };
        let key = (a.min(b), a.max(b));
        match self.placed.iter().position(|p| *p == key) {
            Some(at) => {
                self.placed.swap_remove(at);
                true
            }
            None => false,
        }
    }

    /// Processes the contacts of one step.
    pub fn step(&mut self, input: &StepInput<'_>, out: &mut StepStrikes<'_>) {
        let StepInput { t0, dt, pairs, sides, names, to_body } = *input;
        self.current.clear();
        for pair in pairs {
            let total: f64 = pair.points.iter().map(|p| p.normal_impulse).sum();
            self.current.insert(pair.key, total);
            // Objects set on each other touched at t = 0 (module doc).
            let recent_touch = match self.last_touch.insert(pair.key, t0) {
                None if self.first_touch_of_placed(pair, sides) => Some(0.0),
                seen => seen,
            };
            let before = self.previous.get(&pair.key).copied().unwrap_or(0.0);
            let rise = total - before;
            if rise <= MIN_IMPULSE_NS || rise <= SUSTAIN_DEADBAND * before || total <= 0.0 {
                continue;
            }
            let approach = pair.points.iter().map(|p| p.approach_m_s).fold(0.0, f64::max);
            let fresh = before == 0.0;
            let recent = recent_touch.is_some_and(|t| t0 - t <= RECONTACT_WINDOW_S + 0.5 * dt);
            let gate = if recent { MIN_APPROACH_CONTINUING_M_S } else { MIN_APPROACH_M_S };
            if approach < gate {
                continue;
            }
            let share = rise / total;
            let time = if fresh {
                let gap = pair.points.iter().map(|p| p.separation_m).fold(f64::INFINITY, f64::min);
                if approach > 0.0 && gap > 0.0 {
                    t0 + (gap / approach).min(dt)
                } else {
                    // Swept there in the step before, and waited (physics.rs).
                    t0 - pair.swept_lag_s
                }
            } else {
                t0 + 0.5 * dt
            };
            *out.pair_impacts += 1;
            let [s1, s2] = [&sides[pair.sides[0]], &sides[pair.sides[1]]];
            let tau = hertz_contact_time(s1, s2, approach);
            for (k, side) in [s1, s2].into_iter().enumerate() {
                let Some(object) = side.object else { continue };
                out.impacts[object] += 1;
                let sign = if k == 0 { share } else { -share };
                for p in &pair.points {
                    let world = p.impulse_on_1.map(|x| sign * x);
                    out.strikes[object].push(Strike {
                        time_s: time,
                        point_m: p.local_m[k],
                        impulse_ns: to_body(object, world),
                        contact_time_s: tau,
                    });
                }
            }
            if let Some(events) = out.events.as_deref_mut() {
                let name =
                    |s: &ContactSide| s.object.map_or_else(|| "ground".to_string(), |i| names[i].clone());
                let mut impulse = [0.0; 3];
                let mut point = [0.0; 3];
                for p in &pair.points {
                    for c in 0..3 {
                        impulse[c] += share * p.impulse_on_1[c];
                        point[c] += p.world_m[c] * p.normal_impulse / total;
                    }
                }
                events.push(ImpactEvent {
                    time_s: time,
                    bodies: [name(s1), name(s2)],
                    point_m: point,
                    impulse_ns: impulse,
                    approach_speed_m_s: approach,
                    contact_time_s: tau,
                });
            }
        }
        std::mem::swap(&mut self.previous, &mut self.current);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn side(mass: f64, radius: f64, e: f64) -> ContactSide {
        ContactSide {
            object: None,
            plane_strain_pa: e,
            mass_kg: mass,
            radius_m: radius,
            friction: 0.5,
            finish: crate::roughness::DEFAULT_FINISH,
        }
    }

    /// analytic.md §3: steel ball R = 5 mm (4.110 g) on a massive steel flat
    /// at 1 m/s: t_c = 35.24 µs; t_c ∝ v^(−1/5).
    #[test]
    fn hertz_time_matches_reference_example() {
        let steel = 2.0e11 / (1.0 - 0.3 * 0.3);
        let ball = side(4.110e-3, 5e-3, steel);
        let flat = side(f64::INFINITY, f64::INFINITY, steel);
        let t = hertz_contact_time(&ball, &flat, 1.0);
        assert!((t - 35.24e-6).abs() < 0.05e-6, "{t}");
        let t32 = hertz_contact_time(&ball, &flat, 32.0);
        assert!((t32 / t - 0.5).abs() < 1e-9);
        assert_eq!(hertz_contact_time(&ball, &flat, 0.0), MAX_CONTACT_TIME_S);
        assert_eq!(hertz_contact_time(&ball, &flat, 1e12), MIN_CONTACT_TIME_S);
    }
}
