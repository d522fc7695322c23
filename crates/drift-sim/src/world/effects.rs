//! Undeclared effects: the families, the forms a channel's contribution can take, and how one
//! effect's per-axis coefficients are drawn.
//!
//! Every coefficient is sized so that the effect's contribution moves the bias by
//! `magnitude_scale × 3×10⁻³ °/s × U(0.5, 1.5)` over the span its feature typically has (within an
//! activation, or between activations for a channel that is held while powered): comparable to
//! what the paper's model leaves, not more.

use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// The contribution an effect is sized for at `magnitude_scale = 1` (°/s).
pub const TARGET_DPS: f64 = 3.0e-3;
/// The activation length the spans below assume (s).
const NOMINAL_ACTIVATION_S: f64 = 120.0;
/// Typical rise of a sensor's (ASIC) temperature over an activation (°C).
const SENSOR_RISE_C: f64 = 4.5;
/// Typical rise of an element's temperature over an activation (°C).
const ELEMENT_RISE_C: f64 = 3.0;
/// Typical |element temperature − 25 °C| at the +30/+40 °C set points (°C).
const ELEMENT_LEVEL_C: f64 = 10.0;
/// Typical |sensor temperature − 25 °C| (°C).
const SENSOR_LEVEL_C: f64 = 12.0;
/// Largest element heating rate just after switch-on less its end-of-activation rate (°C/s).
const ELEMENT_RATE_SPAN_C_PER_S: f64 = 0.04;
/// |T_asic − 25 °C| × element rise that the self-heating nonlinearity multiplies (°C²).
const SELF_HEATING_SPAN_C2: f64 = 8.0 * ELEMENT_RISE_C;

/// A family of undeclared effects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectFamily {
    /// The accelerometer (gravity in the body frame, g).
    Accelerometer,
    /// The supply voltage's deviation from 5 V.
    SupplyVoltage,
    /// The named auxiliary channel `humidity` (chamber air, %RH).
    Humidity,
    /// The named auxiliary channel `air_pressure` (hPa): a capsule that is not perfectly sealed.
    AirPressure,
    /// The element's own temperature (°C, beyond the base model's polynomial).
    ElementTemperature,
    /// Another axis's sensor (ASIC) temperature, in any form.
    OtherSensorTemperature,
    /// Bias ∝ the element's heating rate dT_e/dt (a thermal gradient across the die).
    TemperatureRate,
    /// One axis's bias follows another sensor's temperature (offset form).
    CrossAxis,
    /// ASIC dissipation grows with its own temperature (CMOS leakage): the rise is no longer
    /// proportional to the power.
    SelfHeating,
}

impl EffectFamily {
    /// Every family, in a fixed order.
    pub const ALL: [Self; 9] = [
        Self::Accelerometer,
        Self::SupplyVoltage,
        Self::Humidity,
        Self::AirPressure,
        Self::ElementTemperature,
        Self::OtherSensorTemperature,
        Self::TemperatureRate,
        Self::CrossAxis,
        Self::SelfHeating,
    ];

    /// The family's name (as in the truth file).
    pub fn name(self) -> &'static str {
        match self {
            Self::Accelerometer => "accelerometer",
            Self::SupplyVoltage => "supply_voltage",
            Self::Humidity => "humidity",
            Self::AirPressure => "air_pressure",
            Self::ElementTemperature => "element_temperature",
            Self::OtherSensorTemperature => "other_sensor_temperature",
            Self::TemperatureRate => "temperature_rate",
            Self::CrossAxis => "cross_axis",
            Self::SelfHeating => "self_heating",
        }
    }

    /// The forms a family's contribution can take (empty: the family has one fixed form).
    pub fn forms(self) -> &'static [EffectForm] {
        use EffectForm::*;
        match self {
            Self::Accelerometer | Self::SupplyVoltage | Self::Humidity | Self::AirPressure => &[
                Offset,
                TimesElementDeviation,
                TimesRise,
                Lagged,
                OnOtherAxis,
                Quadratic,
            ],
            // × (T_e − 25 °C) of the element's own temperature is its quadratic form.
            Self::ElementTemperature => &[Offset, TimesRise, Lagged, OnOtherAxis, Quadratic],
            // Already another axis's: "on another axis" is what it is.
            Self::OtherSensorTemperature => {
                &[Offset, TimesElementDeviation, TimesRise, Lagged, Quadratic]
            }
            Self::TemperatureRate | Self::CrossAxis | Self::SelfHeating => &[],
        }
    }
}

