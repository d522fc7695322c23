//! ROS 2 bags in and out: rosbag2's MCAP storage with the standard `sensor_msgs/msg/Imu` and
//! `sensor_msgs/msg/Temperature` messages (schema encoding `ros2msg`, message encoding `cdr`).
//!
//! Reading ([`read_bag`]): the messages of a gyro topic (`angular_velocity`, rad/s) and of a
//! temperature topic (`temperature`, °C) of one bag (one MCAP file, or the files a split bag was
//! written into), each timed by its `header.stamp` or by the recorder's log time. A topic's schema
//! must be the standard message: its name, its encodings and its definition text, whose fields
//! (with every type it uses, as rosbag2 stores them after `MSG:` lines) must flatten to the
//! standard ones; anything else is an error naming the file and the topic, never a guess.
//! [`Bag::rows`] pairs the two topics into rows (the temperature interpolated linearly at each
//! gyro message) that the CSV reader puts on the recording's grid.
//!
//! Writing ([`write_ros2_bag`]): one `Imu` message per sample and one `Temperature` message per
//! sample and axis, so that ROS tools and Foxglove plot every sample (the recording format batches
//! 100 per message).

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::cdr::{DecodeError, Decoder};
use crate::error::WriteError;
use crate::messages::ChannelInfo;
use crate::segment::{temperature_reading, Segment, RAW_PER_CELSIUS};
use crate::writer::McapFile;

/// Schema name of the standard IMU message.
pub const IMU_SCHEMA: &str = "sensor_msgs/msg/Imu";
/// Schema name of the standard temperature message.
pub const TEMPERATURE_SCHEMA: &str = "sensor_msgs/msg/Temperature";
/// MCAP profile of rosbag2's MCAP storage.
pub const PROFILE_ROS2: &str = "ros2";

/// The line rosbag2 puts between a message's definition and each type it uses, then the fields of
/// `std_msgs/Header`, `builtin_interfaces/Time`, `geometry_msgs/Quaternion` and
/// `geometry_msgs/Vector3`, in rosbag2's layout (after the message's own fields).
macro_rules! dependency {
    (header) => {
        "================================================================================\n\
MSG: std_msgs/Header\n\
# Stamped data: time and coordinate frame.\n\
builtin_interfaces/Time stamp\n\
string frame_id\n\
================================================================================\n\
MSG: builtin_interfaces/Time\n\
# ROS time: seconds and nanoseconds (0 <= nanosec < 1e9).\n\
int32 sec\n\
uint32 nanosec\n"
    };
    (geometry) => {
        "================================================================================\n\
MSG: geometry_msgs/Quaternion\n\
# An orientation as a unit quaternion.\n\
float64 x 0\n\
float64 y 0\n\
float64 z 0\n\
float64 w 1\n\
================================================================================\n\
MSG: geometry_msgs/Vector3\n\
# A vector in free space.\n\
float64 x\n\
float64 y\n\
float64 z\n"
    };
}

/// The `ros2msg` definition of [`IMU_SCHEMA`] as rosbag2 stores it (the standard fields; comments
/// are not part of the layout).
pub const IMU_DEFINITION: &str = concat!(
    "# Inertial measurement: orientation, angular velocity (rad/s), linear acceleration (m/s^2).\n\
# A covariance whose element 0 is -1 marks a quantity the sensor does not estimate.\n\
std_msgs/Header header\n\
\n\
geometry_msgs/Quaternion orientation\n\
float64[9] orientation_covariance # row major about x, y, z\n\
\n\
geometry_msgs/Vector3 angular_velocity\n\
float64[9] angular_velocity_covariance # row major about x, y, z\n\
\n\
geometry_msgs/Vector3 linear_acceleration\n\
float64[9] linear_acceleration_covariance # row major x, y, z\n",
    dependency!(header),
    dependency!(geometry)
);

