"""Recordings from Python: load what the simulator wrote, build from arrays, write, read back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gyrodrift
from conftest import SMALL_CAMPAIGN, make_segment, recording_path


def test_load_a_simulated_recording(campaign_dir: Path) -> None:
    recording = gyrodrift.Recording.load(recording_path(campaign_dir))
    protocol = SMALL_CAMPAIGN["protocol"]
    assert recording.unit_id == "GIU-01"
    assert recording.sample_rate_hz == 1000
    assert recording.path == recording_path(campaign_dir)
    assert recording.metadata["set_point_celsius"] == "30"
    assert len(recording) == len(protocol["intervals_min"]) * protocol["activations"] * protocol["repeats"]
    segment = recording.segments[0]
    n = int(protocol["activation_s"] * 1000)
    assert len(segment) == n
    assert segment.labels.series_kind == "protocol" and segment.labels.activation == 1
    assert segment.rate_dps.shape == (n, 3) and segment.rate_dps.dtype == np.float32
    assert segment.temperature_raw.shape == (n, 3) and segment.temperature_raw.dtype == np.int16
    assert np.array_equal(segment.since_power_on, np.arange(n, dtype=np.uint32))
    assert segment.since_power_on_ms[-1] == n - 1
    assert sorted(segment.aux) == ["accel_x", "accel_y", "accel_z", "chamber_set_point", "supply_voltage"]
    accel = segment.aux_channel("accel_z")
    assert accel.unit == "g" and accel.sample_rate_hz == 100 and len(accel) == n // 10


def test_segment_arrays_are_kept_and_read_only(campaign_dir: Path) -> None:
    segment = gyrodrift.Recording.load(recording_path(campaign_dir)).segments[0]
    assert segment.rate_dps is segment.rate_dps  # made once
    with pytest.raises(ValueError, match="read-only"):
        segment.rate_dps[0, 0] = 1.0


def test_load_campaign_reads_every_recording(campaign_dir: Path) -> None:
    recordings = gyrodrift.load_campaign(campaign_dir)
    names = [r.path.name for r in recordings if r.path is not None]
    assert names == sorted(p.name for p in (campaign_dir / "recordings").glob("*.mcap"))
    assert {r.metadata["set_point_celsius"] for r in recordings} == {"30", "33", "40"}


def test_read_metadata_without_decoding(campaign_dir: Path) -> None:
    metadata = gyrodrift.Recording.read_metadata(recording_path(campaign_dir, "+40.0"))
    assert metadata["unit_id"] == "GIU-01" and metadata["series_kind"] == "protocol"


def test_build_write_and_read_back(tmp_path: Path) -> None:
    first, second = make_segment(), make_segment(2345, power_on_ns=10**10, activation=2)
    recording = gyrodrift.Recording([first, second], metadata={"campaign": "bench 7"})
    assert recording.unit_id == "PY-1" and recording.path is None
    written = recording.save(tmp_path / "bench.mcap")
    assert written == (tmp_path / "bench.mcap").stat().st_size
    assert [p.name for p in tmp_path.iterdir()] == ["bench.mcap"]  # no temporary left behind

    back = gyrodrift.Recording.load(tmp_path / "bench.mcap")
    assert back.metadata["campaign"] == "bench 7" and back.metadata["series_kind"] == "protocol"
    for built, read in zip([first, second], back.segments):
        assert read.labels == built.labels
        assert read.power_on_ns == built.power_on_ns
        assert np.array_equal(read.rate_dps, built.rate_dps)
        assert np.array_equal(read.temperature_raw, built.temperature_raw)
        assert np.array_equal(read.aux["supply_voltage"].values, built.aux["supply_voltage"].values)


def test_named_channels_round_trip_through_mcap(tmp_path: Path) -> None:
    """Any valid name is written to its own /aux/<name> topic and read back with its unit, in the
    segments that have it; the format's own channels are unchanged beside them."""
    n = 2500
    m = n // 10
    rng = np.random.default_rng(7)
    named = {
        "humidity": (rng.normal(40.0, 2.0, m), "%RH"),
        "v3.3": (rng.normal(3.3, 0.01, m).astype(np.float32), "V"),
        "Board-Temp_2": (rng.normal(31.0, 0.5, m), "degC"),
        "0": (np.zeros(m), ""),
    }
    first = make_segment(n)
    base = {
        name: (channel.values, channel.unit, channel.sample_rate_hz) for name, channel in first.aux.items()
    }
    aux = {**base, **{name: (values, unit, 100) for name, (values, unit) in named.items()}}
    with_named = gyrodrift.Segment(first.labels, first.rate_dps, first.temperature_raw, aux=aux)
    second = make_segment(1000, power_on_ns=10**10, activation=2)  # the format's channels only
    gyrodrift.Recording([with_named, second]).save(tmp_path / "named.mcap")

    back = gyrodrift.Recording.load(tmp_path / "named.mcap")
    read = back.segments[0].aux
    assert sorted(read) == sorted([*base, *named])
    for name, (values, unit) in named.items():
        channel = read[name]
        assert channel.unit == unit and channel.sample_rate_hz == 100
        assert np.array_equal(channel.values, np.asarray(values, dtype=np.float32)), name
    for name in base:
        assert (
            np.array_equal(read[name].values, first.aux[name].values)
            and read[name].unit == first.aux[name].unit
        )
    assert sorted(back.segments[1].aux) == sorted(base)


