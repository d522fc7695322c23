//! Named auxiliary channels (`/aux/<name>`, a `ScalarBatch` each): arbitrary names round-trip
//! through MCAP with their units and only in the activations that have them; the writer refuses a
//! channel it cannot store, naming segment and channel, and leaves nothing behind; the reader turns
//! every `/aux/<name>` ScalarBatch into channel `<name>` and refuses any other schema there, naming
//! file, topic and message, and samples of any auxiliary channel past the switch-off.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use drift_recording::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use drift_recording::{
    create_recording, read_recording, write_recording, AuxChannel, ReadError, Recording, Segment,
    SegmentLabels, SeriesKind, WriteError, AUX_RATE_HZ,
};

const FS: u32 = 1000;

fn channel(unit: &str, values: Vec<f32>) -> AuxChannel {
    AuxChannel {
        unit: unit.into(),
        sample_rate_hz: AUX_RATE_HZ,
        values,
    }
}

/// An activation of `n` samples at 1 kHz with the format's own channels (full length) and `named`.
fn segment(
    activation: u32,
    power_on_ns: u64,
    n: usize,
    named: &[(&str, &str, Vec<f32>)],
) -> Segment {
    let m = n.div_ceil((FS / AUX_RATE_HZ) as usize);
    let ramp = |scale: f32| (0..m).map(|i| scale * i as f32).collect::<Vec<f32>>();
    let mut aux = BTreeMap::from([
        ("accel_x".to_owned(), channel("g", ramp(0.001))),
        ("accel_y".to_owned(), channel("g", ramp(-0.001))),
        ("accel_z".to_owned(), channel("g", vec![1.0; m])),
        ("supply_voltage".to_owned(), channel("V", vec![5.0; m])),
        (
            "chamber_set_point".to_owned(),
            channel("degC", vec![30.0; m]),
        ),
    ]);
    for (name, unit, values) in named {
        aux.insert((*name).to_owned(), channel(unit, values.clone()));
    }
    Segment {
        labels: SegmentLabels {
            unit_id: "BENCH-9".into(),
            set_point_celsius: 30.0,
            session_set_point_celsius: None,
            series_kind: SeriesKind::Protocol,
            series: 1,
            repeat: 1,
            activation,
            interval_min: Some(5.0),
            off_before_s: None,
        },
        sample_rate_hz: FS,
        power_on_ns,
        since_power_on: (0..n as u32).collect(),
        rate_dps: std::array::from_fn(|a| (0..n).map(|i| 1e-4 * (i + a) as f32).collect()),
        temperature_raw: std::array::from_fn(|a| {
            (0..n).map(|i| 6000 + (i / 7 + a) as i16).collect()
        }),
        temperature_scale: drift_recording::TemperatureScale::default(),
        aux,
    }
}

fn recording(segments: Vec<Segment>) -> Recording {
    Recording {
        path: PathBuf::new(),
        metadata: BTreeMap::from([
            ("unit_id".into(), "BENCH-9".into()),
            ("sample_rate_hz".into(), FS.to_string()),
        ]),
        unit_id: "BENCH-9".into(),
        sample_rate_hz: FS,
        segments,
    }
}

/// Values that are not a ramp, so a shifted or truncated copy would not compare equal.
fn wiggle(m: usize, seed: f32) -> Vec<f32> {
    (0..m)
        .map(|i| (seed + i as f32 * 0.37).sin() * 3.3)
        .collect()
}

