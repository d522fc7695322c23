//! `gyrodrift import csv` end to end: a CSV made here (irregular millisecond timestamps, rad/s,
//! accelerometer columns) → a campaign folder → its MCAP contents; bad inputs named by file, row,
//! column or option with nothing written; extra columns as named auxiliary channels (`--aux`); the
//! rest of the loop on data the paper's method cannot be fitted on; and the measured MPU6050 file
//! of `../shared/data/measured/` when it is present.

use std::path::{Path, PathBuf};

use drift_recording::{read_campaign_dir, read_recording, RAW_PER_CELSIUS};

mod common;

use common::{gyrodrift, ok};

fn fails(args: &[&str]) -> String {
    let (out, text) = gyrodrift(args);
    assert!(!out.status.success(), "{args:?} succeeded: {text}");
    text
}

const RAD_PER_S: [f64; 3] = [0.01, -0.002, 0.0005];

/// Activation `id`: rows at 100 Hz with ±3 ms jitter (deterministic), one 0.2 s pause, times in
/// ms from `start_ms`; rates constant in rad/s plus 0.001 rad/s per °C; temperature rising
/// 0.2 °C per 10 s from `celsius0`; gravity on `g_axis`.
fn rows(id: u32, seconds: f64, start_ms: f64, celsius0: f64, g_axis: usize) -> (String, f64) {
    let mut text = String::new();
    let mut t = 0.0_f64;
    let mut k = 0u32;
    while t <= seconds {
        let celsius = celsius0 + 0.02 * t;
        let rate: Vec<String> = RAD_PER_S
            .iter()
            .map(|r| format!("{}", r + 0.001 * (celsius - celsius0)))
            .collect();
        let g: Vec<&str> = (0..3)
            .map(|a| if a == g_axis { "1.0" } else { "0.0" })
            .collect();
        text.push_str(&format!(
            "{id},{},{},{celsius},{},x\n",
            start_ms + 1000.0 * t,
            rate.join(","),
            g.join(",")
        ));
        k += 1;
        // Jitter of −3, 0, +3 ms around 10 ms steps, and one 0.2 s pause at row 50.
        t += 0.010 + 0.003 * f64::from(k % 3) - 0.003;
        if k == 50 {
            t += 0.2;
        }
    }
    (text, t)
}

const HEADER: &str = "seg,time_ms,wx,wy,wz,temp,ax,ay,az,note\n";

fn write_csv(dir: &Path) -> (PathBuf, [f64; 2]) {
    let (a, last_a) = rows(7, 30.0, 5000.0, 24.0, 2);
    let (b, last_b) = rows(8, 20.0, 0.0, 24.5, 0);
    let path = dir.join("bench.csv");
    std::fs::write(&path, format!("{HEADER}{a}{b}")).unwrap();
    (path, [last_a, last_b])
}

fn import_args<'a>(csv: &'a str, out: &'a str) -> Vec<&'a str> {
    vec![
        "import",
        "csv",
        csv,
        "-o",
        out,
        "--time-column",
        "time_ms",
        "--time-unit",
        "ms",
        "--rate-columns",
        "wx,wy,wz",
        "--rate-unit",
        "rad/s",
        "--temperature-columns",
        "temp",
        "--segment-column",
        "seg",
        "--accel-columns",
        "ax,ay,az",
        "--rate-hz",
        "100",
        "--timing",
        "resample",
        "--max-gap",
        "0.5",
        "--unit-id",
        "BENCH",
    ]
}

