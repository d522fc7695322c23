//! Inputs and requests the commands refuse rather than guess at: each case runs the binary and
//! asserts its exit status and the message that names what is wrong and where.

mod common;

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::gyrodrift;

/// Exit status 2 (the command could not do its job) and a message containing every `needle`.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let (out, text) = gyrodrift(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {text}");
    for needle in needles {
        assert!(text.contains(needle), "{args:?}: no `{needle}` in {text}");
    }
    text
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A short campaign of one unit at +30, +40 and +33 °C, simulated once for every test here.
fn campaign() -> &'static Path {
    static CAMPAIGN: OnceLock<PathBuf> = OnceLock::new();
    CAMPAIGN.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        let file = dir.join("short.toml");
        std::fs::write(&file, "[protocol]\nactivations = 3\nactivation_s = 30.0\n").unwrap();
        let out = dir.join("campaign");
        common::ok(&[
            "simulate",
            "-q",
            "-c",
            s(&file),
            "-o",
            s(&out),
            "--units",
            "1",
            "--set-points",
            "30,40,33",
            "--intervals",
            "1,30",
            "--repeats",
            "2",
            "--seed",
            "4",
        ]);
        out
    })
}

/// A copy of the campaign's folder tree (files copied) in `to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

fn first_recording(campaign: &Path) -> PathBuf {
    let mut files: Vec<PathBuf> = std::fs::read_dir(campaign.join("recordings"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    files.remove(0)
}

// --- exit codes -------------------------------------------------------------------------------

#[test]
fn check_without_recordings_exits_2_not_1() {
    let dir = tempfile::tempdir().unwrap();
    let empty = s(dir.path());
    refused(
        &["check", empty, "--tables", empty, "-o", empty],
        &["no .mcap recordings in"],
    );
}

#[test]
fn check_refuses_a_share_removed_above_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = s(dir.path());
    refused(
        &["check", d, "--tables", d, "--min-removed", "2"],
        &["--min-removed must be a share 0…1", "got 2"],
    );
}

#[test]
fn exit_codes_are_documented_in_help() {
    let (out, text) = gyrodrift(&["--help"]);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("Exit status: 0 done") && text.contains("2 usage, input or output error"),
        "{text}"
    );
}

// --- mislabelled or partial results -----------------------------------------------------------

#[test]
fn report_refuses_a_validation_set_point_the_fit_sees() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "report",
            s(campaign()),
            "-q",
            "--calibration",
            "30,40",
            "--validation",
            "30",
            "-o",
            s(&dir.path().join("report")),
        ],
        &["+30 °C is both a calibration and a validation set point"],
    );
    assert!(!dir.path().join("report").exists());
}

#[test]
fn report_refuses_the_campaign_as_its_own_noise_floor() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "report",
            s(campaign()),
            "-q",
            "--noise-floor",
            s(campaign()),
            "-o",
            s(&dir.path().join("report")),
        ],
        &[
            "(--noise-floor) holds the same recording as",
            "(the campaign)",
            "zero-drift twin",
        ],
    );
    assert!(!dir.path().join("report").exists());
}

#[test]
fn report_refuses_a_copy_of_the_calibration_data_as_evaluation_data() {
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("copy");
    copy_tree(campaign(), &copy);
    // A copy under another name, given by its recordings folder: the same recordings by content.
    refused(
        &[
            "report",
            "--calibration-data",
            s(campaign()),
            "--evaluation-data",
            s(&copy.join("recordings")),
            "-q",
            "-o",
            s(&dir.path().join("report")),
        ],
        &[
            "(--evaluation-data) holds the same recording as",
            "(--calibration-data)",
            "recordings the fit does not see",
        ],
    );
    assert!(!dir.path().join("report").exists());
}

#[test]
fn simulate_refuses_set_points_that_name_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    for list in ["30,30", "30,30.04"] {
        let out = dir.path().join(list);
        refused(
            &["simulate", "-q", "-o", s(&out), "--set-points", list],
            &[
                "set_points_celsius[1]",
                "names the same recording files (+30.0 °C) as set_points_celsius[0] = 30 °C",
                "--set-points",
            ],
        );
        assert!(!out.join("summary.json").exists());
    }
}

#[test]
fn report_refuses_a_validation_set_point_without_data() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "report",
            s(campaign()),
            "-q",
            "--validation",
            "99",
            "-o",
            s(&dir.path().join("report")),
        ],
        &[
            "no activations at the validation set point +99 °C",
            "set points recorded: +30, +33, +40 °C",
        ],
    );
    assert!(!dir.path().join("report").exists());
}

#[test]
fn report_refuses_a_switch_on_ambient_channel_a_recording_lacks() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "report",
            s(campaign()),
            "-q",
            "--switch-on-ambient",
            "chamber_air",
            "-o",
            s(&dir.path().join("report")),
        ],
        &[
            ".mcap: unit GIU-01, set point ",
            " series ",
            " activation ",
            "no finite `chamber_air` value at switch-on",
            "--switch-on-ambient",
            "channels logged: ",
            "chamber_set_point",
        ],
    );
    assert!(!dir.path().join("report").exists());
}

