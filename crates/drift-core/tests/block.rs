//! Block correction (`correct_block`) against one `correct` per sample: the same outputs and the
//! same final state, bit for bit (NaN payloads included), on the shared vectors and on random
//! activations with sensor faults, for every model and every way of cutting the samples into
//! calls.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(
    clippy::arithmetic_side_effects,
    clippy::float_cmp,
    clippy::cast_possible_truncation,
    clippy::cast_precision_loss,
    missing_docs
)]

mod common;

use drift_core::blob::decode;
use drift_core::{
    AxisModel, CorrectorState, Flags, Model, ModifiedTables, Output, PolynomialAxis,
    PolynomialTables, Previous, RecommendedTables, RelativePolynomialAxis,
    RelativePolynomialTables, Sample, Settings,
};
use proptest::prelude::*;

/// A block length for the cuts below (any length gives the same bits).
const BLOCK_SAMPLES: usize = 128;

const PATH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/vectors.json");

/// How a run is cut into `correct_block` calls: lengths, cycled.
const CUTS: [&[usize]; 6] = [
    &[usize::MAX],
    &[1],
    &[BLOCK_SAMPLES],
    &[BLOCK_SAMPLES + 1, 3],
    &[7, 200, 0, 64],
    &[2 * BLOCK_SAMPLES - 1],
];

fn bits(output: &Output) -> [u32; 9] {
    let f = |v: f32| v.to_bits();
    let [c0, c1, c2] = output.corrected_dps.map(f);
    let [b0, b1, b2] = output.bias_dps.map(f);
    let [g0, g1, g2] = output.flags.map(|g| u32::from(g.0));
    [c0, c1, c2, b0, b1, b2, g0, g1, g2]
}

/// Runs `samples` from `state` one `correct` at a time and in `correct_block` calls cut by each
/// of [`CUTS`]; asserts equal outputs and final states. Returns every flag the outputs carried.
fn check<M>(
    model: &M,
    state: CorrectorState<<M::Axis as AxisModel>::State>,
    samples: &[Sample],
    what: &str,
) -> Flags
where
    M: Model,
{
    let mut single = state;
    let mut seen = Flags::NONE;
    let expected: Vec<[u32; 9]> = samples
        .iter()
        .map(|sample| {
            let output = single.correct(model, sample);
            seen = output.flags.iter().fold(seen, |seen, &flags| seen | flags);
            bits(&output)
        })
        .collect();
    for cut in CUTS {
        let mut blocked = state;
        let mut outputs = vec![Output::default(); samples.len()];
        let (mut start, mut lengths) = (0, cut.iter().cycle());
        while start < samples.len() {
            let end = start
                .saturating_add(*lengths.next().unwrap())
                .min(samples.len());
            let done = blocked.correct_block(model, &samples[start..end], &mut outputs[start..end]);
            assert_eq!(done, end - start);
            start = end;
        }
        for (i, (output, expected)) in outputs.iter().zip(&expected).enumerate() {
            assert_eq!(&bits(output), expected, "{what}, cut {cut:?}, sample {i}");
        }
        // Compared through `Debug`, which prints each float so that it reads back to the same
        // value: a cached NaN (a missing upper curve) equals itself there.
        assert_eq!(
            format!("{blocked:?}"),
            format!("{single:?}"),
            "{what}, cut {cut:?}: final states differ"
        );
    }
    seen
}

fn unhex(hex: &str) -> Vec<u8> {
    (0..hex.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap())
        .collect()
}

#[test]
fn the_shared_vectors_give_the_same_bits_in_blocks() {
    let file: common::format::VectorFile =
        serde_json::from_str(&std::fs::read_to_string(PATH).unwrap()).unwrap();
    let image = |name: &str| {
        unhex(
            &file
                .models
                .iter()
                .find(|m| m.name == name)
                .unwrap()
                .image_hex,
        )
    };
    let modified: ModifiedTables = decode(&image("modified")).unwrap();
    let extended: ModifiedTables = decode(&image("extended")).unwrap();
    let by_history: ModifiedTables = decode(&image("by_history")).unwrap();
    let warm_started: ModifiedTables = decode(&image("warm_started")).unwrap();
    let standard: PolynomialTables = decode(&image("standard")).unwrap();
    let third_order: PolynomialTables = decode(&image("third_order")).unwrap();
    let recommended: RecommendedTables = decode(&image("recommended")).unwrap();
    for case in &file.cases {
        let samples: Vec<Sample> = case
            .samples
            .iter()
            .map(|s| Sample {
                since_power_on_ms: s[0],
                rate_dps: [s[1], s[2], s[3]].map(f32::from_bits),
                temperature_raw: [s[4], s[5], s[6]].map(f32::from_bits),
            })
            .collect();
        let switch_on = case.switch_on_raw.map(|raw| raw.map(f32::from_bits));
        macro_rules! run {
            ($model:expr) => {{
                let mut state = CorrectorState::new();
                if let Some(raw) = switch_on {
                    let _ = match case.previous {
                        Some(kept) => {
                            let mut previous = kept.map(|[ambient, off]| Previous {
                                ambient_celsius: f32::from_bits(ambient),
                                switch_off_celsius: f32::from_bits(off),
                            });
                            state.power_on_after($model, raw, &mut previous)
                        }
                        None => state.power_on($model, raw),
                    };
                }
                check($model, state, &samples, &case.name);
            }};
        }
        match case.model.as_str() {
            "modified" => run!(&modified),
            "extended" => run!(&extended),
            "by_history" => run!(&by_history),
            "warm_started" => run!(&warm_started),
            "standard" => run!(&standard),
            "third_order" => run!(&third_order),
            "recommended" => run!(&recommended),
            other => panic!("unknown model {other}"),
        }
    }
}

