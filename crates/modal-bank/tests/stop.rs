//! A requested stop refuses new atomic writes and lets none start half-way
//! (its own test binary: the stop is process-wide).

use std::io::Write;

#[test]
fn after_a_stop_request_no_write_starts_and_nothing_is_left_behind() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.bin");
    modal_bank::write_file_atomically(&path, |f| f.write_all(b"before")).unwrap();
    assert_eq!(modal_bank::writes_in_progress(), 0);
    modal_bank::request_stop();
    let err = modal_bank::write_file_atomically(&path, |f| f.write_all(b"after")).unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::Interrupted);
    assert_eq!(std::fs::read(&path).unwrap(), b"before");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, ["a.bin"], "no temporary file");
    assert_eq!(modal_bank::writes_in_progress(), 0);
}
