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
