//! Write → read → compare: recordings round-trip exactly, are bit-for-bit reproducible,
//! carry every label and auxiliary channel, and their samples are the truth plus noise.

mod common;

use drift_recording::write_recording;
use drift_sim::truth::read_truth;
use drift_sim::{
    read_campaign_dir, read_recording, simulate_campaign, Campaign, Field, SeriesKind,
};

/// Small but complete: protocol (2 intervals × 2 repeats × 5 activations of 3 s) and a
/// field session, 2 units, 2 set points, all hidden effects on.
fn small_campaign() -> Campaign {
    let mut c = Campaign {
        units: 2,
        set_points_celsius: vec![30.0, -10.0],
        ..Campaign::default()
    };
    let p = c.protocol.as_mut().unwrap();
    p.intervals_min = vec![1.0, 15.0];
    p.repeats = 2;
    p.activation_s = 3.0;
    c.field = Some(Field {
        sessions: 1,
        activations: 4,
        activation_s: [2.0, 4.0],
        ..Field::default()
    });
    for e in [
        "thermal_lag",
        "acceleration",
        "supply_voltage",
        "cross_axis",
        "rise_nonlinearity",
        "ageing",
    ] {
        c.effects.enable(e).unwrap();
    }
    c
}

#[test]
fn recordings_round_trip_exactly_and_are_reproducible() {
    let c = small_campaign();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let summary = simulate_campaign(&c, a.path(), |_| {}).unwrap();
    simulate_campaign(&c, b.path(), |_| {}).unwrap();
    assert_eq!(summary.files.len(), 2 * 2 * 2);
    for f in &summary.files {
        // Same seed, same bits: recordings and truth.
        let name = f.recording.file_name().unwrap();
        let other = b.path().join("recordings").join(name);
        assert!(
            std::fs::read(&f.recording).unwrap() == std::fs::read(&other).unwrap(),
            "{name:?} differs between runs"
        );
        let truth_name = f.truth.file_name().unwrap();
        assert!(
            std::fs::read(&f.truth).unwrap()
                == std::fs::read(b.path().join("truth").join(truth_name)).unwrap()
        );
    }
    // A different seed changes the data.
    let d = tempfile::tempdir().unwrap();
    simulate_campaign(
        &Campaign {
            seed: 2,
            ..c.clone()
        },
        d.path(),
        |_| {},
    )
    .unwrap();
    let name = summary.files[0].recording.file_name().unwrap();
    assert!(
        std::fs::read(&summary.files[0].recording).unwrap()
            != std::fs::read(d.path().join("recordings").join(name)).unwrap()
    );

    let recordings = read_campaign_dir(a.path()).unwrap();
    assert_eq!(recordings.len(), summary.files.len());
    for rec in &recordings {
        // Re-write the segments and read again: identical, sample for sample, bit for bit.
        let copy = a.path().join("copy.mcap");
        write_recording(rec, &copy).unwrap();
        let again = read_recording(&copy).unwrap();
        assert_eq!(again.metadata, rec.metadata);
        assert_eq!(again.segments.len(), rec.segments.len());
        for (x, y) in rec.segments.iter().zip(&again.segments) {
            assert_eq!(x.labels, y.labels);
            assert_eq!(x.since_power_on, y.since_power_on);
            assert_eq!(x.temperature_raw, y.temperature_raw);
            for axis in 0..3 {
                let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&x.rate_dps[axis]), bits(&y.rate_dps[axis]));
            }
            assert_eq!(x.aux, y.aux);
            assert_eq!(x.power_on_ns, y.power_on_ns);
        }
    }
}

