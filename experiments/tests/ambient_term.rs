//! The diagnosis's ambient term is drift-core's switch-on at a measured ambient: the same numbers
//! as reading the paper's tables with every temperature shifted so that the switch-on reads the
//! air (time since switch-on and the rise unchanged), on simulated warm restarts whose switch-on
//! stands above the chamber.

use drift_diagnose::diagnose::ambient_term;
use drift_evaluate::evaluate::{correct_segment_after, switch_on_raw};
use drift_fit::analyse::analyse;
use drift_fit::fit::fit_unit;
use drift_fit::settings::FitSettings;
use drift_recording::{read_campaign_dir, Segment, TEMPERATURE_MISSING_RAW};
use drift_sim::{simulate_campaign, Campaign, Protocol};

/// A small protocol campaign at +30 and +40 °C, with 1-min off-times (residual heat at switch-on).
fn campaign() -> Vec<Segment> {
    let dir = tempfile::tempdir().unwrap();
    let campaign = Campaign {
        units: 1,
        sample_rate_hz: 100,
        set_points_celsius: vec![30.0, 40.0],
        protocol: Some(Protocol {
            intervals_min: vec![1.0, 30.0],
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

/// The term as it was computed by shifting the temperatures by whole raw units so that the
/// switch-on reads `air`.
fn by_shifting(
    paper: &drift_core::ModifiedTables,
    segment: &Segment,
    switch_on: [f32; 3],
    air: f64,
) -> [Vec<f32>; 3] {
    let core = paper.settings;
    let shift: [f64; 3] = switch_on.map(|raw| {
        ((f64::from(core.celsius(raw)) - air) * f64::from(core.raw_per_celsius)).round()
    });
    let mut at_air = segment.clone();
    for (raw, s) in at_air.temperature_raw.iter_mut().zip(shift) {
        for r in raw.iter_mut().filter(|r| **r != TEMPERATURE_MISSING_RAW) {
            *r = (f64::from(*r) - s).clamp(f64::from(i16::MIN + 1), f64::from(i16::MAX)) as i16;
        }
    }
    let on_at_air: [f32; 3] = std::array::from_fn(|a| switch_on[a] - shift[a] as f32);
    let (paper_rates, _) = correct_segment_after(paper, segment, switch_on, None);
    let (air_rates, _) = correct_segment_after(paper, &at_air, on_at_air, None);
    std::array::from_fn(|a| {
        paper_rates[a]
            .iter()
            .zip(&air_rates[a])
            .map(|(p, q)| p - q)
            .collect()
    })
}

#[test]
fn the_ambient_term_is_the_switch_on_at_the_logged_air() {
    let settings = FitSettings::default();
    let segments = campaign();
    let analysed: Vec<_> = segments
        .iter()
        .map(|s| analyse(s, &settings).unwrap())
        .collect();
    let paper = fit_unit(&analysed, &settings).unwrap().modified;
    let core = paper.settings;
    // The calibration ambients are the cold starts' switch-on temperatures, which stand above
    // the chamber's set point; an air below the lowest or above the highest is clamped both ways.
    let ambients: Vec<f64> = paper.axes[0]
        .ambients
        .iter()
        .map(|a| f64::from(a.ambient_celsius))
        .collect();
    let inside = |air: f64| air > ambients[0] + 0.1 && air < ambients[ambients.len() - 1] - 0.1;
    let mut compared = 0;
    for segment in &segments {
        let on = switch_on_raw(segment, &settings);
        let on_x = f64::from(core.celsius(on[0]));
        // An air 0.8 °C below the switch-on, reached by the shift in whole raw units on X, so that
        // the two ways read the tables at the same ambient there (to f32 rounding); Y and Z are
        // shifted to within half a raw unit.
        let units = (0.8 * f64::from(core.raw_per_celsius)).round();
        let air = (on_x - units / f64::from(core.raw_per_celsius)) as f32;
        if !inside(f64::from(air)) {
            continue;
        }
        let mut logged = segment.clone();
        logged
            .aux
            .get_mut("chamber_set_point")
            .expect("a bench recording logs its set point")
            .values[0] = air;
        let term = ambient_term(&paper, &logged, on).unwrap();
        let shifted = by_shifting(&paper, &logged, on, f64::from(air));
        let largest = term[0].iter().fold(0f32, |m, v| m.max(v.abs()));
        assert!(largest > 1e-4, "the term says something: {largest}");
        for axis in 0..3 {
            let tolerance = if axis == 0 { 1e-6 } else { 1e-4 };
            let worst = term[axis]
                .iter()
                .zip(&shifted[axis])
                .fold(0f32, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                worst <= tolerance,
                "axis {axis}: {worst} °/s apart (largest term {largest})"
            );
        }
        compared += 1;
    }
    assert!(compared >= 2, "warm restarts compared: {compared}");
}
