//! A requested stop refuses new atomic writes and keeps none it came during
//! (its own test binary: the stop is process-wide).

use std::io::Write;

#[test]
fn after_a_stop_request_no_write_starts_and_nothing_is_left_behind() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.bin");
    modal_bank::write_file_atomically(&path, |f| f.write_all(b"before")).unwrap();
    assert_eq!(modal_bank::writes_in_progress(), 0);
    // A stop that comes while a file is written: it is finished, then dropped.
    let other = dir.path().join("b.bin");
    let err = modal_bank::write_file_atomically(&other, |f| {
        f.write_all(b"half")?;
        modal_bank::request_stop();
        f.write_all(b" and the rest")
    })
    .unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::Interrupted);
    assert!(!other.exists(), "a write the stop came during is not renamed into place");
    let err = modal_bank::write_file_atomically(&path, |f| f.write_all(b"after")).unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::Interrupted);
    assert_eq!(std::fs::read(&path).unwrap(), b"before");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, ["a.bin"], "no temporary file");
    assert_eq!(modal_bank::writes_in_progress(), 0);
}