fn names_in(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn arbitrary_names_round_trip_with_their_units_and_activations() {
    // 2345 samples: the last 100 ms batch is partial, and the aux grid has 235 samples.
    let first = segment(
        1,
        1_000,
        2345,
        &[
            ("humidity", "%RH", wiggle(235, 0.0)),
            ("v3.3", "V", wiggle(235, 1.0)),
            ("board-temp", "degC", wiggle(235, 2.0)),
            ("Accel2_X", "m/s^2", wiggle(235, 3.0)),
            // Shorter than the activation: continues with empty batches, read back as written.
            ("late", "", wiggle(40, 4.0)),
        ],
    );
    // Another activation with a different set: only `humidity` (in the same unit) and an empty one.
    let second = segment(
        2,
        10_000_000_000,
        1000,
        &[
            ("humidity", "%RH", wiggle(100, 5.0)),
            ("0", "A", Vec::new()),
        ],
    );
    let original = recording(vec![first, second]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("named.mcap");
    write_recording(&original, &path).unwrap();
    let back = read_recording(&path).unwrap();
    assert_eq!(back.segments, original.segments);
    let keys: Vec<&str> = back.segments[1].aux.keys().map(String::as_str).collect();
    assert_eq!(
        keys,
        [
            "0",
            "accel_x",
            "accel_y",
            "accel_z",
            "chamber_set_point",
            "humidity",
            "supply_voltage"
        ]
    );

    // In the file: one ScalarBatch topic per name, its unit in the channel metadata.
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::read::Summary::read(&bytes).unwrap().unwrap();
    let topics: BTreeMap<&str, (&str, Option<&String>)> = summary
        .channels
        .values()
        .map(|c| {
            let schema = c.schema.as_ref().map_or("", |s| s.name.as_str());
            (c.topic.as_str(), (schema, c.metadata.get("unit")))
        })
        .collect();
    let scalar = schema::SCHEMA_SCALAR.0;
    let unit = |u: &str| Some(u.to_owned());
    for (topic, expected_unit) in [
        ("/aux/humidity", "%RH"),
        ("/aux/v3.3", "V"),
        ("/aux/board-temp", "degC"),
        ("/aux/Accel2_X", "m/s^2"),
        ("/aux/late", ""),
        ("/aux/0", "A"),
    ] {
        assert_eq!(
            topics.get(topic).map(|(s, u)| (*s, (*u).cloned())),
            Some((scalar, unit(expected_unit))),
            "{topic}"
        );
    }
    assert_eq!(topics.len(), 6 + 6, "{topics:?}");
}

#[test]
fn a_recording_without_named_channels_writes_the_same_bytes_as_before() {
    // The fixed topics keep their names and the file its layout: same bytes as the format's own
    // topics written by hand (create_recording, as the simulator does), batch by batch.
    let rec = recording(vec![segment(1, 1_000, 250, &[])]);
    let dir = tempfile::tempdir().unwrap();
    let written = dir.path().join("w.mcap");
    write_recording(&rec, &written).unwrap();
    let by_hand = dir.path().join("h.mcap");
    let mut f = create_recording(&by_hand, rec.metadata.clone()).unwrap();
    let s = &rec.segments[0];
    let event = |powered| PowerEvent {
        powered,
        series_kind: "protocol".into(),
        series: 1,
        repeat: 1,
        activation: 1,
        interval_min: 5.0,
        off_before_s: f64::NAN,
        set_point_celsius: 30.0,
    };
    f.power(&event(true), 1_000).unwrap();
    for (b, (lo, hi)) in [(0usize, 100usize), (100, 200), (200, 250)]
        .into_iter()
        .enumerate()
    {
        let log_ns = 1_000 + b as u64 * 100_000_000;
        let r = &s.rate_dps;
        Vector3Batch::encode(
            lo as u32,
            FS,
            [&r[0][lo..hi], &r[1][lo..hi], &r[2][lo..hi]],
            &mut f.enc,
        );
        f.write_encoded(schema::TOPIC_RATE, log_ns).unwrap();
        let t = &s.temperature_raw;
        RawTemperatureBatch::encode(
            lo as u32,
            FS,
            [&t[0][lo..hi], &t[1][lo..hi], &t[2][lo..hi]],
            &mut f.enc,
        );
        f.write_encoded(schema::TOPIC_TEMPERATURE_RAW, log_ns)
            .unwrap();
        let (a0, a1) = (lo / 10, hi.div_ceil(10));
        let a = |name: &str| &s.aux[name].values[a0..a1];
        Vector3Batch::encode(
            a0 as u32,
            AUX_RATE_HZ,
            [a("accel_x"), a("accel_y"), a("accel_z")],
            &mut f.enc,
        );
        f.write_encoded(schema::TOPIC_ACCEL, log_ns).unwrap();
        ScalarBatch::encode(a0 as u32, AUX_RATE_HZ, a("supply_voltage"), &mut f.enc);
        f.write_encoded(schema::TOPIC_SUPPLY, log_ns).unwrap();
        ScalarBatch::encode(a0 as u32, AUX_RATE_HZ, a("chamber_set_point"), &mut f.enc);
        f.write_encoded(schema::TOPIC_SET_POINT, log_ns).unwrap();
    }
    f.power(&event(false), 1_000 + 250 * 1_000_000).unwrap();
    f.finish().unwrap();
    assert_eq!(
        std::fs::read(written).unwrap(),
        std::fs::read(by_hand).unwrap()
    );
}

/// The writer's error for `rec`, checked to be `Invalid`, to name the file, and to leave the folder
/// empty.
fn refused(rec: &Recording) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mcap");
    let error = write_recording(rec, &path).unwrap_err();
    assert!(matches!(error, WriteError::Invalid { .. }), "{error:?}");
    assert!(
        names_in(dir.path()).is_empty(),
        "{:?}",
        names_in(dir.path())
    );
    let text = error.to_string();
    assert!(text.contains("bad.mcap: "), "{text}");
    text
}

#[test]
fn bad_channel_names_are_refused_naming_segment_and_channel() {
    let cases = [
        ("", "an empty auxiliary channel name"),
        ("gps/fix", "auxiliary channel `gps/fix` has `/` at byte 3"),
        (
            "two words",
            "auxiliary channel `two words` has ` ` at byte 3",
        ),
        ("..", "auxiliary channel `..` starts with `.`"),
        ("-v", "auxiliary channel `-v` starts with `-`"),
        ("accel", "`accel` would be recorded on /aux/accel"),
    ];
    for (name, expected) in cases {
        let good = segment(1, 1_000, 300, &[]);
        let bad = segment(2, 10_000_000_000, 300, &[(name, "V", vec![1.0; 30])]);
        let text = refused(&recording(vec![good, bad]));
        assert!(
            text.contains("segment 1 (series 1, repeat 1, activation 2)")
                && text.contains(expected),
            "{name:?}: {text}"
        );
    }
}

#[test]
fn channels_the_format_cannot_store_are_refused_naming_segment_and_channel() {
    let with = |edit: &dyn Fn(&mut Segment)| {
        let mut s = segment(1, 1_000, 300, &[("humidity", "%RH", vec![40.0; 30])]);
        edit(&mut s);
        refused(&recording(vec![s]))
    };
    let text = with(&|s| s.aux.get_mut("humidity").unwrap().sample_rate_hz = 10);
    assert!(
        text.contains("segment 0 (series 1, repeat 1, activation 1), auxiliary channel `humidity`: sampled at 10 Hz, but the format records auxiliary channels at 100 Hz"),
        "{text}"
    );
    let text = with(&|s| s.aux.get_mut("humidity").unwrap().values.push(41.0));
    assert!(
        text.contains("auxiliary channel `humidity`: 31 values, but the activation (300 samples at 1000 Hz) covers 30 at 100 Hz"),
        "{text}"
    );
    let text = with(&|s| s.aux.get_mut("humidity").unwrap().values[17] = f32::NAN);
    assert!(
        text.contains("auxiliary channel `humidity`: non-finite value NaN at sample 17"),
        "{text}"
    );
    // The format's own channels keep their units: a relabelled one would be read back wrong.
    let text = with(&|s| s.aux.get_mut("supply_voltage").unwrap().unit = "mV".into());
    assert!(
        text.contains("auxiliary channel `supply_voltage`: unit `mV`, but the format records `supply_voltage` in V"),
        "{text}"
    );
    // One topic per named channel, so one unit per file.
    let first = segment(1, 1_000, 300, &[("humidity", "%RH", vec![40.0; 30])]);
    let second = segment(
        2,
        10_000_000_000,
        300,
        &[("humidity", "ppm", vec![40.0; 30])],
    );
    let text = refused(&recording(vec![first, second]));
    assert!(
        text.contains("segment 1 (series 1, repeat 1, activation 2), auxiliary channel `humidity`: unit `ppm`, but segment 0 has it in `%RH`"),
        "{text}"
    );
}

// --- reading files a bench wrote -----------------------------------------------------------------

/// An extra topic of a bench file: name, schema (name, text), channel metadata.
type Extra<'a> = (&'a str, (&'a str, &'a str), &'a [(&'a str, &'a str)]);
/// A batch of an extra topic: (first sample, rate, values); `None` leaves the batch out.
type Batch = Option<(u32, u32, Vec<f32>)>;
/// The extra topics' batches, by topic and batch number.
type Batches<'a> = &'a dyn Fn(&str, u32) -> Batch;

/// A file with the format's topics and one activation of 300 samples, plus `extra` topics (name,
/// schema, channel metadata) whose batch `b` is `batch(b)`: (first sample, rate, values).
fn bench_file(path: &Path, extra: &[Extra], batch: Batches) {
    let metadata = BTreeMap::from([
        ("unit_id".to_owned(), "BENCH-9".to_owned()),
        ("sample_rate_hz".to_owned(), "1000".to_owned()),
    ]);
    let mut f = create_recording(path, metadata).unwrap();
    for (topic, schema, meta) in extra {
        f.add_topic(topic, *schema, meta).unwrap();
    }
    let event = |powered| PowerEvent {
        powered,
        series_kind: "protocol".into(),
        series: 1,
        repeat: 1,
        activation: 1,
        interval_min: 5.0,
        off_before_s: f64::NAN,
        set_point_celsius: 30.0,
    };
    f.power(&event(true), 0).unwrap();
    for b in 0..3u32 {
        let log_ns = u64::from(b) * 100_000_000;
        let rate = vec![0.0f32; 100];
        Vector3Batch::encode(b * 100, 1000, [&rate, &rate, &rate], &mut f.enc);
        f.write_encoded(schema::TOPIC_RATE, log_ns).unwrap();
        let raw = vec![6000i16; 100];
        RawTemperatureBatch::encode(b * 100, 1000, [&raw, &raw, &raw], &mut f.enc);
        f.write_encoded(schema::TOPIC_TEMPERATURE_RAW, log_ns)
            .unwrap();
        let aux = vec![1.0f32; 10];
        Vector3Batch::encode(b * 10, 100, [&aux, &aux, &aux], &mut f.enc);
        f.write_encoded(schema::TOPIC_ACCEL, log_ns).unwrap();
        for topic in [schema::TOPIC_SUPPLY, schema::TOPIC_SET_POINT] {
            ScalarBatch::encode(b * 10, 100, &aux, &mut f.enc);
            f.write_encoded(topic, log_ns).unwrap();
        }
        for (topic, _, _) in extra {
            if let Some((first, rate, values)) = batch(topic, b) {
                // Whatever the schema says, the bytes are a ScalarBatch's: the reader must go by
                // the schema, not by whether the bytes happen to decode.
                ScalarBatch::encode(first, rate, &values, &mut f.enc);
                f.write_encoded(topic, log_ns).unwrap();
            }
        }
    }
    f.power(&event(false), 300 * 1_000_000).unwrap();
    f.finish().unwrap();
}

/// Regular batches of 10 values, `k`-th value `k as f32 / 4`.
fn regular(_: &str, b: u32) -> Batch {
    Some((
        b * 10,
        100,
        (0..10).map(|i| (b * 10 + i) as f32 / 4.0).collect(),
    ))
}

fn read_bench(extra: &[Extra], batch: Batches) -> Result<Recording, ReadError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bench.mcap");
    bench_file(&path, extra, batch);
    read_recording(&path)
}

