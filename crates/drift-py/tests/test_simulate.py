"""Simulation from Python: the command line's campaign, flags and bytes."""

from __future__ import annotations

import json
import os
import subprocess
import time
from pathlib import Path

import pytest

import gyrodrift

TINY = {"units": 1, "set_points": [30.0], "intervals": [1.0], "repeats": 1}
TINY_PROTOCOL = {"protocol": {"activations": 2, "activation_s": 3.0}}


def test_default_is_the_papers_campaign() -> None:
    campaign = gyrodrift.resolve_campaign()
    assert campaign["units"] == 2 and campaign["set_points_celsius"] == [30.0, 40.0, 33.0]
    assert campaign["protocol"]["intervals_min"] == [1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0]
    assert campaign["field"] is None


def test_overrides_mean_what_the_flags_mean() -> None:
    campaign = gyrodrift.resolve_campaign(
        {"name": "mine"}, seed=9, units=3, set_points="-10:10:10", intervals=[2, 4], repeats=5
    )
    assert (campaign["name"], campaign["seed"], campaign["units"]) == ("mine", 9, 3)
    assert campaign["set_points_celsius"] == [-10.0, 0.0, 10.0]
    assert campaign["protocol"]["intervals_min"] == [2.0, 4.0] and campaign["protocol"]["repeats"] == 5
    assert gyrodrift.resolve_campaign(set_points="30,40")["set_points_celsius"] == [30.0, 40.0]
    field_only = gyrodrift.resolve_campaign(field_only=True, noise_scale=0)
    assert field_only["protocol"] is None and field_only["field"] is not None
    assert field_only["noise_scale"] == 0.0
    assert gyrodrift.resolve_campaign(zero_drift=True)["unit_model"] == "zero_systematic_drift"
    assert gyrodrift.resolve_campaign(paper_exact=True)["unit_model"] == "paper_exact"
    with pytest.raises(gyrodrift.InputError, match="`zero_drift` and `paper_exact`"):
        gyrodrift.resolve_campaign(zero_drift=True, paper_exact=True)
    effects = gyrodrift.resolve_campaign(effects=["thermal_lag", "ageing"])["effects"]
    assert effects["thermal_lag"] is not None and effects["ageing"] is not None


def test_campaign_from_toml_json_and_file(tmp_path: Path) -> None:
    toml = "seed = 4\nunits = 1\n[protocol]\nintervals_min = [3]\n"
    json_text = '{"seed": 4, "units": 1, "protocol": {"intervals_min": [3]}}'
    (tmp_path / "c.toml").write_text(toml)
    (tmp_path / "c.json").write_text(json_text)
    expected = gyrodrift.resolve_campaign({"seed": 4, "units": 1, "protocol": {"intervals_min": [3]}})
    assert gyrodrift.resolve_campaign(toml) == expected
    assert gyrodrift.resolve_campaign(json_text) == expected
    assert gyrodrift.resolve_campaign(tmp_path / "c.toml") == expected
    assert gyrodrift.resolve_campaign(tmp_path / "c.json") == expected


def simulate_tiny(out: Path, seed: int) -> Path:
    gyrodrift.simulate(out, TINY_PROTOCOL, seed=seed, **TINY)  # type: ignore[arg-type]
    return out / "recordings" / "GIU-01_sp+30.0C_protocol.mcap"


def test_same_seed_same_bytes_other_seed_other_bytes(tmp_path: Path) -> None:
    summary = gyrodrift.simulate(tmp_path / "a", TINY_PROTOCOL, seed=11, **TINY)  # type: ignore[arg-type]
    assert [Path(f["recording"]).name for f in summary["files"]] == ["GIU-01_sp+30.0C_protocol.mcap"]
    assert summary["samples"] == 2 * 3000
    a = (tmp_path / "a" / "recordings" / "GIU-01_sp+30.0C_protocol.mcap").read_bytes()
    assert simulate_tiny(tmp_path / "b", 11).read_bytes() == a
    assert simulate_tiny(tmp_path / "c", 12).read_bytes() != a


