//! Target `corrector`: the run-time corrector fed arbitrary f32 streams and switch-on
//! temperatures, with valid tables (the shared vectors' models).
//!
//! Input: one byte picks the model (`% 8 == 7`: the tables with warm starts; `% 4 == 3`: the
//! tables keyed by heating history; `% 16 == 14`: the extended model, whose rate filter starts from
//! what `power_on_after` was given; otherwise `% 3`: modified, standard, third-order, as before
//! those models existed, so the committed corpus keeps most of its models), then a sequence of operations, each a tag byte and its operands: power on
//! (3 raw temperatures), power on after a previous activation (3 raw temperatures, then either the
//! `[Previous; 3]` the target carries — `NOTHING` at first, updated by every `power_on_after` and
//! `keep` — or 3 × (ambient °C, switch-off °C) given by the input), keep (record the switch-off
//! temperatures in the carried `[Previous; 3]`), power off, or correct one sample (time since
//! switch-on, 3 rates, 3 raw temperatures). Tag bit 7 decodes the operands as raw f32 bits
//! (anything: NaN, ±∞, subnormals, ±3.4e38); otherwise as small integers around the calibrated
//! envelope, so the fuzzer also walks the table's own branches rather than only its clamps.
//!
//! Invariants (the firmware path's promise): no panic; `power_on`/`power_on_after` with a
//! non-finite reading is refused and leaves the state (and the kept `Previous`) unchanged; every
//! corrected output is finite unless the sample is flagged `RATE_INVALID` (non-finite rate in) or
//! `NOT_POWERED_ON`; the removed bias is always finite; `TEMPERATURE_INVALID` is set exactly when
//! the temperature input is not finite; `power_on_after` leaves a non-NaN ambient and a cleared
//! (NaN) switch-off temperature in `Previous`, `keep` changes only the switch-off temperatures, and
//! only while powered on (to a non-NaN value); the history flags appear only with the
//! history-keyed tables, `HISTORY_UNKNOWN` exactly when nothing finite was kept for the axis and no
//! full cool-down was (`Previous::COOLED`), or after a plain `power_on`, and every sample of an activation carries its history flags.

use drift_core::{AxisModel, Corrector, Flags, Model, Previous, Sample, AXES};

use crate::models::models;

/// Reads operands from the input.
struct Cursor<'a> {
    data: &'a [u8],
}

impl Cursor<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.data.split_at_checked(N)?;
        self.data = rest;
        head.try_into().ok()
    }

    fn byte(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }

    /// A rate, °/s: raw bits, or a value in ±16 °/s with 2⁻¹¹ resolution.
    fn rate(&mut self, raw_bits: bool) -> Option<f32> {
        if raw_bits {
            self.take::<4>().map(f32::from_le_bytes)
        } else {
            self.take::<2>()
                .map(|b| f32::from(i16::from_le_bytes(b)) / 2048.0)
        }
    }

    /// A raw temperature: raw bits, or 5000…7047 raw (25…35 °C at 200 raw/°C), around the
    /// vectors' calibrated ambients.
    fn temperature(&mut self, raw_bits: bool) -> Option<f32> {
        if raw_bits {
            self.take::<4>().map(f32::from_le_bytes)
        } else {
            self.take::<2>()
                .map(|b| 5000.0 + f32::from(u16::from_le_bytes(b) % 2048))
        }
    }

    /// A temperature in °C kept across power-off: raw bits, or 10…42 °C in 1/64 °C steps (around
    /// and beyond the vectors' 20…40 °C ambients and their ~3 °C of stored residual heat).
    fn kept_celsius(&mut self, raw_bits: bool) -> Option<f32> {
        if raw_bits {
            self.take::<4>().map(f32::from_le_bytes)
        } else {
            self.take::<2>()
                .map(|b| 10.0 + f32::from(u16::from_le_bytes(b) % 2048) / 64.0)
        }
    }

    /// Three raw switch-on temperatures.
    fn switch_on(&mut self, raw_bits: bool) -> Option<[f32; AXES]> {
        let [x, y, z] = [(); AXES].map(|()| self.temperature(raw_bits));
        Some([x?, y?, z?])
    }

    /// What was kept of a previous activation, per axis.
    fn previous(&mut self, raw_bits: bool) -> Option<[Previous; AXES]> {
        let [x, y, z] = [(); AXES].map(|()| {
            Some(Previous {
                ambient_celsius: self.kept_celsius(raw_bits)?,
                switch_off_celsius: self.kept_celsius(raw_bits)?,
            })
        });
        Some([x?, y?, z?])
    }

    fn ms(&mut self, raw_bits: bool) -> Option<u32> {
        if raw_bits {
            self.take::<4>().map(u32::from_le_bytes)
        } else {
            // Up to ~4.5 min in 4-ms steps: before, inside and past the reference times.
            self.take::<2>()
                .map(|b| u32::from(u16::from_le_bytes(b)) * 4)
        }
    }
}

