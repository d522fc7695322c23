"""pandas in and out: `Recording.from_dataframe` / `Recording.read_csv` and results as frames.

A frame is written as CSV text (its own column names, time in seconds) and read by the same
validating reader as `gyrodrift import`, so a frame and a file are refused alike, naming the row
(the frame's n-th row, from 1) and the column. pandas is imported only when a frame is used.
"""

from __future__ import annotations

import io
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from . import _gyrodrift

_ACTIVATION = "activation"
"""The activation column made from time gaps (`gap_s`) when none is named."""

_RATE_UNITS = ("deg/s", "rad/s")


def _pandas() -> Any:
    try:
        import pandas  # type: ignore[import-untyped]
    except ImportError as error:
        raise ImportError(
            f"gyrodrift's DataFrame functions need pandas (pip install pandas): {error}"
        ) from None
    return pandas


def _names(value: str | Sequence[str], what: str, counts: tuple[int, ...]) -> list[str]:
    names = [value] if isinstance(value, str) else list(value)
    if len(names) not in counts or not all(isinstance(n, str) for n in names):
        wanted = " or ".join(str(c) for c in counts)
        raise _gyrodrift.InputError(f"`{what}` must be a column name or {wanted} column names, got {value!r}")
    return names


def _seconds(column: Any, name: str, time_unit: str | None) -> np.ndarray:
    """The time column in seconds (float64), from s, ms, timedelta64 or datetime64."""
    pandas = _pandas()
    if pandas.api.types.is_timedelta64_dtype(column):
        if time_unit is not None:
            raise _gyrodrift.InputError(f"`time_unit` is for a numeric time column; `{name}` is timedelta64")
        return np.asarray(column.dt.total_seconds(), dtype=np.float64)
    if pandas.api.types.is_datetime64_any_dtype(column):
        if time_unit is not None:
            raise _gyrodrift.InputError(f"`time_unit` is for a numeric time column; `{name}` is datetime64")
        delta = column - column.iloc[0]
        return np.asarray(delta.dt.total_seconds(), dtype=np.float64)
    if not pandas.api.types.is_numeric_dtype(column):
        raise _gyrodrift.InputError(
            f"time column `{name}` must be numeric (s or ms), timedelta64 or datetime64, got {column.dtype}"
        )
    if time_unit not in ("s", "ms"):
        raise _gyrodrift.InputError(
            f"`time_unit` must be 's' or 'ms' for the numeric time column `{name}`, got {time_unit!r}"
        )
    seconds = np.asarray(column, dtype=np.float64)
    return seconds / 1000.0 if time_unit == "ms" else seconds


def _sample_rate(seconds: np.ndarray, starts: np.ndarray) -> int:
    """The logging rate, Hz, from the median step within activations."""
    steps = np.diff(seconds)
    inside = np.ones(len(steps), dtype=bool)
    inside[starts[1:] - 1] = False
    steps = steps[inside & (steps > 0)]
    if len(steps) == 0:
        raise _gyrodrift.InputError("cannot infer `sample_rate_hz` from fewer than two samples: pass it")
    rate = round(1.0 / float(np.median(steps)))
    if rate < 1 or 1_000_000_000 % rate != 0:
        raise _gyrodrift.InputError(
            f"the median step {float(np.median(steps))} s gives {rate} Hz, "
            "not a rate that divides 10⁹: pass `sample_rate_hz`"
        )
    return rate


