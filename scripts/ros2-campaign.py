#!/usr/bin/env python3
"""A bench campaign as a ROS 2 robot records it, written by the independent `rosbags` library.

One rosbag2 bag (MCAP storage) per activation with `sensor_msgs/msg/Imu` (rad/s) on /imu/data and
`sensor_msgs/msg/Temperature` (°C) on /imu/temperature, plus the activation sheet that labels them
for `gyrodrift import campaign`. The signal is known: after each switch-on the die warms by
`RISE_C` · (1 − e^(−t/τ)) above where the off-time let it cool to, and every axis reads

    rate = bias(T_on) + SLOPE_DPS_PER_C · (T − T_on) + white noise,

so the fitted drift against the rise since switch-on must have the slope `SLOPE_DPS_PER_C`.

Default: 2 set points × 3 off-times × 5 activations of 2 min at 100 Hz = 30 bags. Usage:

    python3 scripts/ros2-campaign.py OUT [--seconds 120] [--rate-hz 100] [--distro jazzy|humble]
        [--compression none|message|file] [--set-points 30,40] [--seed 7]
"""

from __future__ import annotations

import argparse
import math
import random
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
from rosbags.typesys import Stores, get_typestore

SET_POINTS_C = (30.0, 40.0)
OFF_TIMES_MIN = (1.0, 5.0, 20.0)
ACTIVATIONS = 5
SLOPE_DPS_PER_C = 0.02
RISE_C = 4.0
WARM_TAU_S = 40.0
COOL_TAU_S = 300.0
NOISE_DPS = 0.01
NOISE_C = 0.01
FRAME = "imu_link"
# Header stamps as a driver writes them: Unix time in ns.
EPOCH_NS = 1_700_000_000_000_000_000


def bias_dps(axis: int, switch_on_c: float) -> float:
    """The turn-on bias: a per-axis offset that moves with the switch-on temperature."""
    return (0.3, -0.2, 0.1)[axis] + 0.004 * (switch_on_c - 30.0)


def write_bag(path: Path, args: argparse.Namespace, typestore, start_ns: int, ambient: float,
              residual: float, rng: random.Random) -> None:
    Imu = typestore.types["sensor_msgs/msg/Imu"]
    Temperature = typestore.types["sensor_msgs/msg/Temperature"]
    Header = typestore.types["std_msgs/msg/Header"]
    Time = typestore.types["builtin_interfaces/msg/Time"]
    Vector3 = typestore.types["geometry_msgs/msg/Vector3"]
    Quaternion = typestore.types["geometry_msgs/msg/Quaternion"]
    import numpy as np

    writer = Writer(path, version=9 if args.distro == "jazzy" else 8, storage_plugin=StoragePlugin.MCAP)
    if args.compression != "none":
        writer.set_compression(CompressionMode[args.compression.upper()], CompressionFormat.ZSTD)
    with writer:
        imu = writer.add_connection("/imu/data", Imu.__msgtype__, typestore=typestore)
        temp = writer.add_connection("/imu/temperature", Temperature.__msgtype__, typestore=typestore)
        switch_on = ambient + residual
        period_ns = 1_000_000_000 // args.rate_hz
        unknown = np.array([-1.0] + [0.0] * 8)
        for i in range(int(args.seconds * args.rate_hz)):
            t = i * period_ns
            celsius = switch_on + (ambient + RISE_C - switch_on) * (1 - math.exp(-t * 1e-9 / WARM_TAU_S))
            stamp_ns = start_ns + t
            header = Header(stamp=Time(sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000),
                            frame_id=FRAME)
            w = [math.radians(bias_dps(a, switch_on) + SLOPE_DPS_PER_C * (celsius - switch_on)
                              + rng.gauss(0.0, NOISE_DPS)) for a in range(3)]
            msg = Imu(header=header, orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                      orientation_covariance=unknown,
                      angular_velocity=Vector3(x=w[0], y=w[1], z=w[2]),
                      angular_velocity_covariance=np.zeros(9),
                      linear_acceleration=Vector3(x=0.0, y=0.0, z=9.81),
                      linear_acceleration_covariance=np.zeros(9))
            # The recorder receives each message a little after its stamp.
            writer.write(imu, stamp_ns + 2_000_000, typestore.serialize_cdr(msg, Imu.__msgtype__))
            if i % (args.rate_hz // 10) == 0:
                reading = Temperature(header=header, temperature=celsius + rng.gauss(0.0, NOISE_C),
                                      variance=NOISE_C**2)
                writer.write(temp, stamp_ns + 2_000_000,
                             typestore.serialize_cdr(reading, Temperature.__msgtype__))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--seconds", type=float, default=120.0, help="activation length, s")
    parser.add_argument("--rate-hz", type=int, default=100)
    parser.add_argument("--distro", choices=("jazzy", "humble"), default="jazzy")
    parser.add_argument("--compression", choices=("none", "message", "file"), default="none")
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--set-points", type=lambda t: [float(v) for v in t.split(",")],
                        default=list(SET_POINTS_C), help="chamber set points, °C (default 30,40)")
    args = parser.parse_args()
    typestore = get_typestore(Stores.ROS2_JAZZY if args.distro == "jazzy" else Stores.ROS2_HUMBLE)
    rng = random.Random(args.seed)
    args.out.mkdir(parents=True)
    rows = ["file,unit,set_point_celsius,series,repeat,activation,off_before_s,series_kind,switch_on_s,interval_min"]
    clock_s = 0.0
    for ambient in args.set_points:
        for series, off_min in enumerate(OFF_TIMES_MIN, start=1):
            temperature_above = RISE_C * 0.0  # a cold start: the unit sat at the ambient
            for activation in range(1, ACTIVATIONS + 1):
                name = f"sp{ambient:+.0f}_off{off_min:g}min_{activation}"
                off = "" if activation == 1 else f"{off_min * 60:g}"
                if activation > 1:
                    clock_s += off_min * 60
                write_bag(args.out / name, args, typestore,
                          EPOCH_NS + int(round(clock_s * 1e9)), ambient, temperature_above, rng)
                rows.append(f"{name},ROBOT-1,{ambient:g},{series},1,{activation},{off},protocol,"
                            f"{clock_s:.3f},{off_min:g}")
                # The die after the activation: warmed towards ambient + RISE_C, then cooling.
                warm = temperature_above + (RISE_C - temperature_above) * (
                    1 - math.exp(-args.seconds / WARM_TAU_S))
                temperature_above = warm * math.exp(-off_min * 60 / COOL_TAU_S)
                clock_s += args.seconds
            clock_s += 3600.0
    (args.out / "sheet.csv").write_text("\n".join(rows) + "\n")
    print(f"{len(rows) - 1} bags and sheet.csv → {args.out}")


if __name__ == "__main__":
    main()
