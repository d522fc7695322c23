"""ROS 2 in and out, checked with ROS 2's own Python reader and writer (`mcap-ros2-support`).

`gyrodrift export ros2` writes one `sensor_msgs/msg/Imu` per sample, so ROS tools plot every sample:
ROS 2's decoder (`mcap_ros2.decoder.DecoderFactory`, what the deprecated
`mcap_ros2.reader.read_ros2_messages` wraps) reads as many messages as the recording has samples,
with our values and times. `gyrodrift import rosbag` reads a bag written by `mcap_ros2.writer.Writer` with the
standard message definitions. Needs the CLI binary: GYRODRIFT_BIN (scripts/check-python.sh sets it).
"""

from __future__ import annotations

import math
import os
import subprocess
from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from mcap_ros2.writer import Writer

CAMPAIGN = """
seed = 11
units = 1
sample_rate_hz = 100
set_points_celsius = [30.0]

[protocol]
intervals_min = [1.0]
activations = 2
activation_s = 3.0
repeats = 1
"""

# The standard definitions' fields in rosbag2's layout: the message, then each type it uses.
SEPARATOR = "=" * 80
HEADER = f"""{SEPARATOR}
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
{SEPARATOR}
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""
IMU = f"""std_msgs/Header header
geometry_msgs/Quaternion orientation
float64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance
geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance
{HEADER}{SEPARATOR}
MSG: geometry_msgs/Quaternion
float64 x 0
float64 y 0
float64 z 0
float64 w 1
{SEPARATOR}
MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z
"""
TEMPERATURE = f"""std_msgs/Header header
float64 temperature
float64 variance
{HEADER}"""


def binary() -> str:
    path = os.environ.get("GYRODRIFT_BIN")
    if not path:
        pytest.skip("GYRODRIFT_BIN not set (scripts/check-python.sh builds and sets it)")
    return path


def gyrodrift(*args: str) -> str:
    done = subprocess.run([binary(), *args], check=True, capture_output=True, text=True)
    return done.stdout


def our_samples(recording: Path) -> tuple[list[int], list[list[float]], list[list[float]]]:
    """Per sample of a gyrodrift recording, decoded with mcap-ros2-support (its schemas are ros2msg):
    time (ns on the recording clock), rate X, Y, Z (°/s) and temperature X, Y, Z (°C)."""
    times: list[int] = []
    rates: list[list[float]] = [[], [], []]
    celsius: list[list[float]] = [[], [], []]
    with recording.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, decoded in reader.iter_decoded_messages(
            topics=["/gyro/rate", "/gyro/temperature_raw"]
        ):
            period = 1_000_000_000 // decoded.sample_rate_hz
            axes = [decoded.x, decoded.y, decoded.z]
            if channel.topic == "/gyro/rate":
                times.extend(message.log_time + j * period for j in range(len(decoded.x)))
                for axis in range(3):
                    rates[axis].extend(float(v) for v in axes[axis])
            else:
                for axis in range(3):
                    celsius[axis].extend(v / 200.0 for v in axes[axis])
    return times, rates, celsius


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    work = tmp_path_factory.mktemp("ros2")
    (work / "campaign.toml").write_text(CAMPAIGN)
    gyrodrift("simulate", "--campaign", str(work / "campaign.toml"), "--out", str(work / "sim"), "--quiet")
    (path,) = sorted((work / "sim" / "recordings").glob("*_protocol.mcap"))
    return path


def test_export_writes_one_imu_message_per_sample_with_our_values(recording: Path, tmp_path: Path) -> None:
    bag = tmp_path / "bag.mcap"
    gyrodrift("export", "ros2", str(recording), "-o", str(bag))
    times, rates, celsius = our_samples(recording)
    assert len(times) == 600  # two activations of 3 s at 100 Hz
    by_topic: dict[str, list[Any]] = defaultdict(list)
    with bag.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            by_topic[channel.topic].append((schema, message, decoded))
    assert sorted(by_topic) == ["/imu/data", "/imu/temperature", "/imu/temperature/y", "/imu/temperature/z"]
    imu = by_topic["/imu/data"]
    assert len(imu) == len(times)
    for i, (schema, message, decoded) in enumerate(imu):
        assert schema.name == "sensor_msgs/msg/Imu"
        stamp = decoded.header.stamp
        assert stamp.sec * 1_000_000_000 + stamp.nanosec == message.log_time == times[i]
        w = decoded.angular_velocity
        for axis, value in enumerate([w.x, w.y, w.z]):
            # rad/s in f64 of our f32 °/s: back to degrees within f64 rounding.
            assert math.degrees(value) == pytest.approx(rates[axis][i], rel=1e-12, abs=1e-15)
        assert decoded.orientation_covariance[0] == -1.0
        assert decoded.linear_acceleration_covariance[0] == -1.0
    for axis, topic in enumerate(["/imu/temperature", "/imu/temperature/y", "/imu/temperature/z"]):
        messages = by_topic[topic]
        assert len(messages) == len(times)
        assert [decoded.temperature for _, _, decoded in messages] == celsius[axis]
        assert [message.log_time for _, message, _ in messages] == times


def test_a_bag_written_by_ros2s_writer_imports(tmp_path: Path) -> None:
    bag = tmp_path / "bench.mcap"
    start = 1_700_000_000 * 1_000_000_000
    rate_hz, seconds = 200, 2
    period = 1_000_000_000 // rate_hz
    sent = []
    with bag.open("wb") as f:
        writer = Writer(f)
        imu = writer.register_msgdef("sensor_msgs/msg/Imu", IMU)
        temperature = writer.register_msgdef("sensor_msgs/msg/Temperature", TEMPERATURE)
        for i in range(rate_hz * seconds + 1):
            t = start + i * period
            stamp = {"sec": t // 1_000_000_000, "nanosec": t % 1_000_000_000}
            w = [0.01 * math.sin(i / 7.0), -0.002 * i / rate_hz, 0.5]
            sent.append(w)
            writer.write_message(
                "/sensors/gyro",
                imu,
                {
                    "header": {"stamp": stamp, "frame_id": "imu_link"},
                    "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
                    "orientation_covariance": [-1.0] + [0.0] * 8,
                    "angular_velocity": {"x": w[0], "y": w[1], "z": w[2]},
                    "angular_velocity_covariance": [0.0] * 9,
                    "linear_acceleration": {"x": 0.0, "y": 0.0, "z": 9.81},
                    "linear_acceleration_covariance": [0.0] * 9,
                },
                log_time=t + 2_000_000,
                publish_time=t + 2_000_000,
                sequence=i,
            )
            if i % 20 == 0:  # 10 Hz, a ramp of 0.5 °C/s from 25 °C
                writer.write_message(
                    "/sensors/temperature",
                    temperature,
                    {
                        "header": {"stamp": stamp, "frame_id": "imu_link"},
                        "temperature": 25.0 + 0.5 * i / rate_hz,
                        "variance": 0.0,
                    },
                    log_time=t + 2_000_000,
                    publish_time=t + 2_000_000,
                    sequence=i,
                )
        writer.finish()
    out = tmp_path / "campaign"
    text = gyrodrift(
        "import",
        "rosbag",
        str(bag),
        "-o",
        str(out),
        "--gyro-topic",
        "/sensors/gyro",
        "--temperature-topic",
        "/sensors/temperature",
        "--rate-hz",
        str(rate_hz),
        "--unit-id",
        "bench",
    )
    assert "bench.mcap: 1 activations, 401 samples at 200 Hz" in text
    times, rates, celsius = our_samples(out / "recordings" / "bench.mcap")
    assert len(times) == len(sent)
    assert times[0] == 0 and times[-1] == seconds * 1_000_000_000
    for i, w in enumerate(sent):
        for axis in range(3):
            # °/s as f32 of the rad/s sent.
            assert rates[axis][i] == pytest.approx(math.degrees(w[axis]), rel=1e-6, abs=1e-9)
            # The ramp interpolated at each sample, to the raw step (1/200 °C).
            assert celsius[axis][i] == pytest.approx(25.0 + 0.5 * i / rate_hz, abs=0.0051)
