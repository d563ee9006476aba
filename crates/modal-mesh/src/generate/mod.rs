//! Mesh generators for tests, benchmarks and the demo: a box of Kuhn-split
//! hexahedra and mapped structured meshes of a cylinder, tube, sphere and
//! hemispherical bowl. All tets are positively oriented and conforming.
//!
//! [`generate`] is the single entry point for the CLI: it validates the
//! parameters, picks cell counts from the target element size `h` (m) and
//! returns a 4-node (`order` 1) or 10-node (`order` 2) mesh. Quadratic
//! meshes of curved shapes have their mid-edge nodes on the true surface.

mod boxes;
mod mapped;
mod shapes;

pub use boxes::box_mesh;
pub use mapped::{LENGTH_RANGE_M, MAX_GENERATED_TETS};
pub use shapes::{bowl, cylinder, sphere, tube, tube_sized};

use crate::{to_quadratic, MeshError, TetMesh};
use mapped::positive;

/// Default budget of a generated order-2 mesh whose D_min/2 rule would give
/// more (thin plates, bowls and long tubes): about 12 000 tets (≈ 50 000 DOF),
/// the budget the tetrahedralizer's default has for compact solids.
pub const DEFAULT_MAX_TETS: u64 = 12_000;

/// Element sizes of a generated mesh [m]: `h` everywhere, except along a
/// tube's axis, where it is `axial` (≥ `h` for a long thin tube's default,
/// [`Shape::default_sizes`]; other shapes ignore it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElementSizes {
    /// Size across and around.
    pub h: f64,
    /// Size along a tube's axis.
    pub axial: f64,
}

impl ElementSizes {
    /// `h` in every direction.
    pub fn uniform(h: f64) -> Self {
        ElementSizes { h, axial: h }
    }
}

/// The widest a default cell of a thin flat plate may be, in wall
/// thicknesses (one layer of quadratic tets through the wall): flatter
/// cells stiffen bending (measured: a 1 m steel sheet 1 mm thick at 22.7
/// thicknesses was up to 9 % high against half that size; 0.38 % at 4).
pub const MAX_FLAT_CELL_PER_WALL: f64 = 4.0;

/// The same on a curved wall (a bowl; a tube around its axis), where flat
/// cells stiffen sooner: a 10 cm glass bowl with a 2 mm wall was up to
/// 1.18 % high at 4 thicknesses and 0.12 % at 2, against 1.5.
pub const MAX_CURVED_CELL_PER_WALL: f64 = 2.0;

/// The longest a long tube's default cell may be along its axis, in wall
/// thicknesses (measured: a 1 m aluminium tube with a 0.5 mm wall at 100
/// thicknesses was up to 8.5 % high on its shell modes against 20).
pub const MAX_AXIAL_CELL_PER_WALL: f64 = 16.0;

/// The thinnest dimension of a generated shape must be at least this
/// fraction of its largest (a 1 m sheet 0.1 mm thick). Below it no solid
/// rings as one, the wall is almost surely a unit slip (a bowl with a
/// `--thickness 1e-9`), and the solve would stall on a mesh of needles.
pub const MIN_THIN_TO_LARGE: f64 = 1e-4;

/// Refuses a shape thinner than [`MIN_THIN_TO_LARGE`] of its size.
fn check_proportions(shape: &Shape) -> Result<(), MeshError> {
    let (thinnest, largest) = shape.extents();
    // Non-positive or non-finite sizes are each generator's own refusal.
    if thinnest > 0.0 && largest.is_finite() && thinnest < MIN_THIN_TO_LARGE * largest {
        return Err(MeshError::InvalidParameter {
            name: "thickness",
            message: format!(
                "the thinnest dimension ({} m) is below 1/{:.0} of the largest ({} m): no solid this \
                 thin rings as one; check the units",
                crate::readable(thinnest),
                1.0 / MIN_THIN_TO_LARGE,
                crate::readable(largest)
            ),
        });
    }
    Ok(())
}

