//! End-to-end runs of the `gyrodrift` binary.

use std::process::{Command, Stdio};

use drift_core::blob::decode;
use drift_core::{ModifiedTables, PolynomialTables};

fn gyrodrift() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
}

#[test]
fn simulate_fit_and_report_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let campaign = dir.path().join("campaign");
    let run = |args: &[&str]| {
        let out = gyrodrift().args(args).output().unwrap();
        let text = format!(
            "{}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(out.status.success(), "{args:?}: {text}");
        text
    };
    let c = campaign.to_str().unwrap();
    run(&[
        "simulate",
        "-q",
        "-o",
        c,
        "--units",
        "1",
        "--set-points",
        "30,40,33",
        "--intervals",
        "1,30",
        "--repeats",
        "2",
        "--seed",
        "3",
    ]);
    let tables = dir.path().join("tables");
    let text = run(&["fit", c, "-q", "-o", tables.to_str().unwrap()]);
    assert!(text.contains("GIU-01: 5 curves"), "{text}");
    // Standard output closed before the command prints (`gyrodrift … | head`): one line that says
    // so, not a panic report.
    let mut child = gyrodrift()
        .args([
            "fit",
            c,
            "-q",
            "-o",
            dir.path().join("again").to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("broken pipe") && !stderr.contains("panicked"),
        "{stderr}"
    );
    let modified = std::fs::read(tables.join("GIU-01/modified.bin")).unwrap();
    let decoded: ModifiedTables = decode(&modified).unwrap();
    let json: ModifiedTables = serde_json::from_str(
        &std::fs::read_to_string(tables.join("GIU-01/modified.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(decoded, json);
    // The image states the recordings' sample rate, for firmware to check its own against.
    assert_eq!(decoded.settings.sample_rate_hz, 1000.0);
    for name in ["standard", "third_order"] {
        let bytes = std::fs::read(tables.join(format!("GIU-01/{name}.bin"))).unwrap();
        assert!(decode::<PolynomialTables>(&bytes).is_ok(), "{name}");
    }
    let bytes = std::fs::read(tables.join("GIU-01/relative.bin")).unwrap();
    assert!(decode::<drift_core::RelativePolynomialTables>(&bytes).is_ok());
    let report = dir.path().join("report");
    let text = run(&["report", c, "-q", "-o", report.to_str().unwrap()]);
    assert!(text.contains("| +33 °C | validation |"), "{text}");
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(
        md.contains("## Drift per unit and axis (the paper's Table)")
            && md.contains("fig-correlation.svg"),
        "{md}"
    );
    assert!(report.join("fig-correlation.svg").exists() && report.join("report.json").exists());
    // σ(t), fitted on the held-out repeats, checked on the validation set point; the firmware
    // section in the tables folder is the same σ as its JSON.
    assert!(md.contains("## Residual uncertainty σ(t)"), "{md}");
    let sigma: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("uncertainty.json")).unwrap()).unwrap();
    let validation = &sigma[0]["coverage"][0];
    assert_eq!(validation["split"], "validation", "{sigma}");
    assert!(
        validation["classes"][0]["samples"].as_u64().unwrap() > 0,
        "{sigma}"
    );
    // The oracles count the same activations as the coverage they explain.
    for oracle in ["oracle", "split_half"] {
        assert_eq!(
            validation[oracle][0]["axis_activations"], validation["classes"][0]["axis_activations"],
            "{sigma}"
        );
    }
    assert!(md.contains("split-half oracle"), "{md}");
    let section = std::fs::read(report.join("tables/GIU-01/uncertainty.bin")).unwrap();
    let json: drift_core::Uncertainty = serde_json::from_str(
        &std::fs::read_to_string(report.join("tables/GIU-01/uncertainty.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(drift_core::blob::decode_section(&section).unwrap(), json);
    // The coverage map: a figure per unit, every calibration activation in a cell, and the
    // validation data's share outside the envelope.
    assert!(md.contains("## Coverage of the calibration"), "{md}");
    assert!(report.join("fig-coverage-GIU-01.svg").exists());
    let coverage: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("coverage.json")).unwrap()).unwrap();
    let unit = &coverage[0];
    let in_cells: u64 = unit["cells"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["calibration_activations"].as_u64().unwrap())
        .sum();
    assert_eq!(
        in_cells,
        unit["calibration_activations"].as_u64().unwrap(),
        "{unit}"
    );
    assert!(in_cells > 0, "{unit}");
    assert_eq!(unit["outside"][0]["split"], "validation", "{unit}");
    // The headline names the best baseline; the absolute error stands beside the drift, its
    // flags on the first page, before the paper's table.
    assert!(md.contains("best baseline / modified"), "{md}");
    let flags = md
        .find("## Absolute error: where the paper's model is worse")
        .expect("absolute-error flags");
    assert!(
        flags < md.find("## Drift per unit and axis").unwrap(),
        "{md}"
    );
    assert!(md.contains("## Absolute error\n"), "{md}");
    let cells: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("absolute_error.json")).unwrap())
            .unwrap();
    let cell = &cells[0];
    assert!(
        cell["modified"]["mean_dps"].as_f64().unwrap() > 0.0,
        "{cell}"
    );
    assert!(cell["best_baseline"].is_string(), "{cell}");
    let diagnosis = dir.path().join("diagnosis");
    let text = run(&["diagnose", c, "-q", "-o", diagnosis.to_str().unwrap()]);
    assert!(text.contains("GIU-01:") && text.contains("  X: "), "{text}");
    let md = std::fs::read_to_string(diagnosis.join("diagnosis.md")).unwrap();
    assert!(md.contains("absorbed by the model"), "{md}");
    // No field sessions: nothing to choose stage 3 on, and the report says so.
    assert!(
        md.contains("stage 3 keeps the paper's lookup by rise"),
        "{md}"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(diagnosis.join("diagnosis.json")).unwrap()).unwrap();
    let unit = &json[0];
    assert!(unit["crossings"].is_array(), "{unit}");
    assert_eq!(unit["stage3"].as_array().map(Vec::len), Some(3), "{unit}");
    // Nor the initial bias: the paper's on every axis.
    let warm_start = unit["warm_start"].as_array().unwrap();
    assert_eq!(warm_start.len(), 3, "{unit}");
    assert!(
        warm_start
            .iter()
            .all(|c| c["training_activations"] == 0 && c["chosen"] == false),
        "{unit}"
    );
    assert!(
        unit["axes"][0]["ranking"][0]["whole_p_value"].is_number(),
        "{unit}"
    );
    // The loop kept the paper's model: what it lacked is what is left, and said once.
    assert_eq!(unit["paper_axes"], unit["axes"], "{unit}");
    assert!(!md.contains("What the paper's model lacked"), "{md}");
    // The residual plots follow the ranking they show, before the next section.
    let at = |text: &str| {
        md.find(text)
            .unwrap_or_else(|| panic!("no `{text}` in {md}"))
    };
    let plot = at("![Residual of unit GIU-01, axis X");
    assert!(
        at("## Diagnosis of the residual after the loop's model") < plot
            && plot < at("## Where within the held-out activations"),
        "{md}"
    );
    assert!(diagnosis.join("residual-GIU-01-X.svg").exists());
    // Where within the held-out activations the residual sits: every held-out activation, per
    // axis one value per bin, and the section's table for the protocol at +33 °C.
    let profiles = unit["profiles"].as_array().unwrap();
    assert!(!profiles.is_empty(), "{unit}");
    for p in profiles {
        let axes = p["after_dps"].as_array().unwrap();
        assert!(
            axes.len() == 3 && axes.iter().all(|a| a.as_array().unwrap().len() == 12),
            "{p}"
        );
    }
    assert!(
        md.contains("## Where within the held-out activations the residual sits")
            && md.contains("| protocol (")
            && md.contains("| 0–1 s | 1–2 s |"),
        "{md}"
    );
    // Closing the loop on a campaign without field sessions: the section says what it could do.
    let extended = dir.path().join("extended");
    let text = run(&[
        "diagnose",
        c,
        "-q",
        "--extend",
        "-o",
        extended.to_str().unwrap(),
    ]);
    let md = std::fs::read_to_string(extended.join("diagnosis.md")).unwrap();
    assert!(md.contains("## Extended model of unit GIU-01"), "{md}");
    // The console says the outcome too, in one line, not only the file.
    let verdict = text
        .lines()
        .find(|l| l.starts_with("  extended model: "))
        .unwrap_or_else(|| panic!("no extended-model line in {text}"));
    assert!(
        verdict.ends_with("the paper's model unchanged")
            || verdict.ends_with("keyed by history")
            || verdict.contains("admitted "),
        "{verdict}"
    );
    assert!(
        !verdict.contains("admitted ") || md.contains("extended-GIU-01.bin"),
        "{verdict}"
    );
}

#[test]
fn fit_names_a_missing_campaign_folder() {
    let out = gyrodrift()
        .args(["fit", "/nonexistent/campaign", "-q"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("/nonexistent/campaign"), "{stderr}");
}

#[test]
fn atomic_write_leaves_the_old_file_when_it_fails() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("table.bin");
    drift_report::write_atomic(&path, b"first").unwrap();
    drift_report::write_atomic(&path, b"second").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"second");
    // A target that is a directory cannot be replaced: the error names it, nothing else is left.
    let target = dir.path().join("occupied");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"x").unwrap();
    let error = drift_report::write_atomic(&target, b"data").unwrap_err();
    assert!(format!("{error:#}").contains("occupied"), "{error:#}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "temporary file left behind: {left:?}");
}
