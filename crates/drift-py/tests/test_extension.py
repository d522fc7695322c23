"""The extended model from Python: ExtraTerm, ModifiedTables.extension / with_extension, their
validation (drift-core's messages, as TableError) and round trips through JSON, images and files."""

from __future__ import annotations

import json
import re
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gyrodrift
from conftest import VECTORS, Model
from gyrodrift import ExtraTerm, InputError, ModifiedTables, TableError


@pytest.fixture(scope="session")
def extended(models: dict[str, Model]) -> ModifiedTables:
    model = models["extended"]
    assert isinstance(model, ModifiedTables)
    return model


# The vectors' extended model's rate at switch-on, per axis [heating, cooling, faster per remaining].
SWITCH_ON_RATE = [[0.15, 0.004, 0.0085], [0.15, 0.0035, 0.0085], [0.15, 0.003, 0.0085]]


def terms() -> list[ExtraTerm]:
    return [
        ExtraTerm("temperature_rate", 5000, centre=(0.01, 0.012, 0.008), coefficient=(0.1, -0.08, 0.05)),
        ExtraTerm(
            "aux", 0, centre=[5.0] * 3, coefficient=np.array([0.01, -0.012, 0.008]), time_constant_ms=2000
        ),
        ExtraTerm("axis_rise", 0, centre=(2.0, 2.0, 2.0), coefficient=(0.0, 0.002, -0.0015)),
        ExtraTerm("rise_squared", centre=(6.0, 7.0, 5.0), coefficient=(0.0003, -0.0002, 0.0001)),
    ]


# --- reading ---------------------------------------------------------------------------------


def test_the_paper_model_has_no_extension(modified: ModifiedTables) -> None:
    assert modified.extension == ()
    assert "extra term" not in repr(modified)


def test_extension_lists_the_terms_as_in_the_json(extended: ModifiedTables, vectors: dict[str, Any]) -> None:
    named = next(m for m in vectors["models"] if m["name"] == "extended")
    expected = named["tables"]["extension"]["terms"]
    got = extended.extension
    assert isinstance(got, tuple) and len(got) == len(expected) == gyrodrift.MAX_EXTRA_TERMS
    assert [t.kind for t in got] == ["temperature_rate", "aux", "axis_rise", "rise_squared"]
    assert [t.parameter for t in got] == [5000, 0, 0, None]
    assert [t.time_constant_ms for t in got] == [5000, 2000, None, None]
    for term, raw in zip(got, expected):
        # The JSON holds the f32 values printed shortest; the getters give the same f32s.
        assert term.centre == tuple(np.asarray(raw["centre"], dtype=np.float32).tolist())
        assert term.coefficient == tuple(np.asarray(raw["coefficient"], dtype=np.float32).tolist())
    assert got == tuple(terms())
    assert repr(extended).endswith("; 4 extra terms>")


def test_extra_term_repr_reads_as_its_constructor() -> None:
    assert repr(ExtraTerm("aux", 2, centre=(5.0, 5.0, 5.0), coefficient=(0.5, 0.0, -0.25))) == (
        "ExtraTerm('aux', 2, centre=(5.0, 5.0, 5.0), coefficient=(0.5, 0.0, -0.25))"
    )
    assert repr(ExtraTerm("aux", 0, centre=(5, 5, 5), coefficient=(1, 0, 0), time_constant_ms=1000)) == (
        "ExtraTerm('aux', 0, centre=(5.0, 5.0, 5.0), coefficient=(1.0, 0.0, 0.0), time_constant_ms=1000)"
    )
    assert repr(ExtraTerm("rise_squared", None, centre=(0, 0, 0), coefficient=(1, 1, 1))) == (
        "ExtraTerm('rise_squared', centre=(0.0, 0.0, 0.0), coefficient=(1.0, 1.0, 1.0))"
    )


def test_extra_terms_compare_by_value() -> None:
    a, b = terms()[:2]
    assert a == terms()[0] and a != b
    assert ExtraTerm("aux", 1, centre=(0, 0, 0), coefficient=(0, 0, 0)) != ExtraTerm(
        "aux", 2, centre=(0, 0, 0), coefficient=(0, 0, 0)
    )


# --- building --------------------------------------------------------------------------------


def test_with_extension_rebuilds_the_extended_model(
    modified: ModifiedTables, extended: ModifiedTables
) -> None:
    """The vectors' extended model is the paper's model plus these four terms and its rate at
    switch-on."""
    rebuilt = modified.with_extension(terms(), switch_on_rate=SWITCH_ON_RATE)
    assert rebuilt == extended
    assert rebuilt.to_image() == extended.to_image()
    assert modified.extension == ()  # immutable: the original is untouched
    # Without the rate the filter starts at rest: another model.
    assert modified.with_extension(terms()) != extended
    assert extended.with_extension([], np.zeros((3, 3))) == modified
    assert extended.with_extension(()).extension == ()