/// xorshift64*: deterministic, dependency-free randomness.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// Mostly ordinary values near `typical`, sometimes a fault: NaN, ±∞, an extreme finite value.
    fn reading(&mut self, typical: f32, spread: f32) -> f32 {
        match self.below(40) {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => f32::NEG_INFINITY,
            3 => f32::MAX,
            4 => -3.0e38,
            5 => -0.0,
            _ => typical + spread * (self.unit() - 0.5),
        }
    }
}

fn polynomial(random: &mut Random, settings: Settings) -> PolynomialTables {
    let axis = |random: &mut Random| {
        let low = 10.0 + 20.0 * random.unit();
        let count = 1 + random.below(8) as usize;
        // Now and then coefficients large enough to overflow: a non-finite drift (held, flagged).
        let scale = if random.below(5) == 0 { 3.0e38 } else { 0.05 };
        PolynomialAxis {
            range_celsius: [low, low + 5.0 + 30.0 * random.unit()],
            coefficients: (0..count).map(|_| scale * (random.unit() - 0.5)).collect(),
        }
    };
    PolynomialTables::try_new(settings, [axis(random), axis(random), axis(random)]).unwrap()
}

/// A random activation: readings that drift, repeat (stuck runs longer than the threshold), fault
/// and recover; time that mostly advances.
fn activation(random: &mut Random, len: usize) -> Vec<Sample> {
    let mut raw = [6000.0_f32; 3].map(|r| r + 1000.0 * random.unit());
    let mut ms = 0_u32;
    (0..len)
        .map(|_| {
            ms = ms.wrapping_add(random.below(3_000) as u32);
            for raw in &mut raw {
                // Long runs of the same reading, so the stuck counter trips.
                if random.below(8) == 0 {
                    *raw += 40.0 * (random.unit() - 0.5);
                }
            }
            let temperature_raw = raw.map(|r| {
                if random.below(30) == 0 {
                    random.reading(r, 1e3)
                } else {
                    r
                }
            });
            Sample {
                since_power_on_ms: ms,
                rate_dps: [0; 3].map(|_| random.reading(0.0, 2.0)),
                temperature_raw,
            }
        })
        .collect()
}

#[test]
fn random_polynomial_activations_with_faults_give_the_same_bits_in_blocks() {
    let mut random = Random(0x9E37_79B9_7F4A_7C15);
    let mut seen = Flags::NONE;
    for run in 0..300 {
        let settings = Settings {
            stuck_after_samples: [0, 1, 5, 20, 2000][random.below(5) as usize],
            ambient_margin_celsius: random.unit(),
            raw_at_zero_celsius: 100.0 * random.unit(),
            raw_per_celsius: 150.0 + 100.0 * random.unit(),
            ..Settings::default()
        };
        let model = polynomial(&mut random, settings);
        let len = 1 + random.below(400) as usize;
        let samples = activation(&mut random, len);
        let mut state = CorrectorState::new();
        // Some runs are never powered on (pass-through, flagged); some switch on at a fault-free
        // reading far outside the range.
        if run % 10 != 0 {
            let switch_on = [0; 3].map(|_| 4000.0 + 6000.0 * random.unit());
            state.power_on(&model, switch_on).unwrap();
        }
        seen |= check(&model, state, &samples, &format!("random run {run}"));
    }
    // The runs reach every path the block shares with the per-sample one.
    for (flag, name) in Flags::ALL {
        let expected = flag != Flags::AMBIENT_OUT_OF_RANGE
            && flag != Flags::RISE_OUT_OF_SPAN
            && flag != Flags::PAST_LAST_REFERENCE
            && flag != Flags::EXTENSION_INPUT_INVALID
            && flag != Flags::HISTORY_UNKNOWN
            && flag != Flags::HISTORY_OUT_OF_SPAN;
        assert_eq!(seen.contains(flag), expected, "{name}");
    }
}

