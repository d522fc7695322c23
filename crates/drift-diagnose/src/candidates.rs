//! The quantities the diagnosis tests the residual against, per axis, at the recording's own
//! sample rate: every auxiliary channel (whatever its name) and quantities derived from the
//! temperatures and the clock.
//!
//! They are computed the same way on calibration activations (to learn what the paper's tables
//! absorb of each, [`crate::absorb`]) and on the activations being diagnosed, so a kind is defined
//! once, by what it computes, not by where it is used.

use drift_recording::Segment;

use drift_fit::lowpass::centred_moving_average;

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// The time constants the diagnosis offers for the sensor's own temperature rate, s: a derivative
/// smoothed over about ±τ/2 (2 s, 8 s).
pub const SENSOR_RATE_TIME_CONSTANTS_S: [u32; 2] = [2, 8];
/// The time constants the diagnosis offers for the element's rate, s: lags from seconds to minutes,
/// a factor of ~4 apart, so whatever the element's lag one of them is within a factor of 2 of it.
pub const ELEMENT_RATE_TIME_CONSTANTS_S: [u32; 3] = [8, 30, 120];

/// Where a rate candidate's filter starts at switch-on, °C/s per axis (`drift_core::SwitchOnRate`
/// as the fitter measured it on the calibration): the sensor's rate, its own heating included,
/// and the element's, which has not started heating (only the cooling of the heat it switched on
/// with).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StartRates {
    /// The temperature sensor's rate at switch-on: heating less cooling.
    pub sensor: [f32; 3],
    /// The element's rate at switch-on: the cooling alone.
    pub element: [f32; 3],
}

/// The temperature an auxiliary channel's sensitivity is measured from, °C: the data sheets'
/// room temperature. Any other constant changes an interaction only by the channel itself, which
/// is a candidate of its own.
pub const REFERENCE_CELSIUS: f64 = 25.0;

/// The auxiliary channel holding the chamber's set point (the ambient the unit is kept at).
pub const SET_POINT_CHANNEL: &str = "chamber_set_point";

/// The auxiliary channel holding the chamber's air temperature: the ambient the bench logged, which
/// the diagnosis's baseline reads the paper's tables at ([`crate::diagnose::AMBIENT_TERM`]).
pub const AMBIENT_CHANNEL: &str = "chamber_air";

/// Channels that describe the bench rather than the unit, by default: the chamber's set point and
/// its air. Firmware in the field has neither, and the chamber air follows the ambient, which the
/// paper's model reads from the switch-on temperature: where that reading is off (short off-times,
/// ramps) any channel that follows the air explains the residual, in every world, null included.
/// They are context — never ranked, never a term. The analyst adds others with
/// `--bench-channel`.
pub const DEFAULT_BENCH_CHANNELS: [&str; 2] = [SET_POINT_CHANNEL, AMBIENT_CHANNEL];

/// A recorded auxiliary channel less its mean over the calibration activations: what an
/// interaction multiplies. Uncentred, a channel that hardly moves times the heating is the heating
/// itself, scaled — a candidate that matches the tables' own lookup error rather than anything the
/// channel does.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Deviation {
    /// The channel's name.
    pub channel: String,
    /// Its calibration mean, in thousandths of the channel's unit (an integer, so that kinds
    /// compare and sort).
    pub centre_milli: i64,
}

impl Deviation {
    /// `channel` less `centre` (its calibration mean, in the channel's unit).
    pub fn new(channel: &str, centre: f64) -> Self {
        Self {
            channel: channel.to_owned(),
            centre_milli: if centre.is_finite() {
                (centre * 1000.0).round() as i64
            } else {
                0
            },
        }
    }

    fn centre(&self) -> f64 {
        self.centre_milli as f64 / 1000.0
    }
}

