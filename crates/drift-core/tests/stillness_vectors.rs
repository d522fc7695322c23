//! The stillness learner's test vectors: the committed file is current, and drift-core reproduces
//! it bit for bit (what the Cortex-M4 run checks too, `embedded/`).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::arithmetic_side_effects,
    clippy::cast_possible_truncation,
    clippy::panic,
    missing_docs
)]

#[path = "common/stillness_format.rs"]
mod stillness_format;

use drift_core::{StillnessLearner, StillnessSettings};
use stillness_format::{StillnessCase, StillnessVectors};

const PATH: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../testdata/stillness-vectors.json"
);

fn settings_bits(s: &StillnessSettings) -> [u32; 8] {
    s.to_array().map(f32::to_bits)
}

fn settings_of(bits: [u32; 8]) -> StillnessSettings {
    StillnessSettings::from_array(bits.map(f32::from_bits))
}

/// What firmware computes: per gyro sample the output rate and states, then the final offset.
fn run(case: &StillnessCase) -> (Vec<[u32; 3]>, Vec<u8>, [u32; 3]) {
    let mut learner = StillnessLearner::new(&settings_of(case.settings)).unwrap();
    learner
        .set_offset(case.start_offset.map(f32::from_bits))
        .unwrap();
    let (mut rates, mut states) = (Vec::new(), Vec::new());
    let mut accel = case.accel.iter();
    for (i, rate) in case.rate.iter().enumerate() {
        if case.accel_every > 0 && i as u32 % case.accel_every == 0 {
            if let Some(a) = accel.next() {
                learner.accelerometer(a.map(f32::from_bits));
            }
        }
        let out = learner.update(rate.map(f32::from_bits));
        rates.push(out.rate_dps.map(f32::to_bits));
        states.push(u8::from(out.still) | (u8::from(out.learning) << 1));
    }
    (rates, states, learner.offset_dps().map(f32::to_bits))
}

/// Deterministic noise: a 64-bit LCG's uniform draws summed (about normal), times `scale`.
struct Noise(u64);

impl Noise {
    fn next(&mut self, scale: f32) -> f32 {
        let mut sum = 0.0f64;
        for _ in 0..4 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            sum += (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        }
        (sum * 1.732) as f32 * scale
    }
}

/// A case from the learner's inputs, with what drift-core returns for them.
fn case(
    name: &str,
    settings: &StillnessSettings,
    start_offset: [f32; 3],
    accel_every: u32,
    accel: Vec<[f32; 3]>,
    rate: Vec<[f32; 3]>,
) -> StillnessCase {
    let mut c = StillnessCase {
        name: name.into(),
        settings: settings_bits(settings),
        start_offset: start_offset.map(f32::to_bits),
        accel_every,
        accel: accel.into_iter().map(|a| a.map(f32::to_bits)).collect(),
        rate: rate.into_iter().map(|r| r.map(f32::to_bits)).collect(),
        expected: Vec::new(),
        states: Vec::new(),
        final_offset: [0; 3],
    };
    (c.expected, c.states, c.final_offset) = run(&c);
    c
}

