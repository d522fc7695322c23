//! `gyrodrift import campaign` end to end: a simulated campaign exported as one CSV file per
//! activation (some gzip-compressed) plus an activation sheet, by plain text formatting here (not
//! by gyrodrift), imports to recordings equal to the originals, and `fit` and `report` on the
//! import give the same tables and numbers byte for byte; `diagnose` and `check` take the
//! imported folder. Bad sheets and files are named by file, row and column, and a failed import
//! leaves nothing behind.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use drift_recording::{read_campaign_dir, Recording, Segment};

mod common;

use common::{gyrodrift, ok};

const CAMPAIGN: &str =
    "seed = 3\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [30, 40, 33]\n\
[protocol]\nintervals_min = [1, 30]\nrepeats = 2\nactivation_s = 60\n\
[field]\nsessions = 1\nactivations = 3\nactivation_s = [30, 60]\n";

const HEADER: &str = "t_s,gx_dps,gy_dps,gz_dps,temp_x,temp_y,temp_z,ax,ay,az,supply_v\n";

/// One activation as CSV text: time in s from switch-on, rates as the shortest decimal of their
/// f32, temperatures in °C (raw / 200), accelerometer and supply at their 100 Hz sample.
fn activation_csv(s: &Segment) -> String {
    let mut text = String::from(HEADER);
    let fs = f64::from(s.sample_rate_hz);
    let every = (s.sample_rate_hz / 100).max(1) as usize;
    let aux = |name: &str, i: usize| -> f32 {
        let v = &s.aux[name].values;
        v[(i / every).min(v.len() - 1)]
    };
    for i in 0..s.len() {
        let r = &s.rate_dps;
        let t = &s.temperature_raw;
        writeln!(
            text,
            "{},{},{},{},{},{},{},{},{},{},{}",
            f64::from(s.since_power_on[i]) / fs,
            r[0][i],
            r[1][i],
            r[2][i],
            f64::from(t[0][i]) / 200.0,
            f64::from(t[1][i]) / 200.0,
            f64::from(t[2][i]) / 200.0,
            aux("accel_x", i),
            aux("accel_y", i),
            aux("accel_z", i),
            aux("supply_voltage", i),
        )
        .unwrap();
    }
    text
}

fn optional(v: Option<f64>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

/// Writes every activation of `recordings` into `dir` (every third one gzip-compressed) and the
/// sheet `dir/sheet.csv`; returns the sheet's path.
fn export(recordings: &[Recording], dir: &Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir.join("data")).unwrap();
    let mut sheet = String::from(
        "file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s,interval_min,switch_on_ambient_celsius\n",
    );
    let mut k = 0;
    for r in recordings {
        let session: f64 = r.metadata["set_point_celsius"].parse().unwrap();
        for s in &r.segments {
            k += 1;
            let l = &s.labels;
            let text = activation_csv(s);
            let name = if k % 3 == 0 {
                let name = format!("data/a{k:03}.csv.gz");
                let file = std::fs::File::create(dir.join(&name)).unwrap();
                let mut gz = flate2::write::GzEncoder::new(file, flate2::Compression::fast());
                gz.write_all(text.as_bytes()).unwrap();
                gz.finish().unwrap();
                name
            } else {
                let name = format!("data/a{k:03}.csv");
                std::fs::write(dir.join(&name), text).unwrap();
                name
            };
            let ambient = (l.set_point_celsius != session).then_some(l.set_point_celsius);
            writeln!(
                sheet,
                "{name},{},{session},{},{},{},{},{},{}.{:09},{},{}",
                l.unit_id,
                l.series,
                l.repeat,
                l.activation,
                optional(l.off_before_s),
                l.series_kind.as_str(),
                s.power_on_ns / 1_000_000_000,
                s.power_on_ns % 1_000_000_000,
                optional(l.interval_min),
                optional(ambient),
            )
            .unwrap();
        }
    }
    let path = dir.join("sheet.csv");
    std::fs::write(&path, sheet).unwrap();
    path
}

