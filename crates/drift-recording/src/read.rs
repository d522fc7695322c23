//! Reads and validates a recording into per-activation segments: the input of the fitter.
//!
//! The reader refuses ground-truth sidecars (by name, by MCAP profile, and by `/truth/`
//! topics), so code that only uses this module cannot see the truth. It validates while
//! it reads: missing topics, non-monotonic or duplicate timestamps, gaps or overlaps in the
//! sample sequence, NaN/∞ values and unbalanced power events are errors naming the file,
//! topic and the message's index within that topic.
//!
//! Every `/aux/<name>` topic besides the fixed ones is a named auxiliary channel (a `ScalarBatch`):
//! it becomes channel `<name>` of the activations it has messages in. Any other schema there, or a
//! name outside [`crate::check_named_aux_channel`]'s rule, is an error at its first message rather
//! than a skip: a channel a bench meant to record would otherwise vanish from the diagnosis
//! unnoticed. Topics outside `/aux/` that the format does not know are ignored.

use crate::aux::check_named_aux_channel;
use crate::error::ReadError;
use crate::layout::{aux_samples_covered, AUX_RATE_HZ, RECORDINGS_DIR, TRUTH_DIR, TRUTH_EXTENSION};
use crate::messages::ChannelInfo;
use crate::progress::{Progress, QUIET};
use crate::schema::{self, PowerEvent, RawTemperatureBatch, ScalarBatch, Vector3Batch};
use crate::segment::{AuxChannel, Segment, SegmentLabels, SeriesKind, TemperatureScale};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// Topics every recording must have.
pub const REQUIRED_TOPICS: [&str; 6] = [
    schema::TOPIC_RATE,
    schema::TOPIC_TEMPERATURE_RAW,
    schema::TOPIC_ACCEL,
    schema::TOPIC_SUPPLY,
    schema::TOPIC_SET_POINT,
    schema::TOPIC_POWER,
];

/// A validated recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// The file.
    pub path: PathBuf,
    /// The `gyrodrift.recording` metadata record.
    pub metadata: BTreeMap<String, String>,
    /// Unit id.
    pub unit_id: String,
    /// Gyro sample rate (Hz).
    pub sample_rate_hz: u32,
    /// Activations in recording order.
    pub segments: Vec<Segment>,
}

/// Reads every recording of a campaign folder (`<dir>/recordings/*.mcap`, sorted by name).
/// The `truth/` folder is never listed or opened.
pub fn read_campaign_dir(dir: &Path) -> Result<Vec<Recording>, ReadError> {
    let folder = dir.join(RECORDINGS_DIR);
    let entries = std::fs::read_dir(&folder).map_err(|e| ReadError::Io {
        path: folder.clone(),
        source: e,
    })?;
    let mut paths = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| ReadError::Io {
            path: folder.clone(),
            source: e,
        })?;
        let path = entry.path();
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if name.ends_with(".mcap") && !name.starts_with('.') && !name.ends_with(TRUTH_EXTENSION) {
            paths.push(path);
        }
    }
    paths.sort();
    paths.iter().map(|p| read_recording(p)).collect()
}

/// True if a path names a ground-truth sidecar (checked before the file is opened): a
/// `*.truth.mcap` name, or any file directly inside a campaign's `truth/` folder.
pub fn is_truth_path(path: &Path) -> bool {
    let name_says_truth = path
        .file_name()
        .is_some_and(|n| n.to_string_lossy().ends_with(TRUTH_EXTENSION));
    let folder_says_truth = path
        .parent()
        .and_then(Path::file_name)
        .is_some_and(|d| d == TRUTH_DIR);
    name_says_truth || folder_says_truth
}

struct Open {
    labels: SegmentLabels,
    on_ns: u64,
    rate: [Vec<f32>; 3],
    raw: [Vec<i16>; 3],
    accel: [Vec<f32>; 3],
    supply: Vec<f32>,
    set_point: Vec<f32>,
    /// Named channels with a message in this activation.
    named: BTreeMap<String, AuxChannel>,
}

/// Per-topic bookkeeping for messages: index and last log time.
#[derive(Default)]
struct TopicState {
    count: usize,
    last_ns: Option<u64>,
}

