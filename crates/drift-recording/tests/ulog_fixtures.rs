//! The ULog reader on two real PX4 logs (`../shared/data/formats/px4-ulog/`, pyulog's test logs;
//! skipped when absent): instance counts, message counts, first and last timestamps and
//! temperature ranges equal to pyulog 1.3.0's reading of the same files, produced by
//!
//! ```python
//! from pyulog import ULog
//! u = ULog(path)
//! for d in sorted(u.data_list, key=lambda d: (d.name, d.multi_id)):
//!     if d.name in ("sensor_gyro", "sensor_combined"):
//!         ts = d.data["timestamp"]
//!         print(d.name, d.multi_id, len(ts), ts[0], ts[-1],
//!               d.data["temperature"].min() if "temperature" in d.data else "",
//!               d.data["temperature"].max() if "temperature" in d.data else "")
//! print(u.start_timestamp, len(u.data_list))  # topics with data
//! ```
//!
//! and bad input named by file and byte offset.

use std::path::{Path, PathBuf};

use drift_recording::ulog::{read_ulog, read_ulog_bytes, Ulog};

fn fixture(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/formats/px4-ulog")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        println!("skipped: {} is absent", path.display());
        None
    }
}

/// (instance, messages, first timestamp µs, last timestamp µs).
fn counts(log: &Ulog, topic: &str) -> Vec<(u8, usize, f64, f64)> {
    log.topic(topic)
        .iter()
        .map(|t| {
            let ts = t.values("timestamp").unwrap();
            (t.instance, t.len(), ts[0], *ts.last().unwrap())
        })
        .collect()
}

fn range(values: &[f64]) -> (f32, f32) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo as f32, hi as f32)
}

#[test]
fn sample_log_small_reads_as_pyulog_reads_it() {
    let Some(path) = fixture("sample_log_small.ulg") else {
        return;
    };
    let log = read_ulog(&path).unwrap();
    assert_eq!(log.start_us, 20_309_082);
    assert_eq!(log.topics.iter().filter(|t| !t.is_empty()).count(), 70);
    assert_eq!(
        counts(&log, "sensor_gyro"),
        [
            (0, 6, 21_312_030.0, 26_312_455.0),
            (1, 6, 21_311_176.0, 26_311_140.0),
            (2, 6, 21_311_601.0, 26_311_676.0)
        ]
    );
    let temperatures: Vec<(f32, f32)> = log
        .topic("sensor_gyro")
        .iter()
        .map(|t| range(&t.values("temperature").unwrap()))
        .collect();
    assert_eq!(
        temperatures,
        [
            (40.025_37, 40.360_83),
            (28.246_023, 28.368_422),
            (29.434_422, 29.721_958)
        ]
    );
    let gyro = log.topic("sensor_gyro");
    assert_eq!(gyro[0].values("x").unwrap()[0] as f32, -0.041_303_21);
    assert_eq!(
        counts(&log, "sensor_combined"),
        [(0, 1298, 20_326_716.0, 26_822_868.0)]
    );
    let combined = log.topic("sensor_combined");
    assert_eq!(
        combined[0].values("gyro_rad[0]").unwrap()[0] as f32,
        0.002_968_383_5
    );
    assert!(combined[0].values("temperature").is_none());
}

#[test]
fn an_older_log_with_appended_data_reads_as_pyulog_reads_it() {
    let Some(path) = fixture("sample_appended_multiple.ulg") else {
        return;
    };
    let log = read_ulog(&path).unwrap();
    assert_eq!(log.start_us, 12_100_461);
    // Every topic with data, as pyulog lists them (`sorted((d.name, d.multi_id,
    // len(d.data["timestamp"])) for d in u.data_list)`).
    let mut listed: Vec<(&str, u8, usize)> = log
        .topics
        .iter()
        .filter(|t| !t.is_empty())
        .map(|t| (t.name.as_str(), t.instance, t.len()))
        .collect();
    listed.sort();
    assert_eq!(
        listed,
        [
            ("actuator_controls_0", 0, 95),
            ("actuator_outputs", 0, 95),
            ("actuator_outputs", 1, 96),
            ("commander_state", 0, 95),
            ("control_state", 0, 95),
            ("cpuload", 0, 10),
            ("ekf2_innovations", 0, 184),
            ("ekf2_timestamps", 0, 2373),
            ("estimator_status", 0, 48),
            ("sensor_combined", 0, 2373),
            ("sensor_preflight", 0, 184),
            ("system_power", 0, 32),
            ("task_stack_info", 0, 20),
            ("vehicle_attitude", 0, 306),
            ("vehicle_attitude_setpoint", 0, 306),
            ("vehicle_land_detected", 0, 1),
            ("vehicle_local_position", 0, 95),
            ("vehicle_rates_setpoint", 0, 306),
            ("vehicle_status", 0, 43),
            ("wind_estimate", 0, 95),
        ]
    );
    assert!(log.topic("sensor_gyro").is_empty());
    assert_eq!(
        counts(&log, "sensor_combined"),
        [(0, 2373, 12_262_822.0, 21_880_422.0)]
    );
    assert_eq!(
        log.topic("sensor_combined")[0]
            .values("gyro_rad[0]")
            .unwrap()[0] as f32,
        0.003_286_037
    );
}

