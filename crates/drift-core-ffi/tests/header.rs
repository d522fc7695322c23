//! The committed C header is what cbindgen makes of the sources: a changed signature, type or
//! constant fails here until the header is regenerated (`GYRODRIFT_BLESS=1`).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

#[test]
fn the_committed_header_matches_the_sources() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen reads the crate")
        .write(&mut generated);
    let path = crate_dir.join("include/gyrodrift.h");
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read(&path).unwrap();
    assert!(
        committed == generated,
        "{} differs from what cbindgen generates: rerun with GYRODRIFT_BLESS=1 and review the diff",
        path.display()
    );
}