#[test]
fn report_compares_the_switch_on_at_a_logged_ambient() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    common::ok(&[
        "report",
        s(campaign()),
        "-q",
        "--switch-on-ambient",
        "chamber_set_point",
        "-o",
        s(&out),
    ]);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("Switch-on ambient: the `chamber_set_point` channel"),
        "{md}"
    );
    let section = md
        .split("## Switch-on at a measured ambient")
        .nth(1)
        .expect("the section");
    assert!(
        section.contains("| validation | +33 °C | drift |")
            && section.contains("| validation | +33 °C | RMS |"),
        "{section}"
    );
    let json = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(json.contains("modified-at-ambient"));
}

#[test]
fn report_footnote_names_the_validation_set_point_used() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    common::ok(&[
        "report",
        s(campaign()),
        "-q",
        "--calibration",
        "30,33",
        "--validation",
        "40",
        "-o",
        s(&out),
    ]);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("°/s. +40 °C: validation set point, never used in the fit."),
        "{md}"
    );
    assert!(!md.contains("+33 °C: validation"), "{md}");
}

#[test]
fn fit_refuses_a_calibration_set_point_without_data() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "fit",
            s(campaign()),
            "-q",
            "--calibration",
            "30,35",
            "-o",
            s(&dir.path().join("tables")),
        ],
        &["GIU-01: no protocol activations at the calibration set point +35 °C (it has +30 °C)"],
    );
}

#[test]
fn fit_refuses_a_half_simulated_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let half = dir.path().join("half");
    copy_tree(campaign(), &half);
    // What an interrupted `simulate` leaves: no summary.json (written last), a temporary file.
    std::fs::remove_file(half.join("summary.json")).unwrap();
    std::fs::write(half.join("recordings/.GIU-01_x.mcap.99.tmp"), b"partial").unwrap();
    refused(
        &["fit", s(&half), "-q", "-o", s(&dir.path().join("tables"))],
        &["is an incomplete simulated campaign (no summary.json"],
    );
}

#[test]
fn an_interrupted_simulate_removes_its_partial_files_and_exits_130() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    // Long enough (10 units) that the interrupt lands while a file is being written.
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
        .args(["simulate", "-q", "-o", s(&out), "--units", "10"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let partial = |dir: &Path| -> Vec<String> {
        std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .filter(|n| n.ends_with(&format!(".{pid}.tmp")))
                    .collect()
            })
            .unwrap_or_default()
    };
    // Written into a staging folder beside the output, put in place once whole.
    let recordings = dir
        .path()
        .join(format!(".campaign.writing-{pid}"))
        .join("recordings");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while partial(&recordings).is_empty() {
        assert!(
            std::time::Instant::now() < deadline,
            "no partial file appeared"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = std::process::Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let finished = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&finished.stderr);
    assert_eq!(finished.status.code(), Some(130), "{text}");
    assert!(
        text.contains("interrupted: removed the unfinished output"),
        "{text}"
    );
    // Nothing is left: no staging folder, no half campaign.
    assert_eq!(names(dir.path()), Vec::<String>::new());
}