/// The form of a channel's contribution `u` (the channel's deviation from its reference).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectForm {
    /// `b += k·u`.
    Offset,
    /// `b += k·u·(T_e − 25 °C)`: the channel changes the temperature coefficient.
    TimesElementDeviation,
    /// `b += k·u·(T_s − T_s,on)`: the channel scales the drift with the sensor's rise since
    /// switch-on.
    TimesRise,
    /// `b += k·L_τ[u]`: through a first-order lag of time constant τ (10–300 s).
    Lagged,
    /// The contribution lands on another axis: a per-axis channel is read on another axis
    /// (`b_a += k·u_b`); a scalar channel multiplies another axis's sensor rise
    /// (`b_a += k·u·(T_s,b − T_s,b,on)`).
    OnOtherAxis,
    /// `b += k·u²`.
    Quadratic,
}

impl EffectForm {
    /// Every form, in a fixed order.
    pub const ALL: [Self; 6] = [
        Self::Offset,
        Self::TimesElementDeviation,
        Self::TimesRise,
        Self::Lagged,
        Self::OnOtherAxis,
        Self::Quadratic,
    ];

    /// The form's name (as in the truth file).
    pub fn name(self) -> &'static str {
        match self {
            Self::Offset => "offset",
            Self::TimesElementDeviation => "times_element_deviation",
            Self::TimesRise => "times_rise",
            Self::Lagged => "lagged",
            Self::OnOtherAxis => "on_other_axis",
            Self::Quadratic => "quadratic",
        }
    }
}

/// What a term reads; `u` is the value less the reference given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "channel", rename_all = "snake_case")]
pub enum Source {
    /// True specific force along a body axis (g), reference 0.
    Accelerometer {
        /// Body axis 0 = X, 1 = Y, 2 = Z.
        component: usize,
    },
    /// True supply voltage, reference 5 V.
    SupplyVoltage,
    /// A named auxiliary channel (true value, before the measurement noise).
    Aux {
        /// The channel's name in the recordings.
        name: String,
        /// The reference subtracted.
        reference: f64,
    },
    /// True element temperature of an axis, reference 25 °C.
    ElementTemperature {
        /// Axis 0 = X, 1 = Y, 2 = Z.
        axis: usize,
    },
    /// True sensor-site (ASIC) temperature of an axis, reference 25 °C.
    SensorTemperature {
        /// Axis 0 = X, 1 = Y, 2 = Z.
        axis: usize,
    },
}

impl Source {
    /// True when the channel is constant while the unit is powered (it changes only between
    /// activations): its offset and quadratic forms shift the bias per activation, not within one.
    pub fn held(&self) -> bool {
        match self {
            Self::Accelerometer { .. } | Self::SupplyVoltage => true,
            Self::Aux { name, .. } => name == super::AIR_PRESSURE,
            _ => false,
        }
    }
}

/// One term of one axis's bias.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Term {
    /// The biased axis (0 = X, 1 = Y, 2 = Z).
    pub axis: usize,
    /// What the term reads.
    pub source: Source,
    /// Its form.
    pub form: EffectForm,
    /// Whose sensor rise multiplies `u` (`times_rise`, and `on_other_axis` of a scalar channel).
    pub rise_axis: Option<usize>,
    /// Lag time constant (s), for `lagged`.
    pub tau_s: Option<f64>,
    /// The coefficient `k`.
    pub coefficient: f64,
    /// Its unit.
    pub unit: String,
    /// `|k|` × the feature span it was sized on (°/s): the contribution's intended size.
    pub sized_dps: f64,
}

