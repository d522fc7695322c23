//! Field motion: the recorded rate is the static unit's plus the planned body rate, the
//! accelerometer turns with the body, and switching motion on changes nothing else.

use drift_sim::motion::{true_rate, turn_gravity, Motion};
use drift_sim::schedule::plan;
use drift_sim::{read_recording, simulate_campaign, Campaign, Field, Segment};

fn campaign(motion: Option<Motion>) -> Campaign {
    Campaign {
        units: 1,
        set_points_celsius: vec![30.0],
        protocol: None,
        field: Some(Field {
            sessions: 1,
            activations: 2,
            activation_s: [20.0, 20.0],
            motion,
            ..Field::default()
        }),
        ..Campaign::default()
    }
}

fn segments(c: &Campaign) -> Vec<Segment> {
    let dir = tempfile::tempdir().unwrap();
    let summary = simulate_campaign(c, dir.path(), |_| {}).unwrap();
    read_recording(&summary.files[0].recording)
        .unwrap()
        .segments
}

#[test]
fn the_recorded_rate_carries_the_planned_rotations_and_nothing_else_changes() {
    let motion = Motion {
        rotation_s: [3.0, 3.0],
        rate_dps: [45.0, 45.0],
        still_s: [4.0, 4.0],
    };
    let moving = campaign(Some(motion));
    let still = segments(&campaign(None));
    let moved = segments(&moving);
    let plans = plan(&moving);
    let rotations = &plans[0].activations[0].motion;
    assert_eq!(rotations.len(), 3, "{rotations:?}");
    assert_eq!((rotations[0].start, rotations[0].end), (4_000, 7_000));
    let (a, b) = (&still[0], &moved[0]);
    assert_eq!(a.temperature_raw, b.temperature_raw);
    for axis in 0..3 {
        for i in (0..a.len()).step_by(97) {
            let body = true_rate(rotations, i as u32)[axis];
            let difference = f64::from(b.rate_dps[axis][i] - a.rate_dps[axis][i]);
            // The rate's output LSB (24-bit words) is far below 1e-4 °/s.
            assert!((difference - body).abs() < 1e-4, "axis {axis} sample {i}");
        }
    }
    // Still before the first turn, gravity has turned with it after (45°/s for 3 s about the
    // rotation's axis); the accelerometer's bias (≤ 0.005 g) and noise stay in.
    let accel =
        |s: &Segment, k: usize| ["accel_x", "accel_y", "accel_z"].map(|n| s.aux[n].values[k]);
    let (before, after) = (accel(b, 390), accel(b, 720));
    assert_eq!(before, accel(a, 390));
    let turned = turn_gravity(before.map(f64::from), rotations[0].rate_dps, 3.0);
    for (got, want) in after.iter().zip(turned) {
        assert!(
            (f64::from(*got) - want).abs() < 0.02,
            "{after:?} vs {turned:?}"
        );
    }
}

#[test]
fn bad_motion_is_named() {
    let mut c = campaign(Some(Motion {
        still_s: [5.0, 1.0],
        ..Motion::default()
    }));
    let err = c.validate().unwrap_err().to_string();
    assert!(err.contains("field.motion.still_s"), "{err}");
    c.field.as_mut().unwrap().motion = Some(Motion {
        rotation_s: [0.0, 1.0],
        ..Motion::default()
    });
    let err = c.validate().unwrap_err().to_string();
    assert!(err.contains("field.motion.rotation_s"), "{err}");
}
