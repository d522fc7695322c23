//! The paper's correlation tables: per axis, per calibration ambient, per activation curve.

use heapless::Vec;

use crate::error::{check_finite, check_increasing, check_len, Error, Location, Problem};
use crate::flags::Flags;
use crate::model::{AxisModel, Model};
use crate::settings::Settings;
use crate::stage::ambient::AmbientPosition;
use crate::stage::heating;
use crate::stage::since_power_on::TimePosition;
use crate::AXES;

/// One heating-dynamics curve (one activation curve of the calibration: an interval × activation
/// number, or the merged "independent" first activations), sampled at the axis's reference times.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Curve<const R: usize> {
    /// Temperature rise since switch-on that this curve had reached at each reference time, °C.
    pub rise_celsius: Vec<f32, R>,
    /// Correlation `k = drift / rise` at each reference time, (°/s) per °C.
    pub k_dps_per_celsius: Vec<f32, R>,
}

/// All curves of one axis at one calibration ambient, and the initial bias there.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AmbientCurves<const R: usize, const C: usize> {
    /// Switch-on sensor temperature of this calibration point (fully cooled unit), °C.
    pub ambient_celsius: f32,
    /// Initial (switch-on) bias at this temperature, °/s. Interpolated linearly between ambients.
    pub initial_bias_dps: f32,
    /// Heating-dynamics curves, ordered so that at every reference time each curve's rise is
    /// strictly greater than the previous curve's.
    pub curves: Vec<Curve<R>, C>,
}

/// The correlation table of one axis.
///
/// Capacities are const generics (`R` reference times, `A` ambients, `C` curves per ambient), so a
/// firmware build sizes the table exactly and a host build can be generous; the counts actually
/// used are the vectors' lengths.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AxisTable<const R: usize, const A: usize, const C: usize> {
    /// Reference times since switch-on, milliseconds, strictly increasing, the first one > 0
    /// (where the rise is already measurable).
    pub reference_ms: Vec<u32, R>,
    /// Calibration ambients, strictly increasing in `ambient_celsius`.
    pub ambients: Vec<AmbientCurves<R, C>, A>,
}

/// The paper's ("modified") model for a whole unit: settings and one table per axis.
///
/// Default capacities (16 reference times, 8 ambients, 32 curves per ambient) suit host analysis;
/// firmware names its own, e.g. `ModifiedTables<8, 3, 16>`.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ModifiedTables<const R: usize = 16, const A: usize = 8, const C: usize = 32> {
    /// Sensor conversion and envelope settings.
    pub settings: Settings,
    /// One table per axis (X, Y, Z).
    pub axes: [AxisTable<R, A, C>; AXES],
}

impl<const R: usize, const A: usize, const C: usize> ModifiedTables<R, A, C> {
    /// The validating constructor: returns the tables only if [`Model::validate`] accepts them.
    pub fn try_new(settings: Settings, axes: [AxisTable<R, A, C>; AXES]) -> Result<Self, Error> {
        let tables = Self { settings, axes };
        tables.validate()?;
        Ok(tables)
    }
}

