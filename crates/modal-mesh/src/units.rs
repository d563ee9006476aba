//! Is a mesh file in metres? Mesh files carry no unit (OBJ, STL, PLY, OFF,
//! Gmsh, TetGen, Medit), yet 3D printing and CAD write millimetres, and some
//! tools centimetres or inches. Read as metres, a 12 cm mug written in
//! millimetres is a 120 m object: its modes lie a thousand times lower, far
//! below the audible band, and an eigen solve for that band runs minutes into
//! a cluster of near-zero modes before it fails. The size of the object is
//! the only clue, so it is judged here once for every reader.

/// The largest bounding-box diagonal [m] taken as metres without a word: a
/// sounding object larger than this (a bus, a bridge span) is rare, while any
/// object of more than 20 mm written in millimetres lands above it.
pub const LARGEST_PLAIN_DIAGONAL_M: f64 = 20.0;

/// The largest bounding-box diagonal [m] taken as metres without a warning:
/// a file in centimetres or inches of an object of 10–20 cm, or in millimetres
/// of a bead, lands between this and [`LARGEST_PLAIN_DIAGONAL_M`] (a 12 cm mug
/// in inches: 6.9 m, 24 t, its modes 40× too low), where real objects are rare
/// but exist (a 3 m beam), so it is said, not refused.
pub const LARGEST_UNREMARKED_DIAGONAL_M: f64 = 2.5;

/// The smallest bounding-box diagonal [m] taken as metres without a word: a
/// smaller object (a file in kilometres, or metres mistaken for millimetres)
/// rings above any audio band.
pub const SMALLEST_PLAIN_DIAGONAL_M: f64 = 0.005;

/// `x` as one would type it, for quoting a user's value back in a message:
/// `1.21`, `343`, `0.5`, but `1e300` and `1e-300` rather than hundreds of
/// digits (Rust's `{}` writes every digit of an f64).
pub fn readable(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The range of scale factors accepted, stated or not: a scale converts a
/// file's unit to metres, from micrometres (10⁻⁶) to kilometres (10³) and
/// a margin beyond. Outside it no conversion is meant (`--scale 1e300`
/// overflowed every coordinate and ended in "every triangle has zero area").
pub const SCALE_RANGE: std::ops::RangeInclusive<f64> = 1e-6..=1e6;

/// Why `factor` cannot be a mesh file's scale, if it cannot: not a positive
/// number, or outside [`SCALE_RANGE`]. Phrased to follow the key's name
/// (`--scale`, `scale`).
pub fn scale_refusal(factor: f64) -> Option<String> {
    if !(factor.is_finite() && factor > 0.0) {
        return Some(format!("must be a positive number, got {factor}"));
    }
    (!SCALE_RANGE.contains(&factor)).then(|| {
        format!(
            "= {factor:e} is no unit conversion: a scale turns a file's unit into metres (0.001 for \
             millimetres, 0.0254 for inches) and lies between {:e} and {:e}",
            SCALE_RANGE.start(),
            SCALE_RANGE.end()
        )
    })
}

/// The bounding box (lower corner, upper corner) of `points`; (+∞, −∞) when
/// there are none.
pub fn bounding_box(points: impl IntoIterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    points.into_iter().fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), p| {
        (std::array::from_fn(|c| lo[c].min(p[c])), std::array::from_fn(|c| hi[c].max(p[c])))
    })
}

