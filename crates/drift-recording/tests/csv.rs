//! The CSV reader: the column mapping, each kind of bad row named by file, column and row, and the
//! measured MPU6050 file of `../shared/data/measured/` (read when present).

use std::path::{Path, PathBuf};

use drift_recording::{
    read_csv, read_csv_bytes, read_recording, write_recording, CsvAuxColumn, CsvColumns, CsvError,
    CsvOptions, CsvTiming, TEMPERATURE_MISSING_RAW,
};

const HEADER: &str = "segment_id,t_s,gx_dps,gy_dps,gz_dps,temp_c,extra\n";

/// `n` rows of activation `id` at `rate` Hz, warming by 0.005 °C per row from 30 °C.
fn rows(id: u32, n: u32, rate: f64) -> String {
    (0..n)
        .map(|i| {
            let t = f64::from(i) / rate;
            format!(
                "{id},{t},0.01,{},-0.5,{},x\n",
                f64::from(i) * 1e-3,
                30.0 + 0.005 * f64::from(i)
            )
        })
        .collect()
}

fn strict(rate: u32) -> CsvOptions {
    CsvOptions {
        sample_rate_hz: rate,
        ..CsvOptions::default()
    }
}

/// The error for `text` read as `bench.csv`, as text, checked to name the file.
fn error(text: &str, options: &CsvOptions) -> String {
    let message = read_csv_bytes(Path::new("bench.csv"), text.as_bytes(), options)
        .unwrap_err()
        .to_string();
    assert!(message.starts_with("bench.csv: "), "{message}");
    message
}

#[test]
fn fixed_rate_rows_read_into_one_segment_per_activation() {
    let text = format!("{HEADER}{}{}", rows(0, 50, 100.0), rows(1, 30, 100.0));
    let rec = read_csv_bytes(Path::new("bench.csv"), text.as_bytes(), &strict(100)).unwrap();
    assert_eq!(rec.segments.len(), 2);
    let s = &rec.segments[0];
    assert_eq!((s.len(), s.sample_rate_hz, s.labels.series), (50, 100, 1));
    assert_eq!(s.temperature_raw[0][0], 6000);
    assert_eq!(s.temperature_raw[2][49], 6049); // 30.245 °C → 6049 raw
    assert!((s.labels.set_point_celsius - 30.0).abs() < 1e-9);
    assert_eq!(rec.segments[1].labels.series, 2);
    // Both activations start at t = 0: laid out one after the other, so MCAP's log times increase.
    assert!(rec.segments[1].power_on_ns > rec.segments[0].power_on_ns);
    // CSV → MCAP → the same segments.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bench.mcap");
    write_recording(&rec, &path).unwrap();
    let back = read_recording(&path).unwrap();
    for (a, b) in back.segments.iter().zip(&rec.segments) {
        assert_eq!(
            (&a.rate_dps, &a.temperature_raw),
            (&b.rate_dps, &b.temperature_raw)
        );
    }
}

#[test]
fn a_custom_column_mapping_with_one_sensor_per_axis() {
    let text = "time,wx,wy,wz,tx,ty,tz\n0,1,2,3,20,21,22\n0.001,1,2,3,20,21,22\n";
    let options = CsvOptions {
        columns: CsvColumns {
            time_s: "time".into(),
            rate_dps: ["wx".into(), "wy".into(), "wz".into()],
            temperature_celsius: ["tx".into(), "ty".into(), "tz".into()],
            segment: None,
            ..CsvColumns::default()
        },
        set_point_celsius: Some(25.0),
        ..CsvOptions::default()
    };
    let rec = read_csv_bytes(Path::new("b.csv"), text.as_bytes(), &options).unwrap();
    let s = &rec.segments[0];
    assert_eq!(s.len(), 2);
    assert_eq!(
        [
            s.temperature_raw[0][1],
            s.temperature_raw[1][1],
            s.temperature_raw[2][1]
        ],
        [4000, 4200, 4400]
    );
    assert_eq!(s.labels.set_point_celsius, 25.0);
    assert_eq!(rec.metadata["set_point_celsius"], "25");
}

fn named(channel: &str, column: &str, unit: &str) -> CsvAuxColumn {
    CsvAuxColumn {
        channel: channel.into(),
        column: column.into(),
        unit: unit.into(),
    }
}

