//! The recording's nominal set point (metadata `set_point_celsius`) reaches every activation's
//! labels beside the chamber at its switch-on, and a value that is not a number is refused.

use std::collections::BTreeMap;
use std::path::PathBuf;

use drift_recording::{
    read_recording, write_recording, Recording, Segment, SegmentLabels, SeriesKind,
};

const FS: u32 = 1000;

/// One activation of 200 samples that switched on with the chamber at `at_switch_on` °C.
fn activation(activation: u32, at_switch_on: f64) -> Segment {
    let n = 200;
    Segment {
        labels: SegmentLabels {
            unit_id: "BENCH-7".into(),
            set_point_celsius: at_switch_on,
            session_set_point_celsius: None,
            series_kind: SeriesKind::Field,
            series: 1,
            repeat: 1,
            activation,
            interval_min: None,
            off_before_s: Some(60.0),
        },
        sample_rate_hz: FS,
        power_on_ns: u64::from(activation) * 10_000_000_000,
        since_power_on: (0..n as u32).collect(),
        rate_dps: std::array::from_fn(|a| vec![1e-3 * a as f32; n]),
        temperature_raw: std::array::from_fn(|_| vec![7000; n]),
        temperature_scale: drift_recording::TemperatureScale::default(),
        aux: BTreeMap::new(),
    }
}

fn recording(set_point: Option<&str>) -> Recording {
    let mut metadata = BTreeMap::from([
        ("unit_id".to_owned(), "BENCH-7".to_owned()),
        ("sample_rate_hz".to_owned(), FS.to_string()),
    ]);
    if let Some(s) = set_point {
        metadata.insert("set_point_celsius".to_owned(), s.to_owned());
    }
    Recording {
        path: PathBuf::new(),
        metadata,
        unit_id: "BENCH-7".into(),
        sample_rate_hz: FS,
        // A ramped session at +40 °C: the chamber was at 36.5 and 43.25 °C at the switch-ons.
        segments: vec![activation(1, 36.5), activation(2, 43.25)],
    }
}

#[test]
fn every_activation_carries_the_recordings_nominal_set_point() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ramped.mcap");
    write_recording(&recording(Some("40")), &path).unwrap();
    let back = read_recording(&path).unwrap();
    let labels: Vec<(f64, Option<f64>, f64)> = back
        .segments
        .iter()
        .map(|s| {
            (
                s.labels.set_point_celsius,
                s.labels.session_set_point_celsius,
                s.labels.nominal_set_point_celsius(),
            )
        })
        .collect();
    assert_eq!(
        labels,
        [(36.5, Some(40.0), 40.0), (43.25, Some(40.0), 40.0)]
    );
}

#[test]
fn without_the_metadata_key_the_switch_on_label_is_the_nominal_one() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no-set-point.mcap");
    write_recording(&recording(None), &path).unwrap();
    let back = read_recording(&path).unwrap();
    assert_eq!(back.segments[0].labels.session_set_point_celsius, None);
    assert_eq!(back.segments[1].labels.nominal_set_point_celsius(), 43.25);
}

#[test]
fn a_set_point_that_is_not_a_number_is_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["warm", "NaN", "inf", ""] {
        let path = dir.path().join("bad.mcap");
        write_recording(&recording(Some(bad)), &path).unwrap();
        let e = read_recording(&path).unwrap_err().to_string();
        assert!(e.contains("set_point_celsius"), "{bad:?}: {e}");
    }
}
