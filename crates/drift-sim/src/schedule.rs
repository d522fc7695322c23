//! Expands a campaign into files and activations, with every random choice of the
//! schedule (field off-times, ambient ramps, voltages, orientations, heating scatter)
//! drawn up front from seeded streams. The engine then only integrates physics.

use crate::campaign::{Campaign, Field, Protocol};
use crate::motion::{self, Rotation};
use crate::rng;
use crate::unit::NOMINAL_SUPPLY_V;
use rand::rngs::ChaCha8Rng;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

pub use drift_recording::SeriesKind;

/// One switch-on to switch-off, as planned.
#[derive(Debug, Clone, PartialEq)]
pub struct ActivationPlan {
    /// Series number within the file (from 1).
    pub series: u32,
    /// Repeat of the interval (from 1).
    pub repeat: u32,
    /// Activation within the series (from 1).
    pub activation: u32,
    /// Protocol interval (min); `None` for field sessions.
    pub interval_min: Option<f64>,
    /// Time off before this switch-on (ms).
    pub off_before_ms: u64,
    /// Ambient held during that off-time (°C).
    pub ambient_off_c: f64,
    /// Ambient at switch-on (°C); differs from `ambient_off_c` when the unit was carried.
    pub ambient_on_c: f64,
    /// Ambient ramp during the activation (°C/s).
    pub ambient_ramp_c_per_s: f64,
    /// Number of samples.
    pub samples: u32,
    /// Supply voltage (V).
    pub supply_v: f64,
    /// Gravity direction in the body frame (unit vector; the accelerometer reads +1 g along it).
    pub gravity_body: [f64; 3],
    /// Relative ASIC heating power per axis (1 = nominal).
    pub heating_scale: [f64; 3],
    /// Rotations during the activation, in order (none: held static).
    pub motion: Vec<Rotation>,
}

/// One MCAP file: one unit at one chamber set point, one kind of series.
#[derive(Debug, Clone, PartialEq)]
pub struct FilePlan {
    /// Unit index (0-based).
    pub unit_index: u32,
    /// Chamber set point (°C).
    pub set_point_c: f64,
    /// Series kind.
    pub kind: SeriesKind,
    /// Index of this file in the unit's sequence (0-based), for seeding.
    pub file_index: u32,
    /// File stem, e.g. `GIU-01_sp+30.0C_protocol`.
    pub stem: String,
    /// Campaign time at which the file starts (ms); the unit is in equilibrium then.
    pub start_ms: u64,
    /// Activations in order.
    pub activations: Vec<ActivationPlan>,
}

impl FilePlan {
    /// Samples in the file.
    pub fn samples(&self) -> u64 {
        self.activations.iter().map(|a| u64::from(a.samples)).sum()
    }
    /// Duration from file start to the last switch-off (ms).
    pub fn duration_ms(&self, sample_rate_hz: u32) -> u64 {
        self.activations
            .iter()
            .map(|a| a.off_before_ms + u64::from(a.samples) * 1000 / u64::from(sample_rate_hz))
            .sum()
    }
}

/// Z up, the unit standing on its base (the protocol's orientation).
pub const Z_UP: [f64; 3] = [0.0, 0.0, 1.0];

fn minutes_to_ms(min: f64) -> u64 {
    (min * 60_000.0).round().max(0.0) as u64
}

/// Plans every file of every unit.
pub fn plan(c: &Campaign) -> Vec<FilePlan> {
    let mut files = Vec::new();
    for unit in 0..c.units {
        let mut clock_ms = 0u64;
        let mut file_index = 0u32;
        for &sp in &c.set_points_celsius {
            let kinds = [
                (SeriesKind::Protocol, c.protocol.is_some()),
                (SeriesKind::Field, c.field.is_some()),
            ];
            for (kind, on) in kinds {
                if !on {
                    continue;
                }
                let mut r = rng::stream(
                    c.seed,
                    &[rng::tag("schedule"), u64::from(unit), u64::from(file_index)],
                );
                let mut activations = match (kind, &c.protocol, &c.field) {
                    (SeriesKind::Protocol, Some(p), _) => protocol(p, sp, c, &mut r),
                    (SeriesKind::Field, _, Some(f)) => field(f, sp, c, &mut r),
                    _ => Vec::new(),
                };
                if let (
                    SeriesKind::Field,
                    Some(Field {
                        motion: Some(m), ..
                    }),
                ) = (kind, &c.field)
                {
                    for (k, act) in activations.iter_mut().enumerate() {
                        let mut r = rng::stream(
                            c.seed,
                            &[
                                rng::tag("motion"),
                                u64::from(unit),
                                u64::from(file_index),
                                k as u64,
                            ],
                        );
                        act.motion = motion::plan(m, act.samples, c.sample_rate_hz, &mut r);
                    }
                }
                let stem = format!("GIU-{:02}_sp{:+.1}C_{}", unit + 1, sp, kind.as_str());
                let file = FilePlan {
                    unit_index: unit,
                    set_point_c: sp,
                    kind,
                    file_index,
                    stem,
                    start_ms: clock_ms,
                    activations,
                };
                clock_ms += file.duration_ms(c.sample_rate_hz);
                files.push(file);
                file_index += 1;
            }
        }
    }
    files
}