/// A recording's bytes, opened and checked up to its metadata: not ground truth, has a summary,
/// every required topic and the `gyrodrift.recording` metadata.
struct Opened {
    buf: Vec<u8>,
    metadata: BTreeMap<String, String>,
    unit_id: String,
    sample_rate_hz: u32,
    /// The metadata's `set_point_celsius`, when it has one.
    session_set_point_celsius: Option<f64>,
    /// The metadata's temperature scale.
    temperature_scale: TemperatureScale,
}

fn open(path: &Path) -> Result<Opened, ReadError> {
    refuse_truth_name(path)?;
    let buf = std::fs::read(path).map_err(|e| ReadError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    open_bytes(path, buf)
}

/// The name check happens before anything is read, so a sidecar is never even opened.
fn refuse_truth_name(path: &Path) -> Result<(), ReadError> {
    if is_truth_path(path) {
        return Err(ReadError::GroundTruth {
            path: path.to_path_buf(),
            why: "sidecar file name or truth/ folder".into(),
        });
    }
    Ok(())
}

fn open_bytes(path: &Path, buf: Vec<u8>) -> Result<Opened, ReadError> {
    // A file that starts as MCAP and lacks the closing magic was cut short: say so, rather than
    // the container's "bad magic" (which reads like the wrong kind of file).
    if buf.starts_with(mcap::MAGIC) && !buf.ends_with(mcap::MAGIC) {
        return Err(ReadError::Truncated {
            path: path.to_path_buf(),
            length: buf.len(),
        });
    }
    crate::messages::check_uncompressed_chunks(&buf).map_err(|e| ReadError::Mcap {
        path: path.to_path_buf(),
        source: e,
    })?;
    let mcap_err = |e| ReadError::Mcap {
        path: path.to_path_buf(),
        source: e,
    };
    if let Some(Ok(mcap::records::Record::Header(h))) = mcap::read::LinearReader::new(&buf)
        .map_err(mcap_err)?
        .next()
    {
        if h.profile == schema::PROFILE_TRUTH {
            return Err(ReadError::GroundTruth {
                path: path.to_path_buf(),
                why: format!("MCAP profile `{}`", h.profile),
            });
        }
    }
    let summary = mcap::read::Summary::read(&buf)
        .map_err(mcap_err)?
        .ok_or_else(|| ReadError::Metadata {
            path: path.to_path_buf(),
            name: "summary".into(),
            reason: "the MCAP has no summary section (was finish() called?)".into(),
        })?;
    let topics: Vec<&str> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    if let Some(t) = topics.iter().find(|t| t.starts_with(schema::TRUTH_PREFIX)) {
        return Err(ReadError::GroundTruth {
            path: path.to_path_buf(),
            why: format!("topic {t}"),
        });
    }
    for required in REQUIRED_TOPICS {
        if !topics.contains(&required) {
            return Err(ReadError::MissingTopic {
                path: path.to_path_buf(),
                topic: required.into(),
            });
        }
    }
    let meta_err = |reason: String| ReadError::Metadata {
        path: path.to_path_buf(),
        name: schema::METADATA_RECORDING.into(),
        reason,
    };
    let mut metadata = None;
    for index in &summary.metadata_indexes {
        if index.name == schema::METADATA_RECORDING {
            // mcap 0.26 adds offset + length unchecked and slices with them (found by fuzzing,
            // F9): check the index against the file first.
            let fits = index
                .offset
                .checked_add(index.length)
                .is_some_and(|end| end <= buf.len() as u64);
            if !fits {
                return Err(meta_err(format!(
                    "metadata index points outside the file (offset {}, length {}, file {} bytes)",
                    index.offset,
                    index.length,
                    buf.len()
                )));
            }
            metadata = Some(
                mcap::read::metadata(&buf, index)
                    .map_err(mcap_err)?
                    .metadata,
            );
        }
    }
    let metadata = metadata.ok_or_else(|| meta_err("record missing".into()))?;
    let field = |k: &str| {
        metadata
            .get(k)
            .cloned()
            .ok_or_else(|| meta_err(format!("key `{k}` missing")))
    };
    let unit_id = field("unit_id")?;
    let sample_rate_hz: u32 = field("sample_rate_hz")?
        .parse()
        .map_err(|e| meta_err(format!("sample_rate_hz: {e}")))?;
    if sample_rate_hz == 0 || 1_000_000_000 % sample_rate_hz != 0 {
        return Err(meta_err(format!(
            "sample_rate_hz must divide 10⁹, got {sample_rate_hz}"
        )));
    }
    // Optional (an imported log may not know it), but a value that is there must be a number:
    // the activations' roles are decided by it.
    let session_set_point_celsius = metadata
        .get("set_point_celsius")
        .map(|s| match s.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(meta_err(format!(
                "set_point_celsius must be a finite number of °C, got `{s}`"
            ))),
        })
        .transpose()?;
    let temperature_scale = TemperatureScale::from_metadata(&metadata).map_err(meta_err)?;
    Ok(Opened {
        buf,
        metadata,
        unit_id,
        sample_rate_hz,
        session_set_point_celsius,
        temperature_scale,
    })
}

