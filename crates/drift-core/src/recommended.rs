//! The recommended model: the paper's drift correction after switch-on with a turn-on bias fitted
//! across every calibration activation.
//!
//! The paper's tables correct the drift after switch-on better than any polynomial of the
//! temperature, but read the turn-on bias from the calibration's fully cooled starts at its
//! ambients alone (linear between them, held beyond them): a unit switched on warm, or between or
//! beyond the calibrated ambients while the air drifts, starts from the wrong offset, and a
//! polynomial of the switch-on temperature fitted on every calibration activation does better
//! there. This model takes each part from where it is strongest: the turn-on bias
//! `q(T_on) + h · residual heat` (the residual heat firmware estimates from what it kept of the
//! previous activation, [`crate::SwitchOn`]), the drift after it from the paper's three stages.
//! Per sample it does exactly what the paper's model does.

use crate::error::{check_finite, Error, Location, Problem};
use crate::flags::Flags;
use crate::history::SwitchOn;
use crate::model::{AxisModel, Model};
use crate::modified::ModifiedAxisState;
use crate::polynomial::PolynomialAxis;
use crate::settings::Settings;
use crate::table::{AxisTable, ModifiedTables};
use crate::AXES;

/// The turn-on bias of one axis: `q(T_on) + dps_per_residual_celsius · residual heat`.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TurnOn {
    /// `q`: the turn-on bias of a start with no residual heat, as a polynomial of the switch-on
    /// temperature over the calibration's switch-on temperatures, continued along its tangent
    /// beyond them ([`PolynomialAxis::continued`]; flagged `TEMPERATURE_OUT_OF_RANGE` beyond the
    /// ambient margin).
    pub polynomial: PolynomialAxis,
    /// How much a °C of residual heat at switch-on moves the turn-on bias, (°/s) per °C.
    pub dps_per_residual_celsius: f32,
    /// The most residual heat a calibration activation switched on with, °C: more is held at it
    /// (flagged `HISTORY_OUT_OF_SPAN`). Without a clock, an ambient that rose between switch-off
    /// and switch-on reads as residual heat; the slope is only known over the heats it was
    /// fitted on.
    pub most_residual_heat_celsius: f32,
}

impl TurnOn {
    /// The turn-on bias at `switch_on` and its flags. No residual heat is added for a start whose
    /// history is unknown (taken as fully cooled, flagged where the heat would have mattered).
    #[inline]
    pub fn bias(&self, settings: &Settings, switch_on: &SwitchOn) -> (f32, Flags) {
        let (q, _) = self
            .polynomial
            .continued(switch_on.switch_on_celsius, settings.ambient_margin_celsius);
        // The envelope's flags; the heat beyond its most is held there.
        let mut flags = self
            .envelope(settings.ambient_margin_celsius)
            .flags(switch_on);
        let heat = switch_on.residual_heat_celsius;
        let warm = if switch_on.known && heat > 0.0 {
            let held = if heat > self.most_residual_heat_celsius {
                self.most_residual_heat_celsius
            } else {
                heat
            };
            self.dps_per_residual_celsius * held
        } else {
            0.0
        };
        if !switch_on.known && self.dps_per_residual_celsius != 0.0 {
            flags |= Flags::HISTORY_UNKNOWN;
        }
        (q + warm, flags)
    }

    /// Checks the polynomial and the slope; `at` names the axis.
    pub fn validate(&self, at: Location) -> Result<(), Error> {
        self.polynomial.validate(at)?;
        check_finite(
            "dps_per_residual_celsius",
            at,
            [self.dps_per_residual_celsius],
        )?;
        check_finite(
            "most_residual_heat_celsius",
            at,
            [self.most_residual_heat_celsius],
        )?;
        if self.most_residual_heat_celsius < 0.0 {
            return Err(Error::new(
                "most_residual_heat_celsius",
                at,
                Problem::Negative,
            ));
        }
        Ok(())
    }
}

/// One axis of the recommended model: the paper's table for the drift, [`TurnOn`] for the bias at
/// switch-on.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RecommendedAxis<const R: usize, const A: usize, const C: usize> {
    /// The paper's correlation table; its initial biases are not used.
    pub table: AxisTable<R, A, C>,
    /// The turn-on bias.
    pub turn_on: TurnOn,
}

impl<const R: usize, const A: usize, const C: usize> RecommendedAxis<R, A, C> {
    /// An axis with no data (which validation rejects): for a `static` filled in place.
    pub const EMPTY: Self = Self {
        table: AxisTable::EMPTY,
        turn_on: TurnOn {
            polynomial: PolynomialAxis {
                range_celsius: [0.0; 2],
                coefficients: heapless::Vec::new(),
            },
            dps_per_residual_celsius: 0.0,
            most_residual_heat_celsius: 0.0,
        },
    };
}