#[test]
fn labels_aux_channels_and_sample_counts_match_the_campaign() {
    let c = small_campaign();
    let dir = tempfile::tempdir().unwrap();
    simulate_campaign(&c, dir.path(), |_| {}).unwrap();
    let recordings = read_campaign_dir(dir.path()).unwrap();
    let protocol = recordings
        .iter()
        .find(|r| {
            r.path
                .to_string_lossy()
                .contains("GIU-01_sp+30.0C_protocol")
        })
        .unwrap();
    assert_eq!(protocol.unit_id, "GIU-01");
    assert_eq!(protocol.metadata["set_point_celsius"], "30");
    assert_eq!(protocol.segments.len(), 2 * 2 * 5);
    for (i, seg) in protocol.segments.iter().enumerate() {
        let l = &seg.labels;
        assert_eq!(l.series_kind, SeriesKind::Protocol);
        assert_eq!(l.activation as usize, i % 5 + 1);
        assert_eq!(l.repeat as usize, (i / 5) % 2 + 1);
        assert_eq!(l.interval_min, Some(if i < 10 { 1.0 } else { 15.0 }));
        assert_eq!(
            l.off_before_s,
            Some(if l.activation == 1 {
                3600.0
            } else {
                l.interval_min.unwrap() * 60.0
            })
        );
        assert_eq!(l.set_point_celsius, 30.0);
        // The file's nominal set point is the switch-on one here: said once (`None`).
        assert_eq!(l.session_set_point_celsius, None);
        assert_eq!(l.nominal_set_point_celsius(), 30.0);
        assert_eq!(seg.len(), 3000);
        assert_eq!(seg.since_power_on_ms(2999), Some(2999));
        for name in [
            "accel_x",
            "accel_y",
            "accel_z",
            "supply_voltage",
            "chamber_set_point",
        ] {
            assert_eq!(seg.aux[name].values.len(), 300, "{name}");
        }
        // Z up, 5 V, chamber at the set point.
        assert!((seg.aux["accel_z"].values[0] - 1.0).abs() < 0.02);
        assert!((seg.aux["supply_voltage"].values[0] - 5.0).abs() < 0.02);
        assert_eq!(seg.aux["chamber_set_point"].values[0], 30.0);
        // Raw temperature is 200 units per °C near the set point (sensor offset ≤ 1 °C).
        assert!((seg.temperature_celsius(0, 0).unwrap() - 30.0).abs() < 3.0);
    }
    // Activations are in time order on the recording clock.
    assert!(protocol
        .segments
        .windows(2)
        .all(|w| w[1].power_on_ns > w[0].power_on_ns));
    let field = recordings
        .iter()
        .find(|r| r.path.to_string_lossy().contains("GIU-02_sp-10.0C_field"))
        .unwrap();
    assert_eq!(field.segments.len(), 4);
    for seg in &field.segments {
        assert_eq!(seg.labels.series_kind, SeriesKind::Field);
        assert_eq!(seg.labels.interval_min, None);
        assert!(seg.len() >= 2000 && seg.len() <= 4000 && seg.len() % 100 == 0);
        // Every activation belongs to the file's set point, wherever the ramp had taken the
        // chamber at its switch-on.
        assert_eq!(seg.labels.nominal_set_point_celsius(), -10.0);
    }
}

#[test]
fn noise_free_samples_are_the_truth_quantised() {
    let mut c = small_campaign();
    c.noise_scale = 0.0;
    c.field = None;
    let dir = tempfile::tempdir().unwrap();
    let summary = simulate_campaign(&c, dir.path(), |_| {}).unwrap();
    let rec = read_recording(&summary.files[0].recording).unwrap();
    let truth = read_truth(&summary.files[0].truth).unwrap();
    assert_eq!(truth.len(), rec.segments.len());
    let lsb = 1.0 / 16384.0;
    for (seg, t) in rec.segments.iter().zip(&truth) {
        for axis in 0..3 {
            assert_eq!(t.systematic_bias_dps[axis].len(), seg.len());
            for (r, b) in seg.rate_dps[axis].iter().zip(&t.systematic_bias_dps[axis]) {
                // Output quantisation (half an LSB) plus f32 rounding of both numbers.
                assert!(
                    (f64::from(*r) - f64::from(*b)).abs() <= 0.5 * lsb + 1e-6,
                    "{r} vs {b}"
                );
            }
        }
    }
}
