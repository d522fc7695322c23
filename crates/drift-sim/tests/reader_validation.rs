//! The reader refuses ground truth and reports broken recordings by file, topic and
//! message index.

mod common;

use drift_recording::create_recording;
use drift_recording::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use drift_sim::{read_campaign_dir, read_recording, simulate_campaign, Campaign, ReadError};
use std::collections::BTreeMap;
use std::path::Path;

fn metadata() -> BTreeMap<String, String> {
    BTreeMap::from([
        ("unit_id".into(), "BENCH-1".into()),
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
        off_before_s: 3600.0,
        set_point_celsius: 30.0,
    }
}

/// What to break in a hand-written two-batch recording.
#[derive(Clone, Copy, PartialEq)]
enum Fault {
    None,
    Gap,
    DuplicateTime,
    BackwardsTime,
    Nan,
    NoSupplyTopic,
    NoSwitchOff,
}

/// Writes one activation of 200 samples in two 100-sample batches, with one fault.
fn write(path: &Path, fault: Fault) {
    let mut f = if fault == Fault::NoSupplyTopic {
        // Register everything except the supply topic by hand.
        let mut f = drift_recording::writer::McapFile::create(
            path,
            schema::PROFILE_RECORDING,
            mcap::Compression::Zstd,
        )
        .unwrap();
        f.add_topic(schema::TOPIC_RATE, schema::SCHEMA_VECTOR3, &[])
            .unwrap();
        f.add_topic(
            schema::TOPIC_TEMPERATURE_RAW,
            schema::SCHEMA_RAW_TEMPERATURE,
            &[],
        )
        .unwrap();
        f.add_topic(schema::TOPIC_ACCEL, schema::SCHEMA_VECTOR3, &[])
            .unwrap();
        f.add_topic(schema::TOPIC_SET_POINT, schema::SCHEMA_SCALAR, &[])
            .unwrap();
        f.add_topic(schema::TOPIC_POWER, schema::SCHEMA_POWER, &[])
            .unwrap();
        f.metadata(schema::METADATA_RECORDING, metadata()).unwrap();
        f
    } else {
        create_recording(path, metadata()).unwrap()
    };
    f.power(&power(true), 1_000).unwrap();
    for batch in 0..2u32 {
        let first = if fault == Fault::Gap && batch == 1 {
            150
        } else {
            batch * 100
        };
        let mut rate = vec![0.01f32; 100];
        if fault == Fault::Nan && batch == 1 {
            rate[37] = f32::NAN;
        }
        let time = match (fault, batch) {
            (Fault::DuplicateTime, 1) => 1_000,
            (Fault::BackwardsTime, 1) => 500,
            _ => 1_000 + u64::from(first) * 1_000_000,
        };
        Vector3Batch::encode(first, 1000, [&rate, &rate, &rate], &mut f.enc);
        f.write_encoded(schema::TOPIC_RATE, time).unwrap();
        let raw = vec![6000i16; 100];
        RawTemperatureBatch::encode(first, 1000, [&raw, &raw, &raw], &mut f.enc);
        f.write_encoded(schema::TOPIC_TEMPERATURE_RAW, time)
            .unwrap();
        let aux = vec![1.0f32; 10];
        let aux_first = first / 10;
        Vector3Batch::encode(aux_first, 100, [&aux, &aux, &aux], &mut f.enc);
        f.write_encoded(schema::TOPIC_ACCEL, time).unwrap();
        if fault != Fault::NoSupplyTopic {
            ScalarBatch::encode(aux_first, 100, &aux, &mut f.enc);
            f.write_encoded(schema::TOPIC_SUPPLY, time).unwrap();
        }
        ScalarBatch::encode(aux_first, 100, &aux, &mut f.enc);
        f.write_encoded(schema::TOPIC_SET_POINT, time).unwrap();
    }
    if fault != Fault::NoSwitchOff {
        f.power(&power(false), 1_000 + 200 * 1_000_000).unwrap();
    }
    f.finish().unwrap();
}

fn read_with(fault: Fault) -> Result<drift_sim::Recording, ReadError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bench.mcap");
    write(&path, fault);
    read_recording(&path)
}

