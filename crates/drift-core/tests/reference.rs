//! An independent f64 restatement of the method, written from the docs (linear scans, no shared
//! code with the crate), checked against the shared test vectors. This is what makes the vectors
//! evidence of correctness rather than a snapshot of whatever the corrector does.
#![allow(clippy::print_stderr)]
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
    missing_docs
)]

mod common;

use common::format::VectorFile;
use serde_json::Value;

/// Largest difference allowed between the f32 corrector and this f64 reference, °/s. The f32
/// rounding of the bias (~0.1 °/s, ulp 7.5e-9) and of `k · rise` stays below it (worst seen 1.4e-8); a wrong
/// interpolation stage is far above it (curves differ by ~1e-4 °/s).
const TOLERANCE_DPS: f64 = 1e-7;
/// The extended model's temperature rate is a difference of two f32 temperatures near 30 °C
/// (spacing 2e-6 °C) scaled by 1000/τ: its f32 rounding alone reaches a few 1e-7 °/s.
const EXTENDED_TOLERANCE_DPS: f64 = 1e-6;

const AMBIENT_OUT_OF_RANGE: u32 = 1;
const RISE_OUT_OF_SPAN: u32 = 2;
const PAST_LAST_REFERENCE: u32 = 4;
const TEMPERATURE_OUT_OF_RANGE: u32 = 8;
const TEMPERATURE_INVALID: u32 = 16;
const TEMPERATURE_STUCK: u32 = 32;
const RATE_INVALID: u32 = 64;
const NOT_POWERED_ON: u32 = 128;
const EXTENSION_INPUT_INVALID: u32 = 512;
const HISTORY_UNKNOWN: u32 = 1024;
const HISTORY_OUT_OF_SPAN: u32 = 2048;

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn list(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(f).collect()
}

fn lerp(lo: f64, hi: f64, w: f64) -> f64 {
    lo + (hi - lo) * w
}

/// Linear-scan bracket: (lo, hi, weight) with clamping; `None` when outside on that side.
fn bracket(knots: &[f64], x: f64) -> (usize, usize, f64, i8) {
    let n = knots.len();
    if x < knots[0] {
        return (0, 0, 0.0, -1);
    }
    if x > knots[n - 1] {
        return (n - 1, n - 1, 0.0, 1);
    }
    for j in 0..n - 1 {
        if knots[j] <= x && x < knots[j + 1] {
            return (j, j + 1, (x - knots[j]) / (knots[j + 1] - knots[j]), 0);
        }
    }
    (n - 1, n - 1, 0.0, 0)
}

struct Settings {
    per: f64,
    zero: f64,
    ambient_margin: f64,
    rise_margin: f64,
    stuck: u32,
}

fn settings(tables: &Value) -> Settings {
    let s = &tables["settings"];
    Settings {
        per: f(&s["raw_per_celsius"]),
        zero: f(&s["raw_at_zero_celsius"]),
        ambient_margin: f(&s["ambient_margin_celsius"]),
        rise_margin: f(&s["rise_margin_celsius"]),
        stuck: s["stuck_after_samples"].as_u64().unwrap() as u32,
    }
}