/// A recording's segments without the format's own auxiliary channels that CSV does not carry
/// (the chamber set point).
fn comparable(r: &Recording) -> Vec<Segment> {
    r.segments
        .iter()
        .cloned()
        .map(|mut s| {
            s.aux.remove("chamber_set_point");
            s
        })
        .collect()
}

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let name = p.strip_prefix(dir).unwrap().display().to_string();
                out.push((name, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn a_campaign_exported_as_csv_files_and_a_sheet_imports_fits_and_reports_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("campaign.toml"), CAMPAIGN).unwrap();
    let original = d.join("original");
    let o = original.to_str().unwrap();
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        d.join("campaign.toml").to_str().unwrap(),
        "-o",
        o,
    ]);
    let recordings = read_campaign_dir(&original).unwrap();
    assert_eq!(
        recordings.len(),
        6,
        "protocol and field at three set points"
    );
    let sheet = export(&recordings, &d.join("bench"));
    let imported = d.join("imported");
    let i = imported.to_str().unwrap();
    let text = ok(&[
        "import",
        "campaign",
        sheet.to_str().unwrap(),
        "-o",
        i,
        "--rate-hz",
        "100",
        "--temperature-columns",
        "temp_x,temp_y,temp_z",
        "--accel-columns",
        "ax,ay,az",
        "--supply-column",
        "supply_v",
    ]);
    assert!(text.contains("6 recordings"), "{text}");
    assert!(imported.join("import.json").is_file());
    // The same recordings: names, metadata that the pipeline reads, labels, clock and samples.
    let back = read_campaign_dir(&imported).unwrap();
    assert_eq!(back.len(), recordings.len());
    for (a, b) in recordings.iter().zip(&back) {
        assert_eq!(a.path.file_name(), b.path.file_name());
        for key in [
            "unit_id",
            "set_point_celsius",
            "series_kind",
            "sample_rate_hz",
        ] {
            assert_eq!(a.metadata[key], b.metadata[key], "{key} of {:?}", a.path);
        }
        assert_eq!(comparable(a), comparable(b), "{:?}", a.path);
    }
    // Fit and report on both: the same tables and numbers, byte for byte.
    for (campaign, out) in [(o, "fit-original"), (i, "fit-imported")] {
        ok(&["fit", campaign, "-q", "-o", d.join(out).to_str().unwrap()]);
    }
    // The tables, byte for byte; not `calibration-data.json`, which names each calibration
    // recording by its bytes (an import writes other bytes for the same data).
    let fitted = |out: &str| -> Vec<(String, Vec<u8>)> {
        files(&d.join(out))
            .into_iter()
            .filter(|(n, _)| !n.ends_with("calibration-data.json"))
            .collect()
    };
    let tables = fitted("fit-original");
    assert!(tables.iter().any(|(n, _)| n.ends_with("modified.bin")));
    assert_eq!(tables, fitted("fit-imported"));
    for (campaign, out) in [(o, "report-original"), (i, "report-imported")] {
        ok(&[
            "report",
            campaign,
            "-q",
            "-o",
            d.join(out).to_str().unwrap(),
        ]);
    }
    for name in ["report.json", "report.md"] {
        let a = std::fs::read_to_string(d.join("report-original").join(name)).unwrap();
        let b = std::fs::read_to_string(d.join("report-imported").join(name)).unwrap();
        let a = a.replace(o, "CAMPAIGN");
        let b = b.replace(i, "CAMPAIGN");
        assert_eq!(a, b, "{name}");
    }
    // The other commands take the imported folder.
    let tables = d.join("fit-imported");
    ok(&[
        "diagnose",
        i,
        "-q",
        "-o",
        d.join("diagnosis").to_str().unwrap(),
    ]);
    let (out, text) = gyrodrift(&[
        "check",
        i,
        "--tables",
        tables.to_str().unwrap(),
        "-o",
        d.join("check").to_str().unwrap(),
    ]);
    assert!(
        out.status.code().is_some_and(|c| c == 0 || c == 1),
        "{text}"
    );
    assert!(d.join("check").join("check.json").is_file(), "{text}");
}

/// Two activations of one unit at +30 °C, at 10 Hz.
fn small_bench(dir: &Path, sheet_rows: &[&str], second_file: &str) -> std::path::PathBuf {
    let rows = |t0: f64| {
        let mut text = String::from("t_s,gx_dps,gy_dps,gz_dps,temp_c\n");
        for k in 0..20 {
            writeln!(
                text,
                "{},0.01,0.02,0.03,{}",
                t0 + f64::from(k) / 10.0,
                30.0 + 0.01 * f64::from(k)
            )
            .unwrap();
        }
        text
    };
    std::fs::write(dir.join("one.csv"), rows(0.0)).unwrap();
    std::fs::write(dir.join("two.csv"), second_file.replace("ROWS", &rows(5.0))).unwrap();
    let mut sheet = String::from(
        "file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s\n",
    );
    for row in sheet_rows {
        sheet.push_str(row);
        sheet.push('\n');
    }
    let path = dir.join("sheet.csv");
    std::fs::write(&path, sheet).unwrap();
    path
}

