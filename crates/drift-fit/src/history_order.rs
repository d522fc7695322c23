//! Does the rise still tell heating histories apart? The paper's stage 3 finds an activation's
//! heating history by its temperature rise alone: "rise is lower for each later activation", so a
//! unit that switched on warmer (a shorter off-time) is expected to rise less at every moment. When
//! that fails — curves cross — two histories with different drift/rise ratios share one rise, and
//! stage 3 reads `k` from the wrong one on every activation, including those that repeat the
//! calibration exactly.
//!
//! What breaks it, measured (experiments/README.md, *Rise nonlinearity and a third calibration ambient*): heating power that grows
//! with the unit's own temperature. A warm start then heats faster than a cold one for the first
//! tens of seconds, and the curves of the 2- and 5-min series rise above the independent curve.
//!
//! The check runs on the averaged calibration curves, so the fit can say so before anyone trusts
//! the tables; what it costs in drift is measured by the stage-3 oracle (`experiments/examples/stage3_oracle.rs`).

use crate::curves::{CurveKey, SetPointCurves};

/// A warmer start must beat a colder one by at least this much (°C) to be compared: curves whose
/// switch-on temperatures are closer than this (the 10-min series against the independent curve:
/// ~0.1 °C) may rise in either order without anything being wrong.
pub const WARMER_BY_CELSIUS: f64 = 0.2;

/// How far (°C) a warmer start's rise may exceed a colder start's before it counts as crossing:
/// drift-core's default `rise_margin_celsius` (ten raw sensor steps), far above the scatter of a
/// curve averaged over repeats.
pub const CROSSING_MARGIN_CELSIUS: f64 = 0.05;

/// A curve by its name (`2min#4`) in serialised reports.
fn curve_name<S: serde::Serializer>(key: &CurveKey, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_str(&key.name())
}

/// The worst crossing of one set point and axis.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Crossing {
    /// Chamber set point, °C.
    pub set_point_celsius: f64,
    /// Axis (0 = X).
    pub axis: usize,
    /// The curve that switched on warmer and yet rose more.
    #[serde(serialize_with = "curve_name")]
    pub warmer: CurveKey,
    /// The curve it rose above.
    #[serde(serialize_with = "curve_name")]
    pub colder: CurveKey,
    /// How much warmer the first switched on, °C.
    pub switched_on_warmer_by_celsius: f64,
    /// When the crossing is largest, ms after switch-on.
    pub at_ms: u32,
    /// By how much the warmer start's rise exceeds the colder start's there, °C.
    pub rise_excess_celsius: f64,
    /// How many (warmer, colder) pairs of this set point and axis cross at all.
    pub crossing_pairs: usize,
    /// How many pairs were compared.
    pub compared_pairs: usize,
}

impl Crossing {
    /// One line for a fit's notes.
    pub fn note(&self) -> String {
        format!(
            "{} °C, {}: stage 3 cannot tell heating histories apart by rise — {} of {} curve pairs cross; worst: {} switched on {:.2} °C warmer than {} and rises {:.3} °C more at {:.1} s (a warmer start should rise less; heating power that grows with temperature does this, see docs/closed-loop.md)",
            self.set_point_celsius,
            ["X", "Y", "Z"][self.axis],
            self.crossing_pairs,
            self.compared_pairs,
            self.warmer.name(),
            self.switched_on_warmer_by_celsius,
            self.colder.name(),
            self.rise_excess_celsius,
            f64::from(self.at_ms) / 1000.0,
        )
    }
}

