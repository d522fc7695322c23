"""`pickle` and `copy.deepcopy` round-trip every public class, and objects cross processes."""

from __future__ import annotations

import copy
import multiprocessing
import pickle
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gyrodrift
from conftest import SMALL_CAMPAIGN, same_bits


@pytest.fixture(scope="module")
def fitted(campaign_dir: Path) -> gyrodrift.FittedUnit:
    (unit,) = gyrodrift.fit(campaign_dir)
    return unit


@pytest.fixture(scope="module")
def recording(campaign_dir: Path) -> gyrodrift.Recording:
    return gyrodrift.Recording.load(campaign_dir / "recordings" / "GIU-01_sp+33.0C_protocol.mcap")


def round_trips(value: Any) -> list[Any]:
    return [pickle.loads(pickle.dumps(value)), copy.deepcopy(value), copy.copy(value)]


def same_arrays(a: Any, b: Any) -> bool:
    return bool(np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True))


def test_value_classes_compare_equal_after_a_round_trip(fitted: gyrodrift.FittedUnit) -> None:
    term = gyrodrift.ExtraTerm("aux", 0, centre=(5.0,) * 3, coefficient=(0.01, 0, 0), time_constant_ms=1000)
    output = gyrodrift.Corrector(fitted.modified).correct(0, (0.1, 0.2, 0.3), (6000.0, 6000.0, 6000.0))
    values = [
        fitted.modified,
        fitted.by_history,
        fitted.standard,
        fitted.third_order,
        fitted.relative,
        fitted.recommended,
        fitted.modified.with_extension([term]),
        gyrodrift.Settings(raw_per_celsius=100.0, stuck_after_samples=7),
        term,
        gyrodrift.FitSettings(),
        gyrodrift.Labels(unit_id="BENCH-7", set_point_celsius=30.0, repeat=2, activation=3, interval_min=5.0),
        output,
    ]
    for value in values:
        for back in round_trips(value):
            assert type(back) is type(value)
            assert back == value


def test_a_fitted_unit_keeps_its_tables_curves_and_notes(fitted: gyrodrift.FittedUnit) -> None:
    for back in round_trips(fitted):
        assert back.unit_id == fitted.unit_id
        for name in ("modified", "by_history", "standard", "third_order", "relative", "recommended"):
            assert getattr(back, name) == getattr(fitted, name)
            assert getattr(back, name).to_image() == getattr(fitted, name).to_image()
        assert back.notes == fitted.notes
        assert back.settings == fitted.settings
        assert repr(back) == repr(fitted)


def test_segments_recordings_and_aux_channels_keep_every_sample(recording: gyrodrift.Recording) -> None:
    for back in round_trips(recording):
        assert back.unit_id == recording.unit_id
        assert back.metadata == recording.metadata
        assert len(back.segments) == len(recording.segments)
        for a, b in zip(recording.segments, back.segments):
            assert a.labels == b.labels
            assert same_arrays(a.rate_dps, b.rate_dps)
            assert same_arrays(a.temperature_raw, b.temperature_raw)
            assert same_arrays(a.since_power_on_ms, b.since_power_on_ms)
            assert a.aux.keys() == b.aux.keys() and (a.sample_rate_hz, a.power_on_ns) == (
                b.sample_rate_hz,
                b.power_on_ns,
            )
            volts, again = a.aux_channel("supply_voltage"), b.aux_channel("supply_voltage")
            assert (volts.unit, volts.sample_rate_hz) == (again.unit, again.sample_rate_hz)
            assert same_arrays(volts.values, again.values)
    channel = recording.segments[0].aux_channel("accel_x")
    for back in round_trips(channel):
        assert same_arrays(back.values, channel.values) and back.unit == channel.unit


def test_an_evaluation_its_results_and_analysed_activations_round_trip(
    evaluation: gyrodrift.Evaluation,
) -> None:
    for back in round_trips(evaluation):
        assert back.records == evaluation.records
        assert back.noise_floor_units == evaluation.noise_floor_units
        assert back.timings == evaluation.timings
        assert [f.modified for f in back.fitted] == [f.modified for f in evaluation.fitted]
        for a, b in zip(evaluation.calibration, back.calibration):
            assert a.labels == b.labels and len(a) == len(b)
            assert same_arrays(a.drift_dps, b.drift_dps) and same_arrays(a.rise_celsius, b.rise_celsius)
    result = evaluation.results[0]
    for back in round_trips(result):
        assert (back.split, back.labels) == (result.split, result.labels)
        assert back.drift_dps == result.drift_dps and back.flags == result.flags


def test_a_diagnosis_round_trips(campaign_dir: Path, fitted: gyrodrift.FittedUnit) -> None:
    diagnosis = fitted.diagnose(gyrodrift.load_campaign(campaign_dir), extend=True)
    for back in round_trips(diagnosis):
        assert repr(back) == repr(diagnosis)
        for name in ("ranking", "paper_ranking", "chosen", "proposed_terms", "admissions", "stage3"):
            assert getattr(back, name) == getattr(diagnosis, name), name
        assert back.warm_start == diagnosis.warm_start and back.before_after == diagnosis.before_after
        assert back.extended == diagnosis.extended and back.activations == diagnosis.activations
        profiles, again = diagnosis.profiles, back.profiles
        assert profiles.keys() == again.keys()
        assert all(same_arrays(profiles[k], again[k]) for k in profiles if k != "series_kind")


