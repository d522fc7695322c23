//! Block correction: many samples per call, the same outputs bit for bit as one call per sample.
//!
//! A model whose drift depends on the temperature alone (the polynomial baselines) hands the
//! corrector its drift as a function of the temperature ([`AxisModel::drift_of_temperatures`]),
//! which runs inside loops over [`BLOCK_SAMPLES`] readings per axis. In the common case — every
//! reading of the block finite, no reading that can reach the stuck threshold, every drift plausible —
//! one fused loop per axis does what `correct_axis` does per sample (conversion, model, flags,
//! bias, output), which the compiler vectorises. Otherwise that axis goes through the general
//! block path: the model's answers for the block, then, with the same operations in the same order
//! as the per-sample path, the checks (the per-sample path's own [`read_axis`] when a reading is
//! not finite, else the stuck counter worked out run by run), the model's flags, the hold of the
//! last good drift (run by run), the output. Every other model, an extended model and a state that
//! is not powered on go sample by sample.

use super::{rate_flag, read_axis, AxisState, CorrectorState, Output, Sample};
use crate::error::saturating_u16;
use crate::flags::Flags;
use crate::model::{AxisModel, Model, TemperatureBlock, BLOCK_SAMPLES};
use crate::settings::Settings;
use crate::AXES;

/// One axis of a block, per sample: the inputs, the model's answers, the results. Reused from
/// block to block (no clearing per block); entries past a short last block hold whatever was
/// there and are evaluated but never read.
#[derive(Clone, Copy)]
struct Lane {
    rate: [f32; BLOCK_SAMPLES],
    raw: [f32; BLOCK_SAMPLES],
    drift: [f32; BLOCK_SAMPLES],
    model_flags: [Flags; BLOCK_SAMPLES],
    /// The checks' flags, then the output's.
    flags: [Flags; BLOCK_SAMPLES],
    /// Valid and not stuck: the model's answer counts.
    healthy: [bool; BLOCK_SAMPLES],
    /// The model's answer is held: healthy and finite.
    take: [bool; BLOCK_SAMPLES],
    /// The bias if the answer is held.
    candidate: [f32; BLOCK_SAMPLES],
    bias: [f32; BLOCK_SAMPLES],
    corrected: [f32; BLOCK_SAMPLES],
}

const EMPTY_LANE: Lane = Lane {
    rate: [0.0; BLOCK_SAMPLES],
    raw: [0.0; BLOCK_SAMPLES],
    drift: [0.0; BLOCK_SAMPLES],
    model_flags: [Flags::NONE; BLOCK_SAMPLES],
    flags: [Flags::NONE; BLOCK_SAMPLES],
    healthy: [false; BLOCK_SAMPLES],
    take: [false; BLOCK_SAMPLES],
    candidate: [0.0; BLOCK_SAMPLES],
    bias: [0.0; BLOCK_SAMPLES],
    corrected: [0.0; BLOCK_SAMPLES],
};