#[test]
fn bad_input_is_named_by_file_and_byte_offset() {
    let name = Path::new("bad.ulg");
    let e = read_ulog_bytes(name, b"not a ulog file at all").unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad.ulg: byte 0: not a ULog file (magic `ULog` 01 12 35 missing)"
    );
    // A data message for a subscription nobody made.
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    bytes.extend([4u8, 0, b'D', 7, 0, 1, 2]);
    let e = read_ulog_bytes(name, &bytes).unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad.ulg: byte 16: data for msg_id 7, which no subscription defines: the file is corrupt"
    );
    // A subscription to a format never defined.
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    let body = b"\x00\x03\x00sensor_gyro";
    bytes.extend([body.len() as u8, 0, b'A']);
    bytes.extend(body);
    let e = read_ulog_bytes(name, &bytes).unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad.ulg: byte 16: no format definition `sensor_gyro`: the file is corrupt"
    );
    // A header that starts as ULog's but is damaged, or cut short, is a corrupt ULog file.
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    bytes[1] = b'X';
    let e = read_ulog_bytes(name, &bytes).unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad.ulg: byte 0: the ULog header is corrupt: its magic reads 55 58 6f 67 01 12 35, not `ULog` 01 12 35: the file is corrupt"
    );
    let e = read_ulog_bytes(name, b"ULog\x01\x12").unwrap_err();
    assert_eq!(
        e.to_string(),
        "bad.ulg: byte 0: the file ends inside the 16-byte ULog header (6 bytes): the file is corrupt (truncated)"
    );
    // Unknown incompatible flags: a newer version, or damage.
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    let mut flags = vec![0u8; 40];
    flags[8] = 0xff;
    bytes.extend([40u8, 0, b'B']);
    bytes.extend(&flags);
    let e = read_ulog_bytes(name, &bytes).unwrap_err();
    assert!(
        e.to_string().ends_with("incompatible flags 0xff (this reader knows bit 0, appended data): the file is corrupt, or from a newer ULog version"),
        "{e}"
    );
}

#[test]
fn nested_formats_arrays_and_padding_are_flattened() {
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    let mut message = |kind: u8, body: &[u8]| {
        bytes.extend((body.len() as u16).to_le_bytes());
        bytes.push(kind);
        bytes.extend(body);
    };
    message(b'F', b"inner:int16_t a;uint8_t[2] _padding0;float b;");
    message(b'F', b"outer:uint64_t timestamp;inner[2] in;double t;");
    message(b'A', b"\x01\x05\x00outer");
    let mut data = vec![5u8, 0];
    data.extend(1_000u64.to_le_bytes());
    for (a, b) in [(-3i16, 1.5f32), (4, 2.5)] {
        data.extend(a.to_le_bytes());
        data.extend([0, 0]);
        data.extend(b.to_le_bytes());
    }
    data.extend(36.6f64.to_le_bytes());
    message(b'D', &data);
    let log = read_ulog_bytes(Path::new("nested.ulg"), &bytes).unwrap();
    let t = &log.topic("outer")[0];
    assert_eq!(t.instance, 1);
    assert_eq!(
        t.field_names().collect::<Vec<_>>(),
        ["timestamp", "in[0].a", "in[0].b", "in[1].a", "in[1].b", "t"]
    );
    assert_eq!(t.values("in[0].a").unwrap(), [-3.0]);
    assert_eq!(t.values("in[1].b").unwrap(), [2.5]);
    assert_eq!(t.values("t").unwrap(), [36.6]);
}
