//! Block correction: many samples per call, the same outputs bit for bit as one call per sample.
//!
//! A model whose drift depends on the temperature alone (the polynomial baselines) is evaluated for
//! [`BLOCK_SAMPLES`] readings per axis at once. Then, axis by axis, what `correct_axis` does around
//! the model runs as loops over the block, with the same operations in the same order: the checks
//! (the per-sample path's own [`read_axis`] when a reading is not finite, else a scan of the stuck
//! counter alone), the model's flags, the hold of the last good drift, the output. Only the stuck
//! counter and the hold are carried from sample to sample; everything else is a loop the compiler
//! vectorises. Every other model, an extended model and a state that is not powered on go sample by
//! sample.

use super::{rate_flag, read_axis, AxisState, CorrectorState, Output, Sample};
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
        for (i, sample) in samples.iter().enumerate() {
            let [rate_x, rate_y, rate_z] = sample.rate_dps;
            let [raw_x, raw_y, raw_z] = sample.temperature_raw;
            for (lane, rate, raw) in [
                (&mut *x, rate_x, raw_x),
                (&mut *y, rate_y, raw_y),
                (&mut *z, rate_z, raw_z),
            ] {
                if let (Some(lane_rate), Some(lane_raw)) =
                    (lane.rate.get_mut(i), lane.raw.get_mut(i))
                {
                    *lane_rate = rate;
                    *lane_raw = raw;
                }
            }
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
        for (i, output) in outputs.iter_mut().enumerate() {
            let at = |values: &[f32; BLOCK_SAMPLES]| values.get(i).copied().unwrap_or(f32::NAN);
            let flags = |lane: &Lane| lane.flags.get(i).copied().unwrap_or(Flags::NONE);
            *output = Output {
                corrected_dps: [at(&x.corrected), at(&y.corrected), at(&z.corrected)],
                bias_dps: [at(&x.bias), at(&y.bias), at(&z.bias)],
                flags: [flags(x), flags(y), flags(z)],
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

/// [`check_any`] when all `count` readings are finite: then only the stuck counter goes from
/// sample to sample (a reading repeats the last one exactly, or replaces it), and the flags are a
/// loop over the block.
#[inline(always)]
fn check_finite<S>(settings: &Settings, state: &mut AxisState<S>, lane: &mut Lane, count: usize) {
    let after = settings.stuck_after_samples;
    let mut last = state.last_raw.to_bits();
    let mut repeats = state.repeats;
    let readings = lane.raw.get(..count).unwrap_or_default();
    let healthy = lane.healthy.get_mut(..count).unwrap_or_default();
    // Branches rather than selects: readings repeat in runs, which the branch predictor follows
    // (measured faster than a branch-free counter).
    for (&raw, healthy) in readings.iter().zip(healthy) {
        let same = raw.to_bits() == last;
        repeats = if same { repeats.saturating_add(1) } else { 0 };
        last = raw.to_bits();
        *healthy = !(same && after != 0 && repeats >= after);
    }
    state.last_raw = f32::from_bits(last);
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
        // for a non-finite drift, MODEL_INVALID.
        let finite = drift.is_finite();
        let answered = if finite {
            model_flags
        } else {
            model_flags | Flags::MODEL_INVALID
        };
        flags.0 |= if healthy { answered.0 } else { 0 };
        *take = healthy & finite;
        *candidate = state.initial_bias_dps + drift;
    }
    let mut held = state.bias_dps;
    let chosen = lane.take.iter().zip(&lane.candidate).take(count);
    for (bias, (&take, &candidate)) in lane.bias.iter_mut().zip(chosen) {
        if take {
            held = candidate;
        }
        *bias = held;
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
