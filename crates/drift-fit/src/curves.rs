//! The paper's curves: activations grouped by (interval, activation number), the repeats averaged,
//! and every activation that followed a full cool-down merged into one "independent" curve.

use std::collections::BTreeMap;

use drift_recording::SeriesKind;

use crate::analyse::Analysed;
use crate::settings::FitSettings;

/// Which calibration curve an activation belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CurveKey {
    /// Switched on after a full cool-down: the first activation of any series, and every
    /// activation of a series whose interval is at least `independent_after_min`.
    Independent,
    /// Activation `activation` (2…) of a series with a short interval.
    After {
        /// Off-time between activations, whole seconds (an integer, so keys compare exactly).
        interval_s: u32,
        /// Activation number within the series.
        activation: u32,
    },
}

impl CurveKey {
    /// The key of an activation, or `None` for activations that are not part of the protocol.
    pub fn of(analysed: &Analysed, settings: &FitSettings) -> Option<Self> {
        let labels = &analysed.labels;
        if labels.series_kind != SeriesKind::Protocol {
            return None;
        }
        let interval = labels.interval_min?;
        if labels.activation <= 1 || interval >= settings.independent_after_min {
            Some(Self::Independent)
        } else {
            Some(Self::After {
                interval_s: (interval * 60.0).round() as u32,
                activation: labels.activation,
            })
        }
    }

    /// A short human-readable name: `independent` or `1min#3`.
    pub fn name(&self) -> String {
        match self {
            Self::Independent => "independent".into(),
            Self::After {
                interval_s,
                activation,
            } if interval_s % 60 == 0 => {
                format!("{}min#{activation}", interval_s / 60)
            }
            Self::After {
                interval_s,
                activation,
            } => format!("{interval_s}s#{activation}"),
        }
    }
}

/// One curve: the mean of its member activations, per axis, on the analysis grid.
#[derive(Debug, Clone, PartialEq)]
pub struct AveragedCurve {
    /// Which curve.
    pub key: CurveKey,
    /// How many activations were averaged.
    pub members: usize,
    /// Mean low-frequency drift `g(t)`, °/s.
    pub drift_dps: [Vec<f64>; 3],
    /// Mean temperature rise, °C.
    pub rise_celsius: [Vec<f64>; 3],
    /// Mean sensor temperature at switch-on, per axis, °C: how warm the history left the unit.
    pub switch_on_celsius: [f64; 3],
    /// Mean initial bias, per axis, °/s: where this history's bias starts.
    pub initial_bias_dps: [f64; 3],
}

impl AveragedCurve {
    /// Number of grid points.
    pub fn len(&self) -> usize {
        self.drift_dps[0].len()
    }

    /// Whether the curve is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Every curve at one chamber set point.
#[derive(Debug, Clone, PartialEq)]
pub struct SetPointCurves {
    /// Chamber set point, °C.
    pub set_point_celsius: f64,
    /// Grid spacing, ms.
    pub grid_ms: u32,
    /// Mean switch-on sensor temperature of the independent activations, per axis, °C: the
    /// table's calibration ambient.
    pub ambient_celsius: [f64; 3],
    /// Mean initial bias of the independent activations, per axis, °/s.
    pub initial_bias_dps: [f64; 3],
    /// The curves, ordered by key (independent first).
    pub curves: Vec<AveragedCurve>,
}

fn mean_of(members: &[&Analysed], value: impl Fn(&Analysed) -> [f64; 3]) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for member in members {
        for (s, v) in sum.iter_mut().zip(value(member)) {
            *s += v;
        }
    }
    sum.map(|s| s / members.len().max(1) as f64)
}

/// Mean over `members` of the first `len` values of `pick(member)`, member after member.
///
/// Accumulated row by row (each member's values added to the running sums in one contiguous pass)
/// rather than point by point across members: the same additions in the same order per point —
/// from −0.0, as `Iterator::sum` starts — so the same bits, without striding through every
/// member's array for each point.
fn mean(members: &[&Analysed], len: usize, pick: impl Fn(&Analysed) -> &[f32]) -> Vec<f64> {
    let mut sums = vec![-0.0_f64; len];
    for member in members {
        for (sum, &value) in sums.iter_mut().zip(&pick(member)[..len]) {
            *sum += f64::from(value);
        }
    }
    let count = members.len() as f64;
    for sum in &mut sums {
        *sum /= count;
    }
    sums
}

fn average(key: CurveKey, members: &[&Analysed]) -> AveragedCurve {
    let len = members.iter().map(|m| m.len()).min().unwrap_or(0);
    AveragedCurve {
        key,
        members: members.len(),
        drift_dps: [0, 1, 2].map(|axis| mean(members, len, |m| &m.drift_dps[axis])),
        rise_celsius: [0, 1, 2].map(|axis| mean(members, len, |m| &m.rise_celsius[axis])),
        switch_on_celsius: mean_of(members, |a| a.switch_on_celsius),
        initial_bias_dps: mean_of(members, |a| a.initial_bias_dps),
    }
}

/// Groups protocol activations by set point and curve, averaging the repeats. Set points come out
/// in increasing order; field activations are ignored.
pub fn group(analysed: &[Analysed], settings: &FitSettings) -> Vec<SetPointCurves> {
    // Set points as integer milli-degrees, so grouping is exact.
    let mut by_set_point: BTreeMap<i64, BTreeMap<CurveKey, Vec<&Analysed>>> = BTreeMap::new();
    for activation in analysed {
        if let Some(key) = CurveKey::of(activation, settings) {
            let set_point = (activation.labels.set_point_celsius * 1000.0).round() as i64;
            by_set_point
                .entry(set_point)
                .or_default()
                .entry(key)
                .or_default()
                .push(activation);
        }
    }
    by_set_point
        .into_iter()
        .map(|(set_point, curves)| {
            let independent = curves
                .get(&CurveKey::Independent)
                .cloned()
                .unwrap_or_default();
            SetPointCurves {
                set_point_celsius: set_point as f64 / 1000.0,
                grid_ms: settings.grid_ms,
                ambient_celsius: mean_of(&independent, |a| a.switch_on_celsius),
                initial_bias_dps: mean_of(&independent, |a| a.initial_bias_dps),
                curves: curves
                    .iter()
                    .map(|(key, members)| average(*key, members))
                    .collect(),
            }
        })
        .collect()
}
