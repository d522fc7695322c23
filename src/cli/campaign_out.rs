//! Where an import writes: a new campaign folder, made in a temporary folder beside it and renamed
//! at the end, so a failed import leaves nothing.

use std::path::{Path, PathBuf};

use anyhow::Context;
use drift_recording::{write_recording, RECORDINGS_DIR};

/// The temporary folder beside `out` that becomes `out`.
fn staging(out: &Path) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "campaign".into());
    out.with_file_name(format!(".{name}.importing-{}", std::process::id()))
}

/// Refuses an output that exists and is not an empty folder: an import writes a new folder.
pub fn refuse_existing(out: &Path) -> anyhow::Result<()> {
    if out.exists()
        && std::fs::read_dir(out)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true)
    {
        anyhow::bail!(
            "{}: exists and is not an empty folder (an import writes a new campaign folder)",
            out.display()
        );
    }
    Ok(())
}

/// Writes `recordings` (file stem, recording) and `import.json` (`manifest` with the recordings
/// listed) into a temporary folder beside `out`, renamed to `out` at the end; on any error the
/// temporary folder is removed and `out` is not made. Returns a line per recording.
pub fn write_campaign(
    out: &Path,
    recordings: &[(String, drift_recording::Recording)],
    manifest: &serde_json::Value,
) -> anyhow::Result<Vec<String>> {
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    let stage = staging(out);
    let result = write_all(&stage, recordings, manifest).and_then(|lines| {
        std::fs::rename(&stage, out)
            .with_context(|| format!("renaming {} to {}", stage.display(), out.display()))?;
        Ok(lines)
    });
    if result.is_err() {
        // Best effort: the folder may not even exist.
        let _ = std::fs::remove_dir_all(&stage);
    }
    result
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