#[test]
fn simulate_force_keeps_the_earlier_campaign_until_the_new_one_is_whole() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    copy_tree(campaign(), &out);
    let before = names(&out.join("recordings"));
    // Interrupted while the new campaign is being written: the earlier one is all there.
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
        .args(["simulate", "-q", "-o", s(&out), "--force", "--units", "10"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stage = dir
        .path()
        .join(format!(".campaign.writing-{}", child.id()))
        .join("recordings");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while std::fs::read_dir(&stage).map_or(true, |mut e| e.next().is_none()) {
        assert!(std::time::Instant::now() < deadline, "no file written");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert_eq!(
        names(&out.join("recordings")),
        before,
        "replaced while writing"
    );
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let finished = child.wait_with_output().unwrap();
    assert_eq!(finished.status.code(), Some(130));
    assert_eq!(names(&out.join("recordings")), before);
    assert!(out.join("summary.json").is_file());
    // Replaced whole once the new campaign is written; its summary names the files in place.
    common::ok(&[
        "simulate",
        "-q",
        "-o",
        s(&out),
        "--force",
        "--units",
        "1",
        "--set-points",
        "30",
        "--intervals",
        "1",
        "--repeats",
        "1",
    ]);
    assert_eq!(
        names(&out.join("recordings")),
        ["GIU-01_sp+30.0C_protocol.mcap"]
    );
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains(&format!(
            "\"{}\"",
            out.join("recordings/GIU-01_sp+30.0C_protocol.mcap")
                .display()
        )) && !summary.contains("writing"),
        "{summary}"
    );
    assert_eq!(names(dir.path()), ["campaign"], "no staging folder left");
}

#[test]
fn simulate_refuses_a_non_empty_folder_and_force_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    copy_tree(campaign(), &out);
    let stale = out.join("recordings/GIU-09_stale.mcap");
    std::fs::copy(first_recording(&out), &stale).unwrap();
    let file = dir.path().join("short.toml");
    std::fs::write(&file, "[protocol]\nactivations = 2\nactivation_s = 3.0\n").unwrap();
    let args = |force: bool| {
        let mut args = vec![
            "simulate",
            "-q",
            "-c",
            s(&file),
            "-o",
            s(&out),
            "--units",
            "1",
            "--set-points",
            "30",
            "--intervals",
            "1",
            "--repeats",
            "1",
        ];
        if force {
            args.push("--force");
        }
        args
    };
    refused(
        &args(false),
        &[
            "is not empty (recordings, summary.json, truth)",
            "pass --force to replace the campaign there, or choose a new folder",
        ],
    );
    assert!(stale.exists(), "nothing removed without --force");
    common::ok(&args(true));
    assert!(!stale.exists(), "--force clears what it replaces");
    let recordings = std::fs::read_dir(out.join("recordings")).unwrap().count();
    assert_eq!(recordings, 1);
    // --force replaces a campaign, nothing else.
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    refused(
        &args(true),
        &["holds files `simulate` does not write (notes.txt)"],
    );
    assert!(out.join("notes.txt").exists());
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn every_writer_refuses_a_folder_of_another_run_and_force_replaces_its_own_whole() {
    let dir = tempfile::tempdir().unwrap();
    let c = s(campaign());
    let tables = dir.path().join("tables");
    let fit = |force: bool| {
        let mut args = vec!["fit", c, "-q", "-o", s(&tables)];
        if force {
            args.push("--force");
        }
        args
    };
    common::ok(&fit(false));
    // A stale unit of an earlier run would be used by `check --tables`: a rerun refuses, and
    // --force replaces the folder whole.
    std::fs::create_dir(tables.join("GIU-02")).unwrap();
    refused(
        &fit(false),
        &[
            "is not empty (.gyrodrift-output, GIU-01, GIU-02, calibration-data.json)",
            "pass --force to replace the tables folder there, or choose a new folder",
        ],
    );
    assert!(
        tables.join("GIU-02").exists(),
        "nothing removed without --force"
    );
    common::ok(&fit(true));
    assert_eq!(
        names(&tables),
        [".gyrodrift-output", "GIU-01", "calibration-data.json"]
    );
    assert_eq!(names(dir.path()), ["tables"], "no staging folder left");

    // Another command's output, or a folder of the user's, is never replaced.
    let report = dir.path().join("report");
    common::ok(&["report", c, "-q", "-o", s(&report)]);
    refused(
        &["fit", c, "-q", "-o", s(&report), "--force"],
        &["holds the output of `gyrodrift report`, not of `fit`"],
    );
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    for args in [
        vec!["fit", c, "-q", "-o", s(&mine), "--force"],
        vec!["report", c, "-q", "-o", s(&mine), "--force"],
        vec![
            "check",
            c,
            "--tables",
            s(&tables),
            "-q",
            "-o",
            s(&mine),
            "--force",
        ],
        vec!["demo", "-q", "-o", s(&mine), "--force"],
    ] {
        refused(&args, &["holds files", "does not write (notes.txt)"]);
    }
    assert_eq!(names(&mine), ["notes.txt"]);
    refused(
        &["report", c, "-q", "-o", s(&report)],
        &["pass --force to replace the report there"],
    );
    common::ok(&["report", c, "-q", "-o", s(&report), "--force"]);
}

#[test]
fn an_interrupted_demo_leaves_the_earlier_demo_as_it_was_and_no_temporaries() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    // An earlier demo's output, as far as the rule sees it: its marker and what it holds.
    std::fs::create_dir_all(out.join("campaign")).unwrap();
    std::fs::write(out.join(".gyrodrift-output"), "demo\n").unwrap();
    std::fs::write(out.join("campaign/summary.json"), "{}").unwrap();
    std::fs::create_dir_all(out.join("report")).unwrap();
    std::fs::write(out.join("report/report.md"), "# earlier\n").unwrap();
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_gyrodrift"))
        .args(["demo", "-q", "--force", "-o", s(&out)])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let recordings = dir
        .path()
        .join(format!(".demo.writing-{pid}/campaign/recordings"));
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while !std::fs::read_dir(&recordings).is_ok_and(|mut d| d.next().is_some()) {
        assert!(
            std::time::Instant::now() < deadline,
            "the demo wrote nothing"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = std::process::Command::new("kill")
        .args(["-INT", &pid.to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let finished = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&finished.stderr);
    assert_eq!(finished.status.code(), Some(130), "{text}");
    assert!(text.contains("removed the unfinished output"), "{text}");
    assert_eq!(
        names(dir.path()),
        ["demo"],
        "no staging folder or temporary left"
    );
    assert_eq!(names(&out), [".gyrodrift-output", "campaign", "report"]);
    assert_eq!(names(&out.join("campaign")), ["summary.json"]);
    assert_eq!(
        std::fs::read_to_string(out.join("report/report.md")).unwrap(),
        "# earlier\n"
    );
}

#[test]
fn demo_names_an_older_demo_without_the_marker_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    // What a demo wrote before output folders were marked.
    for folder in ["campaign", "noise-floor", "report"] {
        std::fs::create_dir_all(out.join(folder)).unwrap();
    }
    std::fs::write(out.join("report/report.md"), "# earlier\n").unwrap();
    refused(
        &["demo", "-q", "-o", s(&out)],
        &[
            "holds campaign, noise-floor, report but no .gyrodrift-output file",
            "the output of an older `gyrodrift demo`",
            "pass --force to replace it, or delete the folder",
        ],
    );
    assert_eq!(names(&out), ["campaign", "noise-floor", "report"]);
    assert_eq!(
        std::fs::read_to_string(out.join("report/report.md")).unwrap(),
        "# earlier\n"
    );
}

#[test]
fn check_on_the_tables_own_calibration_data_says_it_is_in_sample() {
    let dir = tempfile::tempdir().unwrap();
    let tables = dir.path().join("tables");
    common::ok(&["fit", s(campaign()), "-q", "-o", s(&tables)]);
    let checked = dir.path().join("check");
    let (out, text) = gyrodrift(&[
        "check",
        s(campaign()),
        "--tables",
        s(&tables),
        "-q",
        "-o",
        s(&checked),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{text}");
    assert!(
        text.contains(
            "in-sample: 2 of 3 recordings checked are calibration data these tables were fitted on"
        ),
        "{text}"
    );
    let md = std::fs::read_to_string(checked.join("check.md")).unwrap();
    assert!(md.contains("**In-sample.** 2 of 3"), "{md}");
    // A copy is recognised by content; a recording the fit did not see is not in-sample.
    let copy = dir.path().join("copy");
    copy_tree(campaign(), &copy);
    for entry in std::fs::read_dir(copy.join("recordings")).unwrap() {
        let path = entry.unwrap().path();
        if !path.to_string_lossy().contains("sp+33.0C") {
            std::fs::remove_file(path).unwrap();
        }
    }
    let (out, text) = gyrodrift(&[
        "check",
        s(&copy),
        "--tables",
        s(&tables),
        "-q",
        "-o",
        s(&dir.path().join("check-33")),
    ]);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{text}");
    assert!(!text.contains("in-sample"), "{text}");
}

#[test]
fn import_csv_into_a_folder_replaces_an_earlier_import_only_when_forced() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("a.csv");
    std::fs::write(&csv, CSV).unwrap();
    let other = dir.path().join("b.csv");
    std::fs::write(&other, CSV).unwrap();
    let out = dir.path().join("imported");
    common::ok(&csv_args(s(&csv), s(&out), &[]));
    // A second file is not added to the first import (its import.json would list only one).
    refused(
        &csv_args(s(&other), s(&out), &[]),
        &["is not empty", "pass --force to replace the import there"],
    );
    assert_eq!(names(&out.join("recordings")), ["csv_a.mcap"]);
    common::ok(&csv_args(s(&other), s(&out), &["--force"]));
    assert_eq!(names(&out.join("recordings")), ["csv_b.mcap"]);
    let manifest = std::fs::read_to_string(out.join("import.json")).unwrap();
    assert!(
        manifest.contains("b.csv") && !manifest.contains("a.csv"),
        "{manifest}"
    );
    // An import is not the place for a report, nor a report's folder for an import.
    let report = dir.path().join("report");
    common::ok(&["report", s(campaign()), "-q", "-o", s(&report)]);
    refused(
        &csv_args(s(&csv), s(&report), &["--force"]),
        &["holds the output of `gyrodrift report`, not of `import`"],
    );
}

// --- writers validate with the reader's rules ---------------------------------------------------

const CSV: &str = "segment_id,t_s,gx,gy,gz,temp\n0,0.000,0.1,0.2,0.3,30.0\n0,0.001,0.1,0.2,0.3,30.0\n0,0.002,0.1,0.2,0.3,30.0\n";

fn csv_args<'a>(csv: &'a str, out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "import",
        "csv",
        csv,
        "-o",
        out,
        "--rate-columns",
        "gx,gy,gz",
        "--temperature-columns",
        "temp",
    ];
    args.extend_from_slice(extra);
    args
}

/// A CSV of `rows` rows at `rate` rows per second, time in seconds.
fn csv_at(path: &Path, rows: usize, rate: f64) {
    let mut text = String::from("segment_id,t_s,gx,gy,gz,temp\n");
    for i in 0..rows {
        text.push_str(&format!("0,{:.6},0.1,0.2,0.3,30.0\n", i as f64 / rate));
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn import_csv_refuses_made_up_samples_and_unused_rows_unless_asked() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("seconds.csv");
    csv_at(&csv, 2000, 1000.0);
    let out = dir.path().join("a.mcap");
    let resample = ["--timing", "resample"];
    // Seconds read as milliseconds: 2000 rows would become 2 samples.
    let mut args = csv_args(s(&csv), s(&out), &resample);
    args.extend(["--time-unit", "ms"]);
    refused(
        &args,
        &[
            "seconds.csv: 2000 rows became 2 samples at 1000 Hz",
            "give `--time-unit s`",
            "`--downsample`",
        ],
    );
    assert!(!out.exists());
    common::ok(&csv_args(s(&csv), s(&out), &resample));
    // 100 Hz rows on a 1000 Hz grid: 90 % of the samples made up.
    let slow = dir.path().join("slow.csv");
    csv_at(&slow, 200, 100.0);
    let out = dir.path().join("b.mcap");
    refused(
        &csv_args(s(&slow), s(&out), &resample),
        &[
            "slow.csv: 200 rows became 1991 samples at 1000 Hz",
            "90 % of the samples would be made up",
            "give `--rate-hz 100`, or `--upsample`",
        ],
    );
    let mut args = csv_args(s(&slow), s(&out), &resample);
    args.push("--upsample");
    common::ok(&args);
    let at_100 = dir.path().join("c.mcap");
    let mut args = csv_args(s(&slow), s(&at_100), &resample);
    args.extend(["--rate-hz", "100"]);
    common::ok(&args);
}

#[test]
fn a_truncated_ulog_is_refused_unless_asked() {
    let real = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/formats/px4-ulog/sample_log_small.ulg");
    let Ok(bytes) = std::fs::read(&real) else {
        println!("skipped: the PX4 fixture is absent");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let grid = ["--rate-hz", "1", "--max-gap", "1.5"];
    let mut args = vec!["import", "ulog", s(&real), "-o", s(&whole)];
    args.extend(grid);
    common::ok(&args);
    let cut = dir.path().join("cut.ulg");
    std::fs::write(&cut, &bytes[..bytes.len() * 9 / 10 + 1]).unwrap();
    let out = dir.path().join("imported");
    let mut args = vec!["import", "ulog", s(&cut), "-o", s(&out)];
    args.extend(grid);
    refused(
        &args,
        &[
            "cut.ulg: the log ends inside a message at byte",
            "the file is truncated",
            "`--truncated` to import the complete messages before the cut",
        ],
    );
    assert!(!out.exists());
    // Logged at 1 Hz: the default 100 Hz grid would make up 99 % of its samples.
    let at_100 = dir.path().join("at-100");
    refused(
        &[
            "import",
            "ulog",
            s(&real),
            "-o",
            s(&at_100),
            "--max-gap",
            "1.5",
        ],
        &[
            "sample_log_small.ulg: 6 `sensor_gyro` instance 0 messages became",
            "would be made up by interpolation",
            "give `--rate-hz 1`, or `--upsample`",
        ],
    );
    assert!(!at_100.exists());
    args.push("--truncated");
    let text = common::ok(&args);
    assert!(!text.contains("truncated"), "{text}");
}

#[test]
fn import_refuses_a_set_point_the_reader_would_refuse() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    std::fs::write(&csv, CSV).unwrap();
    let out = dir.path().join("measured");
    refused(
        &csv_args(s(&csv), s(&out), &["--set-point", "nan"]),
        &["bench.csv: option `set_point_celsius`: must be a finite number of °C, got NaN"],
    );
    assert!(!out.exists());
}

#[test]
fn simulate_refuses_intervals_the_recording_clock_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    refused(
        &[
            "simulate",
            "-q",
            "-o",
            s(&out),
            "--units",
            "1",
            "--set-points",
            "30",
            "--intervals",
            "1e9",
            "--repeats",
            "1",
        ],
        &["protocol.intervals_min[0]"],
    );
    assert!(!out.exists());
}

// --- foreign channels, unknown fields ------------------------------------------------------------

/// A recording whose `/gyro/rate` channel carries `schema` (name, encoding) and
/// `message_encoding`: everything else as the format writes it.
fn foreign_rate_channel(path: &Path, schema: (&str, &str), message_encoding: &str) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::WriteOptions::new()
        .profile("gyrodrift")
        .create(file)
        .unwrap();
    let metadata = [("unit_id", "GIU-01"), ("sample_rate_hz", "1000")]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect();
    w.write_metadata(&mcap::records::Metadata {
        name: "gyrodrift.recording".into(),
        metadata,
    })
    .unwrap();
    let own = [
        (
            "/gyro/temperature_raw",
            "gyrodrift_msgs/msg/RawTemperatureBatch",
        ),
        ("/aux/accel", "gyrodrift_msgs/msg/Vector3Batch"),
        ("/aux/supply_voltage", "gyrodrift_msgs/msg/ScalarBatch"),
        ("/aux/chamber_set_point", "gyrodrift_msgs/msg/ScalarBatch"),
        ("/power/state", "gyrodrift_msgs/msg/PowerEvent"),
    ];
    for (topic, name) in own {
        let id = w.add_schema(name, "ros2msg", b"").unwrap();
        w.add_channel(id, topic, "cdr", &Default::default())
            .unwrap();
    }
    let id = w.add_schema(schema.0, schema.1, b"").unwrap();
    let rate = w
        .add_channel(id, "/gyro/rate", message_encoding, &Default::default())
        .unwrap();
    w.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id: rate,
            sequence: 1,
            log_time: 1,
            publish_time: 1,
        },
        b"{\"x\": 1}",
    )
    .unwrap();
    w.finish().unwrap();
}

