//! Seed inputs for each target (`cargo run -p drift-fuzz --example write-seeds`): small valid
//! inputs the fuzzer starts from, so its mutations begin inside the formats.

use std::collections::BTreeMap;

use drift_recording::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use drift_recording::AUX_RATE_HZ;

/// Seeds of the blob target: each vector image under each mode byte.
pub fn blob() -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for (_, image) in crate::models::images() {
        for mode in [0u8, 3] {
            out.push([&[mode][..], &image].concat());
        }
    }
    out
}

/// A small recording, written uncompressed (so byte mutations reach the CDR messages instead of
/// breaking a zstd frame) and once zstd-compressed like the simulator's.
pub fn recording() -> Vec<Vec<u8>> {
    [None, Some(mcap::Compression::Zstd)]
        .into_iter()
        .map(small_recording)
        .collect()
}

fn small_recording(compression: Option<mcap::Compression>) -> Vec<u8> {
    let mut cursor = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::WriteOptions::new()
            .profile(schema::PROFILE_RECORDING)
            .compression(compression)
            .create(&mut cursor)
            .expect("in-memory writer");
        let mut channels = BTreeMap::new();
        let topics = [
            (schema::TOPIC_RATE, schema::SCHEMA_VECTOR3),
            (
                schema::TOPIC_TEMPERATURE_RAW,
                schema::SCHEMA_RAW_TEMPERATURE,
            ),
            (schema::TOPIC_ACCEL, schema::SCHEMA_VECTOR3),
            (schema::TOPIC_SUPPLY, schema::SCHEMA_SCALAR),
            (schema::TOPIC_SET_POINT, schema::SCHEMA_SCALAR),
            (schema::TOPIC_POWER, schema::SCHEMA_POWER),
        ];
        for (topic, (name, text)) in topics {
            let schema_id = w
                .add_schema(name, "ros2msg", text.as_bytes())
                .expect("schema");
            let id = w
                .add_channel(schema_id, topic, "cdr", &BTreeMap::new())
                .expect("channel");
            channels.insert(topic, id);
        }
        let metadata = BTreeMap::from([
            ("unit_id".to_owned(), "SEED".to_owned()),
            ("sample_rate_hz".to_owned(), "1000".to_owned()),
        ]);
        w.write_metadata(&mcap::records::Metadata {
            name: schema::METADATA_RECORDING.into(),
            metadata,
        })
        .expect("metadata");
        let mut enc = drift_recording::cdr::Encoder::default();
        let mut sequence = 0;
        let mut put = |w: &mut mcap::Writer<_>, topic: &str, ns: u64, bytes: &[u8]| {
            sequence += 1;
            let header = mcap::records::MessageHeader {
                channel_id: channels[topic],
                sequence,
                log_time: ns,
                publish_time: ns,
            };
            w.write_to_known_channel(&header, bytes).expect("message");
        };
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
        event(true).encode(&mut enc);
        put(&mut w, schema::TOPIC_POWER, 1_000, enc.bytes());
        // Two batches of 10 samples at 1000 Hz (one auxiliary sample each).
        for batch in 0..2u32 {
            let first = batch * 10;
            let ns = 1_000 + u64::from(first) * 1_000_000;
            let rate = [0.01f32, -0.02, 0.5, 0.0, 1e-3, 2.0, -1.0, 0.25, 0.125, 3.0];
            Vector3Batch::encode(first, 1000, [&rate, &rate, &rate], &mut enc);
            put(&mut w, schema::TOPIC_RATE, ns, enc.bytes());
            let raw = [
                6000i16, 6001, 6002, 6003, 6004, 6005, 6006, -32768, 6008, 6009,
            ];
            RawTemperatureBatch::encode(first, 1000, [&raw, &raw, &raw], &mut enc);
            put(&mut w, schema::TOPIC_TEMPERATURE_RAW, ns, enc.bytes());
            let aux = [1.0f32];
            Vector3Batch::encode(batch, AUX_RATE_HZ, [&aux, &aux, &aux], &mut enc);
            put(&mut w, schema::TOPIC_ACCEL, ns, enc.bytes());
            ScalarBatch::encode(batch, AUX_RATE_HZ, &aux, &mut enc);
            put(&mut w, schema::TOPIC_SUPPLY, ns, enc.bytes());
            ScalarBatch::encode(batch, AUX_RATE_HZ, &aux, &mut enc);
            put(&mut w, schema::TOPIC_SET_POINT, ns, enc.bytes());
        }
        event(false).encode(&mut enc);
        put(
            &mut w,
            schema::TOPIC_POWER,
            1_000 + 20 * 1_000_000,
            enc.bytes(),
        );
        w.finish().expect("finish");
    }
    cursor.into_inner()
}