/// A shape to mesh; all lengths in metres.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Box `[0, size[0]] × [0, size[1]] × [0, size[2]]`.
    Box {
        /// Edge lengths (m).
        size: [f64; 3],
    },
    /// Solid cylinder along z from z = 0, axis through the origin.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length along z (m).
        length: f64,
    },
    /// Hollow cylinder along z from z = 0.
    Tube {
        /// Inner radius (m).
        inner_radius: f64,
        /// Outer radius (m) (> inner).
        outer_radius: f64,
        /// Length along z (m).
        length: f64,
    },
    /// Ball centred at the origin.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// Hemispherical shell opening towards +z, rim in the plane z = 0,
    /// centre of curvature at the origin.
    Bowl {
        /// Outer radius (m).
        radius: f64,
        /// Wall thickness (m) (< radius).
        thickness: f64,
    },
}

impl Shape {
    /// (D_min, D_max) [m]: the thinnest dimension (shortest side, diameter,
    /// wall or shell thickness) and the largest overall dimension.
    pub fn extents(&self) -> (f64, f64) {
        match *self {
            Shape::Box { size } => {
                (size.iter().copied().fold(f64::INFINITY, f64::min), size.iter().copied().fold(0.0, f64::max))
            }
            Shape::Cylinder { radius, length } => ((2.0 * radius).min(length), (2.0 * radius).max(length)),
            Shape::Tube { inner_radius, outer_radius, length } => {
                ((outer_radius - inner_radius).min(length), (2.0 * outer_radius).max(length))
            }
            Shape::Sphere { radius } => (2.0 * radius, 2.0 * radius),
            Shape::Bowl { radius, thickness } => (thickness, 2.0 * radius),
        }
    }

    /// Default element size h [m] at element `order`, chosen by the accuracy
    /// study (docs/benchmarks/accuracy.md, `modal bench accuracy`):
    /// - order 2: h = min(D_min/2, D_max/4) — the cheapest measured rule with
    ///   a max error ≤ 0.72 % on the first 12–20 modes of the free bar
    ///   (D_min/2 binds), the cantilever (D_min/2) and the sphere (D_max/4);
    /// - order 1: h = min(D_min/8, D_max/20) — ≈ 3.3 % on the bar and 1.6 % on
    ///   the sphere; linear tets lock in bending, so 1 % is out of reach at a
    ///   sane cost.
    ///
    /// At order 2 a thin plate, disc or bowl (a wall much thinner than the shape
    /// is large) would get far more elements from D_min/2 than its modes
    /// need, and a 0.9 × 0.6 m sheet 4 mm thick (8.1 M DOF) more than any
    /// machine holds: the size then grows until the mesh has at most
    /// [`DEFAULT_MAX_TETS`] tets ([`Shape::tet_count`]), but never beyond
    /// D_max/20 nor [`MAX_FLAT_CELL_PER_WALL`] (bowl:
    /// [`MAX_CURVED_CELL_PER_WALL`]) wall thicknesses (a thinner,
    /// wider plate keeps more tets, and the memory guard refuses what does
    /// not fit). Measured (first 12 modes, BENCHMARKS "Thin plates and
    /// bowls"): a steel 15 × 10 cm plate 4 mm thick at one layer through
    /// the thickness (h = 4 mm) is within 0.6 % of two layers at 2 mm, the
    /// sheet at 14.7 mm within 0.3 % of 7.35 mm, a glass bowl (6 cm, 4 mm
    /// wall) at its budget size within 0.64 % of 3 mm, a 20 cm steel disc 2 mm
    /// thick at 6 mm (11 424 tets) within 0.39 % of 2 mm. Long rods (also
    /// cylinders) keep about `D_min/2` unless it is over the budget: a 1 m rod
    /// of 10 mm diameter at 6 mm is within 0.11 % of 3 mm. Tubes: see
    /// [`Shape::default_sizes`] (uniform cells at the budget put a thin
    /// tube's shell modes 35 % high).
    ///
    /// Invalid dimensions give 1 m, so that the generator reports them.
    pub fn default_element_size(&self, order: u8) -> f64 {
        self.default_sizes(order).h
    }

