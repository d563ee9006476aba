//! The second try of a thin shell not meshed in layers as given: its copy
//! smoothed by Taubin's filter (module `smooth`), creases kept, used when
//! it stays within a tenth of a wall of the input. A scan's noise folds the
//! layers (BENCHMARKS, "Noisy scans of thin shells").

use rayon::prelude::*;

use crate::bvh::Bvh;
use crate::diagnose::Repaired;
use crate::geom::V3;
use crate::mesher::not_layered_reason;
use crate::shell::{layered, LayerSizing, Layered, NotLayered};
use crate::smooth::{averaged_normals, taubin};

/// Passes of Taubin smoothing (module `smooth`) of a surface not layered as
/// given: at most 7 % of a scan's vertex-to-vertex noise is left after 10.
pub const NOISE_SMOOTHING_PASSES: usize = 10;

/// Edges whose faces' normals, averaged over [`CREASE_NORMAL_RADIUS_PER_WALL`]
/// (`smooth::averaged_normals`), turn by more than this are creases the
/// smoothing keeps (a rim's 90°; a scan's noise tilts single 1–2 mm facets
/// by tens of degrees, but hardly their average).
pub const SMOOTHING_CREASE_DEG: f64 = 60.0;

/// Half-side of the cube the crease test's normals are averaged over, in
/// walls (2V/A): a few of a scan's triangles, well inside the wall.
pub const CREASE_NORMAL_RADIUS_PER_WALL: f64 = 1.0 / 3.0;

/// The smoothed copy is used only when 99 % of its vertices stay within
/// this many wall thicknesses (2V/A) of the input surface, so the wall it
/// meshes is the input's. Measured (99th percentile, walls): noisy bowls
/// with 0.1 mm rms on 4 and 6 mm walls 0.045 and 0.043; clean inputs, whose
/// faceted corners the filter pulls in, 0.000 (plate) to 0.057 (a bowl of
/// 6 k triangles), 0.094 and 0.152 (the corpus and 15 cm bells' lips).
pub const MAX_SMOOTHING_SHIFT_PER_WALL: f64 = 0.1;

/// The input surface's vertices after Taubin smoothing, a BVH over its
/// triangles, and how far they lie from the input surface [m]: the median,
/// the 99th percentile, the largest.
pub(crate) struct Smoothed {
    vertices: Vec<V3>,
    /// The smoothed triangles (the layers' surface and, after them, the one
    /// the curved boundary follows).
    pub surface: Bvh,
    shift_m: [f64; 3],
}

impl Smoothed {
    /// The smoothed surface, when it differs from `repaired` (with `bvh`
    /// over it) by noise alone ([`MAX_SMOOTHING_SHIFT_PER_WALL`] of `wall`).
    pub fn if_only_noise(repaired: &Repaired, bvh: &Bvh, wall: f64) -> Option<Smoothed> {
        let (v, t) = (&repaired.vertices, &repaired.triangles);
        let normals = averaged_normals(v, t, bvh, CREASE_NORMAL_RADIUS_PER_WALL * wall);
        let vertices = taubin(v, t, &normals, SMOOTHING_CREASE_DEG, NOISE_SMOOTHING_PASSES);
        let mut shift: Vec<f64> = vertices.par_iter().map(|&p| bvh.distance(p)).collect();
        if shift.is_empty() {
            return None;
        }
        shift.sort_by(f64::total_cmp);
        let at = |q: f64| shift[((shift.len() - 1) as f64 * q).round() as usize];
        let shift_m = [at(0.5), at(0.99), at(1.0)];
        if shift_m[1] > MAX_SMOOTHING_SHIFT_PER_WALL * wall {
            return None;
        }
        let surface = Bvh::new(t.iter().map(|t| t.map(|v| vertices[v])).collect());
        Some(Smoothed { vertices, surface, shift_m })
    }

    /// What the smoothing did and why, for the user; `reason`: why the input
    /// itself was not layered.
    pub fn warning(&self, reason: &NotLayered, wall_m: f64) -> String {
        let [median, p99, max] = self.shift_m;
        format!(
            "not meshed in layers as given ({}), so meshed in layers on a copy smoothed by \
             {NOISE_SMOOTHING_PASSES} passes of Taubin's filter (noise, like a scan's, folds the layers): \
             the copy lies {median:.2e} m from the input at the median vertex, {p99:.2e} m at the 99th \
             percentile, {max:.2e} m at most (wall {wall_m:.3e} m)",
            not_layered_reason(reason)
        )
    }

    /// [`layered`] on the smoothed surface, its skins' small holes closed.
    pub fn layered(
        &self,
        repaired: &Repaired,
        diagonal: f64,
        shape: (f64, usize),
        sizing: LayerSizing,
    ) -> Result<Layered, NotLayered> {
        layered(&self.vertices, &repaired.triangles, &self.surface, diagonal, shape, sizing, true)
    }
}