/// The diagonal of the axis-aligned bounding box of `points` [m]; 0 for none.
pub fn bounding_diagonal(points: &[[f64; 3]]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let (lo, hi) = bounding_box(points.iter().copied());
    (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt()
}

/// A warning when an object's bounding-box diagonal `diagonal_m` suggests its
/// file is not in metres, naming the `--scale` that would fix it.
pub fn unit_warning(diagonal_m: f64) -> Option<String> {
    if diagonal_m > LARGEST_PLAIN_DIAGONAL_M {
        Some(format!(
            "the bounding box diagonal is {diagonal_m:.4} m: if the file is in millimetres use --scale 0.001, in centimetres --scale 0.01"
        ))
    } else if diagonal_m > LARGEST_UNREMARKED_DIAGONAL_M {
        Some(format!(
            "the object is {diagonal_m:.2} m across (bounding-box diagonal): if the file is not in metres, give its \
             scale (--scale 0.01 for centimetres, 0.0254 for inches, 0.001 for millimetres)"
        ))
    } else if diagonal_m > 0.0 && diagonal_m < SMALLEST_PLAIN_DIAGONAL_M {
        Some(format!(
            "the bounding box diagonal is only {:.4} mm: check the file's units and use --scale if it is not in metres",
            diagonal_m * 1e3
        ))
    } else {
        None
    }
}

/// Why an object of diagonal `diagonal_m` whose scale nobody stated is not
/// solved: `Some(message)` above [`LARGEST_PLAIN_DIAGONAL_M`]. Said before
/// the work, because the solve of such a file fails only after minutes (see
/// the module doc). A stated scale (`--scale 1`) takes any size as meant.
pub fn unstated_size_refusal(diagonal_m: f64) -> Option<String> {
    (diagonal_m > LARGEST_PLAIN_DIAGONAL_M).then(|| {
        format!(
            "the object is {diagonal_m:.1} m across (bounding-box diagonal) and mesh files carry no unit: if the \
             file is in millimetres give it a scale of 0.001 (--scale 0.001, or `scale = 0.001` in a scene or \
             manifest), in centimetres 0.01, in inches 0.0254; to solve it at this size, state the scale \
             (--scale 1)"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readable_numbers_are_short() {
        assert_eq!(readable(1e300), "1e300");
        assert_eq!(readable(-1e-300), "-1e-300");
        assert_eq!(readable(343.0), "343");
        assert_eq!(readable(0.0), "0");
        assert_eq!(readable(f64::NAN), "NaN");
        assert_eq!(readable(2.5e6), "2.5e6");
    }

    #[test]
    fn only_unit_conversions_are_scales() {
        for factor in [1e-6, 0.001, 0.0254, 1.0, 1000.0, 1e6] {
            assert_eq!(scale_refusal(factor), None, "{factor}");
        }
        for factor in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(
                scale_refusal(factor).is_some_and(|w| w.starts_with("must be a positive number")),
                "{factor}"
            );
        }
        for factor in [1e300, 1e-300, 2e6, 5e-7] {
            let why = scale_refusal(factor).expect("refused");
            assert!(why.contains("no unit conversion") && why.contains(&format!("{factor:e}")), "{why}");
        }
    }

    #[test]
    fn a_millimetre_mug_is_refused_and_a_metre_one_is_not() {
        let mug_m = [[0.0, 0.0, 0.0], [0.12, 0.09, 0.1]];
        let mug_mm = mug_m.map(|p| p.map(|x| x * 1000.0));
        let (d_m, d_mm) = (bounding_diagonal(&mug_m), bounding_diagonal(&mug_mm));
        assert!((d_mm - 1000.0 * d_m).abs() < 1e-9 * d_mm);
        assert_eq!(unstated_size_refusal(d_m), None);
        assert_eq!(unit_warning(d_m), None);
        let refusal = unstated_size_refusal(d_mm).expect("a 180 m mug is refused");
        assert!(refusal.contains("--scale 0.001") && refusal.contains("180.3 m across"), "{refusal}");
        assert!(unit_warning(d_mm).is_some_and(|w| w.contains("--scale 0.001")));
    }

    #[test]
    fn a_mug_in_inches_is_warned_about_and_a_metre_object_is_not() {
        let mug_inches = bounding_diagonal(&[[0.0; 3], [4.7, 3.5, 3.9]]);
        assert_eq!(unstated_size_refusal(mug_inches), None);
        assert!(unit_warning(mug_inches).is_some_and(|w| w.contains("0.0254") && w.contains("7.04 m across")));
        // A dataset's object normalized to the unit cube is taken as it is.
        assert_eq!(unit_warning(bounding_diagonal(&[[0.0; 3], [1.0; 3]])), None);
    }

    #[test]
    fn a_tiny_object_is_warned_about_not_refused() {
        let bead = [[0.0; 3], [0.001, 0.001, 0.001]];
        let d = bounding_diagonal(&bead);
        assert_eq!(unstated_size_refusal(d), None);
        assert!(unit_warning(d).is_some_and(|w| w.contains("check the file's units")));
        assert_eq!(bounding_diagonal(&[]), 0.0);
    }
}
