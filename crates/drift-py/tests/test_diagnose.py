"""FittedUnit.diagnose: the command line's `gyrodrift diagnose --extend` from Python, on a campaign
with a supply-voltage sensitivity the fitter is never told about."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gyrodrift

CAMPAIGN = """
name = "py-diagnose"
seed = 3
units = 1
set_points_celsius = [30.0, 40.0, 33.0]
[protocol]
intervals_min = [1.0, 5.0, 30.0]
repeats = 2
[field]
sessions = 3
ambient_ramp_c_per_min = 0.0
carry_probability = 0.0
[effects.supply_voltage]
dps_per_v = 0.04
"""


@pytest.fixture(scope="module")
def campaign(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("diagnose")
    gyrodrift.simulate(out, CAMPAIGN)
    return out


@pytest.fixture(scope="module")
def diagnosis(campaign: Path) -> gyrodrift.Diagnosis:
    (unit,) = gyrodrift.fit(campaign)
    return unit.diagnose(gyrodrift.load_campaign(campaign), extend=True)


def test_the_hidden_supply_effect_is_found_admitted_and_lowers_the_held_out_error(
    diagnosis: gyrodrift.Diagnosis,
) -> None:
    chosen = dict(diagnosis.chosen)
    found = [axis for axis, name in chosen.items() if name == "aux:supply_voltage"]
    assert len(found) >= 2, diagnosis.ranking
    assert "aux:supply_voltage" in diagnosis.proposed_terms
    assert "supply_voltage" in diagnosis.aux_inputs
    admitted = {(a["candidate"], a["axis"]) for a in diagnosis.admissions if a["admitted"]}
    assert all(("aux:supply_voltage", axis) in admitted for axis in found), diagnosis.admissions
    # An auxiliary input is admitted on the squared residual; a shape term (a rate, rise², another
    # axis's rise, a channel times the rise) on the drift: where the diagnosis found it, that
    # metric falls on the held-out folds; elsewhere it falls significantly. Every decision says why.
    for a in diagnosis.admissions:
        shape = not a["candidate"].startswith("aux:") or " × " in a["candidate"]
        assert a["reason"], a
        if a["admitted"]:
            if a["reason"].startswith("significant in the diagnosis"):
                assert (a["drift_gain_dps"] if shape else a["improvement"]) > 0, a
            else:
                assert (a["drift_p_value"] if shape else a["p_value"]) < 0.05, a
    extended = diagnosis.extended
    assert extended is not None and len(extended.extension) >= 1
    verdict = diagnosis.extended_verdict
    assert verdict is not None and verdict.startswith("admitted "), verdict
    assert all(f"{c} on {axis}" in verdict for c, axis in admitted), verdict
    assert verdict.endswith(f"(firmware image `extended-{diagnosis.unit_id}.bin`)"), verdict
    # The error before/after on the held-out +33 °C field activations, per axis where it was found.
    field33 = [
        r for r in diagnosis.before_after if r["series_kind"] == "field" and r["set_point_celsius"] == 33.0
    ]
    assert field33
    for r in field33:
        assert len(r["mean_dps"]) == 3 and len(r["residual_heat_celsius"]) == 3, r
        assert all(h >= 0.0 for h in r["residual_heat_celsius"]), r
        assert r["off_before_s"] is None or r["off_before_s"] > 0.0, r
    for axis in found:
        a = "XYZ".index(axis)
        before = sum(r["rms_dps"][a][0] for r in field33) / len(field33)
        after = sum(r["rms_dps"][a][1] for r in field33) / len(field33)
        assert after < 0.8 * before, (axis, before, after)


def test_profiles_place_the_held_out_residual_in_time_since_switch_on(
    diagnosis: gyrodrift.Diagnosis,
) -> None:
    profiles = diagnosis.profiles
    edges = profiles["edges_s"]
    assert edges[0] == 0.0 and np.isinf(edges[-1]) and np.all(np.diff(edges) > 0)
    after = profiles["after_dps"]
    n = dict(diagnosis.activations)["held_out"]
    assert after.shape == (n, 3, len(edges) - 1) and after.dtype == np.float64
    assert len(profiles["series_kind"]) == n == profiles["off_before_s"].shape[0]
    assert set(profiles["series_kind"]) <= {"protocol", "field"}
    # Every activation outlasts the first minute, and a residual less its own mean has bins on
    # both sides of zero unless it is flat.
    first_minute = after[:, :, :10]
    assert np.all(np.isfinite(first_minute))
    assert np.all(np.abs(first_minute) < 0.05), np.abs(first_minute).max()
    assert np.any(first_minute > 0.0) and np.any(first_minute < 0.0)


def test_the_ranking_is_records_with_every_axis(diagnosis: gyrodrift.Diagnosis) -> None:
    records = diagnosis.ranking
    assert {r["axis"] for r in records} == {"X", "Y", "Z"}
    first = [r for r in records if r["rank"] == 1]
    assert len(first) == 3
    assert set(records[0]) >= {
        "candidate",
        "level",
        "explained",
        "family_p_value",
        "p_value",
        "whole_p_value",
        "stable",
        "detectable_share",
        "drift_p_value",
        "significant",
        "thermal_response",
        "absorbed_by_model",
        "size_threshold",
        "baseline_explained_within",
        "baseline_explained_between",
    }
    # Selected means beating the shuffles' winners and reaching the size threshold over the
    # baseline, with the same sign in every fold.
    assert all(
        r["family_p_value"] <= 0.05 and r["explained"] >= r["size_threshold"] and r["stable"]
        for r in records
        if r["significant"]
    )
    # The unit's own thermal response is selected before the effects, so on an axis every
    # selected response ranks above every selected effect.
    for axis in "XYZ":
        ranked = sorted((r for r in records if r["axis"] == axis), key=lambda r: r["rank"])
        kinds = [r["thermal_response"] for r in ranked if r["significant"]]
        assert kinds == sorted(kinds, reverse=True), ranked[:4]
    assert all(0.0 <= r["baseline_explained_within"] <= 1.0 for r in records)
    assert all(0.0 <= r["detectable_share"] < 1.0 for r in records)
    counts = dict(diagnosis.activations)
    assert counts["diagnosed"] == counts["training"] > 0
    assert "Diagnosis GIU-01" in repr(diagnosis)


def test_stage_3_is_chosen_per_axis_on_the_training_activations(
    diagnosis: gyrodrift.Diagnosis,
) -> None:
    stage3 = diagnosis.stage3
    assert [c["axis"] for c in stage3] == ["X", "Y", "Z"]
    counts = dict(diagnosis.activations)
    for c in stage3:
        assert c["training_activations"] == counts["training"]
        # Keyed by history only where that leaves less drift, significantly.
        if c["keyed_by_history"]:
            assert c["training_drift_by_history_dps"] < c["training_drift_by_rise_dps"], c
            assert c["p_value"] < 0.05, c
            assert diagnosis.extended is not None


def test_the_initial_bias_is_chosen_per_axis_after_stage_3(
    diagnosis: gyrodrift.Diagnosis,
) -> None:
    warm_start = diagnosis.warm_start
    assert [c["axis"] for c in warm_start] == ["X", "Y", "Z"]
    counts = dict(diagnosis.activations)
    for c in warm_start:
        assert c["training_activations"] == counts["training"]
        assert c["training_rms_cold_dps"] > 0.0 and c["training_rms_warm_dps"] > 0.0, c
        # The warm starts' initial bias only where it leaves less error, significantly.
        if c["chosen"]:
            assert c["training_rms_warm_dps"] < c["training_rms_cold_dps"], c
            assert c["p_value"] < 0.05, c
            assert diagnosis.extended is not None
            axis = "XYZ".index(c["axis"])
            tables = json.loads(diagnosis.extended.to_json())
            assert tables["axes"][axis]["ambients"][0]["warm_starts"], c


def test_the_paper_models_ranking_stands_beside_the_loops(
    diagnosis: gyrodrift.Diagnosis,
) -> None:
    paper, loop = diagnosis.paper_ranking, diagnosis.ranking

    def candidates(records: list[dict[str, Any]]) -> list[tuple[str, str]]:
        return sorted((r["axis"], r["candidate"]) for r in records)

    assert candidates(paper) == candidates(loop)
    changed = any(c["keyed_by_history"] for c in diagnosis.stage3) or any(
        c["chosen"] for c in diagnosis.warm_start
    )
    # Behind another model the residual differs, and so do the scores.
    assert (paper != loop) == changed


def test_a_unit_without_activations_is_an_input_error(campaign: Path) -> None:
    (unit,) = gyrodrift.fit(campaign)
    calibration_only = [
        s
        for recording in gyrodrift.load_campaign(campaign)
        for s in recording.segments
        if s.labels.series_kind == "protocol" and s.labels.set_point_celsius != 33.0
    ]
    assert calibration_only
    with pytest.raises(gyrodrift.InputError, match="outside the calibration protocol"):
        unit.diagnose(calibration_only)
    with pytest.raises(gyrodrift.InputError, match="`segments`"):
        unit.diagnose(42)  # type: ignore[arg-type]


def test_save_writes_the_command_lines_report_of_the_unit(
    diagnosis: gyrodrift.Diagnosis, tmp_path: Path
) -> None:
    # The same renderer as `gyrodrift diagnose`: its Markdown, its JSON record per unit, a residual
    # figure per axis whose top candidate the model does not absorb, and the extended model's image.
    report = diagnosis.save(tmp_path / "out")
    assert report == tmp_path / "out" / "diagnosis.md"
    text = report.read_text()
    assert text.startswith("# gyrodrift diagnosis")
    assert f"# Unit {diagnosis.unit_id}" in text
    assert "## Extended model of unit" in text
    (record,) = json.loads((tmp_path / "out" / "diagnosis.json").read_text())
    assert record["unit"] == diagnosis.unit_id
    assert [a["axis"] for a in record["axes"]] == ["X", "Y", "Z"]
    figures = sorted(p.name for p in (tmp_path / "out").glob("residual-*.svg"))
    assert figures, text
    for name in figures:
        assert f"]({name})" in text
    if diagnosis.extended is not None:
        image = tmp_path / "out" / f"extended-{diagnosis.unit_id}.bin"
        assert image.stat().st_size > 0
        assert f"extended-{diagnosis.unit_id}.bin" in text


# The paper's model is exact for this unit and no hidden effect is on: nothing to extend.
PLAIN = """
name = "py-diagnose-plain"
seed = 3
units = 1
unit_model = "paper_exact"
set_points_celsius = [30.0, 40.0, 33.0]
[protocol]
intervals_min = [1.0, 30.0]
repeats = 2
activation_s = 60.0
[field]
sessions = 2
ambient_ramp_c_per_min = 0.0
carry_probability = 0.0
"""


def test_when_nothing_is_extended_the_reason_is_given_and_saved(tmp_path: Path) -> None:
    campaign = tmp_path / "plain"
    gyrodrift.simulate(campaign, PLAIN)
    (unit,) = gyrodrift.fit(campaign)
    diagnosis = unit.diagnose(gyrodrift.load_campaign(campaign), extend=True)
    assert diagnosis.proposed_terms == [] and diagnosis.admissions == []
    assert diagnosis.extended is None
    assert diagnosis.extended_verdict == (
        "no term proposed (nothing significant maps to a term the firmware can compute); "
        "the paper's model unchanged"
    )
    text = diagnosis.save(tmp_path / "out").read_text()
    section = text[text.index(f"## Extended model of unit {diagnosis.unit_id}") :]
    assert "Nothing significant maps to a term the firmware can compute" in section
    assert "The paper's model is kept unchanged." in section
    assert not list((tmp_path / "out").glob("extended-*"))
