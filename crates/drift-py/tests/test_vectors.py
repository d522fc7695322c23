"""The shared test vectors (testdata/vectors.json), reproduced bit for bit from Python."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import gyrodrift
from conftest import Case, Model, powered_corrector, same_bits


def check_batch(case: Case, corrected: np.ndarray, bias: np.ndarray, flags: np.ndarray) -> None:
    n = len(case.times)
    assert corrected.shape == bias.shape == flags.shape == (n, 3)
    assert flags.dtype == np.uint16
    bad = ~same_bits(case.corrected, corrected) | ~same_bits(case.bias, bias) | (flags != case.flags)
    rows = np.flatnonzero(bad.any(axis=1))
    assert rows.size == 0, f"{case.name}: {rows.size} of {n} samples differ, first at {rows[:5]}"


def test_vectors_cover_every_model_and_enough_samples(cases: list[Case], models: dict[str, Model]) -> None:
    assert (
        {c.model for c in cases}
        == set(models)
        == {
            "modified",
            "standard",
            "third_order",
            "extended",
            "by_history",
            "warm_started",
            "recommended",
        }
    )
    assert sum(len(c.times) for c in cases) > 1000
    with_aux = [c for c in cases if c.aux is not None]
    assert {c.model for c in with_aux} == {"extended"}
    assert all(c.aux is not None and c.aux.shape == (len(c.times), 4) for c in with_aux)
    # The extended model is also run without aux (drift-core's `correct`): its terms hold, flagged.
    assert any(c.model == "extended" and c.aux is None for c in cases)


def test_extended_cases_exercise_the_extension(cases: list[Case], models: dict[str, Model]) -> None:
    """Guards the tests below against passing vacuously: the extended model has terms, and its
    cases include the new flag."""
    extended = models["extended"]
    assert isinstance(extended, gyrodrift.ModifiedTables) and len(extended.extension) == 4
    flags = np.concatenate([c.flags for c in cases if c.model == "extended"])
    assert (flags & gyrodrift.Flags.EXTENSION_INPUT_INVALID).any()


def test_history_cases_start_with_what_was_kept(cases: list[Case], models: dict[str, Model]) -> None:
    """Guards the tests below against passing vacuously: cases with a kept previous activation
    exist (history-keyed and not, and the extended model's rate at switch-on), `powered_corrector`
    starts them with `power_on_after`, and they exercise both history flags."""
    with_previous = [c for c in cases if c.previous is not None]
    assert {c.model for c in with_previous} == {
        "by_history",
        "extended",
        "modified",
        "warm_started",
        "recommended",
    }
    assert all(c.previous is not None and c.previous.shape == (3, 2) for c in with_previous)
    flags = np.concatenate([c.flags for c in cases if c.model == "by_history"])
    for flag in (gyrodrift.Flags.HISTORY_UNKNOWN, gyrodrift.Flags.HISTORY_OUT_OF_SPAN):
        assert (flags & flag).any(), flag
    # The same samples started with `power_on` instead differ: the kept values are read (stage 3
    # keyed by history; the warm starts' initial bias; the rate filter's start).
    for model in ("by_history", "warm_started", "extended", "recommended"):
        case = next(c for c in with_previous if c.model == model and c.switch_on_raw is not None)
        cold = gyrodrift.Corrector(models[case.model])
        cold.power_on(case.switch_on_raw)
        corrected, _, _ = cold.correct_batch(case.times, case.rate, case.temperature, aux=case.aux)
        assert not same_bits(case.corrected, corrected).all(), model


def test_power_on_after_returns_what_to_keep(cases: list[Case], models: dict[str, Model]) -> None:
    """`power_on_after` returns the flags and a new (3, 2) float32 array (this activation's ambient,
    switch-off NaN); `keep` records the last good temperature as switch-off; neither modifies its
    argument. float64 arrays and nested lists (exact widenings) give the same bits."""
    case = next(c for c in cases if c.model == "by_history" and c.name == "history-warm-start")
    assert case.previous is not None and case.switch_on_raw is not None
    raw, previous = case.switch_on_raw, case.previous
    given = previous.copy()
    corrector = gyrodrift.Corrector(models[case.model])
    flags, kept = corrector.power_on_after(raw, previous)
    assert previous.tobytes() == given.tobytes()
    assert len(flags) == 3 and all(isinstance(f, int) for f in flags)
    assert kept.shape == (3, 2) and kept.dtype == np.float32
    assert np.isfinite(kept[:, 0]).all() and np.isnan(kept[:, 1]).all()
    for other in (previous.astype(np.float64), previous.tolist(), np.asfortranarray(previous), previous.T.T):
        again_flags, again_kept = gyrodrift.Corrector(models[case.model]).power_on_after(raw, other)
        assert again_flags == flags and again_kept.tobytes() == kept.tobytes()
    corrected, _, _ = corrector.correct_batch(case.times, case.rate, case.temperature)
    assert same_bits(case.corrected, corrected).all()
    after = corrector.keep(kept)
    assert np.isnan(kept[:, 1]).all()  # not modified
    assert after.shape == (3, 2) and after.dtype == np.float32
    assert after[:, 0].tobytes() == kept[:, 0].tobytes()
    finite = np.isfinite(case.temperature)
    last_raw = np.array([case.temperature[finite[:, a], a][-1] for a in range(3)], np.float32)
    last_good = last_raw / np.float32(200.0)  # the fixture's raw_per_celsius, zero at 0 raw
    assert np.isfinite(after[:, 1]).all()
    np.testing.assert_allclose(after[:, 1], last_good, rtol=1e-6)
    corrector.power_off()
    assert corrector.keep(after).tobytes() == after.tobytes()  # not powered on: unchanged


@pytest.mark.parametrize(
    "previous",
    [
        np.zeros((2, 3), np.float32),
        np.zeros((3, 3), np.float64),
        np.zeros(6, np.float32),
        np.zeros((3, 2), np.int64),
        [[1.0, 2.0], [3.0, 4.0]],
        "nothing",
    ],
)
def test_previous_of_the_wrong_shape_is_refused(previous: Any, models: dict[str, Model]) -> None:
    corrector = gyrodrift.Corrector(models["by_history"])
    with pytest.raises(ValueError, match=r"`previous` must be .*shape \(3, 2\)"):
        corrector.power_on_after([6600.0, 6600.0, 6600.0], previous)
    assert not corrector.is_powered_on
    with pytest.raises(gyrodrift.InputError, match=r"`previous` must be .*shape \(3, 2\)"):
        corrector.keep(previous)


def test_power_on_after_refuses_a_non_finite_switch_on(models: dict[str, Model]) -> None:
    corrector = gyrodrift.Corrector(models["by_history"])
    nothing = np.full((3, 2), np.nan, np.float32)
    with pytest.raises(gyrodrift.InputError, match="switch_on_raw"):
        corrector.power_on_after([6600.0, np.nan, 6600.0], nothing)
    assert not corrector.is_powered_on
    flags, kept = corrector.power_on_after([6600.0, 6600.0, 6600.0], nothing)
    assert all(f & gyrodrift.Flags.HISTORY_UNKNOWN for f in flags)
    assert (kept[:, 0] == np.float32(33.0)).all()


def test_batch_reproduces_every_case(cases: list[Case], models: dict[str, Model]) -> None:
    for case in cases:
        corrector = powered_corrector(models[case.model], case)
        check_batch(case, *corrector.correct_batch(case.times, case.rate, case.temperature, aux=case.aux))


def per_sample(corrector: gyrodrift.Corrector, case: Case, aux: list[Any]) -> list[gyrodrift.Output]:
    return [
        corrector.correct(int(t), rate, temperature, aux=a)
        for t, rate, temperature, a in zip(case.times, case.rate, case.temperature, aux)
    ]


def test_per_sample_reproduces_every_case(cases: list[Case], models: dict[str, Model]) -> None:
    for case in cases:
        corrector = powered_corrector(models[case.model], case)
        # aux per sample as a (4,) float32 row, or None (drift-core's `correct`).
        aux: list[Any] = [None] * len(case.times) if case.aux is None else list(case.aux)
        outputs = per_sample(corrector, case, aux)
        corrected = np.array([o.corrected_dps for o in outputs], dtype=np.float32)
        bias = np.array([o.bias_dps for o in outputs], dtype=np.float32)
        flags = np.array([o.flags for o in outputs], dtype=np.uint16)
        check_batch(case, corrected, bias, flags)


def test_per_sample_aux_as_python_floats(cases: list[Case], models: dict[str, Model]) -> None:
    """A sequence of 4 Python floats (exact widenings of the f32 inputs, NaN included) works too."""
    for case in cases:
        if case.aux is None:
            continue
        corrector = powered_corrector(models[case.model], case)
        outputs = per_sample(corrector, case, [[float(v) for v in row] for row in case.aux])
        check_batch(
            case,
            np.array([o.corrected_dps for o in outputs], dtype=np.float32),
            np.array([o.bias_dps for o in outputs], dtype=np.float32),
            np.array([o.flags for o in outputs], dtype=np.uint16),
        )


def test_aux_none_is_correct_without_aux(cases: list[Case], models: dict[str, Model]) -> None:
    """`aux=None` is drift-core's `correct`: the same as NaN auxiliary inputs, flagged."""
    case = next(c for c in cases if c.aux is not None)
    without = powered_corrector(models[case.model], case).correct_batch(
        case.times, case.rate, case.temperature
    )
    nan_aux = np.full((len(case.times), 4), np.nan, np.float32)
    with_nan = powered_corrector(models[case.model], case).correct_batch(
        case.times, case.rate, case.temperature, aux=nan_aux
    )
    for a, b in zip(without, with_nan):
        assert a.tobytes() == b.tobytes()
    assert (without[2] & gyrodrift.Flags.EXTENSION_INPUT_INVALID).all()


def test_aux_is_ignored_by_models_without_aux_terms(cases: list[Case], models: dict[str, Model]) -> None:
    """Models without extra terms give the same bits with any aux (they have nothing to read it)."""
    for case in cases:
        if case.model == "extended":
            continue
        aux = np.full((len(case.times), 4), 3.5, np.float32)
        corrector = powered_corrector(models[case.model], case)
        check_batch(case, *corrector.correct_batch(case.times, case.rate, case.temperature, aux=aux))


@pytest.mark.parametrize("layout", ["float64", "fortran", "strided", "reversed-copy"])
def test_batch_is_layout_and_dtype_independent(
    layout: str, cases: list[Case], models: dict[str, Model]
) -> None:
    """float64 inputs (exact widenings of the vectors' f32) and non-contiguous views give the same bits."""
    for case in cases:
        aux = case.aux
        if layout == "float64":
            rate, temperature = case.rate.astype(np.float64), case.temperature.astype(np.float64)
            times = case.times
            aux = None if aux is None else aux.astype(np.float64)
        elif layout == "fortran":
            rate, temperature = np.asfortranarray(case.rate), np.asfortranarray(case.temperature)
            times = case.times
            aux = None if aux is None else np.asfortranarray(aux)
        elif layout == "strided":
            # Every other row of a doubled array, and every other column of a widened one.
            rate = np.repeat(case.rate, 2, axis=0)[::2]
            temperature = np.repeat(case.temperature, 2, axis=1)[:, ::2]
            times = np.repeat(case.times, 2)[::2]
            assert not rate.flags.c_contiguous and not temperature.flags.c_contiguous
            assert not times.flags.c_contiguous
            if aux is not None:
                aux = np.repeat(aux, 2, axis=1)[:, ::2]
                assert not aux.flags.c_contiguous
        else:
            rate = case.rate[::-1].copy()[::-1]
            temperature = case.temperature[::-1].copy()[::-1]
            times = case.times[::-1].copy()[::-1]
            aux = None if aux is None else aux[::-1].copy()[::-1]
        corrector = powered_corrector(models[case.model], case)
        check_batch(case, *corrector.correct_batch(times, rate, temperature, aux=aux))


def test_only_aux_in_another_layout_still_gives_the_same_bits(
    cases: list[Case], models: dict[str, Model]
) -> None:
    """float32 C-contiguous inputs with a float64 or strided `aux` (the staged path for one input)."""
    for case in cases:
        if case.aux is None:
            continue
        for aux in (case.aux.astype(np.float64), np.repeat(case.aux, 2, axis=0)[::2]):
            corrector = powered_corrector(models[case.model], case)
            check_batch(case, *corrector.correct_batch(case.times, case.rate, case.temperature, aux=aux))


def test_a_case_split_into_batches_continues_the_activation(
    cases: list[Case], models: dict[str, Model]
) -> None:
    for case in cases:
        corrector = powered_corrector(models[case.model], case)
        parts = [
            corrector.correct_batch(
                case.times[s],
                case.rate[s],
                case.temperature[s],
                aux=None if case.aux is None else case.aux[s],
            )
            for s in (slice(0, 1), slice(1, 7), slice(7, None))
            if len(case.times[s])
        ]
        check_batch(case, *(np.concatenate(outputs) for outputs in zip(*parts)))


def test_models_from_json_equal_models_from_images(vectors: dict, models: dict[str, Model]) -> None:
    import json

    for named in vectors["models"]:
        cls = type(models[named["name"]])
        assert cls.from_json(json.dumps(named["tables"])) == models[named["name"]]


def test_images_are_reproduced_byte_for_byte(vectors: dict, models: dict[str, Model]) -> None:
    for named in vectors["models"]:
        assert models[named["name"]].to_image() == bytes.fromhex(named["image_hex"])


def test_outputs_are_fresh_writeable_c_contiguous_arrays(cases: list[Case], models: dict[str, Model]) -> None:
    case = cases[0]
    corrector = powered_corrector(models[case.model], case)
    corrected, bias, flags = corrector.correct_batch(case.times, case.rate, case.temperature)
    assert (corrected.dtype, bias.dtype, flags.dtype) == (np.float32, np.float32, np.uint16)
    for array in (corrected, bias, flags):
        assert array.flags.c_contiguous and array.flags.writeable
    corrected[:] = 0  # the caller owns them: writing does not disturb the corrector
    again = powered_corrector(models[case.model], case).correct_batch(case.times, case.rate, case.temperature)
    assert same_bits(case.corrected, again[0]).all()


def test_out_arrays_receive_the_same_results(cases: list[Case], models: dict[str, Model]) -> None:
    """`out=` writes into the caller's arrays (reusable buffers) and returns those same arrays."""
    for case in cases:
        n = len(case.times)
        out = (np.full((n, 3), 7, np.float32), np.full((n, 3), 7, np.float32), np.full((n, 3), 7, np.uint16))
        corrector = powered_corrector(models[case.model], case)
        returned = corrector.correct_batch(case.times, case.rate, case.temperature, aux=case.aux, out=out)
        assert all(r is o for r, o in zip(returned, out))
        check_batch(case, *out)