enum Axis<'a> {
    Modified(&'a Value),
    Polynomial(&'a Value),
}

/// Per-axis reference state after power-on.
struct State {
    on_raw: f64,
    initial: f64,
    drift: f64,
    last_raw: Option<f64>,
    repeats: u32,
    activation: u32,
    ambient: (usize, usize, f64),
    /// Tables keyed by heating history: the bracketing histories and the blend, fixed at switch-on.
    history: Option<(usize, usize, f64)>,
    poly_on: f64,
}

fn poly(axis: &Value, celsius: f64, margin: f64) -> (f64, bool) {
    let range = list(&axis["range_celsius"]);
    let coefficients = list(&axis["coefficients"]);
    let t = celsius.max(range[0]).min(range[1]);
    let mid = (range[0] + range[1]) / 2.0;
    let half = (range[1] - range[0]) / 2.0;
    let x = (t - mid) / half;
    let value: f64 = coefficients
        .iter()
        .enumerate()
        .map(|(i, c)| c * x.powi(i as i32))
        .sum();
    (
        value,
        celsius < range[0] - margin || celsius > range[1] + margin,
    )
}

/// The recommended model's turn-on bias and its flags (docs/method.md): `q` continued along its
/// tangent beyond its range, plus the residual heat's share, the heat held at the most calibrated.
fn turn_on(turn_on: &Value, s: &Settings, raw: f64, previous: Option<(f64, f64)>) -> (f64, u32) {
    let celsius = (raw - s.zero) / s.per;
    let polynomial = &turn_on["polynomial"];
    let range = list(&polynomial["range_celsius"]);
    let coefficients = list(&polynomial["coefficients"]);
    let (mid, half) = ((range[0] + range[1]) / 2.0, (range[1] - range[0]) / 2.0);
    let x = (celsius - mid) / half;
    let edge = x.clamp(-1.0, 1.0);
    let at = |x: f64| -> f64 {
        coefficients
            .iter()
            .enumerate()
            .map(|(i, c)| c * x.powi(i as i32))
            .sum()
    };
    let derivative: f64 = coefficients
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, c)| i as f64 * c * edge.powi(i as i32 - 1))
        .sum();
    let q = at(edge) + derivative * (x - edge);
    let mut flags = 0;
    if celsius < range[0] - s.ambient_margin || celsius > range[1] + s.ambient_margin {
        flags |= TEMPERATURE_OUT_OF_RANGE;
    }
    let slope = f(&turn_on["dps_per_residual_celsius"]);
    let most = f(&turn_on["most_residual_heat_celsius"]);
    let (_, heat, known) = estimate(celsius, previous);
    if !known && slope != 0.0 {
        flags |= HISTORY_UNKNOWN;
    }
    if known && heat > most {
        flags |= HISTORY_OUT_OF_SPAN;
    }
    let warm = if known && heat > 0.0 {
        slope * heat.min(most)
    } else {
        0.0
    };
    (q + warm, flags)
}

/// The docs' estimate of (ambient, residual heat, known) at switch-on from what was kept of the
/// previous activation, `(ambient, switch-off temperature)`.
fn estimate(celsius: f64, previous: Option<(f64, f64)>) -> (f64, f64, bool) {
    match previous {
        Some((ambient, off)) if ambient.is_finite() && off.is_finite() => {
            if celsius >= off {
                (celsius, 0.0, true)
            } else {
                let ambient = ambient.min(celsius);
                (ambient, celsius - ambient, true)
            }
        }
        _ => (celsius, 0.0, false),
    }
}

/// Where `x` falls among `knots`, with the side flag of `bracket` turned into "beyond the margin".
fn locate(knots: &[f64], x: f64, margin: f64) -> (usize, usize, f64, bool) {
    let (lo, hi, w, side) = bracket(knots, x);
    let outside = match side {
        -1 => x < knots[0] - margin,
        1 => x > knots[knots.len() - 1] + margin,
        _ => false,
    };
    (lo, hi, w, outside)
}

