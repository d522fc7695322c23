//! What to record: the campaign description (TOML or JSON), with the paper's protocol as
//! the default.

use crate::error::SimError;
use crate::faults::SensorFaults;
use crate::hidden::HiddenEffects;
use crate::motion::Motion;
use crate::unit::UnitModel;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A calibration campaign.
///
/// In a file, the `[protocol]` and `[field]` tables say which kinds of series are recorded;
/// when neither is present the paper's protocol is recorded with its defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Campaign {
    /// Name, written into every recording's metadata.
    pub name: String,
    /// Seed of every random draw: same campaign + seed = same bits.
    pub seed: u64,
    /// Number of simulated units (each draws its own parameters).
    pub units: u32,
    /// Output rate (Hz). Must be a multiple of 100 and divide 10⁹ (1000 in the paper).
    pub sample_rate_hz: u32,
    /// Chamber set points (°C), recorded in this order (one file per unit and set point).
    pub set_points_celsius: Vec<f64>,
    /// Physical units, units with zero systematic drift (noise floor), or units the paper's model
    /// represents exactly (a true null case).
    pub unit_model: UnitModel,
    /// Scales every random component (white noise, bias instability, turn-on jitter,
    /// temperature-sensor noise, heating scatter): 1 = physical, 0 = noise-free truth.
    pub noise_scale: f64,
    /// The paper's protocol (series of activations at fixed intervals).
    #[serde(default)]
    pub protocol: Option<Protocol>,
    /// Field-like sessions.
    #[serde(default)]
    pub field: Option<Field>,
    /// Hidden effects (all off by default).
    pub effects: HiddenEffects,
    /// Rate of the ground-truth bias in the sidecar.
    pub truth_bias: TruthBias,
    /// Temperature-sensor faults injected at run time (all off by default; ground truth).
    pub faults: SensorFaults,
}

/// How densely the sidecar stores the true (noise-free) bias.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TruthBias {
    /// Every gyro sample (exact, ~doubles the bytes written).
    #[default]
    EverySample,
    /// At the 100 Hz auxiliary rate. The systematic bias is smooth (thermal time
    /// constants ≥ 8 s), so linear interpolation between 10-ms points is exact to
    /// ~1e-8 °/s, far below the output LSB; the sidecar is 3× smaller.
    AuxRate,
}

/// The paper's protocol: series of activations with a fixed off-time between them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Protocol {
    /// Off-times between activations (min), one series kind each.
    pub intervals_min: Vec<f64>,
    /// Activations per series.
    pub activations: u32,
    /// Duration of each activation (s).
    pub activation_s: f64,
    /// Recordings of each series.
    pub repeats: u32,
    /// Off-time before each series (min): full cool-down.
    pub rest_min: f64,
    /// Per-activation, per-axis 1σ relative scatter of the ASIC heating power.
    pub heating_scatter: f64,
    /// Amplitude of the chamber's regulation cycle around the set point (°C): the air a real
    /// chamber holds is not constant. Scaled by `noise_scale`.
    pub chamber_ripple_c: f64,
    /// Period range of the chamber's regulation cycle (min), drawn per recording, uniform.
    pub chamber_period_min: [f64; 2],
}

impl Default for Protocol {
    fn default() -> Self {
        Self {
            intervals_min: vec![1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0],
            activations: 5,
            activation_s: 120.0,
            repeats: 3,
            rest_min: 60.0,
            heating_scatter: 0.005,
            // Temperature chambers hold ±0.1–0.5 °C; compressor cycles take minutes.
            chamber_ripple_c: 0.2,
            chamber_period_min: [5.0, 20.0],
        }
    }
}

/// Field-like sessions: the unit used the way it is used, not the way it is calibrated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Field {
    /// Sessions per unit and set point (each starts after `rest_min`).
    pub sessions: u32,
    /// Activations per session.
    pub activations: u32,
    /// Activation duration range (s), uniform.
    pub activation_s: [f64; 2],
    /// Off-time range between activations (min), log-uniform.
    pub off_min: [f64; 2],
    /// Largest |ambient ramp| during an activation (°C/min), uniform in ±.
    pub ambient_ramp_c_per_min: f64,
    /// Largest |ambient − set point| (°C); ramps turn back at this limit.
    pub ambient_excursion_c: f64,
    /// Probability that the unit is carried to another ambient just before a switch-on.
    pub carry_probability: f64,
    /// Largest |ambient step| when carried (°C).
    pub carry_step_c: f64,
    /// Supply voltage range per activation (V), uniform.
    pub supply_v: [f64; 2],
    /// Probability that the orientation changes before an activation.
    pub orientation_change_probability: f64,
    /// Per-activation, per-axis 1σ relative scatter of the ASIC heating power.
    pub heating_scatter: f64,
    /// Off-time before each session (min).
    pub rest_min: f64,
    /// Rotations with still gaps during each activation; `None` holds the unit static.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<Motion>,
}

