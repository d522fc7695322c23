//! The labels an exported bag carries for its way back: one MCAP metadata record, `gyrodrift`,
//! with the recording's unit, rate, set point and series kind and each activation's labels and
//! place on the clock. ROS tools ignore it; `import rosbag` reads it (from the summary's metadata
//! index, without decoding a message) and splits the bag into the activations it came from.

use std::collections::BTreeMap;
use std::path::Path;

use crate::segment::{Segment, SegmentLabels, SeriesKind};

/// The metadata record's name.
pub const LABELS_RECORD: &str = "gyrodrift";

/// One exported activation: its labels and where it lies on the bag's clock.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportedActivation {
    /// The activation's labels.
    pub labels: SegmentLabels,
    /// Switch-on on the bag's clock, ns.
    pub power_on_ns: u64,
    /// Samples.
    pub samples: usize,
}

/// What an exported bag says about itself.
#[derive(Debug, Clone, PartialEq)]
pub struct ExportedLabels {
    /// Unit id.
    pub unit_id: String,
    /// The recording's sample rate, Hz.
    pub sample_rate_hz: u32,
    /// The recording's set point, °C, when its metadata gave one.
    pub set_point_celsius: Option<f64>,
    /// The recording's series kind.
    pub series_kind: SeriesKind,
    /// The activations, in order.
    pub activations: Vec<ExportedActivation>,
}

fn option(v: Option<f64>) -> String {
    v.map(|v| format!("{v:?}")).unwrap_or_default()
}

/// The record's entries for `segments` of a recording with `metadata`.
pub fn labels_entries(
    unit_id: &str,
    sample_rate_hz: u32,
    metadata: &BTreeMap<String, String>,
    segments: &[&Segment],
) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("unit_id".into(), unit_id.to_owned());
    m.insert("sample_rate_hz".into(), sample_rate_hz.to_string());
    if let Some(sp) = metadata.get("set_point_celsius") {
        m.insert("set_point_celsius".into(), sp.clone());
    }
    let kind = segments
        .first()
        .map(|s| s.labels.series_kind)
        .or_else(|| {
            metadata
                .get("series_kind")
                .and_then(|k| SeriesKind::parse(k))
        })
        .unwrap_or(SeriesKind::Field);
    m.insert("series_kind".into(), kind.as_str().into());
    m.insert("activations".into(), segments.len().to_string());
    for (k, s) in segments.iter().enumerate() {
        let l = &s.labels;
        let p = format!("activation.{k}.");
        for (key, value) in [
            ("power_on_ns", s.power_on_ns.to_string()),
            ("samples", s.len().to_string()),
            ("set_point_celsius", format!("{:?}", l.set_point_celsius)),
            (
                "session_set_point_celsius",
                option(l.session_set_point_celsius),
            ),
            ("series_kind", l.series_kind.as_str().into()),
            ("series", l.series.to_string()),
            ("repeat", l.repeat.to_string()),
            ("activation", l.activation.to_string()),
            ("interval_min", option(l.interval_min)),
            ("off_before_s", option(l.off_before_s)),
        ] {
            m.insert(format!("{p}{key}"), value);
        }
    }
    m
}

/// Reads the record from an MCAP file's bytes: `Ok(None)` if the file has none (a bag another
/// tool wrote), an error naming the entry if it is there but unreadable.
pub fn read_labels(path: &Path, buf: &[u8]) -> Result<Option<ExportedLabels>, String> {
    let Ok(Some(summary)) = mcap::read::Summary::read(buf) else {
        return Ok(None);
    };
    let Some(index) = summary
        .metadata_indexes
        .iter()
        .find(|i| i.name == LABELS_RECORD)
    else {
        return Ok(None);
    };
    let record = mcap::read::metadata(buf, index)
        .map_err(|e| format!("{}: metadata record `{LABELS_RECORD}`: {e}", path.display()))?;
    parse(&record.metadata)
        .map(Some)
        .map_err(|e| format!("{}: metadata record `{LABELS_RECORD}`: {e}", path.display()))
}

fn parse(m: &BTreeMap<String, String>) -> Result<ExportedLabels, String> {
    let get = |key: &str| m.get(key).ok_or_else(|| format!("no entry `{key}`"));
    fn num<T: std::str::FromStr>(key: &str, text: &str) -> Result<T, String> {
        text.parse()
            .map_err(|_| format!("entry `{key}`: `{text}` is not a number"))
    }
    let opt = |key: &str| -> Result<Option<f64>, String> {
        match m.get(key).map(String::as_str) {
            None | Some("") => Ok(None),
            Some(t) => num(key, t).map(Some),
        }
    };
    let kind = |key: &str| -> Result<SeriesKind, String> {
        let t = get(key)?;
        SeriesKind::parse(t).ok_or_else(|| format!("entry `{key}`: `{t}` is not a series kind"))
    };
    let unit_id = get("unit_id")?.clone();
    let count: usize = num("activations", get("activations")?)?;
    let mut activations = Vec::new();
    for k in 0..count {
        let key = |name: &str| format!("activation.{k}.{name}");
        let labels = SegmentLabels {
            unit_id: unit_id.clone(),
            set_point_celsius: num(&key("set_point_celsius"), get(&key("set_point_celsius"))?)?,
            session_set_point_celsius: opt(&key("session_set_point_celsius"))?,
            series_kind: kind(&key("series_kind"))?,
            series: num(&key("series"), get(&key("series"))?)?,
            repeat: num(&key("repeat"), get(&key("repeat"))?)?,
            activation: num(&key("activation"), get(&key("activation"))?)?,
            interval_min: opt(&key("interval_min"))?,
            off_before_s: opt(&key("off_before_s"))?,
        };
        activations.push(ExportedActivation {
            labels,
            power_on_ns: num(&key("power_on_ns"), get(&key("power_on_ns"))?)?,
            samples: num(&key("samples"), get(&key("samples"))?)?,
        });
    }
    Ok(ExportedLabels {
        unit_id,
        sample_rate_hz: num("sample_rate_hz", get("sample_rate_hz")?)?,
        set_point_celsius: opt("set_point_celsius")?,
        series_kind: kind("series_kind")?,
        activations,
    })
}
