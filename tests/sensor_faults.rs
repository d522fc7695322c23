//! Temperature-sensor faults injected by the simulator (dropout, stuck reading, spikes) against the
//! corrector's documented behaviour: outside the faulty samples the output equals the fault-free
//! twin's bit for bit; a dropout is flagged TEMPERATURE_INVALID with the last good drift held; a
//! reading frozen for `stuck_after_samples` is flagged TEMPERATURE_STUCK and held; a spike is a
//! wrong reading the corrector cannot tell from a real one (no flag; error bounded by k × spike).
//! The fitter refuses calibration data with a dropout, naming where.

use drift_core::{Corrector, Flags, Model, Sample};
use drift_evaluate::evaluate::switch_on_raw;
use drift_evaluate::pipeline::{self, Options};
use drift_fit::{FitSettings, FittedUnit};
use drift_recording::{read_recording, temperature_reading, Segment};
use drift_sim::faults::{FaultEvent, FaultKind, FaultWindow, SensorFaults, Spikes};
use drift_sim::truth::read_faults;
use drift_sim::{simulate_campaign, Campaign, Protocol};

fn campaign(faults: SensorFaults) -> Campaign {
    Campaign {
        name: "faults".into(),
        seed: 5,
        units: 1,
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0, 30.0],
            repeats: 1,
            ..Protocol::default()
        }),
        faults,
        ..Campaign::default()
    }
}

fn options() -> Options {
    Options {
        calibration_set_points: vec![30.0, 40.0],
        validation_set_points: vec![33.0],
        fit: FitSettings::default(),
        held_out_repeats: false,
        evaluate: false,
        switch_on_ambient: None,
    }
}

/// Per sample, per axis: corrected rate, bias and flags of the modified tables.
type Trace = Vec<[(f32, f32, Flags); 3]>;

fn trace<M: Model>(model: &M, segment: &Segment) -> Trace {
    let mut corrector = Corrector::new(model).unwrap();
    corrector
        .power_on(switch_on_raw(segment, &FitSettings::default()))
        .unwrap();
    (0..segment.len())
        .map(|i| {
            let out = corrector.correct(&Sample {
                since_power_on_ms: segment.since_power_on_ms(i).unwrap() as u32,
                rate_dps: [0, 1, 2].map(|a| segment.rate_dps[a][i]),
                temperature_raw: [0, 1, 2]
                    .map(|a| temperature_reading(segment.temperature_raw[a][i])),
            });
            [0, 1, 2].map(|a| (out.corrected_dps[a], out.bias_dps[a], out.flags[a]))
        })
        .collect()
}

fn faulty(events: &[FaultEvent], axis: usize, i: usize) -> bool {
    events.iter().any(|e| {
        e.axis == axis
            && (e.start_sample as usize..(e.start_sample + e.samples) as usize).contains(&i)
    })
}