fn power_on(axis: &Axis, s: &Settings, raw: f64, previous: Option<(f64, f64)>) -> State {
    let celsius = (raw - s.zero) / s.per;
    let mut state = State {
        on_raw: raw,
        initial: 0.0,
        drift: 0.0,
        last_raw: Some(raw),
        repeats: 0,
        activation: 0,
        ambient: (0, 0, 0.0),
        history: None,
        poly_on: 0.0,
    };
    match axis {
        Axis::Modified(table) => {
            let ambients = table["ambients"].as_array().unwrap();
            let temps: Vec<f64> = ambients.iter().map(|a| f(&a["ambient_celsius"])).collect();
            let labels = |a: usize| list(&ambients[a]["residual_heat_celsius"]);
            let keyed_by_history = !labels(0).is_empty();
            let warm_starts = |a: usize| -> Vec<(f64, f64)> {
                ambients[a]["warm_starts"]
                    .as_array()
                    .map_or(Vec::new(), |w| {
                        w.iter()
                            .map(|p| (f(&p["residual_heat_celsius"]), f(&p["bias_offset_dps"])))
                            .collect()
                    })
            };
            let warm_started = (0..ambients.len()).any(|a| !warm_starts(a).is_empty());
            let (mut at, mut heat) = (celsius, 0.0);
            if keyed_by_history || warm_started {
                let (ambient, residual, known) = estimate(celsius, previous);
                if !known {
                    state.activation |= HISTORY_UNKNOWN;
                }
                (at, heat) = (ambient, residual);
            }
            let history_at = |at: f64, heat: f64| {
                let (lo, hi, w, _) = locate(&temps, at, s.ambient_margin);
                let blended: Vec<f64> = labels(lo)
                    .iter()
                    .zip(labels(hi))
                    .map(|(l, u)| lerp(*l, u, w))
                    .collect();
                locate(&blended, heat, s.rise_margin)
            };
            if keyed_by_history {
                // Beyond the stored histories: the nearest (clamp), flagged.
                let (lo, hi, w, outside) = history_at(at, heat);
                if outside {
                    state.activation |= HISTORY_OUT_OF_SPAN;
                }
                state.history = Some((lo, hi, w));
            }
            // A table keyed by history was built against the ambient; the paper's stage 2 looks at
            // the switch-on temperature.
            let stage2_at = if keyed_by_history { at } else { celsius };
            let (lo, hi, w, outside) = locate(&temps, stage2_at, s.ambient_margin);
            if outside {
                state.activation |= AMBIENT_OUT_OF_RANGE;
            }
            state.ambient = (lo, hi, w);
            // A warm start's initial bias: the ambient's cold start plus an offset that is zero
            // cold, linear from there through the stored warm starts, held beyond the warmest
            // (flagged beyond it by more than the rise margin).
            // Otherwise the paper's: the cold start's at the switch-on temperature.
            let offset = |a: usize| {
                let points = warm_starts(a);
                if heat <= 0.0 || points.is_empty() {
                    return 0.0;
                }
                let mut previous = (0.0, 0.0);
                for &(h, offset) in &points {
                    if heat <= h {
                        return lerp(previous.1, offset, (heat - previous.0) / (h - previous.0));
                    }
                    previous = (h, offset);
                }
                previous.1
            };
            let warmest = |a: usize| warm_starts(a).last().map_or(0.0, |w| w.0);
            let (mut lo, mut hi, mut w, _) = locate(&temps, at, s.ambient_margin);
            let warm = warm_started && heat > 0.0;
            // Beyond the warmest stored start: held there (`offset`), flagged.
            if warm && heat > lerp(warmest(lo), warmest(hi), w) + s.rise_margin {
                state.activation |= HISTORY_OUT_OF_SPAN;
            }
            if !warm {
                (lo, hi, w, _) = locate(&temps, celsius, s.ambient_margin);
            }
            let total =
                |a: usize| f(&ambients[a]["initial_bias_dps"]) + if warm { offset(a) } else { 0.0 };
            state.initial = lerp(total(lo), total(hi), w);
        }
        Axis::Polynomial(p) => {
            let (value, outside) = poly(p, celsius, s.ambient_margin);
            state.initial = value;
            state.poly_on = value;
            if outside {
                state.activation |= TEMPERATURE_OUT_OF_RANGE;
            }
        }
    }
    state
}

/// `k` at time `ms` and `rise`: each curve is read at the time (stage 1), blended between the two
/// bracketing ambients with weight `w` (stage 2), then the blended curves bracketing `rise` are
/// interpolated (stage 3). Returns (k, rise beyond the span by more than the margin).
fn k_at(
    (lower, upper, w): (&Value, &Value, f64),
    refs: &[f64],
    ms: f64,
    rise: f64,
    margin: f64,
    history: Option<(usize, usize, f64)>,
) -> (f64, bool) {
    let at_time = |values: &[f64], is_rise: bool| -> f64 {
        if ms < refs[0] {
            if is_rise {
                values[0] * ms / refs[0]
            } else {
                values[0]
            }
        } else {
            let (lo, hi, weight, _) = bracket(refs, ms);
            lerp(values[lo], values[hi], weight)
        }
    };
    let blended = |field: &str, is_rise: bool| -> Vec<f64> {
        let lower = lower["curves"].as_array().unwrap();
        let upper = upper["curves"].as_array().unwrap();
        lower
            .iter()
            .zip(upper)
            .map(|(l, u)| {
                let values = |curve: &Value| -> Vec<f64> {
                    let points = curve["points"].as_array().unwrap();
                    points.iter().map(|point| f(&point[field])).collect()
                };
                lerp(
                    at_time(&values(l), is_rise),
                    at_time(&values(u), is_rise),
                    w,
                )
            })
            .collect()
    };
    let rises = blended("rise_celsius", true);
    let ks = blended("k_dps_per_celsius", false);
    if let Some((lo, hi, w)) = history {
        // Keyed by history: the rise does not choose the curves.
        return (lerp(ks[lo], ks[hi], w), false);
    }
    let n = rises.len();
    if rise < rises[0] {
        return (ks[0], rise < rises[0] - margin);
    }
    if rise >= rises[n - 1] {
        return (ks[n - 1], rise > rises[n - 1] + margin);
    }
    let c = (0..n - 1)
        .find(|&c| rises[c] <= rise && rise < rises[c + 1])
        .unwrap();
    (
        lerp(
            ks[c],
            ks[c + 1],
            (rise - rises[c]) / (rises[c + 1] - rises[c]),
        ),
        false,
    )
}