impl<S: Copy + Default> CorrectorState<S> {
    /// Corrects `samples` in order into `outputs` without auxiliary inputs and returns how many
    /// (the shorter of the two lengths): the same outputs and the same final state, bit for bit, as
    /// [`Self::correct`] sample by sample, faster for the polynomial baselines (which then use
    /// ~12 KiB of stack).
    pub fn correct_block<M>(
        &mut self,
        model: &M,
        samples: &[Sample],
        outputs: &mut [Output],
    ) -> usize
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        let count = samples.len().min(outputs.len());
        // A model without the block form (the paper's), an extended model or a state that is not
        // powered on: sample by sample, without lanes to zero or fill.
        let settings = model.settings();
        let answers = self.is_powered_on()
            && model.extension().is_empty()
            && (model.axes().iter().zip(&self.axes)).all(|(axis, state)| {
                axis.drift_of_temperatures(settings, &state.model, Probe)
                    .is_some()
            });
        if !answers {
            for (sample, output) in samples.iter().zip(outputs.iter_mut()) {
                *output = self.correct(model, sample);
            }
            return count;
        }
        let mut lanes = [EMPTY_LANE; AXES];
        let pairs = samples
            .chunks(BLOCK_SAMPLES)
            .zip(outputs.chunks_mut(BLOCK_SAMPLES));
        for (samples, outputs) in pairs {
            let answered = self.is_powered_on()
                && model.extension().is_empty()
                && self.correct_answered(model, samples, outputs, &mut lanes);
            if !answered {
                for (sample, output) in samples.iter().zip(outputs.iter_mut()) {
                    *output = self.correct(model, sample);
                }
            }
        }
        count
    }

    /// One block through the model's [`AxisModel::drift_of_temperatures`]; `false` (and nothing
    /// changed) if the model has no such form.
    fn correct_answered<M>(
        &mut self,
        model: &M,
        samples: &[Sample],
        outputs: &mut [Output],
        lanes: &mut [Lane; AXES],
    ) -> bool
    where
        M: Model,
        M::Axis: AxisModel<State = S>,
    {
        let settings = model.settings();
        let celsius_per_raw = settings.celsius_per_raw();
        let [x, y, z] = lanes;
        // Zipped iterators rather than indices: no bounds check per value.
        let rates = x
            .rate
            .iter_mut()
            .zip(y.rate.iter_mut())
            .zip(z.rate.iter_mut());
        let raws = x.raw.iter_mut().zip(y.raw.iter_mut()).zip(z.raw.iter_mut());
        for (sample, (((rate_x, rate_y), rate_z), ((raw_x, raw_y), raw_z))) in
            samples.iter().zip(rates.zip(raws))
        {
            [*rate_x, *rate_y, *rate_z] = sample.rate_dps;
            [*raw_x, *raw_y, *raw_z] = sample.temperature_raw;
        }
        let count = samples.len();
        // Every axis answers before any state changes: the model's loops write the lanes only.
        let mut fused = [None; AXES];
        for (((lane, axis), state), fused) in [&mut *x, &mut *y, &mut *z]
            .into_iter()
            .zip(model.axes())
            .zip(&self.axes)
            .zip(&mut fused)
        {
            let block = Fused {
                lane: &mut *lane,
                count,
                settings,
                celsius_per_raw,
                state: Carried {
                    repeats: state.repeats,
                    last_raw: state.last_raw,
                    bias_dps: state.bias_dps,
                },
                initial_bias_dps: state.initial_bias_dps,
                activation_flags: state.activation_flags,
            };
            match axis.drift_of_temperatures(settings, &state.model, block) {
                Some(answered) => *fused = answered,
                None => return false,
            }
            if fused.is_none() {
                let block = Answers {
                    lane: &mut *lane,
                    settings,
                    celsius_per_raw,
                };
                if axis
                    .drift_of_temperatures(settings, &state.model, block)
                    .is_none()
                {
                    return false;
                }
            }
        }
        for ((state, lane), fused) in self
            .axes
            .iter_mut()
            .zip([&mut *x, &mut *y, &mut *z])
            .zip(fused)
        {
            if let Some(carried) = fused {
                state.repeats = carried.repeats;
                state.last_raw = carried.last_raw;
                state.bias_dps = carried.bias_dps;
                continue;
            }
            let readings = lane.raw.get(..count).unwrap_or_default();
            if readings.iter().fold(true, |all, raw| all & raw.is_finite()) {
                check_finite(settings, state, lane, count);
            } else {
                check_any(settings, celsius_per_raw, state, lane, count);
            }
            finish(state, lane, count);
        }
        // Sample by sample, so each output is written whole.
        let corrected = x.corrected.iter().zip(&y.corrected).zip(&z.corrected);
        let bias = x.bias.iter().zip(&y.bias).zip(&z.bias);
        let flags = x.flags.iter().zip(&y.flags).zip(&z.flags);
        for (output, (((&cx, &cy), &cz), (((&bx, &by), &bz), ((&fx, &fy), &fz)))) in
            outputs.iter_mut().zip(corrected.zip(bias.zip(flags)))
        {
            *output = Output {
                corrected_dps: [cx, cy, cz],
                bias_dps: [bx, by, bz],
                flags: [fx, fy, fz],
            };
        }
        true
    }
}