#[test]
fn a_rate_channel_in_another_schema_is_refused_with_the_channel_named() {
    let dir = tempfile::tempdir().unwrap();
    let recordings = dir.path().join("recordings");
    std::fs::create_dir_all(&recordings).unwrap();
    foreign_rate_channel(
        &recordings.join("imu.mcap"),
        ("sensor_msgs/msg/Imu", "ros2msg"),
        "cdr",
    );
    refused(
        &["fit", s(dir.path()), "-q", "-o", s(&dir.path().join("t"))],
        &[
            "imu.mcap",
            "channel /gyro/rate has schema `sensor_msgs/msg/Imu` (ros2msg)",
            "the format writes it as gyrodrift_msgs/msg/Vector3Batch",
        ],
    );
    // The right schema name in another encoding is not ours either.
    foreign_rate_channel(
        &recordings.join("imu.mcap"),
        ("gyrodrift_msgs/msg/Vector3Batch", "jsonschema"),
        "json",
    );
    refused(
        &["fit", s(dir.path()), "-q", "-o", s(&dir.path().join("t"))],
        &["channel /gyro/rate has schema `gyrodrift_msgs/msg/Vector3Batch` (jsonschema) with json messages"],
    );
}

#[test]
fn fit_settings_with_a_misspelt_field_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let settings = dir.path().join("settings.json");
    std::fs::write(&settings, "{\"lowpass_window_sample\": 500}").unwrap();
    refused(
        &[
            "fit",
            s(campaign()),
            "-q",
            "--settings",
            s(&settings),
            "-o",
            s(&dir.path().join("t")),
        ],
        &[
            "settings.json: not valid fit settings",
            "unknown field `lowpass_window_sample`",
        ],
    );
}

