"""Every example script runs to completion, headless, from a fresh interpreter."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


def test_there_are_examples() -> None:
    assert EXAMPLES


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_runs(script: Path) -> None:
    env = {**os.environ, "MPLBACKEND": "Agg"}
    result = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip()


def test_correct_activation_reports_each_model() -> None:
    script = next(p for p in EXAMPLES if p.name == "correct_activation.py")
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, check=True).stdout
    rows = {
        line.split()[0]: line.split()[1:3] for line in out.splitlines() if line[:1].isalpha() and "  " in line
    }
    for name in ("uncorrected", "modified", "standard", "third_order"):
        assert name in rows, out
    # The drift-aware model leaves less error than no correction at the end of the warm-up.
    assert float(rows["modified"][1]) < float(rows["uncorrected"][1]), out


def test_report_table_prints_the_papers_table() -> None:
    script = next(p for p in EXAMPLES if p.name == "report_table.py")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    out = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, check=True, env=env, timeout=120
    ).stdout
    rows = {
        tuple(cell.strip() for cell in line.strip("|").split("|")[:3]): line.strip("|").split("|")[3:]
        for line in out.splitlines()
        if line.startswith("| ")
    }
    assert ("calibration", "set point", "data") in rows, out
    for model in ("standard", "modified"):
        for set_point, data in (
            ("+30 °C", "held-out repeat"),
            ("+33 °C", "validation"),
            ("+40 °C", "held-out repeat"),
        ):
            assert len(rows[(model, set_point, data)]) == 3, out  # one column per axis of the one unit
    standard = [float(v) for v in rows[("standard", "+33 °C", "validation")]]
    modified = [float(v) for v in rows[("modified", "+33 °C", "validation")]]
    assert all(m < s for m, s in zip(modified, standard)), out
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        assert "figures skipped" in out
    else:
        assert "saved 5 figures" in out


def test_production_line_fits_every_unit_on_two_workers() -> None:
    script = next(p for p in EXAMPLES if p.name == "production_line.py")
    out = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, check=True, timeout=120
    ).stdout
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        assert "pip install 'gyrodrift[distributed]'" in out, out
        return
    rows = [line.split(" | ") for line in out.splitlines() if line.startswith("| GIU-")]
    assert [r[0] for r in rows] == ["| GIU-01", "| GIU-02", "| GIU-03"], out
    assert all(r[2] == "XYZ" for r in rows), out  # every axis passes the check on +33 °C
    # six stored models per unit: recommended, modified, by history, standard, third order, relative
    assert "3 units on 2 workers" in out and "wrote 18 firmware images" in out, out
