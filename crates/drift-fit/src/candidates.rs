//! The quantities the diagnosis tests the residual against, per axis, at the recording's own
//! sample rate: every auxiliary channel (whatever its name) and quantities derived from the
//! temperatures and the clock.
//!
//! They are computed the same way on calibration activations (to learn what the paper's tables
//! absorb of each, [`crate::absorb`]) and on the activations being diagnosed, so a kind is defined
//! once, by what it computes, not by where it is used.

use drift_core::{Extension, ExtensionState, ExtraTerm, Term, TermInputs};
use drift_recording::{Segment, RAW_PER_CELSIUS};

use crate::evaluate::sample_at;
use crate::lowpass::centred_moving_average;

/// Time constants of the temperature-rate candidates, ms: a ×4 grid over the thermal time
/// constants of a small package, seconds to minutes. The element a MEMS gyro's bias follows is
/// heated through the ASIC whose temperature the unit measures, so its rate is the measured
/// temperature's rate through a lag the fitter does not know: the diagnosis scores each.
pub const RATE_TIME_CONSTANTS_MS: [u32; 4] = [2_000, 8_000, 32_000, 128_000];

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// The auxiliary channel holding the chamber's set point (the ambient the unit is kept at).
pub const SET_POINT_CHANNEL: &str = "chamber_set_point";

/// One kind of candidate; its value for axis `a` may depend on `a`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A recorded auxiliary channel, the same for every axis.
    Aux(String),
    /// The axis's own temperature rate, °C/s, through a first-order low-pass of this time
    /// constant (ms): `d/dt` of the low-passed temperature, computed by drift-core's
    /// [`ExtensionState`] on the last good readings exactly as the firmware's rate term is.
    TemperatureRate(u32),
    /// The axis's own temperature rise since switch-on, squared, °C².
    RiseSquared,
    /// Another axis's rise since switch-on, °C: the axis `offset` (1 or 2) places further on.
    OtherAxisRise(usize),
    /// Time since switch-on, s.
    SinceSwitchOn,
    /// The axis's switch-on temperature, °C (constant over the activation).
    SwitchOnTemperature,
    /// Switch-on temperature less the chamber set point, °C: heat left from the last activation,
    /// an estimate of the off-time before it.
    ResidualHeat,
    /// Time since the campaign started, s: what ageing would follow.
    CampaignTime,
}

impl Kind {
    /// Every kind a segment with these auxiliary channels offers.
    pub fn all(aux_channels: impl IntoIterator<Item = String>, has_set_point: bool) -> Vec<Self> {
        let mut kinds: Vec<Self> = aux_channels.into_iter().map(Self::Aux).collect();
        kinds.extend(RATE_TIME_CONSTANTS_MS.map(Self::TemperatureRate));
        kinds.extend([
            Self::RiseSquared,
            Self::OtherAxisRise(1),
            Self::OtherAxisRise(2),
            Self::SinceSwitchOn,
            Self::SwitchOnTemperature,
            Self::CampaignTime,
        ]);
        if has_set_point {
            kinds.push(Self::ResidualHeat);
        }
        kinds
    }

    /// The candidate's name on `axis` (what reports and the term plan read).
    pub fn name(&self, axis: usize) -> String {
        let own = AXES.get(axis).copied().unwrap_or("?");
        match self {
            Self::Aux(channel) => format!("aux:{channel}"),
            Self::TemperatureRate(tau_ms) => {
                format!("temperature rate {own} (τ {} s)", tau_ms / 1000)
            }
            Self::RiseSquared => format!("rise² {own}"),
            Self::OtherAxisRise(offset) => format!("rise {}", AXES[(axis + offset) % 3]),
            Self::SinceSwitchOn => "time since switch-on".into(),
            Self::SwitchOnTemperature => "switch-on temperature".into(),
            Self::ResidualHeat => "residual heat at switch-on (off-time)".into(),
            Self::CampaignTime => "campaign time (ageing)".into(),
        }
    }

