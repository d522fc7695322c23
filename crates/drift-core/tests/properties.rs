//! Property tests of the three interpolation stages on random valid tables: the interpolation
//! reproduces the table at its knots, stays between neighbouring table values, and is continuous
//! across knots.
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

use drift_core::{
    AmbientCurves, AmbientPosition, AxisModel, AxisTable, Curve, CurvePoint, Flags,
    ModifiedAxisState, Settings, SwitchOn,
};
use proptest::prelude::*;

type Table = AxisTable<6, 3, 5>;

/// Smallest gap between neighbouring curves' rises, °C, and between reference times, ms.
const RISE_GAP: f32 = 0.2;
const TIME_GAP_MS: u32 = 10_000;

fn table() -> impl Strategy<Value = Table> {
    (2usize..=6, 1usize..=3, 1usize..=5).prop_flat_map(|(refs, ambients, curves)| {
        (
            prop::collection::vec(0u32..20_000, refs),
            prop::collection::vec(1u32..40, ambients),
            prop::collection::vec(
                prop::collection::vec((0.0f32..1.0, -0.01f32..0.01), refs * curves),
                ambients,
            ),
            prop::collection::vec(-0.5f32..0.5, ambients),
        )
            .prop_map(move |(time_steps, ambient_steps, points, biases)| {
                let mut table = Table::default();
                let mut t = 0;
                for step in time_steps {
                    t += TIME_GAP_MS + step;
                    table.reference_ms.push(t).unwrap();
                }
                // Ambients on a 0.5 °C grid, so 200 raw units per °C hit them exactly.
                let mut ambient = -10.0;
                for ((step, points), bias) in ambient_steps.into_iter().zip(points).zip(biases) {
                    ambient += step as f32 * 0.5;
                    let mut at = AmbientCurves {
                        ambient_celsius: ambient,
                        initial_bias_dps: bias,
                        curves: heapless::Vec::new(),
                        residual_heat_celsius: heapless::Vec::new(),
                        warm_starts: heapless::Vec::new(),
                    };
                    // Ordered by rise at every reference time: curve c sits at least RISE_GAP above c − 1.
                    let mut rise: Vec<f32> = (0..refs).map(|j| j as f32 * 0.5).collect();
                    for c in 0..curves {
                        let mut curve = Curve::default();
                        for (j, rise) in rise.iter_mut().enumerate() {
                            let (spread, k) = points[c * refs + j];
                            if c > 0 {
                                *rise += RISE_GAP + spread;
                            }
                            curve
                                .points
                                .push(CurvePoint {
                                    rise_celsius: *rise,
                                    k_dps_per_celsius: k,
                                })
                                .unwrap();
                        }
                        at.curves.push(curve).unwrap();
                    }
                    table.ambients.push(at).unwrap();
                }
                table
            })
    })
}

fn settings() -> Settings {
    Settings::default()
}

/// A start at a calibration ambient with `heat` °C of residual heat, the history known.
fn warm_start(ambient_celsius: f32, heat: f32) -> SwitchOn {
    SwitchOn {
        switch_on_celsius: ambient_celsius + heat,
        ambient_celsius,
        residual_heat_celsius: heat,
        remaining: 0.5, // the tables do not read it
        known: true,
    }
}

fn position(table: &Table, celsius: f32) -> AmbientPosition {
    AmbientPosition::locate(&table.ambients, celsius, 0.5, |a| a.ambient_celsius)
}

/// `k` from a fresh state (no hints, empty cache), checked to be the same bits from states whose
/// hints point elsewhere and from a state warmed up on other samples of the same activation: the
/// hints and the bracket cache may only save work.
fn k(table: &Table, celsius: f32, ms: u32, rise: f32) -> f32 {
    let fresh = ModifiedAxisState::new(&position(table, celsius));
    let fresh_k = table
        .correlation(&settings(), &mut fresh.clone(), ms, rise)
        .0;
    for hint in [1, 4, 255] {
        let mut hinted = fresh.with_hints(hint, hint);
        let hinted_k = table.correlation(&settings(), &mut hinted, ms, rise).0;
        assert_eq!(
            hinted_k.to_bits(),
            fresh_k.to_bits(),
            "hint {hint} changed the result"
        );
    }
    let mut warm = fresh;
    for (other_ms, other_rise) in [
        (ms / 2, rise * 0.5),
        (ms.saturating_add(1), rise + 0.3),
        (ms, rise * 1.5 + 0.1),
    ] {
        table.correlation(&settings(), &mut warm, other_ms, other_rise);
    }
    let warm_k = table.correlation(&settings(), &mut warm, ms, rise).0;
    assert_eq!(
        warm_k.to_bits(),
        fresh_k.to_bits(),
        "a warm cache changed the result"
    );
    fresh_k
}

