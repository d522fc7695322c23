"""Errors of recordings, simulation, fitting and evaluation: a gyrodrift exception whose message
says which argument (or file, topic, message) and what was expected; never a PanicException."""

from __future__ import annotations

import errno
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gyrodrift
from conftest import format_aux, make_segment, recording_path
from gyrodrift import CampaignError, FileError, FitError, GyrodriftError, InputError, RecordingError

N = 1000
LABELS = gyrodrift.Labels(unit_id="U", set_point_celsius=30.0)
RATE = np.zeros((N, 3), dtype=np.float32)
RAW = np.zeros((N, 3), dtype=np.int16)


def test_hierarchy() -> None:
    for error in (RecordingError, CampaignError, FitError):
        assert issubclass(error, GyrodriftError) and error.__module__ == "gyrodrift"
    assert issubclass(CampaignError, ValueError)


# --- building segments -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            {"rate_dps": np.zeros((N, 3), dtype=np.int64)},
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got int64 array of shape (1000, 3)",
        ),
        (
            {"rate_dps": np.zeros((N, 2), dtype=np.float32)},
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got float32 array of shape (1000, 2)",
        ),
        (
            {"rate_dps": np.zeros((0, 3), dtype=np.float32)},
            "`rate_dps` must not be empty, got float32 array of shape (0, 3)",
        ),
        (
            {"rate_dps": np.where(np.arange(N)[:, None] == 7, np.nan, RATE).astype(np.float32)},
            "`rate_dps` must be finite (the recording format stores no NaN or inf), got a non-finite value at row 7, axis X",
        ),
        (
            {"temperature_raw": np.zeros((N, 3), dtype=np.float32)},
            "`temperature_raw` must be an int16 array of shape (n, 3), got float32 array of shape (1000, 3) (temperatures in °C? convert with np.round(settings.raw(celsius)).astype(np.int16); .astype(np.int16) would truncate °C to whole degrees)",
        ),
        (
            {"temperature_raw": np.zeros((N - 1, 3), dtype=np.int16)},
            "`temperature_raw` must have one row per row of `rate_dps` (1000), got 999 rows",
        ),
        ({"labels": {"unit_id": "U"}}, "`labels` must be a gyrodrift.Labels, got dict"),
        (
            {"sample_rate_hz": 999},
            "`sample_rate_hz` must be a multiple of 100 Hz that divides 10**9 (e.g. 1000), got 999",
        ),
        ({"power_on_ns": -1}, "`power_on_ns` must be an integer ≥ 0 (ns), got -1"),
        (
            {"aux": [1, 2]},
            "`aux` must be a dict of channel name → AuxChannel or (values, unit, sample_rate_hz), got list",
        ),
        (
            {"aux": {"gps": np.zeros(3)}},
            '`aux["gps"]` must be a gyrodrift.AuxChannel or a (values, unit, sample_rate_hz) tuple, got float64 array of shape (3,)',
        ),
        (
            {"aux": {"supply_voltage": (np.array([5.0, np.nan]), "V", 100)}},
            'aux["supply_voltage"]: `values` must be finite, got NaN at index 1',
        ),
    ],
)
def test_segment_arguments(arguments: dict[str, Any], message: str) -> None:
    values: dict[str, Any] = {"labels": LABELS, "rate_dps": RATE, "temperature_raw": RAW, **arguments}
    positional = [values.pop(k) for k in ("labels", "rate_dps", "temperature_raw")]
    with pytest.raises(InputError) as raised:
        gyrodrift.Segment(*positional, **values)
    assert str(raised.value) == message


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"repeat": 0}, "`repeat` must be an integer in 1..=4294967295, got 0"),
        ({"activation": "2"}, "`activation` must be an integer in 1..=4294967295, got '2'"),
        ({"series_kind": "bench"}, '`series_kind` must be "protocol" or "field", got \'bench\''),
        ({"set_point_celsius": float("nan")}, "`set_point_celsius` must be a finite float, got NaN"),
        ({"unit_id": ""}, "`unit_id` must be a non-empty str, got ''"),
        ({"interval_min": -1.0}, "`interval_min` must be a finite float ≥ 0 or None, got -1"),
    ],
)
def test_label_arguments(arguments: dict[str, Any], message: str) -> None:
    values: dict[str, Any] = {"unit_id": "U", "set_point_celsius": 30.0, **arguments}
    with pytest.raises(InputError) as raised:
        gyrodrift.Labels(**values)
    assert str(raised.value) == message