def test_another_versions_state_is_refused_by_name(fitted: gyrodrift.FittedUnit) -> None:
    restore, (kind, _version, state) = fitted.__reduce__()
    with pytest.raises(
        gyrodrift.InputError, match=r"cannot unpickle a gyrodrift FittedUnit of version 0\.0\.0"
    ):
        restore(kind, "0.0.0", state)
    with pytest.raises(gyrodrift.InputError, match="cannot unpickle FittedUnit: corrupt state"):
        restore(kind, gyrodrift.__version__, state[: len(state) // 2])


def fit_images(segments: list[gyrodrift.Segment]) -> tuple[gyrodrift.FittedUnit, bytes]:
    (unit,) = gyrodrift.fit(segments)
    return unit, unit.modified.to_image()


def test_segments_go_to_worker_processes_and_fitted_units_come_back(campaign_dir: Path) -> None:
    segments = [s for r in gyrodrift.load_campaign(campaign_dir) for s in r.segments]
    here = fit_images(segments)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        (there,) = pool.map(fit_images, [segments])
    assert there[1] == here[1]
    assert there[0].modified == here[0].modified and there[0].relative == here[0].relative


def test_dask_with_processes_fits_three_units(tmp_path: Path) -> None:
    distributed = pytest.importorskip("dask.distributed", reason="the [distributed] extra is not installed")
    campaign = {**SMALL_CAMPAIGN, "name": "pytest-pickle", "units": 3, "set_points_celsius": [30.0, 40.0]}
    gyrodrift.simulate(tmp_path, campaign)
    recordings = gyrodrift.load_campaign(tmp_path)
    by_unit: dict[str, list[gyrodrift.Segment]] = {}
    for r in recordings:
        by_unit.setdefault(r.unit_id, []).extend(r.segments)
    assert len(by_unit) == 3
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        # Scattered (not embedded in the task graph): the segments are ~16 MB per unit.
        data = [client.scatter(segments) for segments in by_unit.values()]
        futures = client.map(fit_images, data, pure=False)
        results = client.gather(futures)
    for (unit, image), segments in zip(results, by_unit.values()):
        assert isinstance(unit, gyrodrift.FittedUnit)
        assert image == fit_images(segments)[1]
        assert unit.unit_id == segments[0].labels.unit_id


def test_a_corrector_continues_its_activation_after_a_round_trip(
    models: dict[str, Any], cases: list[Any]
) -> None:
    checked = 0
    for case in cases:
        if case.switch_on_raw is None or case.power_on_fails or case.previous is not None:
            continue
        model = models[case.model]
        half = len(case.times) // 2
        corrector = gyrodrift.Corrector(model)
        corrector.power_on(case.switch_on_raw)
        args = (case.times, case.rate, case.temperature)
        kwargs = {} if case.aux is None else {"aux": case.aux}
        first = corrector.correct_batch(
            *(a[:half] for a in args), **({k: v[:half] for k, v in kwargs.items()})
        )
        for back in round_trips(corrector):
            rest = back.correct_batch(*(a[half:] for a in args), **({k: v[half:] for k, v in kwargs.items()}))
            corrected = np.concatenate([first[0], rest[0]])
            assert same_bits(case.corrected, corrected).all(), case.name
        checked += 1
    assert checked >= 3


def test_a_stillness_learner_continues_where_it_was_pickled() -> None:
    rng = np.random.default_rng(3)
    n = 12_000  # 12 s at 1 kHz: still long enough to learn
    rate = (0.02 + 0.001 * rng.standard_normal((n, 3))).astype(np.float32)
    accel = np.tile(np.float32([0.0, 0.0, 1.0]), (n // 10, 1))
    whole = gyrodrift.StillnessLearner(still_for_s=2.0)
    expected, _, learning = whole.update_batch(rate, accel)
    assert learning.any()
    half = n // 2
    learner = gyrodrift.StillnessLearner(still_for_s=2.0)
    first, _, _ = learner.update_batch(rate[:half], accel[: half // 10])
    for back in round_trips(learner):
        assert type(back) is gyrodrift.StillnessLearner
        assert back.offset_dps == learner.offset_dps
        rest, _, _ = back.update_batch(rate[half:], accel[half // 10 :])
        assert same_bits(expected, np.concatenate([first, rest])).all()


COVERED = {
    "ActivationResult",
    "AnalysedActivation",
    "AuxChannel",
    "Corrector",
    "Diagnosis",
    "Evaluation",
    "ExtraTerm",
    "FitSettings",
    "FittedUnit",
    "Labels",
    "ModifiedTables",
    "Output",
    "PolynomialTables",
    "Recording",
    "RecommendedTables",
    "RelativePolynomialTables",
    "Segment",
    "Settings",
    "StillnessLearner",
    "Uncertainty",
}


def test_every_public_class_is_covered_here_and_errors_pickle_too() -> None:
    classes = {
        name
        for name in gyrodrift.__all__
        if isinstance(getattr(gyrodrift, name), type)
        and not issubclass(getattr(gyrodrift, name), BaseException)
    }
    # Flags is an enum.IntFlag: pickles by value.
    assert classes - {"Flags"} == COVERED
    assert pickle.loads(pickle.dumps(gyrodrift.Flags.RATE_INVALID)) is gyrodrift.Flags.RATE_INVALID
    error = pickle.loads(pickle.dumps(gyrodrift.InputError("`x` must be finite")))
    assert isinstance(error, gyrodrift.InputError) and isinstance(error, ValueError)
    assert str(error) == "`x` must be finite"
