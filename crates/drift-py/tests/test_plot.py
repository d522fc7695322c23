"""The report's figures with matplotlib (the `gyrodrift[plot]` extra), headless."""

from __future__ import annotations

from pathlib import Path

import pytest

import gyrodrift

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from gyrodrift import plot  # noqa: E402  (after choosing the backend)


@pytest.mark.parametrize("name", sorted(plot.FIGURES))
def test_each_figure_draws_data(evaluation: gyrodrift.Evaluation, name: str) -> None:
    import matplotlib.pyplot as plt

    ax = plot.FIGURES[name](evaluation)
    try:
        assert ax.lines, name
        assert all(len(line.get_xdata()) > 0 for line in ax.lines)  # type: ignore[arg-type]
        assert ax.get_xlabel() and ax.get_ylabel()
    finally:
        plt.close(ax.figure)  # type: ignore[arg-type]


def test_rise_per_interval_has_one_line_per_activation(evaluation: gyrodrift.Evaluation) -> None:
    import matplotlib.pyplot as plt

    ax = plot.rise_per_interval(evaluation, axis="Y", set_point=40.0)
    try:
        assert [line.get_label() for line in ax.lines] == ["activation 1", "activation 2", "activation 3"]
        assert list(ax.lines[0].get_xdata()) == [1.0, 20.0]  # type: ignore[arg-type]
    finally:
        plt.close(ax.figure)  # type: ignore[arg-type]


def test_save_figures(evaluation: gyrodrift.Evaluation, tmp_path: Path) -> None:
    written = plot.save_figures(evaluation, tmp_path / "figures")
    assert [p.name for p in written] == [f"{name}.png" for name in plot.FIGURES]
    assert all(p.stat().st_size > 1000 for p in written)


def test_bad_axis_and_unit(evaluation: gyrodrift.Evaluation) -> None:
    with pytest.raises(ValueError, match="`axis` must be one of X, Y, Z"):
        plot.drift_per_interval(evaluation, axis="W")
    with pytest.raises(ValueError, match="unknown unit 'NOPE'"):
        plot.drift_per_interval(evaluation, unit="NOPE")