#[test]
fn the_corrector_holds_and_flags_injected_faults_and_is_exact_elsewhere() {
    let faults = SensorFaults {
        dropout: Some(FaultWindow::default()),
        stuck: Some(FaultWindow {
            start_s: [70.0, 90.0],
            ..FaultWindow::default()
        }),
        spikes: Some(Spikes::default()),
    };
    let dir = tempfile::tempdir().unwrap();
    let (clean_dir, faulty_dir) = (dir.path().join("clean"), dir.path().join("faulty"));
    simulate_campaign(&campaign(SensorFaults::default()), &clean_dir, |_| {}).unwrap();
    let summary = simulate_campaign(&campaign(faults), &faulty_dir, |_| {}).unwrap();

    // The fitter refuses the faulty calibration recordings, naming unit, activation, axis, sample.
    let files = pipeline::recording_files(&faulty_dir).unwrap();
    let error = pipeline::run(&files, &options(), false, drift_recording::QUIET)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("unit GIU-01")
            && error.contains("temperature reading missing at sample")
            && error.contains("sensor dropout"),
        "{error}"
    );

    let files = pipeline::recording_files(&clean_dir).unwrap();
    let fitted: FittedUnit = pipeline::run(&files, &options(), false, drift_recording::QUIET)
        .unwrap()
        .fitted
        .remove(0);
    let stuck_after = usize::from(fitted.modified.settings().stuck_after_samples);
    let file = summary
        .files
        .iter()
        .find(|f| f.set_point_celsius == 33.0)
        .unwrap();
    let events = read_faults(&file.truth).unwrap();
    let clean_path = clean_dir
        .join("recordings")
        .join(file.recording.file_name().unwrap());
    let (clean, bad) = (
        read_recording(&clean_path).unwrap(),
        read_recording(&file.recording).unwrap(),
    );
    let mut seen = [0usize; 3];
    for (c, b) in clean.segments.iter().zip(&bad.segments) {
        let here: Vec<FaultEvent> = events
            .iter()
            .filter(|e| {
                (e.series, e.repeat, e.activation)
                    == (b.labels.series, b.labels.repeat, b.labels.activation)
            })
            .cloned()
            .collect();
        assert!(
            !here.is_empty(),
            "every activation has faults (probability 1)"
        );
        let (tc, tb) = (trace(&fitted.modified, c), trace(&fitted.modified, b));
        for axis in 0..3 {
            for i in 0..b.len() {
                let (clean_out, bad_out) = (tc[i][axis], tb[i][axis]);
                if !faulty(&here, axis, i) {
                    // The hint of stage 3 and the stuck counter are the only state a fault leaves
                    // behind, and neither changes a result: exact outside the faulty samples.
                    assert_eq!(
                        clean_out.0.to_bits(),
                        bad_out.0.to_bits(),
                        "axis {axis} sample {i}"
                    );
                    assert!(!bad_out
                        .2
                        .intersects(Flags::TEMPERATURE_INVALID | Flags::TEMPERATURE_STUCK));
                }
            }
        }
        for e in &here {
            let (a, start, end) = (
                e.axis,
                e.start_sample as usize,
                (e.start_sample + e.samples) as usize,
            );
            let held_from = tb[start - 1][a].1;
            match e.kind {
                FaultKind::Dropout => {
                    seen[0] += 1;
                    for s in &tb[start..end] {
                        assert!(s[a].2.contains(Flags::TEMPERATURE_INVALID));
                        assert!(
                            s[a].1.to_bits() == held_from.to_bits() || overlapping(&here, e),
                            "dropout holds the last good bias"
                        );
                        assert!(s[a].0.is_finite());
                    }
                }
                FaultKind::Stuck => {
                    seen[1] += 1;
                    // Flagged at the latest once the frozen reading has repeated the limit.
                    let flagged = &tb[(start + stuck_after).min(end)..end];
                    assert!(flagged.iter().all(
                        |s| s[a].2.contains(Flags::TEMPERATURE_STUCK) || overlapping(&here, e)
                    ));
                    if let Some(first) = flagged.first() {
                        assert!(
                            flagged
                                .iter()
                                .all(|s| s[a].1 == first[a].1 || overlapping(&here, e)),
                            "stuck holds"
                        );
                    }
                }
                FaultKind::Spike => {
                    seen[2] += 1;
                    // Not detectable per sample: no fault flag; the error is the drift model's
                    // response to a 5 °C wrong rise, bounded by the largest |k| of the tables.
                    let out = tb[start][a];
                    assert!(!out.2.intersects(Flags::FAULTS) || overlapping(&here, e));
                    let error = (out.0 - tc[start][a].0).abs();
                    assert!(error < 0.5, "spike error {error} °/s");
                }
            }
        }
    }
    assert!(
        seen.iter().all(|&n| n > 0),
        "dropouts, stuck, spikes seen: {seen:?}"
    );
}

/// Faults on the same axis whose windows overlap change each other's expectations.
fn overlapping(events: &[FaultEvent], e: &FaultEvent) -> bool {
    events.iter().any(|o| {
        o != e
            && o.axis == e.axis
            && o.start_sample < e.start_sample + e.samples
            && e.start_sample < o.start_sample + o.samples
    })
}

#[test]
fn faults_are_ground_truth_only() {
    let dir = tempfile::tempdir().unwrap();
    let faults = SensorFaults {
        spikes: Some(Spikes::default()),
        ..SensorFaults::default()
    };
    let mut c = campaign(faults);
    c.set_points_celsius = vec![30.0];
    c.protocol.as_mut().unwrap().activation_s = 2.0;
    let summary = simulate_campaign(&c, dir.path(), |_| {}).unwrap();
    let recording = read_recording(&summary.files[0].recording).unwrap();
    assert!(
        recording.metadata.keys().all(|k| !k.contains("fault")),
        "{:?}",
        recording.metadata
    );
    let campaign_json = std::fs::read_to_string(dir.path().join("truth/campaign.json")).unwrap();
    assert!(campaign_json.contains("\"spikes\""), "{campaign_json}");
    assert_eq!(read_faults(&summary.files[0].truth).unwrap().len(), 10 * 15);
    // Off by default: the sidecar records none.
    let clean = tempfile::tempdir().unwrap();
    c.faults = SensorFaults::default();
    let summary = simulate_campaign(&c, clean.path(), |_| {}).unwrap();
    assert!(read_faults(&summary.files[0].truth).unwrap().is_empty());
}