#[test]
fn table_json_with_an_unknown_field_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let tables = dir.path().join("tables");
    common::ok(&["fit", s(campaign()), "-q", "-o", s(&tables)]);
    for name in ["modified", "standard", "relative"] {
        let path = tables.join(format!("GIU-01/{name}.json"));
        let text = std::fs::read_to_string(&path).unwrap();
        let misspelt = text.replacen('{', "{\"setings\": {},", 1);
        let error = match name {
            "modified" => serde_json::from_str::<drift_core::ModifiedTables>(&misspelt)
                .map(|_| ())
                .unwrap_err(),
            "relative" => serde_json::from_str::<drift_core::RelativePolynomialTables>(&misspelt)
                .map(|_| ())
                .unwrap_err(),
            _ => serde_json::from_str::<drift_core::PolynomialTables>(&misspelt)
                .map(|_| ())
                .unwrap_err(),
        };
        assert!(
            error.to_string().contains("unknown field `setings`"),
            "{name}: {error}"
        );
    }
}

// --- implausible magnitudes and sizes ------------------------------------------------------------

#[test]
fn import_refuses_an_implausible_rate_naming_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    std::fs::write(
        &csv,
        CSV.replacen("0.1,0.2,0.3,30.0\n0,0.002", "0.1,1e30,0.3,30.0\n0,0.002", 1),
    )
    .unwrap();
    let out = dir.path().join("measured");
    refused(
        &csv_args(s(&csv), s(&out), &[]),
        &[
            "bench.csv: row 2 (line 3), column `gy`",
            "rate 1.000e30 °/s is beyond the plausible 10000 °/s",
        ],
    );
    assert!(!out.exists());
}