#[test]
fn extra_columns_become_named_channels_and_reach_the_mcap() {
    // 1 kHz rows: the named channels take every 10th row (the format's 100 Hz), like supply.
    let header = "segment_id,t_s,gx_dps,gy_dps,gz_dps,temp_c,rh,v_bat,vin\n";
    let text: String = (0..250)
        .map(|i| {
            let t = f64::from(i) / 1000.0;
            format!(
                "0,{t},0.01,0,0,30,{},{},{}\n",
                40.0 + f64::from(i) * 0.01,
                3.7 - f64::from(i) * 1e-4,
                12.0 + f64::from(i % 7)
            )
        })
        .collect();
    let options = CsvOptions {
        columns: CsvColumns {
            supply_voltage: Some("vin".into()),
            aux: vec![
                named("humidity", "rh", "%RH"),
                named("battery.v", "v_bat", ""),
            ],
            ..CsvColumns::default()
        },
        ..strict(1000)
    };
    let rec = read_csv_bytes(
        Path::new("b.csv"),
        format!("{header}{text}").as_bytes(),
        &options,
    )
    .unwrap();
    let s = &rec.segments[0];
    let humidity = &s.aux["humidity"];
    assert_eq!(
        (humidity.unit.as_str(), humidity.sample_rate_hz),
        ("%RH", 100)
    );
    let expected: Vec<f32> = (0..25)
        .map(|j| (40.0 + f64::from(j * 10) * 0.01) as f32)
        .collect();
    assert_eq!(humidity.values, expected);
    assert_eq!(s.aux["battery.v"].unit, "");
    assert_eq!(s.aux["battery.v"].values[24], (3.7 - 240.0 * 1e-4) as f32);
    assert_eq!(s.aux["supply_voltage"].values[1], 15.0); // row 10: 12 + 3
                                                         // CSV → MCAP → the same channels, on their own topics.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.mcap");
    write_recording(&rec, &path).unwrap();
    let back = read_recording(&path).unwrap();
    assert_eq!(back.segments[0].aux["humidity"], *humidity);
    assert_eq!(back.segments[0].aux["battery.v"], s.aux["battery.v"]);
}

#[test]
fn a_bad_named_column_mapping_is_refused_before_reading_rows() {
    let text = format!("{HEADER}{}", rows(0, 5, 100.0));
    let with = |aux: Vec<CsvAuxColumn>| CsvOptions {
        columns: CsvColumns {
            aux,
            ..CsvColumns::default()
        },
        ..strict(100)
    };
    let cases: [(Vec<CsvAuxColumn>, &str); 4] = [
        (
            vec![named("rh 2", "extra", "")],
            "bench.csv: option `columns.aux`: auxiliary channel `rh 2` has ` ` at byte 2",
        ),
        (
            vec![named("supply_voltage", "extra", "V")],
            "bench.csv: option `columns.aux`: auxiliary channel `supply_voltage` is one of the format's own channels",
        ),
        (
            vec![named("a", "temp_c", "degC"), named("a", "gx_dps", "")],
            "bench.csv: option `columns.aux`: auxiliary channel `a` is mapped twice",
        ),
        (
            vec![named("humidity", "rh", "%RH")],
            "bench.csv: missing column `rh` (the header has: segment_id,t_s,",
        ),
    ];
    for (aux, expected) in cases {
        let message = error(&text, &with(aux));
        assert!(message.starts_with(expected), "{message}");
    }
    // A named column is a number like any other: the row and the column are named.
    let text = format!("{HEADER}{}", rows(0, 5, 100.0));
    let message = error(&text, &with(vec![named("note", "extra", "")]));
    assert!(
        message.starts_with("bench.csv: row 1 (line 2), column `extra`: `x` is not a number"),
        "{message}"
    );
}

