"""`ModifiedTables.check` / `PolynomialTables.check`: is a stored calibration still valid?"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

import gyrodrift
from conftest import recording_path
from gyrodrift import InputError

FIELDS = {
    "unit_id",
    "axis",
    "passed",
    "activations",
    "uncorrected_drift_dps",
    "corrected_drift_dps",
    "worst_drift_dps",
    "removed",
    "residual_rms_dps",
    "ambient_out_of_range",
    "rise_out_of_span",
    "past_last_reference",
    "history_unknown_or_out_of_span",
    "outside_envelope",
    "samples",
    "outside_envelope_samples",
    "faulty",
    "failures",
}


def test_the_fitted_tables_pass_on_data_they_did_not_see(
    campaign_dir: Path, evaluation: gyrodrift.Evaluation
) -> None:
    unit = evaluation.fitted[0]
    records = unit.modified.check(recording_path(campaign_dir, "+33.0"))
    assert [r["axis"] for r in records] == ["X", "Y", "Z"]
    for r in records:
        assert set(r) == FIELDS
        assert r["unit_id"] == "GIU-01" and r["activations"] == 12
        assert r["passed"] and r["failures"] == [], r
        assert 0 < r["corrected_drift_dps"] < r["uncorrected_drift_dps"]
        assert r["worst_drift_dps"] >= r["corrected_drift_dps"]
        assert r["removed"] == pytest.approx(1 - r["corrected_drift_dps"] / r["uncorrected_drift_dps"])
        assert r["samples"] > 0 and 0 <= r["outside_envelope_samples"] <= r["samples"]
        assert 0 <= r["outside_envelope"] <= r["activations"]
    # Segments in memory give the same records as the file.
    recording = gyrodrift.Recording.load(recording_path(campaign_dir, "+33.0"))
    assert unit.modified.check(recording) == records
    # A limit nobody meets fails every axis and says why.
    tight = unit.modified.check(recording, max_drift=1e-6)
    assert not any(r["passed"] for r in tight)
    assert all(r["failures"][0].startswith("drift left") for r in tight), tight
    # The baselines are checked the same way, through their own corrector.
    standard = unit.standard.check(recording, max_drift=1.0, max_rms=1.0, min_removed=0.0)
    assert [r["activations"] for r in standard] == [12, 12, 12]
    assert all(s["corrected_drift_dps"] != m["corrected_drift_dps"] for s, m in zip(standard, records))


def test_python_and_command_line_agree(
    campaign_dir: Path, evaluation: gyrodrift.Evaluation, tmp_path: Path
) -> None:
    """Same tables, same recording: the records equal `gyrodrift check`'s JSON, with its defaults
    (the recommended model)."""
    binary = os.environ.get("GYRODRIFT_BIN")
    if not binary:
        pytest.skip("GYRODRIFT_BIN not set (scripts/check-python.sh builds and sets it)")
    unit = evaluation.fitted[0]
    (tmp_path / "tables" / "GIU-01").mkdir(parents=True)
    unit.recommended.save_image(tmp_path / "tables" / "GIU-01" / "recommended.bin")
    recordings = tmp_path / "recordings"
    recordings.mkdir()
    (recordings / "a.mcap").write_bytes(recording_path(campaign_dir, "+33.0").read_bytes())
    tables, out = tmp_path / "tables", tmp_path / "out"
    subprocess.run(
        [binary, "check", str(recordings), "--tables", str(tables), "-q", "-o", str(out)],
        check=True,
        capture_output=True,
    )
    cli = json.loads((tmp_path / "out" / "check.json").read_text())["units"][0]["axes"]
    ours = unit.recommended.check(recordings)
    for mine, theirs in zip(ours, cli):
        for key in ("corrected_drift_dps", "residual_rms_dps", "removed", "activations", "failures"):
            assert mine[key] == theirs[key], key


def test_bad_arguments_are_input_errors(campaign_dir: Path, evaluation: gyrodrift.Evaluation) -> None:
    unit = evaluation.fitted[0]
    source = recording_path(campaign_dir, "+33.0")
    with pytest.raises(InputError, match=r"`max_drift` must be a finite number ≥ 0, got -1"):
        unit.modified.check(source, max_drift=-1.0)
    with pytest.raises(InputError, match=r"`min_removed` must be a share 0…1 .*, got NaN"):
        unit.modified.check(source, min_removed=float("nan"))
    with pytest.raises(InputError, match=r"`min_removed` must be a share 0…1 .*, got 2"):
        unit.modified.check(source, min_removed=2.0)
    with pytest.raises(InputError, match="`source` must be"):
        unit.modified.check(42)  # type: ignore[arg-type]
    first = gyrodrift.Recording.load(source).segments[0]
    stranger = gyrodrift.Segment(
        gyrodrift.Labels(unit_id="GIU-99", set_point_celsius=33.0), first.rate_dps, first.temperature_raw
    )
    with pytest.raises(InputError, match=r"one unit's activations .* `GIU-01` and `GIU-99`"):
        unit.modified.check([first, stranger])
    supply = gyrodrift.ExtraTerm("aux", 0, centre=(5.0, 5.0, 5.0), coefficient=(0.01, 0.0, 0.0))
    with pytest.raises(InputError, match="reads auxiliary input 0"):
        unit.modified.with_extension([supply]).check(source)
