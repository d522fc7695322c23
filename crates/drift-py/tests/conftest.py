"""Fixtures shared by the gyrodrift tests: the shared test vectors and their models."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

import numpy as np
import pytest

import gyrodrift

VECTORS = Path(__file__).resolve().parents[3] / "testdata" / "vectors.json"

Model = Union[gyrodrift.ModifiedTables, gyrodrift.PolynomialTables, gyrodrift.RecommendedTables]


@dataclass
class Case:
    """One vector case, with its floats turned from bit patterns into numpy arrays."""

    name: str
    model: str
    switch_on_raw: np.ndarray | None  # (3,) float32
    power_on_fails: bool
    times: np.ndarray  # (n,) uint32
    rate: np.ndarray  # (n, 3) float32
    temperature: np.ndarray  # (n, 3) float32
    corrected: np.ndarray  # (n, 3) float32
    bias: np.ndarray  # (n, 3) float32
    flags: np.ndarray  # (n, 3) uint16
    aux: np.ndarray | None = None  # (n, 4) float32: the auxiliary inputs, when the case passes them
    # (3, 2) float32: what was kept of the previous activation, per axis [ambient °C, switch-off °C];
    # when present the case starts with `power_on_after` rather than `power_on`.
    previous: np.ndarray | None = None


def f32(bits: Any) -> np.ndarray:
    """IEEE-754 binary32 bit patterns to float32 values (NaN payloads preserved)."""
    return np.asarray(bits, dtype=np.uint32).view(np.float32)


def load_vectors() -> dict[str, Any]:
    with VECTORS.open() as file:
        data: dict[str, Any] = json.load(file)
    return data


def model_class(kind: str) -> type[Model]:
    return {
        "modified": gyrodrift.ModifiedTables,
        "polynomial": gyrodrift.PolynomialTables,
        "recommended": gyrodrift.RecommendedTables,
    }[kind]


@pytest.fixture(scope="session")
def vectors() -> dict[str, Any]:
    return load_vectors()


@pytest.fixture(scope="session")
def models(vectors: dict[str, Any]) -> dict[str, Model]:
    """The vector models, loaded from their firmware images (the canonical form)."""
    return {
        m["name"]: model_class(m["kind"]).from_image(bytes.fromhex(m["image_hex"])) for m in vectors["models"]
    }


@pytest.fixture(scope="session")
def modified(models: dict[str, Model]) -> gyrodrift.ModifiedTables:
    model = models["modified"]
    assert isinstance(model, gyrodrift.ModifiedTables)
    return model


def parse_case(case: dict[str, Any]) -> Case:
    samples = np.asarray(case["samples"], dtype=np.uint32)
    expected = np.asarray(case["expected"], dtype=np.uint32)
    switch_on = case["switch_on_raw"]
    return Case(
        name=case["name"],
        model=case["model"],
        switch_on_raw=None if switch_on is None else f32(switch_on),
        power_on_fails=case["power_on_fails"],
        times=np.ascontiguousarray(samples[:, 0]),
        rate=f32(np.ascontiguousarray(samples[:, 1:4])),
        temperature=f32(np.ascontiguousarray(samples[:, 4:7])),
        corrected=f32(np.ascontiguousarray(expected[:, 0:3])),
        bias=f32(np.ascontiguousarray(expected[:, 3:6])),
        flags=expected[:, 6:9].astype(np.uint16),
        aux=f32(np.asarray(case["aux"], dtype=np.uint32).reshape(-1, 4)) if "aux" in case else None,
        previous=f32(np.asarray(case["previous"], dtype=np.uint32)) if "previous" in case else None,
    )


@pytest.fixture(scope="session")
def cases(vectors: dict[str, Any]) -> list[Case]:
    return [parse_case(c) for c in vectors["cases"]]


def same_bits(expected: np.ndarray, got: np.ndarray) -> np.ndarray:
    """Element-wise: equal bit patterns, or both NaN (the vectors' rule)."""
    assert got.dtype == np.float32, got.dtype
    equal = expected.view(np.uint32) == got.view(np.uint32)
    return equal | (np.isnan(expected) & np.isnan(got))


def powered_corrector(model: Model, case: Case) -> gyrodrift.Corrector:
    """A fresh corrector, powered on as the case says (a rejected power_on leaves it off):
    `power_on_after` with the case's kept previous activation when it has one, else `power_on`."""
    corrector = gyrodrift.Corrector(model)
    if case.switch_on_raw is not None:
        raw = case.switch_on_raw
        previous = case.previous

        def start() -> None:
            if previous is None:
                corrector.power_on(raw)
            else:
                corrector.power_on_after(raw, previous)

        if case.power_on_fails:
            with pytest.raises(gyrodrift.InputError):
                start()
        else:
            start()
    return corrector


# --- a small simulated campaign, shared by the recording, fit and evaluation tests -------------

SMALL_CAMPAIGN: dict[str, Any] = {
    "name": "pytest",
    "seed": 7,
    "units": 1,
    "set_points_celsius": [30.0, 40.0, 33.0],
    # 20-s activations: long enough for the analysis (4-s initial-bias window, 2-s first reference
    # time), short enough that the whole suite stays fast.
    "protocol": {"intervals_min": [1.0, 20.0], "activations": 3, "activation_s": 20.0, "repeats": 2},
}


@pytest.fixture(scope="session")
def campaign_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A simulated campaign folder: 1 unit, +30/+40/+33 °C, 2 intervals × 3 activations × 2 repeats."""
    out = tmp_path_factory.mktemp("campaign")
    gyrodrift.simulate(out, SMALL_CAMPAIGN)
    return out


@pytest.fixture(scope="session")
def evaluation(campaign_dir: Path) -> gyrodrift.Evaluation:
    return gyrodrift.evaluate(campaign_dir)


def recording_path(campaign_dir: Path, set_point: str = "+30.0") -> Path:
    return campaign_dir / "recordings" / f"GIU-01_sp{set_point}C_protocol.mcap"


def format_aux(n: int, rate_hz: int = 1000) -> dict[str, tuple[np.ndarray, str, int]]:
    """The auxiliary channels the recording format stores, for an activation of `n` samples."""
    m = -(-n // (rate_hz // 100))
    ones = np.ones(m, dtype=np.float32)
    return {
        "accel_x": (0 * ones, "g", 100),
        "accel_y": (0 * ones, "g", 100),
        "accel_z": (ones, "g", 100),
        "supply_voltage": (5 * ones, "V", 100),
        "chamber_set_point": (30 * ones, "degC", 100),
    }


def make_segment(
    n: int = 2500, *, power_on_ns: int = 0, activation: int = 1, unit_id: str = "PY-1", aux: bool = True
) -> gyrodrift.Segment:
    """A synthetic activation: a slow warm-up with a drift that follows it."""
    t = np.arange(n) / 1000.0
    rise = 2.0 * (1 - np.exp(-t / 30.0))
    temperature = (6000 + 200 * rise[:, None] + np.zeros((1, 3))).round().astype(np.int16)
    rate = (0.01 * rise[:, None] * np.array([1.0, -0.5, 0.25])).astype(np.float32)
    labels = gyrodrift.Labels(
        unit_id=unit_id, set_point_celsius=30.0, activation=activation, interval_min=1.0, off_before_s=60.0
    )
    return gyrodrift.Segment(
        labels, rate, temperature, power_on_ns=power_on_ns, aux=format_aux(n) if aux else None
    )
