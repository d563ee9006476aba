//! How long an edge of a layered wall's master skin may be (step 3 of
//! module `shell`): two wall thicknesses where the wall is curved across
//! the edge, longer along the straight axis of a slender shell (a chime),
//! where the edge bends no more than a curved one may:
//!
//! ```text
//!   bend = |(n_b − n_a)·(x_b − x_a)| = L²·κ_n  ≤  h_c²·κ_max
//! ```
//!
//! (`κ_n` the normal curvature along the edge, `h_c` the curved size).
//!
//! Where the wall is flat (a plate, a cymbal: an edge of `h_c` bends less
//! than [`MAX_BEND_PER_WALL`] walls), nothing locks, and the size follows the
//! modes instead: [`FLAT_CELLS_PER_WAVELENGTH`] edges per bending wavelength
//! of the `N/2`-th mode, `N` the modes the bank keeps
//! ([`crate::TetOptions::resolved_modes`]; at least the
//! [`FLAT_RESOLVED_MODES`]-th): sized for its 64th mode, a plate's modes up
//! to the 128th stayed within 0.57 % (BENCHMARKS). A free plate of one-side
//! area `A` has about `N = A·k²/(4π)` bending modes below wavenumber `k`
//! (Weyl's law), so that wavelength is `2π / √(4πN/A)`.

use crate::geom::{add, dot, norm, scale, sub, unit, V3};
use crate::shell::LayerSizing;

/// An edge longer than the curved in-plane size `h_c` is kept where the wall
/// is straight along it and curved across it: its bend
/// `|(n_b − n_a)·(x_b − x_a)| = L²·κ_n` (`κ_n` the normal curvature along
/// the edge, from its ends' normals) at most what an edge of `h_c` bends in
/// the most curved direction at its ends (`h_c²·κ_max`, `κ_max` the largest
/// `κ_n` of the edges there), and that bend more than this many wall
/// thicknesses (a wall flatter than that, a plate, keeps `h_c` in every
/// direction: a 15 × 10 cm steel plate 2 mm thick at 3.1 mm edges is within
/// 0.28 % of two layers at 1 mm on 16 modes, at 6.25 mm 0.94 %). `L²κ/t` is
/// what makes flat-faceted elements on a curved wall stiffen (membrane
/// locking), so a longer edge never bends more than the validated `h_c`
/// rule's: on a sphere every direction is curved and no edge exceeds `h_c`;
/// along a pipe's axis edges reach the straight size.
pub const MAX_BEND_PER_WALL: f64 = 0.1;

/// Edges per bending wavelength of the sized mode on a flat wall (module
/// doc). Frequency error against edges per wavelength, measured on a
/// 15 × 10 cm steel plate 2 mm thick (16 modes) and a 30 cm brass cymbal
/// 1.5 mm thick (20 modes): 0.28 % and 0.17 % at 17.5, 0.55 % at 12, 0.94 %
/// and 1.14 % at 8.7: 12 keeps half the default 1 % target.
pub const FLAT_CELLS_PER_WAVELENGTH: f64 = 12.0;

/// The lowest mode whose wavelength sizes a flat wall: the number of modes
/// `modal precompute` keeps by default. A bank of `N` modes sizes its flat
/// walls for the `N/2`-th when that is higher
/// ([`crate::TetOptions::resolved_modes`]): on a 20 × 15 cm steel plate 1 mm
/// thick, sized for its 64th mode, modes 65–128 erred at most 0.57 %
/// (median 0.15 %); sized for the 128th, 0.22 %, at twice the DOF and about
/// 16× the solve time.
pub const FLAT_RESOLVED_MODES: usize = 64;

/// How long a master-skin edge may be (step 3 of the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct EdgeLimits {
    /// Any edge up to this length is kept [m].
    pub(crate) curved_m: f64,
    /// A longer edge is kept up to this length where the wall is straight
    /// along it and curved across it (a pipe's axis) [m].
    pub(crate) straight_m: f64,
    /// "Curved across": an edge of `curved_m` bends more than this
    /// ([`MAX_BEND_PER_WALL`]) [m].
    pub(crate) bend_m: f64,
    /// A longer edge is kept up to this length where the wall is flat
    /// (module doc) [m].
    pub(crate) flat_m: f64,
}

impl EdgeLimits {
    /// The limits of a wall `wall_m` thick whose master skin has `area_m2`;
    /// `slender` the length of a slender body ([`slender_length`]), `None`:
    /// no long cells.
    pub(crate) fn new(sizing: &LayerSizing, wall_m: f64, area_m2: f64, slender: Option<f64>) -> EdgeLimits {
        let curved_m = sizing.in_plane_m.unwrap_or((sizing.wall_cells * wall_m).min(sizing.max_in_plane_m));
        let straight_m = match (sizing.in_plane_m, slender) {
            (None, Some(length)) => (sizing.straight_wall_cells * wall_m)
                .min(length / SLENDER_CELLS_PER_LENGTH * sizing.size_factor)
                .min(sizing.max_in_plane_m)
                .max(curved_m),
            _ => curved_m,
        };
        let flat_m = match sizing.in_plane_m {
            None => (flat_wavelength(area_m2, sizing.resolved_modes) / FLAT_CELLS_PER_WAVELENGTH
                * sizing.size_factor)
                .min(sizing.max_in_plane_m)
                .max(curved_m),
            Some(_) => curved_m,
        };
        EdgeLimits { curved_m, straight_m, bend_m: MAX_BEND_PER_WALL * wall_m, flat_m }
    }