def test_a_loaded_recording_writes_back_unchanged(campaign_dir: Path, tmp_path: Path) -> None:
    original = gyrodrift.Recording.load(recording_path(campaign_dir, "+33.0"))
    original.save(tmp_path / "copy.mcap")
    copy = gyrodrift.Recording.load(tmp_path / "copy.mcap")
    assert copy.metadata == original.metadata
    for a, b in zip(original.segments, copy.segments):
        assert a.labels == b.labels and a.power_on_ns == b.power_on_ns
        assert np.array_equal(a.rate_dps, b.rate_dps) and np.array_equal(a.temperature_raw, b.temperature_raw)


def test_float64_rates_are_rounded_to_float32() -> None:
    rate = np.full((1000, 3), 0.1, dtype=np.float64)
    labels = gyrodrift.Labels(unit_id="U", set_point_celsius=30.0)
    segment = gyrodrift.Segment(labels, rate, np.zeros((1000, 3), dtype=np.int16))
    assert np.array_equal(segment.rate_dps, rate.astype(np.float32))


def test_in_memory_segments_feed_the_corrector(campaign_dir: Path) -> None:
    segment = gyrodrift.Recording.load(recording_path(campaign_dir, "+33.0")).segments[0]
    model = gyrodrift.fit(campaign_dir)[0].modified
    corrector = gyrodrift.Corrector(model)
    corrector.power_on(segment.temperature_raw[:20].mean(axis=0))
    corrected, _, flags = corrector.correct_batch(
        segment.since_power_on_ms, segment.rate_dps, segment.temperature_raw.astype(np.float32)
    )
    assert corrected.shape == segment.rate_dps.shape
    assert not (flags & gyrodrift.Flags.faults().value).any()
    # The segment's own int16 temperatures go in as they are, with the same result.
    corrector.power_on(segment.temperature_raw[:20].mean(axis=0))
    from_int16, _, _ = corrector.correct_batch(
        segment.since_power_on_ms, segment.rate_dps, segment.temperature_raw
    )
    assert np.array_equal(from_int16, corrected)


def test_an_auxiliary_channel_may_be_any_numpy_view() -> None:
    """A column of a 2-D table or a strided slice is copied, not refused as non-contiguous."""
    table = np.random.default_rng(3).normal(3.3, 0.01, (200, 4))
    column = table[:, 1]
    assert not column.flags.c_contiguous
    labels = gyrodrift.Labels(unit_id="U", set_point_celsius=30.0)
    segment = gyrodrift.Segment(
        labels,
        np.zeros((2000, 3), dtype=np.float32),
        np.zeros((2000, 3), dtype=np.int16),
        aux={"supply": (column, "V", 100), "every_other": (table[::-1, 0], "V", 100)},
    )
    assert np.array_equal(segment.aux["supply"].values, column.astype(np.float32))
    assert np.array_equal(segment.aux["every_other"].values, table[::-1, 0].astype(np.float32))


def test_ramped_field_labels_give_the_sessions_nominal_set_point(tmp_path: Path) -> None:
    campaign = {
        "name": "py-ramped",
        "seed": 5,
        "units": 1,
        "set_points_celsius": [33.0],
        "field": {
            "sessions": 1,
            "activations": 6,
            "activation_s": [1.0, 2.0],
            "off_min": [0.5, 1.0],
            "ambient_ramp_c_per_min": 6.0,
            "carry_probability": 0.5,
            "rest_min": 1.0,
        },
    }
    gyrodrift.simulate(tmp_path, campaign)
    (recording,) = gyrodrift.load_campaign(tmp_path)
    labels = [s.labels for s in recording.segments]
    assert len(labels) == 6 and all(lab.series_kind == "field" for lab in labels)
    assert all(lab.nominal_set_point_celsius == 33.0 for lab in labels)
    # The ambient at switch-on ramps away from the set point (it starts there).
    assert any(lab.set_point_celsius != 33.0 for lab in labels)
    # Labels made in Python have no session set point: the switch-on one is the nominal one.
    assert gyrodrift.Labels(unit_id="U", set_point_celsius=31.5).nominal_set_point_celsius == 31.5
    with pytest.raises(AttributeError):
        labels[0].nominal_set_point_celsius = 30.0  # type: ignore[misc]
    # A recording built from them keeps the session's set point: the labels read back equal.
    gyrodrift.Recording(recording.segments).save(tmp_path / "copy.mcap")
    copy = gyrodrift.Recording.load(tmp_path / "copy.mcap")
    assert copy.metadata["set_point_celsius"] == "33"
    assert [s.labels for s in copy.segments] == labels
