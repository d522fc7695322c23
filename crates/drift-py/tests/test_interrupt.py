"""Ctrl-C during a long call raises KeyboardInterrupt and leaves nothing half-written; a `progress`
callable is told how far the call got. Each long call runs on an input that would take many
seconds, interrupted shortly after it starts (as Ctrl-C does: the interpreter's SIGINT flag)."""

from __future__ import annotations

import _thread
import signal
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import gyrodrift

# Repeats of the small campaign's activations: far more work than the interruption lets run.
MANY = 2000


def interrupted(call: Callable[[], Any], after_s: float = 0.3) -> None:
    """Runs `call`, sending the main thread SIGINT's KeyboardInterrupt `after_s` after it starts;
    the call must stop within a second of the signal."""
    sent: list[float] = []

    def send() -> None:
        sent.append(time.monotonic())
        _thread.interrupt_main()

    # Python's own SIGINT handler, as in an interactive session: a process started in the
    # background by a non-interactive shell (CI, nohup) inherits SIGINT ignored, and then
    # `interrupt_main` does nothing.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(after_s, send)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
        stopped = time.monotonic()
    finally:
        timer.cancel()
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert stopped - sent[0] < 1.0, f"stopped {stopped - sent[0]:.2f} s after the signal"


@pytest.fixture(scope="module")
def segments(campaign_dir: Path) -> list[gyrodrift.Segment]:
    return [s for r in gyrodrift.load_campaign(campaign_dir) for s in r.segments]


@pytest.fixture(scope="module")
def many_files(campaign_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder of the small campaign's recordings linked many times: a long read for no disk."""
    folder = tmp_path_factory.mktemp("many")
    recordings = sorted((campaign_dir / "recordings").glob("*.mcap"))
    for i in range(MANY // len(recordings)):
        for recording in recordings:
            (folder / f"copy{i:04d}-{recording.name}").symlink_to(recording)
    return folder


def test_simulate_stops_and_leaves_no_campaign_nor_staging_folder(tmp_path: Path) -> None:
    out = tmp_path / "campaign"
    interrupted(lambda: gyrodrift.simulate(out, units=2))
    assert not out.exists()
    assert list(tmp_path.iterdir()) == [], "no staging folder left"


def test_simulate_forced_over_a_campaign_keeps_the_earlier_one_whole(tmp_path: Path) -> None:
    out = tmp_path / "campaign"
    tiny = {"protocol": {"activations": 2, "activation_s": 3.0}}
    earlier = gyrodrift.simulate(out, tiny, units=1, set_points=[30.0], intervals=[1.0], repeats=1)
    interrupted(lambda: gyrodrift.simulate(out, units=2, force=True))
    assert [p.name for p in tmp_path.iterdir()] == ["campaign"], "no staging folder left"
    assert sorted(p.name for p in (out / "recordings").iterdir()) == sorted(
        Path(f["recording"]).name for f in earlier["files"]
    )


def test_fit_evaluate_and_report_stop(
    many_files: Path, segments: list[gyrodrift.Segment], tmp_path: Path
) -> None:
    interrupted(lambda: gyrodrift.fit(segments * MANY))
    interrupted(lambda: gyrodrift.fit(many_files))
    interrupted(lambda: gyrodrift.evaluate(many_files))
    out = tmp_path / "report"
    interrupted(lambda: gyrodrift.report(many_files, out))
    assert not out.exists() or list(out.iterdir()) == [], "nothing of the report written"


def test_reading_and_diagnosing_stop(
    many_files: Path, segments: list[gyrodrift.Segment], evaluation: gyrodrift.Evaluation
) -> None:
    interrupted(lambda: gyrodrift.load_campaign(many_files))
    (unit,) = evaluation.fitted
    interrupted(lambda: unit.diagnose(segments * MANY))
    interrupted(lambda: unit.diagnose(many_files))
    interrupted(lambda: unit.evaluate_series(segments * MANY))


def test_diagnosing_stops_within_a_second_while_it_ranks(
    segments: list[gyrodrift.Segment], evaluation: gyrodrift.Evaluation
) -> None:
    """The ranking's shuffle tests are seconds of work on ten copies of the small campaign; Ctrl-C
    sent when `progress` first hears of them stops the call well before they end."""
    (unit,) = evaluation.fitted
    ranking = "ranking the candidates per axis"
    calls: list[tuple[str, int, int]] = []
    sent: list[float] = []

    def progress(step: str, done: int, total: int) -> None:
        calls.append((step, done, total))
        if step == ranking and not sent:
            sent.append(time.monotonic())
            _thread.interrupt_main()

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            unit.diagnose(segments * 10, progress=progress)
        stopped = time.monotonic()
    finally:
        signal.signal(signal.SIGINT, previous)
    assert sent, f"the ranking was never reported: {calls}"
    assert stopped - sent[0] < 1.0, f"{stopped - sent[0]:.2f} s after the signal"
    step, done, total = calls[-1]
    assert step == ranking and done < total, calls
    monotonic(calls)


def test_after_an_interruption_the_same_call_runs_whole(
    campaign_dir: Path, segments: list[gyrodrift.Segment]
) -> None:
    interrupted(lambda: gyrodrift.fit(segments * MANY))
    (unit,) = gyrodrift.fit(campaign_dir)
    assert unit.unit_id == "GIU-01"


def monotonic(calls: list[tuple[str, int, int]]) -> None:
    """Within each step the count never goes back and never passes the total."""
    for (step, done, total), (next_step, next_done, _) in zip(calls, calls[1:]):
        if step == next_step:
            assert next_done >= done, calls
        assert 0 <= done <= total, calls


def test_progress_counts_grow_to_the_total(
    tmp_path: Path, campaign_dir: Path, segments: list[gyrodrift.Segment]
) -> None:
    calls: list[tuple[str, int, int]] = []

    def progress(step: str, done: int, total: int) -> None:
        calls.append((step, done, total))

    summary = gyrodrift.simulate(
        tmp_path / "c",
        {"protocol": {"activations": 2, "activation_s": 3.0}},
        units=1,
        set_points=[30.0],
        intervals=[1.0],
        repeats=1,
        progress=progress,
    )
    assert calls, "called at least once, at the end"
    monotonic(calls)
    assert calls[-1] == ("simulating", summary["samples"], summary["samples"])

    calls.clear()
    gyrodrift.fit(segments * 3, progress=progress)
    monotonic(calls)
    step, done, total = calls[-1]
    assert (step, done) == ("analysing activations", total) and total > 0

    calls.clear()
    gyrodrift.fit(campaign_dir, progress=progress)
    monotonic(calls)
    assert calls[-1][1:] == (3, 3), "the campaign's 3 recordings, all done"


def test_an_exception_in_progress_stops_the_call_and_is_raised(tmp_path: Path) -> None:
    class Stop(Exception):
        pass

    def progress(step: str, done: int, total: int) -> None:
        raise Stop(step)

    out = tmp_path / "campaign"
    with pytest.raises(Stop, match="simulating"):
        gyrodrift.simulate(out, units=2, progress=progress)
    assert list(tmp_path.iterdir()) == []


def test_progress_must_be_callable(campaign_dir: Path) -> None:
    with pytest.raises(gyrodrift.InputError, match="`progress` must be None or a callable"):
        gyrodrift.fit(campaign_dir, progress=3)  # type: ignore[arg-type]