def from_dataframe(
    frame: Any,
    *,
    rate_unit: str,
    time: str = "time",
    time_unit: str | None = None,
    rate: Sequence[str] = ("rate_x", "rate_y", "rate_z"),
    temperature: str | Sequence[str] = "temperature",
    activation: str | None = None,
    gap_s: float | None = None,
    sample_rate_hz: int | None = None,
    max_gap_s: float | None = None,
    unit_id: str = "dataframe",
    set_point_celsius: float | None = None,
    series_kind: str = "protocol",
    interval_min: float | None = None,
    temperature_dropouts: bool = False,
    name: str = "DataFrame",
) -> _gyrodrift.Recording:
    """See `gyrodrift.Recording.from_dataframe`."""
    pandas = _pandas()
    if not isinstance(frame, pandas.DataFrame):
        raise _gyrodrift.InputError(f"`frame` must be a pandas DataFrame, got {type(frame).__name__}")
    if rate_unit not in _RATE_UNITS:
        raise _gyrodrift.InputError(
            f"`rate_unit` must be 'deg/s' or 'rad/s' (what the rate columns hold), got {rate_unit!r}"
        )
    rates = _names(rate, "rate", (3,))
    temperatures = _names(temperature, "temperature", (1, 3))
    if len(temperatures) == 1:
        temperatures *= 3
    if activation is not None and gap_s is not None:
        raise _gyrodrift.InputError("pass `activation` (a column) or `gap_s` (split on time gaps), not both")
    wanted = [time, *rates, *temperatures] + ([activation] if activation is not None else [])
    missing = [c for c in dict.fromkeys(wanted) if c not in frame.columns]
    if missing:
        raise _gyrodrift.InputError(
            f"{name}: missing column(s) {', '.join(map(repr, missing))} "
            f"(the frame has: {', '.join(map(str, frame.columns))})"
        )
    if len(frame) == 0:
        raise _gyrodrift.InputError(f"{name}: no rows")
    seconds = _seconds(frame[time], time, time_unit)
    columns: dict[str, Any] = {time: seconds}
    for column in dict.fromkeys([*rates, *temperatures]):
        values = frame[column]
        if not pandas.api.types.is_numeric_dtype(values):
            raise _gyrodrift.InputError(f"{name}: column `{column}` must be numeric, got {values.dtype}")
        columns[column] = values.to_numpy(dtype=np.float64)
    if activation is not None:
        ids = frame[activation].astype(str).to_numpy()
        starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
        columns[activation] = ids
    elif gap_s is not None:
        if not (isinstance(gap_s, (int, float)) and math.isfinite(gap_s) and gap_s > 0):
            raise _gyrodrift.InputError(f"`gap_s` must be a number of seconds > 0, got {gap_s!r}")
        starts = np.flatnonzero(np.r_[True, np.diff(seconds) > gap_s])
        activation = _ACTIVATION if _ACTIVATION not in columns else f"_{_ACTIVATION}"
        ids = np.zeros(len(seconds), dtype=np.int64)
        ids[starts[1:]] = 1
        columns[activation] = np.cumsum(ids)
    else:
        starts = np.array([0])
    if sample_rate_hz is None:
        sample_rate_hz = _sample_rate(seconds, starts)
    text = io.StringIO()
    pandas.DataFrame(columns).to_csv(text, index=False, float_format="%.17g", na_rep="")
    recording = _gyrodrift._read_csv_text(
        text.getvalue().encode(),
        name,
        time=time,
        rate=rates,
        temperature=temperatures,
        activation=activation,
        rate_unit=rate_unit,
        unit_id=unit_id,
        sample_rate_hz=sample_rate_hz,
        max_gap_s=max_gap_s,
        set_point_celsius=set_point_celsius,
        series_kind=series_kind,
        temperature_dropouts=temperature_dropouts,
    )
    if gap_s is None and interval_min is None:
        return recording
    # One session: activations numbered in order, the off-time before each measured from the log
    # (only when one clock runs through it: split on gaps), the protocol's interval if given.
    ends = np.r_[starts[1:] - 1, len(seconds) - 1]
    segments = []
    for k, segment in enumerate(recording.segments):
        old = segment.labels
        # Switched off one sample period after the previous activation's last row.
        last = seconds[ends[k - 1]] + 1.0 / sample_rate_hz if k > 0 else math.nan
        off = float(seconds[starts[k]] - last) if k > 0 and gap_s is not None else None
        labels = _gyrodrift.Labels(
            unit_id=old.unit_id,
            set_point_celsius=old.set_point_celsius,
            series_kind=old.series_kind,
            activation=k + 1,
            interval_min=interval_min,
            off_before_s=off,
        )
        segments.append(
            _gyrodrift.Segment(
                labels,
                segment.rate_dps,
                segment.temperature_raw,
                sample_rate_hz=segment.sample_rate_hz,
                power_on_ns=segment.power_on_ns,
                aux=segment.aux,
            )
        )
    metadata = {k: v for k, v in recording.metadata.items() if k not in ("unit_id", "sample_rate_hz")}
    return _gyrodrift.Recording(segments, unit_id=recording.unit_id, metadata=metadata)