def test_same_bytes_as_the_command_line(tmp_path: Path) -> None:
    """`gyrodrift simulate` and `gyrodrift.simulate` with the same campaign and flags write the same
    recording, byte for byte. Needs the CLI binary: GYRODRIFT_BIN (scripts/check-python.sh sets it)."""
    binary = os.environ.get("GYRODRIFT_BIN")
    if not binary:
        pytest.skip("GYRODRIFT_BIN not set (scripts/check-python.sh builds and sets it)")
    (tmp_path / "campaign.toml").write_text("[protocol]\nactivations = 2\nactivation_s = 3.0\n")
    subprocess.run(
        [binary, "simulate", "-q", "-c", str(tmp_path / "campaign.toml"), "-o", str(tmp_path / "cli"),
         "--seed", "5", "--units", "1", "--set-points", "30", "--intervals", "1", "--repeats", "1"],
        check=True,
    )  # fmt: skip
    from_python = simulate_tiny(tmp_path / "py", 5)
    from_cli = tmp_path / "cli" / "recordings" / from_python.name
    assert from_cli.read_bytes() == from_python.read_bytes()


def test_a_campaign_already_there_is_refused_unless_force(tmp_path: Path) -> None:
    """One rule with the command line: a folder that is not empty is refused; `force=True`
    replaces a campaign there, never anything else."""
    first = simulate_tiny(tmp_path, 11).read_bytes()
    with pytest.raises(
        gyrodrift.InputError,
        match=r"is not empty \(recordings, summary.json, truth\): simulating into it would mix two "
        "campaigns; pass force=True to replace",
    ):
        gyrodrift.simulate(tmp_path, TINY_PROTOCOL, seed=12, **TINY)  # type: ignore[arg-type]
    assert (tmp_path / "recordings" / "GIU-01_sp+30.0C_protocol.mcap").read_bytes() == first
    gyrodrift.simulate(tmp_path, TINY_PROTOCOL, seed=12, force=True, **TINY)  # type: ignore[arg-type]
    assert (tmp_path / "recordings" / "GIU-01_sp+30.0C_protocol.mcap").read_bytes() != first
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(
        gyrodrift.InputError,
        match=r"holds files `simulate` does not write \(notes.txt\): force=True replaces only a campaign",
    ):
        gyrodrift.simulate(tmp_path, TINY_PROTOCOL, seed=13, force=True, **TINY)  # type: ignore[arg-type]
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_a_forced_campaign_is_written_beside_and_put_in_place_whole(tmp_path: Path) -> None:
    """As the command line: the new campaign is written into a staging folder beside `out`, which
    takes its place at the end; the summary (returned and stored) names the files in `out`."""
    out = tmp_path / "campaign"
    simulate_tiny(out, 11)
    (out / "recordings" / "stale.mcap").write_bytes(b"old")
    summary = gyrodrift.simulate(out, TINY_PROTOCOL, seed=12, force=True, **TINY)  # type: ignore[arg-type]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["campaign"], "no staging folder left"
    assert not (out / "recordings" / "stale.mcap").exists(), "replaced whole"
    stored = json.loads((out / "summary.json").read_text())
    for files in (summary["files"], stored["files"]):
        assert files and all(Path(f["recording"]).parent == out / "recordings" for f in files)
        assert all(Path(f["recording"]).exists() for f in files)


def test_a_campaign_too_large_is_refused_with_its_size_before_it_is_planned(tmp_path: Path) -> None:
    """A billion units would need tens of GB to plan: refused at once with what it would write,
    and nothing is made."""
    started = time.monotonic()
    with pytest.raises(gyrodrift.InputError, match=r"would write about [0-9.]+ TB .*above max_gb 20"):
        gyrodrift.simulate(tmp_path / "c", units=10**9)
    assert time.monotonic() - started < 10.0
    assert not (tmp_path / "c").exists()
    with pytest.raises(gyrodrift.InputError, match=r"`max_gb` must be > 0, got -1"):
        gyrodrift.simulate(tmp_path / "c", max_gb=-1.0)