impl<const R: usize, const A: usize, const C: usize> AxisModel for RecommendedAxis<R, A, C> {
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
        // The table places the ambient for stages 1–3 and flags it; its initial bias is not used.
        let (_, table_flags) = self.table.power_on_after(settings, switch_on, state);
        let (bias, flags) = self.turn_on.bias(settings, switch_on);
        (bias, table_flags | flags)
    }

    /// The table places stage 2 at the measured ambient; the turn-on bias stays a function of the
    /// switch-on temperature, with the measured residual heat.
    fn power_on_at_ambient(
        &self,
        settings: &Settings,
        switch_on: &SwitchOn,
        state: &mut Self::State,
    ) -> (f32, Flags) {
        let (_, table_flags) = self.table.power_on_at_ambient(settings, switch_on, state);
        let (bias, flags) = self.turn_on.bias(settings, switch_on);
        (bias, table_flags | flags)
    }

    #[inline(always)]
    fn drift(
        &self,
        settings: &Settings,
        state: &mut Self::State,
        since_power_on_ms: u32,
        temperature_celsius: f32,
        rise_celsius: f32,
    ) -> (f32, Flags) {
        self.table.drift(
            settings,
            state,
            since_power_on_ms,
            temperature_celsius,
            rise_celsius,
        )
    }
}

/// The recommended model for a whole unit: settings and one [`RecommendedAxis`] per axis.
///
/// Capacities as [`ModifiedTables`]'s.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RecommendedTables<const R: usize = 16, const A: usize = 12, const C: usize = 32> {
    /// Sensor conversion and envelope settings.
    pub settings: Settings,
    /// One axis per gyro axis (X, Y, Z).
    pub axes: [RecommendedAxis<R, A, C>; AXES],
}

impl<const R: usize, const A: usize, const C: usize> RecommendedTables<R, A, C> {
    /// No axis data and [`Settings::ZEROED`] (which validation rejects), all-zero bytes: for a
    /// `static` in `.bss` that `blob::decode_into` fills.
    pub const EMPTY: Self = Self {
        settings: Settings::ZEROED,
        axes: [
            RecommendedAxis::EMPTY,
            RecommendedAxis::EMPTY,
            RecommendedAxis::EMPTY,
        ],
    };

    /// The paper's tables (their settings and curves) with `turn_on` per axis, validated.
    pub fn try_new(
        tables: &ModifiedTables<R, A, C>,
        turn_on: [TurnOn; AXES],
    ) -> Result<Self, Error> {
        let [x, y, z] = turn_on;
        let [tx, ty, tz] = &tables.axes;
        let model = Self {
            settings: tables.settings,
            axes: [
                RecommendedAxis {
                    table: tx.clone(),
                    turn_on: x,
                },
                RecommendedAxis {
                    table: ty.clone(),
                    turn_on: y,
                },
                RecommendedAxis {
                    table: tz.clone(),
                    turn_on: z,
                },
            ],
        };
        model.validate()?;
        Ok(model)
    }
}

impl<const R: usize, const A: usize, const C: usize> Model for RecommendedTables<R, A, C> {
    type Axis = RecommendedAxis<R, A, C>;

    fn settings(&self) -> &Settings {
        &self.settings
    }

    fn axes(&self) -> &[Self::Axis; AXES] {
        &self.axes
    }

