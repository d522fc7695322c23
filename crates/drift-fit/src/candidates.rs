//! The quantities the diagnosis tests the residual against, per axis, at the recording's own
//! sample rate: every auxiliary channel (whatever its name) and quantities derived from the
//! temperatures and the clock.
//!
//! They are computed the same way on calibration activations (to learn what the paper's tables
//! absorb of each, [`crate::absorb`]) and on the activations being diagnosed, so a kind is defined
//! once, by what it computes, not by where it is used.

use drift_recording::{Segment, RAW_PER_CELSIUS};

use crate::lowpass::centred_moving_average;

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// The auxiliary channel holding the chamber's set point (the ambient the unit is kept at).
pub const SET_POINT_CHANNEL: &str = "chamber_set_point";

/// One kind of candidate; its value for axis `a` may depend on `a`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A recorded auxiliary channel, the same for every axis.
    Aux(String),
    /// The axis's own temperature rate, °C/s: central difference over ±1 s of the 1-s low-passed
    /// temperature.
    TemperatureRate,
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
        kinds.extend([
            Self::TemperatureRate,
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
            Self::TemperatureRate => format!("temperature rate {own}"),
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
            Self::TemperatureRate => per_axis(&|axis| {
                let rise = rise(axis);
                let half = (rate_hz as usize).max(1);
                (0..n)
                    .map(|i| {
                        let (lo, hi) = (i.saturating_sub(half), (i + half).min(n - 1));
                        if hi > lo {
                            ((rise[hi] - rise[lo]) * rate_hz / (hi - lo) as f64) as f32
                        } else {
                            0.0
                        }
                    })
                    .collect()
            }),
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
