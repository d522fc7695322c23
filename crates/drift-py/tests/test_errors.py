"""Every error path: a gyrodrift exception whose message names the argument and what was expected.

Never a PanicException, never a crash; NaN inputs are data (flagged), not errors.
"""

from __future__ import annotations

import json
import re
import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gyrodrift
from conftest import Model
from gyrodrift import (
    FileError,
    Flags,
    GyrodriftError,
    ImageError,
    InputError,
    ModifiedTables,
    PolynomialTables,
    TableError,
)

N = 5


@pytest.fixture
def corrector(modified: ModifiedTables) -> gyrodrift.Corrector:
    c = gyrodrift.Corrector(modified)
    c.power_on([6000.0, 6000.0, 6000.0])
    return c


def inputs(n: int = N) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    times = np.arange(1, n + 1, dtype=np.uint32) * 10
    rate = np.full((n, 3), 0.1, dtype=np.float32)
    temperature = np.full((n, 3), 6000.0, dtype=np.float32) + np.arange(n, dtype=np.float32)[:, None]
    return times, rate, temperature


# --- hierarchy -------------------------------------------------------------------------------


def test_hierarchy() -> None:
    for error in (InputError, TableError, ImageError, FileError):
        assert issubclass(error, GyrodriftError)
        assert error.__module__ == "gyrodrift"
    assert issubclass(GyrodriftError, Exception)
    assert issubclass(InputError, ValueError)
    assert issubclass(FileError, OSError)


# --- batch arrays ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("argument", "bad", "message"),
    [
        (
            "rate_dps",
            np.zeros((N, 3), dtype=np.int64),
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got int64 array of shape (5, 3)",
        ),
        (
            "rate_dps",
            np.zeros((N, 2), dtype=np.float32),
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got float32 array of shape (5, 2)",
        ),
        (
            "rate_dps",
            np.zeros(N * 3, dtype=np.float32),
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got float32 array of shape (15,)",
        ),
        (
            "rate_dps",
            np.zeros((N, 3), dtype=np.float16),
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got float16 array of shape (5, 3)",
        ),
        (
            "rate_dps",
            np.zeros((N, 3), dtype=">f4"),
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got >f4 array of shape (5, 3)",
        ),
        (
            "rate_dps",
            [[0.0, 0.0, 0.0]] * N,
            "`rate_dps` must be a float32 or float64 array of shape (n, 3), got list",
        ),
        (
            "temperature_raw",
            np.zeros((N, 3, 1), dtype=np.float32),
            "`temperature_raw` must be a float32, float64 or int16 array of shape (n, 3), got float32 array of shape (5, 3, 1)",
        ),
        (
            "temperature_raw",
            np.zeros((N, 3), dtype=np.complex64),
            "`temperature_raw` must be a float32, float64 or int16 array of shape (n, 3), got complex64 array of shape (5, 3)",
        ),
        (
            "since_power_on_ms",
            np.arange(N, dtype=np.int64),
            "`since_power_on_ms` must be a uint32 array of shape (n,), got int64 array of shape (5,) (convert with .astype(np.uint32))",
        ),
        (
            "since_power_on_ms",
            np.arange(N, dtype="timedelta64[ns]"),
            "`since_power_on_ms` must be a uint32 array of shape (n,), got timedelta64[ns] array of shape (5,) (timedelta64: convert with (t // np.timedelta64(1, 'ms')).astype(np.uint32); .astype(np.uint32) would count its native unit)",
        ),
        (
            "since_power_on_ms",
            np.arange(N, dtype=np.float64),
            "`since_power_on_ms` must be a uint32 array of shape (n,), got float64 array of shape (5,)",
        ),
        (
            "since_power_on_ms",
            np.zeros((N, 1), dtype=np.uint32),
            "`since_power_on_ms` must be a uint32 array of shape (n,), got uint32 array of shape (5, 1)",
        ),
        ("since_power_on_ms", None, "`since_power_on_ms` must be a uint32 array of shape (n,), got NoneType"),
    ],
)
def test_batch_rejects_wrong_dtype_and_shape(
    corrector: gyrodrift.Corrector, argument: str, bad: Any, message: str
) -> None:
    args = dict(zip(("since_power_on_ms", "rate_dps", "temperature_raw"), inputs()))
    args[argument] = bad
    with pytest.raises(InputError, match=re.escape(message)):
        corrector.correct_batch(args["since_power_on_ms"], args["rate_dps"], args["temperature_raw"])


