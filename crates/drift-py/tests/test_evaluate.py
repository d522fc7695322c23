"""Evaluation from Python: the report's table as data (records, DataFrame) and per activation."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import gyrodrift
from conftest import recording_path

KEYS = {"unit", "set_point_celsius", "split", "model", "axis", "drift_dps", "residual_rms_dps", "activations"}


def test_records_cover_every_split_model_and_axis(evaluation: gyrodrift.Evaluation) -> None:
    records = evaluation.records
    assert records and all(set(r) == KEYS for r in records)
    assert {(r["split"], r["set_point_celsius"]) for r in records} == {
        ("held_out_repeat", 30.0),
        ("held_out_repeat", 40.0),
        ("validation", 33.0),
    }
    assert {r["model"] for r in records} == {
        "uncorrected",
        "standard",
        "3rd-order",
        "relative",
        "relative-cubic",
        "modified",
        "by-history",
        "recommended",
    }
    assert {r["axis"] for r in records} == {"X", "Y", "Z"}
    assert len(evaluation.fitted) == 1 and len(evaluation.calibration) == 24
    assert len(evaluation.results) == 36  # 12 activations per set point


def test_the_papers_method_beats_no_correction(evaluation: gyrodrift.Evaluation) -> None:
    def mean(model: str) -> float:
        values = [
            r["drift_dps"] for r in evaluation.records if r["split"] == "validation" and r["model"] == model
        ]
        return sum(values) / len(values)

    assert mean("modified") < mean("uncorrected")


def test_per_activation_evaluation_and_summarise_agree(
    campaign_dir, evaluation: gyrodrift.Evaluation
) -> None:  # type: ignore[no-untyped-def]
    unit = evaluation.fitted[0]
    validation = gyrodrift.Recording.load(recording_path(campaign_dir, "+33.0"))
    results = unit.evaluate_series(validation.segments)
    assert {r.split for r in results} == {"validation"}
    assert set(results[0].drift_dps) == {
        "uncorrected",
        "standard",
        "3rd-order",
        "relative",
        "relative-cubic",
        "modified",
        "by-history",
        "recommended",
    }
    expected = [r for r in evaluation.records if r["split"] == "validation"]
    assert gyrodrift.summarise(results) == expected


def test_results_carry_labels_and_flags(evaluation: gyrodrift.Evaluation) -> None:
    held_out = [r for r in evaluation.results if r.split == "held_out_repeat"]
    assert {r.labels.repeat for r in held_out} == {1, 2}
    assert all(r.flags["uncorrected"] == (0, 0, 0) for r in held_out)


def test_dataframe_with_pandas(evaluation: gyrodrift.Evaluation) -> None:
    pd = pytest.importorskip("pandas")
    frame = evaluation.to_dataframe()
    assert isinstance(frame, pd.DataFrame)
    assert set(frame.columns) == KEYS and len(frame) == len(evaluation.records)
    table = frame[frame.split == "validation"].pivot_table(index="model", columns="axis", values="drift_dps")
    assert table.loc["modified", "X"] < table.loc["uncorrected", "X"]


def test_dataframe_without_pandas(evaluation: gyrodrift.Evaluation, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)  # `import pandas` now fails
    with pytest.raises(ImportError, match="needs pandas"):
        evaluation.to_dataframe()
    assert evaluation.records  # the records need nothing


def test_paper_table(evaluation: gyrodrift.Evaluation) -> None:
    table = gyrodrift.paper_table(evaluation.records)
    lines = table.splitlines()
    assert lines[0] == "| calibration | set point | data | GIU-01 X | GIU-01 Y | GIU-01 Z |"
    rows = [line.split(" | ")[:3] for line in lines[2:]]
    assert rows[:3] == [["| standard", "+30 °C", "held-out repeat"], ["| standard", "+33 °C", "validation"],
                        ["| standard", "+40 °C", "held-out repeat"]]  # fmt: skip
    models = ["| standard", "| 3rd-order", "| relative", "| modified", "| best baseline / modified"]
    assert [r[0] for r in rows] == [m for m in models for _ in range(3)]
    # Each ratio names the baseline it was taken against, the best of the three on that cell.
    assert all(cell.strip().split(" ")[1] in ("(standard)", "(3rd-order)", "(relative)")
               for cell in lines[-1].split("|")[4:-1])  # fmt: skip


def test_the_history_keyed_model_starts_from_what_was_kept(
    campaign_dir: Path, evaluation: gyrodrift.Evaluation
) -> None:
    """`previous` reaches the history-keyed model only: without it the start is unknown (flagged),
    from a known full cool-down it is known; a bad shape is named."""
    unit = evaluation.fitted[0]
    segment = gyrodrift.Recording.load(recording_path(campaign_dir, "+33.0")).segments[0]
    unknown = unit.evaluate(segment)
    assert unit.evaluate_series([segment])[0].drift_dps["modified"] == unknown.drift_dps["modified"]
    history_unknown = gyrodrift.Flags.HISTORY_UNKNOWN
    assert all(f & history_unknown for f in unknown.flags["by-history"])
    assert not any(f & history_unknown for f in unknown.flags["modified"])
    cooled = np.array([[np.nan, -np.inf]] * 3)
    known = unit.evaluate(segment, previous=cooled)
    assert not any(f & history_unknown for f in known.flags["by-history"])
    assert known.drift_dps["modified"] == unknown.drift_dps["modified"]
    with pytest.raises(ValueError, match="previous"):
        unit.evaluate(segment, previous=np.zeros((2, 3)))
