//! Settings shared by every model: how raw temperature maps to °C and when to flag.

use crate::error::{Error, Location, Problem};

/// Sensor conversion and envelope settings, stored with the tables.
///
/// | field | meaning | unit | default |
/// |---|---|---|---|
/// | `raw_per_celsius` | temperature-sensor scale | raw units / °C | 200 |
/// | `raw_at_zero_celsius` | temperature-sensor reading at 0 °C | raw units | 0 |
/// | `ambient_margin_celsius` | how far outside the calibrated range before flagging | °C | 0.5 |
/// | `rise_margin_celsius` | how far outside the stored curves' rise span before flagging | °C | 0.05 |
/// | `stuck_after_samples` | identical raw readings in a row that count as a stuck sensor (0: never) | samples | 2000 |
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Settings {
    /// Temperature-sensor scale, raw units per °C (the paper's unit: 200).
    pub raw_per_celsius: f32,
    /// Temperature-sensor reading at 0 °C, raw units.
    pub raw_at_zero_celsius: f32,
    /// Switch-on temperatures (and polynomial temperatures) further than this outside the calibrated
    /// range are flagged; inside it, the clamp is considered part of the calibration.
    pub ambient_margin_celsius: f32,
    /// Rises further than this outside the span of the stored curves are flagged. Covers sensor
    /// quantisation and noise near switch-on, where the rise is close to zero.
    pub rise_margin_celsius: f32,
    /// Number of identical raw temperature readings in a row after which the sensor counts as stuck.
    /// At 1000 Hz and 200 raw units per °C a live sensor's noise changes the reading far more often.
    /// 0 disables the check.
    pub stuck_after_samples: u16,
}

impl Default for Settings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl Settings {
    /// The defaults ([`Default`]) as a constant, for `const` and `static` tables.
    pub const DEFAULT: Self = Self {
        raw_per_celsius: 200.0,
        raw_at_zero_celsius: 0.0,
        ambient_margin_celsius: 0.5,
        rise_margin_celsius: 0.05,
        stuck_after_samples: 2000,
    };

    /// Every field zero (a scale of 0 raw units per °C, which validation rejects): the settings of
    /// empty tables, so that a `static` holding them is all-zero bytes and the linker places it in
    /// `.bss` (zeroed at start-up) rather than copying its initial value from flash.
    pub const ZEROED: Self = Self {
        raw_per_celsius: 0.0,
        raw_at_zero_celsius: 0.0,
        ambient_margin_celsius: 0.0,
        rise_margin_celsius: 0.0,
        stuck_after_samples: 0,
    };

    /// Checks that every value is finite and in its documented range.
    pub fn validate(&self) -> Result<(), Error> {
        let at = Location::default();
        let finite = [
            ("raw_per_celsius", self.raw_per_celsius),
            ("raw_at_zero_celsius", self.raw_at_zero_celsius),
            ("ambient_margin_celsius", self.ambient_margin_celsius),
            ("rise_margin_celsius", self.rise_margin_celsius),
        ];
        for (field, value) in finite {
            if !value.is_finite() {
                return Err(Error::new(field, at, Problem::NonFinite));
            }
        }
        if self.raw_per_celsius <= 0.0 {
            return Err(Error::new("raw_per_celsius", at, Problem::NotPositive));
        }
        for (field, value) in [
            ("ambient_margin_celsius", self.ambient_margin_celsius),
            ("rise_margin_celsius", self.rise_margin_celsius),
        ] {
            if value < 0.0 {
                return Err(Error::new(field, at, Problem::Negative));
            }
        }
        Ok(())
    }

    /// Converts a raw temperature reading to °C.
    #[inline]
    pub fn celsius(&self, raw: f32) -> f32 {
        self.celsius_with(raw, self.celsius_per_raw())
    }

    /// °C per raw unit, the reciprocal of `raw_per_celsius`: computed once per sample, so that the
    /// conversions of every axis multiply instead of dividing.
    #[inline]
    pub(crate) fn celsius_per_raw(&self) -> f32 {
        1.0 / self.raw_per_celsius
    }

    /// [`Self::celsius`] with `celsius_per_raw` already computed (the same bits).
    #[inline]
    pub(crate) fn celsius_with(&self, raw: f32, celsius_per_raw: f32) -> f32 {
        (raw - self.raw_at_zero_celsius) * celsius_per_raw
    }
}