/// The `ros2msg` definition of [`TEMPERATURE_SCHEMA`] as rosbag2 stores it.
pub const TEMPERATURE_DEFINITION: &str = concat!(
    "# A temperature reading.\n\
std_msgs/Header header\n\
\n\
float64 temperature # degrees Celsius\n\
\n\
float64 variance # 0 is interpreted as variance unknown\n",
    dependency!(header)
);

/// A bag could not be read as asked.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// File-system error.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The MCAP container is cut short or broken.
    #[error("{path}: MCAP: {reason}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A topic is missing, empty, or not the standard message.
    #[error("{path}: topic {topic}: {reason}")]
    Topic {
        /// The bag (a file or a bag folder).
        path: PathBuf,
        /// The topic.
        topic: String,
        /// What is wrong and how to fix it.
        reason: String,
    },
    /// A message could not be decoded or is out of order.
    #[error("{path}: topic {topic}, message #{index}: {reason}")]
    Message {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Index of the message within its topic in the bag (0-based).
        index: usize,
        /// What is wrong.
        reason: String,
    },
}

/// Which time a message is put at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BagClock {
    /// The message's `header.stamp` (the driver's time of the measurement).
    Header,
    /// The MCAP log time (when the recorder received the message).
    Log,
}

/// What [`read_bag`] reads: the topics' names.
#[derive(Debug, Clone)]
pub struct BagTopics {
    /// The `sensor_msgs/msg/Imu` topic.
    pub gyro: String,
    /// The `sensor_msgs/msg/Temperature` topic.
    pub temperature: String,
}

/// One bag's gyro and temperature messages, in time order.
#[derive(Debug, Clone)]
pub struct Bag {
    /// The bag (its file or folder).
    pub path: PathBuf,
    /// The topics read.
    pub topics: BagTopics,
    /// Per gyro message: time (ns on the chosen clock) and angular velocity X, Y, Z (rad/s).
    pub gyro: Vec<(i64, [f64; 3])>,
    /// Per temperature message: time (ns) and temperature (°C).
    pub temperature: Vec<(i64, f64)>,
    /// Every topic of the bag with its schema name, for messages and listings.
    pub all_topics: BTreeMap<String, String>,
}

/// Rows of one bag ([`Bag::rows`]): what the CSV reader resamples.
#[derive(Debug, Clone)]
pub struct BagRows {
    /// CSV text with the header `t_s,gx,gy,gz,temp_c`: time since `start_ns` (s), angular velocity
    /// (rad/s), temperature (°C); one row per gyro message.
    pub csv: String,
    /// Time of the first row, ns on the bag's clock.
    pub start_ns: i64,
    /// Time of the last row, ns.
    pub end_ns: i64,
    /// Index of the gyro message of the first row (messages before the first temperature message
    /// are left out: the temperature is not extrapolated).
    pub first_message: usize,
    /// Number of rows.
    pub rows: usize,
}

