//! [`SynthModel`]: the part of a mode bank the synthesizer needs, checked
//! once and shared (via `Arc`) by every voice of the same asset.
//!
//! Modal coordinates follow the bank: mass-normalized shapes `φ_i` [1/√kg],
//! so an impulse `j` [N·s] at surface point `p` gives mode `i` the modal
//! velocity `a_i = φ_i(p)·j` [√kg·m/s] and the surface displacement at `x` is
//! `u(x, t) = Σ_i φ_i(x) q_i(t)` \[m\].

use std::sync::Arc;

use crate::error::SynthError;
use crate::options::OutputGain;
use crate::surface::{node_weights, SurfaceLocator, SurfacePoint};
use modal_bank::ModeBank;
use modal_mesh::Surface;

/// Largest accepted distance of a strike point from the surface, as a
/// fraction of the bounding-box diagonal.
pub const MAX_SNAP_FRACTION: f64 = 0.1;

/// Per-mode data and the surface of one bank, validated. The shapes and the
/// surface are read from the bank itself, shared, never copied.
#[derive(Clone, Debug)]
pub struct SynthModel {
    /// Undamped natural frequencies \[Hz\].
    pub frequencies_hz: Vec<f64>,
    /// Decay rates d [1/s].
    pub decay_rates: Vec<f64>,
    /// Damping ratios ξ [-].
    pub damping_ratios: Vec<f64>,
    bank: Arc<ModeBank>,
    locator: SurfaceLocator,
}

impl SynthModel {
    /// The per-mode output gains `g_i` that `gain` fixes before any strike;
    /// `None` for a contact microphone at the first struck point, whose
    /// gains [`Self::mic_gains`] gives once that point is known.
    pub(crate) fn initial_gains(&self, gain: &OutputGain) -> Result<Option<Vec<f64>>, SynthError> {
        match gain {
            OutputGain::ContactMic { at: Some(p) } => Ok(Some(self.mic_gains(&self.locate(*p)?))),
            OutputGain::ContactMic { at: None } => Ok(None),
            OutputGain::RadiationProxy => Ok(Some(self.rms_normal_shapes())),
            OutputGain::PerMode(g) => {
                let expected = self.mode_count();
                if g.len() != expected {
                    return Err(SynthError::GainCount { got: g.len(), expected });
                }
                Ok(Some(g.clone()))
            }
        }
    }

    /// Contact-microphone gains `g_i = φ_i(p)·n(p)` at a surface point.
    pub(crate) fn mic_gains(&self, p: &SurfacePoint) -> Vec<f64> {
        let mut g = vec![0.0; self.mode_count()];
        self.shapes_dot(p, p.normal, &mut g);
        g
    }

    /// Copies and checks what the synthesizer needs from `bank` (the whole
    /// bank is cloned; [`SynthModel::shared`] avoids the copy).
    pub fn new(bank: &ModeBank) -> Result<SynthModel, SynthError> {
        SynthModel::shared(Arc::new(bank.clone()))
    }

    /// Checks `bank` and keeps a reference to it (its shapes and surface are
    /// used in place).
    pub fn shared(bank: Arc<ModeBank>) -> Result<SynthModel, SynthError> {
        check(&bank)?;
        Ok(SynthModel {
            frequencies_hz: bank.frequencies_hz.clone(),
            decay_rates: bank.decay_rates.clone(),
            damping_ratios: bank.damping_ratios.clone(),
            locator: SurfaceLocator::new(&bank.surface),
            bank,
        })
    }

    /// Number of modes.
    pub fn mode_count(&self) -> usize {
        self.frequencies_hz.len()
    }

    /// The surface.
    pub fn surface(&self) -> &Surface {
        &self.bank.surface
    }