/// CSV seeds: fixed-rate rows, host timestamps, a dropout, two activations.
pub fn csv() -> Vec<Vec<u8>> {
    let header = "segment_id,t_s,gx_dps,gy_dps,gz_dps,temp_c,ax_g\n";
    let strict: String = (0..12)
        .map(|i| {
            format!(
                "0,{},{},0.1,-0.2,{},1\n",
                f64::from(i) / 100.0,
                0.01 * f64::from(i),
                30.0 + 0.005 * f64::from(i)
            )
        })
        .collect();
    let jitter = "0,0,1,2,3,25.0,0\n0,0.004,1,2,3,25.1,0\n0,0.013,1,2,3,,0\n0,0.031,1,2,3,25.2,0\n1,0,0,0,0,24,0\n1,0.2,0,0,0,nan,0\n1,0.25,1e3,-1e3,0,24.5,0\n";
    vec![
        [&[0u8][..], header.as_bytes(), strict.as_bytes()].concat(),
        [&[6u8][..], header.as_bytes(), jitter.as_bytes()].concat(),
        [&[2u8][..], b"t_s,gx_dps,gy_dps,gz_dps,temp_c\n0,1,1,1,20\n"].concat(),
    ]
}

/// Corrector seeds: each model with a power-on, samples in the envelope, faults and raw bits.
pub fn corrector() -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for model in 0u8..3 {
        let mut ops = vec![model];
        // Power on at 30 °C (6000 raw = 5000 + 1000).
        ops.push(0);
        for _ in 0..3 {
            ops.extend_from_slice(&1000u16.to_le_bytes());
        }
        for step in 0u16..40 {
            ops.push(9);
            ops.extend_from_slice(&(step * 1500).to_le_bytes());
            for _ in 0..3 {
                ops.extend_from_slice(&((step as i16) * 7).to_le_bytes());
                ops.extend_from_slice(&(1000 + step * 3).to_le_bytes());
            }
        }
        // One sample as raw bits: NaN temperature, infinite rate, huge values.
        ops.push(0x89);
        ops.extend_from_slice(&60_000u32.to_le_bytes());
        for value in [f32::INFINITY, f32::NAN, 3.0e38, -3.0e38, 0.5, 6100.0] {
            ops.extend_from_slice(&value.to_le_bytes());
        }
        ops.push(8); // power off
        ops.push(9);
        ops.extend_from_slice(&[0; 14]);
        out.push(ops);
    }
    out.push(corrector_by_history());
    // The same operations on the tables with warm starts' initial bias.
    let mut warm = corrector_by_history();
    if let Some(which) = warm.first_mut() {
        *which = 7;
    }
    out.push(warm);
    // The same operations on the extended model, whose rate filter starts from what was kept.
    let mut extended = corrector_by_history();
    if let Some(which) = extended.first_mut() {
        *which = 14;
    }
    out.push(extended);
    out
}

/// The tables keyed by heating history: a warm start after a given previous activation, keep,
/// power off, a restart after what was kept, and one start after NaN and infinite kept values.
fn corrector_by_history() -> Vec<u8> {
    let mut ops = vec![3u8];
    let samples = |ops: &mut Vec<u8>, first: u16| {
        for step in first..first + 20 {
            ops.push(9);
            ops.extend_from_slice(&(step * 1500).to_le_bytes());
            for _ in 0..3 {
                ops.extend_from_slice(&((step as i16) * 7).to_le_bytes());
                ops.extend_from_slice(&(1600 + step * 5).to_le_bytes());
            }
        }
    };
    // power_on_after, given: switch-on 33 °C (6600 raw), ambient 31 °C, switch-off 36 °C
    // (kept values are 10 °C + n/64).
    ops.push(7);
    for _ in 0..3 {
        ops.extend_from_slice(&1600u16.to_le_bytes());
    }
    for _ in 0..3 {
        ops.extend_from_slice(&(21 * 64u16).to_le_bytes());
        ops.extend_from_slice(&(26 * 64u16).to_le_bytes());
    }
    samples(&mut ops, 0);
    ops.push(5); // keep
    ops.push(8); // power off
    ops.push(6); // power_on_after with what was kept
    for _ in 0..3 {
        ops.extend_from_slice(&1650u16.to_le_bytes());
    }
    samples(&mut ops, 0);
    ops.push(5);
    // power_on_after, given as raw bits: NaN, ±∞ and extreme kept values.
    ops.push(0x87);
    for value in [6600.0f32, 6640.0, 6580.0] {
        ops.extend_from_slice(&value.to_le_bytes());
    }
    for value in [f32::NAN, 36.0, 31.0, f32::INFINITY, -3.4e38, 3.4e38] {
        ops.extend_from_slice(&value.to_le_bytes());
    }
    samples(&mut ops, 20);
    ops.push(0x85); // keep (the raw-bits bit changes nothing)
    ops
}