def test_unknown_channel() -> None:
    segment = make_segment()
    with pytest.raises(InputError) as raised:
        segment.aux_channel("gps")
    assert str(raised.value) == (
        'unknown channel "gps": this segment has accel_x, accel_y, accel_z, chamber_set_point, supply_voltage'
    )
    with pytest.raises(InputError, match='unknown channel "gps": this segment has no auxiliary channels'):
        make_segment(aux=False).aux_channel("gps")


# --- recordings ------------------------------------------------------------------------------


def test_recording_of_mixed_units_or_overlapping_segments() -> None:
    with pytest.raises(InputError, match='segments\\[1\\] is of unit "B", the recording\'s is "PY-1"'):
        gyrodrift.Recording([make_segment(), make_segment(power_on_ns=10**10, unit_id="B")])
    with pytest.raises(
        InputError, match="segments\\[1\\] switches on at 2000000000 ns, not after segments\\[0\\]"
    ):
        gyrodrift.Recording([make_segment(2500), make_segment(power_on_ns=2 * 10**9)])
    with pytest.raises(InputError, match="`unit_id` must be given when `segments` is empty"):
        gyrodrift.Recording([])


def test_saving_channels_the_format_does_not_store(tmp_path: Path) -> None:
    aux: dict[str, Any] = {**format_aux(N), "gps": (np.zeros(5), "deg", 1)}
    segment = gyrodrift.Segment(LABELS, RATE, RAW, aux=aux)
    with pytest.raises(
        InputError, match=r'channel "gps" must hold 100 values at 100 Hz .* got 5 values at 1 Hz'
    ):
        gyrodrift.Recording([segment]).save(tmp_path / "r.mcap")
    for name, reason in [
        ("gps/fix", "auxiliary channel `gps/fix` has `/` at byte 3"),
        ("", "an empty auxiliary channel name"),
        ("accel", "auxiliary channel `accel` would be recorded on /aux/accel, the accelerometer's topic"),
    ]:
        named = gyrodrift.Segment(LABELS, RATE, RAW, aux={**format_aux(N), name: (np.zeros(100), "deg", 100)})
        with pytest.raises(InputError, match=f"segments\\[0\\]: {re.escape(reason)}"):
            gyrodrift.Recording([named]).save(tmp_path / "r.mcap")
    relabelled = gyrodrift.Segment(
        LABELS, RATE, RAW, aux={**format_aux(N), "supply_voltage": (np.ones(100), "mV", 100)}
    )
    with pytest.raises(
        InputError, match='channel "supply_voltage" is in "mV", the recording format stores it in "V"'
    ):
        gyrodrift.Recording([relabelled]).save(tmp_path / "r.mcap")
    first, second = (
        gyrodrift.Segment(
            LABELS, RATE, RAW, power_on_ns=on, aux={**format_aux(N), "rh": (np.ones(100), unit, 100)}
        )
        for on, unit in [(0, "%RH"), (10**10, "ppm")]
    )
    with pytest.raises(
        InputError, match='segments\\[1\\]: channel "rh" is in "ppm", segments\\[0\\] has it in "%RH"'
    ):
        gyrodrift.Recording([first, second]).save(tmp_path / "r.mcap")
    bare = gyrodrift.Segment(LABELS, RATE, RAW)
    with pytest.raises(InputError, match='segments\\[0\\]: channel "accel_x" is missing'):
        gyrodrift.Recording([bare]).save(tmp_path / "r.mcap")
    short = gyrodrift.Segment(LABELS, RATE, RAW, aux={**format_aux(N), "accel_y": (np.zeros(7), "g", 100)})
    with pytest.raises(InputError, match=r'channel "accel_y" must hold 100 values at 100 Hz .* got 7 values'):
        gyrodrift.Recording([short]).save(tmp_path / "r.mcap")
    assert not list(tmp_path.iterdir())


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileError) as raised:
        gyrodrift.Recording.load(tmp_path / "nope.mcap")
    assert raised.value.errno == errno.ENOENT
    assert raised.value.filename == str(tmp_path / "nope.mcap")
    with pytest.raises(FileError):
        gyrodrift.load_campaign(tmp_path / "no-such-folder")


