//! Status flags: every clamp, hold and fault the corrector applies is reported, never silent.

use core::ops::{BitOr, BitOrAssign};

/// A set of status bits for one axis of one corrected sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct Flags(pub u16);

impl Flags {
    /// No flag: the sample was corrected inside the calibrated envelope.
    pub const NONE: Self = Self(0);
    /// The switch-on temperature lies outside the calibrated ambients by more than
    /// [`Settings::ambient_margin_celsius`](crate::Settings): the nearest ambient's tables are used
    /// (clamp). Set on every sample of the activation.
    pub const AMBIENT_OUT_OF_RANGE: Self = Self(1 << 0);
    /// The current temperature rise lies outside the span of the stored heating-dynamics curves by
    /// more than [`Settings::rise_margin_celsius`](crate::Settings): the nearest curve's `k` is used
    /// (clamp).
    pub const RISE_OUT_OF_SPAN: Self = Self(1 << 1);
    /// Time since switch-on is past the last reference time: `k` is held at its value there.
    pub const PAST_LAST_REFERENCE: Self = Self(1 << 2);
    /// Polynomial baselines: the temperature lies outside the fitted range by more than the ambient
    /// margin; the polynomial is evaluated at the nearest end of the range (clamp), never extrapolated.
    pub const TEMPERATURE_OUT_OF_RANGE: Self = Self(1 << 3);
    /// The temperature reading is NaN or infinite: the last good drift estimate is held.
    pub const TEMPERATURE_INVALID: Self = Self(1 << 4);
    /// The temperature reading has not changed for
    /// [`Settings::stuck_after_samples`](crate::Settings) samples: the last good drift estimate is
    /// held until it changes again.
    pub const TEMPERATURE_STUCK: Self = Self(1 << 5);
    /// The rate input is NaN or infinite: it passes through uncorrected-but-flagged (the output is
    /// non-finite too).
    pub const RATE_INVALID: Self = Self(1 << 6);
    /// `correct` was called before a successful `power_on`: the rate passes through uncorrected.
    pub const NOT_POWERED_ON: Self = Self(1 << 7);
    /// The model produced a non-finite or implausible drift or initial bias (beyond
    /// [`MAX_PLAUSIBLE_DRIFT_DPS`](crate::MAX_PLAUSIBLE_DRIFT_DPS), for example from a temperature
    /// reading far outside any sensor's range): the last good drift estimate is held.
    pub const MODEL_INVALID: Self = Self(1 << 8);
    /// Extended model: an auxiliary input an extra term reads is NaN, infinite or was not passed
    /// (that term holds its filtered input), or the terms' contribution is non-finite or beyond
    /// [`MAX_PLAUSIBLE_DRIFT_DPS`](crate::MAX_PLAUSIBLE_DRIFT_DPS) (the extension then adds
    /// nothing). (Temperature faults hold the temperature the terms read, under the flags above.)
    pub const EXTENSION_INPUT_INVALID: Self = Self(1 << 9);

    /// A table keyed by heating history was powered on without what was kept of the previous
    /// activation ([`crate::CorrectorState::power_on`] rather than `power_on_after`, or nothing
    /// finite kept): the start is taken as fully cooled. Set on every sample of the activation.
    pub const HISTORY_UNKNOWN: Self = Self(1 << 10);
    /// A table keyed by heating history or with warm starts: the residual heat at switch-on lies
    /// outside the span of the stored histories (or beyond the warmest stored warm start) by more
    /// than [`Settings::rise_margin_celsius`](crate::Settings): the nearest history's curve and
    /// the warmest start's initial bias are used (clamp). Set on every sample of the activation.
    pub const HISTORY_OUT_OF_SPAN: Self = Self(1 << 11);

    /// Every flag with its name, in bit order (for bindings, logs and reports: a flag added here is
    /// listed everywhere).
    pub const ALL: [(Self, &'static str); 12] = [
        (Self::AMBIENT_OUT_OF_RANGE, "AMBIENT_OUT_OF_RANGE"),
        (Self::RISE_OUT_OF_SPAN, "RISE_OUT_OF_SPAN"),
        (Self::PAST_LAST_REFERENCE, "PAST_LAST_REFERENCE"),
        (Self::TEMPERATURE_OUT_OF_RANGE, "TEMPERATURE_OUT_OF_RANGE"),
        (Self::TEMPERATURE_INVALID, "TEMPERATURE_INVALID"),
        (Self::TEMPERATURE_STUCK, "TEMPERATURE_STUCK"),
        (Self::RATE_INVALID, "RATE_INVALID"),
        (Self::NOT_POWERED_ON, "NOT_POWERED_ON"),
        (Self::MODEL_INVALID, "MODEL_INVALID"),
        (Self::EXTENSION_INPUT_INVALID, "EXTENSION_INPUT_INVALID"),
        (Self::HISTORY_UNKNOWN, "HISTORY_UNKNOWN"),
        (Self::HISTORY_OUT_OF_SPAN, "HISTORY_OUT_OF_SPAN"),
    ];

    /// Flags that mean the correction of this sample is degraded (a hold or pass-through), as opposed
    /// to an envelope clamp.
    pub const FAULTS: Self = Self(
        Self::TEMPERATURE_INVALID.0
            | Self::TEMPERATURE_STUCK.0
            | Self::RATE_INVALID.0
            | Self::NOT_POWERED_ON.0
            | Self::MODEL_INVALID.0
            | Self::EXTENSION_INPUT_INVALID.0,
    );

    /// Whether every bit of `other` is set in `self`.
    pub const fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether any bit of `other` is set in `self`.
    pub const fn intersects(self, other: Self) -> bool {
        self.0 & other.0 != 0
    }

    /// Whether no bit is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The union of two sets.
    #[must_use]
    pub const fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

impl BitOr for Flags {
    type Output = Self;
    fn bitor(self, rhs: Self) -> Self {
        self.union(rhs)
    }
}

impl BitOrAssign for Flags {
    fn bitor_assign(&mut self, rhs: Self) {
        *self = self.union(rhs);
    }
}

#[cfg(test)]
mod tests {
    use super::Flags;

    #[test]
    fn all_lists_every_bit_once_in_order() {
        let mut seen = 0u16;
        for (i, (flag, _)) in Flags::ALL.iter().enumerate() {
            assert_eq!(flag.0, 1 << i);
            seen |= flag.0;
        }
        assert_eq!(seen.count_ones() as usize, Flags::ALL.len());
    }
}
