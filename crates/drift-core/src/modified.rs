//! The paper's ("modified") model at run time: the correlation tables read through the three
//! stages, per axis, and the per-axis state that makes the next sample cheap.

use heapless::Vec;

use crate::error::{Error, Location};
use crate::extension::Extension;
use crate::flags::Flags;
use crate::history::SwitchOn;
use crate::model::{AxisModel, ConstDefault, Model};
use crate::settings::Settings;
use crate::stage::ambient::AmbientPosition;
use crate::stage::heating::{by_history, cached_k, search, BlendedCurves, Knots};
use crate::stage::since_power_on::{Moment, Segment, SegmentKind};
use crate::table::{AxisTable, CurvePoint, ModifiedTables};
use crate::warm_start;
use crate::AXES;

/// Per-axis run-time state of the modified model: where the switch-on temperature fell among the
/// calibration ambients (fixed for the activation), the current reference-time segment (stage 1)
/// and stage 3's bracket with its knots for that segment.
///
/// The segment and the bracket only make the next sample cheaper; they never change a result.
/// Kept field by field rather than as an [`AmbientPosition`] and a [`Segment`], so that the
/// one-byte indices share one word: a unit's state stays within 256 bytes (docs/embedded.md).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ModifiedAxisState {
    ambient_weight: f32,
    ambient_lo: u8,
    segment_start_ms: u32,
    segment_len_ms: u32,
    segment_per_ms: f32,
    segment_lo: u8,
    segment_kind: SegmentKind,
    /// Stage 3's cache: the bracket's lower and upper knots (see `stage::heating::TOP`). A table
    /// keyed by history caches one (blended) curve and needs no upper one: there the second slot
    /// holds the activation's history position instead ([`Self::history`]), so that a unit's state
    /// stays within 256 bytes.
    knots: [Knots; 2],
    curve: u8,
}

impl ConstDefault for ModifiedAxisState {
    const DEFAULT: Self = Self {
        ambient_weight: 0.0,
        ambient_lo: 0,
        segment_start_ms: 0,
        segment_len_ms: 0,
        segment_per_ms: 0.0,
        segment_lo: 0,
        segment_kind: SegmentKind::BeforeFirst,
        knots: [[CurvePoint::ZERO; 2]; 2],
        curve: 0,
    };
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

    /// Tables keyed by history: the stored history below the activation's residual heat and the
    /// weight of the next one, fixed at switch-on.
    fn history(&self) -> (u8, f32) {
        let [_, [position, _]] = self.knots;
        (
            saturating_u8_of(position.k_dps_per_celsius),
            position.rise_celsius,
        )
    }

    fn set_history(&mut self, lo: u8, weight: f32) {
        let position = CurvePoint {
            rise_celsius: weight,
            k_dps_per_celsius: f32::from(lo),
        };
        self.knots[1] = [position, position];
    }

    fn set_segment(&mut self, segment: Segment) {
        self.segment_start_ms = segment.start_ms;
        self.segment_len_ms = segment.len_ms;
        self.segment_per_ms = segment.per_ms;
        self.segment_lo = segment.lo;
        self.segment_kind = segment.kind;
    }
}

impl<const R: usize, const A: usize, const C: usize> AxisTable<R, A, C> {
    /// The initial bias at stage 2's `position` after a start with `residual_heat_celsius` (0: a
    /// cold start, the paper's): the ambients' cold-start bias plus their warm starts' offset.
    fn initial_bias(&self, position: &AmbientPosition, residual_heat_celsius: f32) -> f32 {
        let at = |i: u8| {
            self.ambients.get(usize::from(i)).map_or(f32::NAN, |a| {
                a.initial_bias_dps + warm_start::offset_dps(&a.warm_starts, residual_heat_celsius)
            })
        };
        position.blend(at(position.lo), at(position.hi))
    }

