//! What [`crate::write_recording`] can store, checked before the file is created: every auxiliary
//! channel of every segment is either one of the format's own (in its fixed unit) or a valid named
//! channel with one unit across the recording; all are at the format's auxiliary rate, finite, and
//! no longer than their activation. The reader refuses or relabels anything else, so a file written
//! without these checks could be unreadable, or silently relabel or drop samples; and whatever the
//! reader accepts passes them, so a recording read can always be written back.

use crate::aux::{check_named_aux_channel, fixed_aux_unit, named_aux_topic};
use crate::layout::{aux_samples_covered, AUX_RATE_HZ};
use crate::read::Recording;
use crate::segment::{AuxChannel, Segment};
use std::collections::BTreeMap;

/// A named channel of the recording: one topic per file, so one unit.
pub(crate) struct NamedTopic {
    pub name: String,
    pub topic: String,
    pub unit: String,
}

/// The named channels to register (sorted by name), or what is wrong, naming segment and channel.
pub(crate) fn check_writable(recording: &Recording) -> Result<Vec<NamedTopic>, String> {
    // Name → (unit, the first segment that has it), to name both segments when units disagree.
    let mut named: BTreeMap<&str, (&str, usize)> = BTreeMap::new();
    for (k, segment) in recording.segments.iter().enumerate() {
        let at = || where_in(k, segment);
        let scale = recording.segments[0].temperature_scale;
        if segment.temperature_scale != scale {
            return Err(format!(
                "{}: temperature scale {:?}, but segment 0 has {scale:?} (a recording has one \
                 temperature sensor scale)",
                at(),
                segment.temperature_scale
            ));
        }
        for (name, channel) in &segment.aux {
            match fixed_aux_unit(name) {
                Some(unit) if channel.unit != unit => {
                    return Err(format!(
                        "{}, auxiliary channel `{name}`: unit `{}`, but the format records \
                         `{name}` in {unit}",
                        at(),
                        channel.unit
                    ))
                }
                Some(_) => {}
                None => {
                    check_named_aux_channel(name).map_err(|e| format!("{}: {e}", at()))?;
                    let (unit, first) = *named.entry(name).or_insert((&channel.unit, k));
                    if unit != channel.unit {
                        return Err(format!(
                            "{}, auxiliary channel `{name}`: unit `{}`, but segment {first} has \
                             it in `{unit}` (a named channel is one topic with one unit per file)",
                            at(),
                            channel.unit
                        ));
                    }
                }
            }
            check_samples(segment, channel)
                .map_err(|e| format!("{}, auxiliary channel `{name}`: {e}", at()))?;
        }
    }
    Ok(named
        .into_iter()
        .map(|(name, (unit, _))| NamedTopic {
            name: name.to_owned(),
            topic: named_aux_topic(name),
            unit: unit.to_owned(),
        })
        .collect())
}

fn where_in(k: usize, segment: &Segment) -> String {
    let l = &segment.labels;
    format!(
        "segment {k} (series {}, repeat {}, activation {})",
        l.series, l.repeat, l.activation
    )
}

fn check_samples(segment: &Segment, channel: &AuxChannel) -> Result<(), String> {
    if channel.sample_rate_hz != AUX_RATE_HZ {
        return Err(format!(
            "sampled at {} Hz, but the format records auxiliary channels at {AUX_RATE_HZ} Hz",
            channel.sample_rate_hz
        ));
    }
    let fs = segment.sample_rate_hz;
    let covered = aux_samples_covered(segment.len(), fs);
    if channel.values.len() > covered {
        return Err(format!(
            "{} values, but the activation ({} samples at {fs} Hz) covers {covered} at \
             {AUX_RATE_HZ} Hz",
            channel.values.len(),
            segment.len()
        ));
    }
    if let Some(i) = channel.values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "non-finite value {} at sample {i} (the reader refuses NaN and ∞)",
            channel.values[i]
        ));
    }
    Ok(())
}
