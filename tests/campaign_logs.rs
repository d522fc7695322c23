//! `gyrodrift import campaign` with ROS 2 bags in the sheet's `file` column: a simulated series
//! exported as one bag folder per activation and labelled by a sheet imports to the same samples
//! with the sheet's labels; sheet labels the data contradict (a set point the temperatures are
//! not at, an off-time the switch-on times do not give) are refused by row and column; a PX4 log
//! in the sheet gives one gyro, chosen by option.

use std::fmt::Write as _;
use std::path::Path;

use drift_recording::{read_campaign_dir, read_recording, Recording};

mod common;

use common::{gyrodrift, ok};

fn simulate(dir: &Path) -> Recording {
    std::fs::write(
        dir.join("c.toml"),
        "seed = 9\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [30]\n[protocol]\nintervals_min = [1]\nrepeats = 1\nactivation_s = 10\n",
    )
    .unwrap();
    let sim = dir.join("sim");
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        dir.join("c.toml").to_str().unwrap(),
        "-o",
        sim.to_str().unwrap(),
    ]);
    read_campaign_dir(&sim).unwrap().remove(0)
}

/// A sheet for the exported bags `activation-00k`, with `set_point` and the off-time before the
/// second activation replaced by `second_off` when given.
fn sheet(r: &Recording, set_point: f64, second_off: Option<f64>) -> String {
    let mut text = String::from(
        "file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s,interval_min\n",
    );
    for (k, s) in r.segments.iter().enumerate() {
        let l = &s.labels;
        let off = match (k, second_off) {
            (1, Some(off)) => Some(off),
            _ => l.off_before_s,
        };
        writeln!(
            text,
            "bags/activation-{:03},{},{set_point},{},{},{},{},protocol,{},{}",
            k + 1,
            l.unit_id,
            l.series,
            l.repeat,
            l.activation,
            off.map(|o| o.to_string()).unwrap_or_default(),
            s.power_on_ns as f64 * 1e-9,
            l.interval_min.map(|m| m.to_string()).unwrap_or_default(),
        )
        .unwrap();
    }
    text
}

#[test]
fn bags_named_by_a_sheet_import_with_its_labels_and_contradicting_labels_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let original = simulate(d);
    ok(&[
        "export",
        "ros2",
        original.path.to_str().unwrap(),
        "-o",
        d.join("bags").to_str().unwrap(),
    ]);
    let sheet_path = d.join("sheet.csv");
    std::fs::write(&sheet_path, sheet(&original, 30.0, None)).unwrap();
    let out = d.join("campaign");
    let import = |out: &Path| {
        gyrodrift(&[
            "import",
            "campaign",
            sheet_path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--rate-hz",
            "100",
        ])
    };
    let (status, text) = import(&out);
    assert!(status.status.success(), "{text}");
    let name = format!("recordings/{}_sp+30.0C_protocol.mcap", original.unit_id);
    let back = read_recording(&out.join(name)).unwrap();
    assert_eq!(back.segments.len(), original.segments.len());
    for (a, b) in original.segments.iter().zip(&back.segments) {
        assert_eq!(b.labels, a.labels);
        assert_eq!(b.power_on_ns, a.power_on_ns);
        assert_eq!(b.temperature_raw, a.temperature_raw);
        for axis in 0..3 {
            for (x, y) in a.rate_dps[axis].iter().zip(&b.rate_dps[axis]) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-3), "{x} vs {y}");
            }
        }
    }
    // The sheet says +40 °C; the data sit at +30 °C.
    std::fs::write(&sheet_path, sheet(&original, 40.0, None)).unwrap();
    let refused = d.join("refused");
    let (status, text) = import(&refused);
    assert_eq!(status.status.code(), Some(2), "{text}");
    assert!(
        text.contains(
            "sheet.csv: row 1 (line 2), column `set_point_celsius`: 40 °C, but the data of"
        ) && text.contains("the label is another set point's"),
        "{text}"
    );
    assert!(!refused.exists());
    // An off-time the switch-on times contradict.
    std::fs::write(&sheet_path, sheet(&original, 30.0, Some(9999.0))).unwrap();
    let (status, text) = import(&refused);
    assert_eq!(status.status.code(), Some(2), "{text}");
    assert!(
        text.contains("sheet.csv: row 2 (line 3), column `off_before_s`: 9999 s, but `switch_on_s` puts this switch-on"),
        "{text}"
    );
    assert!(!refused.exists());
}

/// A real PX4 log in the sheet (pyulog's sample, when the shared data is present): one of its
/// three gyros, chosen by `--ulog-instance`, with the sheet's labels.
#[test]
fn a_ulog_named_by_a_sheet_imports_one_gyro_with_the_sheet_labels() {
    let log = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/formats/px4-ulog/sample_log_small.ulg");
    if !log.exists() {
        eprintln!("skipped: {} is not here", log.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(&log, d.join("flight.ulg")).unwrap();
    let sheet_path = d.join("sheet.csv");
    std::fs::write(
        &sheet_path,
        "file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s\nflight.ulg,PX4,25,1,1,1,,field,0\n",
    )
    .unwrap();
    let import = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "import",
            "campaign",
            sheet_path.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--rate-hz",
            "10",
            "--max-gap",
            "2",
        ];
        args.extend_from_slice(extra);
        gyrodrift(&args)
    };
    let (status, text) = import(&d.join("refused"), &[]);
    assert_eq!(status.status.code(), Some(2), "{text}");
    assert!(
        text.contains("sheet.csv: row 1 (line 2), column `file`: ")
            && text.contains("flight.ulg: 3 gyros (sensor_gyro instance 0, sensor_gyro instance 1, sensor_gyro instance 2)")
            && text.contains("`--ulog-instance`"),
        "{text}"
    );
    let out = d.join("out");
    let (status, text) = import(&out, &["--ulog-instance", "1"]);
    assert!(status.status.success(), "{text}");
    let r = read_recording(&out.join("recordings/PX4_sp+25.0C_field.mcap")).unwrap();
    assert_eq!(r.segments.len(), 1);
    assert_eq!(r.segments[0].labels.unit_id, "PX4");
    assert_eq!(r.segments[0].labels.set_point_celsius, 25.0);
    assert!(r.segments[0].len() > 10);
}