    /// Nearest surface point to `p` \[m\]. Errors when `p` is not finite, the
    /// surface is empty, or `p` lies farther than [`MAX_SNAP_FRACTION`] of the
    /// bounding-box diagonal from the surface.
    pub fn locate(&self, p: [f64; 3]) -> Result<SurfacePoint, SynthError> {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(SynthError::InvalidPoint(p));
        }
        let hit = self.locator.nearest(self.surface(), p).ok_or(SynthError::EmptySurface)?;
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
        let w = node_weights(self.surface(), p);
        for (i, o) in out.iter_mut().enumerate() {
            let mode = self.mode_shape(i);
            *o = (0..w.len).map(|k| w.weights[k] * normal_component(mode, w.nodes[k], &v)).sum();
        }
    }

    /// Radiation proxy gain per mode [1/√kg]: the area-weighted RMS of the
    /// normal component of the shape over the surface,
    /// `g_i = √( Σ_T A_T · mean_corners((φ_i·n_T)²) / Σ_T A_T )`.
    ///
    /// Per-triangle areas and unit normals are computed once; then each mode
    /// reads only its own (contiguous) shape block, summing over triangles
    /// in index order.
    pub fn rms_normal_shapes(&self) -> Vec<f64> {
        let faces = TriangleNormals::new(self.surface());
        let mut acc = vec![0.0; self.mode_count()];
        for (i, g) in acc.iter_mut().enumerate() {
            let mode = self.mode_shape(i);
            for (tri, (area, un)) in faces.triangles.iter().zip(&faces.area_normal) {
                let sq: f64 = tri.iter().map(|&k| normal_component(mode, k, un).powi(2)).sum();
                *g += area * sq / 3.0;
            }
        }
        if faces.area_total > 0.0 {
            acc.iter_mut().for_each(|g| *g = (*g / faces.area_total).sqrt());
        }
        acc
    }

    /// Where a tap along the surface normal rings the lowest modes most: the
    /// centroid of the corner triangle `T` maximizing
    /// `Σ_{i < K} p_i (v_i(T) / max_T' |v_i(T')|)²`, `v_i(T)` the mean normal
    /// shape `φ_i·n_T` over `T`'s corners, `K` = [`RINGING_MODES`] and
    /// `p_i = rms(v_i)² / max|v_i|²` (area-weighted) the share of the surface
    /// mode `i` moves: a mode of the whole body weighs more than one of a
    /// handle, an ear or a foot, whose maximum is as large but on a small
    /// part (a mug was struck on its handle and a wine glass under its foot
    /// when every mode weighed the same; now at the rim). A bar is struck on
    /// its broad face at an end, a bowl or a bell radially at the rim, a plate
    /// across its face at the edge: where a player strikes them, and where
    /// the body's farthest point (a corner, whose tap points along the bar's
    /// axis) is not. Only faces turned away from the centre of mass are
    /// candidates (struck from outside); of equal scores (a symmetric body's
    /// faces) the highest in y, then z. Without modes, the first such face.
    /// `None` without a non-degenerate triangle.
    pub fn ringing_point(&self) -> Option<[f64; 3]> {
        let s = self.surface();
        let faces = TriangleNormals::new(s);
        if faces.triangles.is_empty() {
            return None;
        }
        let modes = self.mode_count().min(RINGING_MODES);
        let v: Vec<Vec<f64>> = (0..modes).map(|i| self.mean_normal_shapes(i, &faces)).collect();
        let largest: Vec<f64> = v.iter().map(|vi| vi.iter().fold(0.0, |m: f64, x| m.max(x.abs()))).collect();
        let participation: Vec<f64> = v
            .iter()
            .zip(&largest)
            .map(|(vi, &l)| {
                let mean_square = vi.iter().zip(&faces.area_normal).map(|(x, (a, _))| a * x * x).sum::<f64>();
                if l > 0.0 {
                    mean_square / faces.area_total / (l * l)
                } else {
                    0.0
                }
            })
            .collect();
        let score = |t: usize| -> f64 {
            (0..modes)
                .filter(|&i| largest[i] > 0.0)
                .map(|i| participation[i] * (v[i][t] / largest[i]).powi(2))
                .sum()
        };
        let centroids: Vec<[f64; 3]> = faces
            .triangles
            .iter()
            .map(|tri| {
                let corners = tri.map(|k| s.positions[k]);
                [0, 1, 2].map(|c| (corners[0][c] + corners[1][c] + corners[2][c]) / 3.0)
            })
            .collect();
        // Struck from outside: a face turned away from the centre of mass (a
        // tube's or a cup's inside rings as its outside does, but is not
        // where a tap comes from). A closed surface always has such faces.
        let com = self.bank.mass.center_of_mass_m;
        let outer = |t: usize| {
            let (c, n) = (centroids[t], faces.area_normal[t].1);
            (0..3).map(|k| (c[k] - com[k]) * n[k]).sum::<f64>() > 0.0
        };
        let scores: Vec<f64> =
            (0..faces.triangles.len()).map(|t| if outer(t) { score(t) } else { f64::NEG_INFINITY }).collect();
        let top = scores.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // Equal within rounding: a plate's top and bottom, a disc's rim all round.
        let tie = top - 1e-9 * top.abs();
        let height = |t: usize| (centroids[t][1], centroids[t][2]);
        let best =
            (0..scores.len()).filter(|&t| scores[t] >= tie).fold(
                None,
                |best: Option<usize>, t| match best {
                    Some(b) if height(b) >= height(t) => Some(b),
                    _ => Some(t),
                },
            )?;
        Some(centroids[best])
    }

    /// Mode `i`'s normal shape `φ_i·n_T` averaged over each triangle's corners.
    fn mean_normal_shapes(&self, i: usize, faces: &TriangleNormals) -> Vec<f64> {
        let mode = self.mode_shape(i);
        faces
            .triangles
            .iter()
            .zip(&faces.area_normal)
            .map(|(tri, (_, n))| tri.iter().map(|&k| normal_component(mode, k, n)).sum::<f64>() / 3.0)
            .collect()
    }

    /// Mode `i`'s shape at every surface node, `[x, y, z]` per node.
    fn mode_shape(&self, i: usize) -> &[f32] {
        let nodes = self.surface().positions.len();
        &self.bank.shapes[i * nodes * 3..(i + 1) * nodes * 3]
    }
}