def read_csv(path: Any, *, rate_unit: str, **options: Any) -> _gyrodrift.Recording:
    """See `gyrodrift.Recording.read_csv`."""
    pandas = _pandas()
    options.setdefault("name", str(path))
    return from_dataframe(pandas.read_csv(path), rate_unit=rate_unit, **options)


_INDEX = ("unit_id", "split", "nominal_set_point_celsius", "series_kind", "series", "repeat", "activation")
_METRICS = ("drift_dps", "residual_rms_dps", "flags")


def results_frame(results: Any, metric: str = "drift_dps") -> Any:
    """See `gyrodrift.results_frame`."""
    pandas = _pandas()
    if metric not in _METRICS:
        raise _gyrodrift.InputError(f"`metric` must be one of {', '.join(_METRICS)}, got {metric!r}")
    if isinstance(results, _gyrodrift.Evaluation):
        results = results.results
    rows: list[tuple[Any, ...]] = []
    values: list[list[float]] = []
    columns: list[tuple[str, str]] | None = None
    for k, result in enumerate(results):
        if not isinstance(result, _gyrodrift.ActivationResult):
            raise _gyrodrift.InputError(
                f"`results[{k}]` must be a gyrodrift.ActivationResult, got {type(result).__name__}"
            )
        labels = result.labels
        per_model = getattr(result, metric)
        if columns is None:
            columns = [(model, axis) for model in per_model for axis in ("X", "Y", "Z")]
        rows.append(
            (
                labels.unit_id,
                result.split,
                labels.nominal_set_point_celsius,
                labels.series_kind,
                labels.series,
                labels.repeat,
                labels.activation,
            )
        )
        values.append([v for model, _ in columns[::3] for v in per_model[model]])
    index = pandas.MultiIndex.from_tuples(rows, names=_INDEX)
    header = pandas.MultiIndex.from_tuples(columns or [], names=("model", "axis"))
    frame = pandas.DataFrame(values, index=index, columns=header)
    return frame.sort_index()


def correct_frame(model: Any, segment: Any) -> Any:
    """See `gyrodrift.correct_frame`."""
    pandas = _pandas()
    if not isinstance(segment, _gyrodrift.Segment):
        raise _gyrodrift.InputError(f"`segment` must be a gyrodrift.Segment, got {type(segment).__name__}")
    corrector = _gyrodrift.Corrector(model)
    temperature = segment.temperature_raw.astype(np.float32)
    corrector.power_on(temperature[0])
    corrected, bias, flags = corrector.correct_batch(segment.since_power_on_ms, segment.rate_dps, temperature)
    columns: dict[str, Any] = {}
    for name, values in (("corrected", corrected), ("bias", bias)):
        for k, axis in enumerate("xyz"):
            columns[f"{name}_{axis}_dps"] = values[:, k]
    for k, axis in enumerate("xyz"):
        columns[f"flags_{axis}"] = flags[:, k]
    index = pandas.Index(segment.since_power_on_ms / 1000.0, name="time_s")
    return pandas.DataFrame(columns, index=index)