def test_switch_on_rate_reads_as_given_and_none_keeps_it(
    modified: ModifiedTables, extended: ModifiedTables
) -> None:
    rate = extended.switch_on_rate
    assert rate.dtype == np.float32 and rate.shape == (3, 3)
    np.testing.assert_array_equal(rate, np.asarray(SWITCH_ON_RATE, dtype=np.float32))
    np.testing.assert_array_equal(modified.switch_on_rate, np.zeros((3, 3), dtype=np.float32))
    # `None` keeps it, whatever the terms; a float64 array is taken as f32 values.
    np.testing.assert_array_equal(extended.with_extension(terms()[:1]).switch_on_rate, rate)
    doubled = extended.with_extension(terms(), np.asarray(SWITCH_ON_RATE) * 2)
    np.testing.assert_array_equal(doubled.switch_on_rate, rate * 2)


@pytest.mark.parametrize(
    ("rate", "error", "message"),
    [
        (np.zeros((3, 2)), InputError, "`switch_on_rate` must be a float32 or float64 array of shape (3, 3)"),
        ([[0.1, 0.0]] * 3, InputError, "`switch_on_rate` must be a float32 or float64 array of shape (3, 3)"),
        (
            [[0.1, 0.004, 0.0], [0.1, 0.004, 0.0], [0.1, -0.001, 0.0]],
            TableError,
            "invalid tables: axes[2].switch_on_rate: must not be negative",
        ),
        (
            [[float("nan"), 0.004, 0.0], [0.1, 0.004, 0.0], [0.1, 0.004, 0.0]],
            TableError,
            "invalid tables: axes[0].switch_on_rate: value is NaN or infinite",
        ),
    ],
)
def test_a_bad_switch_on_rate_is_named(
    modified: ModifiedTables, rate: Any, error: type[Exception], message: str
) -> None:
    with pytest.raises(error, match=re.escape(message)):
        modified.with_extension(terms(), rate)


def test_with_extension_accepts_a_tuple_and_replaces_the_terms(extended: ModifiedTables) -> None:
    one = extended.with_extension((terms()[3],))
    assert one.extension == (terms()[3],)
    assert repr(one).endswith("; 1 extra term>")


@pytest.mark.parametrize(
    ("term", "message"),
    [
        (
            ExtraTerm("aux", 4, centre=(0, 0, 0), coefficient=(0, 0, 0)),
            "invalid tables: term_input[1]: must be less than 4",
        ),
        (
            ExtraTerm("axis_rise", 3, centre=(0, 0, 0), coefficient=(0, 0, 0)),
            "invalid tables: term_axis[1]: must be less than 3",
        ),
        (
            ExtraTerm("temperature_rate", 0, centre=(0, 0, 0), coefficient=(0, 0, 0)),
            "invalid tables: term_time_constant_ms[1]: must be greater than zero",
        ),
        (
            ExtraTerm("temperature_rate", 1000, centre=(0, 0, 0), coefficient=(0, 0, 0)),
            "invalid tables: term_time_constant_ms[1]: differs from the earlier entry it must equal",
        ),
        (
            ExtraTerm("rise_squared", centre=(0, float("nan"), 0), coefficient=(0, 0, 0)),
            "invalid tables: axes[1].term_centre[1]: value is NaN or infinite",
        ),
        (
            ExtraTerm("rise_squared", centre=(0, 0, 0), coefficient=(0, 0, float("inf"))),
            "invalid tables: axes[2].term_coefficient[1]: value is NaN or infinite",
        ),
    ],
)
def test_with_extension_passes_drift_cores_validation_through(
    modified: ModifiedTables, term: ExtraTerm, message: str
) -> None:
    """Term 0 is a valid 5-s rate term, so the bad term sits at index 1."""
    with pytest.raises(TableError, match=re.escape(message)):
        modified.with_extension([terms()[0], term])


@pytest.mark.parametrize(
    ("argument", "message"),
    [
        (terms() + terms()[:1], "`terms` must hold at most 4 terms, got 5"),
        ([terms()[0], {"kind": "aux"}], "`terms[1]` must be a gyrodrift.ExtraTerm, got dict"),
        (terms()[0], "`terms` must be a sequence of gyrodrift.ExtraTerm, got ExtraTerm"),
        ("aux", "`terms` must be a sequence of gyrodrift.ExtraTerm, got str"),
        (None, "`terms` must be a sequence of gyrodrift.ExtraTerm, got NoneType"),
    ],
)
def test_with_extension_rejects_what_is_not_a_list_of_terms(
    modified: ModifiedTables, argument: Any, message: str
) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        modified.with_extension(argument)


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        (
            ("humidity", 1),
            {},
            "`kind` must be one of 'temperature_rate', 'aux', 'axis_rise', 'rise_squared', "
            "'aux_times_rise', got \"humidity\"",
        ),
        ((3, 1), {}, "`kind` must be a str, got int"),
        (("aux",), {}, "`parameter` is required for kind 'aux' (the auxiliary input's index), got None"),
        (
            ("temperature_rate", None),
            {},
            "`parameter` is required for kind 'temperature_rate' (the rate filter's time constant, ms), got None",
        ),
        (
            ("temperature_rate", -5),
            {},
            "`parameter` must be an integer in 0..=4294967295 (ms), got -5",
        ),
        (("aux", 256), {}, "`parameter` must be an integer in 0..=255 (an auxiliary input's index), got 256"),
        (("axis_rise", 1.5), {}, "`parameter` must be an integer in 0..=255 (an axis index), got 1.5"),
        (("rise_squared", 0), {}, "`parameter` must be None for kind 'rise_squared', got 0"),
        (("aux", 0), {"centre": (1, 2)}, "`centre` must be a sequence of 3 floats (X, Y, Z), got tuple"),
        (
            ("aux", 0),
            {"time_constant_ms": -1},
            "`time_constant_ms` must be an integer in 0..=4294967295 (ms), got -1",
        ),
        (
            ("temperature_rate", 2000),
            {"time_constant_ms": 2000},
            "`time_constant_ms` is only for kinds 'aux' and 'aux_times_rise' (a rate term's time "
            'constant is its `parameter`), got 2000 for kind "temperature_rate"',
        ),
        (
            ("aux", 0),
            {"coefficient": "abc"},
            "`coefficient` must be a sequence of 3 floats (X, Y, Z), got str",
        ),
    ],
)
def test_extra_term_rejects_bad_arguments(args: tuple, kwargs: dict[str, Any], message: str) -> None:
    full = {"centre": (0.0, 0.0, 0.0), "coefficient": (0.0, 0.0, 0.0), **kwargs}
    with pytest.raises(InputError, match=re.escape(message)):
        ExtraTerm(*args, **full)


