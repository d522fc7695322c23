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
}

/// `segment` with its rates replaced by `values`.
fn carrying(segment: &Segment, values: [Vec<f32>; 3]) -> Segment {
    Segment {
        rate_dps: values,
        ..segment.clone()
    }
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
        let analysed = calibration
            .par_iter()
            .filter_map(|segment| values(segment).map(|v| analyse(&carrying(segment, v), settings)))
            .collect::<Result<Vec<_>, _>>()?;
        if analysed.is_empty() {
            return Ok(None);
        }
        let fitted = fit_unit_at(&analysed, settings, Some(references))?;
        Ok(Some(Self {
            tables: keying.tables(&fitted.modified, &fitted.by_history),
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
        keying
            .correct(&self.tables, &carrying(segment, values), switch_on)
            .0
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use drift_recording::{SegmentLabels, SeriesKind};

    use super::*;

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