fn import_fails(sheet: &Path, out: &Path) -> String {
    let (status, text) = gyrodrift(&[
        "import",
        "campaign",
        sheet.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--rate-hz",
        "10",
    ]);
    assert!(!status.status.success(), "{text}");
    assert!(!out.exists(), "a failed import left {}", out.display());
    let parent = out.parent().unwrap();
    let left: Vec<_> = std::fs::read_dir(parent)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("importing"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    text
}

#[test]
fn bad_sheets_and_files_are_named_by_file_row_and_column_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out");
    let good = [
        "one.csv,U1,30,1,1,1,,protocol,0",
        "two.csv,U1,30,1,1,2,60,protocol,62",
    ];
    // The good case first: it imports, with the labels of the sheet.
    let sheet = small_bench(d, &good, "ROWS");
    let text = ok(&[
        "import",
        "campaign",
        sheet.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--rate-hz",
        "10",
    ]);
    assert!(
        text.contains("U1_sp+30.0C_protocol.mcap: 2 activations"),
        "{text}"
    );
    let back = read_campaign_dir(&out).unwrap();
    let s = &back[0].segments[1];
    assert_eq!(
        (s.labels.activation, s.labels.off_before_s, s.power_on_ns),
        (2, Some(60.0), 62_000_000_000)
    );
    // Importing into it again is refused unless --force: an import never adds to another.
    let (status, text) = gyrodrift(&[
        "import",
        "campaign",
        sheet.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--rate-hz",
        "10",
    ]);
    assert!(
        status.status.code() == Some(2) && text.contains("pass --force to replace the import"),
        "{text}"
    );
    std::fs::remove_dir_all(&out).unwrap();

    // A bad cell in an activation file: the sheet's row, the file, its row and its column.
    let sheet = small_bench(d, &good, "ROWS7.0,x,0,0,30\n");
    let text = import_fails(&sheet, &out);
    assert!(
        text.contains("sheet.csv: row 2 (line 3), column `file`")
            && text.contains("two.csv: row 21 (line 22), column `gx_dps`: `x` is not a number"),
        "{text}"
    );
    let cases: [(&[&str], &str); 6] = [
        (
            &["one.csv,U1,30,1,1,1,,protocol,0", "two.csv,U1,30,1,1,2,60,protocol,1"],
            "row 2 (line 3), column `switch_on_s`: switch-on at 1 s is not after the end",
        ),
        (
            &["one.csv,U1,30,1,1,1,,protocol,0", "gone.csv,U1,30,1,1,2,60,protocol,62"],
            "row 2 (line 3), column `file`: no such file",
        ),
        (
            &["one.csv,U1,30,1,1,1,,protocol,0", "two.csv,U1,30,1,1,1,60,protocol,62"],
            "row 2 (line 3), column `activation`: unit U1, protocol series 1, repeat 1, activation 1 at 30 °C is already in row 1",
        ),
        (
            &["one.csv,U1,30,1,1,1,,chamber,0"],
            "row 1 (line 2), column `series_kind`: expected `protocol` or `field`, got `chamber`",
        ),
        (
            &["one.csv,U1,warm,1,1,1,,protocol,0"],
            "row 1 (line 2), column `set_point_celsius`: `warm` is not a finite number",
        ),
        (
            &["one.csv,U1,30,0,1,1,,protocol,0"],
            "row 1 (line 2), column `series`: expected a whole number ≥ 1, got `0`",
        ),
    ];
    for (rows, expected) in cases {
        let sheet = small_bench(d, rows, "ROWS");
        let text = import_fails(&sheet, &out);
        assert!(
            text.contains("sheet.csv: ") && text.contains(expected),
            "{rows:?}: {text}"
        );
    }
    // A missing column is named with what the header has.
    std::fs::write(d.join("sheet.csv"), "file,unit\none.csv,U1\n").unwrap();
    let text = import_fails(&d.join("sheet.csv"), &out);
    assert!(
        text.contains("missing column `set_point_celsius`"),
        "{text}"
    );
}