#[test]
fn a_csv_with_irregular_ms_times_and_rad_per_s_becomes_a_campaign_the_tools_read() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = write_csv(dir.path());
    let campaign = dir.path().join("campaign");
    let (c, s) = (csv.to_str().unwrap(), campaign.to_str().unwrap());
    let text = ok(&import_args(c, s));
    assert!(text.contains("→ 2 activations"), "{text}");
    // One steady 0.2 s pause per activation: steps over two periods are counted and reported.
    assert!(text.contains("2 steps over two periods"), "{text}");

    let mcap = campaign.join("recordings/BENCH_bench.mcap");
    let rec = read_recording(&mcap).unwrap();
    assert_eq!(rec.unit_id, "BENCH");
    assert_eq!(rec.sample_rate_hz, 100);
    assert_eq!(rec.segments.len(), 2);
    // The same through the campaign reader the commands use.
    assert_eq!(read_campaign_dir(&campaign).unwrap().len(), 1);

    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(campaign.join("import.json")).unwrap())
            .unwrap();
    let to_dps = 180.0 / std::f64::consts::PI;
    for (k, segment) in rec.segments.iter().enumerate() {
        // Grid: from the activation's first row every 10 ms up to its last row.
        let n = segment.len();
        assert_eq!(manifest["activations"][k]["samples"], n);
        let seconds = [30.0, 20.0][k];
        assert!(
            (n as f64 / 100.0 - seconds).abs() < 0.05,
            "activation {k}: {n} samples"
        );
        // Rates: rad/s → °/s, and the temperature term interpolated exactly (linear in time).
        for i in [0, n / 2, n - 1] {
            let celsius = segment.temperature_celsius(0, i).unwrap();
            let c0 = [24.0, 24.5][k];
            for (axis, rad_per_s) in RAD_PER_S.iter().enumerate() {
                let expected = (rad_per_s + 0.001 * (celsius - c0)) * to_dps;
                let got = f64::from(segment.rate_dps[axis][i]);
                // The temperature is stored in 1/200 °C: its rounding bounds the comparison.
                let tolerance = 0.001 * to_dps * 0.5 / RAW_PER_CELSIUS + 1e-5;
                assert!(
                    (got - expected).abs() < tolerance,
                    "activation {k}, sample {i}, axis {axis}: {got} vs {expected}"
                );
            }
            // 0.02 °C/s from c0: sample i is at i / 100 s.
            let expected = c0 + 0.02 * i as f64 / 100.0;
            assert!((celsius - expected).abs() <= 0.5 / RAW_PER_CELSIUS + 1e-9);
        }
        // Accelerometer: the aux channel at 100 Hz, one value per gyro sample here.
        let g_axis = [2, 0][k];
        for (a, name) in ["accel_x", "accel_y", "accel_z"].iter().enumerate() {
            let channel = &segment.aux[*name];
            assert_eq!(channel.values.len(), n, "{name}");
            let expected = if a == g_axis { 1.0 } else { 0.0 };
            assert!(channel.values.iter().all(|&v| v == expected), "{name}");
        }
        assert_eq!(segment.labels.series, k as u32 + 1);
    }
    assert_eq!(rec.metadata["csv_rows"], manifest["metadata"]["csv_rows"]);

    // The same import into one .mcap file gives the same segments.
    let single = dir.path().join("one.mcap");
    ok(&import_args(c, single.to_str().unwrap()));
    let again = read_recording(&single).unwrap();
    for (a, b) in again.segments.iter().zip(&rec.segments) {
        assert_eq!(
            (&a.rate_dps, &a.temperature_raw),
            (&b.rate_dps, &b.temperature_raw)
        );
    }

    // The loop: the paper's method cannot be fitted (no warm-up, one ambient, no power cycles),
    // and the commands say so by name.
    let tables = dir.path().join("tables");
    let text = fails(&["fit", s, "-q", "-o", tables.to_str().unwrap()]);
    assert!(
        text.contains("unit BENCH: the paper's method cannot be fitted")
            && text.contains("no power-on warm-up")
            && text.contains("one ambient")
            && text.contains("no power cycles"),
        "{text}"
    );
    assert!(!tables.exists());
    let text = fails(&[
        "diagnose",
        s,
        "-q",
        "-o",
        dir.path().join("d").to_str().unwrap(),
    ]);
    assert!(text.contains("cannot be fitted"), "{text}");
    // `report` writes what the data does tell instead.
    let report = dir.path().join("report");
    let text = ok(&["report", s, "-q", "-o", report.to_str().unwrap()]);
    assert!(
        text.contains("report (measured data, no tables fitted)"),
        "{text}"
    );
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    for section in [
        "## Why the paper's tables are not fitted",
        "## Noise floor",
        "## Bias against temperature (1-D)",
        "## Residual after a linear temperature correction",
        "## What this data cannot tell",
    ] {
        assert!(md.contains(section), "{section}");
    }
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(report.join("characterisation.json")).unwrap(),
    )
    .unwrap();
    let unit = &json[0];
    assert_eq!(unit["activations"].as_array().unwrap().len(), 2);
    // The built-in slope: 0.001 rad/s per °C on every axis.
    let slope = unit["axes"][0]["within_slope"]["value"].as_f64().unwrap();
    assert!(
        (slope - 0.001 * to_dps).abs() < 0.01 * 0.001 * to_dps,
        "{slope}"
    );
    let bias = unit["activations"][0]["axes"][0]["bias_dps"]
        .as_f64()
        .unwrap();
    assert!(
        (bias - (0.01 + 0.001 * 0.3) * to_dps).abs() < 0.01,
        "{bias}"
    );
    let kinds: Vec<&str> = unit["obstacles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["no_warm_up", "one_ambient", "no_power_cycles"]);
}

