//! Changes to a campaign that the command line's flags and Python's keywords make, applied in one
//! place so that `gyrodrift simulate` and `gyrodrift.simulate` record the same campaign.

use crate::campaign::{set_point_range, TruthBias};
use crate::error::SimError;
use crate::{Campaign, Field, Protocol, UnitModel};

/// What to change in a campaign: each `Some` or `true` overrides the campaign's own value.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// The random seed.
    pub seed: Option<u64>,
    /// Number of units.
    pub units: Option<u32>,
    /// Chamber set points, °C.
    pub set_points: Option<Vec<f64>>,
    /// The protocol's off-times between activations, minutes (adds the protocol if missing).
    pub intervals: Option<Vec<f64>>,
    /// The protocol's repeats (adds the protocol if missing).
    pub repeats: Option<u32>,
    /// Add field-like sessions.
    pub field: bool,
    /// Field-like sessions only: no protocol.
    pub field_only: bool,
    /// A unit with zero systematic drift (the noise floor's twin).
    pub zero_drift: bool,
    /// The unit the paper's model represents exactly.
    pub paper_exact: bool,
    /// Hidden effects to switch on, by name.
    pub effects: Vec<String>,
    /// Noise scale (0: noise-free).
    pub noise_scale: Option<f64>,
    /// Record the truth's bias at the auxiliary channels' rate.
    pub truth_at_aux_rate: bool,
}

/// Why overrides cannot be applied.
#[derive(Debug, thiserror::Error)]
pub enum OverrideError {
    /// Two overrides that exclude each other are both set (named as the keywords are).
    #[error("`{0}` and `{1}` cannot both be set")]
    Conflict(&'static str, &'static str),
    /// An effect name the simulator does not know.
    #[error("`effects`: {0}")]
    Effect(String),
    /// The campaign they make is not valid.
    #[error(transparent)]
    Campaign(#[from] SimError),
}

/// Why set-point text does not parse.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetPointsError {
    /// A piece that is not a number.
    #[error("`{0}` is not a number")]
    NotANumber(String),
    /// A range that is not `from:to:step`.
    #[error("a range must be from:to:step, got `{0}`")]
    BadRange(String),
    /// A range without set points.
    #[error("range `{0}` is empty")]
    EmptyRange(String),
    /// A range with more set points than a chamber campaign can hold (refused before any is made).
    #[error("range `{0}` makes {1:.3e} set points; at most {MAX_SET_POINTS} (a chamber needs hours per set point): use a larger step")]
    TooMany(String, f64),
}

/// Most set points a range may make.
pub const MAX_SET_POINTS: usize = 1000;

/// Set points as text: a list `30,40,33` or a range `-40:60:10` (from:to:step, inclusive), °C.
pub fn parse_set_points(text: &str) -> Result<Vec<f64>, SetPointsError> {
    let number = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| SetPointsError::NotANumber(s.trim().to_owned()))
    };
    if text.contains(':') {
        let [from, to, step] = text.split(':').collect::<Vec<_>>()[..] else {
            return Err(SetPointsError::BadRange(text.to_owned()));
        };
        let (from, to, step) = (number(from)?, number(to)?, number(step)?);
        let count = (to - from) / step + 1.0;
        if count > MAX_SET_POINTS as f64 {
            return Err(SetPointsError::TooMany(text.to_owned(), count));
        }
        let points = set_point_range(from, to, step);
        if points.is_empty() {
            return Err(SetPointsError::EmptyRange(text.to_owned()));
        }
        return Ok(points);
    }
    text.split(',').map(number).collect()
}

impl Overrides {
    /// `campaign` with the overrides applied, validated.
    pub fn apply(&self, mut c: Campaign) -> Result<Campaign, OverrideError> {
        if self.field && self.field_only {
            return Err(OverrideError::Conflict("field", "field_only"));
        }
        if self.zero_drift && self.paper_exact {
            return Err(OverrideError::Conflict("zero_drift", "paper_exact"));
        }
        if let Some(seed) = self.seed {
            c.seed = seed;
        }
        if let Some(units) = self.units {
            c.units = units;
        }
        if let Some(points) = &self.set_points {
            c.set_points_celsius.clone_from(points);
        }
        if self.intervals.is_some() || self.repeats.is_some() {
            let p = c.protocol.get_or_insert_with(Protocol::default);
            if let Some(intervals) = &self.intervals {
                p.intervals_min.clone_from(intervals);
            }
            if let Some(repeats) = self.repeats {
                p.repeats = repeats;
            }
        }
        if self.field || self.field_only {
            c.field.get_or_insert_with(Field::default);
        }
        if self.field_only {
            c.protocol = None;
        }
        if self.zero_drift {
            c.unit_model = UnitModel::ZeroSystematicDrift;
        }
        if self.paper_exact {
            c.unit_model = UnitModel::PaperExact;
        }
        for name in &self.effects {
            c.effects
                .enable(name.trim())
                .map_err(OverrideError::Effect)?;
        }
        if self.truth_at_aux_rate {
            c.truth_bias = TruthBias::AuxRate;
        }
        if let Some(scale) = self.noise_scale {
            c.noise_scale = scale;
        }
        c.validate()?;
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_points_parse_as_lists_and_ranges() {
        assert_eq!(parse_set_points("30, 40,33"), Ok(vec![30.0, 40.0, 33.0]));
        assert_eq!(parse_set_points("-10:10:10"), Ok(vec![-10.0, 0.0, 10.0]));
        assert_eq!(
            parse_set_points("30,abc"),
            Err(SetPointsError::NotANumber("abc".into()))
        );
        assert_eq!(
            parse_set_points("1:2"),
            Err(SetPointsError::BadRange("1:2".into()))
        );
        assert_eq!(
            parse_set_points("10:0:1"),
            Err(SetPointsError::EmptyRange("10:0:1".into()))
        );
    }

    #[test]
    fn overrides_change_what_they_name_and_refuse_conflicts() {
        let overrides = Overrides {
            seed: Some(7),
            units: Some(1),
            repeats: Some(2),
            field_only: true,
            effects: vec!["thermal_lag".into()],
            ..Overrides::default()
        };
        let c = overrides.apply(Campaign::default()).unwrap();
        assert_eq!((c.seed, c.units), (7, 1));
        assert!(c.protocol.is_none() && c.field.is_some());
        assert!(c.effects.thermal_lag.is_some());
        let twin = Overrides {
            zero_drift: true,
            ..Overrides::default()
        };
        let c = twin.apply(Campaign::default()).unwrap();
        assert_eq!(c.unit_model, UnitModel::ZeroSystematicDrift);
        let both = Overrides {
            field: true,
            field_only: true,
            ..Overrides::default()
        };
        assert_eq!(
            both.apply(Campaign::default()).unwrap_err().to_string(),
            "`field` and `field_only` cannot both be set"
        );
        let unknown = Overrides {
            effects: vec!["sunspots".into()],
            ..Overrides::default()
        };
        assert!(unknown
            .apply(Campaign::default())
            .unwrap_err()
            .to_string()
            .starts_with("`effects`: unknown effect `sunspots`"));
    }
}