/// (topic, message index, reason) of a message error, checked to name the file.
fn message_error(result: Result<Recording, ReadError>) -> (String, usize, String) {
    match result {
        Err(ReadError::Message {
            path,
            topic,
            index,
            reason,
        }) => {
            assert!(path.ends_with("bench.mcap"), "{}", path.display());
            (topic, index, reason)
        }
        other => panic!("expected a message error, got {other:?}"),
    }
}

#[test]
fn a_bench_scalar_topic_under_aux_is_a_channel_named_after_it() {
    let rec = read_bench(
        &[
            (
                "/aux/oven_humidity",
                schema::SCHEMA_SCALAR,
                &[("unit", "%RH")],
            ),
            // No unit in the metadata: read with an empty unit rather than refused.
            ("/aux/count", schema::SCHEMA_SCALAR, &[]),
            // Outside /aux/, a topic the format does not know is still ignored, whatever it is.
            ("/bench/notes", ("bench/Note", "string text\n"), &[]),
        ],
        &regular,
    )
    .unwrap();
    let aux = &rec.segments[0].aux;
    let expected: Vec<f32> = (0..30).map(|k| k as f32 / 4.0).collect();
    assert_eq!(aux["oven_humidity"], channel("%RH", expected.clone()));
    assert_eq!(aux["count"], channel("", expected));
    assert_eq!(aux.len(), 7, "{:?}", aux.keys());
}

