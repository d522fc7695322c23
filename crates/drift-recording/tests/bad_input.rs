//! The bad-input corpus for the MCAP reader, beside `drift-sim/tests/reader_validation.rs` (gap,
//! duplicate and backwards time, NaN rate, missing supply topic, no switch-off, ground truth):
//! truncated and bit-flipped files, every missing topic and metadata key, ∞ and NaN in each
//! channel, overlapping and dropped samples, mismatched axis counts, oversized records, and the
//! missing-temperature marker. Each error names the file and, for a message, the topic and index.

use std::collections::BTreeMap;
use std::path::Path;

use drift_recording::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use drift_recording::writer::McapFile;
use drift_recording::{
    read_recording, read_recording_bytes, temperature_reading, ReadError, Recording,
    REQUIRED_TOPICS, TEMPERATURE_MISSING_RAW,
};

const BATCHES: u32 = 3;
const N: usize = 100;

/// One message about to be written; a hook may change or drop it.
struct Msg {
    topic: &'static str,
    batch: u32,
    log_ns: u64,
    first: u32,
    rate_hz: u32,
    f: [Vec<f32>; 3],
    raw: [Vec<i16>; 3],
    skip: bool,
}

fn metadata() -> BTreeMap<String, String> {
    BTreeMap::from([
        ("unit_id".into(), "BENCH-2".into()),
        ("sample_rate_hz".into(), "1000".into()),
    ])
}

fn power(on: bool) -> PowerEvent {
    PowerEvent {
        powered: on,
        series_kind: "protocol".into(),
        series: 1,
        repeat: 1,
        activation: 1,
        interval_min: 5.0,
        off_before_s: f64::NAN,
        set_point_celsius: 30.0,
    }
}

/// Writes one activation of 3 × 100 samples; `topics` are registered, `meta` is the metadata
/// record (none if `None`), `hook` edits each sample message.
fn write_with(
    path: &Path,
    topics: &[&'static str],
    meta: Option<BTreeMap<String, String>>,
    hook: &dyn Fn(&mut Msg),
) {
    let mut f = McapFile::create(path, schema::PROFILE_RECORDING, mcap::Compression::Zstd).unwrap();
    for &topic in topics {
        let s = match topic {
            schema::TOPIC_RATE | schema::TOPIC_ACCEL => schema::SCHEMA_VECTOR3,
            schema::TOPIC_TEMPERATURE_RAW => schema::SCHEMA_RAW_TEMPERATURE,
            schema::TOPIC_POWER => schema::SCHEMA_POWER,
            _ => schema::SCHEMA_SCALAR,
        };
        f.add_topic(topic, s, &[]).unwrap();
    }
    if let Some(meta) = meta {
        f.metadata(schema::METADATA_RECORDING, meta).unwrap();
    }
    f.power(&power(true), 1_000).unwrap();
    for batch in 0..BATCHES {
        for topic in &REQUIRED_TOPICS[..5] {
            if !topics.contains(topic) {
                continue;
            }
            let aux = *topic != schema::TOPIC_RATE && *topic != schema::TOPIC_TEMPERATURE_RAW;
            let (n, rate_hz) = if aux { (N / 10, 100) } else { (N, 1000) };
            let first = batch * n as u32;
            let ramp: Vec<f32> = (0..n).map(|i| 0.001 * i as f32).collect();
            let mut m = Msg {
                topic,
                batch,
                log_ns: 1_000 + u64::from(batch) * 100_000_000,
                first,
                rate_hz,
                f: [ramp.clone(), ramp.clone(), ramp],
                raw: std::array::from_fn(|a| (0..n).map(|i| 6000 + (i + a) as i16).collect()),
                skip: false,
            };
            hook(&mut m);
            if m.skip {
                continue;
            }
            let f3 = [&m.f[0][..], &m.f[1][..], &m.f[2][..]];
            match *topic {
                schema::TOPIC_RATE | schema::TOPIC_ACCEL => {
                    Vector3Batch::encode(m.first, m.rate_hz, f3, &mut f.enc);
                }
                schema::TOPIC_TEMPERATURE_RAW => {
                    let r = [&m.raw[0][..], &m.raw[1][..], &m.raw[2][..]];
                    RawTemperatureBatch::encode(m.first, m.rate_hz, r, &mut f.enc);
                }
                _ => {
                    ScalarBatch::encode(m.first, m.rate_hz, &m.f[0], &mut f.enc);
                }
            }
            f.write_encoded(topic, m.log_ns).unwrap();
        }
    }
    f.power(&power(false), 1_000 + u64::from(BATCHES) * 100_000_000)
        .unwrap();
    f.finish().unwrap();
}

fn read(hook: &dyn Fn(&mut Msg)) -> Result<Recording, ReadError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bench.mcap");
    write_with(&path, &REQUIRED_TOPICS, Some(metadata()), hook);
    read_recording(&path)
}

