//! Temperature-sensor faults injected into activations at run time: dropouts, a stuck reading,
//! spikes. All off by default (`None`); a campaign file switches one on by writing its table (e.g.
//! `[faults.dropout]`), with default magnitudes that can be overridden.
//!
//! What a recording shows is only what a bench would log: a dropout is the missing-reading marker
//! ([`drift_recording::TEMPERATURE_MISSING_RAW`]), a stuck sensor repeats its last reading, a spike
//! is a wrong reading. Where and what was injected is ground truth: in `truth/campaign.json` and in
//! each sidecar's metadata record [`FAULTS_METADATA`] (never in a recording's metadata).
//! Faults are drawn from a random stream of their own, so switching them on changes no other bit
//! of the recording: a faulty campaign and its fault-free twin differ only at the faults.

use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::error::SimError;
use drift_recording::{RAW_PER_CELSIUS, TEMPERATURE_MISSING_RAW};

/// Name of the truth sidecar's metadata record that lists the injected faults (key `events`,
/// a JSON array of [`FaultEvent`]).
pub const FAULTS_METADATA: &str = "gyrodrift.faults";

/// The switchable sensor faults of a campaign (all off by default).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorFaults {
    /// The temperature reading is missing for a while (bus error, sensor reset).
    pub dropout: Option<FaultWindow>,
    /// The temperature reading freezes at its last value for a while.
    pub stuck: Option<FaultWindow>,
    /// Single wrong temperature readings (EMI, a torn read).
    pub spikes: Option<Spikes>,
}

/// Where and how long a window fault (dropout, stuck) hits an activation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FaultWindow {
    /// Probability that an activation has the fault.
    pub probability: f64,
    /// Start, seconds after switch-on, uniform in [low, high].
    pub start_s: [f64; 2],
    /// Duration, seconds, uniform in [low, high] (cut at the end of the activation).
    pub duration_s: [f64; 2],
    /// Every axis's sensor at once; otherwise one axis, drawn per activation.
    pub all_axes: bool,
}

impl Default for FaultWindow {
    fn default() -> Self {
        // Inside the heating transient, longer than the corrector's stuck limit (2 s at 1 kHz).
        Self {
            probability: 1.0,
            start_s: [20.0, 60.0],
            duration_s: [3.0, 10.0],
            all_axes: false,
        }
    }
}

/// Isolated wrong readings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Spikes {
    /// Probability that an activation has spikes.
    pub probability: f64,
    /// Spikes per affected activation, each on one sample of one drawn axis.
    pub count: u32,
    /// Spike size, °C, added with a random sign.
    pub amplitude_celsius: f64,
}

impl Default for Spikes {
    fn default() -> Self {
        Self {
            probability: 1.0,
            count: 10,
            amplitude_celsius: 5.0,
        }
    }
}

/// What a fault does to the reading.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// Reading missing (the marker).
    #[default]
    Dropout,
    /// Reading frozen at the value before the window.
    Stuck,
    /// Reading offset by `offset_raw`.
    Spike,
}

/// One injected fault (ground truth).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FaultEvent {
    /// Series, repeat and activation of the faulty activation (its recording labels).
    pub series: u32,
    /// Repeat.
    pub repeat: u32,
    /// Activation.
    pub activation: u32,
    /// Axis, 0..3.
    pub axis: usize,
    /// Kind.
    pub kind: FaultKind,
    /// First faulty sample (index since switch-on).
    pub start_sample: u32,
    /// Faulty samples.
    pub samples: u32,
    /// Spike offset, raw units (0 for the other kinds).
    pub offset_raw: i32,
}