/// Asks a model whether it has the block form, doing nothing with it.
struct Probe;

impl TemperatureBlock for Probe {
    type Output = ();

    #[inline(always)]
    fn run(self, _drift: impl Fn(f32) -> (f32, Flags)) {}
}

/// What an axis's state carries from sample to sample through a block (besides the model's
/// state, which the block path's models do not change).
#[derive(Clone, Copy)]
struct Carried {
    repeats: u16,
    last_raw: f32,
    bias_dps: f32,
}

/// The fused path of one axis's block, for the common case: every reading finite and every drift
/// plausible. The readings are split into runs of repeats of one value (the stuck counter within a
/// run is known from where it starts); the healthy part of each run goes through one loop that
/// does what `correct_axis` does for a healthy reading with a finite drift — the conversion, the
/// model, the flags, the held bias (the model's answer), the output — and which the compiler
/// vectorises; its stuck part holds the last bias. Answers the state after the block, or `None`
/// if the case is not the common one: then the lane's outputs are not used and the axis goes
/// through the general path.
struct Fused<'a> {
    lane: &'a mut Lane,
    count: usize,
    settings: &'a Settings,
    celsius_per_raw: f32,
    state: Carried,
    initial_bias_dps: f32,
    activation_flags: Flags,
}

impl TemperatureBlock for Fused<'_> {
    type Output = Option<Carried>;

    #[inline(always)]
    fn run(self, drift: impl Fn(f32) -> (f32, Flags)) -> Option<Carried> {
        let Self {
            lane,
            count,
            settings,
            celsius_per_raw,
            state,
            initial_bias_dps,
            activation_flags,
        } = self;
        let Lane {
            rate,
            raw,
            flags,
            bias,
            corrected,
            ..
        } = lane;
        let constants = Constants {
            settings,
            celsius_per_raw,
            initial_bias_dps,
            activation_flags,
        };
        fused_block(
            Inputs { rate, raw, count },
            flags,
            bias,
            corrected,
            drift,
            constants,
            state,
        )
    }
}

/// A lane's inputs.
struct Inputs<'a> {
    rate: &'a [f32; BLOCK_SAMPLES],
    raw: &'a [f32; BLOCK_SAMPLES],
    count: usize,
}

/// [`Fused`]'s work. Out of line with the outputs as separate arguments, so that the compiler
/// knows they do not overlap (no run-time overlap checks before each loop).
#[inline(never)]
fn fused_block(
    inputs: Inputs<'_>,
    flags: &mut [Flags; BLOCK_SAMPLES],
    bias: &mut [f32; BLOCK_SAMPLES],
    corrected: &mut [f32; BLOCK_SAMPLES],
    drift: impl Fn(f32) -> (f32, Flags),
    constants: Constants<'_>,
    state: Carried,
) -> Option<Carried> {
    let Inputs { rate, raw, count } = inputs;
    let Constants {
        settings,
        activation_flags,
        ..
    } = constants;
    let readings = raw.get(..count)?;
    let finite = |readings: &[f32]| readings.iter().fold(true, |all, raw| all & raw.is_finite());
    // A whole block (the usual case) as a fixed-size array: no loop tail.
    let all_finite = match <&[f32; BLOCK_SAMPLES]>::try_from(readings) {
        Ok(whole) => finite(whole),
        Err(_) => finite(readings),
    };
    if !all_finite {
        return None;
    }
    let after = usize::from(settings.stuck_after_samples);
    if after == 0 || usize::from(state.repeats).saturating_add(count) < after {
        return unstuck_block(
            Inputs { rate, raw, count },
            flags,
            bias,
            corrected,
            &drift,
            constants,
            state,
        );
    }
    let changes = changes(state.last_raw, raw, count);
    let Carried {
        mut repeats,
        mut last_raw,
        mut bias_dps,
    } = state;
    let mut start = 0;
    while let Some(&first) = readings.get(start) {
        // The run ends at the next change (or at the block's end).
        let later = changes
            .checked_shr(u32::try_from(start.saturating_add(1)).unwrap_or(u32::MAX))
            .unwrap_or(0);
        let len = usize::try_from(later.trailing_zeros())
            .map_or(count, |zeros| zeros.saturating_add(1))
            .min(count.saturating_sub(start));
        let end = start.saturating_add(len);
        // The stuck counter at the run's first reading (as `read_axis`: one more repeat of
        // the last reading, or a new reading), then one more per reading of the run.
        let counter = if first.to_bits() == last_raw.to_bits() {
            repeats.saturating_add(1)
        } else {
            0
        };
        let healthy = if after == 0 {
            len
        } else {
            after.saturating_sub(usize::from(counter)).min(len)
        };
        let split = start.saturating_add(healthy);
        // Each loop runs over whole vectors: past its range it computes readings that a later
        // loop of this block overwrites (its own run's stuck part, the next run) or that lie
        // past `count` (never read). Only the range's own bias is kept.
        if healthy > 0 {
            let whole = whole_vectors(start, split, 4);
            let all = fused_run(
                rate.get(whole.clone())?,
                raw.get(whole.clone())?,
                flags.get_mut(whole.clone())?,
                bias.get_mut(whole.clone())?,
                corrected.get_mut(whole)?,
                &drift,
                constants,
            );
            if !all {
                return None;
            }
            bias_dps = *bias.get(split.checked_sub(1)?)?;
        }
        if split < end {
            let whole = whole_vectors(split, end, 8);
            held_run(
                rate.get(whole.clone())?,
                flags.get_mut(whole.clone())?,
                bias.get_mut(whole.clone())?,
                corrected.get_mut(whole)?,
                bias_dps,
                activation_flags,
            );
        }
        repeats = counter.saturating_add(saturating_u16(len.saturating_sub(1)));
        last_raw = first;
        start = end;
    }
    Some(Carried {
        repeats,
        last_raw,
        bias_dps,
    })
}