#[test]
fn an_unknown_schema_under_aux_is_an_error_naming_file_topic_and_message() {
    let (topic, index, reason) = message_error(read_bench(
        &[("/aux/gps", schema::SCHEMA_VECTOR3, &[("unit", "deg")])],
        &regular,
    ));
    assert_eq!((topic.as_str(), index), ("/aux/gps", 0));
    assert_eq!(
        reason,
        "schema `gyrodrift_msgs/msg/Vector3Batch`: an auxiliary topic other than /aux/accel is a named channel and must be gyrodrift_msgs/msg/ScalarBatch"
    );
    let text = read_bench(
        &[("/aux/gps", ("std_msgs/msg/Float64", "float64 data\n"), &[])],
        &regular,
    )
    .unwrap_err()
    .to_string();
    assert!(
        text.ends_with("bench.mcap: topic /aux/gps, message #0: schema `std_msgs/msg/Float64`: an auxiliary topic other than /aux/accel is a named channel and must be gyrodrift_msgs/msg/ScalarBatch"),
        "{text}"
    );
}

#[test]
fn a_topic_that_cannot_be_a_named_channel_is_an_error_naming_it() {
    // It would shadow the accelerometer's X channel.
    let (topic, index, reason) = message_error(read_bench(
        &[("/aux/accel_x", schema::SCHEMA_SCALAR, &[("unit", "g")])],
        &regular,
    ));
    assert_eq!((topic.as_str(), index), ("/aux/accel_x", 0));
    assert!(
        reason.contains("auxiliary channel `accel_x` is one of the format's own channels"),
        "{reason}"
    );
    // Two topic levels: not a channel name.
    let (topic, _, reason) = message_error(read_bench(
        &[("/aux/gps/speed", schema::SCHEMA_SCALAR, &[])],
        &regular,
    ));
    assert_eq!(topic, "/aux/gps/speed");
    assert!(
        reason.contains("auxiliary channel `gps/speed` has `/` at byte 3"),
        "{reason}"
    );
}

