"""gyrodrift: remove the temperature-driven zero drift of MEMS gyroscopes.

The corrector is drift-core's, the code the firmware runs, bound with pyo3: a `Corrector` holds a
model (`ModifiedTables`, the paper's method, or a baseline: `PolynomialTables`,
`RelativePolynomialTables`) and one unit's run-time state, and corrects one sample (`correct`) or
numpy arrays (`correct_batch`) with the same f32 results as the firmware. The extended model
(`ModifiedTables.extension`, `ExtraTerm`) adds extra linear terms, some of which read auxiliary
inputs passed as `aux=`.

Around it, what the command line does: `simulate` a campaign, `Recording`/`Segment`/`load_campaign`
for MCAP recordings (read, build from arrays, write), `fit` the tables, `evaluate` them on data the
fit did not see (the report's table as records or a pandas DataFrame), `paper_table` to print it,
and `gyrodrift.plot` (matplotlib, the `[plot]` extra) for the report's figures.
"""

from __future__ import annotations

import enum

from . import _gyrodrift
from ._gyrodrift import (
    AUX_INPUTS,
    MAX_EXTRA_TERMS,
    ActivationResult,
    AnalysedActivation,
    AuxChannel,
    CampaignError,
    Corrector,
    Diagnosis,
    Evaluation,
    ExtraTerm,
    FileError,
    FitError,
    FitSettings,
    FittedUnit,
    GyrodriftError,
    ImageError,
    InputError,
    Labels,
    ModifiedTables,
    Output,
    PolynomialTables,
    RecommendedTables,
    Recording,
    RecordingError,
    RelativePolynomialTables,
    Segment,
    Settings,
    StillnessLearner,
    TableError,
    Uncertainty,
    __version__,
    analyse,
    evaluate,
    excess_cut,
    fit,
    load_campaign,
    report,
    resolve_campaign,
    simulate,
    summarise,
)
from .frames import correct_frame, results_frame
from .models import model_attribute, model_name
from .tables import paper_table

__all__ = [
    "AUX_INPUTS",
    "MAX_EXTRA_TERMS",
    "ActivationResult",
    "AnalysedActivation",
    "AuxChannel",
    "CampaignError",
    "Corrector",
    "Diagnosis",
    "Evaluation",
    "ExtraTerm",
    "FileError",
    "FitError",
    "FitSettings",
    "FittedUnit",
    "Flags",
    "GyrodriftError",
    "ImageError",
    "InputError",
    "Labels",
    "ModifiedTables",
    "Output",
    "PolynomialTables",
    "RecommendedTables",
    "Recording",
    "RecordingError",
    "RelativePolynomialTables",
    "Segment",
    "Settings",
    "StillnessLearner",
    "TableError",
    "Uncertainty",
    "__version__",
    "analyse",
    "correct_frame",
    "evaluate",
    "excess_cut",
    "fit",
    "load_campaign",
    "model_attribute",
    "model_name",
    "paper_table",
    "report",
    "resolve_campaign",
    "results_frame",
    "simulate",
    "summarise",
]


class Flags(enum.IntFlag):
    """Status flags, per axis and sample (the `flags` outputs are bitwise ORs of these).

    `Flags(value)` names the bits of one output value, e.g. `Flags(flags[i, 0])`.
    """

    AMBIENT_OUT_OF_RANGE = _gyrodrift.AMBIENT_OUT_OF_RANGE
    """Switch-on temperature outside the calibrated ambients: nearest ambient used (clamp)."""
    RISE_OUT_OF_SPAN = _gyrodrift.RISE_OUT_OF_SPAN
    """Temperature rise outside the stored curves' span: nearest curve's k used (clamp)."""
    PAST_LAST_REFERENCE = _gyrodrift.PAST_LAST_REFERENCE
    """Time past the last reference time: k held at its last value."""
    TEMPERATURE_OUT_OF_RANGE = _gyrodrift.TEMPERATURE_OUT_OF_RANGE
    """Polynomial baselines: temperature outside the fitted range (clamp)."""
    TEMPERATURE_INVALID = _gyrodrift.TEMPERATURE_INVALID
    """NaN/inf temperature: last good drift held."""
    TEMPERATURE_STUCK = _gyrodrift.TEMPERATURE_STUCK
    """Temperature unchanged for `stuck_after_samples`: last good drift held."""
    RATE_INVALID = _gyrodrift.RATE_INVALID
    """NaN/inf rate: passed through (output non-finite)."""
    NOT_POWERED_ON = _gyrodrift.NOT_POWERED_ON
    """No successful power_on: rate passed through uncorrected."""
    MODEL_INVALID = _gyrodrift.MODEL_INVALID
    """The tables produced a non-finite or implausible drift (beyond 1e4 deg/s: corrupt tables, or a
    temperature reading far outside any sensor): last good drift held."""
    EXTENSION_INPUT_INVALID = _gyrodrift.EXTENSION_INPUT_INVALID
    """Extended model: an auxiliary input an extra term reads is NaN/inf or was not passed
    (`aux=None`): that term holds its last filtered value (0 before any)."""
    HISTORY_UNKNOWN = _gyrodrift.HISTORY_UNKNOWN
    """Tables keyed by heating history, powered on without what was kept of the previous activation
    (`power_on`, or nothing finite kept for the axis in `power_on_after`): taken as a cold start."""
    HISTORY_OUT_OF_SPAN = _gyrodrift.HISTORY_OUT_OF_SPAN
    """Tables keyed by heating history: the residual heat at switch-on lies outside the stored
    histories' span (beyond the rise margin): the nearest history's curve is used (clamp)."""

    @classmethod
    def faults(cls) -> Flags:
        """The flags that mean a degraded correction (a hold or pass-through), not a clamp."""
        return cls(_gyrodrift.FAULTS)