/// One sample on one axis: (corrected, bias, flags).
fn correct(
    axis: &Axis,
    s: &Settings,
    st: &mut State,
    ms: u32,
    rate: f32,
    raw: f32,
) -> (f64, f64, u32) {
    let mut flags = st.activation;
    if !rate.is_finite() {
        flags |= RATE_INVALID;
    }
    if !raw.is_finite() {
        flags |= TEMPERATURE_INVALID;
    } else {
        let raw = f64::from(raw);
        if st.last_raw == Some(raw) {
            st.repeats += 1;
        } else {
            st.repeats = 0;
            st.last_raw = Some(raw);
        }
        if s.stuck != 0 && st.repeats >= s.stuck {
            flags |= TEMPERATURE_STUCK;
        } else {
            let rise = (raw - st.on_raw) / s.per;
            let celsius = (raw - s.zero) / s.per;
            match axis {
                Axis::Modified(table) => {
                    let refs: Vec<f64> = table["reference_ms"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(f)
                        .collect();
                    let ambients = table["ambients"].as_array().unwrap();
                    let ms = f64::from(ms);
                    if ms > refs[refs.len() - 1] {
                        flags |= PAST_LAST_REFERENCE;
                    }
                    let (lo, hi, w) = st.ambient;
                    let (k, out) = k_at(
                        (&ambients[lo], &ambients[hi], w),
                        &refs,
                        ms,
                        rise,
                        s.rise_margin,
                        st.history,
                    );
                    if out {
                        flags |= RISE_OUT_OF_SPAN;
                    }
                    st.drift = k * rise;
                }
                Axis::Polynomial(p) => {
                    let (value, outside) = poly(p, celsius, s.ambient_margin);
                    if outside {
                        flags |= TEMPERATURE_OUT_OF_RANGE;
                    }
                    st.drift = value - st.poly_on;
                }
            }
        }
    }
    let bias = st.initial + st.drift;
    (f64::from(rate) - bias, bias, flags)
}

#[test]
fn vectors_agree_with_an_independent_f64_reference() {
    if std::env::var_os("GYRODRIFT_BLESS").is_some() {
        return; // the vectors are being rewritten; check them on the next run
    }
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../testdata/vectors.json");
    let file: VectorFile = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut worst = 0.0_f64;
    let mut checked = 0;
    for case in &file.cases {
        let named = file.models.iter().find(|m| m.name == case.model).unwrap();
        let tables = &named.tables;
        let s = settings(tables);
        let axes: Vec<Axis> = (0..3)
            .map(|i| match named.kind.as_str() {
                "modified" => Axis::Modified(&tables["axes"][i]),
                // Per sample the paper's table; the turn-on bias replaced below.
                "recommended" => Axis::Modified(&tables["axes"][i]["table"]),
                _ => Axis::Polynomial(&tables["axes"][i]),
            })
            .collect();
        let switch_on = case.switch_on_raw.map(|raw| raw.map(f32::from_bits));
        let powered = matches!(switch_on, Some(raw) if raw.iter().all(|r| r.is_finite()));
        assert_eq!(
            case.power_on_fails,
            switch_on.is_some() && !powered,
            "{}",
            case.name
        );
        let mut states: Vec<State> = match switch_on {
            Some(raw) if powered => (0..3)
                .map(|i| {
                    let previous = case.previous.map(|kept| {
                        let [ambient, off] = kept[i].map(|b| f64::from(f32::from_bits(b)));
                        (ambient, off)
                    });
                    let mut state = power_on(&axes[i], &s, f64::from(raw[i]), previous);
                    if named.kind == "recommended" {
                        let (bias, flags) = turn_on(
                            &tables["axes"][i]["turn_on"],
                            &s,
                            f64::from(raw[i]),
                            previous,
                        );
                        state.initial = bias;
                        state.activation |= flags;
                    }
                    state
                })
                .collect(),
            _ => Vec::new(),
        };
        let kept: [Option<(f64, f64)>; 3] = std::array::from_fn(|i| {
            case.previous.map(|kept| {
                let [ambient, off] = kept[i].map(|b| f64::from(f32::from_bits(b)));
                (ambient, off)
            })
        });
        let mut extension = switch_on.filter(|_| powered).map(|raw| {
            Extension::new(
                &tables["extension"],
                raw.map(|r| (f64::from(r) - s.zero) / s.per),
                kept,
            )
        });
        for (i, (input, expected)) in case.samples.iter().zip(&case.expected).enumerate() {
            let mut outputs = [(0.0, 0.0, 0); 3];
            for axis in 0..3 {
                let rate = f32::from_bits(input[1 + axis]);
                let raw = f32::from_bits(input[4 + axis]);
                outputs[axis] = if powered {
                    correct(&axes[axis], &s, &mut states[axis], input[0], rate, raw)
                } else {
                    (
                        f64::from(rate),
                        0.0,
                        NOT_POWERED_ON | if rate.is_finite() { 0 } else { RATE_INVALID },
                    )
                };
            }
            if let Some(extension) = extension.as_mut().filter(|e| !e.terms.is_empty()) {
                let aux = case
                    .aux
                    .get(i)
                    .map_or([f64::NAN; 4], |a| a.map(|b| f64::from(f32::from_bits(b))));
                let held: Vec<f64> = states
                    .iter()
                    .zip(switch_on.unwrap())
                    .map(|(st, on)| st.last_raw.unwrap_or(f64::from(on)))
                    .collect();
                let celsius: Vec<f64> = held.iter().map(|r| (r - s.zero) / s.per).collect();
                let rise: Vec<f64> = held
                    .iter()
                    .zip(&states)
                    .map(|(r, st)| (r - st.on_raw) / s.per)
                    .collect();
                let (extra, missing) = extension.step(f64::from(input[0]), &celsius, &rise, &aux);
                for (output, extra) in outputs.iter_mut().zip(extra) {
                    if missing {
                        output.2 |= EXTENSION_INPUT_INVALID;
                    }
                    output.0 -= extra;
                    output.1 += extra;
                }
            }
            for axis in 0..3 {
                let (corrected, bias, flags) = outputs[axis];
                let rate = f32::from_bits(input[1 + axis]);
                let got_corrected = f64::from(f32::from_bits(expected[axis]));
                let got_bias = f64::from(f32::from_bits(expected[3 + axis]));
                let at = format!("{} sample {i} axis {axis}", case.name);
                assert_eq!(expected[6 + axis], flags, "flags at {at}");
                if corrected.is_finite() {
                    // The corrected rate is itself an f32: allow its own rounding at large rates.
                    let rounding = f64::from(f32::EPSILON) * f64::from(rate).abs();
                    let error =
                        ((got_corrected - corrected).abs() - rounding).max((got_bias - bias).abs());
                    let tolerance = if extension.as_ref().is_some_and(|e| !e.terms.is_empty()) {
                        EXTENDED_TOLERANCE_DPS
                    } else {
                        TOLERANCE_DPS
                    };
                    assert!(
                        error <= tolerance,
                        "{at}: f32 {got_corrected} vs f64 {corrected} (bias {got_bias} vs {bias})"
                    );
                    worst = worst.max(error);
                } else {
                    assert!(
                        !got_corrected.is_finite() && got_corrected.is_nan() == corrected.is_nan(),
                        "{at}"
                    );
                }
                checked += 1;
            }
        }
    }
    eprintln!("{checked} axis-samples checked; worst |f32 − f64| = {worst:.3e} °/s (tolerance {TOLERANCE_DPS:e})");
    assert!(checked > 3000);
}

/// One extra term from the JSON tables: kind, parameters by name, centre and coefficient per axis.
type JsonTerm = (String, serde_json::Map<String, Value>, [f64; 3], [f64; 3]);

/// The extended model's extra terms, restated in f64 from the JSON tables.
struct Extension {
    terms: Vec<JsonTerm>,
    filtered: [f64; 3],
    /// Per term, the low-passed auxiliary input (None before the first finite one).
    aux_filtered: Vec<Option<f64>>,
    last_ms: f64,
}

impl Extension {
    /// The state at switch-on; the rate filter starts at the cooling rate the kept `previous`
    /// activation implies (at rest without one).
    fn new(json: &Value, switch_on_celsius: [f64; 3], previous: [Option<(f64, f64)>; 3]) -> Self {
        let triple = |v: &Value| [f(&v[0]), f(&v[1]), f(&v[2])];
        let terms: Vec<_> = json["terms"]
            .as_array()
            .map(|terms| {
                terms
                    .iter()
                    .map(|t| {
                        let (kind, parameters) = match &t["term"] {
                            Value::String(name) => (name.clone(), serde_json::Map::new()),
                            Value::Object(map) => {
                                let (name, inner) = map.iter().next().unwrap();
                                (name.clone(), inner.as_object().unwrap().clone())
                            }
                            other => panic!("term {other}"),
                        };
                        (
                            kind,
                            parameters,
                            triple(&t["centre"]),
                            triple(&t["coefficient"]),
                        )
                    })
                    .collect()
            })
            .unwrap_or_default();
        let tau_s = terms
            .iter()
            .find(|t| t.0 == "TemperatureRate")
            .map_or(0.0, |t| f(&t.1["time_constant_ms"]) / 1000.0);
        let filtered = std::array::from_fn(|axis| {
            let celsius = switch_on_celsius[axis];
            let start = &json["switch_on_rate"][axis];
            let (heating, a, b) = if start.is_null() {
                (0.0, 0.0, 0.0)
            } else {
                (
                    f(&start["heating_celsius_per_s"]),
                    f(&start["cooling_per_second"]),
                    f(&start["cooling_per_second_per_remaining"]),
                )
            };
            let (ambient, heat, _) = estimate(celsius, previous[axis]);
            let remaining = match previous[axis] {
                Some((_, off)) if heat > 0.0 => (heat / (off - ambient)).clamp(0.0, 1.0),
                _ => 0.0,
            };
            // Started as if it had followed the rate at switch-on: heating − heat · (a + b·remaining).
            let rate = heating - heat * (a + b * remaining);
            celsius - rate * tau_s
        });
        Self {
            aux_filtered: vec![None; terms.len()],
            terms,
            filtered,
            last_ms: 0.0,
        }
    }

    /// Per axis, the terms' contribution, and whether an auxiliary input a term reads is not
    /// finite (that term then holds its filtered value; 0 before the first finite input).
    fn step(&mut self, ms: f64, celsius: &[f64], rise: &[f64], aux: &[f64; 4]) -> (Vec<f64>, bool) {
        let elapsed = (ms - self.last_ms).max(0.0);
        let previous_ms = self.last_ms;
        self.last_ms = ms;
        let tau = self
            .terms
            .iter()
            .find(|t| t.0 == "TemperatureRate")
            .map(|t| f(&t.1["time_constant_ms"]));
        let mut rate = [f64::NAN; 3];
        if let Some(tau) = tau {
            for axis in 0..3 {
                // The textbook form (the core keeps the lag instead, for f32 precision).
                let next = self.filtered[axis]
                    + elapsed / (tau + elapsed) * (celsius[axis] - self.filtered[axis]);
                rate[axis] = (celsius[axis] - next) * 1000.0 / tau;
                self.filtered[axis] = next;
            }
        }
        let mut missing = false;
        let mut aux_value = vec![None; self.terms.len()];
        for (t, (kind, parameters, ..)) in self.terms.iter().enumerate() {
            if kind != "Aux" {
                continue;
            }
            let input = aux[f(&parameters["input"]) as usize];
            // The time constant grows with the time since switch-on until it reaches the term's.
            let tau = f(&parameters["time_constant_ms"]).min(previous_ms);
            let held = &mut self.aux_filtered[t];
            if input.is_finite() {
                // Textbook first-order low-pass (backward Euler), starting at the first input.
                *held = Some(match *held {
                    Some(previous) if tau > 0.0 => {
                        previous + elapsed / (tau + elapsed) * (input - previous)
                    }
                    _ => input,
                });
            } else {
                missing = true;
            }
            aux_value[t] = *held;
        }
        let sums = (0..3)
            .map(|axis| {
                let mut sum = 0.0;
                for (t, (kind, parameters, centre, coefficient)) in self.terms.iter().enumerate() {
                    let value = match kind.as_str() {
                        "TemperatureRate" => rate[axis],
                        "Aux" => aux_value[t].unwrap_or(centre[axis]),
                        "AxisRise" => rise[f(&parameters["axis"]) as usize],
                        "RiseSquared" => rise[axis] * rise[axis],
                        other => panic!("unknown term {other}"),
                    };
                    sum += coefficient[axis] * (value - centre[axis]);
                }
                sum
            })
            .collect();
        (sums, missing)
    }
}