#[test]
fn bad_input_is_named_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = write_csv(dir.path());
    let campaign = dir.path().join("campaign");
    let (c, s) = (csv.to_str().unwrap(), campaign.to_str().unwrap());
    let with = |replace: &[(&str, &str)]| -> Vec<String> {
        let mut args: Vec<String> = import_args(c, s).iter().map(|a| a.to_string()).collect();
        for (option, value) in replace {
            let i = args.iter().position(|a| a == option).unwrap();
            args[i + 1] = value.to_string();
        }
        args
    };
    let run = |args: Vec<String>| fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    // A missing column: the file, the column and the header it was looked for in.
    let text = run(with(&[("--rate-columns", "wx,wy,omega_z")]));
    assert!(
        text.contains(&format!(
            "{c}: missing column `omega_z` (the header has: seg,time_ms,"
        )),
        "{text}"
    );
    // Bad unit options, by option and accepted values.
    let text = run(with(&[("--rate-unit", "rpm")]));
    assert!(
        text.contains("option `--rate-unit`: expected `deg/s` or `rad/s`, got `rpm`"),
        "{text}"
    );
    let text = run(with(&[("--time-unit", "us")]));
    assert!(
        text.contains("option `--time-unit`: expected `s` or `ms`, got `us`"),
        "{text}"
    );
    let text = run(with(&[("--timing", "nearest")]));
    assert!(text.contains("option `--timing`"), "{text}");
    let text = run(with(&[("--accel-columns", "ax,ay")]));
    assert!(
        text.contains("option `--accel-columns`: expected 3"),
        "{text}"
    );
    // Accelerometer at the format's 100 Hz needs a grid that is a multiple of it.
    let text = run(with(&[("--rate-hz", "250")]));
    assert!(text.contains("a multiple of it, got 250 Hz"), "{text}");
    // The 0.2 s pauses exceed a 0.1 s limit: the row after the first is named.
    let text = run(with(&[("--max-gap", "0.1")]));
    assert!(
        text.contains(&format!(
            "{c}: row 51 (line 52), column `time_ms`: gap: 0.2"
        )),
        "{text}"
    );
    // A bad value: file, row, line and column.
    let good = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<String> = good.lines().map(str::to_owned).collect();
    let mut fields: Vec<String> = lines[3].split(',').map(str::to_owned).collect();
    fields[3] = "n/a".into();
    lines[3] = fields.join(",");
    let broken = dir.path().join("broken.csv");
    std::fs::write(&broken, lines.join("\n") + "\n").unwrap();
    let b = broken.to_str().unwrap();
    let mut args = import_args(b, s);
    args[2] = b;
    let text = fails(&args);
    assert!(
        text.contains(&format!(
            "{b}: row 3 (line 4), column `wy`: `n/a` is not a number"
        )),
        "{text}"
    );
    // After every failure: nothing at all in the output.
    assert!(
        !campaign.exists(),
        "{:?}",
        std::fs::read_dir(&campaign).map(|d| d.count())
    );
}

