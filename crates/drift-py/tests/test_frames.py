"""pandas in and out: a continuous log → `Recording.from_dataframe` → fit → corrected frame; the
refusals of wrong units and bad times; results as a frame."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import gyrodrift

pd = pytest.importorskip("pandas")


def bench_log(campaign_dir: Path, set_point: str, gap_s: float = 30.0) -> pd.DataFrame:
    """A simulated protocol series written as a bench would log it: one clock in ms through
    several power-ons, rates in rad/s, one die temperature in °C."""
    recording = gyrodrift.Recording.load(campaign_dir / "recordings" / f"GIU-01_sp{set_point}C_protocol.mcap")
    frames, start_ms = [], 1_000.0
    for segment in recording.segments[:3]:
        n = len(segment)
        frames.append(
            pd.DataFrame(
                {
                    "t_ms": start_ms + segment.since_power_on_ms.astype(np.float64),
                    "gx": np.deg2rad(segment.rate_dps[:, 0].astype(np.float64)),
                    "gy": np.deg2rad(segment.rate_dps[:, 1].astype(np.float64)),
                    "gz": np.deg2rad(segment.rate_dps[:, 2].astype(np.float64)),
                    "temp_c": segment.temperature_raw[:, 0] / 200.0,
                }
            )
        )
        start_ms += n + gap_s * 1000.0
    return pd.concat(frames, ignore_index=True)


def test_a_log_with_three_power_ons_is_fitted_and_corrected_as_a_frame(campaign_dir: Path) -> None:
    logs = {30.0: bench_log(campaign_dir, "+30.0"), 40.0: bench_log(campaign_dir, "+40.0")}
    options = dict(time="t_ms", time_unit="ms", rate=("gx", "gy", "gz"), temperature="temp_c", gap_s=1.0)
    # The documented ≤ 5 lines: frames in, fit, a corrected frame out.
    recordings = [
        gyrodrift.Recording.from_dataframe(
            log, rate_unit="rad/s", set_point_celsius=sp, interval_min=30, **options
        )
        for sp, log in logs.items()
    ]
    (unit,) = gyrodrift.fit(recordings, calibration=[30, 40])
    corrected = gyrodrift.correct_frame(unit.modified, recordings[0].segments[1])
    assert [len(r.segments) for r in recordings] == [3, 3]
    second = recordings[0].segments[1]
    assert second.labels.activation == 2 and second.labels.interval_min == 30.0
    assert second.labels.off_before_s == pytest.approx(30.0, abs=1e-3)
    assert second.sample_rate_hz == 1000
    rate = second.rate_dps
    log = logs[30.0]
    first_len = len(recordings[0].segments[0])
    expected = np.rad2deg(log["gx"].to_numpy()[first_len : first_len + len(second)]).astype(np.float32)
    assert np.allclose(rate[:, 0], expected, atol=1e-6)
    assert list(corrected.columns[:3]) == ["corrected_x_dps", "corrected_y_dps", "corrected_z_dps"]
    assert corrected.index.name == "time_s" and len(corrected) == len(second)
    assert np.abs(corrected["corrected_x_dps"].mean()) < np.abs(rate[:, 0].mean())


def frame(n: int = 50) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "time": np.arange(n) / 100.0,
            "rate_x": np.zeros(n),
            "rate_y": np.zeros(n),
            "rate_z": np.zeros(n),
            "temperature": np.full(n, 25.0),
        }
    )


def test_times_that_go_back_are_refused_naming_the_row_and_column() -> None:
    log = frame()
    log.loc[20, "time"] = 0.05
    with pytest.raises(
        gyrodrift.InputError, match=r"DataFrame: row 21 \(line 22\), column `time`: time 0.05 s goes back"
    ):
        gyrodrift.Recording.from_dataframe(log, rate_unit="deg/s", time_unit="s", sample_rate_hz=100)


def test_a_restarting_clock_is_refused_unless_an_activation_column_says_so() -> None:
    log = pd.concat([frame(), frame()], ignore_index=True)
    with pytest.raises(gyrodrift.InputError, match=r"row 51 .*goes back"):
        gyrodrift.Recording.from_dataframe(log, rate_unit="deg/s", time_unit="s", gap_s=1.0)
    log["power_on"] = [0] * 50 + [1] * 50
    recording = gyrodrift.Recording.from_dataframe(
        log, rate_unit="deg/s", time_unit="s", activation="power_on"
    )
    assert [len(s) for s in recording.segments] == [50, 50]


def test_raw_counts_given_as_celsius_are_refused() -> None:
    log = frame()
    log["temperature"] = 6000.0
    with pytest.raises(
        gyrodrift.InputError, match=r"row 1 .*column `temperature`: temperature 6000 °C is outside"
    ):
        gyrodrift.Recording.from_dataframe(log, rate_unit="deg/s", time_unit="s")


def test_the_units_must_be_named() -> None:
    with pytest.raises(TypeError, match="rate_unit"):
        gyrodrift.Recording.from_dataframe(frame(), time_unit="s")  # type: ignore[call-arg]
    with pytest.raises(gyrodrift.InputError, match=r"`rate_unit` must be 'deg/s' or 'rad/s'.*'dps'"):
        gyrodrift.Recording.from_dataframe(frame(), rate_unit="dps", time_unit="s")
    with pytest.raises(
        gyrodrift.InputError, match=r"`time_unit` must be 's' or 'ms' for the numeric time column `time`"
    ):
        gyrodrift.Recording.from_dataframe(frame(), rate_unit="deg/s")
    with pytest.raises(gyrodrift.InputError, match=r"missing column\(s\) 'rate_q'"):
        gyrodrift.Recording.from_dataframe(
            frame(), rate_unit="deg/s", time_unit="s", rate=("rate_x", "rate_y", "rate_q")
        )


def test_timedelta_times_and_three_temperature_columns_are_read(tmp_path: Path) -> None:
    log = frame()
    log["time"] = pd.to_timedelta(log["time"], unit="s")
    log["tx"], log["ty"], log["tz"] = 25.0, 26.0, 27.0
    recording = gyrodrift.Recording.from_dataframe(log, rate_unit="deg/s", temperature=("tx", "ty", "tz"))
    (segment,) = recording.segments
    assert segment.sample_rate_hz == 100
    assert segment.temperature_raw[0].tolist() == [5000, 5200, 5400]
    path = tmp_path / "log.csv"
    frame().to_csv(path, index=False)
    again = gyrodrift.Recording.read_csv(path, rate_unit="deg/s", time_unit="s")
    assert len(again.segments[0]) == 50


def test_settings_raw_is_the_inverse_of_celsius_and_takes_arrays() -> None:
    settings = gyrodrift.Settings(raw_per_celsius=100.0, raw_at_zero_celsius=10.0)
    assert settings.raw(25.0) == 2510.0 and settings.celsius(settings.raw(25.0)) == 25.0
    raw = settings.raw(pd.Series([0.0, 1.5, -40.0]))
    assert raw.dtype == np.float32 and raw.tolist() == [10.0, 160.0, -3990.0]
    assert settings.raw(np.zeros((2, 3))).shape == (2, 3)
    with pytest.raises(gyrodrift.InputError, match="`celsius` must be a float or an array of floats"):
        settings.raw("warm")


def test_celsius_passed_to_power_on_as_raw_is_refused_and_the_state_kept(campaign_dir: Path) -> None:
    (unit,) = gyrodrift.fit(campaign_dir)
    corrector = gyrodrift.Corrector(unit.modified)
    with pytest.raises(gyrodrift.InputError, match=r"look like °C, not raw sensor counts.*settings.raw"):
        corrector.power_on((30.2, 30.1, 30.3))
    assert corrector.correct(0, (0.0, 0.0, 0.0), (6000.0,) * 3).flags[0] & gyrodrift.Flags.NOT_POWERED_ON
    corrector.power_on(unit.modified.settings.raw(np.array([30.2, 30.1, 30.3])))
    assert not corrector.correct(0, (0.0, 0.0, 0.0), (6040.0,) * 3).flags[0] & gyrodrift.Flags.NOT_POWERED_ON


def test_results_as_a_frame_indexed_by_activation(evaluation: gyrodrift.Evaluation) -> None:
    frame = gyrodrift.results_frame(evaluation)
    assert frame.index.names == [
        "unit_id",
        "split",
        "nominal_set_point_celsius",
        "series_kind",
        "series",
        "repeat",
        "activation",
    ]
    assert len(frame) == len(evaluation.results)
    assert ("modified", "X") in frame.columns and ("3rd-order", "Z") in frame.columns
    result = evaluation.results[0]
    labels = result.labels
    row = frame.loc[
        (
            labels.unit_id,
            result.split,
            labels.nominal_set_point_celsius,
            labels.series_kind,
            labels.series,
            labels.repeat,
            labels.activation,
        )
    ]
    assert row["modified"].tolist() == list(result.drift_dps["modified"])
    flags = gyrodrift.results_frame(evaluation.results, metric="flags")
    assert flags[("uncorrected", "X")].dtype.kind in "iu" or not math.isnan(
        flags[("uncorrected", "X")].iloc[0]
    )


def test_a_model_named_either_way_finds_its_frame_column_record_and_fitted_tables(
    evaluation: gyrodrift.Evaluation, tmp_path: Path
) -> None:
    unit = evaluation.fitted[0]
    frame = gyrodrift.results_frame(evaluation)
    frame_models = list(dict.fromkeys(frame.columns.get_level_values("model")))
    # Every name the frame uses has an identifier that names it back.
    for name in frame_models:
        assert gyrodrift.model_name(name) == name
        assert gyrodrift.model_name(gyrodrift.model_attribute(name)) == name
    # Frame and record names → the fitted unit's tables and the files `save` writes.
    assert getattr(unit, gyrodrift.model_attribute("3rd-order")) == unit.third_order
    assert getattr(unit, gyrodrift.model_attribute("by-history")) == unit.by_history
    saved = unit.save(tmp_path)
    for name in {r["model"] for r in evaluation.records} & {"3rd-order", "by-history", "modified"}:
        assert (saved / f"{gyrodrift.model_attribute(name)}.json").is_file()
    # Every fitted model's attribute → its frame column, record and per-activation dict key.
    attributes = ("modified", "by_history", "standard", "third_order", "relative", "recommended")
    for attribute in attributes:
        assert type(getattr(unit, attribute)).__name__.endswith("Tables")
        name = gyrodrift.model_name(attribute)
        assert name in frame_models
        assert name in evaluation.results[0].drift_dps
    assert frame[gyrodrift.model_name("third_order")].equals(frame["3rd-order"])
    records = evaluation.records
    assert gyrodrift.paper_table(records, models=["third_order", "by_history"]) == gyrodrift.paper_table(
        records, models=["3rd-order", "by-history"]
    )
    assert "| 3rd-order |" in gyrodrift.paper_table(records, models=["third_order"])
    valid = r"the models are uncorrected, standard, 3rd-order \(third_order\), .*by-history \(by_history\)"
    with pytest.raises(gyrodrift.InputError, match=r"unknown model name 'third-order': " + valid):
        gyrodrift.model_attribute("third-order")
    with pytest.raises(gyrodrift.InputError, match=r"unknown model name '3rd_order': " + valid):
        gyrodrift.paper_table(records, models=["3rd_order"])


def test_a_series_passed_as_an_array_is_told_to_use_to_numpy(models: dict[str, object]) -> None:
    corrector = gyrodrift.Corrector(models["modified"])  # type: ignore[arg-type]
    times = pd.Series(np.arange(5, dtype=np.uint32))
    with pytest.raises(
        gyrodrift.InputError, match=r"got Series \(a pandas object: pass .to_numpy\(\) of the column\(s\)"
    ):
        corrector.correct_batch(times, np.zeros((5, 3), np.float32), np.full((5, 3), 6000.0, np.float32))
