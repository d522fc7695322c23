//! A failing `gyrodrift fit` or `report` leaves nothing half-written: no new output folder, an
//! existing output untouched byte for byte, no temporary files; the error names the bad file.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use drift_sim::{simulate_campaign, Campaign, Protocol};

fn gyrodrift() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries {
            let path = entry.unwrap().path();
            if path.is_dir() {
                for (k, v) in snapshot(&path) {
                    out.insert(
                        format!("{}/{k}", path.file_name().unwrap().to_string_lossy()),
                        v,
                    );
                }
            } else {
                out.insert(
                    path.file_name().unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&path).unwrap(),
                );
            }
        }
    }
    out
}

/// A tiny campaign whose +40 °C recording is cut in half (a bench that crashed while writing).
fn broken_campaign(dir: &Path) -> std::path::PathBuf {
    let c = Campaign {
        units: 1,
        set_points_celsius: vec![30.0, 40.0],
        protocol: Some(Protocol {
            intervals_min: vec![1.0],
            repeats: 1,
            activations: 2,
            activation_s: 20.0,
            ..Protocol::default()
        }),
        ..Campaign::default()
    };
    let summary = simulate_campaign(&c, dir, |_| {}).unwrap();
    let victim = summary
        .files
        .iter()
        .find(|f| f.set_point_celsius == 40.0)
        .unwrap()
        .recording
        .clone();
    let bytes = std::fs::read(&victim).unwrap();
    std::fs::write(&victim, &bytes[..bytes.len() / 2]).unwrap();
    victim
}

fn fails(args: &[&str]) -> String {
    let out = gyrodrift().args(args).output().unwrap();
    assert!(!out.status.success(), "{args:?} succeeded");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn a_failing_fit_or_report_leaves_no_output_and_keeps_an_existing_one() {
    let dir = tempfile::tempdir().unwrap();
    let campaign = dir.path().join("campaign");
    let victim = broken_campaign(&campaign);
    let c = campaign.to_str().unwrap();

    // No output folder appears.
    let fresh = dir.path().join("fresh");
    let stderr = fails(&["fit", c, "-q", "-o", fresh.to_str().unwrap()]);
    assert!(
        stderr.contains(&*victim.file_name().unwrap().to_string_lossy()),
        "{stderr}"
    );
    assert!(!fresh.exists(), "fit created {}", fresh.display());
    let stderr = fails(&["report", c, "-q", "-o", fresh.to_str().unwrap()]);
    assert!(stderr.contains("sp+40.0C"), "{stderr}");
    assert!(!fresh.exists(), "report created {}", fresh.display());

    // An existing output is untouched, and no temporary file is left beside it.
    let old = dir.path().join("old");
    std::fs::create_dir_all(old.join("GIU-01")).unwrap();
    std::fs::write(old.join("GIU-01/modified.json"), b"{\"previous\": true}").unwrap();
    std::fs::write(old.join("report.md"), b"# previous report\n").unwrap();
    let before = snapshot(&old);
    fails(&["fit", c, "-q", "-o", old.to_str().unwrap()]);
    fails(&["report", c, "-q", "-o", old.to_str().unwrap()]);
    assert_eq!(snapshot(&old), before);
}

#[test]
fn an_unwritable_table_folder_writes_nothing() {
    // The unit's folder is occupied by a file: the first write fails, naming it, and because every
    // table is encoded before the first write, no other file appears.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tables");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("GIU-01"), b"not a folder").unwrap();
    let fitted = drift_fit_unit();
    let error = drift_evaluate::tables_folder::write(&out, &[fitted]).unwrap_err();
    assert!(format!("{error:#}").contains("GIU-01"), "{error:#}");
    assert_eq!(
        snapshot(&out).len(),
        1,
        "{:?}",
        snapshot(&out).keys().collect::<Vec<_>>()
    );
    assert_eq!(std::fs::read(out.join("GIU-01")).unwrap(), b"not a folder");
}

/// A fitted unit from a tiny noise-free campaign.
fn drift_fit_unit() -> drift_fit::FittedUnit {
    let dir = tempfile::tempdir().unwrap();
    let c = Campaign {
        units: 1,
        noise_scale: 0.0,
        set_points_celsius: vec![30.0, 40.0],
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 30.0],
            repeats: 1,
            activations: 3,
            ..Protocol::default()
        }),
        ..Campaign::default()
    };
    simulate_campaign(&c, dir.path(), |_| {}).unwrap();
    let files = drift_evaluate::pipeline::recording_files(dir.path()).unwrap();
    let options = drift_evaluate::pipeline::Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: vec![],
        fit: drift_fit::FitSettings::default(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    };
    drift_evaluate::pipeline::run(&files, &options, false, drift_recording::QUIET)
        .unwrap()
        .fitted
        .remove(0)
}
