//! Ground truth, for evaluation code only: never for fitting or diagnosis.
//!
//! The truth of a recording `recordings/X.mcap` is `truth/X.truth.mcap` (per-sample noise-free
//! bias, node temperatures, bias instability) plus `truth/units.json` and
//! `truth/campaign.json`. [`drift_recording::read_recording`] refuses all of them; this module
//! is the only door, and its name says what it is.

use drift_recording::schema::{self, Vector3Batch};
use drift_recording::ReadError;
use std::path::Path;

/// Per-activation truth series (per-sample systematic bias, °/s, X/Y/Z).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TruthSegment {
    /// Noise-free bias per sample, including the turn-on jitter (°/s).
    pub systematic_bias_dps: [Vec<f32>; 3],
    /// Element temperatures at 100 Hz (°C): the temperature the bias follows, which for a
    /// [`crate::unit::UnitModel::PaperExact`] unit is the sensor's site.
    pub element_celsius: [Vec<f32>; 3],
    /// ASIC (temperature-sensor site) true temperatures at 100 Hz (°C).
    pub asic_celsius: [Vec<f32>; 3],
    /// A drawn world's undeclared effects alone at 100 Hz (°/s; empty for a campaign).
    pub effect_dps: [Vec<f32>; 3],
}

/// Reads a `.truth.mcap` sidecar into per-activation series (in recording order).
pub fn read_truth(path: &Path) -> Result<Vec<TruthSegment>, ReadError> {
    let buf = std::fs::read(path).map_err(|e| ReadError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    let mcap_err = |e| ReadError::Mcap {
        path: path.to_path_buf(),
        source: e,
    };
    let mut out: Vec<TruthSegment> = Vec::new();
    let mut counts = std::collections::HashMap::<String, usize>::new();
    for message in mcap::MessageStream::new(&buf).map_err(mcap_err)? {
        let message = message.map_err(mcap_err)?;
        let topic = message.channel.topic.as_str();
        let index = *counts
            .entry(topic.to_owned())
            .and_modify(|c| *c += 1)
            .or_insert(0);
        let bad = |reason: String| ReadError::Message {
            path: path.to_path_buf(),
            topic: topic.to_owned(),
            index,
            reason,
        };
        match topic {
            schema::TOPIC_POWER => {
                let event = schema::PowerEvent::decode(&message.data).map_err(bad)?;
                if event.powered {
                    out.push(TruthSegment::default());
                }
            }
            schema::TOPIC_TRUTH_BIAS
            | schema::TOPIC_TRUTH_ELEMENT
            | schema::TOPIC_TRUTH_ASIC
            | schema::TOPIC_TRUTH_EFFECT => {
                let seg = out
                    .last_mut()
                    .ok_or_else(|| bad("truth before the first switch-on".into()))?;
                let target = match topic {
                    schema::TOPIC_TRUTH_BIAS => &mut seg.systematic_bias_dps,
                    schema::TOPIC_TRUTH_ELEMENT => &mut seg.element_celsius,
                    schema::TOPIC_TRUTH_ASIC => &mut seg.asic_celsius,
                    _ => &mut seg.effect_dps,
                };
                Vector3Batch::decode_into(&message.data, target).map_err(bad)?;
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Reads the sensor faults injected into a recording from its `.truth.mcap` sidecar (empty when
/// the campaign injected none).
pub fn read_faults(path: &Path) -> Result<Vec<crate::faults::FaultEvent>, ReadError> {
    let buf = std::fs::read(path).map_err(|e| ReadError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    let mcap_err = |e| ReadError::Mcap {
        path: path.to_path_buf(),
        source: e,
    };
    let meta_err = |reason: String| ReadError::Metadata {
        path: path.to_path_buf(),
        name: crate::faults::FAULTS_METADATA.into(),
        reason,
    };
    let Some(summary) = mcap::read::Summary::read(&buf).map_err(mcap_err)? else {
        return Err(meta_err("the sidecar has no summary section".into()));
    };
    for index in &summary.metadata_indexes {
        if index.name == crate::faults::FAULTS_METADATA {
            let record = mcap::read::metadata(&buf, index).map_err(mcap_err)?;
            let events = record
                .metadata
                .get("events")
                .ok_or_else(|| meta_err("key `events` missing".into()))?;
            return serde_json::from_str(events).map_err(|e| meta_err(e.to_string()));
        }
    }
    Ok(Vec::new())
}