impl<const R: usize, const A: usize, const C: usize> AxisTable<R, A, C> {
    /// Checks this axis's table; `at` names the axis in errors.
    pub fn validate(&self, at: Location) -> Result<(), Error> {
        let references = self.reference_ms.len();
        if references == 0 {
            return Err(Error::new("reference_ms", at, Problem::Empty));
        }
        if self.reference_ms.first() == Some(&0) {
            return Err(Error::new("reference_ms", at.index(0), Problem::NotPositive));
        }
        if let Some(index) = self
            .reference_ms
            .windows(2)
            .position(|pair| matches!(pair, [a, b] if b <= a))
        {
            return Err(Error::new(
                "reference_ms",
                at.index(index.saturating_add(1)),
                Problem::NotIncreasing,
            ));
        }
        if self.ambients.is_empty() {
            return Err(Error::new("ambients", at, Problem::Empty));
        }
        check_increasing(
            "ambient_celsius",
            at,
            self.ambients.iter().map(|a| a.ambient_celsius),
        )?;
        for (a, ambient) in self.ambients.iter().enumerate() {
            let at = at.ambient(a);
            check_finite("initial_bias_dps", at, [ambient.initial_bias_dps])?;
            if ambient.curves.is_empty() {
                return Err(Error::new("curves", at, Problem::Empty));
            }
            for (c, curve) in ambient.curves.iter().enumerate() {
                let at = at.curve(c);
                check_len("rise_celsius", at, references, curve.rise_celsius.len())?;
                check_len(
                    "k_dps_per_celsius",
                    at,
                    references,
                    curve.k_dps_per_celsius.len(),
                )?;
                check_finite("rise_celsius", at, curve.rise_celsius.iter().copied())?;
                check_finite(
                    "k_dps_per_celsius",
                    at,
                    curve.k_dps_per_celsius.iter().copied(),
                )?;
            }
            // At every reference time the curves must be ordered by rise, for the heating stage's
            // bracket search.
            for j in 0..references {
                let rises = ambient
                    .curves
                    .iter()
                    .map(|curve| curve.rise_celsius.get(j).copied().unwrap_or(f32::NAN));
                let mut previous = f32::NEG_INFINITY;
                for (c, rise) in rises.enumerate() {
                    if rise <= previous {
                        return Err(Error::new(
                            "rise_celsius",
                            at.curve(c).index(j),
                            Problem::NotIncreasing,
                        ));
                    }
                    previous = rise;
                }
            }
        }
        Ok(())
    }
}

/// Per-axis run-time state of the modified model: where the switch-on temperature fell among the
/// calibration ambients (fixed for the activation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ModifiedAxisState {
    /// Stage 2's position, located at switch-on.
    pub ambient: AmbientPosition,
}

impl<const R: usize, const A: usize, const C: usize> AxisModel for AxisTable<R, A, C> {
    type State = ModifiedAxisState;

    fn power_on(
        &self,
        settings: &Settings,
        switch_on_celsius: f32,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        let ambient = AmbientPosition::locate(
            &self.ambients,
            switch_on_celsius,
            settings.ambient_margin_celsius,
            |a| a.ambient_celsius,
        );
        state.ambient = ambient;
        let bias_at = |i: u8| {
            self.ambients
                .get(usize::from(i))
                .map_or(f32::NAN, |a| a.initial_bias_dps)
        };
        let initial_bias = ambient.blend(bias_at(ambient.lo), bias_at(ambient.hi));
        let flags = if ambient.out_of_range {
            Flags::AMBIENT_OUT_OF_RANGE
        } else {
            Flags::NONE
        };
        (initial_bias, flags)
    }

    fn drift(
        &self,
        settings: &Settings,
        state: &mut Self::State,
        since_power_on_ms: u32,
        _temperature_celsius: f32,
        rise_celsius: f32,
    ) -> (f32, Flags) {
        let time = TimePosition::locate(&self.reference_ms, since_power_on_ms);
        let margin = settings.rise_margin_celsius;
        let k_in = |i: u8| {
            self.ambients.get(usize::from(i)).map_or((f32::NAN, false), |a| {
                heating::k_at(&a.curves, &time, rise_celsius, margin)
            })
        };
        let ambient = state.ambient;
        let (k_lo, mut out_of_span) = k_in(ambient.lo);
        let k = if ambient.hi == ambient.lo {
            k_lo
        } else {
            let (k_hi, hi_out_of_span) = k_in(ambient.hi);
            out_of_span |= hi_out_of_span;
            ambient.blend(k_lo, k_hi)
        };
        let mut flags = Flags::NONE;
        if out_of_span {
            flags |= Flags::RISE_OUT_OF_SPAN;
        }
        if time.past_last {
            flags |= Flags::PAST_LAST_REFERENCE;
        }
        (k * rise_celsius, flags)
    }
}

impl<const R: usize, const A: usize, const C: usize> Model for ModifiedTables<R, A, C> {
    type Axis = AxisTable<R, A, C>;

    fn settings(&self) -> &Settings {
        &self.settings
    }

    fn axes(&self) -> &[Self::Axis; AXES] {
        &self.axes
    }

    fn validate(&self) -> Result<(), Error> {
        self.settings.validate()?;
        for (axis, table) in self.axes.iter().enumerate() {
            table.validate(Location::axis(axis))?;
        }
        Ok(())
    }
}