proptest! {
    // Miri runs a handful of cases (each is ~10⁴× slower there); natively all 512.
    #![proptest_config(ProptestConfig::with_cases(if cfg!(miri) { 4 } else { 512 }))]

    #[test]
    fn table_is_valid(table in table()) {
        prop_assert!(table.validate(drift_core::Location::axis(0)).is_ok());
    }

    /// At a calibration ambient, a reference time and a stored curve's rise, `k` is the stored value
    /// exactly.
    #[test]
    fn reproduces_table_values_at_knots(table in table(), a in 0usize..3, c in 0usize..5, j in 0usize..6) {
        let a = a % table.ambients.len();
        let j = j % table.reference_ms.len();
        let ambient = &table.ambients[a];
        let c = c % ambient.curves.len();
        let curve = &ambient.curves[c];
        let got = k(&table, ambient.ambient_celsius, table.reference_ms[j], curve.points[j].rise_celsius);
        prop_assert_eq!(got, curve.points[j].k_dps_per_celsius);
    }

    /// Anywhere inside the envelope, `k` lies between the smallest and largest stored `k` of the
    /// bracketing ambients and reference times.
    #[test]
    fn stays_between_neighbouring_values(table in table(), ambient_u in 0.0f32..1.0, time_u in 0.0f32..1.0, rise_u in 0.0f32..1.0) {
        let first = table.ambients.first().unwrap().ambient_celsius;
        let last = table.ambients.last().unwrap().ambient_celsius;
        let celsius = first + (last - first) * ambient_u;
        let t0 = table.reference_ms[0];
        let t1 = *table.reference_ms.last().unwrap();
        let ms = t0 + ((t1 - t0) as f32 * time_u) as u32;
        let j = table.reference_ms.iter().rposition(|&t| t <= ms).unwrap();
        let j1 = (j + 1).min(table.reference_ms.len() - 1);
        let p = position(&table, celsius);
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        let mut rise_lo = f32::INFINITY;
        let mut rise_hi = f32::NEG_INFINITY;
        for a in [p.lo, p.hi] {
            for curve in &table.ambients[usize::from(a)].curves {
                for jj in [j, j1] {
                    lo = lo.min(curve.points[jj].k_dps_per_celsius);
                    hi = hi.max(curve.points[jj].k_dps_per_celsius);
                    rise_lo = rise_lo.min(curve.points[jj].rise_celsius);
                    rise_hi = rise_hi.max(curve.points[jj].rise_celsius);
                }
            }
        }
        let rise = rise_lo + (rise_hi - rise_lo) * rise_u;
        let got = k(&table, celsius, ms, rise);
        let slack = 1e-6 * (hi - lo).abs().max(1e-3);
        prop_assert!(got >= lo - slack && got <= hi + slack, "k {} outside [{}, {}]", got, lo, hi);
    }

    /// Across each curve's rise (stage 3) `k` has no jump: its change over ±δ is bounded by the
    /// steepest slope between neighbouring curves.
    #[test]
    fn continuous_across_curve_rises(table in table(), a in 0usize..3, c in 0usize..5, time_u in 0.0f32..1.0) {
        let a = a % table.ambients.len();
        let ambient = &table.ambients[a];
        let t0 = table.reference_ms[0];
        let t1 = *table.reference_ms.last().unwrap();
        let ms = t0 + ((t1 - t0) as f32 * time_u) as u32;
        let j = table.reference_ms.iter().rposition(|&t| t <= ms).unwrap();
        let j1 = (j + 1).min(table.reference_ms.len() - 1);
        let span = (table.reference_ms[j1] - table.reference_ms[j]).max(1) as f32;
        let w = (ms - table.reference_ms[j]) as f32 / span;
        let at = |curve: &drift_core::Curve<6>, rise: bool| {
            let v = |jj: usize| if rise { curve.points[jj].rise_celsius } else { curve.points[jj].k_dps_per_celsius };
            v(j) + (v(j1) - v(j)) * w
        };
        let c = c % ambient.curves.len();
        let rise = at(&ambient.curves[c], true);
        let mut slope = 0.0f32;
        for pair in ambient.curves.windows(2) {
            let dk = (at(&pair[1], false) - at(&pair[0], false)).abs();
            let dr = at(&pair[1], true) - at(&pair[0], true);
            slope = slope.max(dk / dr);
        }
        let delta = 1e-3;
        let below = k(&table, ambient.ambient_celsius, ms, rise - delta);
        let above = k(&table, ambient.ambient_celsius, ms, rise + delta);
        prop_assert!((above - below).abs() <= 2.0 * delta * slope * 1.01 + 1e-6, "jump {} at rise {}", above - below, rise);
    }

    /// Across each reference time (stage 1) `k` has no jump: one millisecond either side moves it by
    /// no more than the table's steepest rates of change allow.
    #[test]
    fn continuous_across_reference_times(table in table(), a in 0usize..3, j in 1usize..6, rise_u in 0.0f32..1.0) {
        let a = a % table.ambients.len();
        let ambient = &table.ambients[a];
        let j = j % table.reference_ms.len();
        let t = table.reference_ms[j];
        let top = ambient.curves.last().unwrap().points[j].rise_celsius;
        let rise = top * rise_u;
        let dt = 1.0 / TIME_GAP_MS as f32; // per ms, the steepest a segment can be, per unit change
        let k_range = 0.02;
        let rise_range = 0.5 + 4.0 * (RISE_GAP + 1.0);
        // dk/dt ≤ 3·(k change rate) + 2·|Δk|·2·(rise change rate)/gap, from k = k_lo + w (k_hi − k_lo).
        let bound_per_ms = 3.0 * k_range * dt + 2.0 * k_range * 2.0 * rise_range * dt / RISE_GAP;
        let here = k(&table, ambient.ambient_celsius, t, rise);
        for neighbour in [t - 1, t + 1] {
            let there = k(&table, ambient.ambient_celsius, neighbour, rise);
            prop_assert!((there - here).abs() <= bound_per_ms + 1e-6, "jump {} at t {}", there - here, t);
        }
    }

    /// Keyed by history: at a calibration ambient, a stored history's residual heat and a
    /// reference time, `k` is that history's stored value exactly, whatever the rise (the rise
    /// does not choose the curve); between histories it lies between their values; any residual
    /// heat, finite or not, gives a finite `k` and no panic.
    #[test]
    fn keyed_by_history_reads_the_history_not_the_rise(
        table in table(),
        a in 0usize..3,
        c in 0usize..5,
        j in 0usize..6,
        rises in (-2.0f32..10.0, -2.0f32..10.0),
        between_u in 0.0f32..1.0,
        wild in prop_oneof![Just(f32::NAN), Just(f32::INFINITY), -5.0f32..50.0],
    ) {
        let mut table = table;
        for ambient in &mut table.ambients {
            let count = ambient.curves.len();
            ambient.residual_heat_celsius = (0..count).map(|c| 0.4 * c as f32).collect();
        }
        prop_assert!(table.validate(drift_core::Location::axis(0)).is_ok());
        let a = a % table.ambients.len();
        let j = j % table.reference_ms.len();
        let ambient = &table.ambients[a];
        let c = c % ambient.curves.len();
        let start = |heat: f32| {
            let mut state = ModifiedAxisState::default();
            let switch_on = warm_start(ambient.ambient_celsius, heat);
            let (_, flags) = table.power_on_after(&settings(), &switch_on, &mut state);
            (state, flags)
        };
        let ms = table.reference_ms[j];
        let (state, flags) = start(ambient.residual_heat_celsius[c]);
        prop_assert!(!flags.intersects(Flags::HISTORY_OUT_OF_SPAN | Flags::HISTORY_UNKNOWN));
        let stored = ambient.curves[c].points[j].k_dps_per_celsius;
        for rise in [rises.0, rises.1] {
            let got = table.correlation(&settings(), &mut state.clone(), ms, rise);
            prop_assert_eq!(got.0, stored);
            prop_assert!(!got.1.contains(Flags::RISE_OUT_OF_SPAN));
        }
        if c + 1 < ambient.curves.len() {
            let heat = 0.4 * (c as f32 + between_u);
            let (state, _) = start(heat);
            let got = table.correlation(&settings(), &mut state.clone(), ms, rises.0).0;
            let (lo, hi) = (stored, ambient.curves[c + 1].points[j].k_dps_per_celsius);
            prop_assert!(got >= lo.min(hi) - 1e-7 && got <= lo.max(hi) + 1e-7, "{got} not in {lo}..{hi}");
        }
        let (state, _) = start(wild);
        let got = table.correlation(&settings(), &mut state.clone(), ms, rises.0).0;
        prop_assert!(got.is_finite());
    }

    /// Warm starts: at a calibration ambient, a stored warm start's residual heat gives that
    /// ambient's cold initial bias plus the warm start's offset; between two stored warm starts the offset lies
    /// between theirs; beyond the warmest, the warmest's, flagged; a cold start has none; any
    /// residual heat, finite or not, gives a finite initial bias and no panic — whether stage 3 is
    /// keyed by rise or by history (beyond every stored history too).
    #[test]
    fn warm_starts_offset_the_initial_bias_by_residual_heat(
        table in table(),
        a in 0usize..3,
        offsets in prop::collection::vec(-0.02f32..0.02, 1..5),
        w in 0usize..5,
        between_u in 0.0f32..1.0,
        by_history in any::<bool>(),
        wild in prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY), -5.0f32..50.0],
    ) {
        let mut table = table;
        for ambient in &mut table.ambients {
            ambient.warm_starts = offsets
                .iter()
                .enumerate()
                .map(|(i, &offset)| drift_core::WarmStart {
                    residual_heat_celsius: 0.5 * (i + 1) as f32,
                    bias_offset_dps: offset,
                })
                .collect();
            if by_history {
                let count = ambient.curves.len();
                ambient.residual_heat_celsius = (0..count).map(|c| 0.4 * c as f32).collect();
            }
        }
        prop_assert!(table.validate(drift_core::Location::axis(0)).is_ok());
        let a = a % table.ambients.len();
        let ambient = &table.ambients[a];
        let started = |heat: f32| {
            let mut state = ModifiedAxisState::default();
            let switch_on = warm_start(ambient.ambient_celsius, heat);
            table.power_on_after(&settings(), &switch_on, &mut state)
        };
        let bias = |heat: f32| started(heat).0;
        let cold = ambient.initial_bias_dps;
        prop_assert_eq!(bias(0.0), cold);
        let w = w % offsets.len();
        let stored = ambient.warm_starts[w];
        prop_assert_eq!(bias(stored.residual_heat_celsius), cold + stored.bias_offset_dps);
        if w + 1 < offsets.len() {
            let got = bias(stored.residual_heat_celsius + 0.5 * between_u) - cold;
            let (lo, hi) = (stored.bias_offset_dps, offsets[w + 1]);
            prop_assert!(got >= lo.min(hi) - 1e-6 && got <= lo.max(hi) + 1e-6, "{got} not in {lo}..{hi}");
        }
        // More heat than the warmest stored start left (an off-time shorter than the
        // calibration's): held at the warmest, flagged.
        let warmest = ambient.warm_starts[offsets.len() - 1];
        let (beyond, flags) = started(warmest.residual_heat_celsius + 1.0);
        prop_assert_eq!(beyond, cold + warmest.bias_offset_dps);
        prop_assert!(flags.contains(Flags::HISTORY_OUT_OF_SPAN));
        prop_assert!(bias(wild).is_finite());
    }
}
