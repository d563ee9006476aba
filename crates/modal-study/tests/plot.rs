//! The PNG plot writer: a valid file for real data, a clear error for none.

use modal_study::plot::{write_loglog_png, LogLogPlot, PlotError, Series};

/// A directory removed when the test ends (a fixed name under /tmp was left
/// behind by every run).
fn scratch() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

#[test]
fn writes_a_png_with_two_series() {
    let series = [
        Series { label: "TET4".into(), points: vec![(0.01, 0.3), (0.1, 0.08), (1.0, 0.02)] },
        Series { label: "TET10".into(), points: vec![(0.02, 0.01), (0.2, 1e-3), (2.0, 1e-4), (3.0, 0.0)] },
    ];
    let plot = LogLogPlot {
        title: "bar: error vs time",
        x_label: "time (s)",
        y_label: "max rel. error",
        series: &series,
    };
    let dir = scratch();
    let path = dir.path().join("two.png");
    write_loglog_png(&path, &plot).expect("plot written");
    let bytes = std::fs::read(&path).expect("read back");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert!(bytes.len() > 5_000 && bytes.len() < 300_000, "plausible size, got {}", bytes.len());
    // Width and height from the IHDR chunk.
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (960, 640));
    // No temporary file is left next to it.
    let leftovers = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().contains(".tmp"))
        .count();
    assert_eq!(leftovers, 0);
}

#[test]
fn rejects_plots_without_positive_data() {
    let dir = scratch();
    let path = dir.path().join("none.png");
    let empty = LogLogPlot { title: "empty", x_label: "x", y_label: "y", series: &[] };
    let err = write_loglog_png(&path, &empty).unwrap_err();
    assert!(matches!(err, PlotError::NoData { .. }), "{err}");
    let bad =
        [Series { label: "bad".into(), points: vec![(0.0, 1.0), (-1.0, 2.0), (f64::NAN, 1.0), (1.0, -3.0)] }];
    let plot = LogLogPlot { title: "non-positive", x_label: "x", y_label: "y", series: &bad };
    let err = write_loglog_png(&path, &plot).unwrap_err();
    assert_eq!(err.to_string(), "plot 'non-positive' has no positive finite data point to draw on log axes");
    assert!(!path.exists(), "no file for a rejected plot");
}
