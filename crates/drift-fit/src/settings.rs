//! Fitting settings, in physical units, with the paper's values as defaults.

use serde::{Deserialize, Serialize};

/// How the tables are fitted. Every field has a unit in its name and a documented default; a
/// missing field keeps its default, an unknown (misspelt) one is an error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitSettings {
    /// Low-pass: centred moving average over this many seconds ("a window at the operating
    /// frequency (1000)": 1000 samples at the paper's 1000 Hz), converted with each recording's
    /// own sample rate ([`Self::lowpass_window`]).
    pub lowpass_window_s: f64,
    /// Analysis grid: the low-passed curves are kept every this many milliseconds.
    pub grid_ms: u32,
    /// The initial (switch-on) bias is the intercept of the rate against the temperature rise
    /// over this first part of the activation, seconds.
    pub initial_bias_window_s: f64,
    /// The switch-on temperature is the mean of this first part of the activation, ms.
    pub switch_on_window_ms: u32,
    /// First reference time, s: where the rise has become measurable (the paper's first point: 2 s).
    pub first_reference_s: f64,
    /// Number of reference times per axis, the first included (greedy largest-error insertion).
    pub reference_count: usize,
    /// The value at a reference time is the mean of this many correlation samples around it
    /// (the paper's `d_j = Σ gt_(i−5) / 10`), on the analysis grid.
    pub reference_window_points: usize,
    /// Series with an interval of at least this many minutes are "independent" (like a first
    /// activation after a full cool-down) and merged into one curve.
    pub independent_after_min: f64,
    /// Degree of the PX4/ArduPilot-style least-squares polynomial baseline.
    pub polynomial_degree: usize,
}

impl Default for FitSettings {
    fn default() -> Self {
        Self {
            lowpass_window_s: 1.0,
            grid_ms: 10,
            initial_bias_window_s: 4.0,
            switch_on_window_ms: 20,
            first_reference_s: 2.0,
            reference_count: 8,
            reference_window_points: 10,
            independent_after_min: 15.0,
            polynomial_degree: 3,
        }
    }
}

impl FitSettings {
    /// The low-pass window in samples at `sample_rate_hz`: [`Self::lowpass_window_s`] of the
    /// recording's own samples, at least one. Every metric and fit reads the window through this,
    /// so one campaign gives the same figures at any rate.
    pub fn lowpass_window(&self, sample_rate_hz: u32) -> usize {
        let samples = (self.lowpass_window_s * f64::from(sample_rate_hz)).round();
        if samples.is_finite() && samples >= 1.0 {
            samples as usize
        } else {
            1
        }
    }
}

impl FitSettings {
    /// The analysis grid at `sample_rate_hz`, as (samples, ms): the smallest multiple of
    /// [`Self::grid_ms`] that is a whole number of samples, so that grid point `i` lies exactly
    /// `i · ms` after switch-on (10 ms is 2.5 samples at 250 Hz: the grid there is 20 ms). A
    /// thousand grid spacings are whole samples at every integer rate, so there always is one.
    pub fn grid_at(&self, sample_rate_hz: u32) -> (usize, u32) {
        let rate = u64::from(sample_rate_hz.max(1));
        let grid_ms = u64::from(self.grid_ms.max(1));
        (1..=1000)
            .map(|multiple| grid_ms * multiple)
            .find(|ms| ms * rate % 1000 == 0)
            .and_then(|ms| Some(((ms * rate / 1000) as usize, u32::try_from(ms).ok()?)))
            .unwrap_or((rate as usize, 1000))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_is_a_duration_at_every_rate() {
        let settings = FitSettings::default();
        assert_eq!(settings.lowpass_window(1000), 1000);
        assert_eq!(settings.lowpass_window(200), 200);
        assert_eq!(settings.lowpass_window(100), 100);
        assert_eq!(settings.lowpass_window(0), 1);
    }

    #[test]
    fn the_grid_is_whole_samples_at_every_rate() {
        let settings = FitSettings::default();
        assert_eq!(settings.grid_at(1000), (10, 10));
        assert_eq!(settings.grid_at(200), (2, 10));
        assert_eq!(settings.grid_at(100), (1, 10));
        assert_eq!(settings.grid_at(250), (5, 20));
        assert_eq!(settings.grid_at(50), (1, 20));
        assert_eq!(settings.grid_at(10), (1, 100));
        assert_eq!(settings.grid_at(833), (833, 1000));
        for rate in 1..=2000 {
            let (samples, ms) = settings.grid_at(rate);
            assert_eq!(
                samples as u64 * 1000,
                u64::from(ms) * u64::from(rate),
                "{rate} Hz"
            );
            assert_eq!(ms % settings.grid_ms, 0, "{rate} Hz");
        }
    }
}
