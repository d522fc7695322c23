//! Replays every committed fuzz corpus file (`fuzz/corpus/<target>/*`) and every finding
//! (`fuzz/regressions/<target>/*`) through the same target
//! function cargo-fuzz runs, on stable: what the fuzzer once found keeps being checked by
//! `cargo test`. Also runs the seeds, so a format change that breaks them is noticed here.

use std::path::Path;

#[test]
fn every_corpus_file_passes_its_target() {
    replay("corpus", true);
}

/// The inputs that found each bug (`fuzz/regressions/<target>/finding-*`), kept apart from the
/// corpus because `cargo fuzz cmin` drops inputs that add no coverage.
#[test]
fn every_finding_passes_its_target() {
    replay("regressions", false);
}

fn replay(folder: &str, every_target: bool) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz")
        .join(folder);
    let mut total = 0;
    for (target, run) in drift_fuzz::TARGETS {
        let dir = root.join(target);
        if !every_target && !dir.exists() {
            continue;
        }
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|entry| entry.map(|e| e.path()))
            .collect::<Result<_, _>>()
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        files.sort();
        assert!(!files.is_empty(), "{}: empty corpus", dir.display());
        for file in &files {
            let bytes = std::fs::read(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
            // Name the file if the target panics: that file is the reproducer.
            let outcome = std::panic::catch_unwind(|| run(&bytes));
            assert!(
                outcome.is_ok(),
                "{target}: {} fails (reproduce: cargo +nightly fuzz run {target} {})",
                file.display(),
                file.display()
            );
        }
        println!("{target}: {} {folder} files", files.len());
        total += files.len();
    }
    assert!(total > 0);
}

#[test]
fn seeds_pass_their_targets() {
    let sets = [
        ("blob", drift_fuzz::seeds::blob()),
        ("recording", drift_fuzz::seeds::recording()),
        ("csv", drift_fuzz::seeds::csv()),
        ("corrector", drift_fuzz::seeds::corrector()),
    ];
    for (target, seeds) in sets {
        let run = drift_fuzz::TARGETS
            .iter()
            .find(|(t, _)| *t == target)
            .map(|(_, f)| *f)
            .unwrap_or_else(|| panic!("{target}"));
        for seed in &seeds {
            run(seed);
        }
    }
}