/// The history flags.
const HISTORY: Flags = Flags(Flags::HISTORY_UNKNOWN.0 | Flags::HISTORY_OUT_OF_SPAN.0);

/// Bits of a `[Previous; 3]`, so that NaN compares equal to itself.
fn bits(previous: &[Previous; AXES]) -> [[u32; 2]; AXES] {
    previous.map(|p| [p.ambient_celsius.to_bits(), p.switch_off_celsius.to_bits()])
}

/// What the run carries between operations.
struct Run<'m, M: Model> {
    corrector: Corrector<'m, M>,
    /// What firmware keeps across power-off.
    previous: [Previous; AXES],
    /// The flags of the current activation, as `power_on`/`power_on_after` returned them.
    activation: [Flags; AXES],
    /// Whether the model reads the heating history (stage 3 or the initial bias).
    by_history: bool,
}

impl<M: Model> Run<'_, M>
where
    <M::Axis as AxisModel>::State: PartialEq,
{
    /// `power_on` (`previous` `None`) or `power_on_after` with `previous`.
    fn power_on(&mut self, raw: [f32; AXES], previous: Option<[Previous; AXES]>) {
        let before = *self.corrector.state();
        let kept_before = self.previous;
        let started = match previous {
            Some(given) => {
                self.previous = given;
                self.corrector.power_on_after(raw, &mut self.previous)
            }
            None => self.corrector.power_on(raw),
        };
        let given = previous.unwrap_or(Previous::NOTHING);
        match started {
            Ok(flags) => {
                assert!(raw.iter().all(|r| r.is_finite()), "accepted {raw:?}");
                for (axis, (flags, given)) in flags.iter().zip(given).enumerate() {
                    // A switch-off at −∞ is a clock's "fully cooled" (`Previous::COOLED`): known.
                    let known = given.switch_off_celsius == f32::NEG_INFINITY
                        || (given.ambient_celsius.is_finite()
                            && given.switch_off_celsius.is_finite());
                    if self.by_history {
                        assert_eq!(
                            flags.contains(Flags::HISTORY_UNKNOWN),
                            !known,
                            "axis {axis}: HISTORY_UNKNOWN disagrees with {given:?} ({raw:?})"
                        );
                    } else {
                        assert!(
                            !flags.intersects(HISTORY),
                            "axis {axis}: history flags without a history-keyed table: {flags:?}"
                        );
                    }
                }
                if previous.is_some() {
                    for kept in &self.previous {
                        assert!(
                            !kept.ambient_celsius.is_nan() && kept.switch_off_celsius.is_nan(),
                            "power_on_after kept {kept:?} (from {given:?}, {raw:?})"
                        );
                    }
                }
                self.activation = flags;
            }
            Err(_) => {
                assert!(raw.iter().any(|r| !r.is_finite()), "refused {raw:?}");
                // Compared as text: the state's bracket cache may hold NaN knots (no
                // curve above the top one), and NaN != NaN under `==`.
                assert!(
                    format!("{:?}", self.corrector.state()) == format!("{before:?}"),
                    "a refused power_on changed the state"
                );
                if previous.is_some() {
                    assert!(
                        bits(&self.previous) == bits(&given),
                        "a refused power_on_after changed what was kept"
                    );
                    // As firmware would: what it had kept is still in its retained RAM.
                    self.previous = kept_before;
                }
            }
        }
    }

    fn keep(&mut self) {
        let before = self.previous;
        let powered = self.corrector.state().is_powered_on();
        self.corrector.keep(&mut self.previous);
        for (axis, (kept, before)) in self.previous.iter().zip(&before).enumerate() {
            assert!(
                kept.ambient_celsius.to_bits() == before.ambient_celsius.to_bits(),
                "axis {axis}: keep changed the ambient ({before:?} -> {kept:?})"
            );
            if powered {
                assert!(
                    !kept.switch_off_celsius.is_nan(),
                    "axis {axis}: keep recorded NaN"
                );
            } else {
                assert!(
                    kept.switch_off_celsius.to_bits() == before.switch_off_celsius.to_bits(),
                    "axis {axis}: keep while powered off changed {before:?} -> {kept:?}"
                );
            }
        }
    }
}