impl Default for Field {
    fn default() -> Self {
        Self {
            sessions: 2,
            activations: 8,
            activation_s: [60.0, 180.0],
            off_min: [0.5, 40.0],
            ambient_ramp_c_per_min: 3.0,
            ambient_excursion_c: 10.0,
            carry_probability: 0.2,
            carry_step_c: 15.0,
            supply_v: [4.6, 5.4],
            orientation_change_probability: 0.5,
            heating_scatter: 0.03,
            rest_min: 60.0,
            motion: None,
        }
    }
}

impl Default for Campaign {
    /// The paper's campaign: 2 units, +30/+40 °C (calibration) and +33 °C (validation),
    /// the full protocol.
    fn default() -> Self {
        Self {
            name: "paper".into(),
            seed: 1,
            units: 2,
            sample_rate_hz: 1000,
            set_points_celsius: drift_recording::paper::CAMPAIGN_SET_POINTS_CELSIUS.to_vec(),
            unit_model: UnitModel::Physical,
            noise_scale: 1.0,
            protocol: Some(Protocol::default()),
            field: None,
            effects: HiddenEffects::default(),
            truth_bias: TruthBias::EverySample,
            faults: SensorFaults::default(),
        }
    }
}

/// Set points from `from` to `to` (inclusive) in `step` (e.g. −40…+60 in 10 °C steps).
pub fn set_point_range(from: f64, to: f64, step: f64) -> Vec<f64> {
    if step.is_nan() || step <= 0.0 || to < from {
        return Vec::new();
    }
    let n = ((to - from) / step + 1e-9).floor() as usize;
    (0..=n).map(|k| from + step * k as f64).collect()
}

/// Seconds in a (Julian) year.
const SECONDS_PER_YEAR: f64 = 365.25 * 86_400.0;
/// Longest recording the format's u64-ns clock holds with room to spare: 100 years (the clock
/// wraps after 584).
const MAX_RECORDING_S: f64 = 100.0 * SECONDS_PER_YEAR;