    /// Every edge at the curved size.
    pub(crate) fn isotropic(&self) -> EdgeLimits {
        EdgeLimits { straight_m: self.curved_m, flat_m: self.curved_m, ..*self }
    }

    pub(crate) fn is_isotropic(&self) -> bool {
        self.straight_m <= self.curved_m && self.flat_m <= self.curved_m
    }

    /// The longest edge any wall may keep [m].
    pub(crate) fn longest(&self) -> f64 {
        self.straight_m.max(self.flat_m)
    }

    /// Whether the edge from `a` to `b` (normals `na`, `nb`; `kappa` the
    /// larger `κ_max` of its ends [1/m]) must be split.
    pub(crate) fn too_long(
        &self,
        (a, na): (V3, V3),
        (b, nb): (V3, V3),
        kappa: f64,
        middle: impl Fn() -> V3,
    ) -> bool {
        let d = sub(b, a);
        let length = norm(d);
        let across = self.curved_m * self.curved_m * kappa;
        if length <= self.curved_m {
            return false;
        }
        // A flat wall: any direction up to the plate size, while the edge stays flat.
        let (limit, allowed) =
            if across <= self.bend_m { (self.flat_m, self.bend_m) } else { (self.straight_m, across) };
        if length > limit || bend(d, sub(nb, na)) > allowed {
            return true;
        }
        // Straight between its ends, but maybe not in between (across a crease).
        let (half, nm) = (scale(d, 0.5), middle());
        bend(half, sub(nm, na)).max(bend(half, sub(nb, nm))) > 0.25 * allowed
    }
}

/// A body is slender when its length along its principal axis is at least
/// this many times its largest diameter across it.
pub const SLENDER_RATIO: f64 = 5.0;

/// Long cells along a slender wall are at most its length over this (the
/// generated tubes' axial rule).
pub const SLENDER_CELLS_PER_LENGTH: f64 = 20.0;

/// The length of the body through `points` along its principal axis (the
/// covariance's dominant eigenvector, by power iteration) when that is at
/// least [`SLENDER_RATIO`] times its diameter across the axis; `None`
/// otherwise. Long cells are for slender tubes only: their low modes bend
/// the whole cross-section (beams) or vary slowly along the axis (rings),
/// while on a compact shell a mode bends the wall through its thickness in
/// every direction, and one layer of 10-node tets stiffens under long cells
/// (a 15 cm bell's crown flap mode 55 % high at 5.4 wall thicknesses along
/// its generatrix; a plate at 4 walls 0.94 % against 0.28 % at 2).
pub(crate) fn slender_length(points: &[V3]) -> Option<f64> {
    let n = points.len() as f64;
    if points.is_empty() {
        return None;
    }
    let centre = scale(points.iter().fold([0.0; 3], |acc, &p| add(acc, p)), 1.0 / n);
    let mut covariance = [[0.0; 3]; 3];
    for p in points {
        let d = sub(*p, centre);
        for (i, row) in covariance.iter_mut().enumerate() {
            for (j, c) in row.iter_mut().enumerate() {
                *c += d[i] * d[j];
            }
        }
    }
    let mut axis = [1.0, 0.7, 0.4];
    for _ in 0..100 {
        axis = unit(covariance.map(|row| dot(row, axis)));
    }
    let (mut lo, mut hi, mut radius) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for p in points {
        let d = sub(*p, centre);
        let along = dot(d, axis);
        (lo, hi) = (lo.min(along), hi.max(along));
        radius = radius.max(norm(sub(d, scale(axis, along))));
    }
    let length = hi - lo;
    (length >= SLENDER_RATIO * 2.0 * radius).then_some(length)
}

/// The mode whose wavelength sizes a flat wall when the bank keeps `modes`
/// modes: the `modes/2`-th, at least the [`FLAT_RESOLVED_MODES`]-th (module doc).
pub(crate) fn flat_sized_mode(modes: usize) -> usize {
    modes.div_ceil(2).max(FLAT_RESOLVED_MODES)
}

/// The bending wavelength of the mode that sizes a plate of one-side area
/// `area_m2` whose bank keeps `modes` modes ([`flat_sized_mode`]) [m].
fn flat_wavelength(area_m2: f64, modes: usize) -> f64 {
    let mode = flat_sized_mode(modes) as f64;
    std::f64::consts::TAU / (4.0 * std::f64::consts::PI * mode / area_m2).sqrt()
}

/// `|Δn·Δx| = L²·κ_n` of an edge `d` whose ends' normals differ by `dn` [m].
pub(crate) fn bend(d: V3, dn: V3) -> f64 {
    dot(dn, d).abs()
}