/// One drawn undeclared effect: its family, form and per-axis coefficients.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Effect {
    /// The family.
    pub family: EffectFamily,
    /// The form (channel families and `cross_axis`; `None` for `temperature_rate` and
    /// `self_heating`, whose form is fixed).
    pub form: Option<EffectForm>,
    /// The bias terms (one per axis for channel families and `cross_axis`).
    pub terms: Vec<Term>,
    /// `temperature_rate`: per-axis coefficient ((°/s)/(°C/s)) on the element heating rate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_dps_per_c_per_s: Option<[f64; 3]>,
    /// `self_heating`: relative ASIC power growth per °C above 25 °C (1/°C).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub asic_power_per_c: Option<f64>,
}

/// `(level, swing within an activation, unit)` of a source's `u`.
fn source_scale(source: &Source) -> (f64, f64, &'static str) {
    match source {
        Source::Accelerometer { .. } => (1.0, 0.0, "g"),
        Source::SupplyVoltage => (0.3, 0.0, "V"),
        Source::Aux { name, .. } if name == super::AIR_PRESSURE => (5.0, 0.1, "hPa"),
        Source::Aux { .. } => (10.0, 3.0, "%RH"),
        Source::ElementTemperature { .. } => (ELEMENT_LEVEL_C, ELEMENT_RISE_C, "°C"),
        Source::SensorTemperature { .. } => (SENSOR_LEVEL_C, SENSOR_RISE_C, "°C"),
    }
}

/// The typical span of a term's feature (what `k` multiplies), and `k`'s unit.
fn feature_span(source: &Source, form: EffectForm, tau_s: Option<f64>) -> (f64, String) {
    let (level, swing, unit) = source_scale(source);
    // A held channel shows only when it changes between activations: by about its level.
    let own = if source.held() { level } else { swing };
    let scalar = matches!(source, Source::SupplyVoltage | Source::Aux { .. });
    let dps = "°/s";
    match form {
        EffectForm::Offset => (own, format!("{dps}/{unit}")),
        // A held channel changes the temperature coefficient per activation: its steps between
        // activations (level × T_e − 25 °C) count as much as its drift within one.
        EffectForm::TimesElementDeviation if source.held() => (
            level * 0.5 * (ELEMENT_RISE_C + ELEMENT_LEVEL_C),
            format!("{dps}/({unit}·°C)"),
        ),
        EffectForm::TimesElementDeviation => (
            level * ELEMENT_RISE_C + swing * ELEMENT_LEVEL_C,
            format!("{dps}/({unit}·°C)"),
        ),
        EffectForm::TimesRise => (level * SENSOR_RISE_C, format!("{dps}/({unit}·°C)")),
        EffectForm::Lagged => {
            // A slow lag shows less within an activation, but still carries the channel's changes
            // between activations: size it on at least half the channel's swing.
            let tau = tau_s.unwrap_or(NOMINAL_ACTIVATION_S);
            let passed = (NOMINAL_ACTIVATION_S / (NOMINAL_ACTIVATION_S + tau)).max(0.5);
            (own * passed, format!("{dps}/{unit}"))
        }
        EffectForm::OnOtherAxis if scalar => (level * SENSOR_RISE_C, format!("{dps}/({unit}·°C)")),
        EffectForm::OnOtherAxis => (own, format!("{dps}/{unit}")),
        EffectForm::Quadratic if source.held() => (level * level, format!("{dps}/{unit}²")),
        EffectForm::Quadratic => (2.0 * level * swing, format!("{dps}/{unit}²")),
    }
}

fn sign(r: &mut ChaCha8Rng) -> f64 {
    if r.random::<bool>() {
        1.0
    } else {
        -1.0
    }
}

/// `scale × TARGET × sign × U(0.5, 1.5) / span`, and the size it gives.
fn coefficient(r: &mut ChaCha8Rng, scale: f64, span: f64) -> (f64, f64) {
    let size = scale * TARGET_DPS * (0.5 + r.random::<f64>());
    (sign(r) * size / span, size)
}

fn other_axis(r: &mut ChaCha8Rng, a: usize) -> usize {
    (a + 1 + r.random_range(0..2usize)) % 3
}

