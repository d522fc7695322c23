//! `gyrodrift simulate` end to end on a tiny campaign: file + flags → MCAP → reader.

use clap::Parser;
use gyrodrift::cli::{run, Cli};

#[test]
fn simulate_writes_a_readable_campaign_from_file_and_flags() {
    let dir = tempfile::tempdir().unwrap();
    let campaign = dir.path().join("campaign.toml");
    std::fs::write(
        &campaign,
        "seed = 3\nunits = 2\n[protocol]\nintervals_min = [1, 15]\nrepeats = 1\nactivation_s = 1\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let mut args = vec![
        "gyrodrift",
        "simulate",
        "--campaign",
        campaign.to_str().unwrap(),
    ];
    args.extend([
        "--units",
        "1",
        "--set-points=-10:10:20",
        "--effects",
        "thermal_lag,ageing",
    ]);
    args.extend(["--out", out.to_str().unwrap(), "--quiet"]);
    run(Cli::try_parse_from(args).unwrap()).unwrap();
    let recordings = drift_sim::read_campaign_dir(&out).unwrap();
    // --units overrides the file; the range gives −10 and +10 °C.
    assert_eq!(recordings.len(), 2);
    let set_points: Vec<f64> = recordings
        .iter()
        .map(|r| r.segments[0].labels.set_point_celsius)
        .collect();
    assert!(
        set_points.contains(&-10.0) && set_points.contains(&10.0),
        "{set_points:?}"
    );
    assert!(recordings
        .iter()
        .all(|r| r.segments.len() == 10 && r.segments[0].len() == 1000));
    // The effects went to the truth, not into the recordings.
    let truth = std::fs::read_to_string(out.join("truth").join("campaign.json")).unwrap();
    assert!(truth.contains("thermal_lag") && truth.contains("ageing"));
    assert!(out.join("summary.json").exists());
}

#[test]
fn simulate_rejects_bad_flags_with_a_named_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out_arg = out.to_str().unwrap();
    let cli = Cli::try_parse_from([
        "gyrodrift",
        "simulate",
        "--effects",
        "gremlins",
        "--out",
        out_arg,
        "-q",
    ])
    .unwrap();
    let error = run(cli).unwrap_err().to_string();
    assert!(error.contains("gremlins"), "{error}");
    let cli = Cli::try_parse_from([
        "gyrodrift",
        "simulate",
        "--set-points",
        "30,abc",
        "--out",
        out_arg,
        "-q",
    ])
    .unwrap();
    assert!(run(cli).unwrap_err().to_string().contains("abc"));
    // One unit model at a time: clap names both flags.
    let error = Cli::try_parse_from([
        "gyrodrift",
        "simulate",
        "--zero-drift",
        "--paper-exact",
        "--out",
        out_arg,
    ])
    .unwrap_err()
    .to_string();
    assert!(
        error.contains("--zero-drift") && error.contains("--paper-exact"),
        "{error}"
    );
    assert!(!out.exists());
}

#[test]
fn simulate_records_a_paper_exact_unit_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let cli = Cli::try_parse_from([
        "gyrodrift",
        "simulate",
        "--paper-exact",
        "--intervals",
        "1",
        "--repeats",
        "1",
        "--set-points",
        "30",
        "--out",
        out.to_str().unwrap(),
        "-q",
    ])
    .unwrap();
    run(cli).unwrap();
    let truth = std::fs::read_to_string(out.join("truth").join("campaign.json")).unwrap();
    let campaign: serde_json::Value = serde_json::from_str(&truth).unwrap();
    assert_eq!(campaign["unit_model"], "paper_exact", "{truth}");
}
