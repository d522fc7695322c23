"""The Python `mcap` package reads what `gyrodrift simulate` writes.

Run by scripts/check-python.sh (its fresh venv gets `mcap mcap-ros2-support pytest`):

    GYRODRIFT_BIN=target/release/gyrodrift .venv-check/bin/python -m pytest crates/drift-sim/tests/python

Without GYRODRIFT_BIN the test runs `cargo run -q -p gyrodrift --` itself.
"""

import os
import struct
import subprocess
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

ROOT = Path(__file__).resolve().parents[4]

CAMPAIGN = """
name = "python-read-test"
seed = 7
units = 1
set_points_celsius = [30.0]

[protocol]
intervals_min = [1.0]
activations = 2
activation_s = 2.0
repeats = 1

[field]
sessions = 1
activations = 2
activation_s = [1.0, 2.0]
"""


@pytest.fixture(scope="module")
def out_dir(tmp_path_factory):
    work = tmp_path_factory.mktemp("sim")
    campaign = work / "campaign.toml"
    campaign.write_text(CAMPAIGN)
    binary = os.environ.get("GYRODRIFT_BIN")
    command = [binary] if binary else ["cargo", "run", "-q", "-p", "gyrodrift", "--"]
    out = work / "out"
    subprocess.run(
        [*command, "simulate", "--campaign", str(campaign), "--out", str(out), "--quiet"],
        check=True,
        cwd=ROOT,
    )
    return out


def recording(out_dir, kind):
    (path,) = sorted((out_dir / "recordings").glob(f"*_{kind}.mcap"))
    return path


def decode_vector3_batch(data: bytes):
    """CDR little endian by hand: header, uint32 first_sample, uint32 rate, 3 × float32[]."""
    assert data[:4] == b"\x00\x01\x00\x00"
    first, rate = struct.unpack_from("<II", data, 4)
    offset, axes = 12, []
    for _ in range(3):
        (n,) = struct.unpack_from("<I", data, offset)
        axes.append(struct.unpack_from(f"<{n}f", data, offset + 4))
        offset += 4 + 4 * n
    return first, rate, axes


def test_header_schemas_and_zstd_chunks(out_dir):
    with open(recording(out_dir, "protocol"), "rb") as f:
        reader = make_reader(f)
        assert reader.get_header().profile == "gyrodrift"
        summary = reader.get_summary()
        topics = {c.topic: c for c in summary.channels.values()}
        for topic in [
            "/gyro/rate",
            "/gyro/temperature_raw",
            "/aux/accel",
            "/aux/supply_voltage",
            "/aux/chamber_set_point",
            "/power/state",
        ]:
            channel = topics[topic]
            assert channel.message_encoding == "cdr"
            assert summary.schemas[channel.schema_id].encoding == "ros2msg"
        assert summary.chunk_indexes and all(c.compression == "zstd" for c in summary.chunk_indexes)
        (meta,) = [m for m in reader.iter_metadata() if m.name == "gyrodrift.recording"]
        assert meta.metadata["unit_id"] == "GIU-01"
        assert meta.metadata["temperature_raw_per_celsius"] == "200"


def test_decoded_messages_match_the_documented_layout(out_dir):
    with open(recording(out_dir, "protocol"), "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        events, rate_samples, temperatures = [], 0, []
        for _schema, channel, message, decoded in reader.iter_decoded_messages():
            if channel.topic == "/power/state":
                events.append((decoded.powered, decoded.series_kind, decoded.activation, decoded.interval_min))
            elif channel.topic == "/gyro/rate":
                first, rate, axes = decode_vector3_batch(message.data)
                assert (first, rate) == (decoded.first_sample, decoded.sample_rate_hz) and rate == 1000
                assert list(axes[2]) == pytest.approx(list(decoded.z), rel=0, abs=0)
                assert all(abs(v) < 1.0 for axis in axes for v in axis)
                rate_samples += len(decoded.x)
            elif channel.topic == "/gyro/temperature_raw":
                temperatures.extend(decoded.x)
        assert events == [
            (True, "protocol", 1, 1.0),
            (False, "protocol", 1, 1.0),
            (True, "protocol", 2, 1.0),
            (False, "protocol", 2, 1.0),
        ]
        assert rate_samples == 2 * 2000
        # 200 raw units per degree C, chamber at +30 degrees C, a few degrees of self-heating at most.
        assert all(27 * 200 < t < 40 * 200 for t in temperatures)


def test_field_sessions_and_truth_sidecar(out_dir):
    with open(recording(out_dir, "field"), "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        kinds = {d.series_kind for _s, c, _m, d in reader.iter_decoded_messages(topics=["/power/state"])}
        assert kinds == {"field"}
    (truth,) = sorted((out_dir / "truth").glob("*_protocol.truth.mcap"))
    with open(truth, "rb") as f:
        reader = make_reader(f)
        assert reader.get_header().profile == "gyrodrift-truth"
        assert "/truth/systematic_bias" in {c.topic for c in reader.get_summary().channels.values()}