impl SensorFaults {
    /// Whether any fault is switched on.
    pub fn any(&self) -> bool {
        self.dropout.is_some() || self.stuck.is_some() || self.spikes.is_some()
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), SimError> {
        let probability = |field: &str, p: f64| {
            if (0.0..=1.0).contains(&p) {
                Ok(())
            } else {
                Err(SimError::campaign(
                    field,
                    format!("must be a probability in [0, 1], got {p}"),
                ))
            }
        };
        for (name, window) in [("dropout", &self.dropout), ("stuck", &self.stuck)] {
            let Some(w) = window else { continue };
            probability(&format!("faults.{name}.probability"), w.probability)?;
            for (field, range) in [("start_s", w.start_s), ("duration_s", w.duration_s)] {
                if !(range[0].is_finite()
                    && range[1].is_finite()
                    && 0.0 <= range[0]
                    && range[0] <= range[1])
                {
                    return Err(SimError::campaign(
                        format!("faults.{name}.{field}"),
                        format!("must be [low, high] with 0 ≤ low ≤ high, got {range:?}"),
                    ));
                }
            }
        }
        if let Some(s) = &self.spikes {
            probability("faults.spikes.probability", s.probability)?;
            if !(s.amplitude_celsius.is_finite() && s.amplitude_celsius > 0.0) {
                return Err(SimError::campaign(
                    "faults.spikes.amplitude_celsius",
                    format!("must be > 0 °C, got {}", s.amplitude_celsius),
                ));
            }
        }
        Ok(())
    }

    /// Draws the faults of one activation of `samples` samples at `rate_hz`.
    pub(crate) fn draw(
        &self,
        r: &mut ChaCha8Rng,
        labels: (u32, u32, u32),
        samples: u32,
        rate_hz: u32,
    ) -> Vec<FaultEvent> {
        let mut events = Vec::new();
        let fs = f64::from(rate_hz);
        let (series, repeat, activation) = labels;
        let mut event = |axis, kind, start: u32, length: u32, offset_raw| {
            let start = start.min(samples);
            let length = length.min(samples - start);
            if length > 0 {
                events.push(FaultEvent {
                    series,
                    repeat,
                    activation,
                    axis,
                    kind,
                    start_sample: start,
                    samples: length,
                    offset_raw,
                });
            }
        };
        let windows = [
            (FaultKind::Dropout, &self.dropout),
            (FaultKind::Stuck, &self.stuck),
        ];
        for (kind, window) in windows {
            let Some(w) = window else { continue };
            // Draw every number whether or not the fault fires, so each draw is stable.
            let fires = r.random::<f64>() < w.probability;
            let start = (w.start_s[0] + (w.start_s[1] - w.start_s[0]) * r.random::<f64>()) * fs;
            let length =
                (w.duration_s[0] + (w.duration_s[1] - w.duration_s[0]) * r.random::<f64>()) * fs;
            let axis = r.random_range(0..3usize);
            if fires {
                let axes = if w.all_axes { 0..3 } else { axis..axis + 1 };
                for a in axes {
                    event(a, kind, start as u32, length.max(1.0) as u32, 0);
                }
            }
        }
        if let Some(s) = &self.spikes {
            if r.random::<f64>() < s.probability {
                for _ in 0..s.count {
                    let at = r.random_range(0..samples.max(1));
                    let axis = r.random_range(0..3usize);
                    let sign = if r.random::<bool>() { 1.0 } else { -1.0 };
                    let offset = (sign * s.amplitude_celsius * RAW_PER_CELSIUS).round() as i32;
                    event(axis, FaultKind::Spike, at, 1, offset);
                }
            }
        }
        events
    }
}

/// Applies one activation's faults to its raw readings as they are produced.
pub(crate) struct Injector<'a> {
    events: &'a [FaultEvent],
    /// Per axis: the reading a stuck sensor repeats.
    held: [Option<i16>; 3],
    /// Per axis: the last reading produced (what a sensor freezes at).
    last: [i16; 3],
}

impl<'a> Injector<'a> {
    pub(crate) fn new(events: &'a [FaultEvent]) -> Self {
        Self {
            events,
            held: [None; 3],
            last: [0; 3],
        }
    }