impl Bag {
    /// Pairs each gyro message inside the temperature topic's span with the temperature
    /// interpolated linearly at its time. A step between temperature messages longer than
    /// `max_temperature_gap_s` seconds is an error naming the message after it.
    pub fn rows(&self, max_temperature_gap_s: f64) -> Result<BagRows, BagError> {
        let topic_error = |topic: &str, reason: String| BagError::Topic {
            path: self.path.clone(),
            topic: topic.to_owned(),
            reason,
        };
        let (Some(t_first), Some(t_last)) = (self.temperature.first(), self.temperature.last())
        else {
            return Err(topic_error(&self.topics.temperature, "no messages".into()));
        };
        let gap_ns = max_temperature_gap_s * 1e9;
        if let Some(i) = self
            .temperature
            .windows(2)
            .position(|w| (w[1].0 - w[0].0) as f64 > gap_ns)
        {
            return Err(BagError::Message {
                path: self.path.clone(),
                topic: self.topics.temperature.clone(),
                index: i + 1,
                reason: format!(
                    "{:.3} s since the previous temperature message (at most {max_temperature_gap_s} s are interpolated across; `--max-temperature-gap` allows more)",
                    (self.temperature[i + 1].0 - self.temperature[i].0) as f64 * 1e-9
                ),
            });
        }
        let first_message = self.gyro.partition_point(|g| g.0 < t_first.0);
        let kept: Vec<&(i64, [f64; 3])> = self.gyro[first_message..]
            .iter()
            .take_while(|g| g.0 <= t_last.0)
            .collect();
        let (Some(first), Some(last)) = (kept.first(), kept.last()) else {
            return Err(topic_error(
                &self.topics.gyro,
                format!(
                    "no message between the first and the last message of {} ({} to {} ns): the topics do not overlap in time",
                    self.topics.temperature, t_first.0, t_last.0
                ),
            ));
        };
        let (start_ns, end_ns) = (first.0, last.0);
        let mut csv = String::with_capacity(kept.len() * 64 + 32);
        csv.push_str("t_s,gx,gy,gz,temp_c\n");
        let mut j = 0usize;
        for (t, w) in kept.iter().map(|g| (g.0, g.1)) {
            while j + 2 < self.temperature.len() && self.temperature[j + 1].0 <= t {
                j += 1;
            }
            let (ta, a) = self.temperature[j];
            let (tb, b) = self.temperature.get(j + 1).copied().unwrap_or((ta, a));
            let c = if tb > ta && t > ta {
                let f = ((t - ta) as f64 / (tb - ta) as f64).clamp(0.0, 1.0);
                if f >= 1.0 {
                    b
                } else {
                    a + (b - a) * f
                }
            } else {
                a
            };
            // Time from the first row in ns, exact in f64 up to 104 days.
            let _ = writeln!(
                csv,
                "{},{},{},{},{}",
                (t - start_ns) as f64 * 1e-9,
                w[0],
                w[1],
                w[2],
                c
            );
        }
        Ok(BagRows {
            csv,
            start_ns,
            end_ns,
            first_message,
            rows: kept.len(),
        })
    }
}

/// The MCAP files of a bag: the file itself, or a bag folder's `.mcap` files in the order of the
/// number their name ends with (rosbag2 names a split bag's files `<bag>_0.mcap`, `<bag>_1.mcap`,
/// ...).
pub fn bag_files(path: &Path) -> Result<Vec<PathBuf>, BagError> {
    if !path.is_dir() {
        return Ok(vec![path.to_path_buf()]);
    }
    let io = |source| BagError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(path)
        .map_err(io)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .filter(|p| {
            !p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with('.'))
        })
        .collect();
    files.sort_by_key(|p| {
        let stem = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let digits: String = stem
            .chars()
            .rev()
            .take_while(char::is_ascii_digit)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        (
            stem[..stem.len() - digits.len()].to_owned(),
            digits.parse::<u64>().unwrap_or(0),
            stem,
        )
    });
    if files.is_empty() {
        return Err(BagError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "a bag folder without .mcap files (only rosbag2's MCAP storage is read; convert a .db3 bag with `ros2 bag convert`)",
            ),
        });
    }
    Ok(files)
}

/// A field of a `.msg` definition: type (normalised) and name.
type Field = (String, String);

/// A parsed definition: the message's own fields, and the fields of each type it defines.
type Definition = (Vec<Field>, HashMap<String, Vec<Field>>);

const PRIMITIVES: [&str; 17] = [
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64", "string", "wstring", "float", "double",
];

/// `pkg/msg/Name` → `pkg/Name`; `Header` → `std_msgs/Header` (the one type ROS names without its
/// package); anything else as written.
fn normalise_type(ty: &str) -> String {
    let (base, array) = match ty.find('[') {
        Some(i) => ty.split_at(i),
        None => (ty, ""),
    };
    let base = match base.split('/').collect::<Vec<_>>().as_slice() {
        [pkg, "msg", name] => format!("{pkg}/{name}"),
        ["Header"] => "std_msgs/Header".to_owned(),
        _ => base.to_owned(),
    };
    format!("{base}{array}")
}