impl Campaign {
    /// Reads a campaign file: `.json` as JSON, anything else as TOML.
    pub fn from_file(path: &Path) -> Result<Self, SimError> {
        let text = std::fs::read_to_string(path).map_err(|e| SimError::io(path, e))?;
        let parse_err = |reason: String| SimError::Parse {
            path: path.to_path_buf(),
            reason,
        };
        let mut campaign: Self = if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            serde_json::from_str(&text).map_err(|e| parse_err(e.to_string()))?
        } else {
            toml::from_str(&text).map_err(|e| parse_err(e.to_string()))?
        };
        if campaign.protocol.is_none() && campaign.field.is_none() {
            campaign.protocol = Some(Protocol::default());
        }
        campaign.validate()?;
        Ok(campaign)
    }

    /// Checks every field; the error names the field and what was expected.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |f: &str, r: &str| SimError::campaign(f, r);
        if self.units == 0 {
            return Err(bad("units", "must be ≥ 1"));
        }
        if self.sample_rate_hz == 0
            || self.sample_rate_hz % 100 != 0
            || 1_000_000_000 % self.sample_rate_hz != 0
        {
            return Err(bad(
                "sample_rate_hz",
                &format!(
                    "must be a multiple of 100 that divides 10⁹, got {}",
                    self.sample_rate_hz
                ),
            ));
        }
        if self.set_points_celsius.is_empty() {
            return Err(bad("set_points_celsius", "need at least one set point"));
        }
        for (i, t) in self.set_points_celsius.iter().enumerate() {
            if !(t.is_finite() && (-60.0..=100.0).contains(t)) {
                return Err(bad(
                    &format!("set_points_celsius[{i}]"),
                    &format!("must be in −60…+100 °C, got {t}"),
                ));
            }
        }
        // Files are named by the set point to 0.1 °C: two that round alike would write one file.
        for (j, b) in self.set_points_celsius.iter().enumerate() {
            let name = format!("{b:+.1}");
            if let Some(i) = self.set_points_celsius[..j]
                .iter()
                .position(|a| format!("{a:+.1}") == name)
            {
                return Err(bad(
                    &format!("set_points_celsius[{j}]"),
                    &format!(
                        "{b} °C names the same recording files ({name} °C) as set_points_celsius[{i}] \
                         = {} °C; give each set point once (--set-points), at least 0.1 °C apart",
                        self.set_points_celsius[i]
                    ),
                ));
            }
        }
        if !(self.noise_scale.is_finite() && self.noise_scale >= 0.0) {
            return Err(bad(
                "noise_scale",
                &format!("must be ≥ 0, got {}", self.noise_scale),
            ));
        }
        if self.unit_model == UnitModel::ZeroSystematicDrift && !self.effects.active().is_empty() {
            return Err(bad(
                "effects",
                "a zero-systematic-drift unit cannot carry hidden effects",
            ));
        }
        if self.protocol.is_none() && self.field.is_none() {
            return Err(bad(
                "protocol/field",
                "nothing to record: give [protocol] and/or [field]",
            ));
        }
        self.faults.validate()?;
        if let Some(p) = &self.protocol {
            if p.intervals_min.is_empty() {
                return Err(bad("protocol.intervals_min", "need at least one interval"));
            }
            for (i, m) in p.intervals_min.iter().enumerate() {
                if !(m.is_finite() && *m > 0.0) {
                    return Err(bad(
                        &format!("protocol.intervals_min[{i}]"),
                        &format!("must be > 0 min, got {m}"),
                    ));
                }
            }
            check_activations("protocol", p.activations, p.repeats.max(1))?;
            if p.repeats == 0 {
                return Err(bad("protocol.repeats", "must be ≥ 1"));
            }
            check_duration("protocol.activation_s", p.activation_s)?;
            check_nonneg("protocol.rest_min", p.rest_min)?;
            check_fraction("protocol.heating_scatter", p.heating_scatter)?;
            check_nonneg("protocol.chamber_ripple_c", p.chamber_ripple_c)?;
            if p.chamber_ripple_c > 10.0 {
                return Err(bad(
                    "protocol.chamber_ripple_c",
                    &format!("must be ≤ 10 °C, got {}", p.chamber_ripple_c),
                ));
            }
            check_ordered("protocol.chamber_period_min", p.chamber_period_min)?;
            if p.chamber_period_min[0] <= 0.0 {
                return Err(bad(
                    "protocol.chamber_period_min",
                    &format!("must be > 0 min, got {:?}", p.chamber_period_min),
                ));
            }
            // A recording's clock is u64 ns, and the reader refuses one that wraps: a set point's
            // file holds every series, so all of them must fit it.
            let series_s: f64 = p
                .intervals_min
                .iter()
                .map(|m| f64::from(p.activations) * (p.activation_s + 60.0 * (m + p.rest_min)))
                .sum();
            let file_s = f64::from(p.repeats) * series_s;
            if file_s > MAX_RECORDING_S {
                let (i, m) = p
                    .intervals_min
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.total_cmp(b.1))
                    .map_or((0, 0.0), |(i, m)| (i, *m));
                return Err(bad(
                    &format!("protocol.intervals_min[{i}]"),
                    &format!(
                        "{m} min makes a recording {:.3e} years long; a recording's clock holds {} years",
                        file_s / SECONDS_PER_YEAR,
                        MAX_RECORDING_S / SECONDS_PER_YEAR
                    ),
                ));
            }
        }
        if let Some(f) = &self.field {
            check_activations("field", f.activations, f.sessions)?;
            for d in f.activation_s {
                check_duration("field.activation_s", d)?;
            }
            check_ordered("field.activation_s", f.activation_s)?;
            check_ordered("field.off_min", f.off_min)?;
            let session_s =
                f64::from(f.activations) * (f.activation_s[1] + 60.0 * (f.off_min[1] + f.rest_min));
            if session_s > MAX_RECORDING_S {
                return Err(bad(
                    "field.off_min",
                    &format!(
                        "makes a session up to {:.3e} years long; a recording's clock holds {} years",
                        session_s / SECONDS_PER_YEAR,
                        MAX_RECORDING_S / SECONDS_PER_YEAR
                    ),
                ));
            }
            if f.off_min[0] <= 0.0 {
                return Err(bad(
                    "field.off_min",
                    "lower bound must be > 0 (log-uniform)",
                ));
            }
            check_ordered("field.supply_v", f.supply_v)?;
            if f.supply_v[0] <= 0.0 {
                return Err(bad("field.supply_v", "must be > 0 V"));
            }
            check_nonneg("field.ambient_ramp_c_per_min", f.ambient_ramp_c_per_min)?;
            check_nonneg("field.ambient_excursion_c", f.ambient_excursion_c)?;
            check_nonneg("field.carry_step_c", f.carry_step_c)?;
            check_nonneg("field.rest_min", f.rest_min)?;
            check_probability("field.carry_probability", f.carry_probability)?;
            check_probability(
                "field.orientation_change_probability",
                f.orientation_change_probability,
            )?;
            check_fraction("field.heating_scatter", f.heating_scatter)?;
            if let Some(m) = &f.motion {
                for d in m.rotation_s {
                    check_duration("field.motion.rotation_s", d)?;
                }
                check_ordered("field.motion.rotation_s", m.rotation_s)?;
                check_ordered("field.motion.rate_dps", m.rate_dps)?;
                check_nonneg("field.motion.rate_dps", m.rate_dps[0])?;
                check_ordered("field.motion.still_s", m.still_s)?;
                check_nonneg("field.motion.still_s", m.still_s[0])?;
                if m.still_s[1] > 86_400.0 {
                    return Err(bad("field.motion.still_s", "must be ≤ 24 h"));
                }
            }
        }
        Ok(())
    }
}