/// Reads a recording's metadata (unit id, chamber set point, series kind, ...) without decoding its
/// messages: how the fitter picks calibration files without decoding anything else. The same
/// checks as [`read_recording`] up to the metadata (ground truth is refused).
pub fn read_metadata(path: &Path) -> Result<BTreeMap<String, String>, ReadError> {
    Ok(open(path)?.metadata)
}

/// Reads and validates one recording.
pub fn read_recording(path: &Path) -> Result<Recording, ReadError> {
    OpenRecording::open(path)?.read()
}

/// [`read_recording`], telling `progress` how far it got ([`OpenRecording::read_with`]).
pub fn read_recording_with(path: &Path, progress: &dyn Progress) -> Result<Recording, ReadError> {
    OpenRecording::open(path)?.read_with(progress)
}

/// A recording file read into memory and checked up to its metadata (the checks of
/// [`read_metadata`]), its messages not yet decoded: a reader that chooses files by their metadata
/// reads each file once, and one that wants activations one at a time never holds a whole
/// recording's samples.
pub struct OpenRecording {
    path: PathBuf,
    opened: Opened,
}

impl OpenRecording {
    /// Reads the file and checks it up to its metadata, as [`read_metadata`] does.
    pub fn open(path: &Path) -> Result<Self, ReadError> {
        Ok(Self {
            path: path.to_path_buf(),
            opened: open(path)?,
        })
    }

    /// The `gyrodrift.recording` metadata record.
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.opened.metadata
    }

    /// Unit id.
    pub fn unit_id(&self) -> &str {
        &self.opened.unit_id
    }

    /// Decodes and validates every message, as [`read_recording`] does.
    pub fn read(self) -> Result<Recording, ReadError> {
        self.read_with(QUIET)
    }

    /// [`OpenRecording::read`], telling `progress` after each activation how many of the file's
    /// bytes are decoded (step [`READING`]); [`ReadError::Interrupted`] when it asks to stop.
    pub fn read_with(self, progress: &dyn Progress) -> Result<Recording, ReadError> {
        let mut segments = Vec::new();
        let (path, metadata, unit_id, sample_rate_hz) = (
            self.path.clone(),
            self.opened.metadata.clone(),
            self.opened.unit_id.clone(),
            self.opened.sample_rate_hz,
        );
        decode(
            &self.path,
            self.opened,
            &mut |segment| {
                segments.push(segment);
                true
            },
            progress,
        )?;
        Ok(Recording {
            path,
            metadata,
            unit_id,
            sample_rate_hz,
            segments,
        })
    }

    /// Decodes and validates the messages with [`read_recording`]'s checks, handing `each` every
    /// activation as soon as its switch-off is read, in recording order; `each` returns whether to
    /// go on. Returns `Ok(true)` when the whole file was read and valid, `Ok(false)` when `each`
    /// stopped it. An error can come after activations were handed over (a fault later in the
    /// file): then the file is invalid as a whole, as it is for [`read_recording`].
    pub fn for_each_activation(
        self,
        mut each: impl FnMut(Segment) -> bool,
    ) -> Result<bool, ReadError> {
        decode(&self.path, self.opened, &mut each, QUIET)
    }

    /// [`OpenRecording::for_each_activation`], telling `progress` after each activation as
    /// [`OpenRecording::read_with`] does; [`ReadError::Interrupted`] when it asks to stop.
    pub fn for_each_activation_with(
        self,
        mut each: impl FnMut(Segment) -> bool,
        progress: &dyn Progress,
    ) -> Result<bool, ReadError> {
        decode(&self.path, self.opened, &mut each, progress)
    }
}