#[test]
fn each_bad_row_is_named_by_column_and_row() {
    let good = rows(0, 5, 100.0);
    let opts = strict(100);
    let cases: Vec<(String, &[&str])> = vec![
        // Missing column: named, with the header it was looked for in.
        (
            "segment_id,t_s,gx_dps,gy_dps,temp_c\n0,0,1,1,30\n".into(),
            &[
                "missing column `gz_dps`",
                "segment_id,t_s,gx_dps,gy_dps,temp_c",
            ],
        ),
        // Mismatched counts: a row with fewer fields than the header.
        (
            format!("{HEADER}{good}0,0.05,1,1,30,x\n"),
            &["row 6 (line 7)", "6 fields, the header has 7"],
        ),
        // NaN and infinite rates.
        (
            format!("{HEADER}{good}0,0.05,NaN,0,0,30,x\n"),
            &["row 6 (line 7), column `gx_dps`", "non-finite rate NaN"],
        ),
        (
            format!("{HEADER}{good}0,0.05,0,inf,0,30,x\n"),
            &["column `gy_dps`", "non-finite rate inf"],
        ),
        // Not a number.
        (
            format!("{HEADER}{good}0,0.05,0,0,zero,30,x\n"),
            &["row 6 (line 7), column `gz_dps`", "`zero` is not a number"],
        ),
        // A temperature cell left empty (a dropout) without temperature_dropouts.
        (
            format!("{HEADER}{good}0,0.05,0,0,0,,x\n"),
            &["column `temp_c`", "missing temperature"],
        ),
        // Outside the raw int16 range.
        (
            format!("{HEADER}{good}0,0.05,0,0,0,400,x\n"),
            &["column `temp_c`", "outside the raw range"],
        ),
        // Duplicate and backwards time.
        (
            format!("{HEADER}{good}0,0.04,0,0,0,30,x\n"),
            &["row 6 (line 7), column `t_s`", "duplicate time 0.04"],
        ),
        (
            format!("{HEADER}{good}0,0.01,0,0,0,30,x\n"),
            &[
                "column `t_s`",
                "time 0.01 s goes back (previous row 0.04 s)",
            ],
        ),
        // A gap in a fixed-rate stream (dropped samples) and an off-grid row.
        (
            format!("{HEADER}{good}0,0.08,0,0,0,30,x\n"),
            &[
                "row 6 (line 7), column `t_s`",
                "gap: time 0.08 s is sample 8.00",
                "expected sample 5",
                "`--timing resample --rate-hz",
            ],
        ),
        (
            format!("{HEADER}{good}0,0.0449,0,0,0,30,x\n"),
            &["row 6", "early sample"],
        ),
        // Rows of one activation split by another.
        (
            format!("{HEADER}{good}1,0,0,0,0,30,x\n0,0.05,0,0,0,30,x\n"),
            &[
                "row 7 (line 8), column `segment_id`",
                "activation `0` resumes after activation `1`",
            ],
        ),
        // No data.
        (HEADER.into(), &["no data rows"]),
    ];
    for (text, expected) in cases {
        let message = error(&text, &opts);
        for part in expected {
            assert!(message.contains(part), "expected `{part}` in: {message}");
        }
    }
    let bad_rate = CsvOptions {
        sample_rate_hz: 7,
        ..strict(100)
    };
    assert!(error(&format!("{HEADER}{good}"), &bad_rate).contains("option `sample_rate_hz`"));
}

#[test]
fn host_timestamps_resample_and_gaps_beyond_the_limit_are_named() {
    let options = CsvOptions {
        sample_rate_hz: 100,
        timing: CsvTiming::Resample { max_gap_s: 0.1 },
        ..CsvOptions::default()
    };
    // Jittered times: 0, 4, 13, 31 ms; values linear in time, so resampling is exact.
    let text = format!("{HEADER}0,0,0,0,0,30,x\n0,0.004,4,0,0,30.004,x\n0,0.013,13,0,0,30.013,x\n0,0.031,31,0,0,30.031,x\n");
    let rec = read_csv_bytes(Path::new("host.csv"), text.as_bytes(), &options).unwrap();
    let s = &rec.segments[0];
    assert_eq!(s.len(), 4); // 0, 10, 20, 30 ms
    for (i, expected) in [0.0f32, 10.0, 20.0, 30.0].iter().enumerate() {
        assert!(
            (s.rate_dps[0][i] - expected).abs() < 1e-4,
            "{i}: {}",
            s.rate_dps[0][i]
        );
    }
    assert_eq!(s.temperature_raw[0][3], 6006); // 30.03 °C
    let text = format!("{HEADER}0,0,0,0,0,30,x\n0,0.05,0,0,0,30,x\n0,0.3,0,0,0,30,x\n");
    let message = error(&text, &options);
    assert!(
        message.contains("row 3 (line 4), column `t_s`") && message.contains("gap: 0.250 s"),
        "{message}"
    );
}

