//! The standard messages' names and definition texts, as rosbag2 stores them in a bag's schemas.

/// Schema name of the standard IMU message.
pub const IMU_SCHEMA: &str = "sensor_msgs/msg/Imu";
/// Schema name of the standard temperature message.
pub const TEMPERATURE_SCHEMA: &str = "sensor_msgs/msg/Temperature";
/// The ROS 2 type description hash (REP-2011, `RIHS01`) of `sensor_msgs/msg/Imu`, as ROS 2 Jazzy
/// and `rosbags` give it.
pub const IMU_TYPE_HASH: &str =
    "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b";
/// The type description hash of `sensor_msgs/msg/Temperature`.
pub const TEMPERATURE_TYPE_HASH: &str =
    "RIHS01_72514a14126ab9f8a9abec974c78e5610a367b59db5da355ff1fb982d5bad4b8";
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
