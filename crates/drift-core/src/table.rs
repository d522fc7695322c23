//! The paper's correlation tables: per axis, per calibration ambient, per activation curve. The data
//! and its validation only; the stages that read it and the model they make are `stage` and
//! `modified`.

use heapless::Vec;

use crate::error::{check_increasing, check_len, Error, Location, Problem};
use crate::extension::Extension;
use crate::model::Model;
use crate::settings::Settings;
use crate::warm_start::{self, WarmStart};
use crate::AXES;

/// The largest plausible |k|, (°/s) per °C, and the largest plausible drift a stored point stands
/// for, |k · rise|, °/s: 100 °/s of drift, or of drift per degree of self-heating, is beyond any
/// gyro (MEMS parts drift by hundredths to tenths). A point beyond both is a unit slip or a broken
/// fit, refused when the tables are validated rather than corrected with at run time. Either alone
/// is not refused: where the rise at a reference time is near zero (early after switch-on, a
/// sensor that barely warms) `k = drift / rise` is steep for a small drift, and the closed loop's
/// refits without a candidate term can store a large drift on a moderate `k` before the guard
/// judges the term on held-out data.
pub const MAX_PLAUSIBLE_K: u16 = 100;
/// See [`MAX_PLAUSIBLE_K`].
pub const MAX_PLAUSIBLE_STORED_DRIFT_DPS: u16 = 100;
/// The largest plausible |rise| since switch-on, °C (a unit's self-heating is a few to tens of °C).
pub const MAX_PLAUSIBLE_RISE_CELSIUS: u16 = 500;

/// One point of a heating-dynamics curve: where the curve stood at one reference time.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct CurvePoint {
    /// Temperature rise since switch-on that the curve had reached, °C.
    pub rise_celsius: f32,
    /// Correlation `k = drift / rise` there, (°/s) per °C.
    pub k_dps_per_celsius: f32,
}

impl CurvePoint {
    /// Rise 0, `k` 0 ([`Default`] as a constant).
    pub const ZERO: Self = Self {
        rise_celsius: 0.0,
        k_dps_per_celsius: 0.0,
    };
}

/// One heating-dynamics curve (one activation curve of the calibration: an interval × activation
/// number, or the merged "independent" first activations): one point per reference time of its axis.
///
/// Rise and `k` sit side by side because the corrector always reads them together.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Curve<const R: usize> {
    /// The curve at each reference time.
    pub points: Vec<CurvePoint, R>,
}

/// All curves of one axis at one calibration ambient, and the initial bias there.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AmbientCurves<const R: usize, const C: usize> {
    /// Switch-on sensor temperature of this calibration point (fully cooled unit), °C.
    pub ambient_celsius: f32,
    /// Initial (switch-on) bias at this temperature, °/s. Interpolated linearly between ambients.
    pub initial_bias_dps: f32,
    /// Heating-dynamics curves. Keyed by rise (the paper, `residual_heat_celsius` empty): ordered
    /// so that at every reference time each curve's rise is strictly greater than the previous
    /// curve's. Keyed by history: one activation history per curve, in the order of
    /// `residual_heat_celsius`.
    pub curves: Vec<Curve<R>, C>,
    /// Stage 3 keyed by heating history (optional): each curve's residual heat at switch-on (how
    /// far its switch-on temperature stood above the ambient, °C), strictly increasing, the first
    /// one the fully cooled start. Empty: stage 3 finds the curves by the current rise, as the
    /// paper does. The same for every ambient of an axis: all empty or one per curve.
    ///
    /// Why: when a warm start heats faster than a cold one, the curves cross and the rise no longer
    /// names the history (docs/closed-loop.md); the residual heat does, if the firmware keeps the
    /// ambient across power-off ([`crate::CorrectorState::power_on_after`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub residual_heat_celsius: Vec<f32, C>,
    /// The initial bias of warm starts (optional), in increasing residual heat: a start at this
    /// ambient with that much residual heat begins at `initial_bias_dps` plus the offset, found by
    /// the ambient and residual heat firmware estimates
    /// ([`crate::CorrectorState::power_on_after`]). Empty: the paper's initial bias, a function of
    /// the switch-on temperature alone. Independent of how stage 3 is keyed; the same for every
    /// ambient of an axis: all empty or none.
    ///
    /// Why: after a short off-time the sensing element is not at the sensor's temperature and is
    /// still cooling when the unit switches on, so its bias starts elsewhere (docs/closed-loop.md).
    #[cfg_attr(feature = "serde", serde(default))]
    pub warm_starts: Vec<WarmStart, C>,
}

