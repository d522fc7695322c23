//! Settings shared by every model: how raw temperature maps to °C and when to flag.
//!
//! Firmware states its sensor in physical units ([`SensorSettings`]: scale, offset, sample rate,
//! stuck timeout in seconds); [`Settings::from_sensor`] converts them once, in a `const fn`, into
//! the per-sample form the corrector reads (a count of samples, no division per sample).

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
/// | `sample_rate_hz` | the sample rate `stuck_after_samples` was converted at (0: not stated) | Hz | 0 |
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
    /// The sample rate `stuck_after_samples` was converted at from seconds
    /// ([`Settings::from_sensor`]), Hz, so firmware can check its own rate against the image's;
    /// 0: not stated (settings given in samples, and images before format version 3). The
    /// corrector does not read it: time comes with each sample.
    #[cfg_attr(feature = "serde", serde(default))]
    pub sample_rate_hz: f32,
}

/// A temperature sensor and its stuck-sensor timeout in physical units, what a firmware team reads
/// off a data sheet. [`Settings::from_sensor`] turns it into [`Settings`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorSettings {
    /// Scale: raw counts per °C (a data sheet's "LSB/°C").
    pub raw_per_celsius: f32,
    /// Raw reading at 0 °C (for a sensor that reads 0 at 25 °C with 256 LSB/°C: −6400).
    pub raw_at_zero_celsius: f32,
    /// Samples per second the corrector is called at, Hz.
    pub sample_rate_hz: f32,
    /// How long an unchanged reading lasts before the sensor counts as stuck, s; 0: never.
    pub stuck_after_seconds: f32,
    /// As [`Settings::ambient_margin_celsius`].
    pub ambient_margin_celsius: f32,
    /// As [`Settings::rise_margin_celsius`].
    pub rise_margin_celsius: f32,
}

impl SensorSettings {
    /// The defaults at 1000 Hz: 200 raw units per °C, 0 at 0 °C, stuck after 2 s, the margins of
    /// [`Settings::DEFAULT`]. [`Settings::from_sensor`] gives the default's 2000 samples.
    pub const DEFAULT: Self = Self {
        raw_per_celsius: Settings::DEFAULT.raw_per_celsius,
        raw_at_zero_celsius: Settings::DEFAULT.raw_at_zero_celsius,
        sample_rate_hz: 1000.0,
        stuck_after_seconds: 2.0,
        ambient_margin_celsius: Settings::DEFAULT.ambient_margin_celsius,
        rise_margin_celsius: Settings::DEFAULT.rise_margin_celsius,
    };
}

impl Default for SensorSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The raw temperature count that means "no reading this sample" in [`Sample::from_counts`](crate::Sample::from_counts):
/// `i16::MIN`, which no 16-bit sensor reports as a temperature. The sample's temperature is NaN,
/// flagged `TEMPERATURE_INVALID`, and the last good drift is held.
pub const MISSING_TEMPERATURE: i16 = i16::MIN;

