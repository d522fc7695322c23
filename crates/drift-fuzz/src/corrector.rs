//! Target `corrector`: the run-time corrector fed arbitrary f32 streams and switch-on
//! temperatures, with valid tables (the shared vectors' models).
//!
//! Input: one byte picks the model, then a sequence of operations, each a tag byte and its
//! operands: power on (3 raw temperatures), power off, or correct one sample (time since switch-on,
//! 3 rates, 3 raw temperatures). Tag bit 7 decodes the operands as raw f32 bits (anything: NaN,
//! ±∞, subnormals, ±3.4e38); otherwise as small integers around the calibrated envelope, so the
//! fuzzer also walks the table's own branches rather than only its clamps.
//!
//! Invariants (the firmware path's promise): no panic; `power_on` with a non-finite reading is
//! refused and leaves the state unchanged; every corrected output is finite unless the sample is
//! flagged `RATE_INVALID` (non-finite rate in) or `NOT_POWERED_ON`; the removed bias is always
//! finite; and `TEMPERATURE_INVALID` is set exactly when the temperature input is not finite.

use drift_core::{AxisModel, Corrector, Flags, Model, Sample, AXES};

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

fn drive<M: Model>(model: &M, data: &[u8])
where
    <M::Axis as AxisModel>::State: PartialEq,
{
    let Ok(mut corrector) = Corrector::new(model) else {
        panic!("the vectors' model does not validate");
    };
    let mut input = Cursor { data };
    while let Some(tag) = input.byte() {
        let raw_bits = tag & 0x80 != 0;
        match tag & 0x7f {
            0..=7 => {
                let Some(raw) = [(); AXES]
                    .map(|()| input.temperature(raw_bits))
                    .into_iter()
                    .collect::<Option<Vec<f32>>>()
                else {
                    return;
                };
                let raw = [raw[0], raw[1], raw[2]];
                let before = *corrector.state();
                match corrector.power_on(raw) {
                    Ok(_) => assert!(raw.iter().all(|r| r.is_finite()), "accepted {raw:?}"),
                    Err(_) => {
                        assert!(raw.iter().any(|r| !r.is_finite()), "refused {raw:?}");
                        // Compared as text: the state's bracket cache may hold NaN knots (no
                        // curve above the top one), and NaN != NaN under `==`.
                        assert!(
                            format!("{:?}", corrector.state()) == format!("{before:?}"),
                            "a refused power_on changed the state"
                        );
                    }
                }
            }
            8 => corrector.power_off(),
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
                let powered = corrector.state().is_powered_on();
                let out = corrector.correct(&sample);
                for axis in 0..AXES {
                    check_axis(&sample, &out, axis, powered);
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
    match which % 3 {
        0 => drive(&m.modified, ops),
        1 => drive(&m.standard, ops),
        _ => drive(&m.third_order, ops),
    }
}
