//! The test-vector cases: activations that exercise every stage, clamp, hold and fault.
//!
//! Inputs are synthesised deterministically (a tiny LCG for noise), expected outputs come from
//! running drift-core's corrector; `tests/reference.rs` checks those outputs against an independent
//! f64 restatement of the method, so the file is not merely self-consistent.

use drift_core::blob::{encode, Image};
use drift_core::{Corrector, Model, Previous, Sample};

use super::fixture;
use super::format::{Case, NamedModel, VectorFile};

/// Deterministic pseudo-noise in [−1, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// How an activation's inputs evolve.
struct Scenario {
    name: &'static str,
    description: &'static str,
    model: &'static str,
    /// Switch-on temperature per axis, °C (None: never powered on; NaN: power-on must fail).
    switch_on_celsius: Option<[f32; 3]>,
    /// Final rise after 120 s, °C, per axis.
    final_rise: [f64; 3],
    /// Sample times, ms.
    times: Vec<u32>,
    /// Per-sample input override (sample index, ms) → optional (rates, raw temperatures).
    tamper: fn(usize, u32, &mut [f32; 3], &mut [f32; 3]),
    /// Auxiliary inputs per (sample index, ms), for the extended model; None: `correct` without.
    aux: Option<fn(usize, u32) -> [f32; 4]>,
    /// What was kept of the previous activation per axis, `[ambient °C, switch-off °C]`: starts
    /// with `power_on_after` instead of `power_on`.
    previous: Option<[[f32; 2]; 3]>,
}

/// Supply voltage sagging and recovering, an accelerometer turned over half-way, and one NaN
/// supply reading (sample 40) the extension must hold through.
fn supply_and_gravity(i: usize, ms: u32) -> [f32; 4] {
    let t = ms as f32 / 1000.0;
    let supply = if i == 40 {
        f32::NAN
    } else {
        5.0 - 0.3 * (t / 30.0).sin()
    };
    let gravity = if ms < 60_000 { 1.0 } else { -1.0 };
    [supply, 0.0, 0.02, gravity]
}

fn untouched(_: usize, _: u32, _: &mut [f32; 3], _: &mut [f32; 3]) {}

fn every(step_ms: u32, until_ms: u32) -> Vec<u32> {
    let mut times: Vec<u32> = (0..=until_ms).step_by(step_ms as usize).collect();
    // Exactly on, just before and just after every reference time: the knots of stage 1.
    for &t in &fixture::REFERENCE_MS {
        if t <= until_ms {
            times.extend([t - 1, t, t + 1]);
        }
    }
    times.sort_unstable();
    times.dedup();
    times
}