def test_extra_term_needs_centre_and_coefficient() -> None:
    with pytest.raises(TypeError, match="centre"):
        ExtraTerm("aux", 0, coefficient=(0, 0, 0))  # type: ignore[call-arg]


# --- round trips -----------------------------------------------------------------------------


def test_json_round_trip_keeps_the_extension(modified: ModifiedTables) -> None:
    model = modified.with_extension(terms()[1:3])
    text = model.to_json()
    assert [t["term"] for t in json.loads(text)["extension"]["terms"]] == [
        {"Aux": {"input": 0, "time_constant_ms": 2000}},
        {"AxisRise": {"axis": 0}},
    ]
    assert ModifiedTables.from_json(text) == model
    assert ModifiedTables.from_json(text).extension == tuple(terms()[1:3])


def test_image_round_trip_keeps_the_extension(modified: ModifiedTables, extended: ModifiedTables) -> None:
    for model in (extended, modified.with_extension(terms()[3:])):
        image = model.to_image()
        assert ModifiedTables.from_image(image) == model
        assert ModifiedTables.from_image(image).extension == model.extension


def test_file_round_trips_keep_the_extension(tmp_path: Path, extended: ModifiedTables) -> None:
    extended.save_json(tmp_path / "extended.json")
    extended.save_image(tmp_path / "extended.bin")
    assert ModifiedTables.load_json(tmp_path / "extended.json") == extended
    assert ModifiedTables.load_image(tmp_path / "extended.bin") == extended


def test_json_without_an_extension_reads_as_none(modified: ModifiedTables) -> None:
    """Tables written before the extended model existed (no `extension` key) still load."""
    data = json.loads(modified.to_json())
    del data["extension"]
    assert ModifiedTables.from_json(json.dumps(data)) == modified


def test_committed_image_still_loads(modified: ModifiedTables) -> None:
    """drift-core's committed image of the paper's tables (format version 1, no extension)."""
    fixture = VECTORS.parent / "image-v1-modified.bin"
    stored = ModifiedTables.load_image(fixture)
    assert stored == modified and stored.extension == ()
    # Version 2 wrote a longer header (64 bytes, not 12); version 3's settings add the sample rate
    # (f32, 0: not stated) after the stuck timeout's varint; every other payload byte is the same.
    old, new = fixture.read_bytes()[12:-4], stored.to_image()[64:-4]
    at = 16 + next(i for i, byte in enumerate(old[16:]) if byte & 0x80 == 0) + 1
    assert new == old[:at] + struct.pack("<f", 0.0) + old[at:]


def test_extension_changes_the_correction(modified: ModifiedTables, extended: ModifiedTables) -> None:
    """The terms reach the corrector: same inputs, other bias; aux changes it again."""
    times = np.arange(1, 201, dtype=np.uint32) * 10
    rate = np.zeros((200, 3), np.float32)
    temperature = (6600.0 + np.linspace(0, 40, 200)[:, None] * np.ones(3)).astype(np.float32)
    aux = np.tile(np.asarray([5.0, 0.0, 0.0, 1.0], dtype=np.float32), (200, 1))

    def bias(model: ModifiedTables, aux: np.ndarray | None) -> np.ndarray:
        corrector = gyrodrift.Corrector(model)
        corrector.power_on(temperature[0])
        return corrector.correct_batch(times, rate, temperature, aux=aux)[1]

    plain, with_aux = bias(modified, None), bias(extended, aux)
    assert not np.array_equal(plain, with_aux)
    assert not np.array_equal(with_aux, bias(extended, aux + np.asarray([0.5, 0, 0, 0], dtype=np.float32)))
    assert np.array_equal(bias(modified, aux), plain)  # the paper's model does not read aux