    /// The reading of `axis` at sample `i`, given the healthy reading `raw`.
    pub(crate) fn apply(&mut self, axis: usize, i: u32, raw: i16) -> i16 {
        let mut out = raw;
        let (mut stuck, mut missing) = (false, false);
        for e in self.events.iter().filter(|e| e.axis == axis) {
            if i < e.start_sample || i - e.start_sample >= e.samples {
                continue;
            }
            match e.kind {
                FaultKind::Dropout => missing = true,
                FaultKind::Stuck => stuck = true,
                FaultKind::Spike => {
                    let spiked = i32::from(out).saturating_add(e.offset_raw);
                    // Saturate inside the valid range: a spike is a wrong reading, not a dropout.
                    out = spiked.clamp(i32::from(i16::MIN) + 1, i32::from(i16::MAX)) as i16;
                }
            }
        }
        // Precedence when windows overlap: no reading at all, then a frozen one, then a spike.
        if stuck {
            out = *self.held[axis].get_or_insert(self.last[axis]);
        } else {
            self.held[axis] = None;
        }
        if missing {
            return TEMPERATURE_MISSING_RAW;
        }
        self.last[axis] = out;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_changes_only_its_samples() {
        let events = [
            FaultEvent {
                series: 1,
                repeat: 1,
                activation: 1,
                axis: 0,
                kind: FaultKind::Dropout,
                start_sample: 2,
                samples: 2,
                offset_raw: 0,
            },
            FaultEvent {
                axis: 1,
                kind: FaultKind::Stuck,
                start_sample: 3,
                samples: 3,
                ..Default::default()
            },
            FaultEvent {
                axis: 2,
                kind: FaultKind::Spike,
                start_sample: 4,
                samples: 1,
                offset_raw: 1000,
                ..Default::default()
            },
        ];
        let mut inject = Injector::new(&events);
        let out: Vec<[i16; 3]> = (0..8u32)
            .map(|i| {
                let raw = 6000 + i as i16;
                [0, 1, 2].map(|a| inject.apply(a, i, raw))
            })
            .collect();
        let axis = |a: usize| out.iter().map(|s| s[a]).collect::<Vec<_>>();
        let m = TEMPERATURE_MISSING_RAW;
        assert_eq!(axis(0), [6000, 6001, m, m, 6004, 6005, 6006, 6007]);
        assert_eq!(axis(1), [6000, 6001, 6002, 6002, 6002, 6002, 6006, 6007]);
        assert_eq!(axis(2), [6000, 6001, 6002, 6003, 7004, 6005, 6006, 6007]);
    }

    #[test]
    fn draws_respect_the_activation_and_the_probability() {
        let faults = SensorFaults {
            dropout: Some(FaultWindow {
                start_s: [1.0, 1.0],
                duration_s: [100.0, 100.0],
                all_axes: true,
                ..FaultWindow::default()
            }),
            stuck: Some(FaultWindow {
                probability: 0.0,
                ..FaultWindow::default()
            }),
            spikes: Some(Spikes::default()),
        };
        let mut r = crate::rng::stream(1, &[7]);
        let events = faults.draw(&mut r, (1, 2, 3), 5000, 1000);
        let dropouts: Vec<_> = events
            .iter()
            .filter(|e| e.kind == FaultKind::Dropout)
            .collect();
        assert_eq!(dropouts.len(), 3);
        // Cut at the end of the activation.
        assert!(dropouts
            .iter()
            .all(|e| e.start_sample == 1000 && e.samples == 4000));
        assert!(events.iter().all(|e| e.kind != FaultKind::Stuck));
        assert_eq!(
            events.iter().filter(|e| e.kind == FaultKind::Spike).count(),
            10
        );
        assert!(events
            .iter()
            .all(|e| (e.series, e.repeat, e.activation) == (1, 2, 3)));
        assert!(SensorFaults {
            spikes: Some(Spikes {
                amplitude_celsius: -1.0,
                ..Spikes::default()
            }),
            ..SensorFaults::default()
        }
        .validate()
        .unwrap_err()
        .to_string()
        .contains("faults.spikes.amplitude_celsius"));
    }
}