fn samples_for(seconds: f64, rate: u32) -> u32 {
    ((seconds * f64::from(rate) / 100.0).round().max(1.0) as u32) * 100
}

fn scatter(r: &mut ChaCha8Rng, sigma: f64) -> [f64; 3] {
    let mut s = [1.0; 3];
    for v in &mut s {
        let z: f64 = StandardNormal.sample(r);
        // Clamp at ±4σ so a heating power can never go negative.
        *v = 1.0 + sigma * z.clamp(-4.0, 4.0);
    }
    s
}

fn protocol(p: &Protocol, sp: f64, c: &Campaign, r: &mut ChaCha8Rng) -> Vec<ActivationPlan> {
    let mut out = Vec::new();
    let mut series = 0;
    let samples = samples_for(p.activation_s, c.sample_rate_hz);
    let activation_s = f64::from(samples) / f64::from(c.sample_rate_hz);
    let chamber = ChamberCycle::draw(p, c.noise_scale, r);
    let mut clock_s = 0.0;
    for &interval in &p.intervals_min {
        for repeat in 1..=p.repeats {
            series += 1;
            for activation in 1..=p.activations {
                let off = if activation == 1 {
                    p.rest_min
                } else {
                    interval
                };
                let off_s = off * 60.0;
                // The off-time holds the air at its mid-off value (the exact cooling solution
                // needs it constant); while powered it follows the cycle's chord.
                let ambient_off = sp + chamber.at(clock_s + 0.5 * off_s);
                clock_s += off_s;
                let ambient_on = sp + chamber.at(clock_s);
                let ambient_end = sp + chamber.at(clock_s + activation_s);
                clock_s += activation_s;
                out.push(ActivationPlan {
                    series,
                    repeat,
                    activation,
                    interval_min: Some(interval),
                    off_before_ms: minutes_to_ms(off),
                    ambient_off_c: ambient_off,
                    ambient_on_c: ambient_on,
                    ambient_ramp_c_per_s: (ambient_end - ambient_on) / activation_s,
                    samples,
                    supply_v: NOMINAL_SUPPLY_V,
                    gravity_body: Z_UP,
                    heating_scale: scatter(r, p.heating_scatter * c.noise_scale),
                    motion: Vec::new(),
                });
            }
        }
    }
    out
}

/// A chamber's regulation cycle around its set point: a sinusoid of drawn period and phase.
struct ChamberCycle {
    amplitude_c: f64,
    radians_per_s: f64,
    phase: f64,
}

impl ChamberCycle {
    fn draw(p: &Protocol, noise_scale: f64, r: &mut ChaCha8Rng) -> Self {
        let [low, high] = p.chamber_period_min;
        let period_s = 60.0 * (low + (high - low) * r.random::<f64>());
        Self {
            amplitude_c: p.chamber_ripple_c * noise_scale,
            radians_per_s: std::f64::consts::TAU / period_s,
            phase: std::f64::consts::TAU * r.random::<f64>(),
        }
    }

    /// Deviation from the set point (°C) at `t_s` into the recording.
    fn at(&self, t_s: f64) -> f64 {
        self.amplitude_c * (self.radians_per_s * t_s + self.phase).sin()
    }
}

/// The six faces plus a small tilt: how a unit ends up when put down by hand.
fn random_orientation(r: &mut ChaCha8Rng) -> [f64; 3] {
    let face = r.random_range(0..6usize);
    let mut g = [0.0; 3];
    g[face % 3] = if face < 3 { 1.0 } else { -1.0 };
    let tilt = 5f64.to_radians();
    for v in &mut g {
        *v += tilt * (2.0 * r.random::<f64>() - 1.0);
    }
    let norm = g.iter().map(|v| v * v).sum::<f64>().sqrt();
    g.map(|v| v / norm)
}