    /// The candidate's values on every axis of `segment`, one per sample; `switch_on` is the raw
    /// switch-on temperature per axis. `None` when the segment lacks what the kind needs.
    pub fn values(&self, segment: &Segment, switch_on: [f32; 3]) -> Option<[Vec<f32>; 3]> {
        let n = segment.len();
        let rate_hz = f64::from(segment.sample_rate_hz.max(1));
        let on_celsius = switch_on.map(|r| f64::from(r) / RAW_PER_CELSIUS);
        let same = |values: Vec<f32>| Some([values.clone(), values.clone(), values]);
        let per_axis = |f: &dyn Fn(usize) -> Vec<f32>| Some([f(0), f(1), f(2)]);
        let rise = |axis: usize| -> Vec<f64> {
            // Low-passed like the residual, so a candidate carries no noise the residual lacks.
            centred_moving_average(
                &segment.temperature_raw[axis],
                segment.sample_rate_hz as usize,
            )
            .into_iter()
            .map(|r| r / RAW_PER_CELSIUS - on_celsius[axis])
            .collect()
        };
        match self {
            Self::Aux(channel) => {
                let channel = segment.aux.get(channel)?;
                if channel.values.is_empty() {
                    return None;
                }
                let ratio = f64::from(channel.sample_rate_hz) / rate_hz;
                same(
                    (0..n)
                        .map(|i| {
                            let at = ((i as f64 * ratio) as usize).min(channel.values.len() - 1);
                            channel.values[at]
                        })
                        .collect(),
                )
            }
            Self::TemperatureRate(tau_ms) => Some(filtered_rates(segment, switch_on, *tau_ms)),
            Self::RiseSquared => {
                per_axis(&|axis| rise(axis).into_iter().map(|r| (r * r) as f32).collect())
            }
            Self::OtherAxisRise(offset) => per_axis(&|axis| {
                rise((axis + offset) % 3)
                    .into_iter()
                    .map(|r| r as f32)
                    .collect()
            }),
            Self::SinceSwitchOn => same((0..n).map(|i| (i as f64 / rate_hz) as f32).collect()),
            Self::SwitchOnTemperature => per_axis(&|axis| vec![on_celsius[axis] as f32; n]),
            Self::ResidualHeat => {
                let set_point = f64::from(*segment.aux.get(SET_POINT_CHANNEL)?.values.first()?);
                per_axis(&|axis| vec![(on_celsius[axis] - set_point) as f32; n])
            }
            Self::CampaignTime => {
                let start = segment.power_on_ns as f64 / 1e9;
                same(
                    (0..n)
                        .map(|i| (start + i as f64 / rate_hz) as f32)
                        .collect(),
                )
            }
        }
    }
}

/// The temperature rate of every axis of `segment`, °C/s, through drift-core's rate filter of time
/// constant `tau_ms`, on the last good reading of each axis (held through a missing one) as the
/// corrector passes it: the firmware's term values, uncentred.
pub fn filtered_rates(segment: &Segment, switch_on: [f32; 3], tau_ms: u32) -> [Vec<f32>; 3] {
    let mut extension = Extension::NONE;
    let _ = extension.terms.push(ExtraTerm {
        term: Term::TemperatureRate {
            time_constant_ms: tau_ms,
        },
        centre: [0.0; 3],
        coefficient: [0.0; 3],
    });
    let celsius_per_raw = 1.0 / RAW_PER_CELSIUS as f32;
    let mut state = ExtensionState::power_on();
    let mut held = switch_on;
    let mut rates: [Vec<f32>; 3] = std::array::from_fn(|_| Vec::with_capacity(segment.len()));
    for i in 0..segment.len() {
        let sample = sample_at(segment, i);
        for (held, raw) in held.iter_mut().zip(sample.temperature_raw) {
            if raw.is_finite() {
                *held = raw;
            }
        }
        let inputs = TermInputs {
            since_power_on_ms: sample.since_power_on_ms,
            rise_celsius: [0, 1, 2].map(|a| (held[a] - switch_on[a]) * celsius_per_raw),
            ..TermInputs::default()
        };
        let values = state.values(&extension, &inputs);
        for (rates, values) in rates.iter_mut().zip(values) {
            rates.push(values[0]);
        }
    }
    rates
}
