//! `gyrodrift import ulog`: the two real PX4 logs of `../shared/data/formats/px4-ulog/` (skipped
//! when absent) import with every `sensor_gyro` instance as a unit, or the older log's
//! `sensor_combined`; a simulated series written here as one ULog file per activation (plain
//! bytes, not through gyrodrift) imports back to the same samples.

use std::path::{Path, PathBuf};

use drift_recording::{read_campaign_dir, read_recording, Segment};

mod common;

use common::{gyrodrift, ok};

fn fixture(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/formats/px4-ulog")
        .join(name);
    path.exists().then_some(path)
}

fn celsius_range(s: &Segment) -> (f64, f64) {
    let c: Vec<f64> = (0..s.len())
        .map(|i| s.temperature_celsius(0, i).unwrap())
        .collect();
    (
        c.iter().copied().fold(f64::INFINITY, f64::min),
        c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

#[test]
fn the_px4_fixtures_import_one_unit_per_gyro_instance() {
    let (Some(small), Some(appended)) = (
        fixture("sample_log_small.ulg"),
        fixture("sample_appended_multiple.ulg"),
    ) else {
        println!("skipped: the PX4 fixtures are absent");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("small");
    // Logged at 1 Hz: a 1 Hz grid.
    let args = [
        "import",
        "ulog",
        small.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--rate-hz",
        "1",
        "--max-gap",
        "1.5",
    ];
    ok(&args);
    let recordings = read_campaign_dir(&out).unwrap();
    let units: Vec<&str> = recordings.iter().map(|r| r.unit_id.as_str()).collect();
    assert_eq!(units, ["px4-gyro0", "px4-gyro1", "px4-gyro2"]);
    // pyulog 1.3.0: 6 messages each over 5.0 s; temperatures 40.025–40.361, 28.246–28.368,
    // 29.434–29.722 °C (`crates/drift-recording/tests/ulog_fixtures.rs`); the grid interpolates
    // between messages, so its range lies within theirs (to the raw step, 0.005 °C).
    let ranges = [(40.02, 40.365), (28.24, 28.373), (29.43, 29.727)];
    for (r, (lo, hi)) in recordings.iter().zip(ranges) {
        let s = &r.segments[0];
        assert!((5..=6).contains(&s.len()), "{}", s.len());
        let (a, b) = celsius_range(s);
        assert!(a >= lo && b <= hi && a < b, "{}: {a}–{b}", r.unit_id);
    }
    // At the default 0.5 s the 1-s steps are gaps, named with the log, topic, message and field,
    // and the option that sets the limit; no row, line or column of a CSV text nobody wrote.
    let (status, text) = gyrodrift(&[
        "import",
        "ulog",
        small.to_str().unwrap(),
        "-o",
        dir.path().join("gaps").to_str().unwrap(),
    ]);
    assert!(
        !status.status.success()
            && text.contains("sample_log_small.ulg: topic `sensor_gyro` instance 0, message 2, field `timestamp`: gap: 1.000 s since the previous message (at most 0.5 s); `--max-gap <s>` sets the longest step")
            && !text.contains("row")
            && !text.contains("line"),
        "{text}"
    );
    assert!(!dir.path().join("gaps").exists());
    // The older log: `sensor_combined`, the barometer's temperature (27.27–27.96 °C per pyulog
    // 1.3.0: `ULog(path).get_dataset("sensor_combined").data["baro_temp_celcius"]`; the grid's raw
    // readings are within 0.005 °C of it).
    let out = dir.path().join("appended");
    ok(&[
        "import",
        "ulog",
        appended.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let r = read_recording(&out.join("recordings/px4-combined0.mcap")).unwrap();
    let s = &r.segments[0];
    assert_eq!(s.len(), 962, "9.6 s at 100 Hz");
    let (a, b) = celsius_range(s);
    assert!(
        (a - 27.27).abs() <= 0.005 && (b - 27.96).abs() <= 0.005,
        "{a}–{b}"
    );
}

/// A ULog file with one `sensor_gyro` instance: timestamp (µs since boot), x, y, z (rad/s),
/// temperature (°C), one message per sample.
fn write_ulog(path: &Path, s: &Segment) {
    let mut b = b"ULog\x01\x12\x35\x01".to_vec();
    b.extend(0u64.to_le_bytes());
    let message = |b: &mut Vec<u8>, kind: u8, body: &[u8]| {
        b.extend((body.len() as u16).to_le_bytes());
        b.push(kind);
        b.extend(body);
    };
    message(
        &mut b,
        b'F',
        b"sensor_gyro:uint64_t timestamp;float x;float y;float z;float temperature;uint8_t[4] _padding0;",
    );
    message(&mut b, b'A', b"\x00\x01\x00sensor_gyro");
    let fs = u64::from(s.sample_rate_hz);
    for i in 0..s.len() {
        let mut data = vec![1u8, 0];
        data.extend((5_000_000 + i as u64 * 1_000_000 / fs).to_le_bytes());
        for axis in 0..3 {
            data.extend((s.rate_dps[axis][i].to_radians()).to_le_bytes());
        }
        data.extend(((f64::from(s.temperature_raw[0][i]) / 200.0) as f32).to_le_bytes());
        message(&mut b, b'D', &data);
    }
    std::fs::write(path, b).unwrap();
}

#[test]
fn a_simulated_series_written_as_ulog_imports_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("c.toml"),
        "seed = 5\nunits = 1\nsample_rate_hz = 100\nset_points_celsius = [30]\n[protocol]\nintervals_min = [1]\nrepeats = 1\nactivation_s = 20\n",
    )
    .unwrap();
    let sim = d.join("sim");
    ok(&[
        "simulate",
        "-q",
        "--campaign",
        d.join("c.toml").to_str().unwrap(),
        "-o",
        sim.to_str().unwrap(),
    ]);
    let original = read_campaign_dir(&sim).unwrap().remove(0);
    let logs = d.join("logs");
    std::fs::create_dir(&logs).unwrap();
    for (k, s) in original.segments.iter().enumerate() {
        write_ulog(&logs.join(format!("log_{k:02}.ulg")), s);
    }
    let out = d.join("imported");
    let text = ok(&[
        "import",
        "ulog",
        logs.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set-point",
        "30",
        "--series-kind",
        "protocol",
        "--unit-id",
        "bench",
    ]);
    assert!(text.contains("bench-gyro0.mcap: 5 activations"), "{text}");
    let back = read_recording(&out.join("recordings/bench-gyro0.mcap")).unwrap();
    assert_eq!(back.metadata["set_point_celsius"], "30");
    assert_eq!(back.segments.len(), original.segments.len());
    for (k, (a, b)) in original.segments.iter().zip(&back.segments).enumerate() {
        assert_eq!(b.labels.activation as usize, k + 1);
        assert_eq!(
            b.labels.off_before_s, None,
            "ULog does not know the off-time"
        );
        assert_eq!(a.len(), b.len());
        // Temperatures exactly (°C as f32 of raw / 200, back to raw); rates to f32 rounding of
        // the rad/s conversion.
        assert_eq!(a.temperature_raw[0], b.temperature_raw[0]);
        for axis in 0..3 {
            for (x, y) in a.rate_dps[axis].iter().zip(&b.rate_dps[axis]) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-3), "{x} vs {y}");
            }
        }
    }
}
