//! `gyrodrift report --calibration-data A --evaluation-data B`: fit on one source, judge on
//! another. Its numbers equal the library path Python's `fit` + `FittedUnit.evaluate_series` take
//! (analyse the protocol activations at the calibration set points, `fit_unit`, then per recording
//! `kept_before` + `evaluate_after`, summarised); a zero-drift twin recorded only at the
//! evaluation set points gives the noise floor, with or without a separate evaluation source.

use std::path::Path;

use drift_evaluate::evaluate::{evaluate_after, kept_before};
use drift_evaluate::summary::{summarise, Split};
use drift_fit::analyse::analyse;
use drift_fit::fit::fit_unit;
use drift_fit::FitSettings;
use drift_recording::{read_campaign_dir, SeriesKind};

mod common;

use common::{gyrodrift, ok};

fn simulate(dir: &Path, name: &str, set_points: &str, extra: &[&str]) -> String {
    let toml = dir.join(format!("{name}.toml"));
    std::fs::write(
        &toml,
        format!(
            "seed = 3\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [{set_points}]\n\
             [protocol]\nintervals_min = [1, 30]\nrepeats = 2\nactivation_s = 60\n"
        ),
    )
    .unwrap();
    let out = dir.join(name);
    let mut args = vec![
        "simulate",
        "-q",
        "--campaign",
        toml.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    ok(&args);
    out.to_str().unwrap().to_owned()
}

#[test]
fn report_fits_on_one_source_and_judges_on_another_as_the_library_path_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = simulate(d, "calibration", "30, 40, 33", &[]);
    let b = simulate(d, "evaluation", "33, 35", &[]);
    let twin = simulate(d, "twin", "33", &["--zero-drift"]);
    let out = d.join("report");
    let text = ok(&[
        "report",
        "-q",
        "--calibration-data",
        &a,
        "--evaluation-data",
        &b,
        "--noise-floor",
        &twin,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        text.contains("| +33 °C | validation |") && text.contains("| +35 °C | validation |"),
        "{text}"
    );
    assert!(!text.contains("held-out repeat"), "{text}");

    // The library path, written out.
    let settings = FitSettings::default();
    let analysed: Vec<_> = read_campaign_dir(Path::new(&a))
        .unwrap()
        .iter()
        .flat_map(|r| r.segments.clone())
        .filter(|s| s.labels.series_kind == SeriesKind::Protocol)
        .filter(|s| [30.0, 40.0].contains(&s.labels.set_point_celsius))
        .map(|s| analyse(&s, &settings).unwrap())
        .collect();
    let unit = fit_unit(&analysed, &settings).unwrap();
    let mut results = Vec::new();
    for (source, split) in [(&b, Split::Validation), (&twin, Split::NoiseFloor)] {
        for recording in read_campaign_dir(Path::new(source)).unwrap() {
            let segments: Vec<_> = recording.segments.iter().collect();
            let kept = kept_before(&segments, &settings, &unit.by_history.settings, true);
            for (segment, previous) in segments.iter().zip(&kept) {
                let mut result = evaluate_after(&unit, segment, &settings, previous);
                if split == Split::NoiseFloor {
                    result.labels.unit_id = format!("noise:{}", result.labels.unit_id);
                }
                results.push((split, result));
            }
        }
    }
    let expected = serde_json::to_string_pretty(&summarise(&results)).unwrap();
    let written = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert_eq!(written, expected);
    // The tables are the ones fitted on A alone.
    let tables = std::fs::read(out.join("tables/GIU-01/modified.bin")).unwrap();
    ok(&["fit", &a, "-q", "-o", d.join("fit").to_str().unwrap()]);
    assert_eq!(
        tables,
        std::fs::read(d.join("fit/GIU-01/modified.bin")).unwrap()
    );

    // The classic report takes a twin recorded at the validation set point alone.
    let text = ok(&[
        "report",
        "-q",
        &a,
        "--validation",
        "33",
        "--noise-floor",
        &twin,
        "-o",
        d.join("classic").to_str().unwrap(),
    ]);
    assert!(text.contains("| +33 °C | validation |"), "{text}");
    let md = std::fs::read_to_string(d.join("classic/report.md")).unwrap();
    assert!(
        md.contains("## Noise floor") && md.contains("noise:GIU-01"),
        "{md}"
    );

    // Evaluation data of units no fit saw: said, not an empty report.
    let other = d.join("other.toml");
    std::fs::write(&other, "seed = 3\nunits = 2\nsample_rate_hz = 100\nset_points_celsius = [33]\n[protocol]\nintervals_min = [1]\nrepeats = 1\nactivation_s = 10\n").unwrap();
    let two = d.join("two");
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        other.to_str().unwrap(),
        "-o",
        two.to_str().unwrap(),
    ]);
    for entry in std::fs::read_dir(two.join("recordings")).unwrap() {
        let p = entry.unwrap().path();
        if p.to_string_lossy().contains("GIU-01") {
            std::fs::remove_file(p).unwrap();
        }
    }
    let (status, text) = gyrodrift(&[
        "report",
        "-q",
        "--calibration-data",
        &a,
        "--evaluation-data",
        two.to_str().unwrap(),
        "-o",
        d.join("none").to_str().unwrap(),
    ]);
    assert!(
        !status.status.success() && text.contains("no unit of the evaluation data (GIU-02)"),
        "{text}"
    );
}

#[test]
fn evaluation_data_in_another_rate_unit_is_named_in_a_warning_printed_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = simulate(d, "calibration", "30, 40", &[]);
    let b = simulate(d, "evaluation", "33, 35", &[]);
    // One recording of the evaluation data logged in another unit: every rate 57.3× larger.
    let scaled = Path::new(&b).join("recordings/GIU-01_sp+35.0C_protocol.mcap");
    let mut recording = drift_recording::read_recording(&scaled).unwrap();
    for segment in &mut recording.segments {
        for axis in &mut segment.rate_dps {
            for v in axis.iter_mut() {
                *v *= 57.3;
            }
        }
    }
    drift_recording::write_recording(&recording, &scaled).unwrap();
    let out = d.join("report");
    let (status, text) = gyrodrift(&[
        "report",
        "-q",
        "--calibration-data",
        &a,
        "--evaluation-data",
        &b,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(status.status.code(), Some(0), "{text}");
    let stderr = String::from_utf8_lossy(&status.stderr);
    let named = "GIU-01_sp+35.0C_protocol.mcap`: uncorrected drift";
    assert!(
        stderr.contains("warning: --evaluation-data: `")
            && stderr.contains(named)
            && stderr.contains("the calibration data's")
            && stderr.contains("another unit or scale (rad/s against °/s is 57×)"),
        "{stderr}"
    );
    assert!(!stderr.contains("sp+33.0C"), "{stderr}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("**Warning:** --evaluation-data: `") && md.contains(named),
        "{md}"
    );
}