/// Parses a `ros2msg` definition as rosbag2 stores it: the message's fields, then, after each
/// separator line of `=`, `MSG: <type>` and that type's fields. Comments, blank lines and
/// constants (`TYPE NAME=value`) are skipped; default values after a field's name are ignored.
fn parse_definition(text: &str) -> Result<Definition, String> {
    let mut main = Vec::new();
    let mut types: HashMap<String, Vec<Field>> = HashMap::new();
    let mut current: Option<String> = None;
    for (n, line) in text.lines().enumerate() {
        let code = line.split('#').next().unwrap_or("").trim();
        if code.len() >= 3 && code.chars().all(|c| c == '=') {
            current = None;
            continue;
        }
        if code.is_empty() {
            continue;
        }
        if let Some(name) = code.strip_prefix("MSG:") {
            let name = normalise_type(name.trim());
            types.entry(name.clone()).or_default();
            current = Some(name);
            continue;
        }
        let mut tokens = code.split_whitespace();
        let (Some(ty), Some(name)) = (tokens.next(), tokens.next()) else {
            return Err(format!("line {}: `{code}` is not `TYPE NAME`", n + 1));
        };
        if name.contains('=') || tokens.next().is_some_and(|t| t.starts_with('=')) {
            continue; // a constant: not on the wire
        }
        let field = (normalise_type(ty), name.to_owned());
        match &current {
            Some(t) => types.entry(t.clone()).or_default().push(field),
            None => main.push(field),
        }
    }
    Ok((main, types))
}

/// The primitive fields a definition puts on the wire, in order, as `type path`.
fn flatten(
    fields: &[Field],
    types: &HashMap<String, Vec<Field>>,
    prefix: &str,
    out: &mut Vec<String>,
    depth: usize,
) -> Result<(), String> {
    if depth > 8 {
        return Err("types nest deeper than 8 levels".into());
    }
    for (ty, name) in fields {
        let base = ty.split('[').next().unwrap_or(ty);
        let is_primitive = PRIMITIVES.contains(&base)
            || base.starts_with("string<=")
            || base.starts_with("wstring<=");
        if is_primitive || ty.contains('[') {
            out.push(format!("{ty} {prefix}{name}"));
            continue;
        }
        let inner = types.get(base).ok_or_else(|| {
            format!("field `{prefix}{name}` has type {base}, which the schema text does not define")
        })?;
        flatten(inner, types, &format!("{prefix}{name}."), out, depth + 1)?;
    }
    Ok(())
}

fn wire_fields(text: &str) -> Result<Vec<String>, String> {
    let (main, types) = parse_definition(text)?;
    let mut out = Vec::new();
    flatten(&main, &types, "", &mut out, 0)?;
    Ok(out)
}

