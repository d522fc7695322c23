//! Block correction: many samples per call, the same outputs bit for bit as one call per sample.
//!
//! A model whose drift depends on the temperature alone (the polynomial baselines) is evaluated for
//! [`BLOCK_SAMPLES`] readings per axis at once. Then, axis by axis, what `correct_axis` does around
//! the model runs as loops over the block, with the same operations in the same order: the checks
//! (the per-sample path's own [`read_axis`] when a reading is not finite, else the stuck counter
//! worked out run by run), the model's flags, the hold of the last good drift (run by run), the
//! output. Everything else is a loop the compiler vectorises. Every other model, an extended model
//! and a state that is not powered on go sample by sample.

use super::{rate_flag, read_axis, AxisState, CorrectorState, Output, Sample};
use crate::error::saturating_u16;
use crate::flags::Flags;
use crate::model::{AxisModel, Model, BLOCK_SAMPLES};
use crate::settings::Settings;
use crate::AXES;

/// One axis of a block, per sample: the inputs, the model's answers, the results. Reused from
/// block to block (no clearing per block); entries past a short last block hold whatever was
/// there and are evaluated but never read.
#[derive(Clone, Copy)]
struct Lane {
    rate: [f32; BLOCK_SAMPLES],
    raw: [f32; BLOCK_SAMPLES],
    celsius: [f32; BLOCK_SAMPLES],
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
    celsius: [0.0; BLOCK_SAMPLES],
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
    /// ~9 KiB of stack).
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
        // Every axis answers before any state changes.
        for ((lane, axis), state) in [&mut *x, &mut *y, &mut *z]
            .into_iter()
            .zip(model.axes())
            .zip(&self.axes)
        {
            for (celsius, &raw) in lane.celsius.iter_mut().zip(&lane.raw) {
                *celsius = settings.celsius_with(raw, celsius_per_raw);
            }
            let answered = axis.drift_of_temperatures(
                settings,
                &state.model,
                &lane.celsius,
                &mut lane.drift,
                &mut lane.model_flags,
            );
            if !answered {
                return false;
            }
        }
        let count = samples.len();
        for (state, lane) in self.axes.iter_mut().zip([&mut *x, &mut *y, &mut *z]) {
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