    fn validate(&self) -> Result<(), Error> {
        self.settings.validate()?;
        for (axis, recommended) in self.axes.iter().enumerate() {
            recommended.table.validate(Location::axis(axis))?;
            recommended.turn_on.validate(Location::axis(axis))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{AmbientCurves, Curve, CurvePoint};

    fn table(initial_bias_dps: f32) -> AxisTable<4, 2, 2> {
        let curve = |k: f32, rise: f32| {
            let mut c = Curve::default();
            c.points
                .push(CurvePoint {
                    rise_celsius: rise,
                    k_dps_per_celsius: k,
                })
                .unwrap();
            c
        };
        let mut ambients = heapless::Vec::new();
        for ambient in [30.0, 40.0] {
            let mut curves = heapless::Vec::new();
            curves.push(curve(0.002, 1.0)).unwrap();
            curves.push(curve(0.003, 2.0)).unwrap();
            ambients
                .push(AmbientCurves {
                    ambient_celsius: ambient,
                    initial_bias_dps,
                    curves,
                    ..AmbientCurves::default()
                })
                .unwrap();
        }
        let mut reference_ms = heapless::Vec::new();
        reference_ms.push(1000).unwrap();
        AxisTable {
            reference_ms,
            ambients,
        }
    }

    fn turn_on() -> TurnOn {
        let mut coefficients = heapless::Vec::new();
        coefficients.extend_from_slice(&[0.01, 0.02]).unwrap();
        TurnOn {
            polynomial: PolynomialAxis {
                range_celsius: [30.0, 40.0],
                coefficients,
            },
            dps_per_residual_celsius: -0.004,
            most_residual_heat_celsius: 3.0,
        }
    }

    fn model() -> RecommendedTables<4, 2, 2> {
        let paper = ModifiedTables {
            settings: Settings::DEFAULT,
            axes: [table(0.5), table(0.5), table(0.5)],
            extension: crate::Extension::NONE,
        };
        RecommendedTables::try_new(&paper, [turn_on(), turn_on(), turn_on()]).unwrap()
    }

    /// The turn-on bias is `q` plus the residual heat's share; the drift after it is the paper's
    /// table's, to the bit.
    #[test]
    fn the_bias_is_the_turn_on_fit_and_the_drift_the_papers() {
        let model = model();
        let settings = Settings::DEFAULT;
        let axis = &model.axes[0];
        let mut state = ModifiedAxisState::default();
        let (cold, flags) = axis.power_on(&settings, 35.0, &mut state);
        assert_eq!(cold, 0.01);
        assert!(flags.contains(Flags::HISTORY_UNKNOWN), "{flags:?}");
        let warm = SwitchOn {
            switch_on_celsius: 40.0,
            ambient_celsius: 38.0,
            residual_heat_celsius: 2.0,
            remaining: 0.5,
            known: true,
        };
        let (bias, flags) = axis.power_on_after(&settings, &warm, &mut state);
        assert!((bias - (0.01 + 0.02 - 0.008)).abs() < 1e-7, "{bias}");
        assert!(!flags.contains(Flags::HISTORY_UNKNOWN), "{flags:?}");
        let mut paper_state = ModifiedAxisState::default();
        let _ = axis
            .table
            .power_on_after(&settings, &warm, &mut paper_state);
        for (ms, rise) in [(500, 0.4_f32), (1000, 1.5), (4000, 2.5)] {
            let got = axis.drift(&settings, &mut state, ms, 40.0 + rise, rise);
            let want = axis
                .table
                .drift(&settings, &mut paper_state, ms, 40.0 + rise, rise);
            assert_eq!(got.0.to_bits(), want.0.to_bits());
            assert_eq!(got.1, want.1);
        }
    }

    #[test]
    fn beyond_the_fitted_range_the_turn_on_follows_its_tangent_and_is_flagged() {
        let model = model();
        let mut state = ModifiedAxisState::default();
        // q = 0.01 + 0.02 · (T − 35) / 5: at 50 °C, 15 °C beyond the middle, 0.07.
        let (bias, flags) = model.axes[1].power_on(&Settings::DEFAULT, 50.0, &mut state);
        assert!((bias - 0.07).abs() < 1e-7, "{bias}");
        assert!(flags.contains(Flags::TEMPERATURE_OUT_OF_RANGE), "{flags:?}");
        assert!(flags.contains(Flags::AMBIENT_OUT_OF_RANGE), "{flags:?}");
        let (nan, flags) = model.axes[1].power_on(&Settings::DEFAULT, f32::NAN, &mut state);
        assert!(flags.contains(Flags::TEMPERATURE_OUT_OF_RANGE), "{flags:?}");
        assert!(
            (nan - -0.01).abs() < 1e-7,
            "a NaN reads as the low end: {nan}"
        );
    }

    #[test]
    fn more_residual_heat_than_calibrated_is_held_and_flagged() {
        let model = model();
        let settings = Settings::DEFAULT;
        let mut state = ModifiedAxisState::default();
        let at = |heat: f32| SwitchOn {
            switch_on_celsius: 35.0,
            ambient_celsius: 35.0 - heat,
            residual_heat_celsius: heat,
            remaining: 0.5,
            known: true,
        };
        let (inside, flags) = model.axes[0].power_on_after(&settings, &at(2.0), &mut state);
        assert!((inside - (0.01 - 0.008)).abs() < 1e-7, "{inside}");
        assert!(!flags.contains(Flags::HISTORY_OUT_OF_SPAN), "{flags:?}");
        let (held, flags) = model.axes[0].power_on_after(&settings, &at(9.0), &mut state);
        assert!((held - (0.01 - 0.012)).abs() < 1e-7, "{held}");
        assert!(flags.contains(Flags::HISTORY_OUT_OF_SPAN), "{flags:?}");
    }

    #[test]
    fn validation_names_the_axis_and_field() {
        let mut model = model();
        model.axes[2].turn_on.dps_per_residual_celsius = f32::NAN;
        let e = model.validate().unwrap_err();
        assert_eq!((e.field, e.at.axis), ("dps_per_residual_celsius", Some(2)));
        let mut model = self::model();
        model.axes[1].turn_on.polynomial.coefficients.clear();
        let e = model.validate().unwrap_err();
        assert_eq!((e.field, e.at.axis), ("coefficients", Some(1)));
        let mut model = self::model();
        model.axes[0].turn_on.most_residual_heat_celsius = -1.0;
        let e = model.validate().unwrap_err();
        assert_eq!(
            (e.field, e.at.axis),
            ("most_residual_heat_celsius", Some(0))
        );
        assert!(RecommendedTables::<4, 2, 2>::EMPTY.validate().is_err());
    }
}