/// One kind of candidate; its value for axis `a` may depend on `a`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A recorded auxiliary channel, the same for every axis.
    Aux(String),
    /// The axis's own temperature rate, °C/s, through a first-order low-pass of time constant
    /// `time_constant_s`: the rise since switch-on (1-s low-passed) less its low-passed self, over
    /// τ — what drift-core's rate term computes (`Term::TemperatureRate`) — started at the
    /// sensor's rate at switch-on ([`StartRates::sensor`]): a bias that follows the temperature
    /// sensor's own rate, the filter only smoothing it ([`SENSOR_RATE_TIME_CONSTANTS_S`]).
    TemperatureRate {
        /// The low-pass's time constant, s.
        time_constant_s: u32,
    },
    /// The same filter started at the element's rate at switch-on ([`StartRates::element`]): the
    /// sensing element sits in its capsule behind the temperature sensor and follows it through a
    /// lag of its own, seconds to minutes, which nobody tells the fitter. The rate such a bias
    /// follows is the sensor's rate low-passed by that lag, and at switch-on the element has not
    /// started heating. The data chooses among [`ELEMENT_RATE_TIME_CONSTANTS_S`].
    ElementRate {
        /// The low-pass's time constant (the element's lag), s.
        time_constant_s: u32,
    },
    /// A recorded auxiliary channel times the axis's own rise since switch-on (channel unit × °C):
    /// a sensitivity to the channel that grows as the unit heats (g-sensitivity or supply
    /// sensitivity with a temperature coefficient of its own).
    AuxTimesRise(Deviation),
    /// A recorded auxiliary channel times the axis's own sensor temperature less
    /// [`REFERENCE_CELSIUS`] (channel unit × °C): the same sensitivity, growing with the
    /// temperature itself rather than with the heating, so it also differs between ambients.
    AuxTimesTemperature(Deviation),
    /// Another axis's temperature rate through the element's lag (°C/s; the axis `offset` places
    /// further on, τ from [`ELEMENT_RATE_TIME_CONSTANTS_S`]): a bias that follows a neighbour's
    /// heating, as a shared substrate or a capsule's gas would carry it.
    OtherAxisRate {
        /// The axis `offset` (1 or 2) places further on.
        offset: usize,
        /// The low-pass's time constant, s.
        time_constant_s: u32,
    },
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
    /// Every kind a segment with these auxiliary channels (each with its calibration mean)
    /// offers.
    pub fn all(
        aux_channels: impl IntoIterator<Item = (String, f64)>,
        has_set_point: bool,
    ) -> Vec<Self> {
        let channels: Vec<(String, f64)> = aux_channels.into_iter().collect();
        let mut kinds: Vec<Self> = channels.iter().map(|(c, _)| Self::Aux(c.clone())).collect();
        // The chamber's set point is constant over a recording: its interactions are what stage 2
        // (the ambient) and stage 3 (the rise) already read.
        for (channel, centre) in channels.iter().filter(|(c, _)| c != SET_POINT_CHANNEL) {
            kinds.push(Self::AuxTimesRise(Deviation::new(channel, *centre)));
            kinds.push(Self::AuxTimesTemperature(Deviation::new(channel, *centre)));
        }
        kinds.extend(
            SENSOR_RATE_TIME_CONSTANTS_S
                .map(|time_constant_s| Self::TemperatureRate { time_constant_s }),
        );
        kinds.extend(
            ELEMENT_RATE_TIME_CONSTANTS_S
                .map(|time_constant_s| Self::ElementRate { time_constant_s }),
        );
        for offset in [1, 2] {
            kinds.extend(ELEMENT_RATE_TIME_CONSTANTS_S.map(|time_constant_s| {
                Self::OtherAxisRate {
                    offset,
                    time_constant_s,
                }
            }));
        }
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

    /// The kinds of the bench's context channels (each with its calibration mean): the channel, and
    /// the channel times the rise and times the temperature — what a bench ambient that ramps
    /// does to a unit whose tables read the ambient once, at switch-on. The diagnosis's baseline.
    pub fn context(channels: impl IntoIterator<Item = (String, f64)>) -> Vec<Self> {
        channels
            .into_iter()
            .flat_map(|(channel, centre)| {
                [
                    Self::Aux(channel.clone()),
                    Self::AuxTimesRise(Deviation::new(&channel, centre)),
                    Self::AuxTimesTemperature(Deviation::new(&channel, centre)),
                ]
            })
            .collect()
    }

    /// Whether the kind is a known gap of the paper's model rather than a candidate: the
    /// switch-on temperature and the residual heat at switch-on, constant over an activation,
    /// which the paper's turn-on bias reads only through a switch-on temperature that residual
    /// heat and ambient ramps move. The diagnosis's baseline takes them.
    pub fn is_known_gap(&self) -> bool {
        matches!(self, Self::SwitchOnTemperature | Self::ResidualHeat)
    }

    /// The candidate's name on `axis` (what reports and the term plan read).
    pub fn name(&self, axis: usize) -> String {
        let own = AXES.get(axis).copied().unwrap_or("?");
        match self {
            Self::Aux(channel) => format!("aux:{channel}"),
            Self::TemperatureRate { time_constant_s } => {
                format!("temperature rate {own} (τ {time_constant_s} s)")
            }
            Self::ElementRate { time_constant_s } => {
                format!("element rate {own} (τ {time_constant_s} s)")
            }
            Self::AuxTimesRise(d) => format!("aux:{} × rise {own}", d.channel),
            Self::AuxTimesTemperature(d) => {
                format!(
                    "aux:{} × temperature {own} (from {REFERENCE_CELSIUS} °C)",
                    d.channel
                )
            }
            Self::OtherAxisRate {
                offset,
                time_constant_s,
            } => format!(
                "element rate {} on {own} (τ {time_constant_s} s)",
                AXES[(axis + offset) % 3]
            ),
            Self::RiseSquared => format!("rise² {own}"),
            Self::OtherAxisRise(offset) => format!("rise {}", AXES[(axis + offset) % 3]),
            Self::SinceSwitchOn => "time since switch-on".into(),
            Self::SwitchOnTemperature => "switch-on temperature".into(),
            Self::ResidualHeat => "residual heat at switch-on (off-time)".into(),
            Self::CampaignTime => "campaign time (ageing)".into(),
        }
    }

    /// The low-pass time constant, s, of an own-axis rate candidate's name (what [`Self::name`]
    /// writes: "temperature rate X (τ 8 s)", "element rate X (τ 30 s)"); `None` for any other
    /// name, another axis's rate ("element rate Y on X (τ 30 s)") included.
    pub fn rate_time_constant_s(name: &str) -> Option<u32> {
        let (axis, tau) = name
            .strip_prefix("temperature rate ")
            .or_else(|| name.strip_prefix("element rate "))?
            .split_once(" (τ ")?;
        if !AXES.contains(&axis) {
            return None;
        }
        tau.strip_suffix(" s)")?.parse().ok()
    }

    /// Whether a candidate's name is a term of the unit's own thermal response beyond the paper's
    /// tables: its rise squared (a sensitivity that is not linear in temperature) and its own
    /// axis's temperature rate, the sensor's or the element's behind it (gradients across the
    /// capsule while it heats, the element's lag) — what a practitioner's thermal calibration
    /// (T, T², a filtered dT/dt) holds. The diagnosis fits them before it looks for effects, so
    /// that an effect is what the unit's heating, represented that well, does not explain.
    pub fn is_thermal_response(name: &str) -> bool {
        name.starts_with("rise² ") || Self::rate_time_constant_s(name).is_some()
    }

    /// Whether a rate candidate's name is the element's rate (its filter starts without the
    /// heating) rather than the sensor's.
    pub fn is_element_rate(name: &str) -> bool {
        name.starts_with("element rate ") && Self::rate_time_constant_s(name).is_some()
    }

    /// The candidate's values on every axis of `segment`, one per sample; `switch_on` is the raw
    /// switch-on temperature per axis, `start` where a rate's filter starts (as the firmware's term
    /// starts). `None` when the segment lacks what the kind needs.
    pub fn values(
        &self,
        segment: &Segment,
        switch_on: [f32; 3],
        start: &StartRates,
    ) -> Option<[Vec<f32>; 3]> {
        let n = segment.len();
        let rate_hz = f64::from(segment.sample_rate_hz.max(1));
        let scale = segment.temperature_scale;
        let on_celsius = switch_on.map(|r| scale.celsius(f64::from(r)));
        let same = |values: Vec<f32>| Some([values.clone(), values.clone(), values]);
        let per_axis = |f: &dyn Fn(usize) -> Vec<f32>| Some([f(0), f(1), f(2)]);
        let rise = |axis: usize| -> Vec<f64> {
            // Low-passed like the residual, so a candidate carries no noise the residual lacks.
            centred_moving_average(
                &segment.temperature_raw[axis],
                segment.sample_rate_hz as usize,
            )
            .into_iter()
            .map(|r| scale.celsius(r) - on_celsius[axis])
            .collect()
        };
        let aux = |name: &str| -> Option<Vec<f64>> {
            let channel = segment.aux.get(name)?;
            if channel.values.is_empty() {
                return None;
            }
            let ratio = f64::from(channel.sample_rate_hz) / rate_hz;
            Some(
                (0..n)
                    .map(|i| {
                        let at = ((i as f64 * ratio) as usize).min(channel.values.len() - 1);
                        f64::from(channel.values[at])
                    })
                    .collect(),
            )
        };
        let deviation = |d: &Deviation| -> Option<Vec<f64>> {
            Some(
                aux(&d.channel)?
                    .into_iter()
                    .map(|v| v - d.centre())
                    .collect(),
            )
        };
        let times = |channel: &[f64], heat: Vec<f64>| -> Vec<f32> {
            channel
                .iter()
                .zip(heat)
                .map(|(c, h)| (c * h) as f32)
                .collect()
        };
        match self {
            Self::Aux(channel) => same(aux(channel)?.into_iter().map(|v| v as f32).collect()),
            Self::AuxTimesRise(d) => {
                let channel = deviation(d)?;
                per_axis(&|axis| times(&channel, rise(axis)))
            }
            Self::AuxTimesTemperature(d) => {
                let channel = deviation(d)?;
                per_axis(&|axis| {
                    let from_reference = rise(axis)
                        .into_iter()
                        .map(|r| r + on_celsius[axis] - REFERENCE_CELSIUS)
                        .collect();
                    times(&channel, from_reference)
                })
            }
            Self::OtherAxisRate {
                offset,
                time_constant_s,
            } => per_axis(&|axis| {
                let other = (axis + offset) % 3;
                filtered_rate(
                    &rise(other),
                    f64::from(*time_constant_s),
                    1.0 / rate_hz,
                    f64::from(start.element[other]),
                )
            }),
            Self::TemperatureRate { time_constant_s } | Self::ElementRate { time_constant_s } => {
                let from = match self {
                    Self::ElementRate { .. } => &start.element,
                    _ => &start.sensor,
                };
                per_axis(&|axis| {
                    filtered_rate(
                        &rise(axis),
                        f64::from(*time_constant_s),
                        1.0 / rate_hz,
                        f64::from(from[axis]),
                    )
                })
            }
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

/// The rate of `rise` (°C, one value per `step_s`) through a first-order low-pass of time constant
/// `tau_s`, as drift-core's rate term steps it (backward Euler on the lag `rise − filtered`, the
/// filter starting `start_rate · τ` below the first rise): `start_rate` at switch-on, the rate of a
/// steady ramp after a few τ.
pub fn filtered_rate(rise: &[f64], tau_s: f64, step_s: f64, start_rate: f64) -> Vec<f32> {
    let keep = tau_s / (tau_s + step_s);
    let mut filtered = rise.first().copied().unwrap_or(0.0) - start_rate * tau_s;
    rise.iter()
        .enumerate()
        .map(|(i, &r)| {
            // The first sample is the switch-on itself: no time has passed to step over.
            let lag = (r - filtered) * if i == 0 { 1.0 } else { keep };
            filtered = r - lag;
            (lag / tau_s) as f32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use drift_core::{Extension, ExtensionState, ExtraTerm, Term, TermInputs};

    /// A rate candidate's name gives back its filter; no other name does.
    #[test]
    fn a_rate_candidates_name_carries_its_time_constant_and_start() {
        for time_constant_s in SENSOR_RATE_TIME_CONSTANTS_S {
            let name = Kind::TemperatureRate { time_constant_s }.name(1);
            assert_eq!(
                Kind::rate_time_constant_s(&name),
                Some(time_constant_s),
                "{name}"
            );
            assert!(!Kind::is_element_rate(&name), "{name}");
        }
        for time_constant_s in ELEMENT_RATE_TIME_CONSTANTS_S {
            let name = Kind::ElementRate { time_constant_s }.name(2);
            assert_eq!(
                Kind::rate_time_constant_s(&name),
                Some(time_constant_s),
                "{name}"
            );
            assert!(Kind::is_element_rate(&name), "{name}");
        }
        for other in [
            Kind::RiseSquared.name(0),
            "temperature rate X".to_owned(),
            "element rate Y".to_owned(),
        ] {
            assert_eq!(Kind::rate_time_constant_s(&other), None, "{other}");
            assert!(!Kind::is_element_rate(&other), "{other}");
        }
        let neighbour = Kind::OtherAxisRate {
            offset: 1,
            time_constant_s: 30,
        };
        assert_eq!(neighbour.name(0), "element rate Y on X (τ 30 s)");
        assert_eq!(Kind::rate_time_constant_s(&neighbour.name(0)), None);
        for kind in [
            Kind::AuxTimesRise(Deviation::new("supply_voltage", 3.3)),
            Kind::AuxTimesTemperature(Deviation::new("supply_voltage", 3.3)),
        ] {
            assert_eq!(Kind::rate_time_constant_s(&kind.name(2)), None);
        }
    }

    /// The diagnosis scores the rate the firmware's term computes: drift-core's filter, fed the
    /// same rise, gives the same values, started at rest or at a rate.
    #[test]
    fn the_filtered_rate_is_drift_cores_rate_term() {
        let (tau_s, step_ms) = (8_u32, 10_u32);
        let rise: Vec<f64> = (0..6000)
            .map(|i| 5.0 * (1.0 - (-f64::from(i * step_ms) / 60_000.0).exp()))
            .collect();
        let mut extension = Extension::NONE;
        let term = ExtraTerm {
            term: Term::TemperatureRate {
                time_constant_ms: tau_s * 1000,
            },
            centre: [0.0; 3],
            coefficient: [1.0; 3],
        };
        extension.terms.push(term).unwrap();
        // Ours against drift-core's, started as a cold start heating at `heating` °C/s.
        let mut compare = |heating: f32| -> Vec<f32> {
            let ours = filtered_rate(
                &rise,
                f64::from(tau_s),
                f64::from(step_ms) / 1000.0,
                f64::from(heating),
            );
            extension.switch_on_rate = [drift_core::SwitchOnRate {
                heating_celsius_per_s: heating,
                ..drift_core::SwitchOnRate::AT_REST
            }; 3];
            let cold = [drift_core::SwitchOn::estimate(30.0, None); 3];
            let mut state = ExtensionState::power_on_after(&extension, &cold);
            for (i, (&r, &mine)) in rise.iter().zip(&ours).enumerate() {
                let inputs = TermInputs {
                    since_power_on_ms: u32::try_from(i).unwrap() * step_ms,
                    rise_celsius: [r as f32; 3],
                    ..TermInputs::default()
                };
                let firmware = state.values(&extension, &inputs)[0][0];
                assert!(
                    (firmware - mine).abs() < 2e-5,
                    "start {heating}, sample {i}: {firmware} vs {mine}"
                );
            }
            ours
        };
        let ours = compare(0.0);
        // The rate through the low-pass: a first-order low-pass of time constant τ turns the
        // decaying rate (5/T)·e^(−t/T) into the same exponential times T/(T − τ) once its own
        // start (e^(−t/τ)) has died away; at t = 60 s that is e^(−7.5) ≈ 6e-4 of it.
        let (t, big_t, tau): (f64, f64, f64) = (59.99, 60.0, f64::from(tau_s));
        let expected = 5.0 / big_t * (-t / big_t).exp() * big_t / (big_t - tau);
        let at = f64::from(ours[6000 - 1]);
        assert!(
            (at - expected).abs() < 0.005 * expected,
            "{at} vs {expected}"
        );
        assert_eq!(ours[0], 0.0);
        let started = compare(0.12);
        assert!((started[0] - 0.12).abs() < 1e-6, "{}", started[0]);
    }
}