    /// [`Shape::default_element_size`] and, for a long tube, a longer size
    /// along its axis: at order 2, when the uniform size would give more
    /// than [`DEFAULT_MAX_TETS`] tets, the axial size grows until the budget
    /// holds (at most length/20 and [`MAX_AXIAL_CELL_PER_WALL`] wall
    /// thicknesses); if that is not enough, the cells around and through the
    /// wall become twice the wall thickness (at least 16 around) and the
    /// axial size grows again (a thin tube may stay over the budget; the
    /// memory guard refuses what does not fit).
    /// Measured (BENCHMARKS "Thin plates and bowls"): a 1 m chime tube,
    /// 25 mm radius, 1.5 mm wall, at 3 mm around and 24 mm along (12 852
    /// tets) is within 0.42 % of 3 mm everywhere (102 204 tets) on its first
    /// 12 modes; uniform cells at the budget (8.7 mm) put its shell modes
    /// 35 % high (the cells' aspect ratio on a curved thin wall).
    pub fn default_sizes(&self, order: u8) -> ElementSizes {
        let (thinnest, largest) = self.extents();
        let sizes = if order == 1 {
            ElementSizes::uniform((thinnest / 8.0).min(largest / 20.0))
        } else {
            let accurate = (thinnest / 2.0).min(largest / 4.0);
            match *self {
                Shape::Box { .. } | Shape::Bowl { .. } | Shape::Cylinder { .. } => {
                    let per_wall = match self {
                        Shape::Bowl { .. } => MAX_CURVED_CELL_PER_WALL,
                        _ => MAX_FLAT_CELL_PER_WALL,
                    };
                    let widest = (largest / 20.0).min(per_wall * thinnest).max(accurate);
                    ElementSizes::uniform(self.within_budget(accurate, widest))
                }
                Shape::Tube { inner_radius, outer_radius, length } => {
                    self.tube_within_budget(accurate, inner_radius, outer_radius, length)
                }
                Shape::Sphere { .. } => ElementSizes::uniform(accurate),
            }
        };
        if [sizes.h, sizes.axial].iter().all(|s| s.is_finite() && *s > 0.0) {
            sizes
        } else {
            ElementSizes::uniform(1.0)
        }
    }

    /// A tube's default sizes (see [`Shape::default_sizes`]).
    fn tube_within_budget(&self, accurate: f64, inner: f64, outer: f64, length: f64) -> ElementSizes {
        let fits = |sizes: ElementSizes| self.tet_count(sizes) <= DEFAULT_MAX_TETS;
        let wall = outer - inner;
        // Along the axis at most 16 wall thicknesses (measured 0.42 % at 16 on the
        // 1.5 mm chime; up to 8.5 % at 100 on a 0.5 mm wall).
        let longest = (length / 20.0).min(MAX_AXIAL_CELL_PER_WALL * wall);
        let longer_along = |h: f64| {
            let axial = smallest_fitting(h, longest.max(h), |axial| fits(ElementSizes { h, axial }));
            ElementSizes { h, axial }
        };
        // First only longer cells along the axis; then, if that is not
        // enough, twice the wall around too.
        let along = longer_along(accurate);
        if fits(along) {
            return along;
        }
        longer_along(
            accurate
                .max((MAX_CURVED_CELL_PER_WALL * wall).min(std::f64::consts::PI * (inner + outer) / 16.0)),
        )
    }