/// The message error of a hook: (topic, index, reason), checked to name the file.
fn message_error(hook: &dyn Fn(&mut Msg)) -> (String, usize, String) {
    match read(hook) {
        Err(ReadError::Message {
            path,
            topic,
            index,
            reason,
        }) => {
            assert!(path.ends_with("bench.mcap"));
            (topic, index, reason)
        }
        other => panic!("expected a message error, got {other:?}"),
    }
}

fn good_bytes() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("good.mcap");
    write_with(&path, &REQUIRED_TOPICS, Some(metadata()), &|_| {});
    std::fs::read(path).unwrap()
}

#[test]
fn the_clean_file_reads() {
    let rec = read(&|_| {}).unwrap();
    assert_eq!(rec.segments[0].len(), 300);
}

#[test]
fn every_missing_topic_is_named() {
    for missing in REQUIRED_TOPICS {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bench.mcap");
        let topics: Vec<&'static str> = REQUIRED_TOPICS
            .iter()
            .copied()
            .filter(|t| *t != missing)
            .collect();
        if missing == schema::TOPIC_POWER {
            // Power events are written by `power()`, which needs the topic: register it under
            // another name's absence instead, by writing no power topic at all.
            let mut f = McapFile::create(&path, schema::PROFILE_RECORDING, mcap::Compression::Zstd)
                .unwrap();
            f.add_topic(schema::TOPIC_RATE, schema::SCHEMA_VECTOR3, &[])
                .unwrap();
            f.metadata(schema::METADATA_RECORDING, metadata()).unwrap();
            f.finish().unwrap();
        } else {
            write_with(&path, &topics, Some(metadata()), &|_| {});
        }
        match read_recording(&path) {
            Err(e @ ReadError::MissingTopic { .. }) => {
                let text = e.to_string();
                assert!(
                    text.contains("bench.mcap") && text.contains("missing topic"),
                    "{text}"
                );
                if missing != schema::TOPIC_POWER {
                    assert!(text.ends_with(missing), "{text}");
                }
            }
            other => panic!("{missing}: expected a missing topic, got {other:?}"),
        }
    }
}

#[test]
fn missing_or_malformed_metadata_is_named() {
    let cases: [(Option<BTreeMap<String, String>>, &str); 4] = [
        (None, "record missing"),
        (
            Some(BTreeMap::from([("sample_rate_hz".into(), "1000".into())])),
            "key `unit_id` missing",
        ),
        (
            Some(BTreeMap::from([
                ("unit_id".into(), "U".into()),
                ("sample_rate_hz".into(), "fast".into()),
            ])),
            "sample_rate_hz: invalid digit",
        ),
        (
            Some(BTreeMap::from([
                ("unit_id".into(), "U".into()),
                ("sample_rate_hz".into(), "7".into()),
            ])),
            "must divide 10⁹, got 7",
        ),
    ];
    for (meta, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bench.mcap");
        write_with(&path, &REQUIRED_TOPICS, meta, &|_| {});
        let text = read_recording(&path).unwrap_err().to_string();
        assert!(
            text.contains("bench.mcap: metadata `gyrodrift.recording`") && text.contains(expected),
            "{text}"
        );
    }
}

