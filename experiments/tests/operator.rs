//! The paper's own operator: at the drift fit's reference times the paper's model is linear in the
//! rates, so for a true bias `g + c·x` it leaves exactly `c·(x − L x)` beside what it leaves of
//! `g`, where `x − L x` is what the absorber (the tables fitted to `x` at those reference times)
//! leaves of `x`. The closed loop scores candidates and fits terms on `x − L x`; this is the
//! identity that makes those numbers mean what they claim.

use drift_core::Previous;
use drift_diagnose::absorb::Absorber;
use drift_diagnose::keying::Keying;
use drift_evaluate::evaluate::switch_on_raw;
use drift_fit::analyse::analyse;
use drift_fit::fit::{fit_unit, fit_unit_at, reference_indices};
use drift_fit::settings::FitSettings;
use drift_recording::{read_campaign_dir, Segment};
use drift_sim::{simulate_campaign, Campaign, Protocol};

/// A small protocol campaign at +30 and +40 °C: every activation is calibration.
fn calibration() -> Vec<Segment> {
    let dir = tempfile::tempdir().unwrap();
    let campaign = Campaign {
        units: 1,
        sample_rate_hz: 100,
        set_points_celsius: vec![30.0, 40.0],
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 5.0, 30.0],
            activations: 3,
            activation_s: 60.0,
            repeats: 1,
            ..Protocol::default()
        }),
        field: None,
        ..Campaign::default()
    };
    simulate_campaign(&campaign, dir.path(), |_| {}).unwrap();
    read_campaign_dir(dir.path())
        .unwrap()
        .into_iter()
        .flat_map(|r| r.segments)
        .collect()
}

/// A quantity per sample and axis: `value(rise °C, seconds since switch-on, phase)`, where the
/// phase differs from one activation to the next.
fn per_sample(
    segment: &Segment,
    settings: &FitSettings,
    value: impl Fn(f64, f64, f64) -> f64,
) -> [Vec<f32>; 3] {
    let on = switch_on_raw(segment, settings);
    let phase = f64::from(segment.labels.activation) + 0.3 * f64::from(segment.labels.series);
    std::array::from_fn(|a| {
        segment.temperature_raw[a]
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                let s = i as f64 / f64::from(segment.sample_rate_hz);
                let rise = (f64::from(t) - f64::from(on[a])) / 200.0;
                value(rise, s, phase) as f32
            })
            .collect()
    })
}

/// A candidate that is no function of the tables' inputs alone: a slow wobble per activation
/// times the rise, with an offset that differs from one activation to the next.
fn candidate(segment: &Segment, settings: &FitSettings) -> [Vec<f32>; 3] {
    per_sample(segment, settings, |rise, s, phase| {
        rise * (0.05 * s + phase).sin() + 0.2 * phase.cos()
    })
}

/// The paper's residual of `segments` with tables fitted on them (at `references`, or chosen).
fn residuals(
    segments: &[Segment],
    settings: &FitSettings,
    references: Option<&[Vec<usize>; 3]>,
) -> (Vec<[Vec<f32>; 3]>, [Vec<usize>; 3]) {
    let analysed: Vec<_> = segments
        .iter()
        .map(|s| analyse(s, settings).unwrap())
        .collect();
    let fitted = match references {
        Some(r) => fit_unit_at(&analysed, settings, Some(r)).unwrap(),
        None => fit_unit(&analysed, settings).unwrap(),
    };
    let refs: Vec<&Segment> = segments.iter().collect();
    let keying = Keying::new([false; 3], &refs, &vec![Previous::COOLED; refs.len()]);
    let out = segments
        .iter()
        .map(|s| {
            keying
                .correct(&fitted.modified, s, switch_on_raw(s, settings))
                .0
        })
        .collect();
    (out, reference_indices(&fitted.modified, settings))
}

