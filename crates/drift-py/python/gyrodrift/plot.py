"""The report's figures with matplotlib (install the `gyrodrift[plot]` extra).

Each function draws one figure of `gyrodrift report` from an `Evaluation` into a matplotlib Axes
(a new figure when `ax` is None) and returns the Axes; `save_figures` writes them all. The data are
the analysed calibration activations (`Evaluation.calibration`) of one unit at one calibration set
point, and the validation results (`Evaluation.results`); the numbers come from Rust, this module only
averages repeats and draws.
"""

from __future__ import annotations

import os
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ._gyrodrift import AnalysedActivation, Evaluation

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "correlation_curves",
    "drift_before_after",
    "drift_per_interval",
    "k_per_interval",
    "rise_per_interval",
    "save_figures",
]

AXES = ("X", "Y", "Z")
MODELS = ("uncorrected", "standard", "3rd-order", "modified")
K_TIMES_S = (2.0, 5.0, 30.0, 60.0, 119.0)


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as error:  # pragma: no cover - exercised only without matplotlib
        raise ImportError("gyrodrift.plot needs matplotlib: pip install 'gyrodrift[plot]'") from error
    return plt


def _new_axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    _, new = _pyplot().subplots(figsize=(7, 4.5))
    return new  # type: ignore[no-any-return]


def _axis_index(axis: str) -> int:
    if axis not in AXES:
        raise ValueError(f"`axis` must be one of {', '.join(AXES)}, got {axis!r}")
    return AXES.index(axis)


def _unit_and_set_point(
    evaluation: Evaluation, unit: str | None, set_point: float | None
) -> tuple[str, float]:
    fitted = evaluation.fitted
    if not fitted:
        raise ValueError("the evaluation has no fitted unit")
    chosen = fitted[0] if unit is None else next((f for f in fitted if f.unit_id == unit), None)
    if chosen is None:
        raise ValueError(f"unknown unit {unit!r}: fitted units are {', '.join(f.unit_id for f in fitted)}")
    if set_point is None:
        set_point = chosen.set_points_celsius[0]
    return chosen.unit_id, set_point


def _activations(evaluation: Evaluation, unit: str, set_point: float) -> list[AnalysedActivation]:
    return [
        a
        for a in evaluation.calibration
        if a.labels.unit_id == unit
        and a.labels.series_kind == "protocol"
        and abs(a.labels.set_point_celsius - set_point) < 1e-6
    ]


def _per_interval(
    activations: Sequence[AnalysedActivation], value: Callable[[AnalysedActivation], float | None]
) -> dict[int, dict[float, float]]:
    """Mean over repeats of `value`, per activation number and interval (min)."""
    sums: dict[int, dict[float, list[float]]] = defaultdict(lambda: defaultdict(list))
    for a in activations:
        interval = a.labels.interval_min
        v = value(a)
        if interval is not None and v is not None:
            sums[a.labels.activation][interval].append(v)
    return {
        act: {i: float(np.mean(vs)) for i, vs in sorted(by_interval.items())}
        for act, by_interval in sorted(sums.items())
    }


def _k_at(a: AnalysedActivation, seconds: float, axis: int) -> float | None:
    """k = drift / rise at a time after switch-on (None where the rise is too small to divide by)."""
    if len(a) == 0:
        return None
    i = min(round(seconds * 1000 / a.grid_ms), len(a) - 1)
    rise = float(a.rise_celsius[i, axis])
    return float(a.drift_dps[i, axis]) / rise if abs(rise) > 1e-3 else None


def _by_activation(
    ax: Axes,
    activations: Sequence[AnalysedActivation],
    value: Callable[[AnalysedActivation], float | None],
) -> None:
    for act, points in _per_interval(activations, value).items():
        ax.plot(list(points), list(points.values()), marker="o", label=f"activation {act}")


def _finish(ax: Axes, title: str, xlabel: str, ylabel: str) -> Axes:
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return ax


def rise_per_interval(
    evaluation: Evaluation,
    *,
    unit: str | None = None,
    set_point: float | None = None,
    axis: str = "X",
    ax: Axes | None = None,
) -> Axes:
    """Temperature rise at the end of each activation against the off-time (the paper's Fig. 3a)."""
    i = _axis_index(axis)
    unit, set_point = _unit_and_set_point(evaluation, unit, set_point)
    ax = _new_axes(ax)
    _by_activation(ax, _activations(evaluation, unit, set_point), lambda a: float(a.rise_celsius[-1, i]))
    return _finish(
        ax,
        f"Rise at the end of each activation ({unit}, {axis}, {set_point:+g} °C)",
        "off-time, min",
        "temperature rise since switch-on, °C",
    )


def drift_per_interval(
    evaluation: Evaluation,
    *,
    unit: str | None = None,
    set_point: float | None = None,
    axis: str = "X",
    ax: Axes | None = None,
) -> Axes:
    """Drift at the end of each activation against the off-time (the paper's Fig. 3b)."""
    i = _axis_index(axis)
    unit, set_point = _unit_and_set_point(evaluation, unit, set_point)
    ax = _new_axes(ax)
    _by_activation(ax, _activations(evaluation, unit, set_point), lambda a: float(a.drift_dps[-1, i]))
    return _finish(
        ax,
        f"Drift at the end of each activation ({unit}, {axis}, {set_point:+g} °C)",
        "off-time, min",
        "bias drift since switch-on, °/s",
    )


