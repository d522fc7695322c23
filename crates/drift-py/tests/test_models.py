"""Models: JSON and firmware-image round trips, files, settings."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import gyrodrift
from conftest import Model
from gyrodrift import ModifiedTables, PolynomialTables, Settings


@pytest.mark.parametrize("name", ["modified", "standard", "third_order"])
def test_json_round_trip(models: dict[str, Model], name: str) -> None:
    model = models[name]
    text = model.to_json()
    assert json.loads(text)["settings"]["stuck_after_samples"] == model.settings.stuck_after_samples
    assert type(model).from_json(text) == model


@pytest.mark.parametrize("name", ["modified", "standard", "third_order"])
def test_image_round_trip(models: dict[str, Model], name: str) -> None:
    model = models[name]
    image = model.to_image()
    assert image[:4] == b"GYDT"
    assert type(model).from_image(image) == model


@pytest.mark.parametrize("name", ["modified", "standard"])
def test_file_round_trips(tmp_path: Path, models: dict[str, Model], name: str) -> None:
    model = models[name]
    cls = type(model)
    model.save_json(tmp_path / "model.json")
    model.save_image(str(tmp_path / "model.bin"))  # str or os.PathLike
    assert cls.load_json(tmp_path / "model.json") == model
    assert cls.load_image(str(tmp_path / "model.bin")) == model
    assert (tmp_path / "model.bin").read_bytes() == model.to_image()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.bin", "model.json"]  # no temporaries


def test_saving_replaces_an_existing_file(tmp_path: Path, models: dict[str, Model]) -> None:
    path = tmp_path / "model.bin"
    models["standard"].save_image(path)
    models["third_order"].save_image(path)
    assert PolynomialTables.load_image(path) == models["third_order"]


def test_equality_is_by_value(models: dict[str, Model]) -> None:
    assert models["standard"] != models["third_order"]
    assert models["modified"] != models["standard"]
    assert models["standard"] == PolynomialTables.from_json(models["standard"].to_json())


def test_settings_defaults_match_drift_core() -> None:
    settings = Settings()
    assert settings.raw_per_celsius == 200.0
    assert settings.raw_at_zero_celsius == 0.0
    assert settings.ambient_margin_celsius == pytest.approx(0.5)
    assert settings.rise_margin_celsius == pytest.approx(0.05)
    assert settings.stuck_after_samples == 2000
    assert settings.celsius(6000.0) == 30.0
    assert "stuck_after_samples=2000" in repr(settings)


def test_with_settings_changes_only_the_settings(modified: ModifiedTables) -> None:
    changed = modified.with_settings(Settings(stuck_after_samples=0, raw_per_celsius=100.0))
    assert changed.settings == Settings(stuck_after_samples=0, raw_per_celsius=100.0)
    assert changed != modified
    original = json.loads(modified.to_json())
    updated = json.loads(changed.to_json())
    assert original["axes"] == updated["axes"]
    assert modified.settings.stuck_after_samples == 20  # the original is untouched (immutable)


def test_repr_summarises_the_tables(models: dict[str, Model]) -> None:
    assert repr(models["modified"]) == (
        "<ModifiedTables reference times x ambients x curves per axis: 8x3x16, 8x3x16, 8x3x16>"
    )
    assert "3 coefficients over [20.0, 40.0]" in repr(models["standard"])


def test_corrector_exposes_its_model_and_state(models: dict[str, Model]) -> None:
    corrector = gyrodrift.Corrector(models["standard"])
    assert corrector.model == models["standard"] and not corrector.is_powered_on
    assert repr(corrector) == "<Corrector PolynomialTables, not powered on>"
    assert corrector.power_on((5400.0, 5400.0, 5400.0)) == (0, 0, 0)  # 27 °C, inside 20..40
    assert corrector.is_powered_on and corrector.switch_on_raw == (5400.0, 5400.0, 5400.0)
    # The standard baseline's initial bias is its polynomial at the switch-on temperature.
    x = (27.0 - 30.0) / 10.0
    assert corrector.initial_bias_dps[0] == pytest.approx(0.124 + 0.02 * x + 0.003 * x * x, abs=1e-6)
    corrector.power_off()
    assert not corrector.is_powered_on
    out = corrector.correct(5, (0.25, 0.5, 1.0), (5400.0, 5400.0, 5400.0))
    assert out.corrected_dps == (0.25, 0.5, 1.0)
    assert all(f == gyrodrift.Flags.NOT_POWERED_ON for f in out.flags)


def test_corrector_power_on_at_a_measured_ambient(modified: ModifiedTables) -> None:
    raw = (6600.0, 6600.0, 6600.0)  # 33 °C
    sample = (20_000, (0.5, 0.0, 0.0), (6700.0, 6700.0, 6700.0))

    def bias(**start: float) -> tuple[float, float, float]:
        corrector = gyrodrift.Corrector(modified)
        corrector.power_on(raw, **start)
        return corrector.correct(*sample).bias_dps

    # At the switch-on temperature it is the paper's start; 3 °C of residual heat over the air
    # moves stage 2 and the initial bias.
    assert bias(ambient_celsius=33.0) == bias()
    assert bias(ambient_celsius=30.0) != bias()
    corrector = gyrodrift.Corrector(modified)
    with pytest.raises(gyrodrift.InputError, match="`ambient_celsius` must be finite, got NaN"):
        corrector.power_on(raw, ambient_celsius=float("nan"))
    assert not corrector.is_powered_on
    nothing = np.full((3, 2), np.nan, dtype=np.float32)
    flags, kept = corrector.power_on_after(raw, nothing, ambient_celsius=30.0)
    assert kept[:, 0].tolist() == [30.0, 30.0, 30.0]
    assert flags == (0, 0, 0)
