//! The loop as the worlds benchmark runs it on one world: the paper's tables fitted on the
//! calibration protocol, then the loop closed on the world's activations — cross-fitted on the
//! analyst's diagnosis campaign when there is one (the first half's loop). The blind run and the
//! oracle's share it, so that they differ only in what the activations carry.

use anyhow::Context;
use drift_diagnose::closing::{close, close_both, Closed, LoopOptions};
use drift_diagnose::roles::Roles;
use drift_fit::analyse::analyse;
use drift_fit::fit::FittedUnit;
use drift_fit::{fit_unit, FitSettings};
use drift_recording::paper::{
    CALIBRATION_SET_POINTS_CELSIUS as CALIBRATION, VALIDATION_SET_POINT_CELSIUS as VALIDATION,
};
use drift_recording::{Segment, QUIET};

/// Fits the paper's tables on `all`'s calibration protocol and closes the loop; `extend` builds and
/// guards the extended model; `select_on_validation` ranks on the +33 °C protocol too.
pub fn fit_and_close<'a>(
    all: &'a [Segment],
    diagnosis: &[&'a Segment],
    extend: bool,
    select_on_validation: bool,
    settings: &FitSettings,
) -> anyhow::Result<(FittedUnit, Closed<'a>)> {
    let analysed = Roles::split(all, &CALIBRATION)
        .calibration
        .iter()
        .map(|s| analyse(s, settings))
        .collect::<Result<Vec<_>, _>>()?;
    let base = fit_unit(&analysed, settings)?;
    let options = LoopOptions {
        extend,
        select_on: if select_on_validation {
            vec![VALIDATION]
        } else {
            Vec::new()
        },
        ..LoopOptions::new(&CALIBRATION)
    };
    let closed = if diagnosis.is_empty() {
        close(&base, all, &[], &options, settings, QUIET)?
    } else {
        close_both(&base, all, diagnosis, &options, settings, QUIET)?
            .into_iter()
            .next()
            .context("the cross-fitted loop closed no half")?
    };
    Ok((base, closed))
}