def test_not_an_mcap_file(tmp_path: Path) -> None:
    path = tmp_path / "garbage.mcap"
    path.write_bytes(b"not an mcap file at all" * 10)
    with pytest.raises(RecordingError, match=f"{path}: MCAP: "):
        gyrodrift.Recording.load(path)


def test_ground_truth_is_refused(campaign_dir: Path) -> None:
    truth = next((campaign_dir / "truth").glob("*.truth.mcap"))
    with pytest.raises(
        RecordingError, match=r"is simulator ground truth .* the recording reader refuses to read it"
    ):
        gyrodrift.Recording.load(truth)


def test_empty_campaign_folder(tmp_path: Path) -> None:
    with pytest.raises(RecordingError, match=r"no \.mcap recordings in"):
        gyrodrift.load_campaign(tmp_path)


def test_validation_error_names_file_topic_and_message(campaign_dir: Path, tmp_path: Path) -> None:
    """A recording with one gyro batch dropped: the reader names the file, the topic and the index."""
    mcap_reader = pytest.importorskip("mcap.reader")
    mcap_writer = pytest.importorskip("mcap.writer")
    source, broken = recording_path(campaign_dir), tmp_path / "broken.mcap"
    with source.open("rb") as f_in, broken.open("wb") as f_out:
        reader = mcap_reader.make_reader(f_in)
        writer = mcap_writer.Writer(f_out)
        header = reader.get_header()
        writer.start(profile=header.profile, library=header.library)
        summary = reader.get_summary()
        assert summary is not None
        for schema in summary.schemas.values():
            writer.register_schema(schema.name, schema.encoding, schema.data)
        channels = {}
        for channel in summary.channels.values():
            channels[channel.id] = writer.register_channel(
                channel.topic, channel.message_encoding, channel.schema_id, channel.metadata
            )
        for record in reader.iter_metadata():
            writer.add_metadata(record.name, record.metadata)
        rate_messages = 0
        for _, channel, message in reader.iter_messages(log_time_order=False):
            if channel.topic == "/gyro/rate":
                rate_messages += 1
                if rate_messages == 3:
                    continue  # drop message #2: message #3 then arrives as #2, 100 samples early
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time)
        writer.finish()
    with pytest.raises(RecordingError) as raised:
        gyrodrift.Recording.load(broken)
    assert str(raised.value) == f"{broken}: topic /gyro/rate, message #2: gap: first_sample 300, expected 200"


# --- simulation ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("campaign", "overrides", "error", "message"),
    [
        ({"units": 0}, {}, CampaignError, "invalid campaign: units: must be ≥ 1"),
        (
            None,
            {"set_points": [30, 200]},
            CampaignError,
            "invalid campaign: set_points_celsius[1]: must be in −60…+100 °C, got 200",
        ),
        (
            {"colour": "blue"},
            {},
            CampaignError,
            'not a valid campaign: `campaign["colour"]`: unknown field `colour`',
        ),
        (
            {"seed": 3, "units": "two"},
            {},
            CampaignError,
            'not a valid campaign: `campaign["units"]`: invalid type: string "two", expected u32',
        ),
        ("units = ", {}, CampaignError, "not a valid campaign TOML"),
        (None, {"set_points": "30,abc"}, InputError, "`set_points` must be a sequence of floats"),
        (None, {"effects": ["sunspots"]}, InputError, "`effects`: unknown effect `sunspots`"),
        (
            None,
            {"effects": "thermal_lag"},
            InputError,
            "`effects` must be a sequence of effect names (str), got 'thermal_lag'",
        ),
        (
            None,
            {"field": True, "field_only": True},
            InputError,
            "`field` and `field_only` cannot both be set",
        ),
        (None, {"units": -1}, InputError, "`units` must be an integer ≥ 1, got -1"),
        (
            42,
            {},
            InputError,
            "`campaign` must be None, a dict, TOML/JSON text or a path (os.PathLike), got int",
        ),
    ],
)
def test_bad_campaigns(
    campaign: Any, overrides: dict[str, Any], error: type[Exception], message: str
) -> None:
    with pytest.raises(error) as raised:
        gyrodrift.resolve_campaign(campaign, **overrides)
    assert message in str(raised.value)
    if not isinstance(campaign, str):
        # The caller wrote a dict or keywords, no text: no line and column of one.
        assert " at line " not in str(raised.value)