fn build() -> StillnessVectors {
    let settings = StillnessSettings {
        sample_rate_hz: 100.0,
        accel_rate_hz: 10.0,
        ..StillnessSettings::default()
    };
    let offset = [0.021, -0.013, 0.034];
    let mut noise = Noise(11);

    // Still, a turn about Z (gravity turns with it), still again: learns, stops, learns on.
    let n = 2_000;
    let turning = |i: usize| (600..800).contains(&i);
    let rate: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            let turn = if turning(i) { 30.0 } else { 0.0 };
            [
                offset[0] + noise.next(0.004),
                offset[1] + noise.next(0.004),
                offset[2] + turn + noise.next(0.004),
            ]
        })
        .collect();
    let accel: Vec<[f32; 3]> = (0..n)
        .step_by(10)
        .map(|i| {
            let tilt = if turning(i) {
                0.2 * ((i - 600) as f32 / 200.0)
            } else {
                0.0
            };
            [
                tilt + noise.next(0.002),
                noise.next(0.002),
                1.0 + noise.next(0.002),
            ]
        })
        .collect();
    let still_turn_still = case(
        "still, a turn about Z, still again (accelerometer at 10 Hz)",
        &settings,
        [0.0; 3],
        10,
        accel,
        rate,
    );

    // Vibration: never still; a NaN rate passes through and restarts the wait.
    let rate: Vec<[f32; 3]> = (0..800)
        .map(|i| {
            if i == 400 {
                [f32::NAN, 0.0, 0.0]
            } else {
                [
                    offset[0] + noise.next(0.3),
                    offset[1] + noise.next(0.3),
                    offset[2] + noise.next(0.3),
                ]
            }
        })
        .collect();
    let accel: Vec<[f32; 3]> = (0..80)
        .map(|i| {
            if i == 20 {
                [f32::INFINITY, 0.0, 1.0]
            } else {
                [
                    noise.next(0.001),
                    noise.next(0.001),
                    1.0 + noise.next(0.001),
                ]
            }
        })
        .collect();
    let vibration = case(
        "vibration, a NaN rate and an infinite acceleration, from a kept offset",
        &settings,
        [0.01, 0.0, -0.02],
        10,
        accel,
        rate,
    );

    // No accelerometer, a slow steady turn below the rate threshold: the learner takes it for
    // offset (as Fusion's does); then still, where the turn's end holds the detector a while.
    let rate: Vec<[f32; 3]> = (0..1_200)
        .map(|i| {
            let turn = if i < 600 { 1.5 } else { 0.0 };
            [
                offset[0] + turn + noise.next(0.004),
                offset[1] + noise.next(0.004),
                offset[2] + noise.next(0.004),
            ]
        })
        .collect();
    let slow_turn = case(
        "no accelerometer, a slow turn below the threshold, then still",
        &StillnessSettings {
            time_constant_s: 2.0,
            still_for_s: 1.5,
            ..settings
        },
        [0.0; 3],
        0,
        Vec::new(),
        rate,
    );
    StillnessVectors {
        cases: vec![still_turn_still, vibration, slow_turn],
    }
}

#[test]
fn committed_stillness_vectors_are_current_and_reproduced() {
    let built = build();
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        let text = serde_json::to_string(&built).unwrap();
        std::fs::write(PATH, text + "\n").unwrap();
    }
    let text = std::fs::read_to_string(PATH)
        .expect("testdata/stillness-vectors.json (regenerate: GYRODRIFT_BLESS=1)");
    let file: StillnessVectors = serde_json::from_str(&text).unwrap();
    assert!(
        file == built,
        "testdata/stillness-vectors.json is stale: run GYRODRIFT_BLESS=1 cargo test -p drift-core --test stillness_vectors"
    );
    for case in &file.cases {
        let (rates, states, offset) = run(case);
        assert_eq!(rates, case.expected, "{}", case.name);
        assert_eq!(states, case.states, "{}", case.name);
        assert_eq!(offset, case.final_offset, "{}", case.name);
    }
    // The cases exercise what they are named for.
    let learned = |c: &StillnessCase| c.states.iter().filter(|s| **s & 2 != 0).count();
    let [turn, vibration, slow] = &file.cases[..] else {
        panic!("three cases")
    };
    assert_eq!(
        turn.states[..600].iter().filter(|s| **s & 2 != 0).count(),
        100,
        "learns after the 5-s wait"
    );
    assert!(
        turn.states[600..800].iter().all(|s| *s == 0),
        "no learning while turning"
    );
    assert!(
        turn.states[800..].iter().filter(|s| **s & 2 != 0).count() > 100,
        "learns again once the turn's variance has decayed and the wait is over"
    );
    assert_eq!(learned(vibration), 0, "vibration is never still");
    assert!(f32::from_bits(vibration.expected[400][0]).is_nan());
    assert!(learned(slow) > 300);
    let slow_x = f32::from_bits(slow.final_offset[0]);
    assert!(
        slow_x > 0.1,
        "a slow turn without accelerometer is taken for offset: {slow_x}"
    );
    let turn_x = f32::from_bits(turn.final_offset[0]);
    assert!(
        turn_x > 0.0 && turn_x < 0.021,
        "on its way to the offset, τ = 8 s: {turn_x}"
    );
}