/// Reads and validates a recording held in memory; `name` stands for the file in errors and in
/// [`Recording::path`] (and is checked like a file name: a ground-truth name is refused). The same
/// checks as [`read_recording`], which reads the file and calls this; fuzzing drives it directly.
pub fn read_recording_bytes(name: &Path, bytes: &[u8]) -> Result<Recording, ReadError> {
    refuse_truth_name(name)?;
    OpenRecording {
        path: name.to_path_buf(),
        opened: open_bytes(name, bytes.to_vec())?,
    }
    .read()
}

/// The step a reader reports to its [`Progress`]: bytes of the file decoded.
pub const READING: &str = "reading";

/// Why decoding stopped before the end of the file.
enum Halt {
    Invalid(ReadError),
    /// The progress hook asked to stop.
    Interrupted,
    /// The receiver of the activations wanted no more.
    Stopped,
}

/// Decodes `opened`'s messages, handing each finished activation to `each`; `Ok(false)` when
/// `each` returned `false`.
fn decode(
    path: &Path,
    opened: Opened,
    each: &mut dyn FnMut(Segment) -> bool,
    progress: &dyn Progress,
) -> Result<bool, ReadError> {
    let Opened {
        buf,
        unit_id,
        sample_rate_hz,
        session_set_point_celsius,
        temperature_scale,
        ..
    } = opened;
    let mcap_err = |e| ReadError::Mcap {
        path: path.to_path_buf(),
        source: e,
    };
    let mut reader = Reader {
        path,
        unit_id: &unit_id,
        rate_hz: sample_rate_hz,
        session_set_point_celsius,
        temperature_scale,
        open: None,
        each,
        stopped: false,
        finished: 0,
        topics: HashMap::new(),
        named_units: HashMap::new(),
    };
    let total = buf.len() as u64;
    let decoded = crate::messages::for_each_message(&buf, |channel, log_ns, data, bytes_in| {
        let finished = reader.finished;
        reader
            .message(channel, log_ns, data)
            .map_err(Halt::Invalid)?;
        if reader.stopped {
            return Err(Halt::Stopped);
        }
        if reader.finished != finished && progress.check(READING, bytes_in as u64, total).is_err() {
            return Err(Halt::Interrupted);
        }
        Ok(())
    });
    match decoded {
        Ok(()) => {}
        Err(Ok(e)) => return Err(mcap_err(e)),
        Err(Err(Halt::Invalid(e))) => return Err(e),
        Err(Err(Halt::Stopped)) => return Ok(false),
        Err(Err(Halt::Interrupted)) => {
            return Err(ReadError::Interrupted {
                path: path.to_path_buf(),
            })
        }
    }
    if reader.open.is_some() {
        let index = reader
            .topics
            .get(schema::TOPIC_POWER)
            .map_or(0, |s| s.count.saturating_sub(1));
        return Err(reader.err(
            schema::TOPIC_POWER,
            index,
            "file ends while the unit is on (no switch-off event)".into(),
        ));
    }
    Ok(true)
}

struct Reader<'p> {
    path: &'p Path,
    unit_id: &'p str,
    rate_hz: u32,
    /// The recording's nominal set point, copied into every activation's labels.
    session_set_point_celsius: Option<f64>,
    /// The recording's temperature scale, carried by every activation.
    temperature_scale: TemperatureScale,
    open: Option<Open>,
    /// Takes each finished activation; `false`: no more wanted.
    each: &'p mut dyn FnMut(Segment) -> bool,
    /// `each` returned `false`.
    stopped: bool,
    /// Activations handed to `each`.
    finished: u64,
    topics: HashMap<String, TopicState>,
    /// Unit of each named channel, from the first channel record it was read with.
    named_units: HashMap<String, String>,
}