fn check_activations(what: &str, activations: u32, series: u32) -> Result<(), SimError> {
    if activations == 0 || activations > 10_000 {
        return Err(SimError::campaign(
            format!("{what}.activations"),
            format!("must be 1…10000, got {activations}"),
        ));
    }
    if series == 0 {
        return Err(SimError::campaign(
            format!("{what}.sessions"),
            "must be ≥ 1",
        ));
    }
    Ok(())
}
fn check_duration(field: &str, s: f64) -> Result<(), SimError> {
    // An activation must hold at least one 100-ms batch and stay within u32 sample indices.
    if !(s.is_finite() && (0.1..=86_400.0).contains(&s)) {
        return Err(SimError::campaign(
            field,
            format!("must be 0.1 s … 24 h, got {s}"),
        ));
    }
    Ok(())
}
fn check_nonneg(field: &str, v: f64) -> Result<(), SimError> {
    if !(v.is_finite() && v >= 0.0) {
        return Err(SimError::campaign(
            field,
            format!("must be finite and ≥ 0, got {v}"),
        ));
    }
    Ok(())
}
fn check_fraction(field: &str, v: f64) -> Result<(), SimError> {
    if !(v.is_finite() && (0.0..0.5).contains(&v)) {
        return Err(SimError::campaign(
            field,
            format!("must be in [0, 0.5), got {v}"),
        ));
    }
    Ok(())
}
fn check_probability(field: &str, v: f64) -> Result<(), SimError> {
    if !(0.0..=1.0).contains(&v) {
        return Err(SimError::campaign(
            field,
            format!("must be a probability in [0, 1], got {v}"),
        ));
    }
    Ok(())
}
fn check_ordered(field: &str, r: [f64; 2]) -> Result<(), SimError> {
    if !(r[0].is_finite() && r[1].is_finite() && r[0] <= r[1]) {
        return Err(SimError::campaign(
            field,
            format!("must be [low, high] with low ≤ high, got {r:?}"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_and_json_read_the_same_campaign() {
        let dir = tempfile::tempdir().unwrap();
        let toml_path = dir.path().join("c.toml");
        std::fs::write(&toml_path, "name = \"t\"\nseed = 9\nset_points_celsius = [30.0]\n[protocol]\nintervals_min = [1.0, 15.0]\nrepeats = 1\n[effects.thermal_lag]\n").unwrap();
        let from_toml = Campaign::from_file(&toml_path).unwrap();
        assert_eq!(from_toml.seed, 9);
        assert_eq!(from_toml.protocol.as_ref().unwrap().activations, 5);
        assert!(from_toml.effects.thermal_lag.is_some());
        assert!(from_toml.field.is_none());
        let json_path = dir.path().join("c.json");
        std::fs::write(&json_path, serde_json::to_string(&from_toml).unwrap()).unwrap();
        assert_eq!(Campaign::from_file(&json_path).unwrap(), from_toml);
    }

    #[test]
    fn invalid_fields_are_named() {
        let mut c = Campaign::default();
        c.protocol.as_mut().unwrap().intervals_min[2] = -1.0;
        let e = c.validate().unwrap_err().to_string();
        assert!(e.contains("protocol.intervals_min[2]"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.toml");
        std::fs::write(&p, "sede = 3\n").unwrap();
        let e = Campaign::from_file(&p).unwrap_err().to_string();
        assert!(e.contains("sede"), "{e}");
    }

    #[test]
    fn wide_range_set_points() {
        let r = set_point_range(-40.0, 60.0, 10.0);
        assert_eq!(r.len(), 11);
        assert_eq!(r[0], -40.0);
        assert_eq!(r[10], 60.0);
    }
}
