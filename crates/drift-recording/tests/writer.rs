//! The writer leaves nothing half-written: a file that cannot be put in place leaves no temporary
//! behind and the target untouched (dropping an unfinished writer is tested in drift-sim).

use std::collections::BTreeMap;

use drift_recording::create_recording;

#[test]
fn a_failed_rename_leaves_no_temporary_and_the_target_untouched() {
    let dir = tempfile::tempdir().unwrap();
    // The target is a non-empty folder: the final rename must fail.
    let target = dir.path().join("bench.mcap");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"x").unwrap();
    let meta = BTreeMap::from([
        ("unit_id".to_owned(), "U".to_owned()),
        ("sample_rate_hz".to_owned(), "1000".to_owned()),
    ]);
    let f = create_recording(&target, meta).unwrap();
    let error = f.finish().unwrap_err().to_string();
    assert!(error.contains("bench.mcap"), "{error}");
    let left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["bench.mcap"], "temporary left behind");
    assert_eq!(std::fs::read(target.join("keep")).unwrap(), b"x");
}