def test_campaign_file_missing(tmp_path: Path) -> None:
    with pytest.raises(FileError) as raised:
        gyrodrift.resolve_campaign(tmp_path / "campaign.toml")
    assert raised.value.errno == errno.ENOENT


def test_a_path_given_as_text_gets_a_hint(tmp_path: Path) -> None:
    (tmp_path / "c.toml").write_text("units = 1\n")
    with pytest.raises(CampaignError, match=r"to read the file, pass a pathlib\.Path"):
        gyrodrift.resolve_campaign(str(tmp_path / "c.toml"))


# --- fitting and evaluation ------------------------------------------------------------------


def test_no_calibration_activations(campaign_dir: Path) -> None:
    with pytest.raises(FitError, match=r"no protocol activations at the calibration set points \[50\.0\]"):
        gyrodrift.fit(campaign_dir, calibration=[50])
    with pytest.raises(
        FitError, match=r"no protocol activations at the calibration set points \[50\.0\] °C in 1 segments"
    ):
        gyrodrift.fit(make_segment(), calibration=[50])


def test_too_short_activation() -> None:
    with pytest.raises(
        FitError, match="unit PY-1, set point 30 °C, series 1 activation 1: 2500 samples is too short"
    ):
        gyrodrift.fit([make_segment(2500)])


def test_setting_out_of_range(campaign_dir: Path) -> None:
    with pytest.raises(FitError, match="fit setting `reference_count`: must be between 2 and 16"):
        gyrodrift.fit(campaign_dir, settings=gyrodrift.FitSettings(reference_count=1))


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: gyrodrift.fit(42),
            "`source` must be a path (campaign folder, folder of .mcap files or one .mcap file)",
        ),
        (
            lambda: gyrodrift.fit([make_segment(), 3]),
            "`source[1]` must be a path, gyrodrift.Recording or Segment, got int",
        ),
        (lambda: gyrodrift.fit([]), "`source` must not be empty"),
        (
            lambda: gyrodrift.fit(make_segment(), calibration=[float("nan")]),
            "`calibration` must hold finite set points, got NaN",
        ),
        (
            lambda: gyrodrift.fit(make_segment(), calibration="30"),
            "`calibration` must be a sequence of set points in °C (floats), got '30'",
        ),
        (
            lambda: gyrodrift.fit(make_segment(), settings={}),
            "`settings` must be a gyrodrift.FitSettings or None, got dict",
        ),
        (lambda: gyrodrift.FitSettings(grid_ms="ten"), "`grid_ms` must be an integer ≥ 1 (ms), got 'ten'"),
        (lambda: gyrodrift.FitSettings.from_json('{"grid_ms": -1}'), "`text` is not valid fit settings JSON"),
        (lambda: gyrodrift.evaluate(make_segment()), "`source` must be recording files"),
        (lambda: gyrodrift.analyse("segment"), "`segment` must be a gyrodrift.Segment, got str"),
        (lambda: gyrodrift.summarise([1]), "`results[0]` must be a gyrodrift.ActivationResult, got int"),
    ],
)
def test_fit_arguments(call: Any, message: str) -> None:
    with pytest.raises(InputError) as raised:
        call()
    assert message in str(raised.value)


def test_unknown_split(evaluation: gyrodrift.Evaluation) -> None:
    with pytest.raises(
        InputError, match="`split` must be one of validation, held_out_repeat, field, noise_floor, got 'test'"
    ):
        evaluation.fitted[0].evaluate(make_segment(5000), split="test")