/// A sheet of four activations of unit U1 at +30 °C, at 10 Hz with a gyro's white noise; the
/// third file's rates are divided by `third_rate_divisor` (57.3: logged in rad/s).
fn noisy_bench(dir: &Path, third_rate_divisor: f64) -> PathBuf {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut sheet = String::from(
        "file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s\n",
    );
    for k in 0..4 {
        let divisor = if k == 2 { third_rate_divisor } else { 1.0 };
        let mut text = String::from("t_s,gx_dps,gy_dps,gz_dps,temp_c\n");
        for i in 0..50 {
            let rate = |bias: f64, n: f64| (bias + 0.05 * n) / divisor;
            text.push_str(&format!(
                "{},{},{},{},{}\n",
                f64::from(i) / 10.0,
                rate(0.1, noise()),
                rate(-0.2, noise()),
                rate(0.05, noise()),
                30.0 + 0.02 * f64::from(i)
            ));
        }
        std::fs::write(dir.join(format!("a{k}.csv")), text).unwrap();
        let off = if k == 0 { String::new() } else { "60".into() };
        sheet.push_str(&format!(
            "a{k}.csv,U1,30,1,1,{},{off},protocol,{}\n",
            k + 1,
            65 * k
        ));
    }
    let path = dir.join("sheet.csv");
    std::fs::write(&path, sheet).unwrap();
    path
}

/// `gyrodrift import campaign SHEET -o OUT --rate-hz 10`.
fn import_campaign_at_10_hz(sheet: &Path, out: &Path) -> Vec<String> {
    [
        "import",
        "campaign",
        s(sheet),
        "-o",
        s(out),
        "--rate-hz",
        "10",
    ]
    .map(str::to_owned)
    .to_vec()
}

#[test]
fn import_campaign_refuses_a_file_in_rad_s_among_files_in_deg_s() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("imported");
    let import = |sheet: &Path| import_campaign_at_10_hz(sheet, &out);
    let args = import(&noisy_bench(dir.path(), 1.0));
    common::ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    std::fs::remove_dir_all(&out).unwrap();
    let args = import(&noisy_bench(dir.path(), 180.0 / std::f64::consts::PI));
    refused(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &[
            "sheet.csv: row 3 (line 4), column `file`: the rate of `",
            "a2.csv` changes from sample to sample by",
            "57× less than the median of unit U1's 3 other files",
            "it looks like rad/s among files in °/s",
            "convert this file to the others' unit",
        ],
    );
    assert!(!out.exists());
}

/// A sheet of two field activations of unit U1 at +25 °C, at 10 Hz; the second file's
/// temperatures in °F when `second_in_fahrenheit`.
fn field_bench(dir: &Path, second_in_fahrenheit: bool) -> PathBuf {
    let mut sheet = String::from(
        "file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s\n",
    );
    for k in 0..2 {
        let mut text = String::from("t_s,gx_dps,gy_dps,gz_dps,temp_c\n");
        for i in 0..50 {
            let celsius = 25.5 + 0.02 * f64::from(i);
            let temperature = if k == 1 && second_in_fahrenheit {
                1.8 * celsius + 32.0
            } else {
                celsius
            };
            let wobble = 0.01 * f64::from(i % 7);
            text.push_str(&format!(
                "{},{},{},{},{temperature}\n",
                f64::from(i) / 10.0,
                0.1 + wobble,
                -0.2 + wobble,
                0.05 - wobble,
            ));
        }
        std::fs::write(dir.join(format!("f{k}.csv")), text).unwrap();
        let off = if k == 0 { String::new() } else { "60".into() };
        sheet.push_str(&format!(
            "f{k}.csv,U1,25,1,1,{},{off},field,{}\n",
            k + 1,
            65 * k
        ));
    }
    let path = dir.join("sheet.csv");
    std::fs::write(&path, sheet).unwrap();
    path
}

