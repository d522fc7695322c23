//! Writes each target's seeds into `fuzz/corpus/<target>/seed-<n>` (run from the repository root:
//! `cargo run -p drift-fuzz --example write-seeds`). The committed corpora started from these.

fn main() -> std::io::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus");
    let sets = [
        ("blob", drift_fuzz::seeds::blob()),
        ("recording", drift_fuzz::seeds::recording()),
        ("csv", drift_fuzz::seeds::csv()),
        ("corrector", drift_fuzz::seeds::corrector()),
    ];
    for (target, seeds) in sets {
        let dir = root.join(target);
        std::fs::create_dir_all(&dir)?;
        for (n, bytes) in seeds.iter().enumerate() {
            std::fs::write(dir.join(format!("seed-{n}")), bytes)?;
        }
        println!("{target}: {} seeds", seeds.len());
    }
    Ok(())
}
