//! What the paper's tables already account for of a quantity.
//!
//! The tables are a lookup over (time since switch-on, ambient, rise under the calibration
//! protocol's heating histories): any effect that is a fixed function of those on the calibration
//! activations is absorbed when the tables are fitted. To know how much of a candidate quantity
//! `c` the tables absorb, the tables are fitted to `c` itself, as if it were the rate, on the same
//! calibration activations and by the same pipeline; on any other activation, `c` less what those
//! tables predict of it is the part of `c` the paper's model cannot represent. Because the fit is
//! (for given reference times) linear in the rates, the paper's model fitted to `rate − β·c` is the
//! paper's model fitted to `rate` less `β` times the tables fitted to `c`: the left-over part is
//! exactly what a term `β·c` adds to the paper's model, which is what the diagnosis must score and
//! what the extension's coefficients must be fitted on.
//!
//! The same linearity lets the tables be fitted to `c / s` and their left-over scaled back by `s`.
//! The tables and the corrector are a gyro's: they refuse or hold what is implausible in °/s (a
//! `k` beyond 100 (°/s)/°C standing for a drift beyond 100 °/s, a bias beyond 10⁴ °/s), and a
//! quantity in a unit of its own can be far larger — an air pressure near 1000 hPa times a rise of
//! 10 °C asks for `k` near 1000. Each axis's quantity is therefore scaled by the power of two that
//! brings its largest calibration value to within [½, 1], which is exact in floating point.

use drift_core::ModifiedTables;
use drift_recording::Segment;
use rayon::prelude::*;

use crate::keying::Keying;
use drift_fit::analyse::analyse;
use drift_fit::error::FitError;
use drift_fit::fit::fit_unit_at;
use drift_fit::settings::FitSettings;

/// The paper's tables fitted to one quantity, stage 3 keyed per axis as the loop's model is.
#[derive(Debug, Clone)]
pub struct Absorber {
    tables: Box<ModifiedTables>,
    /// Per axis, what the quantity was divided by before the tables were fitted to it.
    scale: [f32; 3],
}

/// `segment` with its rates replaced by `values`.
fn carrying(segment: &Segment, values: [Vec<f32>; 3]) -> Segment {
    Segment {
        rate_dps: values,
        ..segment.clone()
    }
}

/// The power of two at or above the largest finite |value| (1 when there is none): dividing by it
/// brings the values within [−1, 1] without rounding.
fn power_of_two_scale<'v>(values: impl IntoIterator<Item = &'v f32>) -> f32 {
    let largest = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(0.0f32, |m, v| m.max(v.abs()));
    if largest > 0.0 && largest.is_normal() {
        // Within the normal range both ways, so that the reciprocal is exact too.
        2f32.powi((largest.log2().ceil() as i32).clamp(-126, 126))
    } else {
        1.0
    }
}

/// `values` with each axis multiplied by `factor[axis]`.
fn scaled(mut values: [Vec<f32>; 3], factor: [f32; 3]) -> [Vec<f32>; 3] {
    for (axis, factor) in values.iter_mut().zip(factor) {
        for v in axis.iter_mut() {
            *v *= factor;
        }
    }
    values
}