/// [`fused_block`] when no reading of the block can reach the stuck threshold (the usual case with
/// the default threshold): every reading healthy, one fused loop over the block.
#[inline(always)]
fn unstuck_block(
    inputs: Inputs<'_>,
    flags: &mut [Flags; BLOCK_SAMPLES],
    bias: &mut [f32; BLOCK_SAMPLES],
    corrected: &mut [f32; BLOCK_SAMPLES],
    drift: &impl Fn(f32) -> (f32, Flags),
    constants: Constants<'_>,
    state: Carried,
) -> Option<Carried> {
    let Inputs { rate, raw, count } = inputs;
    let readings = raw.get(..count)?;
    let whole = whole_vectors(0, count, 4);
    let all = fused_run(
        rate.get(whole.clone())?,
        raw.get(whole.clone())?,
        flags.get_mut(whole.clone())?,
        bias.get_mut(whole.clone())?,
        corrected.get_mut(whole)?,
        drift,
        constants,
    );
    if !all {
        return None;
    }
    // The stuck counter as `read_axis` leaves it: the repeats since the last change.
    let repeats = match last_change(state.last_raw, readings) {
        Some(change) => saturating_u16(count.saturating_sub(change).saturating_sub(1)),
        None => state.repeats.saturating_add(saturating_u16(count)),
    };
    Some(Carried {
        repeats,
        last_raw: *readings.last()?,
        bias_dps: *bias.get(count.checked_sub(1)?)?,
    })
}

/// The index of the last reading that differs (in its bits) from the one before it, `previous`
/// before the first; `None` if every reading repeats `previous`. Eight pairs at a time from the
/// end, each eight one vector comparison.
#[inline(always)]
fn last_change(previous: f32, readings: &[f32]) -> Option<usize> {
    let differs = |a: &f32, b: &f32| a.to_bits() != b.to_bits();
    let mut end = readings.len();
    while end > 8 {
        let start = end.saturating_sub(8);
        let now = readings
            .get(start..end)
            .and_then(|r| <&[f32; 8]>::try_from(r).ok());
        let before = readings
            .get(start.saturating_sub(1)..end.saturating_sub(1))
            .and_then(|r| <&[f32; 8]>::try_from(r).ok());
        let (Some(now), Some(before)) = (now, before) else {
            break;
        };
        let any = now
            .iter()
            .zip(before)
            .fold(0_u32, |any, (a, b)| any | (a.to_bits() ^ b.to_bits()));
        if any != 0 {
            let at = now.iter().zip(before).rposition(|(a, b)| differs(a, b));
            return at.map(|at| start.saturating_add(at));
        }
        end = start;
    }
    // The first readings, the first of them against `previous`.
    let head = readings.get(..end).unwrap_or_default();
    let mut pairs = head.windows(2);
    match pairs.rposition(|pair| matches!(pair, [before, now] if differs(now, before))) {
        Some(at) => Some(at.saturating_add(1)),
        None => head
            .first()
            .filter(|first| differs(first, &previous))
            .map(|_| 0),
    }
}

