"""A ROS 2 robot's bags to the paper's tables with no CSV step, the bags written by the independent
`rosbags` library (scripts/ros2-campaign.py): 2 set points × 3 off-times × 5 activations at 100 Hz
(20 s each here; the full-size 2-min campaign is measured in docs/measured.md), labelled by an
activation sheet, go `import campaign` → `fit` → `report`, and the fitted drift has the slope the
bags were written with. What `export ros2` writes opens in `rosbags`' AnyReader, and a bag whose
messages rosbag2 compressed is refused with the word "compressed". Needs the CLI binary:
GYRODRIFT_BIN (scripts/check-python.sh sets it).
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
SCRIPT = ROOT / "scripts" / "ros2-campaign.py"


def binary() -> str:
    path = os.environ.get("GYRODRIFT_BIN")
    if not path:
        pytest.skip("GYRODRIFT_BIN not set (scripts/check-python.sh builds and sets it)")
    return path


def run(*args: str) -> str:
    done = subprocess.run(args, capture_output=True, text=True)
    assert done.returncode == 0, f"{args}: {done.stdout}{done.stderr}"
    return done.stdout


def known_slope() -> float:
    spec = importlib.util.spec_from_file_location("ros2_campaign", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return float(module.SLOPE_DPS_PER_C)


def test_bags_written_by_rosbags_import_fit_and_report_with_the_known_slope(tmp_path: Path) -> None:
    gyrodrift = binary()
    bags, check = tmp_path / "bags", tmp_path / "check-bags"
    run(sys.executable, str(SCRIPT), str(bags), "--seconds", "20")
    run(
        sys.executable,
        str(SCRIPT),
        str(check),
        "--seconds",
        "20",
        "--set-points",
        "33",
        "--seed",
        "8",
        "--distro",
        "humble",
    )
    assert len([p for p in bags.iterdir() if p.is_dir()]) == 30
    campaign, validation = tmp_path / "campaign", tmp_path / "validation"
    run(gyrodrift, "import", "campaign", str(bags / "sheet.csv"), "-o", str(campaign), "--rate-hz", "100")
    run(gyrodrift, "import", "campaign", str(check / "sheet.csv"), "-o", str(validation), "--rate-hz", "100")
    tables = tmp_path / "tables"
    run(gyrodrift, "fit", str(campaign), "-q", "-o", str(tables))
    report = tmp_path / "report"
    run(
        gyrodrift,
        "report",
        "-q",
        "--calibration-data",
        str(campaign),
        "--evaluation-data",
        str(validation),
        "-o",
        str(report),
    )
    assert (report / "report.json").is_file()
    # The relative baseline's drift p(T), a polynomial on [−1, 1] over its range: its mean slope.
    relative = json.loads((tables / "ROBOT-1" / "relative.json").read_text())
    want = known_slope()
    for axis in relative["axes"]:
        low, high = axis["drift"]["range_celsius"]
        coefficients = axis["drift"]["coefficients"]
        rise = sum(c * (1 - (-1) ** k) for k, c in enumerate(coefficients))
        slope = rise / (high - low)
        assert abs(slope - want) <= 0.02 * want, (slope, want)


def test_an_export_opens_in_rosbags_and_a_compressed_bag_is_refused_by_name(tmp_path: Path) -> None:
    from rosbags.highlevel import AnyReader

    gyrodrift = binary()
    bags = tmp_path / "bags"
    run(sys.executable, str(SCRIPT), str(bags), "--seconds", "3", "--set-points", "30")
    campaign = tmp_path / "campaign"
    run(gyrodrift, "import", "campaign", str(bags / "sheet.csv"), "-o", str(campaign), "--rate-hz", "100")
    exported = tmp_path / "exported"
    run(
        gyrodrift,
        "export",
        "ros2",
        str(campaign / "recordings" / "ROBOT-1_sp+30.0C_protocol.mcap"),
        "-o",
        str(exported),
    )
    manifest = json.loads((campaign / "import.json").read_text())
    samples = [a["samples"] for a in manifest["recordings"][0]["activations"]]
    assert len(samples) == 15
    for k, n in enumerate(samples, start=1):
        with AnyReader([exported / f"activation-{k:03}"]) as reader:
            hashes = {c.topic: c.digest for c in reader.connections}
            assert hashes["/imu/data"].startswith("RIHS01_"), hashes
            count = 0
            for connection, _, raw in reader.messages():
                message = reader.deserialize(raw, connection.msgtype)
                assert message.header.frame_id == "ROBOT-1"
                count += 1
            assert count == 4 * n, (k, count, n)
    squeezed = tmp_path / "squeezed"
    run(
        sys.executable,
        str(SCRIPT),
        str(squeezed),
        "--seconds",
        "1",
        "--set-points",
        "30",
        "--compression",
        "message",
    )
    done = subprocess.run(
        [gyrodrift, "import", "rosbag", str(squeezed / "sp+30_off1min_1"), "-o", str(tmp_path / "refused")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2, done.stderr
    assert "compressed" in done.stderr and "topic /imu/data, message #0" in done.stderr, done.stderr
