//! Where the recommended model's tables are valid: the calibration's switch-on temperatures ×
//! residual heats, per axis. One definition for the corrector's flags (set at switch-on, on every
//! sample of the activation), the coverage map of a report and the share `check` finds outside.
//!
//! ```
//! use drift_core::{Envelope, Flags, SwitchOn};
//!
//! let envelope = Envelope {
//!     switch_on_celsius: [30.0, 45.0],
//!     margin_celsius: 0.5,
//!     most_residual_heat_celsius: 8.0,
//! };
//! let start = |on: f32, heat: f32| SwitchOn {
//!     switch_on_celsius: on,
//!     ambient_celsius: on - heat,
//!     residual_heat_celsius: heat,
//!     remaining: 0.0,
//!     known: true,
//! };
//! assert_eq!(envelope.flags(&start(35.0, 2.0)), Flags::NONE);
//! assert_eq!(envelope.flags(&start(25.0, 0.0)), Flags::TEMPERATURE_OUT_OF_RANGE);
//! assert_eq!(envelope.flags(&start(40.0, 9.0)), Flags::HISTORY_OUT_OF_SPAN);
//! ```

use crate::flags::Flags;
use crate::history::SwitchOn;
use crate::recommended::TurnOn;

/// The calibrated envelope of one axis: switch-on temperatures within the calibration's (± a
/// margin for sensor noise) and residual heat up to the most a calibration activation had.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Envelope {
    /// The calibration's lowest and highest switch-on temperature, °C.
    pub switch_on_celsius: [f32; 2],
    /// How far beyond them a switch-on still counts as inside, °C
    /// ([`Settings::ambient_margin_celsius`](crate::Settings)).
    pub margin_celsius: f32,
    /// The most residual heat a calibration activation switched on with, °C.
    pub most_residual_heat_celsius: f32,
}

impl Envelope {
    /// Every flag [`Envelope::flags`] can set.
    pub const FLAGS: Flags =
        Flags(Flags::TEMPERATURE_OUT_OF_RANGE.0 | Flags::HISTORY_OUT_OF_SPAN.0);

    /// Where `switch_on` lies: `TEMPERATURE_OUT_OF_RANGE` for a switch-on temperature beyond the
    /// calibration's by more than the margin (or not a number), `HISTORY_OUT_OF_SPAN` for more
    /// residual heat than the calibration's most (only when what was kept is known).
    #[allow(clippy::arithmetic_side_effects)] // f32 arithmetic: no overflow panic.
    #[inline]
    pub fn flags(&self, switch_on: &SwitchOn) -> Flags {
        let [low, high] = self.switch_on_celsius;
        let on = switch_on.switch_on_celsius;
        let mut flags =
            if on.is_nan() || on < low - self.margin_celsius || on > high + self.margin_celsius {
                Flags::TEMPERATURE_OUT_OF_RANGE
            } else {
                Flags::NONE
            };
        if heat_beyond(self.most_residual_heat_celsius, switch_on).is_some() {
            flags |= Flags::HISTORY_OUT_OF_SPAN;
        }
        flags
    }

    /// Whether `switch_on` lies inside.
    pub fn contains(&self, switch_on: &SwitchOn) -> bool {
        !self.flags(switch_on).intersects(Self::FLAGS)
    }
}

/// How far `switch_on`'s residual heat lies beyond `most` (°C, > 0), or `None` inside (also for a
/// start whose history is unknown, or a heat that is not a number): where [`Envelope::flags`]
/// sets `HISTORY_OUT_OF_SPAN` and σ(t) widens ([`crate::Uncertainty`]).
#[allow(clippy::arithmetic_side_effects)] // f32 arithmetic: no overflow panic.
#[inline]
pub fn heat_beyond(most: f32, switch_on: &SwitchOn) -> Option<f32> {
    let heat = switch_on.residual_heat_celsius;
    (switch_on.known && heat > 0.0 && heat > most).then_some(heat - most)
}

impl TurnOn {
    /// This axis's envelope: the turn-on polynomial's fitted switch-on temperatures and the most
    /// residual heat its slope was fitted on, with `margin_celsius` beyond the temperatures.
    pub fn envelope(&self, margin_celsius: f32) -> Envelope {
        Envelope {
            switch_on_celsius: self.polynomial.range_celsius,
            margin_celsius,
            most_residual_heat_celsius: self.most_residual_heat_celsius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start(on: f32, heat: f32, known: bool) -> SwitchOn {
        SwitchOn {
            switch_on_celsius: on,
            ambient_celsius: on - heat,
            residual_heat_celsius: heat,
            remaining: 0.0,
            known,
        }
    }

    const ENVELOPE: Envelope = Envelope {
        switch_on_celsius: [30.0, 45.0],
        margin_celsius: 0.5,
        most_residual_heat_celsius: 8.0,
    };

    #[test]
    fn the_margin_is_inside_and_beyond_it_is_flagged() {
        assert!(ENVELOPE.contains(&start(29.5, 0.0, true)));
        assert!(ENVELOPE.contains(&start(45.5, 0.0, true)));
        assert_eq!(
            ENVELOPE.flags(&start(29.4, 0.0, true)),
            Flags::TEMPERATURE_OUT_OF_RANGE
        );
        assert_eq!(
            ENVELOPE.flags(&start(f32::NAN, 0.0, true)),
            Flags::TEMPERATURE_OUT_OF_RANGE
        );
        assert_eq!(
            ENVELOPE.flags(&start(50.0, 9.0, true)),
            Envelope::FLAGS,
            "both at once"
        );
    }

    #[test]
    fn residual_heat_counts_only_when_what_was_kept_is_known() {
        assert!(ENVELOPE.contains(&start(40.0, 8.0, true)));
        assert_eq!(
            ENVELOPE.flags(&start(40.0, 8.5, true)),
            Flags::HISTORY_OUT_OF_SPAN
        );
        assert!(ENVELOPE.contains(&start(40.0, 8.5, false)));
        assert!(ENVELOPE.contains(&start(40.0, f32::NAN, true)));
        assert_eq!(heat_beyond(8.0, &start(40.0, 8.5, true)), Some(0.5));
        assert_eq!(heat_beyond(8.0, &start(40.0, 8.0, true)), None);
        assert_eq!(heat_beyond(8.0, &start(40.0, 9.0, false)), None);
    }
}
