//! The heating history at switch-on, as firmware can know it without a clock: what it kept of the
//! previous activation across power-off.
//!
//! The paper's stage 3 finds the history by the rise; when warm starts heat faster than cold ones
//! the curves cross and the rise names the wrong history (docs/closed-loop.md). A table keyed by
//! history ([`crate::AmbientCurves::residual_heat_celsius`]) reads it from here instead.

/// What firmware keeps of one axis's last activation across power-off (8 bytes per axis), outside
/// the corrector's state: [`crate::CorrectorState::power_on_after`] reads and updates it,
/// [`crate::CorrectorState::keep`] records the switch-off temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Previous {
    /// The ambient estimated for that activation, °C.
    pub ambient_celsius: f32,
    /// The last good temperature reading of that activation, °C.
    pub switch_off_celsius: f32,
}

impl Previous {
    /// Nothing kept (the first activation): the next start is taken as fully cooled, flagged.
    pub const NOTHING: [Self; crate::AXES] = [Self {
        ambient_celsius: f32::NAN,
        switch_off_celsius: f32::NAN,
    }; crate::AXES];

    /// Known to have cooled fully (a clock says the unit was off longer than the calibration's
    /// cool-down): the next start is cold, at whatever ambient it finds, and not flagged. Without
    /// it, an ambient that rose during the off-time by less than the unit's own rise reads as
    /// residual heat ([`SwitchOn::estimate`]).
    pub const COOLED: [Self; crate::AXES] = [Self {
        ambient_celsius: f32::NAN,
        switch_off_celsius: f32::NEG_INFINITY,
    }; crate::AXES];
}

/// The ambient and the residual heat an activation switched on with, estimated from the switch-on
/// temperature and what was kept of the previous activation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwitchOn {
    /// The temperature at switch-on, °C.
    pub switch_on_celsius: f32,
    /// The ambient, °C: where stage 2 of a history-keyed table looks.
    pub ambient_celsius: f32,
    /// How far the switch-on temperature stands above it, °C (≥ 0): where stage 3 looks.
    pub residual_heat_celsius: f32,
    /// The residual heat as a fraction of the heat the unit had at the previous switch-off
    /// (switch-off temperature − ambient), 0 ..= 1; 0 for a cold or unknown start. How far the
    /// cooling had gone: after a short off-time the fast part of the heat is still leaving, and the
    /// unit cools faster per °C of residual heat ([`crate::SwitchOnRate`]).
    pub remaining: f32,
    /// False when nothing was kept (or it was not finite): then the start is taken as fully cooled,
    /// which is what the paper's cold start is.
    pub known: bool,
}

impl SwitchOn {
    /// The estimate. A unit cannot be warmer than the ambient it last saw unless its own heat is
    /// still in it, and it cannot be warmer than when it was switched off by its own heat alone:
    ///
    /// - nothing kept: ambient = switch-on temperature, no residual heat, not known;
    /// - known to have cooled fully ([`Previous::COOLED`]): the same, known;
    /// - switched on at or above the previous switch-off temperature: the ambient rose during the
    ///   off-time; ambient = switch-on temperature, no residual heat;
    /// - otherwise: ambient = the lower of the previous ambient and the switch-on temperature,
    ///   residual heat = switch-on temperature − ambient.
    ///
    /// An ambient that rises during the off-time by less than the unit's own rise reads as residual
    /// heat: only a clock kept across power-off would tell the two apart.
    pub fn estimate(switch_on_celsius: f32, previous: Option<Previous>) -> Self {
        let cold = |known| Self {
            switch_on_celsius,
            ambient_celsius: switch_on_celsius,
            residual_heat_celsius: 0.0,
            remaining: 0.0,
            known,
        };
        let Some(previous) = previous else {
            return cold(false);
        };
        if previous.switch_off_celsius == f32::NEG_INFINITY {
            return cold(true);
        }
        if !(previous.ambient_celsius.is_finite() && previous.switch_off_celsius.is_finite()) {
            return cold(false);
        }
        if switch_on_celsius >= previous.switch_off_celsius {
            return cold(true);
        }
        let ambient = previous.ambient_celsius.min(switch_on_celsius);
        let residual_heat_celsius = switch_on_celsius - ambient;
        // Here switch-off > switch-on ≥ ambient, so the heat at switch-off is positive; the
        // quotient is in 0 ..= 1 unless rounding or an overflow says otherwise.
        let remaining = residual_heat_celsius / (previous.switch_off_celsius - ambient);
        Self {
            switch_on_celsius,
            ambient_celsius: ambient,
            residual_heat_celsius,
            remaining: if remaining.is_finite() {
                remaining.clamp(0.0, 1.0)
            } else {
                0.0
            },
            known: true,
        }
    }
}