#[test]
fn import_campaign_refuses_a_field_file_in_fahrenheit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("imported");
    let import = |sheet: &Path| import_campaign_at_10_hz(sheet, &out);
    let args = import(&field_bench(dir.path(), false));
    common::ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    std::fs::remove_dir_all(&out).unwrap();
    let args = import(&field_bench(dir.path(), true));
    refused(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &[
            "sheet.csv: row 2 (line 3), column `set_point_celsius`: 25 °C, but the data of `",
            "f1.csv` start at 77.90 °C",
            "(field session) reads between 5 and 70 °C",
            "the file's temperature is not in °C (°F or kelvin: convert the file to °C)",
        ],
    );
    assert!(!out.exists());
}

#[test]
fn simulate_refuses_a_set_point_range_too_large_before_making_it() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "simulate",
            "-q",
            "-o",
            s(&dir.path().join("c")),
            "--set-points",
            "0:1e9:1e-9",
        ],
        &["--set-points: range `0:1e9:1e-9` makes 1.000e18 set points; at most 1000"],
    );
}

#[test]
fn simulate_refuses_a_campaign_too_large_with_its_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c");
    refused(
        &["simulate", "-q", "-o", s(&out), "--units", "100000"],
        &["would write about", "TB", "above --max-gb 20"],
    );
    assert!(!out.exists());
}

#[test]
fn a_campaign_too_large_is_sized_before_it_is_planned() {
    // Under a 1 GB address-space limit, planning 100 000 units' schedules would abort the
    // process in the allocator; sized from its first units, it is refused with its size.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c");
    let started = std::time::Instant::now();
    let run = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 1000000 && exec '{}' simulate -q -o '{}' --units 100000",
            env!("CARGO_BIN_EXE_gyrodrift"),
            s(&out)
        ))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{text}");
    assert!(
        text.contains("would write about") && text.contains("TB (about"),
        "{text}"
    );
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
    assert!(!out.exists());
}

// --- messages ------------------------------------------------------------------------------------

#[test]
fn a_truncated_recording_says_truncated_with_the_offset() {
    let dir = tempfile::tempdir().unwrap();
    let recordings = dir.path().join("recordings");
    std::fs::create_dir_all(&recordings).unwrap();
    let bytes = std::fs::read(first_recording(campaign())).unwrap();
    let cut = bytes.len() / 2;
    std::fs::write(recordings.join("cut.mcap"), &bytes[..cut]).unwrap();
    refused(
        &["fit", s(dir.path()), "-q", "-o", s(&dir.path().join("t"))],
        &[&format!(
            "cut.mcap: truncated: the MCAP file ends at byte {cut}"
        )],
    );
}

#[test]
fn a_corrupt_gzip_file_says_gzip() {
    let dir = tempfile::tempdir().unwrap();
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(CSV.repeat(50).as_bytes()).unwrap();
    let mut bytes = gz.finish().unwrap();
    let middle = bytes.len() / 2;
    for b in &mut bytes[middle..middle + 8] {
        *b ^= 0x5A;
    }
    let csv = dir.path().join("bench.csv.gz");
    std::fs::write(&csv, &bytes).unwrap();
    refused(
        &csv_args(s(&csv), s(&dir.path().join("m")), &[]),
        &[
            "bench.csv.gz: gzip:",
            "the compressed file is corrupt or cut short",
        ],
    );
}

#[test]
fn an_error_says_each_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere");
    let text = refused(
        &["fit", s(&missing), "-q", "-o", s(&dir.path().join("t"))],
        &["listing recordings in"],
    );
    assert_eq!(
        text.matches("No such file or directory").count(),
        1,
        "{text}"
    );
}

#[test]
fn long_numbers_are_shortened() {
    let dir = tempfile::tempdir().unwrap();
    let d = s(dir.path());
    let text = refused(
        &["check", d, "--tables", d, "--max-rms", "-1e300"],
        &["--max-rms must be a finite number ≥ 0, got -1.000e300"],
    );
    assert!(text.len() < 300, "{text}");
}

#[test]
fn diagnose_refuses_a_copy_of_the_campaign_as_evaluation_data_or_noise_floor() {
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("copy");
    copy_tree(campaign(), &copy);
    for flag in ["--evaluation-data", "--noise-floor", "--diagnosis-data"] {
        refused(
            &[
                "diagnose",
                s(campaign()),
                "-q",
                // The noise floor is read for the extended model's figures.
                "--extend",
                flag,
                s(&copy.join("recordings")),
                "-o",
                s(&dir.path().join("diagnosis")),
            ],
            &[
                &format!("({flag}) holds the same recording as"),
                "(the campaign)",
                "other recordings than the campaign",
            ],
        );
        assert!(!dir.path().join("diagnosis").exists());
    }
}

#[test]
fn diagnose_refuses_diagnosis_data_at_a_calibration_set_point() {
    let dir = tempfile::tempdir().unwrap();
    refused(
        &[
            "diagnose",
            s(campaign()),
            "-q",
            "--calibration",
            "30,40",
            "--diagnose-on",
            "40",
            "-o",
            s(&dir.path().join("diagnosis")),
        ],
        &[
            "--diagnose-on 40: a calibration set point",
            "--diagnosis-data",
        ],
    );
    assert!(!dir.path().join("diagnosis").exists());
}