/// Why a topic's channel is not `expected` (schema name and standard definition), or `None`.
fn check_channel(channel: &ChannelInfo, expected: (&str, &str)) -> Option<String> {
    let (name, definition) = expected;
    let found = channel.schema.as_deref().unwrap_or("no schema");
    let encoding = channel.schema_encoding.as_deref().unwrap_or("none");
    let standard = name.replace("/msg/", "/");
    if channel.schema.as_deref() != Some(name) && channel.schema.as_deref() != Some(&standard) {
        return Some(format!(
            "schema `{found}` ({encoding}, {} messages), expected {name}; name the right topic with the option",
            channel.message_encoding
        ));
    }
    if encoding != "ros2msg" || channel.message_encoding != "cdr" {
        let hint = if encoding.starts_with("ros1") || channel.message_encoding == "ros1" {
            " (a ROS 1 bag: convert it to ROS 2 first, e.g. with `rosbags-convert`)"
        } else {
            ""
        };
        return Some(format!(
            "schema encoding `{encoding}` with `{}` messages, but only ROS 2's `ros2msg` with `cdr` is read{hint}",
            channel.message_encoding
        ));
    }
    let text = String::from_utf8_lossy(&channel.schema_data);
    let standard_fields = wire_fields(definition).unwrap_or_default();
    let found_fields = match wire_fields(&text) {
        Ok(f) => f,
        Err(e) => {
            return Some(format!(
                "schema `{found}`: its definition cannot be read: {e}"
            ))
        }
    };
    if found_fields == standard_fields {
        return None;
    }
    let k = found_fields
        .iter()
        .zip(&standard_fields)
        .position(|(a, b)| a != b)
        .unwrap_or(found_fields.len().min(standard_fields.len()));
    Some(format!(
        "schema `{found}`: its definition is not the standard one: wire field #{k} is {}, the standard {name} has {} (a custom message under a standard name is not read)",
        found_fields
            .get(k)
            .map_or("missing".to_owned(), |f| format!("`{f}`")),
        standard_fields
            .get(k)
            .map_or("no more fields".to_owned(), |f| format!("`{f}`"))
    ))
}

/// `header.stamp` in ns (and the frame id, which is not kept).
fn header(d: &mut Decoder<'_>) -> Result<i64, DecodeError> {
    let sec = d.i32()?;
    let nanosec = d.u32()?;
    if nanosec >= 1_000_000_000 {
        return Err(format!("header.stamp.nanosec {nanosec} is not below 10⁹"));
    }
    d.string()?;
    Ok(i64::from(sec) * 1_000_000_000 + i64::from(nanosec))
}

/// Decodes a `sensor_msgs/msg/Imu`: its `header.stamp` (ns) and `angular_velocity` (rad/s).
pub fn decode_imu(data: &[u8]) -> Result<(i64, [f64; 3]), DecodeError> {
    let mut d = Decoder::new_ros2(data)?;
    let stamp = header(&mut d)?;
    for _ in 0..(4 + 9) {
        d.f64()?;
    }
    let w = [d.f64()?, d.f64()?, d.f64()?];
    for _ in 0..(9 + 3 + 9) {
        d.f64()?;
    }
    Ok((stamp, w))
}

/// Decodes a `sensor_msgs/msg/Temperature`: its `header.stamp` (ns) and `temperature` (°C).
pub fn decode_temperature(data: &[u8]) -> Result<(i64, f64), DecodeError> {
    let mut d = Decoder::new_ros2(data)?;
    let stamp = header(&mut d)?;
    let celsius = d.f64()?;
    d.f64()?;
    Ok((stamp, celsius))
}

struct TopicReader {
    topic: String,
    expected: (&'static str, &'static str),
    /// The schema text last accepted (a bag may repeat a channel per file).
    accepted: Option<(Option<String>, Vec<u8>)>,
    count: usize,
    last_ns: Option<i64>,
}

impl TopicReader {
    fn new(topic: &str, expected: (&'static str, &'static str)) -> Self {
        Self {
            topic: topic.to_owned(),
            expected,
            accepted: None,
            count: 0,
            last_ns: None,
        }
    }