/// What the fused loop needs besides the readings.
#[derive(Clone, Copy)]
struct Constants<'a> {
    settings: &'a Settings,
    celsius_per_raw: f32,
    initial_bias_dps: f32,
    activation_flags: Flags,
}

/// Healthy readings through the model and into the outputs (one slice each, so the compiler knows
/// they do not overlap); whether every drift was plausible (if not, the general path holds and
/// flags it).
#[inline(always)]
fn fused_run(
    rate: &[f32],
    raw: &[f32],
    flags: &mut [Flags],
    bias: &mut [f32],
    corrected: &mut [f32],
    drift: &impl Fn(f32) -> (f32, Flags),
    constants: Constants<'_>,
) -> bool {
    let Constants {
        settings,
        celsius_per_raw,
        initial_bias_dps,
        activation_flags,
    } = constants;
    // Branch-free, so the loop vectorises; `all` says afterwards whether every drift was
    // plausible (finite and within MAX_PLAUSIBLE_DRIFT_DPS).
    let mut all = true;
    let outputs = flags
        .iter_mut()
        .zip(bias.iter_mut())
        .zip(corrected.iter_mut());
    for ((&rate, &raw), ((flags, bias), corrected)) in rate.iter().zip(raw).zip(outputs) {
        let (drift, model_flags) = drift(settings.celsius_with(raw, celsius_per_raw));
        all &= super::plausible(drift);
        // As `read_axis`, `hold_drift` and `axis_output` for a healthy reading and a finite
        // drift: the checks' flags and the model's, the held bias, the output.
        *flags = activation_flags | rate_flag(rate) | model_flags;
        *bias = initial_bias_dps + drift;
        *corrected = rate - *bias;
    }
    all
}

/// Stuck readings: flagged, the last bias held.
#[inline(always)]
fn held_run(
    rate: &[f32],
    flags: &mut [Flags],
    bias: &mut [f32],
    corrected: &mut [f32],
    held: f32,
    activation_flags: Flags,
) {
    let outputs = flags
        .iter_mut()
        .zip(bias.iter_mut())
        .zip(corrected.iter_mut());
    for (&rate, ((flags, bias), corrected)) in rate.iter().zip(outputs) {
        *flags = activation_flags | rate_flag(rate) | Flags::TEMPERATURE_STUCK;
        *bias = held;
        *corrected = rate - held;
    }
}

/// `start..end` extended to a whole number of `width`-sample vectors, within the block.
#[inline(always)]
fn whole_vectors(start: usize, end: usize, width: usize) -> core::ops::Range<usize> {
    let len = end.saturating_sub(start).next_multiple_of(width);
    start..start.saturating_add(len).min(BLOCK_SAMPLES).max(end)
}

