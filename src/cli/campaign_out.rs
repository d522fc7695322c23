//! Where an import writes: a campaign folder, made in a staging folder beside it and put in place
//! at the end, so a failed import leaves nothing and an earlier import stays whole.

use std::path::Path;

use anyhow::Context;
use drift_recording::output_folder::{Owned, Writer};
use drift_recording::{write_recording, RECORDINGS_DIR};

/// `import` as a writer of output folders: every format's import is a campaign folder.
pub const WRITER: Writer = Writer {
    command: "import",
    product: "import",
    doing: "importing",
    owned: Owned::Marker,
};

/// Refuses an output folder that holds anything but an earlier import, and an earlier import
/// unless `force`: checked before any reading, so a long import is not refused at its end.
pub fn refuse_existing(out: &Path, force: bool) -> anyhow::Result<()> {
    drift_recording::output_folder::check(out, force, "--force", &WRITER)?;
    Ok(())
}

/// Writes `recordings` (file stem, recording) and `import.json` (`manifest` with the recordings
/// listed) into a staging folder beside `out` that replaces `out` at the end (an earlier import
/// there only if `force`); on any error `out` stays as it was. Returns a line per recording.
pub fn write_campaign(
    out: &Path,
    force: bool,
    recordings: &[(String, drift_recording::Recording)],
    manifest: &serde_json::Value,
) -> anyhow::Result<Vec<String>> {
    let staged = super::interrupt::stage(out, force, &WRITER)?;
    let lines = write_all(staged.path(), recordings, manifest)?;
    staged.commit()?;
    Ok(lines)
}

fn write_all(
    stage: &Path,
    recordings: &[(String, drift_recording::Recording)],
    manifest: &serde_json::Value,
) -> anyhow::Result<Vec<String>> {
    let folder = stage.join(RECORDINGS_DIR);
    std::fs::create_dir_all(&folder).with_context(|| format!("creating {}", folder.display()))?;
    let mut listed = Vec::new();
    let mut lines = Vec::new();
    for (stem, recording) in recordings {
        let name = format!("{stem}.mcap");
        let bytes = write_recording(recording, &folder.join(&name))?;
        let samples: usize = recording.segments.iter().map(|s| s.len()).sum();
        let fs = f64::from(recording.sample_rate_hz);
        lines.push(format!(
            "{name}: {} activations, {samples} samples at {} Hz ({:.1} s), {bytes} bytes",
            recording.segments.len(),
            recording.sample_rate_hz,
            samples as f64 / fs
        ));
        listed.push(serde_json::json!({
            "recording": format!("{RECORDINGS_DIR}/{name}"),
            "unit_id": recording.unit_id,
            "metadata": recording.metadata,
            "activations": recording.segments.iter().map(|s| serde_json::json!({
                "labels": s.labels,
                "switch_on_s": s.power_on_ns as f64 / 1e9,
                "samples": s.len(),
                "duration_s": s.len() as f64 / fs,
                "aux": s.aux.iter().map(|(k, c)| (k.clone(), c.values.len())).collect::<std::collections::BTreeMap<_, _>>(),
            })).collect::<Vec<_>>(),
        }));
    }
    let mut json = manifest.clone();
    json["recordings"] = serde_json::Value::Array(listed);
    std::fs::write(
        stage.join("import.json"),
        serde_json::to_string_pretty(&json)?,
    )
    .with_context(|| format!("writing {}", stage.join("import.json").display()))?;
    Ok(lines)
}