impl Absorber {
    /// Fits the paper's tables to the quantity `values` gives on each calibration activation.
    /// `values` returns `None` where the quantity does not exist; such activations are left out,
    /// and a quantity no calibration activation has (an empty channel) has no absorber: `None`.
    ///
    /// The tables are fitted at `references`, the reference times (analysis-grid indices per axis,
    /// [`drift_fit::fit::reference_indices`]) of the drift's own fit: the paper's operator is
    /// linear in the rates only for fixed reference times, and chosen afresh for the candidate they
    /// would take out of it something other than what the drift's tables take (measured: a third of
    /// an interaction effect's explained share lost).
    pub fn fit(
        calibration: &[&Segment],
        values: impl Fn(&Segment) -> Option<[Vec<f32>; 3]> + Sync,
        settings: &FitSettings,
        keying: &Keying,
        references: &[Vec<usize>; 3],
    ) -> Result<Option<Self>, FitError> {
        let carried: Vec<(&Segment, [Vec<f32>; 3])> = calibration
            .par_iter()
            .filter_map(|segment| values(segment).map(|v| (*segment, v)))
            .collect();
        if carried.is_empty() {
            return Ok(None);
        }
        let scale: [f32; 3] = std::array::from_fn(|axis| {
            power_of_two_scale(carried.iter().flat_map(|(_, v)| &v[axis]))
        });
        let analysed = carried
            .into_par_iter()
            .map(|(segment, v)| {
                analyse(
                    &carrying(segment, scaled(v, scale.map(|s| 1.0 / s))),
                    settings,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        let fitted = fit_unit_at(&analysed, settings, Some(references))?;
        Ok(Some(Self {
            tables: keying.tables(&fitted.modified, &fitted.by_history),
            scale,
        }))
    }

    /// The part of `values` (the quantity on `segment`) that the tables do not predict, computed
    /// by drift-core's corrector exactly as it corrects rates, started as the loop's model is
    /// (`keying`, the one the absorber was fitted with).
    pub fn left_over(
        &self,
        segment: &Segment,
        values: [Vec<f32>; 3],
        switch_on: [f32; 3],
        keying: &Keying,
    ) -> [Vec<f32>; 3] {
        let values = scaled(values, self.scale.map(|s| 1.0 / s));
        let left = keying
            .correct(&self.tables, &carrying(segment, values), switch_on)
            .0;
        scaled(left, self.scale)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use drift_recording::{SegmentLabels, SeriesKind};

    use super::*;

    #[test]
    fn the_scale_is_the_power_of_two_at_or_above_the_largest_finite_value() {
        assert_eq!(power_of_two_scale(&[999.0, -1000.0, f32::NAN]), 1024.0);
        assert_eq!(power_of_two_scale(&[0.5, 0.25]), 0.5);
        assert_eq!(power_of_two_scale(&[0.0, f32::INFINITY]), 1.0);
        assert_eq!(power_of_two_scale(&[]), 1.0);
        let largest = power_of_two_scale(&[f32::MAX]);
        assert!(largest.is_finite() && (1.0 / largest).is_normal());
        let values = [vec![999.7f32, -1000.1], vec![0.3], vec![]];
        let there = scaled(values.clone(), [1.0 / 1024.0, 2.0, 1.0]);
        assert_eq!(
            scaled(there, [1024.0, 0.5, 1.0]),
            values,
            "a power of two scales exactly"
        );
    }

    /// A quantity no calibration activation carries (an empty auxiliary channel, the residual heat
    /// without a chamber set point) has nothing to absorb: no absorber, and no error that would
    /// stop the whole diagnosis.
    #[test]
    fn a_quantity_no_calibration_activation_has_gets_no_absorber() {
        let segment = Segment {
            labels: SegmentLabels {
                unit_id: "U".into(),
                set_point_celsius: 30.0,
                session_set_point_celsius: Some(30.0),
                series_kind: SeriesKind::Protocol,
                series: 1,
                repeat: 1,
                activation: 1,
                interval_min: Some(1.0),
                off_before_s: None,
            },
            sample_rate_hz: 1000,
            power_on_ns: 0,
            since_power_on: vec![0],
            rate_dps: [vec![0.0], vec![0.0], vec![0.0]],
            temperature_raw: [vec![6000], vec![6000], vec![6000]],
            temperature_scale: drift_recording::TemperatureScale::default(),
            aux: BTreeMap::new(),
        };
        let keying = Keying::new([false; 3], &[&segment], &[drift_core::Previous::COOLED]);
        let references: [Vec<usize>; 3] = Default::default();
        let absorber = Absorber::fit(
            &[&segment],
            |_| None,
            &FitSettings::default(),
            &keying,
            &references,
        );
        assert!(matches!(absorber, Ok(None)));
    }
}
