//! The paper's correlation tables: per axis, per calibration ambient, per activation curve.

use heapless::Vec;

use crate::error::{check_increasing, check_len, Error, Location, Problem};
use crate::extension::Extension;
use crate::flags::Flags;
use crate::model::{AxisModel, Model};
use crate::settings::Settings;
use crate::stage::ambient::AmbientPosition;
use crate::stage::heating::{k_at, BracketCache};
use crate::stage::since_power_on::{Segment, TimePosition};
use crate::AXES;

/// One point of a heating-dynamics curve: where the curve stood at one reference time.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CurvePoint {
    /// Temperature rise since switch-on that the curve had reached, °C.
    pub rise_celsius: f32,
    /// Correlation `k = drift / rise` there, (°/s) per °C.
    pub k_dps_per_celsius: f32,
}

/// One heating-dynamics curve (one activation curve of the calibration: an interval × activation
/// number, or the merged "independent" first activations): one point per reference time of its axis.
///
/// Rise and `k` sit side by side because the corrector always reads them together.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Curve<const R: usize> {
    /// The curve at each reference time.
    pub points: Vec<CurvePoint, R>,
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
/// Default capacities (16 reference times, 12 ambients, 32 curves per ambient) suit host analysis;
/// firmware names its own, e.g. `ModifiedTables<8, 3, 16>`.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ModifiedTables<const R: usize = 16, const A: usize = 12, const C: usize = 32> {
    /// Sensor conversion and envelope settings.
    pub settings: Settings,
    /// One table per axis (X, Y, Z).
    pub axes: [AxisTable<R, A, C>; AXES],
    /// Extra linear terms (the extended model); empty for the paper's model as published. Tables
    /// written before the extended model existed read as empty.
    #[cfg_attr(feature = "serde", serde(default))]
    pub extension: Extension,
}

impl<const R: usize, const A: usize, const C: usize> ModifiedTables<R, A, C> {
    /// The validating constructor: returns the tables only if [`Model::validate`] accepts them.
    pub fn try_new(settings: Settings, axes: [AxisTable<R, A, C>; AXES]) -> Result<Self, Error> {
        let tables = Self {
            settings,
            axes,
            extension: Extension::NONE,
        };
        tables.validate()?;
        Ok(tables)
    }

    /// The same tables with extra terms; validates the whole.
    pub fn with_extension(self, extension: Extension) -> Result<Self, Error> {
        let tables = Self { extension, ..self };
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
            return Err(Error::new(
                "reference_ms",
                at.index(0),
                Problem::NotPositive,
            ));
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
            if !ambient.initial_bias_dps.is_finite() {
                return Err(Error::new("initial_bias_dps", at, Problem::NonFinite));
            }
            if ambient.curves.is_empty() {
                return Err(Error::new("curves", at, Problem::Empty));
            }
            // Curve c of every ambient is the same activation scenario: stage 2 blends them.
            let first_count = self.ambients.first().map_or(0, |a| a.curves.len());
            check_len("curves", at, first_count, ambient.curves.len())?;
            for (c, curve) in ambient.curves.iter().enumerate() {
                let at = at.curve(c);
                check_len("points", at, references, curve.points.len())?;
                for (j, point) in curve.points.iter().enumerate() {
                    for (field, value) in [
                        ("rise_celsius", point.rise_celsius),
                        ("k_dps_per_celsius", point.k_dps_per_celsius),
                    ] {
                        if !value.is_finite() {
                            return Err(Error::new(field, at.point(j), Problem::NonFinite));
                        }
                    }
                }
            }
            // At every reference time the curves must be ordered by rise, for the heating stage's
            // bracket search.
            for j in 0..references {
                let rises = ambient
                    .curves
                    .iter()
                    .map(|curve| curve.points.get(j).map_or(f32::NAN, |p| p.rise_celsius));
                let mut previous = f32::NEG_INFINITY;
                for (c, rise) in rises.enumerate() {
                    if rise <= previous {
                        return Err(Error::new(
                            "rise_celsius",
                            at.curve(c).point(j),
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
/// calibration ambients (fixed for the activation), and where the previous sample's searches ended.
///
/// The hints and the cache only make the next sample cheaper; they never change a result.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ModifiedAxisState {
    /// Stage 2's position, located at switch-on.
    pub ambient: AmbientPosition,
    /// Stage 1's last reference-time segment (where a search starts).
    pub segment_hint: u8,
    /// Stage 1's current segment, located when time entered it.
    pub segment: Segment,
    /// Stage 3's last bracket and its knots.
    pub bracket: BracketCache,
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
        *state = ModifiedAxisState {
            ambient,
            ..ModifiedAxisState::default()
        };
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
        let (k, flags) = self.correlation(settings, state, since_power_on_ms, rise_celsius);
        (k * rise_celsius, flags)
    }
}

impl<const R: usize, const A: usize, const C: usize> AxisTable<R, A, C> {
    /// The correlation `k` ((°/s) per °C) after the paper's three stages in its order: time since
    /// switch-on (stage 1), ambient (stage 2: the two bracketing calibration ambients' curves are
    /// blended curve by curve), heating dynamics (stage 3: the blended curves whose rises bracket the
    /// current rise). The drift is `k · rise`.
    ///
    /// `state` comes from this axis's power-on (its ambient position); its search hints and caches
    /// are updated.
    #[inline]
    pub fn correlation(
        &self,
        settings: &Settings,
        state: &mut ModifiedAxisState,
        since_power_on_ms: u32,
        rise_celsius: f32,
    ) -> (f32, Flags) {
        let (time, new_segment) = TimePosition::locate_cached(
            &self.reference_ms,
            since_power_on_ms,
            &mut state.segment_hint,
            &mut state.segment,
        );
        if new_segment {
            // The cached knots were read at the old segment's reference times.
            state.bracket.valid = false;
        }
        let (k, out_of_span) = k_at(
            &self.ambients,
            &state.ambient,
            time,
            rise_celsius,
            settings.rise_margin_celsius,
            &mut state.bracket,
        );
        let mut flags = Flags::NONE;
        if out_of_span {
            flags |= Flags::RISE_OUT_OF_SPAN;
        }
        if time.past_last {
            flags |= Flags::PAST_LAST_REFERENCE;
        }
        (k, flags)
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
        self.extension.validate()
    }

    fn extension(&self) -> &Extension {
        &self.extension
    }
}
