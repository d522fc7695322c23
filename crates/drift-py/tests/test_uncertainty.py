"""`gyrodrift.Uncertainty`: σ(t) from the firmware section reproduces the shared σ(t) vectors bit
for bit, its JSON form loads the same, and bad files are refused by name."""

from __future__ import annotations

import copy
import json
import pickle
from pathlib import Path

import numpy as np
import pytest

import gyrodrift

VECTORS = Path(__file__).resolve().parents[3] / "testdata" / "sigma-vectors.json"


def bits(values: list[int]) -> np.ndarray:
    return np.array(values, dtype=np.uint32).view(np.float32)


@pytest.fixture(scope="module")
def vectors() -> dict:
    return json.loads(VECTORS.read_text())


@pytest.fixture
def section(tmp_path: Path, vectors: dict) -> Path:
    path = tmp_path / "uncertainty.bin"
    path.write_bytes(bytes.fromhex(vectors["section_hex"]))
    return path


def test_the_section_reproduces_the_shared_vectors_bit_for_bit(section: Path, vectors: dict) -> None:
    sigma = gyrodrift.Uncertainty.load(section)
    for case in vectors["cases"]:
        previous = (
            None if case["previous"] is None else bits(np.ravel(case["previous"]).tolist()).reshape(3, 2)
        )
        got = sigma.sigma(
            np.array(case["times_ms"], dtype=np.uint32), bits(case["switch_on_celsius"]), previous
        )
        expected = np.array(case["expected"], dtype=np.uint32)
        assert got.dtype == np.float32 and got.shape == expected.shape
        assert (got.view(np.uint32) == expected).all(), case["name"]


def test_sigma_is_piecewise_linear_per_class_as_a_float32_restatement(section: Path) -> None:
    sigma = gyrodrift.Uncertainty.load(section)
    knots = np.array(sigma.knots_ms, dtype=np.uint32)
    table = sigma.sigma_dps
    times = np.arange(0, 200_000, 250, dtype=np.uint32)
    lo, _ = sigma.envelope_celsius
    # Cold inside the envelope (no history), and a warm restart 4 °C above a 30 °C ambient.
    cold = sigma.sigma(times, (lo + 1.0,) * 3)
    warm = sigma.sigma(times, (34.0,) * 3, np.array([[30.0, 36.0]] * 3, dtype=np.float32))
    for row, got in ((table[0], cold), (table[1], warm)):
        reference = np.interp(times.astype(np.float64), knots.astype(np.float64), row.astype(np.float64))
        assert np.allclose(got[:, 0], reference, rtol=1e-5, atol=1e-9)
        assert (got[:, 0] == got[:, 1]).all() and (got[:, 1] == got[:, 2]).all()
    # Outside the envelope σ grows by the stored amount per °C.
    below = sigma.sigma(times[-1:], (lo - 2.0,) * 3)
    assert np.isclose(below[0, 0], table[0, -1] + 2.0 * sigma.per_celsius_outside_dps, rtol=1e-6)
    # Beyond the calibration's most residual heat σ grows too (10 °C of heat, 30 °C ambient).
    assert len(sigma.most_residual_heat_celsius) == 3 and sigma.per_residual_celsius_beyond_dps > 0
    hot = sigma.sigma(times[-1:], (40.0,) * 3, np.array([[30.0, 45.0]] * 3, dtype=np.float32))
    assert (hot[0] > table[1, -1]).all()


def test_json_and_section_load_the_same_and_pickle(tmp_path: Path, section: Path) -> None:
    from_section = gyrodrift.Uncertainty.load(section)
    path = tmp_path / "uncertainty.json"
    path.write_text(from_section.to_json())
    from_json = gyrodrift.Uncertainty.load(path)
    assert from_json == from_section
    for back in (pickle.loads(pickle.dumps(from_json)), copy.deepcopy(from_json)):
        assert back == from_json


def test_bad_files_are_refused_naming_the_file_and_the_problem(tmp_path: Path, section: Path) -> None:
    damaged = tmp_path / "damaged.bin"
    data = bytearray(section.read_bytes())
    data[20] ^= 1
    damaged.write_bytes(bytes(data))
    with pytest.raises(gyrodrift.InputError, match=r"damaged\.bin.*CRC mismatch"):
        gyrodrift.Uncertainty.load(damaged)
    text = json.loads(gyrodrift.Uncertainty.load(section).to_json())
    text["sigma_dps"][1][3] = -0.001
    negative = tmp_path / "negative.json"
    negative.write_text(json.dumps(text))
    with pytest.raises(gyrodrift.InputError, match=r"negative\.json.*sigma_dps"):
        gyrodrift.Uncertainty.load(negative)