/// The correlation table of one axis.
///
/// Capacities are const generics (`R` reference times, `A` ambients, `C` curves per ambient), so a
/// firmware build sizes the table exactly and a host build can be generous; the counts actually
/// used are the vectors' lengths.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
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
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ModifiedTables<const R: usize = 16, const A: usize = 12, const C: usize = 32> {
    /// Sensor conversion and envelope settings.
    pub settings: Settings,
    /// One table per axis (X, Y, Z).
    pub axes: [AxisTable<R, A, C>; AXES],
    /// Extra linear terms (the extended model); empty for the paper's model as published (and
    /// when a JSON form leaves them out).
    #[cfg_attr(feature = "serde", serde(default))]
    pub extension: Extension,
}

impl<const R: usize, const A: usize, const C: usize> ModifiedTables<R, A, C> {
    /// Tables with no axis data and [`Settings::ZEROED`] (which validation rejects) and no
    /// extension: a constant whose bytes are all zero, so that firmware places the tables in a
    /// `static` that the linker puts in `.bss` (no flash copy of the tables' size) and fills them
    /// with `blob::decode_into` (feature `serde`), without building them on the stack.
    pub const EMPTY: Self = Self {
        settings: Settings::ZEROED,
        axes: [AxisTable::EMPTY, AxisTable::EMPTY, AxisTable::EMPTY],
        extension: Extension::NONE,
    };

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
    /// An axis with no reference times and no ambients (which validation rejects).
    pub const EMPTY: Self = Self {
        reference_ms: Vec::new(),
        ambients: Vec::new(),
    };

    /// Whether stage 3 is keyed by the heating history (the curves carry their residual heat)
    /// rather than by the rise.
    pub fn keyed_by_history(&self) -> bool {
        self.ambients
            .first()
            .is_some_and(|a| !a.residual_heat_celsius.is_empty())
    }

    /// Whether the initial bias depends on the residual heat at switch-on
    /// ([`AmbientCurves::warm_starts`]).
    pub fn warm_started(&self) -> bool {
        self.ambients.iter().any(|a| !a.warm_starts.is_empty())
    }

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
        let by_history = self.keyed_by_history();
        let warm_started = self.warm_started();
        for (a, ambient) in self.ambients.iter().enumerate() {
            let at = at.ambient(a);
            if !ambient.initial_bias_dps.is_finite() {
                return Err(Error::new("initial_bias_dps", at, Problem::NonFinite));
            }
            warm_start::validate(&ambient.warm_starts, at)?;
            if ambient.warm_starts.is_empty() && warm_started {
                return Err(Error::new("warm_starts", at, Problem::Empty));
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
                    check_point(point, at.point(j))?;
                }
            }
            if by_history {
                check_len(
                    "residual_heat_celsius",
                    at,
                    ambient.curves.len(),
                    ambient.residual_heat_celsius.len(),
                )?;
                check_increasing(
                    "residual_heat_celsius",
                    at,
                    ambient.residual_heat_celsius.iter().copied(),
                )?;
                continue;
            }
            check_len(
                "residual_heat_celsius",
                at,
                0,
                ambient.residual_heat_celsius.len(),
            )?;
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

/// A stored point: finite, a rise within [`MAX_PLAUSIBLE_RISE_CELSIUS`], and `k` within
/// [`MAX_PLAUSIBLE_K`] or the drift it stands for within [`MAX_PLAUSIBLE_STORED_DRIFT_DPS`].
fn check_point(point: &CurvePoint, at: Location) -> Result<(), Error> {
    let (rise, k) = (point.rise_celsius, point.k_dps_per_celsius);
    if !rise.is_finite() {
        return Err(Error::new("rise_celsius", at, Problem::NonFinite));
    }
    if !k.is_finite() {
        return Err(Error::new("k_dps_per_celsius", at, Problem::NonFinite));
    }
    let limit = MAX_PLAUSIBLE_RISE_CELSIUS;
    if rise.abs() > f32::from(limit) {
        return Err(Error::new(
            "rise_celsius",
            at,
            Problem::Implausible { limit },
        ));
    }
    let limit = MAX_PLAUSIBLE_STORED_DRIFT_DPS;
    if k.abs() > f32::from(MAX_PLAUSIBLE_K) && (k * rise).abs() > f32::from(limit) {
        return Err(Error::new(
            "k_dps_per_celsius",
            at,
            Problem::ImplausibleDrift { limit },
        ));
    }
    Ok(())
}