const fn settings_error(field: &'static str, problem: Problem) -> Error {
    Error::new(
        field,
        Location {
            axis: None,
            ambient: None,
            curve: None,
            point: None,
            index: None,
        },
        problem,
    )
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
        sample_rate_hz: 0.0,
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
        sample_rate_hz: 0.0,
    };

    /// Settings from a sensor in physical units: the stuck timeout converted to samples once,
    /// here (rounded to the nearest), so the corrector counts samples and never divides for it. A
    /// `const fn`, so firmware can hold the result in a `const` or `static`:
    ///
    /// ```
    /// use drift_core::{SensorSettings, Settings};
    /// // A sensor with 256 LSB/°C reading 0 at 25 °C, sampled at 833 Hz, stuck after 1.5 s.
    /// const SETTINGS: Result<Settings, drift_core::Error> = Settings::from_sensor(&SensorSettings {
    ///     raw_per_celsius: 256.0,
    ///     raw_at_zero_celsius: -6400.0,
    ///     sample_rate_hz: 833.0,
    ///     stuck_after_seconds: 1.5,
    ///     ..SensorSettings::DEFAULT
    /// });
    /// let settings = SETTINGS?;
    /// assert_eq!(settings.stuck_after_samples, 1250); // 1249.5, rounded
    /// assert_eq!(settings.stuck_after_seconds(), Some(1250.0 / 833.0));
    /// # Ok::<(), drift_core::Error>(())
    /// ```
    ///
    /// Errors name the field: a non-finite value, a scale or rate not above zero, a negative
    /// timeout or margin, or a timeout longer than 65 535 samples at that rate
    /// (`stuck_after_seconds`, [`Problem::TooManySamples`]).
    pub const fn from_sensor(sensor: &SensorSettings) -> Result<Self, Error> {
        let finite = [
            ("raw_per_celsius", sensor.raw_per_celsius),
            ("raw_at_zero_celsius", sensor.raw_at_zero_celsius),
            ("sample_rate_hz", sensor.sample_rate_hz),
            ("stuck_after_seconds", sensor.stuck_after_seconds),
            ("ambient_margin_celsius", sensor.ambient_margin_celsius),
            ("rise_margin_celsius", sensor.rise_margin_celsius),
        ];
        let mut rest: &[(&'static str, f32)] = &finite;
        while let [(field, value), tail @ ..] = rest {
            if !value.is_finite() {
                return Err(settings_error(field, Problem::NonFinite));
            }
            rest = tail;
        }
        if sensor.raw_per_celsius <= 0.0 {
            return Err(settings_error("raw_per_celsius", Problem::NotPositive));
        }
        if sensor.sample_rate_hz <= 0.0 {
            return Err(settings_error("sample_rate_hz", Problem::NotPositive));
        }
        let non_negative = [
            ("stuck_after_seconds", sensor.stuck_after_seconds),
            ("ambient_margin_celsius", sensor.ambient_margin_celsius),
            ("rise_margin_celsius", sensor.rise_margin_celsius),
        ];
        let mut rest: &[(&'static str, f32)] = &non_negative;
        while let [(field, value), tail @ ..] = rest {
            if *value < 0.0 {
                return Err(settings_error(field, Problem::Negative));
            }
            rest = tail;
        }
        // Both finite and not negative: `samples` is at least 0.5, or infinite on overflow.
        let samples = sensor.stuck_after_seconds * sensor.sample_rate_hz + 0.5;
        if samples >= u16::MAX as f32 + 1.0 {
            return Err(settings_error(
                "stuck_after_seconds",
                Problem::TooManySamples { limit: u16::MAX },
            ));
        }
        // In 0.5..65 536 (checked above): the cast truncates to the nearest whole number of samples.
        #[allow(clippy::cast_possible_truncation)]
        let samples = samples as u16;
        Ok(Self {
            raw_per_celsius: sensor.raw_per_celsius,
            raw_at_zero_celsius: sensor.raw_at_zero_celsius,
            ambient_margin_celsius: sensor.ambient_margin_celsius,
            rise_margin_celsius: sensor.rise_margin_celsius,
            stuck_after_samples: samples,
            sample_rate_hz: sensor.sample_rate_hz,
        })
    }

    /// The stuck timeout in seconds, when the sample rate is stated: `stuck_after_samples`
    /// divided by `sample_rate_hz`.
    pub fn stuck_after_seconds(&self) -> Option<f32> {
        (self.sample_rate_hz > 0.0)
            .then(|| f32::from(self.stuck_after_samples) / self.sample_rate_hz)
    }

    /// Checks that every value is finite and in its documented range.
    pub fn validate(&self) -> Result<(), Error> {
        let at = Location::default();
        let finite = [
            ("raw_per_celsius", self.raw_per_celsius),
            ("raw_at_zero_celsius", self.raw_at_zero_celsius),
            ("ambient_margin_celsius", self.ambient_margin_celsius),
            ("rise_margin_celsius", self.rise_margin_celsius),
            ("sample_rate_hz", self.sample_rate_hz),
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
            ("sample_rate_hz", self.sample_rate_hz),
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