/// The source a channel family reads for axis `a` with `form` (per-axis sources read axis `a`'s
/// own component unless the form puts them on another axis).
fn source_for(family: EffectFamily, a: usize, form: EffectForm, r: &mut ChaCha8Rng) -> Source {
    let own_or_other = |r: &mut ChaCha8Rng| {
        if form == EffectForm::OnOtherAxis {
            other_axis(r, a)
        } else {
            a
        }
    };
    match family {
        EffectFamily::Accelerometer => Source::Accelerometer {
            component: own_or_other(r),
        },
        EffectFamily::SupplyVoltage => Source::SupplyVoltage,
        EffectFamily::Humidity => Source::Aux {
            name: super::HUMIDITY.into(),
            reference: super::HUMIDITY_REFERENCE,
        },
        EffectFamily::AirPressure => Source::Aux {
            name: super::AIR_PRESSURE.into(),
            reference: super::AIR_PRESSURE_REFERENCE,
        },
        EffectFamily::ElementTemperature => Source::ElementTemperature {
            axis: own_or_other(r),
        },
        EffectFamily::OtherSensorTemperature | EffectFamily::CrossAxis => {
            Source::SensorTemperature {
                axis: other_axis(r, a),
            }
        }
        EffectFamily::TemperatureRate | EffectFamily::SelfHeating => {
            unreachable!("no channel")
        }
    }
}

/// Draws one effect of `family` from its own stream `r`. `forms` restricts the forms drawn
/// (`None` = any of the family's); `mean_abs_tempco` is the unit's mean |∂b/∂T_e| ((°/s)/°C), which
/// sizes the self-heating nonlinearity. Returns `None` when `forms` leaves the family no form.
pub(crate) fn draw(
    family: EffectFamily,
    r: &mut ChaCha8Rng,
    scale: f64,
    forms: Option<&[EffectForm]>,
    mean_abs_tempco: f64,
) -> Option<Effect> {
    let mut effect = Effect {
        family,
        form: None,
        terms: Vec::new(),
        rate_dps_per_c_per_s: None,
        asic_power_per_c: None,
    };
    match family {
        EffectFamily::TemperatureRate => {
            let k: [f64; 3] =
                std::array::from_fn(|_| coefficient(r, scale, ELEMENT_RATE_SPAN_C_PER_S).0);
            effect.rate_dps_per_c_per_s = Some(k);
            return Some(effect);
        }
        EffectFamily::SelfHeating => {
            // Leakage grows with temperature: α > 0.
            let (k, _) = coefficient(r, scale, mean_abs_tempco.max(1e-6) * SELF_HEATING_SPAN_C2);
            effect.asic_power_per_c = Some(k.abs());
            return Some(effect);
        }
        _ => {}
    }
    let allowed: Vec<EffectForm> = match family {
        EffectFamily::CrossAxis => vec![EffectForm::Offset],
        _ => family
            .forms()
            .iter()
            .copied()
            .filter(|f| forms.is_none_or(|only| only.contains(f)))
            .collect(),
    };
    if allowed.is_empty() {
        return None;
    }
    let form = allowed[r.random_range(0..allowed.len())];
    effect.form = Some(form);
    // One time constant per effect (the mechanism's), shared by its axes.
    let tau_s = (form == EffectForm::Lagged).then(|| {
        let (lo, hi) = (10f64.ln(), 300f64.ln());
        (lo + (hi - lo) * r.random::<f64>()).exp()
    });
    for a in 0..3 {
        let source = source_for(family, a, form, r);
        let scalar = matches!(source, Source::SupplyVoltage | Source::Aux { .. });
        let rise_axis = match form {
            EffectForm::TimesRise => Some(a),
            EffectForm::OnOtherAxis if scalar => Some(other_axis(r, a)),
            _ => None,
        };
        let (span, unit) = feature_span(&source, form, tau_s);
        let (k, size) = coefficient(r, scale, span);
        effect.terms.push(Term {
            axis: a,
            source,
            form,
            rise_axis,
            tau_s,
            coefficient: k,
            unit,
            sized_dps: size,
        });
    }
    Some(effect)
}
