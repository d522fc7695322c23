//! The recording side of gyrodrift's data flow: recording → **segments** → fitted tables →
//! corrector → residual → report.
//!
//! The format (specified in `docs/recording-format.md`): MCAP files with CDR-encoded (`ros2msg`)
//! batches of samples, one topic per signal (and one per named auxiliary channel, `/aux/<name>`),
//! zstd chunks. [`read_recording`] validates while it reads and yields [`Segment`]s, one per
//! activation, with their protocol labels; it refuses simulator ground truth, so code that reads
//! through it cannot see the truth.
//! [`write_recording`] writes the same format from a real test bench's data, and [`read_csv`] reads
//! measured data from CSV into the same segments; [`read_sheet_campaign`] reads a bench campaign
//! kept as one CSV file per activation plus an activation sheet. [`ros2`] reads ROS 2 bags
//! (`sensor_msgs/msg/Imu`, `sensor_msgs/msg/Temperature`) and writes recordings as ROS 2 bags.

pub mod atomic;
mod aux;
mod block_means;
pub mod cdr;
mod csv_aux;
mod csv_file;
mod error;
mod layout;
mod messages;
pub mod output_folder;
pub mod paper;
mod progress;
mod read;
pub mod ros2;
pub mod schema;
mod segment;
mod sheet;
mod sheet_units;
pub mod ulog;
mod writable;
mod write;
pub mod writer;

pub use atomic::{write_atomic, write_atomic_creating_folder};
pub use aux::{check_named_aux_channel, fixed_aux_unit, named_aux_topic, FIXED_AUX_CHANNELS};
pub use block_means::block_means;
pub use csv_aux::CsvAuxColumn;
pub use csv_file::{
    read_csv, read_csv_bytes, CsvColumns, CsvError, CsvOptions, CsvTiming, RateUnit, TimeUnit,
    MAX_PLAUSIBLE_RATE_DPS,
};
pub use error::{ReadError, WriteError};
pub use layout::{AUX_RATE_HZ, COMPLETION_MARKER, RECORDINGS_DIR, TRUTH_DIR, TRUTH_EXTENSION};
pub use messages::RECORD_LENGTH_LIMIT;
pub use progress::{Interrupted, Progress, Within, QUIET};
pub use read::{
    is_truth_path, read_campaign_dir, read_metadata, read_recording, read_recording_bytes,
    read_recording_with, OpenRecording, Recording, READING, REQUIRED_TOPICS,
};
pub use segment::{
    temperature_reading, AuxChannel, Segment, SegmentLabels, SeriesKind, TemperatureScale,
    RAW_PER_CELSIUS, SCALE_KEY, TEMPERATURE_MISSING_RAW, ZERO_KEY,
};
pub use sheet::{
    read_sheet, read_sheet_campaign, read_sheet_campaign_with, recording_stem, LogReader,
    SheetError, SheetRow, SHEET_COLUMNS,
};
pub use write::{create_recording, write_recording};