/// Bit `i` set where reading `i` (of the first `count`) differs in its bits from the one before
/// it, `previous` before the first: where the runs of repeats start. The comparisons as one
/// vectorised loop over the block, then eight bytes at a time into bits.
#[inline(always)]
fn changes(previous: f32, raw: &[f32; BLOCK_SAMPLES], count: usize) -> u128 {
    const _: () = assert!(BLOCK_SAMPLES == 128, "one bit per reading in a u128");
    let mut differs = [0_u8; BLOCK_SAMPLES];
    if let (Some((first, rest)), Some((&now, later))) =
        (differs.split_first_mut(), raw.split_first())
    {
        *first = u8::from(now.to_bits() != previous.to_bits());
        for ((differs, now), before) in rest.iter_mut().zip(later).zip(raw) {
            *differs = u8::from(now.to_bits() != before.to_bits());
        }
    }
    let mut changes = 0_u128;
    for (shift, eight) in (0_u32..).step_by(8).zip(differs.chunks_exact(8)) {
        let bytes = <[u8; 8]>::try_from(eight).map_or(0, u64::from_le_bytes);
        // Bytes of 0 or 1 → one bit each: the product gathers byte k's bit into bit 56 + k.
        changes |= u128::from(bytes.wrapping_mul(0x0102_0408_1020_4080) >> 56) << shift;
    }
    let kept = u32::try_from(count)
        .ok()
        .and_then(|count| 1_u128.checked_shl(count))
        .map_or(u128::MAX, |bit| bit.wrapping_sub(1));
    changes & kept
}

/// The model's answers for every reading of one axis's block (the general path's input).
struct Answers<'a> {
    lane: &'a mut Lane,
    settings: &'a Settings,
    celsius_per_raw: f32,
}

impl TemperatureBlock for Answers<'_> {
    type Output = ();

    #[inline(always)]
    fn run(self, drift: impl Fn(f32) -> (f32, Flags)) {
        let Self {
            lane,
            settings,
            celsius_per_raw,
        } = self;
        let answers = lane.drift.iter_mut().zip(lane.model_flags.iter_mut());
        for ((drift_dps, flags), &raw) in answers.zip(&lane.raw) {
            (*drift_dps, *flags) = drift(settings.celsius_with(raw, celsius_per_raw));
        }
    }
}

/// The checks before the model for `count` readings of which any may be invalid: the per-sample
/// path's own [`read_axis`], one sample at a time.
fn check_any<S>(
    settings: &Settings,
    celsius_per_raw: f32,
    state: &mut AxisState<S>,
    lane: &mut Lane,
    count: usize,
) {
    let inputs = lane.rate.iter().zip(&lane.raw).take(count);
    let checked = lane.flags.iter_mut().zip(lane.healthy.iter_mut());
    for ((&rate, &raw), (flags, healthy)) in inputs.zip(checked) {
        let reading = read_axis(settings, celsius_per_raw, state, rate, raw);
        *flags = reading.flags;
        *healthy = reading.healthy;
    }
}

/// [`check_any`] when all `count` readings are finite: then a reading either repeats the last
/// one exactly (the stuck counter goes up) or replaces it (the counter restarts), and the counter
/// is stuck from `stuck_after_samples` repeats on. Worked out run by run of repeats rather than
/// sample by sample; the flags are a loop over the block.
#[inline(always)]
fn check_finite<S>(settings: &Settings, state: &mut AxisState<S>, lane: &mut Lane, count: usize) {
    let after = usize::from(settings.stuck_after_samples);
    let mut same = [false; BLOCK_SAMPLES];
    let mut previous = state.last_raw.to_bits();
    for (same, &raw) in same.iter_mut().zip(&lane.raw).take(count) {
        *same = raw.to_bits() == previous;
        previous = raw.to_bits();
    }
    let same = same.get(..count).unwrap_or_default();
    let healthy = lane.healthy.get_mut(..count).unwrap_or_default();
    let mut repeats = state.repeats;
    if after == 0 || usize::from(repeats).saturating_add(count) < after {
        // No reading of this block can reach the threshold.
        healthy.fill(true);
        repeats = match same.iter().rposition(|&same| !same) {
            Some(change) => saturating_u16(count.saturating_sub(change).saturating_sub(1)),
            None => repeats.saturating_add(saturating_u16(count)),
        };
    } else {
        let mut start = 0;
        while let Some(run) = same.get(start..).filter(|run| !run.is_empty()) {
            let repeating = run.first().copied().unwrap_or(false);
            let len = run_length(run);
            let end = start.saturating_add(len);
            let run_healthy = healthy.get_mut(start..end).unwrap_or_default();
            if repeating {
                // The counter reaches `repeats + 1`, `repeats + 2`, ... over the run: stuck from
                // the sample where it reaches `after` on.
                let healthy_len = after.saturating_sub(usize::from(repeats).saturating_add(1));
                let split = run_healthy.split_at_mut_checked(healthy_len.min(len));
                if let Some((fine, stuck)) = split {
                    fine.fill(true);
                    stuck.fill(false);
                }
                repeats = repeats.saturating_add(saturating_u16(len));
            } else {
                run_healthy.fill(true);
                repeats = 0;
            }
            start = end;
        }
    }
    if let Some(&last) = lane.raw.get(..count).and_then(<[f32]>::last) {
        state.last_raw = last;
    }
    state.repeats = repeats;
    for ((flags, &healthy), &rate) in lane.flags.iter_mut().zip(&lane.healthy).zip(&lane.rate) {
        *flags = state.activation_flags | rate_flag(rate);
        if !healthy {
            *flags |= Flags::TEMPERATURE_STUCK;
        }
    }
}