    /// The smallest uniform `h ≥ h_min` (and at most `h_max`) at which the
    /// generator makes at most [`DEFAULT_MAX_TETS`] tets ([`Shape::tet_count`]).
    fn within_budget(&self, h_min: f64, h_max: f64) -> f64 {
        smallest_fitting(h_min, h_max, |h| self.tet_count(ElementSizes::uniform(h)) <= DEFAULT_MAX_TETS)
    }

    /// Tets [`generate_sized`] makes for this shape at `sizes` (computed
    /// from its cell counts; no mesh is built).
    pub fn tet_count(&self, sizes: ElementSizes) -> u64 {
        shapes::tet_count(self, sizes)
    }

    /// Exact volume of the shape (m³) (the meshes approach it as h → 0).
    pub fn volume(&self) -> f64 {
        use std::f64::consts::PI;
        match *self {
            Shape::Box { size } => size[0] * size[1] * size[2],
            Shape::Cylinder { radius, length } => PI * radius * radius * length,
            Shape::Tube { inner_radius, outer_radius, length } => {
                PI * (outer_radius * outer_radius - inner_radius * inner_radius) * length
            }
            Shape::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
            Shape::Bowl { radius, thickness } => {
                2.0 / 3.0 * PI * (radius.powi(3) - (radius - thickness).powi(3))
            }
        }
    }
}

/// Meshes `shape` with elements of size about `h` (m) at element `order`
/// (1: 4-node, 2: 10-node). Errors on non-finite or non-positive lengths,
/// an inner radius not below the outer one, a thickness not below the
/// radius, an order other than 1 or 2, or a mesh of more than
/// [`MAX_GENERATED_TETS`] tets.
pub fn generate(shape: &Shape, h: f64, order: u8) -> Result<TetMesh, MeshError> {
    generate_sized(shape, ElementSizes::uniform(h), order)
}