def correlation_curves(
    evaluation: Evaluation,
    *,
    unit: str | None = None,
    set_point: float | None = None,
    axis: str = "X",
    ax: Axes | None = None,
) -> Axes:
    """k = drift / rise after switch-on, activations of the shortest interval (the paper's Fig. 4)."""
    i = _axis_index(axis)
    unit, set_point = _unit_and_set_point(evaluation, unit, set_point)
    activations = _activations(evaluation, unit, set_point)
    intervals = [a.labels.interval_min for a in activations if a.labels.interval_min is not None]
    ax = _new_axes(ax)
    if intervals:
        shortest = min(intervals)
        members: dict[int, list[AnalysedActivation]] = defaultdict(list)
        for a in activations:
            if a.labels.interval_min == shortest:
                members[a.labels.activation].append(a)
        for act, group in sorted(members.items()):
            n = min(len(m) for m in group)
            drift = np.asarray(np.mean([m.drift_dps[:n, i] for m in group], axis=0, dtype=np.float64))
            rise = np.asarray(np.mean([m.rise_celsius[:n, i] for m in group], axis=0, dtype=np.float64))
            t = group[0].time_s[:n]
            keep = (t >= 2.0) & (np.abs(rise) > 1e-3)
            ax.plot(t[keep], drift[keep] / rise[keep], label=f"activation {act}")
        title = f"Correlation curves, {shortest:g}-min series ({unit}, {axis}, {set_point:+g} °C)"
    else:
        title = f"Correlation curves ({unit}, {axis}, {set_point:+g} °C)"
    return _finish(ax, title, "time since switch-on, s", "correlation k = drift ÷ rise, (°/s)/°C")


def k_per_interval(
    evaluation: Evaluation,
    *,
    unit: str | None = None,
    set_point: float | None = None,
    axis: str = "X",
    activation: int | None = None,
    times_s: Sequence[float] = K_TIMES_S,
    ax: Axes | None = None,
) -> Axes:
    """k at fixed times after switch-on against the off-time, for one activation number (default: the
    last of the series, the 5th in the paper's protocol; the paper's Fig. 5)."""
    i = _axis_index(axis)
    unit, set_point = _unit_and_set_point(evaluation, unit, set_point)
    activations = _activations(evaluation, unit, set_point)
    if activation is None:
        activation = max((a.labels.activation for a in activations), default=1)
    chosen = [a for a in activations if a.labels.activation == activation]
    ax = _new_axes(ax)
    for t in times_s:

        def k_at_t(a: AnalysedActivation, t: float = t) -> float | None:
            return _k_at(a, t, i)

        points = _per_interval(chosen, k_at_t).get(activation, {})
        ax.plot(list(points), list(points.values()), marker="o", label=f"{t:g} s")
    return _finish(
        ax,
        f"k at fixed times, activation {activation} ({unit}, {axis}, {set_point:+g} °C)",
        "off-time, min",
        "correlation k = drift ÷ rise, (°/s)/°C",
    )


def drift_before_after(
    evaluation: Evaluation,
    *,
    unit: str | None = None,
    axis: str = "X",
    split: str = "validation",
    ax: Axes | None = None,
) -> Axes:
    """Drift of every activation of a split (validation by default), before and after correction."""
    i = _axis_index(axis)
    unit, _ = _unit_and_set_point(evaluation, unit, None)
    results = [r for r in evaluation.results if r.split == split and r.labels.unit_id == unit]
    ax = _new_axes(ax)
    for model in MODELS:
        values = [r.drift_dps[model][i] for r in results if model in r.drift_dps]
        ax.plot(range(len(values)), values, linestyle="none", marker="o", markersize=3, label=model)
    return _finish(
        ax, f"Drift per {split} activation ({unit}, {axis})", "activation (recording order)", "drift, °/s"
    )


FIGURES: dict[str, Callable[..., Axes]] = {
    "fig-rise-per-interval": rise_per_interval,
    "fig-drift-per-interval": drift_per_interval,
    "fig-correlation": correlation_curves,
    "fig-k-per-interval": k_per_interval,
    "fig-drift-before-after": drift_before_after,
}
"""The report's figures by file name (without extension)."""


def save_figures(
    evaluation: Evaluation, folder: str | os.PathLike[str], *, unit: str | None = None, suffix: str = ".png"
) -> list[Path]:
    """Draws every figure for `unit` (default: the first fitted) and saves it in `folder` (created if
    missing) as `<name><suffix>`; returns the files written."""
    plt = _pyplot()
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, draw in FIGURES.items():
        figure, ax = plt.subplots(figsize=(7, 4.5))
        try:
            draw(evaluation, unit=unit, ax=ax)
            figure.tight_layout()
            path = folder / f"{name}{suffix}"
            figure.savefig(path)
            written.append(path)
        finally:
            plt.close(figure)
    return written