@pytest.mark.parametrize("argument", ["since_power_on_ms", "rate_dps", "temperature_raw"])
def test_batch_rejects_empty_arrays(corrector: gyrodrift.Corrector, argument: str) -> None:
    args = dict(zip(("since_power_on_ms", "rate_dps", "temperature_raw"), inputs()))
    args[argument] = args[argument][:0]
    with pytest.raises(InputError, match=re.escape(f"`{argument}` must not be empty")):
        corrector.correct_batch(args["since_power_on_ms"], args["rate_dps"], args["temperature_raw"])


@pytest.mark.parametrize("argument", ["rate_dps", "temperature_raw"])
def test_batch_rejects_mismatched_lengths(corrector: gyrodrift.Corrector, argument: str) -> None:
    args = dict(zip(("since_power_on_ms", "rate_dps", "temperature_raw"), inputs()))
    args[argument] = args[argument][:-1]
    message = f"`{argument}` must have one row per time in `since_power_on_ms` (5), got 4 rows"
    with pytest.raises(InputError, match=re.escape(message)):
        corrector.correct_batch(args["since_power_on_ms"], args["rate_dps"], args["temperature_raw"])


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        (
            np.zeros((N, 3), dtype=np.float32),
            "`aux` must be a float32 or float64 array of shape (n, 4), got float32 array of shape (5, 3)",
        ),
        (
            np.zeros(4, dtype=np.float32),
            "`aux` must be a float32 or float64 array of shape (n, 4), got float32 array of shape (4,)",
        ),
        (
            np.zeros((N, 4), dtype=np.int32),
            "`aux` must be a float32 or float64 array of shape (n, 4), got int32 array of shape (5, 4)",
        ),
        ([[0.0] * 4] * N, "`aux` must be a float32 or float64 array of shape (n, 4), got list"),
        (np.zeros((0, 4), dtype=np.float32), "`aux` must not be empty, got float32 array of shape (0, 4)"),
        (
            np.zeros((N - 1, 4), dtype=np.float64),
            "`aux` must have one row per time in `since_power_on_ms` (5), got 4 rows",
        ),
    ],
)
def test_batch_rejects_bad_aux(corrector: gyrodrift.Corrector, bad: Any, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        corrector.correct_batch(*inputs(), aux=bad)


def test_a_rejected_batch_leaves_the_state_alone(modified: ModifiedTables) -> None:
    times, rate, temperature = inputs()
    reference = gyrodrift.Corrector(modified)
    reference.power_on([6000.0] * 3)
    expected = reference.correct_batch(times, rate, temperature)
    corrector = gyrodrift.Corrector(modified)
    corrector.power_on([6000.0] * 3)
    with pytest.raises(InputError):
        corrector.correct_batch(times, rate[:-1], temperature)
    for want, got in zip(expected, corrector.correct_batch(times, rate, temperature)):
        np.testing.assert_array_equal(want, got)


def out_arrays(n: int = N) -> list[np.ndarray]:
    return [np.zeros((n, 3), np.float32), np.zeros((n, 3), np.float32), np.zeros((n, 3), np.uint16)]


@pytest.mark.parametrize(
    ("index", "bad", "message"),
    [
        (
            0,
            np.zeros((N, 3), np.float64),
            "`out[0]` must be a writeable C-contiguous float32 array of shape (5, 3), got float64 array of shape (5, 3)",
        ),
        (
            1,
            np.zeros((N + 1, 3), np.float32),
            "`out[1]` must be a writeable C-contiguous float32 array of shape (5, 3), got float32 array of shape (6, 3)",
        ),
        (
            2,
            np.zeros((N, 3), np.uint32),
            "`out[2]` must be a writeable C-contiguous uint16 array of shape (5, 3), got uint32 array of shape (5, 3)",
        ),
        (
            0,
            np.zeros((3, N), np.float32).T,
            "`out[0]` must be a writeable C-contiguous float32 array of shape (5, 3), got float32 array of shape (5, 3)",
        ),
    ],
)
def test_batch_rejects_bad_out_arrays(
    corrector: gyrodrift.Corrector, index: int, bad: np.ndarray, message: str
) -> None:
    out = out_arrays()
    out[index] = bad
    with pytest.raises(InputError, match=re.escape(message)):
        corrector.correct_batch(*inputs(), out=tuple(out))


def test_batch_rejects_read_only_aliased_or_missing_out(corrector: gyrodrift.Corrector) -> None:
    times, rate, temperature = inputs()
    read_only = out_arrays()
    read_only[1].flags.writeable = False
    with pytest.raises(InputError, match=re.escape("`out[1]` must be writeable and not also an input")):
        corrector.correct_batch(times, rate, temperature, out=tuple(read_only))
    aliased = out_arrays()
    with pytest.raises(InputError, match=re.escape("`out[0]` must be writeable and not also an input")):
        corrector.correct_batch(times, aliased[0], temperature, out=tuple(aliased))
    twice = out_arrays()
    with pytest.raises(InputError, match=re.escape("`out[1]` must be writeable and not also an input")):
        corrector.correct_batch(times, rate, temperature, out=(twice[0], twice[0], twice[2]))
    with pytest.raises(
        InputError,
        match=re.escape("`out` must be a tuple of 3 arrays (corrected_dps, bias_dps, flags), got list"),
    ):
        corrector.correct_batch(times, rate, temperature, out=out_arrays()[:2])  # type: ignore[arg-type]


# --- NaN is data -----------------------------------------------------------------------------


def test_nan_inputs_are_flagged_not_raised(corrector: gyrodrift.Corrector) -> None:
    times, rate, temperature = inputs()
    rate[1, 0] = np.nan
    rate[2, 1] = np.inf
    temperature[3, 2] = np.nan
    corrected, bias, flags = corrector.correct_batch(times, rate, temperature)
    assert flags[1, 0] & Flags.RATE_INVALID and np.isnan(corrected[1, 0])
    assert flags[2, 1] & Flags.RATE_INVALID and not np.isfinite(corrected[2, 1])
    assert flags[3, 2] & Flags.TEMPERATURE_INVALID and np.isfinite(bias[3, 2])
    assert bias[3, 2] == bias[2, 2]  # the last good drift is held
    single = corrector.correct(60, [np.nan, 0.0, 0.0], [6000.0, np.nan, 6001.0])
    assert single.flags[0] & Flags.RATE_INVALID and single.flags[1] & Flags.TEMPERATURE_INVALID


# --- per-sample arguments --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            (-1, [0.0] * 3, [6000.0] * 3),
            "`since_power_on_ms` must be an integer in 0..=4294967295 (ms), got -1",
        ),
        (
            (2**32, [0.0] * 3, [6000.0] * 3),
            "`since_power_on_ms` must be an integer in 0..=4294967295 (ms), got 4294967296",
        ),
        (
            (1.5, [0.0] * 3, [6000.0] * 3),
            "`since_power_on_ms` must be an integer in 0..=4294967295 (ms), got 1.5",
        ),
        ((1, [0.0] * 2, [6000.0] * 3), "`rate_dps` must be a sequence of 3 floats (X, Y, Z), got list"),
        ((1, [0.0] * 3, "abc"), "`temperature_raw` must be a sequence of 3 floats (X, Y, Z), got str"),
        (
            (1, [0.0] * 3, np.zeros(4)),
            "`temperature_raw` must be a sequence of 3 floats (X, Y, Z), got float64 array of shape (4,)",
        ),
    ],
)
def test_correct_rejects_bad_arguments(corrector: gyrodrift.Corrector, args: tuple, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        corrector.correct(*args)


@pytest.mark.parametrize(
    ("aux", "got"),
    [
        ([0.0] * 3, "list"),
        ("abcd", "str"),
        (5.0, "float"),
        (np.zeros((2, 4)), "float64 array of shape (2, 4)"),
        (np.zeros(5, dtype=np.float32), "float32 array of shape (5,)"),
    ],
)
def test_correct_rejects_bad_aux(corrector: gyrodrift.Corrector, aux: Any, got: str) -> None:
    message = (
        "`aux` must be a sequence of 4 floats (auxiliary inputs 0..4) or a float array of shape (4,), "
        f"got {got}"
    )
    with pytest.raises(InputError, match=re.escape(message)):
        corrector.correct(1, [0.0] * 3, [6000.0] * 3, aux=aux)


def test_aux_is_keyword_only(corrector: gyrodrift.Corrector) -> None:
    with pytest.raises(TypeError):
        corrector.correct(1, [0.0] * 3, [6000.0] * 3, [5.0] * 4)  # type: ignore[misc]


def test_power_on_rejects_non_finite_and_keeps_the_state(modified: ModifiedTables) -> None:
    corrector = gyrodrift.Corrector(modified)
    with pytest.raises(
        InputError, match=r"`switch_on_raw` must be finite on every axis.*axes\[1\]\.switch_on_raw"
    ):
        corrector.power_on([6000.0, float("nan"), 6000.0])
    assert not corrector.is_powered_on
    corrector.power_on([6000.0, 6100.0, 6200.0])
    with pytest.raises(InputError):
        corrector.power_on([6000.0, 6000.0, float("inf")])
    assert corrector.is_powered_on and corrector.switch_on_raw == (6000.0, 6100.0, 6200.0)


def test_power_on_rejects_wrong_length(modified: ModifiedTables) -> None:
    with pytest.raises(
        InputError, match=re.escape("`switch_on_raw` must be a sequence of 3 floats (X, Y, Z), got tuple")
    ):
        gyrodrift.Corrector(modified).power_on((6000.0, 6000.0))


def test_corrector_rejects_a_non_model() -> None:
    message = "`model` must be a gyrodrift.ModifiedTables, PolynomialTables, RelativePolynomialTables or RecommendedTables, got dict"
    with pytest.raises(InputError, match=re.escape(message)):
        gyrodrift.Corrector({})  # type: ignore[arg-type]


# --- JSON ------------------------------------------------------------------------------------


def test_bad_json_syntax(modified: ModifiedTables) -> None:
    with pytest.raises(TableError, match=r"not a valid ModifiedTables JSON: .*line 1 column"):
        ModifiedTables.from_json("{not json")


def test_json_of_another_model_type(models: dict[str, Model]) -> None:
    with pytest.raises(
        TableError, match=r"not a valid ModifiedTables JSON: unknown field `range_celsius`.* at line"
    ):
        ModifiedTables.from_json(models["standard"].to_json())


TABLES = ["modified", "by_history", "standard", "third_order", "relative", "recommended"]


def nested_objects(value: Any, path: str = "") -> list[tuple[str, dict[str, Any]]]:
    """Every JSON object inside `value` with its path (`axes[0].stage1`), depth first."""
    found: list[tuple[str, dict[str, Any]]] = []
    if isinstance(value, dict):
        found.append((path, value))
        for key, item in value.items():
            found += nested_objects(item, f"{path}.{key}" if path else key)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            found += nested_objects(item, f"{path}[{i}]")
    return found


@pytest.mark.parametrize("name", TABLES)
def test_from_json_refuses_an_unknown_field_anywhere_and_names_it(
    evaluation: gyrodrift.Evaluation, name: str
) -> None:
    model = getattr(evaluation.fitted[0], name)
    kind = type(model)
    text = model.to_json()
    assert kind.from_json(text) == model
    objects = nested_objects(json.loads(text))
    assert len(objects) > 1, "the tables nest objects"
    for path, _ in objects:
        tables = json.loads(text)
        target = dict(nested_objects(tables))[path]
        target["colour"] = 1
        with pytest.raises(TableError, match=rf"not a valid {kind.__name__} JSON: unknown field `colour`"):
            kind.from_json(json.dumps(tables))


def test_fit_settings_from_json_refuses_an_unknown_field_and_names_it() -> None:
    settings = json.loads(gyrodrift.FitSettings().to_json())
    settings["lowpass_window"] = 1.0
    with pytest.raises(InputError, match="unknown field `lowpass_window`"):
        gyrodrift.FitSettings.from_json(json.dumps(settings))


def test_json_with_invalid_contents_names_the_field(modified: ModifiedTables) -> None:
    tables = json.loads(modified.to_json())
    tables["axes"][2]["reference_ms"][3] = tables["axes"][2]["reference_ms"][2]
    message = "invalid tables: axes[2].reference_ms[3]: not strictly greater than the previous value"
    with pytest.raises(TableError, match=re.escape(message)):
        ModifiedTables.from_json(json.dumps(tables))


def test_json_beyond_the_capacities(modified: ModifiedTables) -> None:
    tables = json.loads(modified.to_json())
    tables["axes"][0]["reference_ms"] = list(range(1, 18))  # capacity is 16
    with pytest.raises(TableError, match=r"not a valid ModifiedTables JSON: invalid length 17"):
        ModifiedTables.from_json(json.dumps(tables))


def test_json_polynomial_with_inverted_range(models: dict[str, Model]) -> None:
    tables = json.loads(models["standard"].to_json())
    tables["axes"][1]["range_celsius"] = [40.0, 20.0]
    with pytest.raises(TableError, match=re.escape("axes[1].range_celsius[1]: not strictly greater")):
        PolynomialTables.from_json(json.dumps(tables))


def test_json_must_be_text() -> None:
    with pytest.raises(InputError, match=re.escape("`text` must be a str, got bytes")):
        ModifiedTables.from_json(b"{}")  # type: ignore[arg-type]


# --- firmware images: one test per decode error ----------------------------------------------


def with_crc(body: bytes) -> bytes:
    """An image body (header + payload) with its CRC-32/ISO-HDLC trailer (zlib's crc32)."""
    return body + struct.pack("<I", zlib.crc32(body))


@pytest.fixture
def image(modified: ModifiedTables) -> bytes:
    return modified.to_image()


@pytest.mark.parametrize(
    ("corrupt", "message"),
    [
        (lambda b: b[:10], "table image truncated: needs 16 bytes, got 10"),
        (lambda b: b[:-1], "table image truncated: needs {n} bytes, got {m}"),
        (lambda b: b"JUNK" + b[4:], "not a gyrodrift table image: magic is [4a, 55, 4e, 4b]"),
        (lambda b: b'{"axes": []}', "not a gyrodrift table image: magic is [7b, 22, 61, 78]"),
        (
            lambda b: b[:4] + b"\x07\x00" + b[6:],
            "table image format version 7 is not supported (this build reads 1 and 2)",
        ),
        (
            lambda b: b[:4] + b"\x00\x00" + b[6:],
            "table image format version 0 is not supported (this build reads 1 and 2)",
        ),
        (
            lambda b: b[:6] + b"\x02" + b[7:],
            "the image holds a polynomial baseline (standard.bin, third_order.bin), "
            "where the paper's modified tables (modified.bin, by_history.bin) is expected",
        ),
        (lambda b: b + b"\x00\x00", "2 unexpected bytes after the table image's CRC"),
        (lambda b: b[:20] + bytes([b[20] ^ 1]) + b[21:], "table image CRC mismatch"),
        (
            lambda b: with_crc(b[:8] + struct.pack("<I", 3) + b[12:64] + b"\xff\xff\xff"),
            "table image payload is malformed",
        ),
        (
            lambda b: with_crc(b[:64] + struct.pack("<f", -1.0) + b[68:-4]),
            "table image contents are invalid: raw_per_celsius: must be greater than zero",
        ),
    ],
    ids=[
        "truncated-header",
        "truncated-body",
        "bad-magic",
        "not-an-image",
        "version-7",
        "version-0",
        "wrong-kind",
        "trailing-bytes",
        "crc-mismatch",
        "malformed-payload",
        "invalid-contents",
    ],
)
def test_each_image_error(image: bytes, corrupt: Any, message: str) -> None:
    bad = corrupt(image)
    message = message.format(n=len(image), m=len(image) - 1)
    with pytest.raises(ImageError, match=re.escape(message)):
        ModifiedTables.from_image(bad)


def test_image_of_the_other_kind(models: dict[str, Model]) -> None:
    with pytest.raises(
        ImageError,
        match=re.escape(
            "the image holds the paper's modified tables (modified.bin, by_history.bin), where a"
        ),
    ):
        PolynomialTables.from_image(models["modified"].to_image())


def test_image_must_be_bytes() -> None:
    with pytest.raises(InputError, match=re.escape("`data` must be bytes or bytearray, got str")):
        ModifiedTables.from_image("47594454")  # type: ignore[arg-type]


def test_image_from_bytearray(image: bytes, modified: ModifiedTables) -> None:
    assert ModifiedTables.from_image(bytearray(image)) == modified


# --- files -----------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["load_json", "load_image"])
def test_missing_file(tmp_path: Path, method: str) -> None:
    path = tmp_path / "missing.bin"
    with pytest.raises(FileError) as raised:
        getattr(ModifiedTables, method)(path)
    assert raised.value.errno == 2 and raised.value.filename == str(path)
    assert "cannot read file: No such file or directory" in str(raised.value)


@pytest.mark.parametrize("method", ["save_json", "save_image"])
def test_unwritable_file(tmp_path: Path, modified: ModifiedTables, method: str) -> None:
    path = tmp_path / "no-such-folder" / "model"
    with pytest.raises(FileError, match="cannot write file"):
        getattr(modified, method)(path)
    assert not path.parent.exists()


def test_json_file_that_is_not_text(tmp_path: Path, image: bytes) -> None:
    path = tmp_path / "model.json"
    path.write_bytes(image)
    with pytest.raises(FileError, match="did not contain valid UTF-8"):
        ModifiedTables.load_json(path)


def test_path_must_be_a_path(modified: ModifiedTables) -> None:
    with pytest.raises(InputError, match=re.escape("`path` must be a str or os.PathLike path, got int")):
        modified.save_json(3)  # type: ignore[arg-type]


# --- settings --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"raw_per_celsius": 0.0}, TableError, "invalid tables: raw_per_celsius: must be greater than zero"),
        ({"raw_per_celsius": float("nan")}, TableError, "raw_per_celsius: value is NaN or infinite"),
        ({"rise_margin_celsius": -0.1}, TableError, "rise_margin_celsius: must not be negative"),
        ({"raw_at_zero_celsius": "zero"}, InputError, "`raw_at_zero_celsius` must be a float, got str"),
        (
            {"stuck_after_samples": 70000},
            InputError,
            "`stuck_after_samples` must be an integer in 0..=65535, got 70000",
        ),
        (
            {"stuck_after_samples": -1},
            InputError,
            "`stuck_after_samples` must be an integer in 0..=65535, got -1",
        ),
    ],
)
def test_settings_validation(kwargs: dict[str, Any], error: type[Exception], message: str) -> None:
    with pytest.raises(error, match=re.escape(message)):
        gyrodrift.Settings(**kwargs)


def test_with_settings_needs_settings(modified: ModifiedTables) -> None:
    with pytest.raises(InputError, match=re.escape("`settings` must be a gyrodrift.Settings, got dict")):
        modified.with_settings({"raw_per_celsius": 100.0})  # type: ignore[arg-type]