/// The smallest `x` in `[lo, hi]` with `fits(x)`, for `fits` monotone
/// (false, then true): `lo` when it fits or the interval is empty, `hi`
/// when nothing fits; bisection on a log scale.
fn smallest_fitting(lo: f64, hi: f64, fits: impl Fn(f64) -> bool) -> f64 {
    if !(lo > 0.0 && hi > lo) || fits(lo) {
        return lo;
    }
    if !fits(hi) {
        return hi;
    }
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if fits(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// [`generate`] with the axial size of a tube set apart ([`ElementSizes`]).
pub fn generate_sized(shape: &Shape, sizes: ElementSizes, order: u8) -> Result<TetMesh, MeshError> {
    check_proportions(shape)?;
    let h = sizes.h;
    mapped::check_order(order)?;
    // The shape's own lengths are checked before h (a default h follows from them).
    match *shape {
        Shape::Box { size } => {
            for (name, s) in ["size x", "size y", "size z"].into_iter().zip(size) {
                positive(name, s)?;
            }
            positive("h", h)?;
            let cells = size.map(|s| shapes::cells_for(s, h));
            mapped::check_count(mapped::tet_count(cells))?;
            let linear = box_mesh(size, cells);
            Ok(if order == 2 { to_quadratic(&linear) } else { linear })
        }
        Shape::Cylinder { radius, length } => cylinder(radius, length, h, order),
        Shape::Tube { inner_radius, outer_radius, length } => {
            tube_sized(inner_radius, outer_radius, length, h, sizes.axial, order)
        }
        Shape::Sphere { radius } => sphere(radius, h, order),
        Shape::Bowl { radius, thickness } => bowl(radius, thickness, h, order),
    }
}

#[cfg(test)]
mod budget_tests {
    use super::*;

    #[test]
    fn a_shape_thinner_than_a_ten_thousandth_of_its_size_is_refused() {
        let sizes = ElementSizes::uniform(0.01);
        let bowl = Shape::Bowl { radius: 0.06, thickness: 1e-9 };
        let e = generate_sized(&bowl, sizes, 2).expect_err("a 1 nm wall").to_string();
        assert!(e.contains("thinnest dimension (1e-9 m) is below 1/10000 of the largest (0.12 m)"), "{e}");
        let tube = Shape::Tube { inner_radius: 0.01, outer_radius: 0.0100001, length: 0.3 };
        assert!(generate_sized(&tube, sizes, 1).is_err());
        // A 1 m sheet 0.2 mm thick is a real object (checked before any meshing).
        let sheet = Shape::Box { size: [1.0, 2e-4, 1.0] };
        assert!(check_proportions(&sheet).is_ok());
    }

    /// A typo's length (`1e300`, `1e-300`) is refused by name, the shape's
    /// own length before the element size it implies; a count that
    /// overflowed reads as such, not as 18446744073709551615.
    #[test]
    fn lengths_outside_the_range_and_overflowing_counts_are_refused_readably() {
        let tiny = Shape::Box { size: [1e-300; 3] };
        let err = generate_sized(&tiny, tiny.default_sizes(2), 2).unwrap_err().to_string();
        assert!(err.starts_with("invalid parameter `size x`: 1e-300 m is outside"), "{err}");
        let huge = Shape::Sphere { radius: 1e9 };
        assert!(generate_sized(&huge, ElementSizes::uniform(1.0), 2)
            .unwrap_err()
            .to_string()
            .contains("`radius`"));
        let bar = Shape::Box { size: [0.2, 0.02, 0.01] };
        for h in [1e300, 1e-300] {
            let err = generate_sized(&bar, ElementSizes::uniform(h), 2).unwrap_err().to_string();
            assert!(err.contains("`h`") && err.contains("1e-6 ..= 1e4 m"), "{err}");
        }
        let overflow = MeshError::TooManyElements { count: u64::MAX, limit: MAX_GENERATED_TETS }.to_string();
        assert!(
            overflow.contains("more than 1.8e19 tets") && !overflow.contains("18446744073709551615"),
            "{overflow}"
        );
        let at_1e_5 = generate_sized(&bar, ElementSizes::uniform(1e-5), 2).unwrap_err().to_string();
        assert!(at_1e_5.contains("would have 2.400e11 tets"), "{at_1e_5}");
    }

    /// The count is what the generator makes, for every shape.
    #[test]
    fn tet_count_is_the_generated_count() {
        let shapes = [
            Shape::Box { size: [0.15, 0.004, 0.1] },
            Shape::Cylinder { radius: 0.02, length: 0.1 },
            Shape::Tube { inner_radius: 0.012, outer_radius: 0.014, length: 0.3 },
            Shape::Sphere { radius: 0.03 },
            Shape::Bowl { radius: 0.06, thickness: 0.004 },
        ];
        for shape in shapes {
            for h in [0.002, 0.003, 0.004, 0.0075] {
                let sizes = ElementSizes { h, axial: 2.5 * h };
                let made = generate_sized(&shape, sizes, 1).unwrap().cells.len() as u64;
                assert_eq!(shape.tet_count(sizes), made, "{shape:?} at {sizes:?}");
            }
        }
    }

    /// Thin shapes get a size within the budget; compact ones keep the
    /// accuracy study's rule.
    #[test]
    fn thin_shapes_are_meshed_within_the_budget_and_compact_ones_as_before() {
        let short_tube = Shape::Tube { inner_radius: 0.015, outer_radius: 0.02, length: 0.03 };
        for shape in [Shape::Box { size: [0.3, 0.02, 0.012] }, Shape::Sphere { radius: 0.05 }, short_tube] {
            let (thinnest, largest) = shape.extents();
            let accurate = (thinnest / 2.0).min(largest / 4.0);
            assert_eq!(shape.default_sizes(2), ElementSizes::uniform(accurate), "{shape:?}");
        }
        // A tube over the budget: first only longer along the axis.
        let tube = Shape::Tube { inner_radius: 0.015, outer_radius: 0.02, length: 0.1 };
        let sizes = tube.default_sizes(2);
        assert!(
            (sizes.h - 0.0025).abs() < 1e-12 && sizes.axial > sizes.h && sizes.axial <= 0.005,
            "{sizes:?}"
        );
        assert!(tube.tet_count(sizes) <= DEFAULT_MAX_TETS);
        // A long thin chime: twice its 1.5 mm wall around, longer cells along, within the budget.
        let chime = Shape::Tube { inner_radius: 0.0235, outer_radius: 0.025, length: 1.0 };
        let sizes = chime.default_sizes(2);
        let near = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(near(sizes.h, 0.003) && near(sizes.axial, MAX_AXIAL_CELL_PER_WALL * 0.0015), "{sizes:?}");
        let made = generate_sized(&chime, sizes, 1).unwrap().cells.len() as u64;
        assert!(made > DEFAULT_MAX_TETS && made < 11 * DEFAULT_MAX_TETS / 10, "{made} tets");
        let sheet = Shape::Box { size: [0.9, 0.004, 0.6] };
        let bowl = Shape::Bowl { radius: 0.06, thickness: 0.004 };
        for shape in [Shape::Box { size: [0.15, 0.004, 0.1] }, bowl] {
            let h = shape.default_element_size(2);
            let (thinnest, largest) = shape.extents();
            assert!(h > thinnest / 2.0 && h <= largest / 20.0, "{shape:?}: h = {h}");
            let made = generate(&shape, h, 1).unwrap().cells.len();
            assert!(made as u64 <= DEFAULT_MAX_TETS, "{shape:?}: {made} tets at h = {h}");
        }
        // A 10 cm bowl with a 2 mm wall: at most 2 thicknesses wide.
        let wide_bowl = Shape::Bowl { radius: 0.1, thickness: 0.002 };
        assert_eq!(wide_bowl.default_element_size(2), MAX_CURVED_CELL_PER_WALL * 0.002);
        // A 1 mm sheet 1 m wide: at most 4 thicknesses wide, over the budget.
        let foil = Shape::Box { size: [1.0, 0.001, 1.0] };
        assert_eq!(foil.default_element_size(2), MAX_FLAT_CELL_PER_WALL * 0.001);
        // The sheet: one layer through its 4 mm, 4 thicknesses across (the budget
        // alone would allow 16.4 mm): a little over the budget.
        let h = sheet.default_element_size(2);
        assert_eq!(h, MAX_FLAT_CELL_PER_WALL * 0.004);
        let made = generate(&sheet, h, 1).unwrap().cells.len() as u64;
        assert!(made > DEFAULT_MAX_TETS && made < 11 * DEFAULT_MAX_TETS / 10, "{made} tets");
        // Order 1 keeps its rule (linear tets lock in bending: no coarsening).
        assert_eq!(sheet.default_element_size(1), 0.004 / 8.0);
        // A disc (a flat cylinder) is a plate: 20 cm across, 2 mm thick, within the
        // budget at 3 thicknesses (D_min/2 gave 1 mm cells, ≈ 380 000 tets); a
        // 30 cm one 1 mm thick is held at 4 thicknesses, over the budget.
        let disc = Shape::Cylinder { radius: 0.1, length: 0.002 };
        let h = disc.default_element_size(2);
        assert!(h > 0.002 && h <= MAX_FLAT_CELL_PER_WALL * 0.002, "disc: h = {h}");
        assert!(disc.tet_count(ElementSizes::uniform(h)) <= DEFAULT_MAX_TETS);
        let cymbal = Shape::Cylinder { radius: 0.15, length: 0.001 };
        assert_eq!(cymbal.default_element_size(2), MAX_FLAT_CELL_PER_WALL * 0.001);
        // A short thick cylinder keeps D_min/2.
        let puck = Shape::Cylinder { radius: 0.038, length: 0.025 };
        assert_eq!(puck.default_element_size(2), 0.0125);
    }
}