    /// The warmest start stored at stage 2's `position` (blended), °C.
    fn warmest_start(&self, position: &AmbientPosition) -> f32 {
        let at = |i: u8| {
            self.ambients
                .get(usize::from(i))
                .and_then(|a| a.warm_starts.last())
                .map_or(0.0, |w| w.residual_heat_celsius)
        };
        position.blend(at(position.lo), at(position.hi))
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
        self.power_on_after(
            settings,
            &SwitchOn::estimate(switch_on_celsius, None),
            state,
        )
    }

    fn power_on_after(
        &self,
        settings: &Settings,
        switch_on: &SwitchOn,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        self.start(settings, switch_on, switch_on.switch_on_celsius, state)
    }

    fn power_on_at_ambient(
        &self,
        settings: &Settings,
        switch_on: &SwitchOn,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        self.start(settings, switch_on, switch_on.ambient_celsius, state)
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
    /// The switch-on: stage 2's position, stage 3's history and the initial bias. `paper_celsius`
    /// is where a table keyed by rise reads its ambient and the cold start's bias: the switch-on
    /// temperature, as the paper does, or an ambient the instrument measured.
    fn start(
        &self,
        settings: &Settings,
        switch_on: &SwitchOn,
        paper_celsius: f32,
        state: &mut ModifiedAxisState,
    ) -> (f32, Flags) {
        let by_history = self.keyed_by_history();
        let margin = settings.ambient_margin_celsius;
        let locate = |celsius| {
            AmbientPosition::locate(&self.ambients, celsius, margin, |a| a.ambient_celsius)
        };
        // The paper indexes ambient by the switch-on temperature, residual heat included, as its
        // calibration saw it; a table keyed by history was built against the ambient itself.
        let heat = switch_on.residual_heat_celsius;
        let (ambient, history) = if by_history {
            let ambient = locate(switch_on.ambient_celsius);
            // More residual heat than the calibration's shortest off-time left: the warmest
            // history's curve (clamp), flagged, like every other stage beyond its span. Why not a
            // cold start there: in use, off-times shorter than the calibration's are common and
            // such a start is nearer the warmest history than a cold one (measured:
            // docs/closed-loop.md). An ambient that rose during the off-time by more
            // than the unit cooled is told apart already (`SwitchOn::estimate`: a cold start).
            let history = self.locate_history(&ambient, heat, settings.rise_margin_celsius);
            (ambient, history)
        } else {
            (locate(paper_celsius), AmbientPosition::default())
        };
        *state = ModifiedAxisState::new(&ambient);
        let mut flags = if ambient.out_of_range {
            Flags::AMBIENT_OUT_OF_RANGE
        } else {
            Flags::NONE
        };
        let warm_started = self.warm_started();
        if (by_history || warm_started) && !switch_on.known {
            flags |= Flags::HISTORY_UNKNOWN;
        }
        if by_history {
            state.set_history(history.lo, history.weight);
            if history.out_of_range {
                flags |= Flags::HISTORY_OUT_OF_SPAN;
            }
        }
        // A warm start's initial bias is the calibration's at its ambient and residual heat, as the
        // calibration's series measured it. More residual heat than the warmest of them left: held
        // at the warmest, flagged. Why not the paper's cold start there: in use, off-times shorter
        // than the calibration's shortest interval are common and leave more heat than any
        // calibration start, and their offset is nearer the warmest start's than a cold start's
        // (measured: docs/closed-loop.md). An ambient that rose during the off-time by
        // more than the unit cooled is told apart already (`SwitchOn::estimate`: a cold start).
        if warm_started && heat > 0.0 {
            let at_ambient = if by_history {
                ambient
            } else {
                locate(switch_on.ambient_celsius)
            };
            if heat > self.warmest_start(&at_ambient) + settings.rise_margin_celsius {
                flags |= Flags::HISTORY_OUT_OF_SPAN;
            }
            return (self.initial_bias(&at_ambient, heat), flags);
        }
        // The paper's: the cold start's bias at the switch-on temperature or the measured
        // ambient (a table keyed by rise located the ambient there already: one search per
        // switch-on, not two).
        let at_paper = if by_history {
            locate(paper_celsius)
        } else {
            ambient
        };
        (self.initial_bias(&at_paper, 0.0), flags)
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
        let moment = segment.moment(since_power_on_ms);
        if let Some(moment) = moment {
            let margin = settings.rise_margin_celsius;
            if let Some((k, beyond)) =
                cached_k(&state.knots, state.curve, moment, rise_celsius, margin)
            {
                return (k, flags(beyond, segment.kind));
            }
        }
        self.correlation_searched(settings, state, since_power_on_ms, rise_celsius, moment)
    }

    /// [`Self::correlation`] when the time left the cached segment or the rise left the bracket:
    /// locates the segment if needed and searches the blended curves. Out of line: a few samples
    /// per segment. `moment` is the time in the cached segment, as the caller found it (`None`:
    /// outside).
    #[inline(never)]
    fn correlation_searched(
        &self,
        settings: &Settings,
        state: &mut ModifiedAxisState,
        since_power_on_ms: u32,
        rise_celsius: f32,
        moment: Option<Moment>,
    ) -> (f32, Flags) {
        let mut segment = state.segment();
        let moment = moment.unwrap_or_else(|| {
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
        if self.keyed_by_history() {
            let (lo, weight) = state.history();
            let [cache, _] = &mut state.knots;
            let k = by_history(&curves, moment, lo, weight, cache, &mut state.curve);
            return (k, flags(false, segment.kind));
        }
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

impl<const R: usize, const A: usize, const C: usize> AxisTable<R, A, C> {
    /// Where the residual heat falls among the stored histories, whose labels are blended between
    /// the two bracketing ambients as their curves are (stage 2). Once per activation.
    fn locate_history(
        &self,
        ambient: &AmbientPosition,
        residual_heat_celsius: f32,
        margin_celsius: f32,
    ) -> AmbientPosition {
        let labels = |i: u8| {
            self.ambients
                .get(usize::from(i))
                .map_or(&[][..], |a| a.residual_heat_celsius.as_slice())
        };
        let (lower, upper) = (labels(ambient.lo), labels(ambient.hi));
        let mut blended: Vec<f32, C> = Vec::new();
        for (c, &label) in lower.iter().enumerate() {
            let upper = upper.get(c).copied().unwrap_or(f32::NAN);
            let _ = blended.push(ambient.blend(label, upper));
        }
        AmbientPosition::locate(&blended, residual_heat_celsius, margin_celsius, |label| {
            *label
        })
    }
}

/// A small index stored as an f32 (exact up to 2^24) back as a `u8`, saturating; NaN reads as 0.
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
fn saturating_u8_of(index: f32) -> u8 {
    // `as` saturates and maps NaN to 0: total, no panic; the index was a `u8` when stored.
    index as u8
}

// `flags` reads `PastLast`'s flag as a mask of its discriminant.
const _: () = assert!(
    SegmentKind::PastLast as u16 == Flags::PAST_LAST_REFERENCE.0
        && SegmentKind::BeforeFirst as u16 & Flags::PAST_LAST_REFERENCE.0 == 0
        && SegmentKind::Between as u16 & Flags::PAST_LAST_REFERENCE.0 == 0
        && SegmentKind::OnLast as u16 & Flags::PAST_LAST_REFERENCE.0 == 0
);

/// The modified model's envelope flags for one sample.
#[inline(always)]
fn flags(rise_out_of_span: bool, kind: SegmentKind) -> Flags {
    let mut flags = Flags(u16::from(kind as u8) & Flags::PAST_LAST_REFERENCE.0);
    if rise_out_of_span {
        flags |= Flags::RISE_OUT_OF_SPAN;
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