/// The worst crossing per set point and axis, looking from grid index `first` on (the first
/// reference time: before it the rise is a few sensor steps). Empty when the rise orders every
/// pair of histories as the paper assumes.
pub fn crossings(set_points: &[SetPointCurves], first: usize) -> Vec<Crossing> {
    let mut found = Vec::new();
    for sp in set_points {
        for axis in 0..3 {
            let mut worst: Option<Crossing> = None;
            let (mut crossing_pairs, mut compared_pairs) = (0, 0);
            for warmer in &sp.curves {
                for colder in &sp.curves {
                    let warmer_by = warmer.switch_on_celsius[axis] - colder.switch_on_celsius[axis];
                    // A NaN switch-on temperature compares as not warmer.
                    if warmer_by.is_nan() || warmer_by < WARMER_BY_CELSIUS {
                        continue;
                    }
                    compared_pairs += 1;
                    let len = warmer.len().min(colder.len());
                    let excess = (first..len)
                        .map(|i| {
                            (
                                i,
                                warmer.rise_celsius[axis][i] - colder.rise_celsius[axis][i],
                            )
                        })
                        .filter(|(_, e)| e.is_finite())
                        .max_by(|a, b| a.1.total_cmp(&b.1));
                    let Some((at, excess)) = excess else { continue };
                    if excess <= CROSSING_MARGIN_CELSIUS {
                        continue;
                    }
                    crossing_pairs += 1;
                    if worst
                        .as_ref()
                        .is_none_or(|w| excess > w.rise_excess_celsius)
                    {
                        worst = Some(Crossing {
                            set_point_celsius: sp.set_point_celsius,
                            axis,
                            warmer: warmer.key,
                            colder: colder.key,
                            switched_on_warmer_by_celsius: warmer_by,
                            at_ms: u32::try_from(at)
                                .unwrap_or(u32::MAX)
                                .saturating_mul(sp.grid_ms),
                            rise_excess_celsius: excess,
                            crossing_pairs: 0,
                            compared_pairs: 0,
                        });
                    }
                }
            }
            if let Some(mut w) = worst {
                w.crossing_pairs = crossing_pairs;
                w.compared_pairs = compared_pairs;
                found.push(w);
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curves::AveragedCurve;

    /// A curve whose rise is `gain · (1 − e^(−t/40 s))` on a 1-s grid, switched on at `on` °C.
    fn curve(key: CurveKey, on: f64, gain: [f64; 2]) -> AveragedCurve {
        let rise = |t: f64| gain[0] * t / 10.0 + gain[1] * (1.0 - (-t / 40.0).exp());
        let r: Vec<f64> = (0..120).map(|i| rise(f64::from(i))).collect();
        AveragedCurve {
            key,
            members: 2,
            drift_dps: [vec![0.0; 120], vec![0.0; 120], vec![0.0; 120]],
            rise_celsius: [r.clone(), r.clone(), r],
            switch_on_celsius: [on; 3],
            initial_bias_dps: [0.0; 3],
        }
    }

    fn set_point(curves: Vec<AveragedCurve>) -> SetPointCurves {
        SetPointCurves {
            set_point_celsius: 30.0,
            grid_ms: 1000,
            ambient_celsius: [30.0; 3],
            initial_bias_dps: [0.0; 3],
            curves,
        }
    }

    const WARM: CurveKey = CurveKey::After {
        interval_s: 120,
        activation: 2,
    };

    #[test]
    fn a_warmer_start_that_rises_less_is_what_the_paper_expects() {
        let sp = set_point(vec![
            curve(CurveKey::Independent, 30.0, [0.0, 5.0]),
            curve(WARM, 31.5, [0.0, 4.0]),
        ]);
        assert!(crossings(&[sp], 2).is_empty());
    }

    #[test]
    fn a_warmer_start_that_rises_more_early_on_is_a_crossing() {
        // Faster early (first term), lower at the end: the nonlinearity's shape.
        let sp = set_point(vec![
            curve(CurveKey::Independent, 30.0, [0.0, 5.0]),
            curve(WARM, 31.5, [0.3, 3.0]),
        ]);
        let found = crossings(&[sp], 2);
        assert_eq!(found.len(), 3, "one per axis: {found:?}");
        let x = &found[0];
        assert_eq!(
            (x.warmer, x.colder, x.axis),
            (WARM, CurveKey::Independent, 0)
        );
        assert_eq!((x.crossing_pairs, x.compared_pairs), (1, 1));
        assert!((x.switched_on_warmer_by_celsius - 1.5).abs() < 1e-12);
        // The largest excess of 0.03 t + 3(1 − e^(−t/40)) − 5(1 − e^(−t/40)) on the 1-s grid.
        let best = (2..120)
            .map(|i| {
                let t = f64::from(i);
                0.03 * t - 2.0 * (1.0 - (-t / 40.0).exp())
            })
            .fold(f64::MIN, f64::max);
        assert!((x.rise_excess_celsius - best).abs() < 1e-9, "{x:?}");
        assert!(
            x.note()
                .contains("2min#2 switched on 1.50 °C warmer than independent"),
            "{}",
            x.note()
        );
    }

    #[test]
    fn starts_closer_than_the_threshold_are_not_compared() {
        let sp = set_point(vec![
            curve(CurveKey::Independent, 30.0, [0.0, 5.0]),
            curve(WARM, 30.1, [0.0, 6.0]),
        ]);
        assert!(crossings(&[sp], 2).is_empty());
    }

    #[test]
    fn an_excess_within_the_margin_is_not_a_crossing() {
        let mut warm = curve(WARM, 31.0, [0.0, 5.0]);
        for r in &mut warm.rise_celsius {
            r.iter_mut()
                .for_each(|v| *v += CROSSING_MARGIN_CELSIUS * 0.9);
        }
        let sp = set_point(vec![curve(CurveKey::Independent, 30.0, [0.0, 5.0]), warm]);
        assert!(crossings(&[sp], 2).is_empty());
    }
}