impl SwitchOn {
    /// The start with an ambient the instrument measured at switch-on (an air or board
    /// thermistor), °C, instead of one estimated: no residual heat is read into it or out of it.
    /// The residual heat is how far the switch-on temperature stands above it (0 at or below it),
    /// and the start is known. `remaining` is that heat as a fraction of the heat the unit had at
    /// the previous switch-off over the same ambient, where that was kept (0 otherwise).
    ///
    /// Total: an ambient that is not a number gives [`Self::estimate`]'s start (the corrector
    /// refuses one before it gets here).
    pub fn measured(
        switch_on_celsius: f32,
        ambient_celsius: f32,
        previous: Option<Previous>,
    ) -> Self {
        if ambient_celsius.is_nan() {
            return Self::estimate(switch_on_celsius, previous);
        }
        let above = switch_on_celsius - ambient_celsius;
        let residual_heat_celsius = if above > 0.0 { above } else { 0.0 };
        let at_switch_off = previous.map_or(f32::NAN, |p| p.switch_off_celsius - ambient_celsius);
        let remaining = residual_heat_celsius / at_switch_off;
        Self {
            switch_on_celsius,
            ambient_celsius,
            residual_heat_celsius,
            // NaN (nothing kept), infinite or negative (a cooled mark, an ambient above the
            // switch-off) all say nothing of the cooling: 0, as for a cold start.
            remaining: if remaining.is_finite() && at_switch_off > 0.0 {
                remaining.clamp(0.0, 1.0)
            } else {
                0.0
            },
            known: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn previous(ambient: f32, off: f32) -> Option<Previous> {
        Some(Previous {
            ambient_celsius: ambient,
            switch_off_celsius: off,
        })
    }

    #[test]
    fn nothing_kept_is_a_cold_start_not_known() {
        let s = SwitchOn::estimate(30.5, None);
        assert_eq!(
            (s.ambient_celsius, s.residual_heat_celsius, s.known),
            (30.5, 0.0, false)
        );
        let s = SwitchOn::estimate(30.5, previous(f32::NAN, 35.0));
        assert!(!s.known);
    }

    #[test]
    fn cooled_is_a_known_cold_start_at_any_ambient() {
        let s = SwitchOn::estimate(33.0, Some(Previous::COOLED[0]));
        assert_eq!(
            (s.ambient_celsius, s.residual_heat_celsius, s.known),
            (33.0, 0.0, true)
        );
    }

    #[test]
    fn short_off_time_keeps_the_ambient_and_reads_residual_heat() {
        let s = SwitchOn::estimate(32.0, previous(30.0, 35.0));
        assert_eq!(
            (s.ambient_celsius, s.residual_heat_celsius, s.known),
            (30.0, 2.0, true)
        );
        // 2 of the 5 °C it had at switch-off.
        assert_eq!(s.remaining, 0.4);
    }

    #[test]
    fn colder_than_the_ambient_lowers_it() {
        let s = SwitchOn::estimate(28.0, previous(30.0, 35.0));
        assert_eq!((s.ambient_celsius, s.residual_heat_celsius), (28.0, 0.0));
    }

    #[test]
    fn warmer_than_at_switch_off_means_the_ambient_rose() {
        let s = SwitchOn::estimate(36.0, previous(30.0, 35.0));
        assert_eq!(
            (s.ambient_celsius, s.residual_heat_celsius, s.known),
            (36.0, 0.0, true)
        );
    }

    #[test]
    fn a_measured_ambient_is_taken_as_it_is() {
        // After a short off-time: the residual heat is what stands above the air, whatever was
        // kept, and the start is known.
        let s = SwitchOn::measured(32.0, 29.0, None);
        assert_eq!(
            (
                s.ambient_celsius,
                s.residual_heat_celsius,
                s.remaining,
                s.known
            ),
            (29.0, 3.0, 0.0, true)
        );
        // Kept: 3 of the 6 °C it had at switch-off over that air.
        let s = SwitchOn::measured(32.0, 29.0, previous(30.0, 35.0));
        assert_eq!(s.remaining, 0.5);
        // Colder than the air (it lags a rising ambient): no residual heat.
        let s = SwitchOn::measured(28.0, 29.0, previous(30.0, 35.0));
        assert_eq!((s.residual_heat_celsius, s.remaining), (0.0, 0.0));
        // The cooled mark says nothing of the cooling's progress.
        let s = SwitchOn::measured(32.0, 29.0, Some(Previous::COOLED[0]));
        assert_eq!((s.residual_heat_celsius, s.remaining), (3.0, 0.0));
    }

    #[test]
    fn a_measured_ambient_at_the_switch_on_is_a_known_cold_start() {
        for kept in [None, previous(30.0, 35.0), Some(Previous::COOLED[0])] {
            assert_eq!(
                SwitchOn::measured(31.0, 31.0, kept),
                SwitchOn::estimate(31.0, Some(Previous::COOLED[0]))
            );
        }
    }

    #[test]
    fn a_measured_ambient_that_is_not_a_number_is_the_estimate() {
        let kept = previous(30.0, 35.0);
        assert_eq!(
            SwitchOn::measured(32.0, f32::NAN, kept),
            SwitchOn::estimate(32.0, kept)
        );
    }
}
