//! Reading one bag's gyro and temperature topics, and pairing them into rows.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::decode::{decode_imu, decode_temperature};
use super::definitions::{IMU_DEFINITION, IMU_SCHEMA, TEMPERATURE_DEFINITION, TEMPERATURE_SCHEMA};
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
