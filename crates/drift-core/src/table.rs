//! The paper's correlation tables: per axis, per calibration ambient, per activation curve.

use heapless::Vec;

use crate::error::{check_increasing, check_len, Error, Location, Problem};
use crate::extension::Extension;
use crate::flags::Flags;
use crate::model::{AxisModel, Model};
use crate::settings::Settings;
use crate::stage::ambient::AmbientPosition;
use crate::stage::heating::{cached_k, search, BlendedCurves, Knots};
use crate::stage::since_power_on::{Moment, Segment, SegmentKind};
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
/// calibration ambients (fixed for the activation), the current reference-time segment (stage 1)
/// and stage 3's bracket with its knots for that segment.
///
/// The segment and the bracket only make the next sample cheaper; they never change a result.
/// Kept field by field rather than as an [`AmbientPosition`] and a [`Segment`], so that the
/// one-byte indices share one word: a unit's state stays within 256 bytes (issue 2).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ModifiedAxisState {
    ambient_weight: f32,
    ambient_lo: u8,
    segment_start_ms: u32,
    segment_len_ms: u32,
    segment_per_ms: f32,
    segment_lo: u8,
    segment_kind: SegmentKind,
    knots: [Knots; 2],
    curve: u8,
}

impl ModifiedAxisState {
    /// The state of an activation that switched on at `ambient` (stage 2's position), with no
    /// segment and the searches starting at the first reference time and the first curve.
    pub fn new(ambient: &AmbientPosition) -> Self {
        Self {
            ambient_weight: ambient.weight,
            ambient_lo: ambient.lo,
            ..Self::default()
        }
    }

    /// The same state with its searches starting at reference time `segment` and curve `curve`
    /// (while no segment is cached): for tests that hints never change a result.
    #[must_use]
    pub fn with_hints(self, segment: u8, curve: u8) -> Self {
        Self {
            segment_lo: segment,
            curve,
            ..self
        }
    }

    /// The reference-time segment of the last sample (empty before the first one).
    pub fn segment(&self) -> Segment {
        Segment {
            start_ms: self.segment_start_ms,
            len_ms: self.segment_len_ms,
            per_ms: self.segment_per_ms,
            lo: self.segment_lo,
            kind: self.segment_kind,
        }
    }

    fn set_segment(&mut self, segment: Segment) {
        self.segment_start_ms = segment.start_ms;
        self.segment_len_ms = segment.len_ms;
        self.segment_per_ms = segment.per_ms;
        self.segment_lo = segment.lo;
        self.segment_kind = segment.kind;
    }
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
        *state = ModifiedAxisState::new(&ambient);
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

    #[inline(always)]
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
    /// `state` comes from this axis's power-on (its ambient position); its segment and bracket are
    /// updated. While the time stays in the segment and the rise in the bracket (almost every
    /// sample), no table is read.
    #[inline(always)]
    pub fn correlation(
        &self,
        settings: &Settings,
        state: &mut ModifiedAxisState,
        since_power_on_ms: u32,
        rise_celsius: f32,
    ) -> (f32, Flags) {
        let segment = state.segment();
        if let Some(moment) = segment.moment(since_power_on_ms) {
            let margin = settings.rise_margin_celsius;
            if let Some((k, beyond)) =
                cached_k(&state.knots, state.curve, moment, rise_celsius, margin)
            {
                return (k, flags(beyond, segment.kind));
            }
        }
        self.correlation_searched(settings, state, since_power_on_ms, rise_celsius)
    }

    /// [`Self::correlation`] when the time left the cached segment or the rise left the bracket:
    /// locates the segment if needed and searches the blended curves. Out of line: a few samples
    /// per segment.
    #[inline(never)]
    fn correlation_searched(
        &self,
        settings: &Settings,
        state: &mut ModifiedAxisState,
        since_power_on_ms: u32,
        rise_celsius: f32,
    ) -> (f32, Flags) {
        let mut segment = state.segment();
        let moment = segment.moment(since_power_on_ms).unwrap_or_else(|| {
            segment = Segment::locate(&self.reference_ms, since_power_on_ms, segment.lo);
            state.set_segment(segment);
            segment.moment(since_power_on_ms).unwrap_or(Moment {
                fraction: f32::NAN,
                before_first: false,
            })
        });
        let curves = BlendedCurves::new(
            &self.ambients,
            state.ambient_lo,
            state.ambient_weight,
            &segment,
        );
        let (k, beyond) = search(
            &curves,
            moment,
            rise_celsius,
            settings.rise_margin_celsius,
            &mut state.knots,
            &mut state.curve,
        );
        (k, flags(beyond, segment.kind))
    }
}

/// The modified model's envelope flags for one sample.
#[inline(always)]
fn flags(rise_out_of_span: bool, kind: SegmentKind) -> Flags {
    let mut flags = Flags::NONE;
    if rise_out_of_span {
        flags |= Flags::RISE_OUT_OF_SPAN;
    }
    if kind == SegmentKind::PastLast {
        flags |= Flags::PAST_LAST_REFERENCE;
    }
    flags
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