fn nan_free(values: &[f32], from: usize) -> Result<(), String> {
    match values[from..].iter().position(|v| !v.is_finite()) {
        Some(k) => Err(format!(
            "non-finite value {} at sample {} of the segment",
            values[from + k],
            from + k
        )),
        None => Ok(()),
    }
}

impl Reader<'_> {
    fn err(&self, topic: &str, index: usize, reason: String) -> ReadError {
        ReadError::Message {
            path: self.path.to_path_buf(),
            topic: topic.to_owned(),
            index,
            reason,
        }
    }

    fn message(
        &mut self,
        channel: &ChannelInfo,
        log_ns: u64,
        data: &[u8],
    ) -> Result<(), ReadError> {
        let topic = channel.topic.as_str();
        if topic.starts_with(schema::TRUTH_PREFIX) {
            return Err(ReadError::GroundTruth {
                path: self.path.to_path_buf(),
                why: format!("topic {topic}"),
            });
        }
        let named = match topic.strip_prefix(schema::AUX_PREFIX) {
            _ if REQUIRED_TOPICS.contains(&topic) => None,
            Some(name) => Some(name),
            None => return Ok(()), // Extra topics a bench may add are allowed and ignored.
        };
        if let Some(reason) = foreign_encoding(channel) {
            let index = self.topics.get(topic).map_or(0, |state| state.count);
            return Err(self.err(topic, index, reason));
        }
        let state = self.topics.entry(topic.to_owned()).or_default();
        let index = state.count;
        state.count += 1;
        if let Some(last) = state.last_ns {
            if log_ns == last {
                return Err(self.err(topic, index, format!("duplicate timestamp {log_ns} ns")));
            }
            if log_ns < last {
                return Err(self.err(
                    topic,
                    index,
                    format!("timestamp {log_ns} ns goes back (previous {last} ns)"),
                ));
            }
        }
        state.last_ns = Some(log_ns);
        let result = if topic == schema::TOPIC_POWER {
            self.power(log_ns, data)
        } else if let Some(name) = named {
            named_channel(name, channel).and_then(|unit| self.named(name, unit, data))
        } else {
            self.samples(topic, data)
        };
        result.map_err(|reason| self.err(topic, index, reason))
    }

    fn power(&mut self, log_ns: u64, data: &[u8]) -> Result<(), String> {
        let e = PowerEvent::decode(data)?;
        let kind = SeriesKind::parse(&e.series_kind).ok_or_else(|| {
            format!(
                "series_kind must be protocol|field, got `{}`",
                e.series_kind
            )
        })?;
        if e.powered {
            if self.open.is_some() {
                return Err("switch-on while already on (missing switch-off)".into());
            }
            if !e.set_point_celsius.is_finite() {
                return Err("set_point_celsius is not finite".into());
            }
            let labels = SegmentLabels {
                unit_id: self.unit_id.to_owned(),
                set_point_celsius: e.set_point_celsius,
                // `None` when it says what the switch-on label says: one form for one meaning,
                // so labels made in memory (without it) read back equal from the file.
                session_set_point_celsius: self
                    .session_set_point_celsius
                    .filter(|&nominal| nominal != e.set_point_celsius),
                series_kind: kind,
                series: e.series,
                repeat: e.repeat,
                activation: e.activation,
                interval_min: e.interval_min.is_finite().then_some(e.interval_min),
                off_before_s: e.off_before_s.is_finite().then_some(e.off_before_s),
            };
            let v = Vec::new;
            self.open = Some(Open {
                labels,
                on_ns: log_ns,
                rate: [v(), v(), v()],
                raw: [Vec::new(), Vec::new(), Vec::new()],
                accel: [v(), v(), v()],
                supply: v(),
                set_point: v(),
                named: BTreeMap::new(),
            });
            return Ok(());
        }
        let open = self.open.take().ok_or("switch-off without switch-on")?;
        if (e.series, e.repeat, e.activation)
            != (
                open.labels.series,
                open.labels.repeat,
                open.labels.activation,
            )
        {
            return Err(format!(
                "switch-off labels (series {}, repeat {}, activation {}) differ from switch-on ({}, {}, {})",
                e.series, e.repeat, e.activation, open.labels.series, open.labels.repeat, open.labels.activation
            ));
        }
        let n = open.rate[0].len();
        if open.raw[0].len() != n {
            return Err(format!(
                "{n} rate samples but {} temperature samples in the activation",
                open.raw[0].len()
            ));
        }
        if n == 0 {
            return Err("activation without samples".into());
        }
        let period_ns = 1_000_000_000 / u64::from(self.rate_hz);
        let expected_off = (n as u64)
            .checked_mul(period_ns)
            .and_then(|d| open.on_ns.checked_add(d))
            .ok_or("the activation ends beyond the u64 ns clock (584 years)")?;
        if log_ns < expected_off {
            return Err(format!(
                "switch-off at {log_ns} ns precedes the end of the last sample ({expected_off} ns)"
            ));
        }
        let aux = |values: Vec<f32>, unit: &str| AuxChannel {
            unit: unit.into(),
            sample_rate_hz: AUX_RATE_HZ,
            values,
        };
        let [ax, ay, az] = open.accel;
        let mut aux = BTreeMap::from([
            ("accel_x".to_owned(), aux(ax, "g")),
            ("accel_y".to_owned(), aux(ay, "g")),
            ("accel_z".to_owned(), aux(az, "g")),
            ("supply_voltage".to_owned(), aux(open.supply, "V")),
            ("chamber_set_point".to_owned(), aux(open.set_point, "degC")),
        ]);
        // Named channels never shadow these: their names were checked at their first message.
        aux.extend(open.named);
        // Samples past the switch-off would be dropped by a write back (and be nonsense).
        let covered = aux_samples_covered(n, self.rate_hz);
        if let Some((name, c)) = aux.iter().find(|(_, c)| c.values.len() > covered) {
            return Err(format!(
                "auxiliary channel `{name}` has {} samples, but the activation ({n} samples at {} \
                 Hz) covers {covered} at {AUX_RATE_HZ} Hz",
                c.values.len(),
                self.rate_hz
            ));
        }
        let segment = Segment {
            labels: open.labels,
            sample_rate_hz: self.rate_hz,
            power_on_ns: open.on_ns,
            since_power_on: (0..n as u32).collect(),
            rate_dps: open.rate,
            temperature_raw: open.raw,
            temperature_scale: self.temperature_scale,
            aux,
        };
        self.finished += 1;
        self.stopped = !(self.each)(segment);
        Ok(())
    }

    /// A batch of the named channel `name` (its unit from the channel metadata).
    fn named(&mut self, name: &str, unit: &str, data: &[u8]) -> Result<(), String> {
        // MCAP allows several channel records on one topic: a recording gives a name one unit.
        let first_unit = self
            .named_units
            .entry(name.to_owned())
            .or_insert_with(|| unit.to_owned());
        if first_unit != unit {
            return Err(format!(
                "channel metadata unit `{unit}`, but an earlier channel on this topic has `{first_unit}`"
            ));
        }
        let open = self
            .open
            .as_mut()
            .ok_or("samples while the unit is off (no switch-on before)")?;
        let channel = open
            .named
            .entry(name.to_owned())
            .or_insert_with(|| AuxChannel {
                unit: unit.to_owned(),
                sample_rate_hz: AUX_RATE_HZ,
                values: Vec::new(),
            });
        let before = channel.values.len();
        let batch = ScalarBatch::decode_into(data, &mut channel.values)?;
        nan_free(&channel.values, before)?;
        check_batch(before, batch, AUX_RATE_HZ)
    }

    fn samples(&mut self, topic: &str, data: &[u8]) -> Result<(), String> {
        let rate_hz = self.rate_hz;
        let open = self
            .open
            .as_mut()
            .ok_or("samples while the unit is off (no switch-on before)")?;
        let (expected, batch) = match topic {
            schema::TOPIC_RATE => {
                let before = open.rate[0].len();
                let r = Vector3Batch::decode_into(data, &mut open.rate)?;
                for axis in &open.rate {
                    nan_free(axis, before)?;
                }
                (before, r)
            }
            schema::TOPIC_TEMPERATURE_RAW => (
                open.raw[0].len(),
                RawTemperatureBatch::decode_into(data, &mut open.raw)?,
            ),
            schema::TOPIC_ACCEL => {
                let before = open.accel[0].len();
                let r = Vector3Batch::decode_into(data, &mut open.accel)?;
                for axis in &open.accel {
                    nan_free(axis, before)?;
                }
                (before, r)
            }
            _ => {
                let values = if topic == schema::TOPIC_SUPPLY {
                    &mut open.supply
                } else {
                    &mut open.set_point
                };
                let before = values.len();
                let r = ScalarBatch::decode_into(data, values)?;
                nan_free(values, before)?;
                (before, r)
            }
        };
        let expected_rate = if topic == schema::TOPIC_RATE || topic == schema::TOPIC_TEMPERATURE_RAW
        {
            rate_hz
        } else {
            AUX_RATE_HZ
        };
        check_batch(expected, batch, expected_rate)
    }
}

