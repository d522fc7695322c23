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

mod decode;
mod definitions;
mod labels;
mod msgdef;
mod read;
mod write;

pub use decode::{decode_imu, decode_temperature, ImuMessage};
pub use definitions::{
    IMU_DEFINITION, IMU_SCHEMA, IMU_TYPE_HASH, PROFILE_ROS2, TEMPERATURE_DEFINITION,
    TEMPERATURE_SCHEMA, TEMPERATURE_TYPE_HASH,
};
pub use labels::{read_labels, ExportedActivation, ExportedLabels, LABELS_RECORD};
pub use read::{bag_files, read_bag, Bag, BagClock, BagError, BagRows, BagTopics};
pub use write::{write_ros2_bag, write_ros2_bag_folder, ExportSource, ExportTopics, WrittenBag};
