"""The command line and Python write the same files through one shared function each: the tables
folder (`gyrodrift fit` / `FittedUnit.save`), the firmware images (`.bin` / `to_image`) and the
report (`gyrodrift report` / `gyrodrift.report`). Needs the CLI binary: GYRODRIFT_BIN
(scripts/check-python.sh builds and sets it)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

import gyrodrift


def cli(*args: str) -> None:
    binary = os.environ.get("GYRODRIFT_BIN")
    if not binary:
        pytest.skip("GYRODRIFT_BIN not set (scripts/check-python.sh builds and sets it)")
    subprocess.run([binary, *args, "-q"], check=True)


# Written by the command line alone: the marker that a folder is its own output (so that
# `--force` may replace it) and the calibration recordings' lengths and CRCs, which `check`
# reads to say when it runs on the tables' own calibration data.
COMMAND_LINE_ONLY = {".gyrodrift-output", "calibration-data.json"}


def files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name not in COMMAND_LINE_ONLY
    }


def test_fit_and_save_write_the_same_tables_folder(campaign_dir: Path, tmp_path: Path) -> None:
    cli("fit", str(campaign_dir), "-o", str(tmp_path / "cli"))
    for unit in gyrodrift.fit(campaign_dir):
        unit.save(tmp_path / "py")
    written = files(tmp_path / "cli")
    assert set(written) == {
        f"GIU-01/{model}.{ext}"
        for model in ("recommended", "modified", "by_history", "standard", "third_order", "relative")
        for ext in ("json", "bin")
    }
    assert written == files(tmp_path / "py")


def test_the_images_in_the_folder_are_the_models_images(campaign_dir: Path, tmp_path: Path) -> None:
    unit = gyrodrift.fit(campaign_dir)[0]
    folder = unit.save(tmp_path)
    for name, model in [
        ("modified", unit.modified),
        ("by_history", unit.by_history),
        ("standard", unit.standard),
        ("third_order", unit.third_order),
    ]:
        image = (folder / f"{name}.bin").read_bytes()
        # The folder's images name their unit in the 64-byte header; a model's own image names none.
        assert image[64:-4] == model.to_image()[64:-4]
        assert image[40:64].rstrip(b"\0").decode() == unit.unit_id
        assert type(model).from_image(image) == model


def test_report_writes_what_the_command_line_writes(campaign_dir: Path, tmp_path: Path) -> None:
    cli("report", str(campaign_dir), "-o", str(tmp_path / "cli"))
    path = gyrodrift.report(str(campaign_dir), tmp_path / "py")
    assert path == tmp_path / "py" / "report.md"
    from_cli, from_python = files(tmp_path / "cli"), files(tmp_path / "py")
    # How long each step took is the one thing that differs from run to run.
    assert set(from_cli) == set(from_python) and "timings.json" in from_cli
    del from_cli["timings.json"], from_python["timings.json"]
    assert {"report.md", "report.json", "absolute_error.json", "tables/GIU-01/modified.bin"} <= set(from_cli)
    assert from_cli == from_python