    /// Checks the channel (once per schema text) and the message's time; returns its index.
    fn next(
        &mut self,
        path: &Path,
        channel: &ChannelInfo,
        t_ns: i64,
        clock: BagClock,
    ) -> Result<usize, BagError> {
        let index = self.count;
        let same = self
            .accepted
            .as_ref()
            .is_some_and(|(name, data)| *name == channel.schema && *data == channel.schema_data);
        if !same {
            if let Some(reason) = check_channel(channel, self.expected) {
                return Err(BagError::Topic {
                    path: path.to_path_buf(),
                    topic: self.topic.clone(),
                    reason,
                });
            }
            self.accepted = Some((channel.schema.clone(), channel.schema_data.clone()));
        }
        if let Some(last) = self.last_ns.filter(|&last| t_ns <= last) {
            let (what, fix) = match clock {
                BagClock::Header => (
                    "header.stamp",
                    "import with `--timestamps log` to use the recorder's receive times",
                ),
                BagClock::Log => (
                    "log time",
                    "the recorder wrote messages out of order; import with `--timestamps header`",
                ),
            };
            return Err(BagError::Message {
                path: path.to_path_buf(),
                topic: self.topic.clone(),
                index,
                reason: format!(
                    "{what} {t_ns} ns is not after the previous message's ({last} ns): the times must increase; {fix}"
                ),
            });
        }
        self.last_ns = Some(t_ns);
        self.count += 1;
        Ok(index)
    }
}