fn field(f: &Field, sp: f64, c: &Campaign, r: &mut ChaCha8Rng) -> Vec<ActivationPlan> {
    let mut out = Vec::new();
    let mut ambient = sp;
    let mut gravity = Z_UP;
    for session in 1..=f.sessions {
        for activation in 1..=f.activations {
            let off_min = if activation == 1 {
                f.rest_min
            } else {
                let (lo, hi) = (f.off_min[0].ln(), f.off_min[1].ln());
                (lo + (hi - lo) * r.random::<f64>()).exp()
            };
            let ambient_off = ambient;
            if r.random::<f64>() < f.carry_probability {
                ambient = sp
                    + (ambient - sp + f.carry_step_c * (2.0 * r.random::<f64>() - 1.0))
                        .clamp(-f.ambient_excursion_c, f.ambient_excursion_c);
            }
            let ambient_on = ambient;
            let seconds =
                f.activation_s[0] + (f.activation_s[1] - f.activation_s[0]) * r.random::<f64>();
            let samples = samples_for(seconds, c.sample_rate_hz);
            let duration_s = f64::from(samples) / f64::from(c.sample_rate_hz);
            let mut ramp = f.ambient_ramp_c_per_min / 60.0 * (2.0 * r.random::<f64>() - 1.0);
            // Turn the ramp back rather than leave the excursion band.
            let end = ambient_on + ramp * duration_s - sp;
            if end.abs() > f.ambient_excursion_c {
                ramp = -ramp;
            }
            ambient = ambient_on + ramp * duration_s;
            if r.random::<f64>() < f.orientation_change_probability {
                gravity = random_orientation(r);
            }
            let supply_v = f.supply_v[0] + (f.supply_v[1] - f.supply_v[0]) * r.random::<f64>();
            out.push(ActivationPlan {
                series: session,
                repeat: 1,
                activation,
                interval_min: None,
                off_before_ms: minutes_to_ms(off_min),
                ambient_off_c: ambient_off,
                ambient_on_c: ambient_on,
                ambient_ramp_c_per_s: ramp,
                samples,
                supply_v,
                gravity_body: gravity,
                heating_scale: scatter(r, f.heating_scatter * c.noise_scale),
                motion: Vec::new(),
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_campaign_matches_the_issue_sample_count() {
        let files = plan(&Campaign::default());
        // 2 units × 3 set points, one protocol file each.
        assert_eq!(files.len(), 6);
        let per_unit: u64 = files
            .iter()
            .filter(|f| f.unit_index == 0)
            .map(FilePlan::samples)
            .sum();
        // 3 set points × 7 intervals × 5 activations × 3 repeats × 120 000 samples.
        assert_eq!(per_unit, 3 * 7 * 5 * 3 * 120_000);
        let a = &files[0].activations;
        assert_eq!(
            (a[0].off_before_ms, a[1].off_before_ms),
            (3_600_000, 60_000)
        );
        assert_eq!((a[4].activation, a[5].activation, a[5].repeat), (5, 1, 2));
        // Files follow each other on the unit's clock.
        assert_eq!(files[1].start_ms, files[0].duration_ms(1000));
    }

    #[test]
    fn field_sessions_stay_in_band_and_are_reproducible() {
        let c = Campaign {
            protocol: None,
            field: Some(Field::default()),
            ..Campaign::default()
        };
        let a = plan(&c);
        assert_eq!(a, plan(&c));
        let f = Field::default();
        for file in &a {
            for act in &file.activations {
                let end =
                    act.ambient_on_c + act.ambient_ramp_c_per_s * f64::from(act.samples) / 1000.0;
                assert!((end - file.set_point_c).abs() <= f.ambient_excursion_c + 1e-9);
                assert!((f.supply_v[0]..=f.supply_v[1]).contains(&act.supply_v));
                let n: f64 = act.gravity_body.iter().map(|g| g * g).sum();
                assert!((n - 1.0).abs() < 1e-12);
            }
        }
        let offs: Vec<u64> = a[0]
            .activations
            .iter()
            .skip(1)
            .map(|x| x.off_before_ms)
            .collect();
        assert!(
            offs.windows(2).any(|w| w[0] != w[1]),
            "field off-times must vary"
        );
    }
}