#[test]
fn temperature_dropouts_are_read_as_the_missing_marker_when_allowed() {
    let options = CsvOptions {
        temperature_dropouts: true,
        ..strict(100)
    };
    let text = format!(
        "{HEADER}0,0,0,0,0,30,x\n0,0.01,0,0,0,,x\n0,0.02,0,0,0,nan,x\n0,0.03,0,0,0,30.1,x\n"
    );
    let rec = read_csv_bytes(Path::new("drop.csv"), text.as_bytes(), &options).unwrap();
    let raw = &rec.segments[0].temperature_raw[1];
    assert_eq!(
        raw,
        &vec![6000, TEMPERATURE_MISSING_RAW, TEMPERATURE_MISSING_RAW, 6020]
    );
    assert_eq!(rec.segments[0].first_missing_temperature(), Some((0, 1)));
    // Rates never accept one.
    let text = format!("{HEADER}0,0,,0,0,30,x\n");
    assert!(error(&text, &options).contains("column `gx_dps`"));
}

#[test]
fn gzip_files_and_their_corruption() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let text = format!("{HEADER}{}", rows(0, 2000, 1000.0));
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(text.as_bytes()).unwrap();
    let bytes = gz.finish().unwrap();
    let path = dir.path().join("bench.csv.gz");
    std::fs::write(&path, &bytes).unwrap();
    assert_eq!(
        read_csv(&path, &strict(1000)).unwrap().segments[0].len(),
        2000
    );
    // Truncated: the error names the file and says gzip, before any row is parsed.
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let message = read_csv(&path, &strict(1000)).unwrap_err().to_string();
    assert!(
        message.contains("bench.csv.gz: gzip:")
            && message.contains("the compressed file is corrupt or cut short"),
        "{message}"
    );
    // A missing file is an I/O error naming it.
    let ghost = dir.path().join("ghost.csv");
    assert!(
        matches!(read_csv(&ghost, &strict(1000)), Err(CsvError::Io { path, .. }) if path == ghost)
    );
}

fn measured() -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/measured/mpu6050-static-sunsided/mpu6050_static.csv.gz");
    if path.exists() {
        Some(path)
    } else {
        println!(
            "skipped: {} is not present (the shared measured data)",
            path.display()
        );
        None
    }
}

#[test]
fn the_measured_mpu6050_file_reads_resampled_and_is_refused_as_fixed_rate() {
    let Some(path) = measured() else { return };
    // Its README: 7 static recordings, host timestamps at ≈100 Hz with pauses up to ~0.5 s.
    let rec = read_csv(&path, &CsvOptions::mpu6050_static()).unwrap();
    assert_eq!(rec.segments.len(), 7);
    let seconds: f64 = rec.segments.iter().map(|s| s.len() as f64 / 100.0).sum();
    assert!((1200.0..1250.0).contains(&seconds), "{seconds} s");
    let s = &rec.segments[4]; // the 10-minute recording: 655.1 s
    assert_eq!(s.len(), 65_514);
    // Its README: bias ≈ [4.54, 0.05–0.12, 1.02–1.12] °/s, die temperature 25.14–25.61 °C.
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    assert!(
        (mean(&s.rate_dps[0]) - 4.54).abs() < 0.1,
        "{}",
        mean(&s.rate_dps[0])
    );
    let (lo, hi) = s.temperature_raw[0]
        .iter()
        .fold((i16::MAX, i16::MIN), |(l, h), &r| (l.min(r), h.max(r)));
    assert!(lo >= 5020 && hi <= 5130, "{lo}..{hi} raw");
    // As fixed-rate rows it is refused at its first jittered row, by file, column and row.
    let message = read_csv(
        &path,
        &CsvOptions {
            timing: CsvTiming::Strict,
            ..CsvOptions::mpu6050_static()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("mpu6050_static.csv.gz: row 2 (line 3), column `t_s`"),
        "{message}"
    );
}