/// Reads one bag (`files`: its MCAP files in order, from [`bag_files`]; `bag` names it): the gyro
/// and temperature topics' messages, timed by `clock`. Errors name the file, the topic and the
/// message's index within its topic; a missing or empty topic is named with the bag's topics.
pub fn read_bag(
    bag: &Path,
    files: &[PathBuf],
    topics: &BagTopics,
    clock: BagClock,
) -> Result<Bag, BagError> {
    let mut gyro_reader = TopicReader::new(&topics.gyro, (IMU_SCHEMA, IMU_DEFINITION));
    let mut temperature_reader = TopicReader::new(
        &topics.temperature,
        (TEMPERATURE_SCHEMA, TEMPERATURE_DEFINITION),
    );
    let mut gyro = Vec::new();
    let mut temperature = Vec::new();
    let mut all_topics = BTreeMap::new();
    for file in files {
        let buf = std::fs::read(file).map_err(|source| BagError::Io {
            path: file.clone(),
            source,
        })?;
        let mcap_error = |reason: String| BagError::Mcap {
            path: file.clone(),
            reason,
        };
        if !buf.starts_with(mcap::MAGIC) {
            return Err(mcap_error(
                "not an MCAP file (only rosbag2's MCAP storage is read; convert a .db3 bag with `ros2 bag convert`)".into(),
            ));
        }
        if !buf.ends_with(mcap::MAGIC) {
            return Err(mcap_error(format!(
                "truncated: the file ends at byte {} without its closing magic (an interrupted recording or copy); `ros2 bag reindex` or `mcap recover` may rescue it",
                buf.len()
            )));
        }
        crate::messages::check_uncompressed_chunks(&buf).map_err(|e| mcap_error(e.to_string()))?;
        crate::messages::for_each_message(&buf, |channel, log_ns, data| {
            let topic = channel.topic.as_str();
            let is_gyro = topic == topics.gyro;
            let is_temperature = topic == topics.temperature;
            if !all_topics.contains_key(topic) {
                all_topics.insert(
                    topic.to_owned(),
                    channel.schema.clone().unwrap_or_else(|| "no schema".into()),
                );
            }
            if !is_gyro && !is_temperature {
                return Ok(());
            }
            let decoded = if is_gyro {
                decode_imu(data).map(|(stamp, w)| (stamp, Some(w), 0.0))
            } else {
                decode_temperature(data).map(|(stamp, c)| (stamp, None, c))
            };
            let reader = if is_gyro {
                &mut gyro_reader
            } else {
                &mut temperature_reader
            };
            let message_error = |index: usize, reason: String| BagError::Message {
                path: file.clone(),
                topic: topic.to_owned(),
                index,
                reason,
            };
            // The schema first: a message of another type would decode to nonsense.
            let (stamp, w, celsius) = match decoded {
                Ok(d) => d,
                Err(reason) => {
                    if let Some(reason) = check_channel(channel, reader.expected) {
                        return Err(BagError::Topic {
                            path: file.clone(),
                            topic: topic.to_owned(),
                            reason,
                        });
                    }
                    return Err(message_error(reader.count, reason));
                }
            };
            let t_ns = match clock {
                BagClock::Header => stamp,
                BagClock::Log => i64::try_from(log_ns).map_err(|_| {
                    message_error(
                        reader.count,
                        format!("log time {log_ns} ns is beyond the i64 clock"),
                    )
                })?,
            };
            let index = reader.next(file, channel, t_ns, clock)?;
            match w {
                Some(w) => {
                    if let Some(axis) = w.iter().position(|v| !v.is_finite()) {
                        return Err(message_error(
                            index,
                            format!("angular_velocity.{} is {}", ["x", "y", "z"][axis], w[axis]),
                        ));
                    }
                    gyro.push((t_ns, w));
                }
                None => temperature.push((t_ns, celsius)),
            }
            Ok(())
        })
        .map_err(|e| match e {
            Ok(mcap) => mcap_error(mcap.to_string()),
            Err(e) => e,
        })?;
    }
    let listing = || {
        if all_topics.is_empty() {
            "the bag has no messages".to_owned()
        } else {
            format!(
                "the bag's topics: {}",
                all_topics
                    .iter()
                    .map(|(t, s)| format!("{t} ({s})"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    };
    for (topic, empty, option) in [
        (&topics.gyro, gyro.is_empty(), "--gyro-topic"),
        (
            &topics.temperature,
            temperature.is_empty(),
            "--temperature-topic",
        ),
    ] {
        if empty {
            return Err(BagError::Topic {
                path: bag.to_path_buf(),
                topic: topic.clone(),
                reason: format!(
                    "no messages; {}; name the right one with `{option}`",
                    listing()
                ),
            });
        }
    }
    Ok(Bag {
        path: bag.to_path_buf(),
        topics: topics.clone(),
        gyro,
        temperature,
        all_topics,
    })
}

/// Topics of an exported bag.
#[derive(Debug, Clone)]
pub struct ExportTopics {
    /// `sensor_msgs/msg/Imu`, one message per sample.
    pub imu: String,
    /// `sensor_msgs/msg/Temperature` of the X axis's sensor; the Y and Z axes' go to `<this>/y`
    /// and `<this>/z`.
    pub temperature: String,
}

impl ExportTopics {
    /// The temperature topic of each axis.
    pub fn temperature_axes(&self) -> [String; 3] {
        [
            self.temperature.clone(),
            format!("{}/y", self.temperature),
            format!("{}/z", self.temperature),
        ]
    }
}

/// Writes `segments` (one unit's activations) as a ROS 2 bag file (rosbag2's MCAP storage,
/// profile `ros2`): per sample one `sensor_msgs/msg/Imu` on `topics.imu` (`angular_velocity` in
/// rad/s; no orientation or acceleration estimate: element 0 of their covariances is −1) and one
/// `sensor_msgs/msg/Temperature` per axis (°C, NaN for a missing reading), with `header.stamp` =
/// log time = the sample's time on the recording clock and `header.frame_id` = `frame_id`.
/// Written through a temporary file renamed at the end; returns the bytes written.
pub fn write_ros2_bag(
    path: &Path,
    segments: &[&Segment],
    frame_id: &str,
    topics: &ExportTopics,
) -> Result<u64, WriteError> {
    let invalid = |reason: String| WriteError::Invalid {
        path: path.to_path_buf(),
        reason,
    };
    let mut f = McapFile::create(path, PROFILE_ROS2, mcap::Compression::Zstd)?;
    f.add_topic(&topics.imu, (IMU_SCHEMA, IMU_DEFINITION), &[])?;
    let temperature_topics = topics.temperature_axes();
    for topic in &temperature_topics {
        f.add_topic(topic, (TEMPERATURE_SCHEMA, TEMPERATURE_DEFINITION), &[])?;
    }
    for (k, segment) in segments.iter().enumerate() {
        let fs = u64::from(segment.sample_rate_hz.max(1));
        let period_ns = 1_000_000_000 / fs;
        let fits = (segment.len() as u64)
            .checked_mul(period_ns)
            .and_then(|d| segment.power_on_ns.checked_add(d))
            .is_some_and(|end| end / 1_000_000_000 <= i32::MAX as u64);
        if !fits {
            return Err(invalid(format!(
                "activation {k} ends beyond a ROS time stamp's range (int32 seconds)"
            )));
        }
        for i in 0..segment.len() {
            let t = segment.power_on_ns + i as u64 * period_ns;
            let (sec, nanosec) = ((t / 1_000_000_000) as i32, (t % 1_000_000_000) as u32);
            let w = |axis: usize| f64::from(segment.rate_dps[axis][i]).to_radians();
            let e = f.enc.begin();
            e.i32(sec).u32(nanosec).string(frame_id);
            e.f64(0.0).f64(0.0).f64(0.0).f64(1.0);
            e.f64(-1.0);
            for _ in 1..9 {
                e.f64(0.0);
            }
            e.f64(w(0)).f64(w(1)).f64(w(2));
            for _ in 0..9 {
                e.f64(0.0);
            }
            e.f64(0.0).f64(0.0).f64(0.0);
            e.f64(-1.0);
            for _ in 1..9 {
                e.f64(0.0);
            }
            f.write_encoded(&topics.imu, t)?;
            for (axis, topic) in temperature_topics.iter().enumerate() {
                let celsius = f64::from(temperature_reading(segment.temperature_raw[axis][i]))
                    / RAW_PER_CELSIUS;
                f.enc
                    .begin()
                    .i32(sec)
                    .u32(nanosec)
                    .string(frame_id)
                    .f64(celsius)
                    .f64(0.0);
                f.write_encoded(topic, t)?;
            }
        }
    }
    f.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standard_definitions_flatten_to_their_wire_fields() {
        let imu = wire_fields(IMU_DEFINITION).unwrap();
        assert_eq!(
            imu.len(),
            3 + 4 + 1 + 3 + 1 + 3 + 1,
            "arrays are one wire field each"
        );
        assert_eq!(imu[0], "int32 header.stamp.sec");
        assert_eq!(imu[2], "string header.frame_id");
        assert_eq!(imu[7], "float64[9] orientation_covariance");
        assert_eq!(imu[8], "float64 angular_velocity.x");
        let t = wire_fields(TEMPERATURE_DEFINITION).unwrap();
        assert_eq!(t[3..], ["float64 temperature", "float64 variance"]);
        // The long type names, `Header` without its package, constants and comments change nothing.
        let other = "Header header # c\nint8 KIND=3\nfloat64 temperature 0.0\nfloat64 variance\n\
=====\nMSG: std_msgs/msg/Header\nbuiltin_interfaces/msg/Time stamp\nstring frame_id\n\
=====\nMSG: builtin_interfaces/msg/Time\nint32 sec\nuint32 nanosec\n";
        assert_eq!(wire_fields(other).unwrap(), t);
        let missing = "std_msgs/Header header\nfloat64 temperature\nfloat64 variance\n";
        assert!(wire_fields(missing)
            .unwrap_err()
            .contains("std_msgs/Header"));
    }

    #[test]
    fn imu_and_temperature_messages_decode() {
        let mut e = crate::cdr::Encoder::default();
        e.begin().i32(12).u32(500).string("imu").f64(21.5).f64(0.0);
        assert_eq!(
            decode_temperature(e.bytes()).unwrap(),
            (12_000_000_500, 21.5)
        );
        assert!(decode_temperature(&e.bytes()[..20]).is_err());
        let mut be = e.bytes().to_vec();
        be[1] = 0;
        assert!(decode_temperature(&be).unwrap_err().contains("big-endian"));
    }
}