#[test]
fn extra_columns_are_imported_as_named_channels() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("env.csv");
    let mut text = String::from("t_s,gx_dps,gy_dps,gz_dps,temp_c,rh,vbat\n");
    for i in 0..300 {
        let t = f64::from(i) / 100.0;
        text.push_str(&format!(
            "{t},0.01,0,0,30,{},{}\n",
            40.0 + 0.5 * f64::from(i),
            3.75 - f64::from(i % 4) / 8.0
        ));
    }
    std::fs::write(&csv, text).unwrap();
    let campaign = dir.path().join("campaign");
    let (c, s) = (csv.to_str().unwrap(), campaign.to_str().unwrap());
    let base = [
        "import",
        "csv",
        c,
        "-o",
        s,
        "--rate-hz",
        "100",
        "--no-segment-column",
        "--unit-id",
        "ENV",
    ];
    let with = |aux: &[&str]| -> Vec<String> {
        let mut args: Vec<String> = base.iter().map(|a| a.to_string()).collect();
        for a in aux {
            args.extend(["--aux".to_owned(), a.to_string()]);
        }
        args
    };
    let run = |args: Vec<String>| fails(&args.iter().map(String::as_str).collect::<Vec<_>>());
    // Bad mappings: named by option, nothing written.
    let text = run(with(&["humidity"]));
    assert!(
        text.contains(
            "option `--aux`: expected name=column or name=column:unit, got `humidity` (no `=`)"
        ),
        "{text}"
    );
    let text = run(with(&["rh/2=rh"]));
    assert!(
        text.contains(&format!(
            "{c}: option `columns.aux`: auxiliary channel `rh/2` has `/` at byte 2"
        )),
        "{text}"
    );
    let text = run(with(&["humidity=humidity"]));
    assert!(
        text.contains(&format!("{c}: missing column `humidity`")),
        "{text}"
    );
    assert!(!campaign.exists());

    let args = with(&["humidity=rh:%RH", "battery=vbat:V"]);
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let rec = read_recording(&campaign.join("recordings/ENV_env.mcap")).unwrap();
    let aux = &rec.segments[0].aux;
    assert_eq!(aux["humidity"].unit, "%RH");
    let expected: Vec<f32> = (0..300).map(|i| 40.0 + 0.5 * i as f32).collect();
    assert_eq!(aux["humidity"].values, expected);
    assert_eq!(aux["battery"].unit, "V");
    assert_eq!(aux["battery"].values[..4], [3.75, 3.625, 3.5, 3.375]);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(campaign.join("import.json")).unwrap())
            .unwrap();
    assert_eq!(manifest["activations"][0]["aux"]["humidity"], 300);
    assert_eq!(manifest["activations"][0]["aux"]["battery"], 300);
}

fn measured() -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/measured/mpu6050-static-sunsided/mpu6050_static.csv.gz");
    if path.exists() {
        Some(path)
    } else {
        println!("skipped: {} is absent", path.display());
        None
    }
}

#[test]
fn the_measured_mpu6050_file_imports_and_reports() {
    let Some(csv) = measured() else { return };
    let dir = tempfile::tempdir().unwrap();
    let campaign = dir.path().join("mpu6050");
    let (c, s) = (csv.to_str().unwrap(), campaign.to_str().unwrap());
    let text = ok(&[
        "import",
        "csv",
        c,
        "-o",
        s,
        "--rate-hz",
        "100",
        "--timing",
        "resample",
        "--max-gap",
        "0.5",
        "--accel-columns",
        "ax_g,ay_g,az_g",
        "--unit-id",
        "MPU6050",
    ]);
    // Its README: 120,346 rows in 7 recordings.
    assert!(text.contains("120346 rows → 7 activations"), "{text}");
    let rec = read_recording(&campaign.join("recordings/MPU6050_mpu6050_static.mcap")).unwrap();
    assert_eq!(rec.segments.len(), 7);
    let s4 = &rec.segments[4]; // the 10-minute recording: 655.1 s
    assert_eq!(s4.len(), 65_514);
    // The board is static: the accelerometer reads about 1 g in every activation.
    for (k, seg) in rec.segments.iter().enumerate() {
        let mean = |name: &str| {
            let v = &seg.aux[name].values;
            v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64
        };
        let g =
            (mean("accel_x").powi(2) + mean("accel_y").powi(2) + mean("accel_z").powi(2)).sqrt();
        assert!((0.9..1.1).contains(&g), "activation {k}: |a| = {g} g");
        assert_eq!(seg.aux["accel_x"].values.len(), seg.len());
    }
    let report = dir.path().join("report");
    let text = ok(&["report", s, "-q", "-o", report.to_str().unwrap()]);
    assert!(text.contains("no power-on warm-up"), "{text}");
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(report.join("characterisation.json")).unwrap(),
    )
    .unwrap();
    let x_bias = json[0]["activations"][4]["axes"][0]["bias_dps"]
        .as_f64()
        .unwrap();
    // Its README: bias X ≈ 4.54 °/s.
    assert!((x_bias - 4.54).abs() < 0.1, "{x_bias}");
}
