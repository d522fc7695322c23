"""The report's tables as text, from the records of `evaluate` (or `summarise`): formatting only."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from .models import model_name

AXES = ("X", "Y", "Z")
MODELS = ("standard", "3rd-order", "relative", "modified")
"""The rows: the three standard baselines and the paper's model; add "by-history" or "uncorrected"."""
BASELINES = ("standard", "3rd-order", "relative")
"""The standard baselines a ratio may be taken against: the best of them on each cell's data."""
SPLIT_NAMES = {
    "validation": "validation",
    "held_out_repeat": "held-out repeat",
    "field": "field",
    "noise_floor": "noise floor",
}


def _rows(records: Sequence[Mapping[str, Any]]) -> list[tuple[float, str]]:
    """(set point, split) rows of the paper's table: held-out repeats and validation, by set point."""
    rows = {
        (float(r["set_point_celsius"]), str(r["split"]))
        for r in records
        if r["split"] in ("held_out_repeat", "validation")
    }
    return sorted(rows)


def paper_table(records: Iterable[Mapping[str, Any]], *, models: Sequence[str] = MODELS) -> str:
    """The paper's Table as Markdown: rows model × set point, columns unit × axis, mean drift in °/s,
    then per set point the best standard baseline / modified ratio, naming the baseline (as
    `report.md`'s "Drift per unit and axis"). Noise-floor units and field sessions are left out.
    `models` may spell a model either way (`"3rd-order"` or `"third_order"`); an unknown name raises
    `InputError`."""
    models = [model_name(m) for m in models]
    records = [r for r in records if not str(r["unit"]).startswith("noise:")]
    units = sorted({str(r["unit"]) for r in records})
    index = {
        (r["unit"], round(float(r["set_point_celsius"]) * 1000), r["split"], r["model"], r["axis"]): float(
            r["drift_dps"]
        )
        for r in records
    }

    def drift(unit: str, set_point: float, split: str, model: str, axis: str) -> float | None:
        return index.get((unit, round(set_point * 1000), split, model, axis))

    header = "| calibration | set point | data |" + "".join(f" {u} {a} |" for u in units for a in AXES)
    lines = [header, "|---|---|---|" + "---:|" * (len(units) * len(AXES))]
    for model in models:
        for set_point, split in _rows(records):
            cells = [drift(u, set_point, split, model, a) for u in units for a in AXES]
            text = "".join(" – |" if v is None else f" {v:.4f} |" for v in cells)
            lines.append(f"| {model} | {set_point:+g} °C | {SPLIT_NAMES[split]} |{text}")
    for set_point, split in _rows(records):
        ratios: list[str] = []
        for u in units:
            for a in AXES:
                modified = drift(u, set_point, split, "modified", a)
                found = [(v, b) for b in BASELINES if (v := drift(u, set_point, split, b, a)) is not None]
                if modified is None or modified <= 0 or not found:
                    ratios.append(" – |")
                    continue
                best, name = min(found)
                ratios.append(f" {best / modified:.2f}× ({name}) |")
        lines.append(
            f"| best baseline / modified | {set_point:+g} °C | {SPLIT_NAMES[split]} |{''.join(ratios)}"
        )
    return "\n".join(lines) + "\n"