#[test]
fn non_finite_values_in_each_float_channel_are_named_with_their_sample() {
    let cases = [
        (schema::TOPIC_RATE, 2, f32::INFINITY, 250),
        (schema::TOPIC_RATE, 1, f32::NEG_INFINITY, 150),
        (schema::TOPIC_ACCEL, 1, f32::NAN, 15),
        (schema::TOPIC_SUPPLY, 2, f32::INFINITY, 25),
        (schema::TOPIC_SET_POINT, 0, f32::NAN, 5),
    ];
    for (topic, batch, value, sample) in cases {
        let (t, index, reason) = message_error(&move |m: &mut Msg| {
            if m.topic == topic && m.batch == batch {
                let at = m.f[0].len() / 2;
                m.f[0][at] = value;
            }
        });
        assert_eq!((t.as_str(), index), (topic, batch as usize));
        assert!(
            reason.contains("non-finite value")
                && reason.contains(&format!("at sample {sample} of the segment")),
            "{topic}: {reason}"
        );
    }
}

#[test]
fn overlapping_dropped_and_mismatched_samples_are_named() {
    // A batch repeated (overlap): its first sample goes back.
    let (topic, index, reason) = message_error(&|m: &mut Msg| {
        if m.topic == schema::TOPIC_TEMPERATURE_RAW && m.batch == 2 {
            m.first = 100;
        }
    });
    assert_eq!((topic.as_str(), index), ("/gyro/temperature_raw", 2));
    assert!(
        reason.contains("overlap or duplicate: first_sample 100, expected 200"),
        "{reason}"
    );

    // Dropped samples at the end of one topic: the counts disagree at switch-off.
    let (topic, index, reason) = message_error(&|m: &mut Msg| {
        if m.topic == schema::TOPIC_TEMPERATURE_RAW && m.batch == 2 {
            for axis in &mut m.raw {
                axis.truncate(60);
            }
        }
    });
    assert_eq!((topic.as_str(), index), ("/power/state", 1));
    assert!(
        reason.contains("300 rate samples but 260 temperature samples"),
        "{reason}"
    );

    // A whole batch dropped from one topic: the next batch is a gap.
    let (topic, index, reason) = message_error(&|m: &mut Msg| {
        m.skip = m.topic == schema::TOPIC_ACCEL && m.batch == 1;
    });
    assert_eq!((topic.as_str(), index), ("/aux/accel", 1));
    assert!(
        reason.contains("gap: first_sample 20, expected 10"),
        "{reason}"
    );

    // Mismatched axis counts inside one message.
    let (topic, index, reason) = message_error(&|m: &mut Msg| {
        if m.topic == schema::TOPIC_RATE && m.batch == 1 {
            m.f[2].pop();
        }
    });
    assert_eq!((topic.as_str(), index), ("/gyro/rate", 1));
    assert!(
        reason.contains("axis lengths differ: x 100, y 100, z 99"),
        "{reason}"
    );

    // A sample rate other than the declared one.
    let (topic, index, reason) = message_error(&|m: &mut Msg| {
        if m.topic == schema::TOPIC_RATE && m.batch == 0 {
            m.rate_hz = 500;
        }
    });
    assert_eq!((topic.as_str(), index), ("/gyro/rate", 0));
    assert!(
        reason.contains("sample_rate_hz 500, expected 1000"),
        "{reason}"
    );
}

#[test]
fn a_missing_temperature_reading_is_read_as_the_marker() {
    // The decision (docs/recording-format.md): a temperature dropout is recorded as −32768, read
    // as such, and fed to the corrector as NaN (it holds and flags); rates have no such marker.
    let rec = read(&|m: &mut Msg| {
        if m.topic == schema::TOPIC_TEMPERATURE_RAW && m.batch == 1 {
            m.raw[1][7] = TEMPERATURE_MISSING_RAW;
        }
    })
    .unwrap();
    let s = &rec.segments[0];
    assert_eq!(s.first_missing_temperature(), Some((1, 107)));
    assert!(temperature_reading(s.temperature_raw[1][107]).is_nan());
    assert!(s.temperature_celsius(1, 107).unwrap().is_nan());
    assert_eq!(temperature_reading(s.temperature_raw[1][106]), 6007.0);
}

#[test]
fn every_truncation_is_an_error_naming_the_file() {
    let good = good_bytes();
    let name = Path::new("cut.mcap");
    for len in (0..good.len()).step_by(7) {
        match read_recording_bytes(name, &good[..len]) {
            Ok(_) => panic!("truncated to {len} of {} bytes, accepted", good.len()),
            Err(e) => assert!(e.to_string().starts_with("cut.mcap: "), "{e}"),
        }
    }
}