#[test]
fn bad_samples_in_a_named_channel_are_named_like_the_format_s_own() {
    let extra: &[Extra] = &[("/aux/humidity", schema::SCHEMA_SCALAR, &[("unit", "%RH")])];
    let cases: [(Batches, usize, &str); 4] = [
        (
            &|t, b| {
                regular(t, b).map(|(f, r, mut v)| {
                    if b == 2 {
                        v[3] = f32::INFINITY;
                    }
                    (f, r, v)
                })
            },
            2,
            "non-finite value inf at sample 23 of the segment",
        ),
        (
            &|t, b| if b == 1 { None } else { regular(t, b) },
            1, // the third batch is the topic's second message
            "gap: first_sample 20, expected 10",
        ),
        (
            &|t, b| regular(t, b).map(|(f, _, v)| (f, if b == 0 { 50 } else { 100 }, v)),
            0,
            "sample_rate_hz 50, expected 100",
        ),
        (
            &|t, b| regular(t, b).map(|(f, r, v)| (if b == 1 { f - 1 } else { f }, r, v)),
            1,
            "overlap or duplicate: first_sample 9, expected 10",
        ),
    ];
    for (batch, expected_index, expected) in cases {
        let (topic, index, reason) = message_error(read_bench(extra, batch));
        assert_eq!(
            (topic.as_str(), index),
            ("/aux/humidity", expected_index),
            "{reason}"
        );
        assert!(reason.contains(expected), "{reason}");
    }
    // More samples than the activation covers: found at the switch-off, when its length is known
    // (a write back would drop them).
    let (topic, index, reason) = message_error(read_bench(extra, &|t, b| {
        regular(t, b).map(|(f, r, mut v)| {
            if b == 2 {
                v.push(9.0);
            }
            (f, r, v)
        })
    }));
    assert_eq!((topic.as_str(), index), ("/power/state", 1));
    assert_eq!(
        reason,
        "auxiliary channel `humidity` has 31 samples, but the activation (300 samples at 1000 Hz) covers 30 at 100 Hz"
    );
}

