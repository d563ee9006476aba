//! [`SynthModel`]: the part of a mode bank the synthesizer needs, checked
//! once and shared (via `Arc`) by every voice of the same asset.
//!
//! Modal coordinates follow the bank: mass-normalized shapes `φ_i` [1/√kg],
//! so an impulse `j` [N·s] at surface point `p` gives mode `i` the modal
//! velocity `a_i = φ_i(p)·j` [√kg·m/s] and the surface displacement at `x` is
//! `u(x, t) = Σ_i φ_i(x) q_i(t)` \[m\].

use crate::error::SynthError;
use crate::surface::{node_weights, SurfaceLocator, SurfacePoint};
use modal_bank::ModeBank;
use modal_mesh::Surface;

/// Largest accepted distance of a strike point from the surface, as a
/// fraction of the bounding-box diagonal.
pub const MAX_SNAP_FRACTION: f64 = 0.1;

/// Per-mode data and the surface of one bank, validated.
#[derive(Clone, Debug)]
pub struct SynthModel {
    /// Undamped natural frequencies \[Hz\].
    pub frequencies_hz: Vec<f64>,
    /// Decay rates d [1/s].
    pub decay_rates: Vec<f64>,
    /// Damping ratios ξ [-].
    pub damping_ratios: Vec<f64>,
    shapes: Vec<f32>,
    surface: Surface,
    locator: SurfaceLocator,
}

impl SynthModel {
    /// Copies and checks what the synthesizer needs from `bank`.
    pub fn new(bank: &ModeBank) -> Result<SynthModel, SynthError> {
        let n = bank.frequencies_hz.len();
        let nodes = bank.surface.positions.len();
        let bad = |m: String| Err(SynthError::InconsistentBank(m));
        if bank.decay_rates.len() != n || bank.damping_ratios.len() != n {
            return bad(format!(
                "{n} frequencies but {} decay rates and {} damping ratios",
                bank.decay_rates.len(),
                bank.damping_ratios.len()
            ));
        }
        if Some(bank.shapes.len()) != n.checked_mul(nodes).and_then(|x| x.checked_mul(3)) {
            return bad(format!(
                "{} shape values, expected {n} modes × {nodes} nodes × 3",
                bank.shapes.len()
            ));
        }
        if let Some(k) = bank.shapes.iter().position(|x| !x.is_finite()) {
            let (mode, node) = (k / 3 / nodes.max(1), k / 3 % nodes.max(1));
            return bad(format!("mode {mode} has a non-finite shape value at surface node {node}"));
        }
        if let Some(k) = bank.surface.positions.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return bad(format!("surface node {k} has a non-finite position"));
        }
        if let Some(t) = bank.surface.triangles.iter().position(|t| t.iter().any(|&k| k >= nodes)) {
            return bad(format!("surface triangle {t} refers to a node >= {nodes}"));
        }
        if let Some(e) = &bank.surface.triangle_edge_nodes {
            if e.len() != bank.surface.triangles.len() {
                return bad(format!(
                    "{} triangles but {} mid-edge triples",
                    bank.surface.triangles.len(),
                    e.len()
                ));
            }
            if let Some(t) = e.iter().position(|t| t.iter().any(|&k| k >= nodes)) {
                return bad(format!("mid-edge nodes of surface triangle {t} refer to a node >= {nodes}"));
            }
        }
        Ok(SynthModel {
            frequencies_hz: bank.frequencies_hz.clone(),
            decay_rates: bank.decay_rates.clone(),
            damping_ratios: bank.damping_ratios.clone(),
            shapes: bank.shapes.clone(),
            surface: bank.surface.clone(),
            locator: SurfaceLocator::new(&bank.surface),
        })
    }

    /// Number of modes.
    pub fn mode_count(&self) -> usize {
        self.frequencies_hz.len()
    }

    /// The surface.
    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    /// Nearest surface point to `p` \[m\]. Errors when `p` is not finite, the
    /// surface is empty, or `p` lies farther than [`MAX_SNAP_FRACTION`] of the
    /// bounding-box diagonal from the surface.
    pub fn locate(&self, p: [f64; 3]) -> Result<SurfacePoint, SynthError> {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(SynthError::InvalidPoint(p));
        }
        let hit = self.locator.nearest(&self.surface, p).ok_or(SynthError::EmptySurface)?;
        let limit = MAX_SNAP_FRACTION * self.locator.bbox_diagonal();
        if hit.distance > limit {
            return Err(SynthError::PointFarFromSurface { point: p, distance: hit.distance, limit });
        }
        Ok(hit)
    }

    /// Mode shapes at a surface point dotted with `v`: `out[i] = φ_i(p)·v`.
    /// `out.len()` must equal `mode_count()`.
    pub fn shapes_dot(&self, p: &SurfacePoint, v: [f64; 3], out: &mut [f64]) {
        assert_eq!(out.len(), self.mode_count(), "shapes_dot: output length");
        let w = node_weights(&self.surface, p);
        let nodes = self.surface.positions.len();
        for (i, o) in out.iter_mut().enumerate() {
            let mut acc = 0.0;
            for k in 0..w.len {
                let b = (i * nodes + w.nodes[k]) * 3;
                let s = &self.shapes[b..b + 3];
                acc += w.weights[k] * (s[0] as f64 * v[0] + s[1] as f64 * v[1] + s[2] as f64 * v[2]);
            }
            *o = acc;
        }
    }

    /// Radiation proxy gain per mode [1/√kg]: the area-weighted RMS of the
    /// normal component of the shape over the surface,
    /// `g_i = √( Σ_T A_T · mean_corners((φ_i·n_T)²) / Σ_T A_T )`.
    pub fn rms_normal_shapes(&self) -> Vec<f64> {
        let s = &self.surface;
        let nodes = s.positions.len();
        let mut area_total = 0.0;
        let mut acc = vec![0.0; self.mode_count()];
        for tri in &s.triangles {
            let [a, b, c] = tri.map(|k| s.positions[k]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n =
                [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
            let twice_area = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if twice_area == 0.0 {
                continue;
            }
            let area = 0.5 * twice_area;
            let un = n.map(|x| x / twice_area);
            area_total += area;
            for (i, g) in acc.iter_mut().enumerate() {
                let mut sq = 0.0;
                for &k in tri {
                    let base = (i * nodes + k) * 3;
                    let sh = &self.shapes[base..base + 3];
                    let d = sh[0] as f64 * un[0] + sh[1] as f64 * un[1] + sh[2] as f64 * un[2];
                    sq += d * d;
                }
                *g += area * sq / 3.0;
            }
        }
        if area_total > 0.0 {
            acc.iter_mut().for_each(|g| *g = (*g / area_total).sqrt());
        }
        acc
    }
}