#[test]
fn gzip_data_in_a_file_named_csv_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(CSV.as_bytes()).unwrap();
    std::fs::write(&csv, gz.finish().unwrap()).unwrap();
    let out = dir.path().join("measured");
    let text = refused(
        &csv_args(s(&csv), s(&out), &[]),
        &[
            "bench.csv: the file holds gzip-compressed data (it starts with bytes 1f 8b), but its name does not end in `.gz`",
            "bench.csv.gz`, or decompress it",
        ],
    );
    assert!(!text.contains("utf-8") && !out.exists(), "{text}");
}

#[test]
fn a_ulog_with_a_damaged_header_says_the_file_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("flight.ulg");
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    bytes[2] = 0;
    std::fs::write(&log, &bytes).unwrap();
    let out = dir.path().join("px4");
    refused(
        &["import", "ulog", s(&log), "-o", s(&out)],
        &["flight.ulg: byte 0: the ULog header is corrupt: its magic reads 55 4c 00 67 01 12 35, not `ULog` 01 12 35: the file is corrupt"],
    );
    // A message the header's definitions do not allow is damage too, named as such.
    bytes[2] = b'o';
    bytes.extend([4u8, 0, b'D', 7, 0, 1, 2]);
    std::fs::write(&log, &bytes).unwrap();
    refused(
        &["import", "ulog", s(&log), "-o", s(&out)],
        &["flight.ulg: byte 16: data for msg_id 7, which no subscription defines: the file is corrupt"],
    );
    assert!(!out.exists());
}

#[test]
fn a_timing_hint_names_the_options_not_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("jitter.csv");
    std::fs::write(
        &csv,
        "segment_id,t_s,gx,gy,gz,temp\n0,0.000,0.1,0.2,0.3,30.0\n0,0.001,0.1,0.2,0.3,30.0\n0,0.0026,0.1,0.2,0.3,30.0\n",
    )
    .unwrap();
    let text = refused(
        &csv_args(s(&csv), s(&dir.path().join("out")), &[]),
        &["on the command line `--timing resample --rate-hz <the logging rate>`"],
    );
    assert!(!text.contains("::"), "{text}");
}

#[test]
fn diagnose_refuses_a_folder_of_another_run_and_force_replaces_its_own_whole() {
    let dir = tempfile::tempdir().unwrap();
    let c = s(campaign());
    let out = dir.path().join("diagnosis");
    let diagnose = |force: bool| {
        let mut args = vec!["diagnose", c, "-q", "-o", s(&out)];
        if force {
            args.push("--force");
        }
        args
    };
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    refused(
        &["diagnose", c, "-q", "-o", s(&mine), "--force"],
        &["holds files", "does not write (notes.txt)"],
    );
    assert_eq!(names(&mine), ["notes.txt"]);
    common::ok(&diagnose(false));
    std::fs::write(out.join("stale.svg"), "an earlier run's").unwrap();
    refused(
        &diagnose(false),
        &["pass --force to replace the diagnosis there, or choose a new folder"],
    );
    assert!(
        out.join("stale.svg").exists(),
        "nothing removed without --force"
    );
    common::ok(&diagnose(true));
    assert!(!out.join("stale.svg").exists() && out.join("diagnosis.md").is_file());
    assert_eq!(
        names(dir.path()),
        ["diagnosis", "mine"],
        "no staging folder left"
    );
}

#[test]
fn export_to_an_existing_mcap_file_is_refused_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let recording = first_recording(campaign());
    let bag = dir.path().join("bag.mcap");
    std::fs::write(&bag, "the user's").unwrap();
    let export = |force: bool| {
        let mut args = vec!["export", "ros2", s(&recording), "-o", s(&bag)];
        if force {
            args.push("--force");
        }
        args
    };
    refused(
        &export(false),
        &["bag.mcap: the file exists; pass --force to replace it, or choose a new file"],
    );
    assert_eq!(std::fs::read_to_string(&bag).unwrap(), "the user's");
    common::ok(&export(true));
    assert!(std::fs::metadata(&bag).unwrap().len() > 1000);
    // Never onto the recording it is made from.
    let copy = dir.path().join("copy.mcap");
    std::fs::copy(&recording, &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    refused(
        &["export", "ros2", s(&copy), "-o", s(&copy), "--force"],
        &["copy.mcap: the recording being exported; give another output file"],
    );
    assert_eq!(std::fs::read(&copy).unwrap(), before);
}

#[test]
fn an_image_of_another_model_is_named_by_model_not_by_number() {
    let dir = tempfile::tempdir().unwrap();
    let c = s(campaign());
    let tables = dir.path().join("tables");
    common::ok(&["fit", c, "-q", "-o", s(&tables)]);
    let unit = tables.join("GIU-01");
    std::fs::copy(unit.join("standard.bin"), unit.join("modified.bin")).unwrap();
    let text = refused(
        &[
            "check",
            c,
            "--tables",
            s(&tables),
            "--model",
            "modified",
            "-q",
            "-o",
            s(&dir.path().join("check")),
        ],
        &["modified.bin: the image holds a polynomial baseline (standard.bin, third_order.bin), where the paper's modified tables (modified.bin, by_history.bin) is expected"],
    );
    assert!(!text.contains("kind 2"), "{text}");
}