/// The schema each of the format's own topics is written with.
fn own_schema(topic: &str) -> Option<&'static str> {
    Some(match topic {
        schema::TOPIC_RATE | schema::TOPIC_ACCEL => schema::SCHEMA_VECTOR3.0,
        schema::TOPIC_TEMPERATURE_RAW => schema::SCHEMA_RAW_TEMPERATURE.0,
        schema::TOPIC_SUPPLY | schema::TOPIC_SET_POINT => schema::SCHEMA_SCALAR.0,
        schema::TOPIC_POWER => schema::SCHEMA_POWER.0,
        _ => return None,
    })
}

/// Why a channel of one of the format's own topics is not in the format's schema and encodings
/// (a bench tool may reuse a topic name for its own messages: decoding them as ours would give
/// plausible wrong numbers), or `None` when it is. Named channels' schema is checked by
/// [`named_channel`]; their encodings here.
fn foreign_encoding(channel: &ChannelInfo) -> Option<String> {
    let expected = own_schema(&channel.topic);
    let schema_ok = expected.is_none_or(|name| channel.schema.as_deref() == Some(name));
    let encodings_ok = channel.message_encoding == "cdr"
        && channel
            .schema_encoding
            .as_deref()
            .is_none_or(|e| e == "ros2msg");
    if schema_ok && encodings_ok {
        return None;
    }
    let found = channel.schema.as_deref().map_or_else(
        || "no schema".to_owned(),
        |name| {
            format!(
                "schema `{name}` ({})",
                channel.schema_encoding.as_deref().unwrap_or("?")
            )
        },
    );
    Some(format!(
        "channel {} has {found} with {} messages, but the format writes it as {} (ros2msg) with cdr messages: not a gyrodrift recording's channel",
        channel.topic,
        channel.message_encoding,
        expected.unwrap_or(schema::SCHEMA_SCALAR.0)
    ))
}

