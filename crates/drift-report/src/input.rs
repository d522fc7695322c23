//! Everything a report is made from.

use drift_evaluate::coverage::UnitCoverage;
use drift_evaluate::evaluate::ActivationResult;
use drift_evaluate::summary::Split;
use drift_evaluate::uncertainty::UnitUncertainty;
use drift_fit::analyse::Analysed;
use drift_fit::FittedUnit;

/// Everything a report is made from.
pub struct ReportInput<'a> {
    /// Title line.
    pub title: &'a str,
    /// How the data and the report were made (commands, seeds), as Markdown lines.
    pub provenance: Vec<String>,
    /// Units the tables were fitted for, in column order.
    pub fitted: &'a [FittedUnit],
    /// Ids of units whose systematic drift is zero (the noise floor), if any.
    pub noise_floor_units: &'a [String],
    /// The calibration activations, analysed (for the figures of the paper's kind).
    pub calibration: &'a [Analysed],
    /// Evaluation results with the data split each was measured on.
    pub results: &'a [(Split, ActivationResult)],
    /// The fit's cool-down, minutes: activations off at least this long count as cold starts.
    pub independent_after_min: f64,
    /// Measured durations of the pipeline's steps, seconds.
    pub timings: Vec<(String, f64)>,
    /// σ(t) per unit with its coverage on held-out activations (empty if not fitted).
    pub uncertainty: &'a [UnitUncertainty],
    /// The calibration's coverage map per unit (empty without a fit).
    pub coverage: &'a [UnitCoverage],
    /// The channel the switch-on ambient was read from, where the paper's tables were also
    /// evaluated started at it.
    pub switch_on_ambient: Option<&'a str>,
}