fn scenarios() -> Vec<Scenario> {
    vec![
        Scenario {
            name: "modified-between-ambients",
            description: "switch-on at 33 °C (between the 30 and 40 °C tables), rise between stored curves, 2 min",
            model: "modified",
            switch_on_celsius: Some([33.0, 33.2, 32.9]),
            final_rise: [4.1, 3.3, 5.2],
            times: every(500, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-on-calibration-ambient",
            description: "switch-on exactly at a calibration ambient (30 °C): stage 2 uses one table",
            model: "modified",
            switch_on_celsius: Some([30.0, 30.0, 30.0]),
            final_rise: [2.4, 4.6, 6.0],
            times: every(1000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-ambient-below-range",
            description: "switch-on at 10 °C, below the calibrated 20–40 °C: clamped to 20 °C and flagged",
            model: "modified",
            switch_on_celsius: Some([10.0, 10.0, 10.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-ambient-above-range",
            description: "switch-on at 50 °C, above the calibrated range: clamped to 40 °C and flagged",
            model: "modified",
            switch_on_celsius: Some([50.0, 50.0, 50.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-rise-out-of-span",
            description: "X heats faster than any stored curve, Y cools (negative rise), Z inside: clamp and flag",
            model: "modified",
            switch_on_celsius: Some([25.0, 25.0, 25.0]),
            final_rise: [9.0, -1.5, 3.0],
            times: every(2000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-past-last-reference",
            description: "runs 5 min: after 120 s k is held at its last value and flagged",
            model: "modified",
            switch_on_celsius: Some([35.0, 35.0, 35.0]),
            final_rise: [3.0, 4.0, 5.0],
            times: every(3000, 300_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-temperature-faults",
            description: "X temperature NaN then +inf for a while, Y stuck for 30 samples, Z fine: hold last good drift and flag",
            model: "modified",
            switch_on_celsius: Some([31.0, 31.0, 31.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: (0..=120).map(|i| i * 250).collect(),
            tamper: |i, _, _, raw| {
                if (40..45).contains(&i) {
                    raw[0] = f32::NAN;
                }
                if (45..50).contains(&i) {
                    raw[0] = f32::INFINITY;
                }
                if (60..90).contains(&i) {
                    raw[1] = 6400.0;
                }
            },
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-rate-faults",
            description: "NaN, ±inf and saturated (±500 °/s) rates: non-finite rates pass through flagged",
            model: "modified",
            switch_on_celsius: Some([36.0, 36.0, 36.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: (0..40).map(|i| i * 100).collect(),
            tamper: |i, _, rate, _| match i {
                10 => rate[0] = f32::NAN,
                11 => rate[1] = f32::INFINITY,
                12 => rate[2] = f32::NEG_INFINITY,
                13 => *rate = [500.0, -500.0, 500.0],
                _ => {}
            },
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-not-powered-on",
            description: "samples without power_on pass through, flagged",
            model: "modified",
            switch_on_celsius: None,
            final_rise: [4.0, 4.0, 4.0],
            times: (0..10).map(|i| i * 100).collect(),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "modified-power-on-rejects-nan",
            description: "power_on with a NaN switch-on temperature (axis Y) fails; samples pass through, flagged",
            model: "modified",
            switch_on_celsius: Some([30.0, f32::NAN, 30.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: (0..10).map(|i| i * 100).collect(),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "standard-nominal",
            description: "the standard (Lagrange, degree 2) baseline over a 2-min activation at 27 °C",
            model: "standard",
            switch_on_celsius: Some([27.0, 27.5, 26.5]),
            final_rise: [4.0, 5.0, 3.0],
            times: every(2000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "standard-out-of-range",
            description: "the standard baseline heated past its fitted range (40 °C): clamped and flagged",
            model: "standard",
            switch_on_celsius: Some([37.0, 37.0, 37.0]),
            final_rise: [6.0, 6.0, 6.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "third-order-nominal",
            description: "the 3rd-order baseline over a 2-min activation at 33 °C",
            model: "third_order",
            switch_on_celsius: Some([33.0, 33.0, 33.0]),
            final_rise: [4.0, 5.0, 3.0],
            times: every(2000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "extended-with-aux",
            description: "the paper's tables plus 4 extra terms (temperature rate, supply voltage low-passed at τ = 2 s, X rise, rise²) at 33 °C with a sagging supply, a NaN supply reading (the supply term holds its filter, flagged) and 1-ms steps",
            model: "extended",
            switch_on_celsius: Some([33.0, 33.2, 32.8]),
            final_rise: [4.0, 5.0, 3.0],
            times: every(1000, 120_000),
            tamper: untouched,
            aux: Some(supply_and_gravity),
            previous: None,
        },
        Scenario {
            name: "extended-temperature-faults",
            description: "the extended model through a NaN X temperature and a stuck Y sensor: the terms read the held temperature",
            model: "extended",
            switch_on_celsius: Some([31.0, 31.0, 31.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: (0..=120).map(|i| i * 250).collect(),
            tamper: |i, _, _, raw| {
                if (40..50).contains(&i) {
                    raw[0] = f32::NAN;
                }
                if (60..90).contains(&i) {
                    raw[1] = 6400.0;
                }
            },
            aux: Some(supply_and_gravity),
            previous: None,
        },
        Scenario {
            name: "extended-without-aux",
            description: "the extended model corrected without auxiliary inputs: the supply term is 0 (no input yet), flagged on every sample; the other terms act",
            model: "extended",
            switch_on_celsius: Some([30.0, 30.0, 30.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(5000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "extended-warm-start",
            description: "the extended model switched on with power_on_after at 33 °C after a short off-time (ambient 31 °C, switched off at 36 / 35.5 °C; Z switched off at 32.5 °C, below its switch-on: the ambient rose, a cold start): the rate filters of X and Y start at the heating less the cooling the kept history implies (X: 2 °C of residual heat, 0.4 of the switch-off heat left, 0.15 − 0.0148 °C/s), Z's at the heating alone",
            model: "extended",
            switch_on_celsius: Some([33.0, 33.0, 33.0]),
            final_rise: [3.0, 2.5, 3.5],
            times: every(1000, 120_000),
            tamper: untouched,
            aux: Some(supply_and_gravity),
            previous: Some([[31.0, 36.0], [31.0, 35.5], [30.5, 32.5]]),
        },
        Scenario {
            name: "history-warm-start",
            description: "tables keyed by heating history: switched on at 33 °C after a short off-time at a 31 °C ambient (X, Y) and 30.5 °C (Z): stage 2 at the ambient, stage 3 at 2.0 / 2.2 / 2.5 °C of residual heat, between stored histories",
            model: "by_history",
            switch_on_celsius: Some([33.0, 33.2, 33.0]),
            final_rise: [3.0, 2.5, 3.5],
            times: every(1000, 150_000),
            tamper: untouched,
            aux: None,
            previous: Some([[31.0, 36.0], [31.0, 35.5], [30.5, 35.0]]),
        },
        Scenario {
            name: "history-unknown",
            description: "tables keyed by history powered on with plain power_on (nothing kept): a cold start at the switch-on temperature, flagged HISTORY_UNKNOWN",
            model: "by_history",
            switch_on_celsius: Some([27.0, 27.0, 27.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "history-ambient-changed",
            description: "tables keyed by history: X switched on above its last switch-off temperature (the ambient rose: cold start); Y with 13 °C of apparent residual heat, beyond every stored history (without a clock an ambient that rose by less than the unit cooled reads as a short off-time: the warmest history and warm start, flagged HISTORY_OUT_OF_SPAN); Z colder than its last ambient (the ambient fell: cold start at the new ambient)",
            model: "by_history",
            switch_on_celsius: Some([33.0, 33.0, 33.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: Some([[25.0, 28.0], [20.0, 40.0], [35.0, 39.0]]),
        },
        Scenario {
            name: "history-nothing-finite-kept",
            description: "tables keyed by history, power_on_after with a NaN kept ambient on Y (nothing usable kept there: cold start, flagged HISTORY_UNKNOWN on Y only)",
            model: "by_history",
            switch_on_celsius: Some([31.0, 31.0, 31.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(5000, 60_000),
            tamper: untouched,
            aux: None,
            previous: Some([[30.0, 34.0], [f32::NAN, 34.0], [30.0, 34.0]]),
        },
        Scenario {
            name: "warm-start-initial-bias",
            description: "the paper's tables (keyed by rise) with warm starts' initial bias, power_on_after: switched on at 33 °C after a short off-time, 2.0 °C of residual heat on X (on a stored warm start), 0.2 °C on Y (between a cold start and the first), 5.0 °C on Z (more than the warmest stored start left, as after an off-time shorter than the calibration's: held at the warmest, flagged HISTORY_OUT_OF_SPAN); the warm starts' initial bias is read at the kept ambient, stage 2 at the switch-on temperature as the paper's",
            model: "warm_started",
            switch_on_celsius: Some([33.0, 33.2, 33.0]),
            final_rise: [3.0, 2.5, 3.5],
            times: every(2000, 120_000),
            tamper: untouched,
            aux: None,
            previous: Some([[31.0, 36.0], [33.0, 35.5], [28.0, 35.0]]),
        },
        Scenario {
            name: "warm-start-unknown",
            description: "tables with warm starts powered on with plain power_on (nothing kept): the cold start's initial bias, flagged HISTORY_UNKNOWN",
            model: "warm_started",
            switch_on_celsius: Some([31.0, 31.0, 31.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(5000, 60_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "recommended-warm-start",
            description: "the recommended model switched on with power_on_after at 33 °C after a short off-time (ambient 31 °C: 2.0 / 2.2 / 2.0 °C of residual heat): the turn-on bias q(T_on) + slope · residual heat, the paper's drift after it",
            model: "recommended",
            switch_on_celsius: Some([33.0, 33.2, 33.0]),
            final_rise: [3.0, 2.5, 3.5],
            times: every(1000, 120_000),
            tamper: untouched,
            aux: None,
            previous: Some([[31.0, 36.0], [31.0, 35.5], [31.0, 35.0]]),
        },
        Scenario {
            name: "recommended-history-unknown",
            description: "the recommended model powered on with plain power_on (nothing kept): q(T_on) alone, flagged HISTORY_UNKNOWN",
            model: "recommended",
            switch_on_celsius: Some([36.0, 36.0, 36.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: None,
        },
        Scenario {
            name: "recommended-outside-turn-on-range",
            description: "the recommended model switched on at 18 °C (after a cool-down: ambient fell), below its turn-on polynomial's 25–45 °C and the 20–40 °C tables: q clamped at 25 °C, flagged TEMPERATURE_OUT_OF_RANGE and AMBIENT_OUT_OF_RANGE",
            model: "recommended",
            switch_on_celsius: Some([18.0, 18.0, 18.0]),
            final_rise: [4.0, 4.0, 4.0],
            times: every(4000, 120_000),
            tamper: untouched,
            aux: None,
            previous: Some([[25.0, 28.0], [25.0, 28.0], [25.0, 28.0]]),
        },
        Scenario {
            name: "modified-ignores-history",
            description: "the paper's tables (keyed by rise) powered on with power_on_after: what was kept is ignored, the outputs are power_on's",
            model: "modified",
            switch_on_celsius: Some([33.0, 33.2, 32.9]),
            final_rise: [4.1, 3.3, 5.2],
            times: every(2000, 120_000),
            tamper: untouched,
            aux: None,
            previous: Some([[31.0, 36.0], [31.0, 35.5], [30.5, 35.0]]),
        },
    ]
}

fn bits3(values: [f32; 3]) -> [u32; 3] {
    values.map(f32::to_bits)
}

fn run<M: Model>(model: &M, scenario: &Scenario, seed: u64) -> Case
where
    M::Axis: drift_core::AxisModel,
{
    let mut noise = Lcg(seed);
    let mut corrector = Corrector::new(model).unwrap();
    let switch_on_raw = scenario
        .switch_on_celsius
        .map(|c| c.map(|c| (c * 200.0).round()));
    let mut power_on_fails = false;
    if let Some(raw) = switch_on_raw {
        power_on_fails = match scenario.previous {
            Some(kept) => {
                let mut previous = kept.map(|[ambient_celsius, switch_off_celsius]| Previous {
                    ambient_celsius,
                    switch_off_celsius,
                });
                corrector.power_on_after(raw, &mut previous).is_err()
            }
            None => corrector.power_on(raw).is_err(),
        };
    }
    let base_raw = switch_on_raw
        .unwrap_or([6000.0; 3])
        .map(|r| if r.is_finite() { r } else { 6000.0 });
    let mut samples = Vec::new();
    let mut expected = Vec::new();
    let mut aux_inputs = Vec::new();
    for (i, &ms) in scenario.times.iter().enumerate() {
        let t = f64::from(ms) / 1000.0;
        let shape = (1.0 - (-t / 60.0).exp()) / (1.0 - (-2.0_f64).exp());
        let mut raw = [0.0_f32; 3];
        let mut rate = [0.0_f32; 3];
        for axis in 0..3 {
            let rise = scenario.final_rise[axis] * shape;
            // Quantised sensor with about one raw unit of noise.
            raw[axis] = (f64::from(base_raw[axis]) + 200.0 * rise + noise.next()).round() as f32;
            let bias = 0.1 * (axis as f64 - 1.0) + 0.004 * rise;
            rate[axis] = (bias + 0.002 * noise.next()) as f32;
        }
        (scenario.tamper)(i, ms, &mut rate, &mut raw);
        let sample = Sample {
            since_power_on_ms: ms,
            rate_dps: rate,
            temperature_raw: raw,
        };
        let out = match scenario.aux {
            Some(aux) => {
                let aux = aux(i, ms);
                aux_inputs.push(aux.map(f32::to_bits));
                corrector.correct_with_aux(&sample, &aux)
            }
            None => corrector.correct(&sample),
        };
        let [rx, ry, rz] = bits3(rate);
        let [tx, ty, tz] = bits3(raw);
        samples.push([ms, rx, ry, rz, tx, ty, tz]);
        let [cx, cy, cz] = bits3(out.corrected_dps);
        let [bx, by, bz] = bits3(out.bias_dps);
        let [fx, fy, fz] = out.flags.map(|f| u32::from(f.0));
        expected.push([cx, cy, cz, bx, by, bz, fx, fy, fz]);
    }
    Case {
        name: scenario.name.into(),
        description: scenario.description.into(),
        model: scenario.model.into(),
        switch_on_raw: switch_on_raw.map(bits3),
        previous: scenario
            .previous
            .map(|kept| kept.map(|pair| pair.map(f32::to_bits))),
        power_on_fails,
        samples,
        expected,
        aux: aux_inputs,
    }
}

fn named<M: Image + serde::Serialize>(name: &str, kind: &str, model: &M) -> NamedModel {
    let mut buffer = vec![0_u8; 64 * 1024];
    let len = encode(model, &mut buffer).unwrap();
    NamedModel {
        name: name.into(),
        kind: kind.into(),
        image_hex: buffer[..len].iter().map(|b| format!("{b:02x}")).collect(),
        // Through text, so the JSON holds the short decimals an f32 prints as, not widened f64s.
        tables: serde_json::from_str(&serde_json::to_string(model).unwrap()).unwrap(),
    }
}

/// Builds the whole vector file.
pub fn build() -> VectorFile {
    let modified = fixture::modified();
    let standard = fixture::standard();
    let third_order = fixture::third_order();
    let extended = fixture::extended();
    let by_history = fixture::by_history();
    let warm_started = fixture::warm_started();
    let recommended = fixture::recommended();
    let cases = scenarios()
        .iter()
        .enumerate()
        .map(|(i, scenario)| match scenario.model {
            "modified" => run(&modified, scenario, i as u64 + 1),
            "standard" => run(&standard, scenario, i as u64 + 1),
            "extended" => run(&extended, scenario, i as u64 + 1),
            "by_history" => run(&by_history, scenario, i as u64 + 1),
            "warm_started" => run(&warm_started, scenario, i as u64 + 1),
            "recommended" => run(&recommended, scenario, i as u64 + 1),
            _ => run(&third_order, scenario, i as u64 + 1),
        })
        .collect();
    VectorFile {
        format: "gyrodrift-test-vectors".into(),
        version: 1,
        description: vec![
            "Shared test vectors for every implementation of the gyrodrift corrector (Rust host, Cortex-M4 firmware, Python).".into(),
            "Each model is given as its firmware image (canonical, bit-exact) and as JSON (readable).".into(),
            "Each case: optional power_on(switch_on_raw) (power_on_after(switch_on_raw, previous) when the case has previous: per axis [ambient °C, switch-off °C]), then correct() per sample (correct_with_aux(aux[i]) when the case has aux), in order, on one fresh state.".into(),
            "samples: [since_power_on_ms, rate x,y,z (°/s), temperature_raw x,y,z]; expected: [corrected x,y,z, bias x,y,z, flags x,y,z].".into(),
            "Floats are IEEE-754 binary32 bit patterns. Expected outputs must match bit for bit; a NaN matches any NaN.".into(),
            "Regenerate with: GYRODRIFT_BLESS=1 cargo test -p drift-core --test vectors".into(),
        ],
        models: vec![
            named("modified", "modified", &modified),
            named("standard", "polynomial", &standard),
            named("third_order", "polynomial", &third_order),
            named("extended", "modified", &extended),
            named("by_history", "modified", &by_history),
            named("warm_started", "modified", &warm_started),
            named("recommended", "recommended", &recommended),
        ],
        cases,
    }
}