/// The unit of a named auxiliary channel's topic (empty if its metadata has none), or why the
/// topic cannot be one.
fn named_channel<'c>(name: &str, channel: &'c ChannelInfo) -> Result<&'c str, String> {
    check_named_aux_channel(name)?;
    let scalar = schema::SCHEMA_SCALAR.0;
    match channel.schema.as_deref() {
        Some(s) if s == scalar => {}
        found => {
            let found = found.map_or_else(|| "no schema".to_owned(), |s| format!("schema `{s}`"));
            return Err(format!(
                "{found}: an auxiliary topic other than {} is a named channel and must be {scalar}",
                schema::TOPIC_ACCEL
            ));
        }
    }
    Ok(channel.metadata.get("unit").map_or("", String::as_str))
}

/// Checks a decoded batch `(first_sample, sample_rate_hz, count)` against where the topic's samples
/// of the activation end (`expected`) and its rate.
fn check_batch(
    expected: usize,
    (first, rate, _n): (u32, u32, usize),
    expected_rate: u32,
) -> Result<(), String> {
    if rate != expected_rate {
        return Err(format!("sample_rate_hz {rate}, expected {expected_rate}"));
    }
    if first as usize != expected {
        let what = if (first as usize) > expected {
            "gap"
        } else {
            "overlap or duplicate"
        };
        return Err(format!("{what}: first_sample {first}, expected {expected}"));
    }
    Ok(())
}
