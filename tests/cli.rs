//! End-to-end runs of the `gyrodrift` binary.

use std::process::Command;

use drift_core::blob::decode;
use drift_core::{ModifiedTables, PolynomialTables};

fn gyrodrift() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
}

#[test]
fn demo_checks_the_vectors_and_writes_decodable_images() {
    let dir = tempfile::tempdir().unwrap();
    let out = gyrodrift()
        .args(["demo", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("outputs differing from the shared vectors: 0"),
        "{stdout}"
    );
    let modified = std::fs::read(dir.path().join("modified.bin")).unwrap();
    let tables: ModifiedTables = decode(&modified).unwrap();
    assert_eq!(tables.axes[0].ambients.len(), 3);
    for name in ["standard", "third_order"] {
        let bytes = std::fs::read(dir.path().join(format!("{name}.bin"))).unwrap();
        assert!(decode::<PolynomialTables>(&bytes).is_ok(), "{name}");
    }
}

#[test]
fn demo_reports_an_unwritable_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, b"not a folder").unwrap();
    let out = gyrodrift()
        .args(["demo", "--out"])
        .arg(blocker.join("sub"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("creating directory"), "{stderr}");
}

#[test]
fn atomic_write_leaves_the_old_file_when_it_fails() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("table.bin");
    gyrodrift::output::write_atomic(&path, b"first").unwrap();
    gyrodrift::output::write_atomic(&path, b"second").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"second");
    // A target that is a directory cannot be replaced: the error names it, nothing else is left.
    let target = dir.path().join("occupied");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"x").unwrap();
    let error = gyrodrift::output::write_atomic(&target, b"data").unwrap_err();
    assert!(format!("{error:#}").contains("occupied"), "{error:#}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "temporary file left behind: {left:?}");
}
