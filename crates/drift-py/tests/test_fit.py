"""Fitting from Python: the command line's fit, from files or from recordings in memory."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import gyrodrift
from conftest import recording_path


def test_fit_a_campaign_folder(campaign_dir: Path) -> None:
    (unit,) = gyrodrift.fit(campaign_dir)
    assert unit.unit_id == "GIU-01"
    assert unit.set_points_celsius == [30.0, 40.0]
    assert "independent" in unit.curve_names and "1min#2" in unit.curve_names
    assert isinstance(unit.modified, gyrodrift.ModifiedTables)
    assert isinstance(unit.standard, gyrodrift.PolynomialTables)
    assert isinstance(unit.third_order, gyrodrift.PolynomialTables)
    assert unit.settings == gyrodrift.FitSettings()


def test_the_tables_and_their_images_state_the_recordings_sample_rate(
    campaign_dir: Path, tmp_path: Path
) -> None:
    (unit,) = gyrodrift.fit(campaign_dir)
    for model in (unit.modified, unit.by_history, unit.standard, unit.third_order, unit.relative):
        assert model.settings.sample_rate_hz == 1000.0
        assert type(model).from_image(model.to_image()).settings.sample_rate_hz == 1000.0
    unit.save(tmp_path / "tables")
    stored = gyrodrift.ModifiedTables.load_image(tmp_path / "tables" / "GIU-01" / "modified.bin")
    assert stored.settings.sample_rate_hz == 1000.0


def test_files_and_memory_give_the_same_tables(campaign_dir: Path) -> None:
    (from_files,) = gyrodrift.fit(campaign_dir)
    (from_memory,) = gyrodrift.fit(gyrodrift.load_campaign(campaign_dir))
    assert from_memory.modified == from_files.modified
    assert from_memory.standard == from_files.standard
    assert from_memory.third_order == from_files.third_order
    calibration = [recording_path(campaign_dir, "+30.0"), recording_path(campaign_dir, "+40.0")]
    (from_list,) = gyrodrift.fit(calibration)
    assert from_list.modified == from_files.modified


def test_settings_are_the_command_lines(campaign_dir: Path) -> None:
    defaults = gyrodrift.FitSettings()
    assert defaults == gyrodrift.FitSettings.from_json("{}")
    assert json.loads(defaults.to_json()) == {
        "lowpass_window_s": 1.0,
        "grid_ms": 10,
        "initial_bias_window_s": 4.0,
        "switch_on_window_ms": 20,
        "first_reference_s": 2.0,
        "reference_count": 8,
        "reference_window_points": 10,
        "independent_after_min": 15.0,
        "polynomial_degree": 3,
    }
    settings = gyrodrift.FitSettings(reference_count=4, polynomial_degree=2)
    assert gyrodrift.FitSettings.from_json(settings.to_json()) == settings
    (unit,) = gyrodrift.fit(campaign_dir, settings=settings)
    tables = json.loads(unit.modified.to_json())
    assert [len(axis["reference_ms"]) for axis in tables["axes"]] == [4, 4, 4]
    assert [len(axis["coefficients"]) for axis in json.loads(unit.third_order.to_json())["axes"]] == [3, 3, 3]


def test_fitted_models_save_like_the_command_line(campaign_dir: Path, tmp_path: Path) -> None:
    (unit,) = gyrodrift.fit(campaign_dir)
    folder = unit.save(tmp_path)
    assert folder == tmp_path / "GIU-01"
    names = sorted(
        f"{model}.{kind}"
        for model in ("recommended", "modified", "by_history", "standard", "third_order", "relative")
        for kind in ("bin", "json")
    )
    assert sorted(p.name for p in folder.iterdir()) == names
    assert gyrodrift.ModifiedTables.load_image(folder / "modified.bin") == unit.modified
    assert gyrodrift.ModifiedTables.load_image(folder / "by_history.bin") == unit.by_history
    assert unit.by_history != unit.modified
    assert gyrodrift.PolynomialTables.load_json(folder / "third_order.json") == unit.third_order


def test_analyse_one_activation(campaign_dir: Path) -> None:
    segment = gyrodrift.Recording.load(recording_path(campaign_dir)).segments[0]
    analysed = gyrodrift.analyse(segment)
    assert analysed.labels == segment.labels and analysed.grid_ms == 10
    assert len(analysed) == len(segment) // 10
    assert analysed.drift_dps.shape == analysed.rise_celsius.shape == (len(analysed), 3)
    assert np.allclose(analysed.time_s[:3], [0.0, 0.01, 0.02])
    assert (analysed.rise_celsius[-1] > 0.1).all()  # the unit warms up
    assert abs(analysed.switch_on_celsius[0] - 30.0) < 5.0


def test_the_relative_baseline_is_fitted_saved_and_corrects(campaign_dir: Path, tmp_path: Path) -> None:
    (unit,) = gyrodrift.fit(campaign_dir)
    relative = unit.relative
    assert isinstance(relative, gyrodrift.RelativePolynomialTables)
    folder = unit.save(tmp_path)
    assert gyrodrift.RelativePolynomialTables.load_image(folder / "relative.bin") == relative
    assert gyrodrift.RelativePolynomialTables.from_json(relative.to_json()) == relative
    # Its image is its own kind: read as another model, it is refused by name.
    with pytest.raises(
        gyrodrift.ImageError, match=r"holds the relative polynomial baseline \(relative.bin\)"
    ):
        gyrodrift.PolynomialTables.load_image(folder / "relative.bin")
    segment = gyrodrift.Recording.load(recording_path(campaign_dir)).segments[0]
    corrector = gyrodrift.Corrector(relative)
    assert corrector.model == relative
    corrector.power_on(segment.temperature_raw[0])
    corrected, bias, _ = corrector.correct_batch(
        segment.since_power_on_ms, segment.rate_dps, segment.temperature_raw
    )
    # bias = q(T_on) + p(T) − p(T_on): at switch-on it is the registered turn-on bias alone.
    assert np.allclose(bias[0], corrector.initial_bias_dps, atol=1e-6)
    assert np.array_equal(corrected, segment.rate_dps - bias)
    # On its own calibration data it leaves a small offset (the static unit's rate is its bias).
    assert np.all(np.abs(corrected.mean(axis=0)) < 0.02)