#[test]
fn every_bit_flip_is_an_error_or_changes_nothing_read() {
    // CRCs cover the chunks (data) and the data section; the reader checks both. A flip that is
    // not caught can only sit where the reader does not look (indexes, statistics, padding): the
    // recording it reads is then the original one, never a wrong one.
    let good = good_bytes();
    let original = read_recording_bytes(Path::new("flip.mcap"), &good).unwrap();
    let mut bytes = good.clone();
    let (mut refused, mut harmless) = (0, 0);
    for byte in 0..good.len() {
        for bit in [0, 3, 7] {
            bytes[byte] ^= 1 << bit;
            match read_recording_bytes(Path::new("flip.mcap"), &bytes) {
                Err(e) => {
                    assert!(e.to_string().starts_with("flip.mcap: "), "{e}");
                    refused += 1;
                }
                Ok(rec) => {
                    assert_eq!(
                        rec.segments, original.segments,
                        "byte {byte} bit {bit}: a wrong recording was read"
                    );
                    harmless += 1;
                }
            }
            bytes[byte] ^= 1 << bit;
        }
    }
    println!(
        "{} bytes × 3 bits: {refused} refused, {harmless} read unchanged",
        good.len()
    );
    assert!(
        refused > harmless,
        "{refused} refused, {harmless} unchanged"
    );
}

#[test]
fn oversized_record_lengths_are_refused_without_allocating_them() {
    // Found by fuzzing (F2): a message record inside an uncompressed chunk whose declared length is
    // 0x7373…; mcap's MessageStream reserved it and aborted. With chunk CRCs off (0 = not
    // computed), nothing catches the length before the reader's limit.
    let mut cursor = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::WriteOptions::new()
            .profile(schema::PROFILE_RECORDING)
            .compression(None)
            .calculate_chunk_crcs(false)
            .calculate_data_section_crc(false)
            .create(&mut cursor)
            .unwrap();
        let schema_id = w.add_schema("s", "ros2msg", b"").unwrap();
        let mut ids = Vec::new();
        for topic in REQUIRED_TOPICS {
            ids.push(
                w.add_channel(schema_id, topic, "cdr", &BTreeMap::new())
                    .unwrap(),
            );
        }
        w.write_metadata(&mcap::records::Metadata {
            name: schema::METADATA_RECORDING.into(),
            metadata: metadata(),
        })
        .unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: ids[0],
            sequence: 1,
            log_time: 5,
            publish_time: 5,
        };
        w.write_to_known_channel(&header, b"MARKER-MESSAGE")
            .unwrap();
        w.finish().unwrap();
    }
    let mut bytes = cursor.into_inner();
    // The message record: opcode 0x05, u64 length, then the header; point the length far away.
    let at = bytes
        .windows(14)
        .position(|w| w == b"MARKER-MESSAGE")
        .unwrap();
    let record = at - (2 + 4 + 8 + 8) - 8 - 1;
    assert_eq!(bytes[record], 0x05);
    bytes[record + 1..record + 9].copy_from_slice(&0x7373_7373_7373_7373u64.to_le_bytes());
    let text = read_recording_bytes(Path::new("huge.mcap"), &bytes)
        .unwrap_err()
        .to_string();
    assert!(text.starts_with("huge.mcap: MCAP: "), "{text}");
}

#[test]
fn a_metadata_index_pointing_past_the_file_is_named() {
    // Found by fuzzing (F9): mcap adds the index's offset and length unchecked and slices.
    let mut bytes = good_bytes();
    // The metadata index record (opcode 0x0D): length u64, then offset u64, length u64, name.
    let name = schema::METADATA_RECORDING.as_bytes();
    let at = bytes
        .windows(name.len())
        .enumerate()
        .filter(|(_, w)| *w == name)
        .map(|(i, _)| i)
        .find(|&i| bytes[i - 4 - 8 - 8 - 8 - 1] == 0x0D)
        .unwrap();
    let offset = at - 4 - 8 - 8;
    bytes[offset..offset + 8].copy_from_slice(&(u64::MAX - 16).to_le_bytes());
    let text = read_recording_bytes(Path::new("index.mcap"), &bytes)
        .unwrap_err()
        .to_string();
    assert!(
        text.starts_with("index.mcap: metadata `gyrodrift.recording`")
            && text.contains("metadata index points outside the file"),
        "{text}"
    );
}