/// `φ(k)·n` for surface node `k` of one mode's shape block (`n` any vector).
fn normal_component(mode: &[f32], k: usize, n: &[f64; 3]) -> f64 {
    let sh = &mode[k * 3..k * 3 + 3];
    sh[0] as f64 * n[0] + sh[1] as f64 * n[1] + sh[2] as f64 * n[2]
}

/// How many of the lowest modes [`SynthModel::ringing_point`] rings.
pub const RINGING_MODES: usize = 8;

/// The non-degenerate corner triangles of a surface with their areas and
/// outward unit normals, and the total area \[m²\].
struct TriangleNormals {
    triangles: Vec<[usize; 3]>,
    area_normal: Vec<(f64, [f64; 3])>,
    area_total: f64,
}

impl TriangleNormals {
    fn new(s: &Surface) -> TriangleNormals {
        let mut faces = TriangleNormals { triangles: Vec::new(), area_normal: Vec::new(), area_total: 0.0 };
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
            faces.area_total += area;
            faces.triangles.push(*tri);
            faces.area_normal.push((area, n.map(|x| x / twice_area)));
        }
        faces
    }
}

/// The consistency checks of [`SynthModel::shared`].
fn check(bank: &ModeBank) -> Result<(), SynthError> {
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
        return bad(format!("{} shape values, expected {n} modes × {nodes} nodes × 3", bank.shapes.len()));
    }
    // One branch-free (vectorized) pass; the position only on failure.
    let all_finite = bank.shapes.iter().fold(true, |ok, x| ok & x.is_finite());
    if let Some(k) = (!all_finite).then(|| bank.shapes.iter().position(|x| !x.is_finite())).flatten() {
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
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::SyntheticBank;

    /// A unit cube bank ([0, 1]³, 12 triangles) with three modes whose shapes
    /// have known normal components: a translation along x (φ·n = ±1 on 2 of
    /// the 6 faces), a breathing field φ = x − (½, ½, ½) (φ·n = ½ at every
    /// corner of every face) and zero (a degenerate triangle is added too).
    fn cube_bank() -> ModeBank {
        let mut bank = SyntheticBank::preset("steel", 3).build();
        bank.surface = crate::synthetic::box_surface([1.0, 1.0, 1.0]);
        bank.surface.triangles.push([0, 0, 1]);
        let p = bank.surface.positions.clone();
        bank.shapes = p
            .iter()
            .map(|_| [1.0f32, 0.0, 0.0])
            .chain(p.iter().map(|x| x.map(|c| (c - 0.5) as f32)))
            .chain(p.iter().map(|_| [0.0f32; 3]))
            .flatten()
            .collect();
        bank
    }

    #[test]
    fn rms_normal_shapes_of_exact_fields() {
        let g = SynthModel::new(&cube_bank()).expect("model").rms_normal_shapes();
        // √(area of the 2 x-faces / total area) = √(1/3); breathing: ½; zero: 0.
        assert!((g[0] - (1.0f64 / 3.0).sqrt()).abs() < 1e-15, "{}", g[0]);
        assert!((g[1] - 0.5).abs() < 1e-15, "{}", g[1]);
        assert_eq!(g[2], 0.0);
    }

    #[test]
    fn the_ringing_point_is_where_the_normal_motion_is_largest_and_outside() {
        // A unit box with a cavity (a box of half its size at its centre, faces
        // turned inwards). Mode 0 moves every node away from the centre, four
        // times as far on the cavity's walls: their normal motion is twice the
        // outer walls', but they face the centre of mass and are not struck.
        let mut bank = SyntheticBank::preset("steel", 3).build();
        let mut surface = crate::synthetic::box_surface([1.0, 1.0, 1.0]);
        let cavity = crate::synthetic::box_surface([0.5, 0.5, 0.5]);
        let outer_nodes = surface.positions.len();
        surface.positions.extend(cavity.positions.iter().map(|p| p.map(|c| c + 0.25)));
        surface
            .triangles
            .extend(cavity.triangles.iter().map(|&[a, b, c]| [a, c, b].map(|k| k + outer_nodes)));
        bank.mass.center_of_mass_m = [0.5; 3];
        let away =
            |k: usize, p: &[f64; 3]| p.map(|c| ((c - 0.5) * if k < outer_nodes { 1.0 } else { 4.0 }) as f32);
        let nodes = surface.positions.len();
        bank.shapes = surface
            .positions
            .iter()
            .enumerate()
            .map(|(k, p)| away(k, p))
            .chain((0..2 * nodes).map(|_| [0.0f32; 3]))
            .flatten()
            .collect();
        bank.surface = surface;
        let model = SynthModel::new(&bank).expect("model");
        let p = model.ringing_point().expect("a point");
        let on_outer_wall = p.iter().any(|&c| c == 0.0 || c == 1.0);
        assert!(on_outer_wall, "{p:?} is not on the outer wall");
        // Without modes (a bank whose band holds none): an outer face, not an error.
        bank.frequencies_hz.clear();
        bank.decay_rates.clear();
        bank.damping_ratios.clear();
        bank.shapes.clear();
        let silent = SynthModel::new(&bank).expect("model").ringing_point().expect("a point");
        assert!(silent.iter().any(|&c| c == 0.0 || c == 1.0), "{silent:?} is not on the outer wall");
    }

    #[test]
    fn a_shared_model_reads_the_bank_in_place() {
        let bank = Arc::new(cube_bank());
        let model = SynthModel::shared(Arc::clone(&bank)).expect("model");
        assert!(std::ptr::eq(model.surface(), &bank.surface));
        let hit = model.locate([0.5, 0.5, 1.05]).expect("on the top face");
        let mut out = vec![0.0; 3];
        model.shapes_dot(&hit, [0.0, 0.0, 1.0], &mut out);
        assert_eq!(out, [0.0, 0.5, 0.0]);
        // A non-finite shape value is found and named.
        let mut bad = cube_bank();
        bad.shapes[3 * 8 + 3 * 5 + 2] = f32::NAN;
        let err = SynthModel::new(&bad).expect_err("NaN shape").to_string();
        assert!(err.contains("mode 1") && err.contains("surface node 5"), "{err}");
    }
}
