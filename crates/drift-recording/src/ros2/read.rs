//! Reading one bag's gyro and temperature topics, and pairing them into rows.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::decode::{decode_imu, decode_temperature, ImuMessage};
use super::definitions::{IMU_DEFINITION, IMU_SCHEMA, TEMPERATURE_DEFINITION, TEMPERATURE_SCHEMA};
use super::labels::{read_labels, ExportedLabels};
use super::msgdef::check_channel;
use crate::messages::ChannelInfo;

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
    /// Accept a temperature whose `header.frame_id` is not the gyro's.
    pub any_temperature_frame: bool,
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
    /// The Y and Z axes' own temperatures (`<temperature topic>/y`, `/z`), when the bag has both.
    pub temperature_yz: Option<[Vec<(i64, f64)>; 2]>,
    /// Every topic of the bag with its schema name, for messages and listings.
    pub all_topics: BTreeMap<String, String>,
    /// The labels `export ros2` wrote into the bag's first file, if it did.
    pub labels: Option<ExportedLabels>,
}

/// Rows of one bag ([`Bag::rows`]): what the CSV reader resamples.
#[derive(Debug, Clone)]
pub struct BagRows {
    /// CSV text with the header `t_s,gx,gy,gz,temp_c,temp_y,temp_z`: time since `start_ns` (s),
    /// angular velocity (rad/s), temperature (°C; the Y and Z axes' own where the bag has them,
    /// else the same as `temp_c`); one row per gyro message.
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
    /// The messages with times in `from_ns..to_ns` (one activation of an exported bag).
    pub fn between(&self, from_ns: i64, to_ns: i64) -> Bag {
        let keep = |s: &[(i64, f64)]| -> Vec<(i64, f64)> {
            s.iter()
                .copied()
                .filter(|m| (from_ns..to_ns).contains(&m.0))
                .collect()
        };
        Bag {
            path: self.path.clone(),
            topics: self.topics.clone(),
            gyro: self
                .gyro
                .iter()
                .copied()
                .filter(|m| (from_ns..to_ns).contains(&m.0))
                .collect(),
            temperature: keep(&self.temperature),
            temperature_yz: self
                .temperature_yz
                .as_ref()
                .map(|[y, z]| [keep(y), keep(z)]),
            all_topics: self.all_topics.clone(),
            labels: None,
        }
    }

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
        let mut csv = String::with_capacity(kept.len() * 96 + 32);
        csv.push_str("t_s,gx,gy,gz,temp_c,temp_y,temp_z\n");
        let series: Vec<&[(i64, f64)]> = match &self.temperature_yz {
            Some([y, z]) => vec![&self.temperature, y, z],
            None => vec![&self.temperature],
        };
        let mut at = vec![0usize; series.len()];
        for (t, w) in kept.iter().map(|g| (g.0, g.1)) {
            let c: Vec<f64> = series
                .iter()
                .zip(&mut at)
                .map(|(s, j)| interpolate(s, t, j))
                .collect();
            let (y, z) = if c.len() == 3 {
                (c[1], c[2])
            } else {
                (c[0], c[0])
            };
            // Time from the first row in ns, exact in f64 up to 104 days.
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{y},{z}",
                (t - start_ns) as f64 * 1e-9,
                w[0],
                w[1],
                w[2],
                c[0]
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

/// The value of `series` (time-ordered) at `t`, linear between its neighbours and held beyond its
/// ends; `j` is where the previous call stopped (times asked for increase).
fn interpolate(series: &[(i64, f64)], t: i64, j: &mut usize) -> f64 {
    while *j + 2 < series.len() && series[*j + 1].0 <= t {
        *j += 1;
    }
    let Some(&(ta, a)) = series.get(*j) else {
        return f64::NAN;
    };
    let (tb, b) = series.get(*j + 1).copied().unwrap_or((ta, a));
    if tb > ta && t > ta {
        let f = ((t - ta) as f64 / (tb - ta) as f64).clamp(0.0, 1.0);
        if f >= 1.0 {
            b
        } else {
            a + (b - a) * f
        }
    } else {
        a
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
        .filter(|p| {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy())
                .unwrap_or_default();
            name.ends_with(".mcap") || name.ends_with(".mcap.zstd")
        })
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

/// `t_ns` as seconds with every digit: two times that differ print differently.
fn seconds(t_ns: i64) -> String {
    let sign = if t_ns < 0 { "-" } else { "" };
    let t = t_ns.unsigned_abs();
    format!("{sign}{}.{:09} s", t / 1_000_000_000, t % 1_000_000_000)
}

struct TopicReader {
    topic: String,
    expected: (&'static str, &'static str),
    /// The schema text last accepted (a bag may repeat a channel per file).
    accepted: Option<(Option<String>, Vec<u8>)>,
    count: usize,
    last_ns: Option<i64>,
    /// The other clock's last time, and whether it has increased so far.
    other: (Option<i64>, bool),
    /// The first message's `header.frame_id` and the frame of every message after it.
    frame: Option<String>,
    /// The first message whose time does not increase. Its error waits for the rest of the topic:
    /// whether the fix is the other clock depends on that clock increasing over all of it.
    backstep: Option<Backstep>,
}

/// Where a topic's time first fails to increase.
struct Backstep {
    path: PathBuf,
    index: usize,
    t_ns: i64,
    last_ns: i64,
}

impl TopicReader {
    fn new(topic: &str, expected: (&'static str, &'static str)) -> Self {
        Self {
            topic: topic.to_owned(),
            expected,
            accepted: None,
            count: 0,
            last_ns: None,
            other: (None, true),
            frame: None,
            backstep: None,
        }
    }

    /// Checks the channel (once per schema text) and the message's frame, and notes whether its
    /// time on the import's clock (`t_ns`; the other clock's time is `other_ns`) increases (see
    /// [`Self::backstep_error`]); returns its index.
    fn next(
        &mut self,
        path: &Path,
        channel: &ChannelInfo,
        (t_ns, other_ns): (i64, i64),
        frame: &str,
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
        let message_error = |reason: String| BagError::Message {
            path: path.to_path_buf(),
            topic: self.topic.clone(),
            index,
            reason,
        };
        match &self.frame {
            None => self.frame = Some(frame.to_owned()),
            Some(first) if first != frame => {
                return Err(message_error(format!(
                    "header.frame_id `{frame}` differs from the topic's first message's `{first}`: two sensors publish on this topic, and their messages would be merged into one signal; record each sensor on its own topic (or filter one frame out with `ros2 bag convert`/`mcap filter`) and import that topic"
                )));
            }
            Some(_) => {}
        }
        let other_increasing = self.other.1 && self.other.0.is_none_or(|last| other_ns > last);
        self.other = (Some(other_ns), other_increasing);
        if let Some(last_ns) = self
            .last_ns
            .filter(|&last| t_ns <= last && self.backstep.is_none())
        {
            self.backstep = Some(Backstep {
                path: path.to_path_buf(),
                index,
                t_ns,
                last_ns,
            });
        }
        self.last_ns = Some(t_ns);
        self.count += 1;
        Ok(index)
    }

    /// The error of the topic's first time that does not increase, if any, with the fix the other
    /// clock allows over the topic read so far (all of it unless reading stopped early).
    fn backstep_error(&self, clock: BagClock) -> Option<BagError> {
        let Backstep {
            path,
            index,
            t_ns,
            last_ns,
        } = self.backstep.as_ref()?;
        let other_increasing = self.other.1;
        let (what, fix) = match clock {
            BagClock::Header if *t_ns < last_ns - 1_000_000_000 && other_increasing => (
                "header.stamp",
                "the driver's clock went back (it restarts at boot, or was set): import with `--timestamps log` to use the recorder's receive times, which increase here",
            ),
            BagClock::Header if other_increasing => (
                "header.stamp",
                "import with `--timestamps log` to use the recorder's receive times, which increase here",
            ),
            BagClock::Log if other_increasing => (
                "log time",
                "the recorder wrote messages out of order; import with `--timestamps header`, whose stamps increase here",
            ),
            _ => (
                if clock == BagClock::Header { "header.stamp" } else { "log time" },
                "neither the header stamps nor the recorder's log times increase here: the topic mixes messages of different sources or the bag was merged out of order; split or reorder it (e.g. `ros2 bag convert`) before importing",
            ),
        };
        Some(BagError::Message {
            path: path.clone(),
            topic: self.topic.clone(),
            index: *index,
            reason: format!(
                "{what} {} is not after the previous message's ({}): the times must increase; {fix}",
                seconds(*t_ns),
                seconds(*last_ns)
            ),
        })
    }
}

/// What one message of a read topic holds.
enum Decoded {
    Gyro(ImuMessage),
    /// Axis (0 = the temperature topic, 1 and 2 its `/y` and `/z`), stamp, frame, °C.
    Temperature(usize, i64, String, f64),
}

/// Reads one bag (`files`: its MCAP files in order, from [`bag_files`]; `bag` names it): the gyro
/// and temperature topics' messages, timed by `clock`, with the temperature topic's `/y` and `/z`
/// (per-axis sensors, as `export ros2` writes them) where the bag has them. Errors name the file,
/// the topic and the message's index within its topic; a missing or empty topic is named with the
/// bag's topics. Refused: rates the message says it does not provide
/// (`angular_velocity_covariance[0] = −1`, REP-145), two `header.frame_id`s on one topic, and a
/// temperature of another frame than the gyro's unless `topics.any_temperature_frame`.
pub fn read_bag(
    bag: &Path,
    files: &[PathBuf],
    topics: &BagTopics,
    clock: BagClock,
) -> Result<Bag, BagError> {
    let mut gyro_reader = TopicReader::new(&topics.gyro, (IMU_SCHEMA, IMU_DEFINITION));
    let axis_topics = [
        topics.temperature.clone(),
        format!("{}/y", topics.temperature),
        format!("{}/z", topics.temperature),
    ];
    let mut temperature_readers = axis_topics
        .clone()
        .map(|t| TopicReader::new(&t, (TEMPERATURE_SCHEMA, TEMPERATURE_DEFINITION)));
    let mut gyro = Vec::new();
    let mut temperatures: [Vec<(i64, f64)>; 3] = Default::default();
    let mut all_topics = BTreeMap::new();
    let mut labels = None;
    // The topic whose time first failed to increase: its error comes first, once the rest of the
    // bag has told whether the other clock increases.
    let mut first_backstep: Option<String> = None;
    let read = (|| -> Result<(), BagError> {
        for (n, file) in files.iter().enumerate() {
            let buf = std::fs::read(file).map_err(|source| BagError::Io {
                path: file.clone(),
                source,
            })?;
            let mcap_error = |reason: String| BagError::Mcap {
                path: file.clone(),
                reason,
            };
            if buf.starts_with(&[0x28, 0xb5, 0x2f, 0xfd]) {
                return Err(mcap_error(
                    "a zstd-compressed file (rosbag2's file compression): decompress it first (`zstd -d`, or `ros2 bag decompress`), then import the .mcap file".into(),
                ));
            }
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
            crate::messages::check_uncompressed_chunks(&buf)
                .map_err(|e| mcap_error(e.to_string()))?;
            if n == 0 {
                labels = read_labels(file, &buf).map_err(mcap_error)?;
            }
            crate::messages::for_each_message(&buf, |channel, log_ns, data, _| {
                let topic = channel.topic.as_str();
                if !all_topics.contains_key(topic) {
                    all_topics.insert(
                        topic.to_owned(),
                        channel.schema.clone().unwrap_or_else(|| "no schema".into()),
                    );
                }
                let is_gyro = topic == topics.gyro;
                let axis = axis_topics.iter().position(|t| t == topic);
                if !is_gyro && axis.is_none() {
                    return Ok(());
                }
                let reader = match axis {
                    Some(a) if !is_gyro => &mut temperature_readers[a],
                    _ => &mut gyro_reader,
                };
                let decoded = if is_gyro {
                    decode_imu(data).map(Decoded::Gyro)
                } else {
                    decode_temperature(data)
                        .map(|(s, f, c)| Decoded::Temperature(axis.unwrap_or(0), s, f, c))
                };
                let message_error = |index: usize, reason: String| BagError::Message {
                    path: file.clone(),
                    topic: topic.to_owned(),
                    index,
                    reason,
                };
                // The schema first: a message of another type would decode to nonsense.
                let decoded = match decoded {
                    Ok(d) => d,
                    Err(reason) => {
                        if data.starts_with(&[0x28, 0xb5, 0x2f, 0xfd]) {
                            return Err(message_error(
                                reader.count,
                                "a zstd-compressed message (rosbag2's message compression): decompress the bag first (`ros2 bag decompress`, or `ros2 bag convert` without compression)".into(),
                            ));
                        }
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
                let (stamp, frame) = match &decoded {
                    Decoded::Gyro(m) => (m.stamp_ns, m.frame_id.as_str()),
                    Decoded::Temperature(_, s, f, _) => (*s, f.as_str()),
                };
                let log_ns = i64::try_from(log_ns).map_err(|_| {
                    message_error(
                        reader.count,
                        format!("log time {log_ns} ns is beyond the i64 clock"),
                    )
                })?;
                let times = match clock {
                    BagClock::Header => (stamp, log_ns),
                    BagClock::Log => (log_ns, stamp),
                };
                let index = reader.next(file, channel, times, frame)?;
                if reader.backstep.is_some() && first_backstep.is_none() {
                    first_backstep = Some(topic.to_owned());
                }
                match decoded {
                    Decoded::Gyro(m) => {
                        if m.rate_covariance_0 == -1.0 {
                            return Err(message_error(
                                index,
                                "angular_velocity_covariance[0] is −1: the driver says this message carries no angular velocity (REP-145); publish the gyro's rates, or name the topic that has them with `--gyro-topic`".into(),
                            ));
                        }
                        if let Some(axis) = m.rate.iter().position(|v| !v.is_finite()) {
                            return Err(message_error(
                                index,
                                format!(
                                    "angular_velocity.{} is {}",
                                    ["x", "y", "z"][axis],
                                    m.rate[axis]
                                ),
                            ));
                        }
                        gyro.push((times.0, m.rate));
                    }
                    Decoded::Temperature(a, _, _, celsius) => temperatures[a].push((times.0, celsius)),
                }
                Ok(())
            })
            .map_err(|e| match e {
                Ok(mcap) => mcap_error(mcap.to_string()),
                Err(e) => e,
            })?;
        }
        Ok(())
    })();
    let readers = || std::iter::once(&gyro_reader).chain(&temperature_readers);
    if let Some(error) = first_backstep
        .as_ref()
        .and_then(|topic| readers().find(|r| r.topic == *topic))
        .and_then(|r| r.backstep_error(clock))
    {
        return Err(error);
    }
    read?;
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
            temperatures[0].is_empty(),
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
    if let (Some(g), Some(t)) = (&gyro_reader.frame, &temperature_readers[0].frame) {
        if g != t && !topics.any_temperature_frame {
            return Err(BagError::Topic {
                path: bag.to_path_buf(),
                topic: topics.temperature.clone(),
                reason: format!(
                    "header.frame_id `{t}` is not the gyro's (`{g}` on {}): this temperature may be another sensor's; name the gyro's own temperature topic with `--temperature-topic`, or accept this one with `--any-temperature-frame`",
                    topics.gyro
                ),
            });
        }
    }
    let [x, y, z] = temperatures;
    let per_axis = if y.is_empty() || z.is_empty() {
        None
    } else {
        Some([y, z])
    };
    Ok(Bag {
        path: bag.to_path_buf(),
        topics: topics.clone(),
        gyro,
        temperature: x,
        temperature_yz: per_axis,
        all_topics,
        labels,
    })
}