fn drive<M: Model>(model: &M, data: &[u8], by_history: bool)
where
    <M::Axis as AxisModel>::State: PartialEq,
{
    let Ok(corrector) = Corrector::new(model) else {
        panic!("the vectors' model does not validate");
    };
    let mut run = Run {
        corrector,
        previous: Previous::NOTHING,
        activation: [Flags::NONE; AXES],
        by_history,
    };
    let mut input = Cursor { data };
    while let Some(tag) = input.byte() {
        let raw_bits = tag & 0x80 != 0;
        match tag & 0x7f {
            0..=4 => {
                let Some(raw) = input.switch_on(raw_bits) else {
                    return;
                };
                run.power_on(raw, None);
            }
            5 => run.keep(),
            6 => {
                // power_on_after with what the run kept.
                let Some(raw) = input.switch_on(raw_bits) else {
                    return;
                };
                run.power_on(raw, Some(run.previous));
            }
            7 => {
                // power_on_after with what the input says was kept (NaN, ±∞ with raw bits).
                let (Some(raw), Some(previous)) =
                    (input.switch_on(raw_bits), input.previous(raw_bits))
                else {
                    return;
                };
                run.power_on(raw, Some(previous));
            }
            8 => run.corrector.power_off(),
            _ => {
                let Some(ms) = input.ms(raw_bits) else { return };
                let mut sample = Sample {
                    since_power_on_ms: ms,
                    ..Sample::default()
                };
                for axis in 0..AXES {
                    let (Some(rate), Some(raw)) =
                        (input.rate(raw_bits), input.temperature(raw_bits))
                    else {
                        return;
                    };
                    sample.rate_dps[axis] = rate;
                    sample.temperature_raw[axis] = raw;
                }
                let powered = run.corrector.state().is_powered_on();
                let out = run.corrector.correct(&sample);
                for axis in 0..AXES {
                    check_axis(&sample, &out, axis, powered);
                    let history = Flags(out.flags[axis].0 & HISTORY.0);
                    if powered {
                        assert_eq!(
                            history,
                            Flags(run.activation[axis].0 & HISTORY.0),
                            "axis {axis}: a sample's history flags differ from its activation's"
                        );
                    } else {
                        assert_eq!(history, Flags::NONE, "axis {axis}: history flags unpowered");
                    }
                }
            }
        }
    }
}

fn check_axis(sample: &Sample, out: &drift_core::Output, axis: usize, powered: bool) {
    let flags = out.flags[axis];
    let (rate, raw) = (sample.rate_dps[axis], sample.temperature_raw[axis]);
    let context = || format!("axis {axis}: {sample:?} -> {out:?}");
    assert!(
        out.bias_dps[axis].is_finite(),
        "non-finite bias: {}",
        context()
    );
    // Finding F3 (docs/reliability.md) is fixed: drift-core refuses a bias beyond
    // MAX_PLAUSIBLE_DRIFT_DPS, so `rate − bias` is finite for every finite rate, up to f32::MAX.
    assert!(
        out.bias_dps[axis].abs() <= 3.0 * drift_core::MAX_PLAUSIBLE_DRIFT_DPS,
        "implausible bias: {}",
        context()
    );
    if !out.corrected_dps[axis].is_finite() {
        assert!(
            flags.intersects(Flags::RATE_INVALID | Flags::NOT_POWERED_ON),
            "non-finite output without a flag that says so: {}",
            context()
        );
    }
    assert_eq!(
        flags.contains(Flags::RATE_INVALID),
        !rate.is_finite(),
        "RATE_INVALID disagrees with the rate: {}",
        context()
    );
    assert_eq!(
        flags.contains(Flags::NOT_POWERED_ON),
        !powered,
        "NOT_POWERED_ON disagrees with the state: {}",
        context()
    );
    if powered {
        assert_eq!(
            flags.contains(Flags::TEMPERATURE_INVALID),
            !raw.is_finite(),
            "TEMPERATURE_INVALID disagrees with the temperature: {}",
            context()
        );
    }
}

/// Runs one input.
pub fn run(data: &[u8]) {
    let Some((&which, ops)) = data.split_first() else {
        return;
    };
    let m = models();
    // Tables that read the heating history (stage 3 or the initial bias) flag what they know of
    // it; the others never do.
    if which % 8 == 7 {
        return drive(&m.warm_started, ops, true);
    }
    if which % 4 == 3 {
        return drive(&m.by_history, ops, true);
    }
    // The extended model reads the history only to start its rate filter: no history flags.
    if which % 16 == 14 {
        return drive(&m.extended, ops, false);
    }
    match which % 3 {
        0 => drive(&m.modified, ops, false),
        1 => drive(&m.standard, ops, false),
        _ => drive(&m.third_order, ops, false),
    }
}
