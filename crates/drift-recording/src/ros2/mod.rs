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
mod msgdef;
mod read;
mod write;

pub use decode::{decode_imu, decode_temperature};
pub use read::{bag_files, read_bag, Bag, BagClock, BagError, BagRows, BagTopics};
pub use write::{write_ros2_bag, ExportTopics};

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