fn message_error(fault: Fault) -> (String, usize, String) {
    match read_with(fault) {
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

#[test]
fn a_valid_hand_written_recording_reads() {
    let rec = read_with(Fault::None).unwrap();
    assert_eq!(rec.segments.len(), 1);
    assert_eq!(rec.segments[0].len(), 200);
    assert_eq!(rec.segments[0].aux["supply_voltage"].values.len(), 20);
}

#[test]
fn errors_name_file_topic_and_message_index() {
    let (topic, index, reason) = message_error(Fault::Gap);
    assert_eq!((topic.as_str(), index), ("/gyro/rate", 1));
    assert!(
        reason.contains("gap") && reason.contains("150") && reason.contains("100"),
        "{reason}"
    );

    let (topic, index, reason) = message_error(Fault::DuplicateTime);
    assert_eq!((topic.as_str(), index), ("/gyro/rate", 1));
    assert!(reason.contains("duplicate"), "{reason}");

    let (topic, index, reason) = message_error(Fault::BackwardsTime);
    assert_eq!((topic.as_str(), index), ("/gyro/rate", 1));
    assert!(reason.contains("goes back"), "{reason}");

    let (topic, index, reason) = message_error(Fault::Nan);
    assert_eq!((topic.as_str(), index), ("/gyro/rate", 1));
    assert!(reason.contains("NaN") && reason.contains("137"), "{reason}");

    let (topic, _, reason) = message_error(Fault::NoSwitchOff);
    assert_eq!(topic, "/power/state");
    assert!(reason.contains("no switch-off"), "{reason}");

    match read_with(Fault::NoSupplyTopic) {
        Err(ReadError::MissingTopic { topic, .. }) => assert_eq!(topic, "/aux/supply_voltage"),
        other => panic!("expected a missing topic, got {other:?}"),
    }
    let text = read_with(Fault::Gap).unwrap_err().to_string();
    assert!(
        text.contains("bench.mcap") && text.contains("/gyro/rate") && text.contains("#1"),
        "{text}"
    );
}

#[test]
fn ground_truth_is_refused_by_name_by_profile_and_by_topic() {
    let mut c = common::protocol_campaign(&[1.0], 1, 1.0);
    c.protocol.as_mut().unwrap().activation_s = 1.0;
    let dir = tempfile::tempdir().unwrap();
    let summary = simulate_campaign(&c, dir.path(), |_| {}).unwrap();
    let truth = &summary.files[0].truth;
    // 1. By name / folder, before the file is opened (a missing file proves it is not read).
    assert!(matches!(
        read_recording(truth),
        Err(ReadError::GroundTruth { .. })
    ));
    let ghost = dir.path().join("truth").join("never-written.truth.mcap");
    assert!(matches!(
        read_recording(&ghost),
        Err(ReadError::GroundTruth { .. })
    ));
    // 2. By MCAP profile, when renamed to look like a recording elsewhere.
    let disguised = dir.path().join("disguised.mcap");
    std::fs::copy(truth, &disguised).unwrap();
    match read_recording(&disguised) {
        Err(ReadError::GroundTruth { why, .. }) => assert!(why.contains("profile"), "{why}"),
        other => panic!("expected ground-truth refusal, got {other:?}"),
    }
    // 3. By topic, even under the recording profile.
    let sneaky = dir.path().join("sneaky.mcap");
    let mut f = create_recording(&sneaky, metadata()).unwrap();
    f.add_topic(schema::TOPIC_TRUTH_BIAS, schema::SCHEMA_VECTOR3, &[])
        .unwrap();
    f.finish().unwrap();
    match read_recording(&sneaky) {
        Err(ReadError::GroundTruth { why, .. }) => assert!(why.contains("/truth/"), "{why}"),
        other => panic!("expected ground-truth refusal, got {other:?}"),
    }
    // The campaign reader lists recordings/ only and never meets the truth.
    let all = read_campaign_dir(dir.path()).unwrap();
    assert_eq!(all.len(), 1);
    // Nothing in a recording's metadata names an effect or a parameter.
    let keys: Vec<&String> = all[0].metadata.keys().collect();
    assert!(
        keys.iter()
            .all(|k| !k.contains("effect") && !k.contains("seed")),
        "{keys:?}"
    );
}

#[test]
fn writers_leave_no_partial_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("unfinished.mcap");
    {
        let mut f = create_recording(&path, metadata()).unwrap();
        f.power(&power(true), 0).unwrap();
        // Dropped without finish(): as after an error upstream.
    }
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    assert!(!path.exists());
    // An invalid campaign fails before anything is written.
    let bad = Campaign {
        units: 0,
        ..Campaign::default()
    };
    let out = dir.path().join("bad");
    assert!(simulate_campaign(&bad, &out, |_| {}).is_err());
    assert!(!out.exists());
}