/// Against the identity for the candidate `x` and coefficient `c`: the largest gap between what
/// the tables leave of `g + c·x` less what they leave of `g` and `c·(x − L x)` with the reference
/// times kept, the largest `c·(x − L x)`, and the gap with the reference times chosen afresh.
fn identity_gaps(
    x: impl Fn(&Segment, &FitSettings) -> [Vec<f32>; 3] + Sync,
    c: f32,
) -> (f64, f64, f64) {
    let settings = FitSettings::default();
    let g = calibration();
    let with_x: Vec<Segment> = g
        .iter()
        .map(|s| {
            let x = x(s, &settings);
            let mut t = s.clone();
            for (rates, x) in t.rate_dps.iter_mut().zip(&x) {
                for (r, x) in rates.iter_mut().zip(x) {
                    *r += c * x;
                }
            }
            t
        })
        .collect();
    let (of_g, references) = residuals(&g, &settings, None);
    let refs: Vec<&Segment> = g.iter().collect();
    let keying = Keying::new([false; 3], &refs, &vec![Previous::COOLED; refs.len()]);
    let absorber = Absorber::fit(
        &refs,
        |s| Some(x(s, &settings)),
        &settings,
        &keying,
        &references,
    )
    .unwrap()
    .unwrap();
    let gap = |of_gx: &[[Vec<f32>; 3]]| -> (f64, f64) {
        let (mut worst, mut size) = (0.0f64, 0.0f64);
        for ((s, before), after) in g.iter().zip(&of_g).zip(of_gx) {
            let left = absorber.left_over(s, x(s, &settings), switch_on_raw(s, &settings), &keying);
            for a in 0..3 {
                for i in 0..before[a].len() {
                    let expected = f64::from(c) * f64::from(left[a][i]);
                    let got = f64::from(after[a][i]) - f64::from(before[a][i]);
                    worst = worst.max((got - expected).abs());
                    size = size.max(expected.abs());
                }
            }
        }
        (worst, size)
    };
    let (same, size) = gap(&residuals(&with_x, &settings, Some(&references)).0);
    let (afresh, _) = gap(&residuals(&with_x, &settings, None).0);
    (same, size, afresh)
}

#[test]
fn the_tables_leave_of_g_plus_cx_what_they_leave_of_g_plus_c_times_x_less_lx() {
    let (same, size, afresh) = identity_gaps(candidate, 0.004);
    // At the drift's reference times: the identity, to the f32 corrector's rounding of rates
    // of up to a few °/s.
    assert!(size > 1e-3, "the candidate must leave something: {size}");
    assert!(same < 2e-5, "gap {same:e} on a term of size {size:e}");
    // Reference times chosen afresh for g + c·x break it: the test can fail.
    assert!(afresh > 50.0 * same.max(1e-7), "{afresh:e} vs {same:e}");
}

/// A quantity in a unit of its own, far from the °/s a gyro's tables hold: an air pressure near
/// 1000 hPa, wobbling by a few hPa, times the rise (the extension's channel × rise term, which
/// firmware computes from the channel as logged). Its absorber is fitted all the same — the
/// tables fitted to it directly would need `k` near 1000 (°/s)/°C — and still mirrors the paper's
/// operator.
#[test]
fn a_quantity_near_a_thousand_units_times_the_rise_is_absorbed_as_the_tables_would() {
    let pressure_times_rise = |segment: &Segment, settings: &FitSettings| -> [Vec<f32>; 3] {
        per_sample(segment, settings, |rise, s, phase| {
            let hpa = 1000.0 + 3.0 * (0.05 * s + phase).sin() + 2.0 * phase.cos();
            hpa * rise
        })
    };
    // 2·10⁻⁴ (°/s)/(hPa·°C): about 2 °/s of drift at a rise of 10 °C, nearly all of it the
    // tables' to absorb (the pressure's mean times the rise).
    let (same, size, _) = identity_gaps(pressure_times_rise, 2e-4);
    assert!(size > 1e-3, "the candidate must leave something: {size}");
    assert!(same < 2e-5, "gap {same:e} on a term of size {size:e}");
}

/// A quantity beyond the 10⁴ °/s the corrector believes of a bias: the campaign's clock, in
/// seconds, two days in. The absorber's corrector would hold such a bias as implausible.
#[test]
fn a_quantity_beyond_the_correctors_plausible_bias_is_absorbed_as_the_tables_would() {
    let clock = |segment: &Segment, _: &FitSettings| -> [Vec<f32>; 3] {
        let start = segment.power_on_ns as f64 / 1e9 + 2e5;
        std::array::from_fn(|_| {
            (0..segment.len())
                .map(|i| (start + i as f64 / f64::from(segment.sample_rate_hz)) as f32)
                .collect()
        })
    };
    let (same, size, _) = identity_gaps(clock, 1e-5);
    assert!(size > 1e-3, "the candidate must leave something: {size}");
    assert!(same < 2e-5, "gap {same:e} on a term of size {size:e}");
}