#[test]
fn random_modified_activations_give_the_same_bits_in_blocks() {
    // The paper's model goes sample by sample inside `correct_block`; still the same bits.
    let tables = common::fixture::modified();
    let mut random = Random(0x0123_4567_89AB_CDEF);
    for run in 0..20 {
        let samples = activation(&mut random, 300);
        let mut state = CorrectorState::new();
        state
            .power_on(
                &tables,
                samples[0]
                    .temperature_raw
                    .map(|r| if r.is_finite() { r } else { 6600.0 }),
            )
            .unwrap();
        check(&tables, state, &samples, &format!("modified run {run}"));
    }
}

/// A temperature reading or a rate: mostly ordinary, sometimes a fault or an extreme value.
fn reading(low: f32, high: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        30 => low..high,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
        1 => Just(f32::MAX),
        1 => Just(-3.0e38_f32),
        1 => Just(-0.0_f32),
    ]
}

/// A polynomial over a random range; now and then with coefficients that overflow (a non-finite or
/// implausible drift, held and flagged).
fn polynomial_axis() -> impl Strategy<Value = PolynomialAxis> {
    let coefficient = prop_oneof![4 => -0.5f32..0.5, 1 => -3.0e38f32..3.0e38];
    (
        -20.0f32..60.0,
        1.0f32..40.0,
        prop::collection::vec(coefficient, 1..=8),
    )
        .prop_map(|(low, span, coefficients)| PolynomialAxis {
            range_celsius: [low, low + span],
            coefficients: coefficients.into_iter().collect(),
        })
}

/// Samples in runs of the same temperature readings (so the stuck counter trips and resets),
/// faults and extreme readings among them.
fn samples() -> impl Strategy<Value = Vec<Sample>> {
    let run = (
        1usize..60,
        prop::array::uniform3(reading(-4_000.0, 16_000.0)),
        0u32..3_000,
    );
    (prop::collection::vec(run, 0..25), reading(-2.0, 2.0)).prop_map(|(runs, rate)| {
        let mut ms = 0_u32;
        runs.into_iter()
            .flat_map(|(length, temperature_raw, step)| {
                (0..length).map(move |i| (temperature_raw, step, i))
            })
            .map(|(temperature_raw, step, i)| {
                ms = ms.wrapping_add(step);
                Sample {
                    since_power_on_ms: ms,
                    // A fault (the generated rate) now and then, else an ordinary varying rate.
                    rate_dps: [0, 1, 2].map(|a| {
                        if (i + a) % 17 == 0 {
                            rate
                        } else {
                            0.01 * (i + a) as f32
                        }
                    }),
                    temperature_raw,
                }
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(if cfg!(miri) { 4 } else { 128 }))]

    /// Both polynomial forms give the same bits and the same final state in blocks as sample by
    /// sample, for any coefficients, stuck threshold and margin, through stuck runs, NaN and
    /// infinite readings and rates, and readings far outside the range.
    #[test]
    fn polynomial_blocks_agree_with_samples(
        axes in prop::array::uniform3(polynomial_axis()),
        turn_on in prop::array::uniform3(polynomial_axis()),
        stuck_after in prop::sample::select(vec![0_u16, 1, 2, 5, 20, 2000]),
        margin in 0.0f32..2.0,
        switch_on in prop::array::uniform3(-4_000.0f32..16_000.0),
        powered_on in prop::bool::weighted(0.9),
        samples in samples(),
    ) {
        let settings = Settings {
            stuck_after_samples: stuck_after,
            ambient_margin_celsius: margin,
            ..Settings::default()
        };
        let absolute = PolynomialTables { settings, axes: axes.clone() };
        let [x, y, z] = axes;
        let [qx, qy, qz] = turn_on;
        let relative = RelativePolynomialTables {
            settings,
            axes: [(x, qx), (y, qy), (z, qz)]
                .map(|(drift, turn_on)| RelativePolynomialAxis { drift, turn_on }),
        };
        let mut state = CorrectorState::new();
        if powered_on {
            state.power_on(&absolute, switch_on).unwrap();
        }
        check(&absolute, state, &samples, "absolute");
        let mut state = CorrectorState::new();
        if powered_on {
            state.power_on(&relative, switch_on).unwrap();
        }
        check(&relative, state, &samples, "relative");
    }
}