#[test]
fn two_channel_records_of_one_named_topic_with_different_units_are_an_error() {
    // MCAP allows several channel records on one topic; a recording's channel has one unit. The
    // third batch goes out on a second channel record of the topic, in per mille.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bench.mcap");
    let metadata = BTreeMap::from([
        ("unit_id".to_owned(), "BENCH-9".to_owned()),
        ("sample_rate_hz".to_owned(), "1000".to_owned()),
    ]);
    let mut f = create_recording(&path, metadata).unwrap();
    let topic = "/aux/humidity";
    f.add_topic(topic, schema::SCHEMA_SCALAR, &[("unit", "%RH")])
        .unwrap();
    let event = |powered| PowerEvent {
        powered,
        series_kind: "protocol".into(),
        series: 1,
        repeat: 1,
        activation: 1,
        interval_min: 5.0,
        off_before_s: f64::NAN,
        set_point_celsius: 30.0,
    };
    f.power(&event(true), 0).unwrap();
    for b in 0..3u32 {
        if b == 2 {
            // Registering the topic again with other metadata makes a second channel record.
            f.add_topic(topic, schema::SCHEMA_SCALAR, &[("unit", "‰")])
                .unwrap();
        }
        let (first, rate, values) = regular(topic, b).unwrap();
        ScalarBatch::encode(first, rate, &values, &mut f.enc);
        f.write_encoded(topic, u64::from(b) * 100_000_000).unwrap();
    }
    f.power(&event(false), 300 * 1_000_000).unwrap();
    f.finish().unwrap();
    let (topic, index, reason) = message_error(read_recording(&path));
    assert_eq!((topic.as_str(), index), ("/aux/humidity", 2));
    assert_eq!(
        reason,
        "channel metadata unit `‰`, but an earlier channel on this topic has `%RH`"
    );
}