/// After the checks, `count` samples of an axis: the model's answer where the reading is healthy
/// (as `hold_drift`), the hold of the last good drift, the outputs (as `axis_output`).
#[inline(always)]
fn finish<S>(state: &mut AxisState<S>, lane: &mut Lane, count: usize) {
    let answers = lane.drift.iter().zip(&lane.model_flags);
    let held = lane.take.iter_mut().zip(&mut lane.candidate);
    for ((flags, &healthy), ((take, candidate), (&drift, &model_flags))) in lane
        .flags
        .iter_mut()
        .zip(&lane.healthy)
        .zip(held.zip(answers))
    {
        // Branch-free, so the loop vectorises: a healthy reading takes the model's flags and,
        // for an implausible (or non-finite) drift, MODEL_INVALID.
        let finite = super::plausible(drift);
        let answered = if finite {
            model_flags
        } else {
            model_flags | Flags::MODEL_INVALID
        };
        flags.0 |= if healthy { answered.0 } else { 0 };
        *take = healthy & finite;
        *candidate = state.initial_bias_dps + drift;
    }
    // Run by run of held and not-held answers: a held run copies its candidates, a run that
    // is not held repeats the last held bias.
    let mut held = state.bias_dps;
    let take = lane.take.get(..count).unwrap_or_default();
    let mut start = 0;
    while let Some(run) = take.get(start..).filter(|run| !run.is_empty()) {
        let taking = run.first().copied().unwrap_or(false);
        let len = run_length(run);
        let end = start.saturating_add(len);
        let bias = lane.bias.get_mut(start..end).unwrap_or_default();
        match lane.candidate.get(start..end) {
            Some(candidates) if taking => {
                for (bias, &candidate) in bias.iter_mut().zip(candidates) {
                    *bias = candidate;
                }
                held = candidates.last().copied().unwrap_or(held);
            }
            _ => bias.fill(held),
        }
        start = end;
    }
    state.bias_dps = held;
    for (corrected, (&rate, &bias)) in lane
        .corrected
        .iter_mut()
        .zip(lane.rate.iter().zip(&lane.bias))
    {
        *corrected = rate - bias;
    }
}

/// How many values at the start of `values` equal the first. Eight at a time: the runs are long
/// (a repeated reading, held answers) and one value at a time was a sixth of the block path.
#[inline(always)]
fn run_length(values: &[bool]) -> usize {
    let Some(&first) = values.first() else {
        return 0;
    };
    let mut len = 0_usize;
    for word in values.chunks_exact(8) {
        if <[bool; 8]>::try_from(word).ok() != Some([first; 8]) {
            break;
        }
        len = len.saturating_add(8);
    }
    let rest = values.get(len..).unwrap_or_default();
    let tail = rest.iter().position(|&value| value != first);
    len.saturating_add(tail.unwrap_or(rest.len()))
}

#[cfg(test)]
mod tests {
    use super::run_length;

    #[test]
    fn run_length_counts_the_leading_equal_values() {
        assert_eq!(run_length(&[]), 0);
        for len in 1..40 {
            for first in [false, true] {
                for tail in 0..10 {
                    let mut values = std::vec![first; len];
                    values.extend(core::iter::repeat_n(!first, tail));
                    assert_eq!(run_length(&values), len, "{len} {first} {tail}");
                }
            }
        }
    }
}
