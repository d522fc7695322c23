"""The native module (pyo3). Use it through `gyrodrift`, which re-exports everything here.

Units are in the names: `_dps` is °/s, `_ms` milliseconds since switch-on, `_raw` raw
temperature-sensor units (see `Settings`), `_celsius` °C. All arithmetic is f32, as on the firmware.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Final, Literal, final, overload

import numpy as np
from numpy.typing import NDArray
from typing_extensions import TypeAlias

__version__: Final[str]
__all__ = [
    "AMBIENT_OUT_OF_RANGE",
    "AUX_INPUTS",
    "EXTENSION_INPUT_INVALID",
    "FAULTS",
    "FLAGS",
    "HISTORY_OUT_OF_SPAN",
    "HISTORY_UNKNOWN",
    "MAX_EXTRA_TERMS",
    "MODEL_INVALID",
    "NOT_POWERED_ON",
    "PAST_LAST_REFERENCE",
    "RATE_INVALID",
    "RISE_OUT_OF_SPAN",
    "TEMPERATURE_INVALID",
    "TEMPERATURE_OUT_OF_RANGE",
    "TEMPERATURE_STUCK",
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
    "_read_csv_text",
    "_restore",
    "analyse",
    "evaluate",
    "excess_cut",
    "fit",
    "load_campaign",
    "report",
    "resolve_campaign",
    "simulate",
    "summarise",
]

_Path: TypeAlias = str | os.PathLike[str]
_Floats3: TypeAlias = Sequence[float] | NDArray[np.floating]
_Model: TypeAlias = ModifiedTables | PolynomialTables | RelativePolynomialTables | RecommendedTables
_Previous: TypeAlias = NDArray[np.floating] | Sequence[Sequence[float]]
_FloatRows: TypeAlias = NDArray[np.floating] | Sequence[Sequence[float]]
_Floats: TypeAlias = NDArray[np.float32] | NDArray[np.float64]
_Floats4: TypeAlias = Sequence[float] | NDArray[np.floating]
_TermKind: TypeAlias = Literal["temperature_rate", "aux", "axis_rise", "rise_squared", "aux_times_rise"]
_Source: TypeAlias = _Path | Recording | Segment | Sequence[_Path | Recording | Segment]
# Called by a long call (at most every 0.1 s, when it moved) with (step, done, total): `done`
# grows within a step. An exception it raises stops the call and is raised from it.
_Progress: TypeAlias = Callable[[str, int, int], object]
_Record: TypeAlias = dict[str, Any]

# Status flags (bits of each `flags` output value); `gyrodrift.Flags` is the IntFlag of these.
AMBIENT_OUT_OF_RANGE: Final[int]
RISE_OUT_OF_SPAN: Final[int]
PAST_LAST_REFERENCE: Final[int]
TEMPERATURE_OUT_OF_RANGE: Final[int]
TEMPERATURE_INVALID: Final[int]
TEMPERATURE_STUCK: Final[int]
RATE_INVALID: Final[int]
NOT_POWERED_ON: Final[int]
MODEL_INVALID: Final[int]
EXTENSION_INPUT_INVALID: Final[int]
HISTORY_UNKNOWN: Final[int]
HISTORY_OUT_OF_SPAN: Final[int]
FAULTS: Final[int]
FLAGS: Final[tuple[tuple[str, int], ...]]
"""Every flag drift-core defines, `(name, value)` in bit order (drift_core::Flags::ALL)."""

AUX_INPUTS: Final[int]
"""Auxiliary inputs the extended model's terms can read per sample (drift_core::AUX_INPUTS, 4)."""
MAX_EXTRA_TERMS: Final[int]
"""Most extra terms a model carries (drift_core::MAX_TERMS, 4)."""

class GyrodriftError(Exception):
    """Base class of every error gyrodrift raises."""

class InputError(GyrodriftError, ValueError):
    """A bad argument: wrong type, dtype, shape or length, or a value the corrector rejects.

    The message names the argument, what was expected and what arrived, e.g. "`rate_dps` must be a
    float32 or float64 array of shape (n, 3), got int64 array of shape (5, 2)".
    """

class TableError(GyrodriftError):
    """Table JSON or settings that do not form a valid model.

    The message names the field and where it sits, e.g. "axes[2].reference_ms[3]: not strictly
    greater than the previous value", or gives serde_json's line and column.
    """

class ImageError(GyrodriftError):
    """A firmware table image that cannot be decoded: truncated, bad magic, unsupported version,
    wrong model kind, trailing bytes, CRC mismatch, malformed payload or invalid contents."""

class FileError(GyrodriftError, OSError):
    """A file that cannot be read or written (`errno`, `strerror` and `filename` are set)."""

class RecordingError(GyrodriftError):
    """A recording that cannot be read, fails validation or cannot be written.

    The message is drift-recording's, naming the file and, where it applies, the topic and the
    message's index within it, e.g. "run.mcap: topic /gyro/rate, message #12: gap: first_sample
    1300, expected 1200".
    """

class CampaignError(GyrodriftError, ValueError):
    """A simulation campaign that is not valid: unknown field, value out of range, text that does
    not parse. The message names the field, e.g. "invalid campaign: units: must be ≥ 1"."""

class FitError(GyrodriftError):
    """Recordings the tables cannot be fitted or evaluated from (too-short activation, no
    calibration activations, an axis that never warms up, a setting out of range). The message
    names the unit and activation, or the setting."""

@final
class Settings:
    """Sensor conversion and envelope settings stored with every model (drift_core::Settings).

    Arguments left out take drift-core's defaults. Validated on construction (`TableError`).
    """

    def __new__(
        cls,
        *,
        raw_per_celsius: float | None = None,
        raw_at_zero_celsius: float | None = None,
        ambient_margin_celsius: float | None = None,
        rise_margin_celsius: float | None = None,
        stuck_after_samples: int | None = None,
        sample_rate_hz: float | None = None,
    ) -> Settings: ...
    @property
    def raw_per_celsius(self) -> float:
        """Temperature-sensor scale, raw units per °C (default 200)."""
    @property
    def raw_at_zero_celsius(self) -> float:
        """Temperature-sensor reading at 0 °C, raw units (default 0)."""
    @property
    def ambient_margin_celsius(self) -> float:
        """Distance outside the calibrated ambients (or fitted range) before flagging, °C (default 0.5)."""
    @property
    def rise_margin_celsius(self) -> float:
        """Distance outside the stored curves' rises before flagging, °C (default 0.05)."""
    @property
    def stuck_after_samples(self) -> int:
        """Identical raw readings in a row that mean a stuck sensor; 0 disables (default 2000)."""
    @property
    def sample_rate_hz(self) -> float:
        """The sample rate the tables were fitted at, Hz: `fit` states the recordings' rate, so
        firmware can check its own against the image's; 0: not stated (default 0)."""
    def celsius(self, raw: float) -> float:
        """A raw temperature reading in °C, computed in f32 as the corrector does."""
    @overload
    def raw(self, celsius: float) -> float: ...
    @overload
    def raw(self, celsius: Any) -> NDArray[np.float32]:
        """Raw temperature readings from °C (f32): a float for a float, a float32 array for an
        array-like (list, numpy array, pandas Series), to feed `power_on`/`correct_batch` a log in
        °C."""

@final
class ModifiedTables:
    """The paper's correlation tables (drift_core::ModifiedTables; host capacities: 16 reference
    times, 12 ambients, 32 curves per ambient). Immutable; validated whenever it is built."""

    @staticmethod
    def from_json(text: str) -> ModifiedTables:
        """Parses drift-core's JSON form. Raises `TableError` (bad JSON or invalid tables)."""
    @staticmethod
    def from_image(data: bytes | bytearray) -> ModifiedTables:
        """Decodes a firmware table image. Raises `ImageError`."""
    @staticmethod
    def load_json(path: _Path) -> ModifiedTables:
        """Reads a JSON file. Raises `FileError` or `TableError`."""
    @staticmethod
    def load_image(path: _Path) -> ModifiedTables:
        """Reads a firmware table image file. Raises `FileError` or `ImageError`."""
    def to_json(self) -> str:
        """drift-core's JSON form, pretty-printed; `from_json` gives back an equal model."""
    def to_image(self) -> bytes:
        """The firmware table image (magic, version, kind, length, postcard payload, CRC-32)."""
    def save_json(self, path: _Path) -> None:
        """Writes the JSON form (temporary file, then rename). Raises `FileError`."""
    def save_image(self, path: _Path) -> None:
        """Writes the firmware table image (temporary file, then rename). Raises `FileError`."""
    @property
    def settings(self) -> Settings:
        """The settings stored with the tables."""
    def with_settings(self, settings: Settings) -> ModifiedTables:
        """The same tables with other settings (validated; `self` is unchanged)."""
    def check(
        self,
        source: _Source,
        *,
        max_drift: float = 0.005,
        max_rms: float = 0.02,
        min_removed: float = 0.5,
        settings: FitSettings | None = None,
    ) -> list[_Record]:
        """Is this stored calibration still valid? (`gyrodrift check` on the command line.)

        Corrects every activation of `source` (one unit's recordings or segments, the unit held
        static) as the firmware would, and returns one record per axis: `unit_id`, `axis`,
        `passed`, `activations`, `uncorrected_drift_dps`, `corrected_drift_dps` (mean drift left),
        `worst_drift_dps`, `removed` (share of the uncorrected drift), `residual_rms_dps`,
        `ambient_out_of_range`, `rise_out_of_span`, `past_last_reference`,
        `history_unknown_or_out_of_span`, `outside_envelope`, `faulty` (activation counts),
        `samples`, `outside_envelope_samples` (samples flagged outside the calibrated envelope)
        and `failures` (why the axis misses a limit). Limits: mean drift left ≤ `max_drift` °/s,
        residual RMS ≤ `max_rms` °/s, share removed ≥ `min_removed`.
        Raises `InputError` (several units in `source`, none at all, a negative limit, an extended
        model that reads an auxiliary input), `FileError` or `RecordingError`."""
    @property
    def extension(self) -> tuple[ExtraTerm, ...]:
        """The extended model's extra terms, in model order; empty for the paper's model."""
    @property
    def switch_on_rate(self) -> NDArray[np.float32]:
        """Per axis X, Y, Z (rows), the rate at switch-on the temperature-rate term's filter starts
        from: `[heating °C/s, cooling_per_second, cooling_per_second_per_remaining]`, float32
        `(3, 3)`. The rate is `heating − residual_heat · (cooling_per_second +
        cooling_per_second_per_remaining · remaining)` for the history `Corrector.power_on_after`
        was given (`power_on`: a cold start, the heating alone). Zeros: the filter starts at rest."""
    def with_extension(
        self, terms: Sequence[ExtraTerm], switch_on_rate: _FloatRows | None = None
    ) -> ModifiedTables:
        """The same tables with `terms` as the extra terms (replacing any; `[]` removes them) and,
        if given, `switch_on_rate` (`(3, 3)`, as the property; `None` keeps the current one).

        At most `MAX_EXTRA_TERMS` terms (`InputError` otherwise, for anything not an `ExtraTerm`,
        or a `switch_on_rate` not of shape (3, 3)). drift-core validates the whole model: an
        unknown input or axis index, a time constant of 0, rate terms with different time
        constants, a NaN/inf centre or coefficient, or a switch-on rate that is not finite or
        whose cooling would warm the unit raise `TableError` naming the term's index or the
        axis. `self` is unchanged.
        """
    def __eq__(self, other: object, /) -> bool: ...

@final
class ExtraTerm:
    """One extra linear term of the extended model (drift_core::ExtraTerm): the axis's bias gains
    `coefficient · (value − centre)`, per axis, where `value` is what `kind` measures.

    Kinds and their `parameter`:

    - `'temperature_rate'`: the axis's temperature rate, °C/s, from a first-order low-pass of time
      constant `parameter` ms (every rate term of a model must use the same one);
    - `'aux'`: auxiliary input `parameter` (0 .. AUX_INPUTS), as passed in `aux=` to
      `Corrector.correct`/`correct_batch`, in its own unit, shared by the axes, through a
      first-order low-pass of time constant `time_constant_ms` (default 0: unfiltered; the
      closed loop fits 1000 ms, so a recorded channel's sample noise stays out of the correction);
    - `'axis_rise'`: the rise since switch-on of axis `parameter` (0 = X, 1 = Y, 2 = Z), °C;
    - `'rise_squared'`: the axis's own rise squared, °C²; `parameter` is None;
    - `'aux_times_rise'`: auxiliary input `parameter`, low-passed as an `'aux'` term is, times the
      axis's own rise since switch-on (input unit × °C).

    Only converted on construction (`InputError` for a wrong type or a missing parameter); the
    values are validated when the term becomes part of a model (`ModifiedTables.with_extension`).
    """

    def __new__(
        cls,
        kind: _TermKind,
        parameter: int | None = None,
        *,
        centre: _Floats3,
        coefficient: _Floats3,
        time_constant_ms: int | None = None,
    ) -> ExtraTerm: ...
    @property
    def kind(self) -> _TermKind:
        """What the term measures: 'temperature_rate', 'aux', 'axis_rise', 'rise_squared' or
        'aux_times_rise'."""
    @property
    def parameter(self) -> int | None:
        """The time constant (ms), auxiliary input index or axis index; None for 'rise_squared'."""
    @property
    def time_constant_ms(self) -> int | None:
        """The low-pass time constant, ms: an 'aux' or 'aux_times_rise' term's (0: unfiltered)
        or a 'temperature_rate' term's (its `parameter`); None for the other kinds."""
    @property
    def centre(self) -> tuple[float, float, float]:
        """Per axis, the value the term is measured from (its calibration mean), in its unit."""
    @property
    def coefficient(self) -> tuple[float, float, float]:
        """Per axis, °/s per unit of the term (0 leaves that axis untouched)."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class PolynomialTables:
    """A polynomial baseline, the paper's standard calibration or a 3rd-order fit
    (drift_core::PolynomialTables). Immutable; validated whenever it is built."""

    @staticmethod
    def from_json(text: str) -> PolynomialTables:
        """Parses drift-core's JSON form. Raises `TableError` (bad JSON or invalid tables)."""
    @staticmethod
    def from_image(data: bytes | bytearray) -> PolynomialTables:
        """Decodes a firmware table image. Raises `ImageError`."""
    @staticmethod
    def load_json(path: _Path) -> PolynomialTables:
        """Reads a JSON file. Raises `FileError` or `TableError`."""
    @staticmethod
    def load_image(path: _Path) -> PolynomialTables:
        """Reads a firmware table image file. Raises `FileError` or `ImageError`."""
    def to_json(self) -> str:
        """drift-core's JSON form, pretty-printed; `from_json` gives back an equal model."""
    def to_image(self) -> bytes:
        """The firmware table image (magic, version, kind, length, postcard payload, CRC-32)."""
    def save_json(self, path: _Path) -> None:
        """Writes the JSON form (temporary file, then rename). Raises `FileError`."""
    def save_image(self, path: _Path) -> None:
        """Writes the firmware table image (temporary file, then rename). Raises `FileError`."""
    @property
    def settings(self) -> Settings:
        """The settings stored with the tables."""
    def with_settings(self, settings: Settings) -> PolynomialTables:
        """The same tables with other settings (validated; `self` is unchanged)."""
    def check(
        self,
        source: _Source,
        *,
        max_drift: float = 0.005,
        max_rms: float = 0.02,
        min_removed: float = 0.5,
        settings: FitSettings | None = None,
    ) -> list[_Record]:
        """Is this stored calibration still valid? (`gyrodrift check` on the command line.)

        Corrects every activation of `source` (one unit's recordings or segments, the unit held
        static) as the firmware would, and returns one record per axis: `unit_id`, `axis`,
        `passed`, `activations`, `uncorrected_drift_dps`, `corrected_drift_dps` (mean drift left),
        `worst_drift_dps`, `removed` (share of the uncorrected drift), `residual_rms_dps`,
        `ambient_out_of_range`, `rise_out_of_span`, `past_last_reference`,
        `history_unknown_or_out_of_span`, `outside_envelope`, `faulty` (activation counts),
        `samples`, `outside_envelope_samples` (samples flagged outside the calibrated envelope)
        and `failures` (why the axis misses a limit). Limits: mean drift left ≤ `max_drift` °/s,
        residual RMS ≤ `max_rms` °/s, share removed ≥ `min_removed`.
        Raises `InputError` (several units in `source`, none at all, a negative limit, an extended
        model that reads an auxiliary input), `FileError` or `RecordingError`."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class RelativePolynomialTables:
    """The least-squares baseline relative to the switch-on: bias = q(T_on) + p(T) − p(T_on), the
    turn-on bias registered at switch-on and the drift after it
    (drift_core::RelativePolynomialTables; firmware image kind 3). Immutable; validated whenever it
    is built."""

    @staticmethod
    def from_json(text: str) -> RelativePolynomialTables:
        """Parses drift-core's JSON form. Raises `TableError` (bad JSON or invalid tables)."""
    @staticmethod
    def from_image(data: bytes | bytearray) -> RelativePolynomialTables:
        """Decodes a firmware table image. Raises `ImageError`."""
    @staticmethod
    def load_json(path: _Path) -> RelativePolynomialTables:
        """Reads a JSON file. Raises `FileError` or `TableError`."""
    @staticmethod
    def load_image(path: _Path) -> RelativePolynomialTables:
        """Reads a firmware table image file. Raises `FileError` or `ImageError`."""
    def to_json(self) -> str:
        """drift-core's JSON form, pretty-printed; `from_json` gives back an equal model."""
    def to_image(self) -> bytes:
        """The firmware table image (magic, version, kind, length, postcard payload, CRC-32)."""
    def save_json(self, path: _Path) -> None:
        """Writes the JSON form (temporary file, then rename). Raises `FileError`."""
    def save_image(self, path: _Path) -> None:
        """Writes the firmware table image (temporary file, then rename). Raises `FileError`."""
    @property
    def settings(self) -> Settings:
        """The settings stored with the tables."""
    def with_settings(self, settings: Settings) -> RelativePolynomialTables:
        """The same tables with other settings (validated; `self` is unchanged)."""
    def check(
        self,
        source: _Source,
        *,
        max_drift: float = 0.005,
        max_rms: float = 0.02,
        min_removed: float = 0.5,
        settings: FitSettings | None = None,
    ) -> list[_Record]:
        """Is this stored calibration still valid? (`gyrodrift check` on the command line.)

        Corrects every activation of `source` (one unit's recordings or segments, the unit held
        static) as the firmware would, and returns one record per axis: `unit_id`, `axis`,
        `passed`, `activations`, `uncorrected_drift_dps`, `corrected_drift_dps` (mean drift left),
        `worst_drift_dps`, `removed` (share of the uncorrected drift), `residual_rms_dps`,
        `ambient_out_of_range`, `rise_out_of_span`, `past_last_reference`,
        `history_unknown_or_out_of_span`, `outside_envelope`, `faulty` (activation counts),
        `samples`, `outside_envelope_samples` (samples flagged outside the calibrated envelope)
        and `failures` (why the axis misses a limit). Limits: mean drift left ≤ `max_drift` °/s,
        residual RMS ≤ `max_rms` °/s, share removed ≥ `min_removed`.
        Raises `InputError` (several units in `source`, none at all, a negative limit, an extended
        model that reads an auxiliary input), `FileError` or `RecordingError`."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class RecommendedTables:
    """The recommended model: the paper's drift correction after switch-on with the turn-on bias
    q(T_on) + h · residual heat fitted across every calibration activation
    (drift_core::RecommendedTables; firmware image kind 4). Start it with
    `Corrector.power_on_after` to use the residual heat. Immutable; validated whenever it is
    built."""

    @staticmethod
    def from_json(text: str) -> RecommendedTables:
        """Parses drift-core's JSON form. Raises `TableError` (bad JSON or invalid tables)."""
    @staticmethod
    def from_image(data: bytes | bytearray) -> RecommendedTables:
        """Decodes a firmware table image. Raises `ImageError`."""
    @staticmethod
    def load_json(path: _Path) -> RecommendedTables:
        """Reads a JSON file. Raises `FileError` or `TableError`."""
    @staticmethod
    def load_image(path: _Path) -> RecommendedTables:
        """Reads a firmware table image file. Raises `FileError` or `ImageError`."""
    def to_json(self) -> str:
        """drift-core's JSON form, pretty-printed; `from_json` gives back an equal model."""
    def to_image(self) -> bytes:
        """The firmware table image (magic, version, kind, length, postcard payload, CRC-32)."""
    def save_json(self, path: _Path) -> None:
        """Writes the JSON form (temporary file, then rename). Raises `FileError`."""
    def save_image(self, path: _Path) -> None:
        """Writes the firmware table image (temporary file, then rename). Raises `FileError`."""
    @property
    def settings(self) -> Settings:
        """The settings stored with the tables."""
    def with_settings(self, settings: Settings) -> RecommendedTables:
        """The same tables with other settings (validated; `self` is unchanged)."""
    def check(
        self,
        source: _Source,
        *,
        max_drift: float = 0.005,
        max_rms: float = 0.02,
        min_removed: float = 0.5,
        settings: FitSettings | None = None,
    ) -> list[_Record]:
        """Is this stored calibration still valid? (`gyrodrift check` on the command line.)

        Corrects every activation of `source` (one unit's recordings or segments, the unit held
        static) as the firmware would, and returns one record per axis: `unit_id`, `axis`,
        `passed`, `activations`, `uncorrected_drift_dps`, `corrected_drift_dps` (mean drift left),
        `worst_drift_dps`, `removed` (share of the uncorrected drift), `residual_rms_dps`,
        `ambient_out_of_range`, `rise_out_of_span`, `past_last_reference`,
        `history_unknown_or_out_of_span`, `outside_envelope`, `faulty` (activation counts),
        `samples`, `outside_envelope_samples` (samples flagged outside the calibrated envelope)
        and `failures` (why the axis misses a limit). Limits: mean drift left ≤ `max_drift` °/s,
        residual RMS ≤ `max_rms` °/s, share removed ≥ `min_removed`.
        Raises `InputError` (several units in `source`, none at all, a negative limit, an extended
        model that reads an auxiliary input), `FileError` or `RecordingError`."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class Output:
    """One corrected sample, per axis (X, Y, Z)."""

    @property
    def corrected_dps(self) -> tuple[float, float, float]:
        """Rate with the estimated drift removed, °/s (f32 values)."""
    @property
    def bias_dps(self) -> tuple[float, float, float]:
        """Estimated bias that was removed (initial bias + drift since switch-on), °/s."""
    @property
    def flags(self) -> tuple[int, int, int]:
        """Status flags per axis (bits of `gyrodrift.Flags`)."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class StillnessLearner:
    """Learns the rate's offset while the instrument stands still: drift-core's learner (x-io
    Fusion's gyroscope offset correction with rate and acceleration variance tests).

    Feed it the tables' corrected rate (`Corrector`) to learn the slow offset the tables cannot
    know, or the raw rate for the learner alone. Results are bit for bit those of the Rust learner.
    """

    def __new__(
        cls,
        *,
        sample_rate_hz: float = 1000.0,
        accel_rate_hz: float = 100.0,
        rate_threshold_dps: float = 3.0,
        rate_sd_threshold_dps: float = 0.1,
        accel_sd_threshold_g: float = 0.01,
        variance_time_constant_s: float = 0.5,
        still_for_s: float = 5.0,
        time_constant_s: float | None = None,
    ) -> StillnessLearner:
        """A learner with no offset learned. `time_constant_s` defaults to Fusion's 0.02 Hz
        cut-off (about 8 s). A non-finite or non-positive setting raises `InputError` naming it."""
    @property
    def offset_dps(self) -> tuple[float, float, float]:
        """The offset learned so far, °/s, X, Y, Z."""
    @property
    def time_constant_s(self) -> float:
        """The time constant of the offset's low-pass, s."""
    def set_offset(self, offset_dps: _Floats3) -> None:
        """Starts from a kept offset, °/s, with the detector cleared."""
    def reset_detector(self) -> None:
        """Clears the still detector and keeps the offset (call it at switch-on)."""
    def accelerometer(self, accel_g: _Floats3) -> None:
        """One accelerometer reading, g, at `accel_rate_hz`; a non-finite reading is skipped."""
    def update(self, rate_dps: _Floats3) -> tuple[tuple[float, float, float], bool, bool]:
        """One rate sample, °/s: `(rate less the offset learned before it, still, learning)`."""
    def update_batch(
        self,
        rate_dps: NDArray[np.float32] | NDArray[np.float64],
        accel_g: NDArray[np.float32] | NDArray[np.float64] | None = None,
        *,
        accel_every: int = 10,
    ) -> tuple[NDArray[np.float32], NDArray[np.bool_], NDArray[np.bool_]]:
        """n rate samples `(n, 3)` in order; accelerometer row k `(m, 3)` is read before rate
        sample `k · accel_every`. Returns the rates less the offset `(n, 3)`, and per sample
        whether it was still and whether it moved the offset."""

@final
class Uncertainty:
    """σ(t) of one unit: the residual bias's standard deviation after switch-on, per activation
    class (cold start, warm restart), growing with the switch-on ambient's distance outside the
    calibrated envelope. A navigation filter takes it as the gyro bias's uncertainty.

    Fitted by `gyrodrift report` / `demo` (tables folder `<unit>/uncertainty.{json,bin}`); values
    are bit for bit those drift-core returns in firmware.
    """

    @staticmethod
    def load(path: _Path) -> Uncertainty:
        """Reads `uncertainty.json` or the firmware section `uncertainty.bin`; the error names the
        file and what is wrong."""
    @property
    def knots_ms(self) -> list[int]:
        """Knot times since switch-on, ms."""
    @property
    def sigma_dps(self) -> NDArray[np.float32]:
        """σ at the knots, °/s, `(2, knots)`: cold start, then warm restart."""
    @property
    def warm_above_celsius(self) -> float:
        """Residual heat at switch-on above which a start is a warm restart, °C."""
    @property
    def envelope_celsius(self) -> tuple[float, float]:
        """The calibrated envelope's lowest and highest ambient, °C."""
    @property
    def per_celsius_outside_dps(self) -> float:
        """Growth of σ per °C of switch-on ambient outside the envelope, °/s."""
    @property
    def most_residual_heat_celsius(self) -> list[float]:
        """The most residual heat a calibration activation switched on with, per axis, °C."""
    @property
    def per_residual_celsius_beyond_dps(self) -> float:
        """Growth of σ per °C of residual heat beyond the most, °/s."""
    def sigma(
        self,
        since_power_on_ms: NDArray[np.uint32],
        switch_on_celsius: _Floats3,
        previous: _Previous | None = None,
    ) -> NDArray[np.float32]:
        """σ per sample and axis, °/s `(n, 3)`, for an activation switched on at
        `switch_on_celsius` after `previous` (`(3, 2)` as `Corrector.power_on_after` takes it;
        None: nothing kept)."""
    def to_json(self) -> str:
        """drift-core's JSON of this σ(t)."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class Corrector:
    """A model and one unit's run-time state: drift-core's corrector, as the firmware runs it.

    Call `power_on` at switch-on, then `correct` per sample or `correct_batch` per block of samples
    (blocks continue the same activation). Results are bit for bit those of the Rust corrector.
    """

    def __new__(cls, model: _Model) -> Corrector:
        """A corrector for `model`, not yet powered on. Raises `InputError` for any other object."""
    @property
    def model(self) -> _Model:
        """The model in use."""
    @property
    def is_powered_on(self) -> bool:
        """Whether `power_on` has succeeded since the last `power_off`."""
    @property
    def switch_on_raw(self) -> tuple[float, float, float]:
        """Raw temperature readings at the last switch-on, per axis."""
    @property
    def initial_bias_dps(self) -> tuple[float, float, float]:
        """Initial (switch-on) bias located at the last switch-on, per axis, °/s."""
    def power_on(
        self, switch_on_raw: _Floats3, *, ambient_celsius: float | None = None
    ) -> tuple[int, int, int]:
        """Starts an activation from the raw temperatures at switch-on (X, Y, Z).

        Returns the flags that hold for the whole activation, per axis. A NaN or infinite reading
        raises `InputError` naming the axis, and the state is unchanged. `ambient_celsius`: the
        ambient the instrument measured at switch-on (an air or board thermistor), °C; the paper's
        stage 2 and initial bias are then read there rather than at the switch-on temperature
        (time since switch-on and the rise as always; AMBIENT_OUT_OF_RANGE outside the tables).
        With it equal to the switch-on temperature the outputs are `power_on`'s. NaN or infinite
        raises `InputError` naming `ambient_celsius`, and the state is unchanged.
        """
    def power_on_after(
        self, switch_on_raw: _Floats3, previous: _Previous, *, ambient_celsius: float | None = None
    ) -> tuple[tuple[int, int, int], NDArray[np.float32]]:
        """`power_on` with what was kept of the previous activation across power-off.

        `previous`: float32 or float64 array (or nested sequence) of shape (3, 2), per axis X, Y, Z
        `[ambient °C, switch-off °C]` (all NaN when nothing was kept: the first activation). A
        table keyed by heating history reads the activation's ambient and residual heat from it
        (HISTORY_UNKNOWN where nothing finite was kept); other models ignore it. Returns
        `(flags, kept)`: the activation's flags per axis, as `power_on`, and what to keep now, a
        new float32 (3, 2) array (this activation's ambient, switch-off NaN until `keep`).
        `previous` itself is not modified. A NaN or infinite `switch_on_raw` raises `InputError`
        and the state is unchanged; a wrong shape or dtype raises `InputError` (a `ValueError`)
        naming `previous` and the shape expected. `ambient_celsius` as for `power_on`: the
        measured ambient replaces the estimate (the residual heat is the switch-on temperature's
        height above it) and is what is kept.
        """
    def keep(self, previous: _Previous) -> NDArray[np.float32]:
        """`previous` (as `power_on_after` returned it) with this activation's last good
        temperature per axis recorded as its switch-off temperature, as a new float32 (3, 2)
        array; unchanged while not powered on. Call it before power-off (or periodically).
        `previous` itself is not modified.
        """
    def power_off(self) -> None:
        """Ends the activation: samples pass through, flagged NOT_POWERED_ON, until `power_on`."""
    def correct(
        self,
        since_power_on_ms: int,
        rate_dps: _Floats3,
        temperature_raw: _Floats3,
        *,
        aux: _Floats4 | None = None,
    ) -> Output:
        """Corrects one sample. NaN/inf inputs are flagged, not raised.

        `aux`: the sample's `AUX_INPUTS` auxiliary inputs (4 floats or a (4,) array, by input
        index), read by an extended model's 'aux' terms (drift-core's `correct_with_aux`); other
        models ignore them. Without `aux` (drift-core's `correct`), or with a NaN/inf input an
        'aux' term reads, that term holds its last filtered value (0 before any), flagged
        EXTENSION_INPUT_INVALID.
        """
    def correct_batch(
        self,
        since_power_on_ms: NDArray[np.uint32],
        rate_dps: NDArray[np.float32] | NDArray[np.float64],
        temperature_raw: NDArray[np.float32] | NDArray[np.float64] | NDArray[np.int16],
        *,
        aux: NDArray[np.float32] | NDArray[np.float64] | None = None,
        out: tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.uint16]] | None = None,
    ) -> tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.uint16]]:
        """Corrects n samples in order, continuing the current activation.

        Arguments: `since_power_on_ms` uint32 (n,); `rate_dps` and `temperature_raw` float32 or
        float64 (n, 3), `temperature_raw` also int16 as `Segment.temperature_raw` returns it;
        `aux` None or float32 or float64 (n, AUX_INPUTS), each sample's auxiliary inputs as in
        `correct`. Any strides (read in place, not copied; float64 is rounded to f32
        per value). Returns `(corrected_dps, bias_dps, flags)`: float32, float32 and uint16
        arrays of shape (n, 3) — new arrays, or the arrays given as `out` (C-contiguous,
        writeable, none of them an input), filled in place, which saves allocating for every
        block. The GIL is released while correcting. Raises `InputError` for a wrong dtype or
        shape, an empty array, or lengths that differ.
        """

# --- recordings -------------------------------------------------------------------------------

@final
class Labels:
    """The labels of one activation (drift_recording::SegmentLabels). Validated: counts from 1,
    finite set point, durations ≥ 0; raises `InputError`."""

    def __new__(
        cls,
        *,
        unit_id: str,
        set_point_celsius: float,
        series_kind: str | None = None,
        series: int | None = None,
        repeat: int | None = None,
        activation: int | None = None,
        interval_min: float | None = None,
        off_before_s: float | None = None,
    ) -> Labels:
        """`series_kind` is "protocol" (default) or "field"; `series`, `repeat`, `activation`
        default to 1; `interval_min` is the protocol off-time (None for field sessions)."""
    @property
    def unit_id(self) -> str:
        """Unit id."""
    @property
    def set_point_celsius(self) -> float:
        """Chamber set point at switch-on, °C."""
    @property
    def nominal_set_point_celsius(self) -> float:
        """The recording's nominal set point, °C (not the ambient at switch-on); read-only."""
    @property
    def series_kind(self) -> str:
        """ "protocol" or "field"."""
    @property
    def series(self) -> int:
        """Series number within the recording, from 1."""
    @property
    def repeat(self) -> int:
        """Repeat of the interval, from 1."""
    @property
    def activation(self) -> int:
        """Activation number within the series, from 1."""
    @property
    def interval_min(self) -> float | None:
        """Protocol off-time between activations, min (None for field sessions)."""
    @property
    def off_before_s(self) -> float | None:
        """Off-time before this switch-on, s (None if unknown)."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class AuxChannel:
    """An auxiliary channel of one activation (accelerometer, supply voltage, ...) at its own rate."""

    def __new__(cls, values: _Floats, unit: str, sample_rate_hz: int) -> AuxChannel:
        """Finite float32/float64 values of shape (n,), a unit ("g", "V", "degC") and a rate in Hz."""
    @property
    def values(self) -> NDArray[np.float32]:
        """Samples (read-only); sample k is at k / sample_rate_hz s after switch-on."""
    @property
    def unit(self) -> str:
        """Physical unit."""
    @property
    def sample_rate_hz(self) -> int:
        """Sample rate, Hz."""
    def __len__(self) -> int: ...

@final
class Segment:
    """One activation (switch-on to switch-off) of one unit: what the fitter consumes.

    Read from a recording, or built from arrays. Its arrays are made on first access and kept;
    they are read-only (copy them to modify).
    """

    def __new__(
        cls,
        labels: Labels,
        rate_dps: _Floats,
        temperature_raw: NDArray[np.int16],
        *,
        sample_rate_hz: int | None = None,
        power_on_ns: int | None = None,
        aux: Mapping[str, AuxChannel | tuple[_Floats, str, int]] | None = None,
        temperature_raw_per_celsius: float | None = None,
        temperature_raw_at_zero_celsius: float | None = None,
    ) -> Segment:
        """An activation from arrays: `rate_dps` float32/float64 (n, 3) in °/s (finite; float64 is
        rounded to f32), `temperature_raw` int16 (n, 3), consecutive samples from switch-on at
        `sample_rate_hz` (default 1000; a multiple of 100 dividing 10**9); `power_on_ns` the
        switch-on time on the recording clock (default 0); `aux` auxiliary channels by name, any
        names (`Recording.save` says which a recording stores); `temperature_raw` is at
        `temperature_raw_per_celsius` raw units per °C (default 200) with
        `temperature_raw_at_zero_celsius` (default 0) read at 0 °C. Raises `InputError` for a wrong
        dtype or shape, an empty or non-finite array, lengths that differ, or a scale that is not
        a finite number (> 0)."""
    @property
    def temperature_raw_per_celsius(self) -> float:
        """Raw temperature units per °C of `temperature_raw` (the recording's sensor scale)."""
    @property
    def temperature_raw_at_zero_celsius(self) -> float:
        """The raw temperature reading at 0 °C."""
    @property
    def labels(self) -> Labels:
        """The activation's labels."""
    @property
    def sample_rate_hz(self) -> int:
        """Gyro and temperature sample rate, Hz."""
    @property
    def power_on_ns(self) -> int:
        """Switch-on time on the recording clock, ns."""
    def __len__(self) -> int: ...
    @property
    def since_power_on(self) -> NDArray[np.uint32]:
        """Sample index since switch-on, (n,) (0 = switch-on)."""
    @property
    def since_power_on_ms(self) -> NDArray[np.uint32]:
        """Milliseconds since switch-on, (n,): what `Corrector.correct_batch` takes (index × 1000 /
        rate, rounded down, as the evaluation computes it)."""
    @property
    def rate_dps(self) -> NDArray[np.float32]:
        """Angular rate X, Y, Z, °/s, (n, 3)."""
    @property
    def temperature_raw(self) -> NDArray[np.int16]:
        """Raw temperature X, Y, Z, (n, 3) (200 raw units per °C)."""
    @property
    def aux(self) -> dict[str, AuxChannel]:
        """Auxiliary channels by name (a new dict on each access)."""
    def aux_channel(self, name: str) -> AuxChannel:
        """One auxiliary channel. Raises `InputError` naming the channels there are if `name` is
        not one of them."""

@final
class Recording:
    """One unit's recording (the MCAP format of docs/recording-format.md): metadata and its
    activations in recording order."""

    def __new__(
        cls,
        segments: Sequence[Segment],
        *,
        unit_id: str | None = None,
        metadata: Mapping[str, str] | None = None,
    ) -> Recording:
        """A recording from segments of one unit at one sample rate, each switching on after the
        previous one switched off (`Segment(power_on_ns=...)`). `unit_id` defaults to the
        segments'; `metadata` adds to (and overrides) the default metadata record, except
        `unit_id` and `sample_rate_hz`. Raises `InputError`."""
    @staticmethod
    def from_dataframe(
        frame: Any,
        *,
        rate_unit: Literal["deg/s", "rad/s"],
        time: str = "time",
        time_unit: Literal["s", "ms"] | None = None,
        rate: Sequence[str] = ("rate_x", "rate_y", "rate_z"),
        temperature: str | Sequence[str] = "temperature",
        activation: str | None = None,
        gap_s: float | None = None,
        sample_rate_hz: int | None = None,
        max_gap_s: float | None = None,
        unit_id: str = "dataframe",
        set_point_celsius: float | None = None,
        series_kind: Literal["protocol", "field"] = "protocol",
        interval_min: float | None = None,
        temperature_dropouts: bool = False,
        name: str = "DataFrame",
    ) -> Recording:
        """A recording from a pandas DataFrame of a continuous log with one or several power-ons.

        `time`: float s or ms (`time_unit` required), timedelta64 or datetime64; `rate`: three
        columns in `rate_unit` (required: no default, so rad/s is never read as °/s);
        `temperature`: one °C column (a single die sensor) or three. Activations: consecutive rows
        with the same `activation` value, or split where the time steps by more than `gap_s`, or
        the whole frame. `sample_rate_hz`: inferred from the median step when None; every row is
        then one sample on the grid (`max_gap_s` None) or rows are interpolated onto it with steps
        up to `max_gap_s`. Checked by `gyrodrift import`'s CSV reader: times that go back or
        repeat, gaps, rates beyond 10,000 °/s and temperatures beyond ±163.8 °C (raw counts given
        as °C) are refused with an `InputError` naming the row (the frame's n-th, from 1) and the
        column. Split on `gap_s`, the activations are numbered 1, 2, … with the off-time before
        each (`off_before_s`) measured from the log; `interval_min` labels them as a protocol
        series at that off-time, which the fit needs to key its curves. Needs pandas."""
    @staticmethod
    def read_csv(path: _Path, *, rate_unit: Literal["deg/s", "rad/s"], **options: Any) -> Recording:
        """`from_dataframe(pandas.read_csv(path), ...)`: the same options; errors name the file."""
    @staticmethod
    def load(path: _Path) -> Recording:
        """Reads and validates an MCAP recording (the GIL is released; Ctrl-C stops it between
        activations). Raises `FileError`
        (missing or unreadable file) or `RecordingError` (naming file, topic and message index)."""
    @staticmethod
    def read_metadata(path: _Path) -> dict[str, str]:
        """A recording's metadata record without decoding its messages."""
    def save(self, path: _Path) -> int:
        """Writes the recording as MCAP (temporary file, fsync, rename) and returns the bytes
        written. Every segment needs the format's auxiliary channels — accel_x, accel_y, accel_z
        in "g", supply_voltage in "V", chamber_set_point in "degC" — and may have any other named
        channels, each written to its own topic `/aux/<name>` and read back by `load`: names of
        ASCII letters, digits, "_", "." and "-", starting with a letter or digit, one unit per
        name across the recording. Every channel is at 100 Hz, one value per 10 ms, or empty (not
        recorded: what `load` gives for a file without it, so a loaded recording saves again). A channel
        that breaks these raises `InputError` naming segment and channel; otherwise `FileError`
        or `RecordingError`."""
    @property
    def path(self) -> Path | None:
        """The file it was read from (None if built in Python)."""
    @property
    def unit_id(self) -> str:
        """Unit id."""
    @property
    def sample_rate_hz(self) -> int:
        """Gyro and temperature sample rate, Hz."""
    @property
    def metadata(self) -> dict[str, str]:
        """The `gyrodrift.recording` metadata record (a new dict on each access)."""
    @property
    def segments(self) -> list[Segment]:
        """The activations, in recording order."""
    def __len__(self) -> int: ...

def load_campaign(folder: _Path) -> list[Recording]:
    """Every recording of a campaign folder (its `recordings/`) or of a folder of .mcap files,
    sorted by name. Ground truth is never opened. Raises `FileError` or `RecordingError`."""

# --- simulation -------------------------------------------------------------------------------

def simulate(
    out: _Path,
    campaign: Mapping[str, Any] | str | os.PathLike[str] | None = None,
    *,
    seed: int | None = None,
    units: int | None = None,
    set_points: Sequence[float] | str | None = None,
    intervals: Sequence[float] | None = None,
    repeats: int | None = None,
    field: bool = False,
    field_only: bool = False,
    zero_drift: bool = False,
    paper_exact: bool = False,
    effects: Sequence[str] | None = None,
    noise_scale: float | None = None,
    truth_at_aux_rate: bool = False,
    force: bool = False,
    max_gb: float = 20.0,
    progress: _Progress | None = None,
) -> dict[str, Any]:
    """Simulates a campaign into `out` (recordings/, truth/, summary.json), as `gyrodrift simulate`
    does: the same campaign and seed give the same bytes. A folder that is not empty is refused
    (`InputError`), as the command line refuses it; `force=True` replaces a campaign there (and
    still refuses a folder holding other files), once the new one is whole: it is written into a
    staging folder beside `out` and put in place at the end. A campaign that would write more than `max_gb`
    (GB) is refused (`InputError`, with its size) before it is planned or written. `campaign` is
    None (the paper's), a dict or TOML/JSON text (drift_sim::Campaign's fields), or a file path
    (os.PathLike; JSON if it ends in .json, else TOML). The keywords are the command line's flags
    (`set_points` also takes its text, "30,40,33" or "-40:60:10"). Returns the run's summary. The
    GIL is released while simulating; Ctrl-C stops it within a second (`KeyboardInterrupt`, the
    staging folder removed, `out` as it was), and `progress` is called with ("simulating", samples
    done, samples in the campaign). Raises `CampaignError`, `InputError` or `FileError`."""

def resolve_campaign(
    campaign: Mapping[str, Any] | str | os.PathLike[str] | None = None,
    *,
    seed: int | None = None,
    units: int | None = None,
    set_points: Sequence[float] | str | None = None,
    intervals: Sequence[float] | None = None,
    repeats: int | None = None,
    field: bool = False,
    field_only: bool = False,
    zero_drift: bool = False,
    paper_exact: bool = False,
    effects: Sequence[str] | None = None,
    noise_scale: float | None = None,
    truth_at_aux_rate: bool = False,
) -> dict[str, Any]:
    """The validated campaign `simulate` would run with the same arguments, as a dict; nothing is
    simulated."""

# --- fitting and evaluation -------------------------------------------------------------------

@final
class FitSettings:
    """How the tables are fitted (drift_fit::FitSettings): the command line's `--settings`, with
    the same defaults. Ranges are checked when fitting (`FitError` naming the setting)."""

    def __new__(
        cls,
        *,
        lowpass_window_s: float | None = None,
        grid_ms: int | None = None,
        initial_bias_window_s: float | None = None,
        switch_on_window_ms: int | None = None,
        first_reference_s: float | None = None,
        reference_count: int | None = None,
        reference_window_points: int | None = None,
        independent_after_min: float | None = None,
        polynomial_degree: int | None = None,
    ) -> FitSettings: ...
    @staticmethod
    def from_json(text: str) -> FitSettings:
        """Settings from the JSON `gyrodrift fit --settings` reads (missing fields: defaults)."""
    def to_json(self) -> str:
        """The JSON form."""
    @property
    def lowpass_window_s(self) -> float:
        """Low-pass: centred moving average over this many seconds of each recording's own samples
        (default 1.0)."""
    @property
    def grid_ms(self) -> int:
        """Analysis grid: curves kept every this many ms (default 10)."""
    @property
    def initial_bias_window_s(self) -> float:
        """Initial bias: intercept of the rate against the rise over this first part, s (default 4)."""
    @property
    def switch_on_window_ms(self) -> int:
        """Switch-on temperature: mean over this first part of the activation, ms (default 20)."""
    @property
    def first_reference_s(self) -> float:
        """First reference time, s (default 2)."""
    @property
    def reference_count(self) -> int:
        """Reference times per axis, the first included (default 8; 2 to 16)."""
    @property
    def reference_window_points(self) -> int:
        """Correlation samples averaged around each reference time, on the grid (default 10)."""
    @property
    def independent_after_min(self) -> float:
        """Series with at least this interval (min) are independent, like a first activation (default 15)."""
    @property
    def polynomial_degree(self) -> int:
        """Degree of the least-squares polynomial baseline (default 3)."""
    def __eq__(self, other: object, /) -> bool: ...

@final
class AnalysedActivation:
    """One activation analysed as the fit does: per axis, every `grid_ms` from switch-on."""

    @property
    def labels(self) -> Labels:
        """The activation's labels."""
    @property
    def grid_ms(self) -> int:
        """Spacing of the curves, ms."""
    def __len__(self) -> int: ...
    @property
    def time_s(self) -> NDArray[np.float64]:
        """Time of each grid point since switch-on, s, (m,)."""
    @property
    def drift_dps(self) -> NDArray[np.float32]:
        """Low-frequency drift g(t) = low-passed rate − initial bias, °/s, (m, 3)."""
    @property
    def rise_celsius(self) -> NDArray[np.float32]:
        """Temperature rise since switch-on (low-passed), °C, (m, 3)."""
    @property
    def switch_on_raw(self) -> tuple[float, float, float]:
        """Raw temperature at switch-on per axis, as firmware passes it to `power_on`."""
    @property
    def switch_on_celsius(self) -> tuple[float, float, float]:
        """Switch-on temperature per axis, °C."""
    @property
    def initial_bias_dps(self) -> tuple[float, float, float]:
        """Initial (switch-on) bias per axis, °/s."""

def analyse(segment: Segment, *, settings: FitSettings | None = None) -> AnalysedActivation:
    """Analyses one activation as the fit does. Raises `FitError` (e.g. too short)."""

@final
class ActivationResult:
    """One activation corrected with every model (drift-core's f32 corrector) and measured."""

    @property
    def split(self) -> str:
        """Which data: "validation", "held_out_repeat", "field" or "noise_floor"."""
    @property
    def labels(self) -> Labels:
        """The activation's labels."""
    @property
    def drift_dps(self) -> dict[str, tuple[float, float, float]]:
        """Per model ("uncorrected", "standard", "3rd-order", "relative", "modified", "by-history"): drift per
        axis, °/s —
        max − min of the 1-s low-frequency rate over the activation (the paper's metric)."""
    @property
    def residual_rms_dps(self) -> dict[str, tuple[float, float, float]]:
        """Per model: RMS of the low-frequency rate per axis, °/s (includes the initial-bias error)."""
    @property
    def flags(self) -> dict[str, tuple[int, int, int]]:
        """Per model: union of the corrector's flags over the activation, per axis."""

@final
class Diagnosis:
    """What the diagnosis found for one unit, and the extended model when one was asked for."""

    @property
    def unit_id(self) -> str:
        """Unit id."""
    @property
    def ranking(self) -> list[dict[str, Any]]:
        """The ranking of every axis as records (axis, rank, candidate, level, explained,
        family_p_value, p_value, whole_p_value, drift_p_value, significant, thermal_response,
        stable, detectable_share, size_threshold, baseline_explained_within,
        baseline_explained_between, coefficient, absorbed_by_model): a new list of dicts.
        `explained` is the candidate's out-of-sample gain over the baseline (the paper model's
        ambient gap and the bench's context channels, fitted first); `significant` marks the
        candidates selected forward: significant family-wise (`family_p_value` ≤ 0.05, shuffles of
        whole series) and with a gain of at least `size_threshold` (its step's, from null worlds).
        `thermal_response` marks the unit's own thermal response (its rise squared, its own axis's
        temperature rate), selected before any effect; every other candidate is an effect, scored
        over the baseline and the thermal response selected. `detectable_share` is the gain an
        effect on that axis must exceed with these activations. The t-tests' p-values are
        reported, not gated on."""
    @property
    def paper_ranking(self) -> list[dict[str, Any]]:
        """The same diagnosis behind the paper's own model (stage 3 keyed by rise, the paper's
        initial bias), as records like `ranking`: what the paper's model lacked, which the loop's
        choices (`stage3`, `warm_start`) and terms answer. Equal to `ranking` when the loop kept
        the paper's model."""
    def to_dataframe(self) -> Any:
        """The ranking as a pandas DataFrame (needs pandas; raises ImportError without it)."""
    @property
    def chosen(self) -> list[tuple[str, str | None]]:
        """Per axis ("X", "Y", "Z"), the significant winning effect's name, or None when no
        significant systematic effect is left beyond the unit's own thermal response."""
    @property
    def proposed_terms(self) -> list[str]:
        """The terms proposed for the extended model: the diagnosis's significant candidates that
        drift-core can compute."""
    @property
    def admissions(self) -> list[dict[str, Any]]:
        """The guard's decision for every proposed term and axis (records: candidate, axis,
        improvement, p_value, drift_gain_dps, drift_p_value, admitted); empty unless
        `extend=True`. A shape term (rate, rise², another axis's rise) is admitted on
        `drift_p_value`, an auxiliary input on `p_value`."""
    @property
    def stage3(self) -> list[dict[str, Any]]:
        """Per axis, stage 3's lookup as the loop chose it on the training activations (records:
        axis, curves_cross, training_activations, training_drift_by_rise_dps,
        training_drift_by_history_dps, p_value, keyed_by_history)."""
    @property
    def warm_start(self) -> list[dict[str, Any]]:
        """Per axis, whether the loop took the initial bias of warm starts from the calibration's
        series, chosen on the training activations after stage 3 (records: axis,
        training_activations, training_rms_cold_dps, training_rms_warm_dps, p_value, chosen)."""
    @property
    def extended(self) -> ModifiedTables | None:
        """The loop's model (stage 3 keyed as chosen, the refitted tables with the admitted terms),
        or None when it is the paper's unchanged. History-keyed axes need `power_on_after`."""
    @property
    def extended_verdict(self) -> str | None:
        """What became of the extended model, as `gyrodrift diagnose --extend` prints it: why nothing
        was extended (e.g. "no term proposed (nothing significant maps to a term the firmware can
        compute); the paper's model unchanged") or which terms were admitted; None unless
        `extend=True`."""
    @property
    def aux_inputs(self) -> list[str]:
        """The recorded channels the firmware passes as the extended model's auxiliary inputs 0..,
        in order."""
    @property
    def before_after(self) -> list[dict[str, Any]]:
        """Per held-out activation, the error before (paper's model) and after (extended model):
        records with set_point_celsius, series_kind, drift_dps, rms_dps and mean_dps (per axis,
        [before, after]; the mean is the activation's offset), by_history_drift_dps,
        by_history_rms_dps, residual_heat_celsius (per axis, as firmware estimates it at switch-on)
        and off_before_s (the recording's label, or None); empty unless `extend=True` and terms
        were proposed."""
    @property
    def profiles(self) -> dict[str, Any]:
        """Where within each held-out activation the loop's residual sits, by time since
        switch-on: `edges_s` (float64, (13,): bin edges, s; the last is inf, the activation's end),
        `after_dps` (float64, (n, 3, 12): per activation, axis and bin, the loop's 1-s residual's
        mean there less the activation's mean, °/s; NaN for a bin the activation ends before),
        `off_before_s` (float64, (n,); NaN when not recorded), `set_point_celsius` (float64,
        (n,)) and `series_kind` (list of "protocol" / "field")."""
    @property
    def activations(self) -> list[tuple[str, int]]:
        """How many activations played each part: calibration, training, held_out, outside_range,
        diagnosed."""

    def save(self, folder: _Path) -> Path:
        """Writes `diagnosis.md`, `diagnosis.json` and the residual figures (and, with
        `extend=True`, the extended model's image) into `folder`, as `gyrodrift diagnose` writes
        them; returns the path of `diagnosis.md`."""

@final
class FittedUnit:
    """Everything fitted for one unit: the paper's tables and both baselines."""

    @property
    def unit_id(self) -> str:
        """Unit id."""
    @property
    def modified(self) -> ModifiedTables:
        """The paper's ("modified") tables."""
    @property
    def by_history(self) -> ModifiedTables:
        """The same curves with stage 3 keyed by heating history (each curve labelled by the
        residual heat it switched on with): for firmware that keeps what it knew of the previous
        activation (`Corrector.power_on_after`)."""
    @property
    def standard(self) -> PolynomialTables:
        """The paper's standard calibration (Lagrange polynomial through the set points)."""
    @property
    def third_order(self) -> PolynomialTables:
        """The least-squares polynomial baseline (3rd order by default)."""
    @property
    def relative(self) -> RelativePolynomialTables:
        """The least-squares baseline relative to the switch-on (bias = q(T_on) + p(T) − p(T_on)),
        orders chosen by leave-one-series-out cross-validation on the calibration data."""
    @property
    def recommended(self) -> RecommendedTables:
        """The recommended model: the paper's curves with the turn-on bias fitted on every
        calibration activation (`recommended.bin`)."""
    @property
    def settings(self) -> FitSettings:
        """The settings the unit was fitted with (used again by `evaluate`)."""
    @property
    def set_points_celsius(self) -> list[float]:
        """Calibration set points, °C, in table order."""
    @property
    def curve_names(self) -> list[str]:
        """The curves kept, in table order: "independent" or "<interval>min#<activation>"."""
    @property
    def notes(self) -> list[str]:
        """Things the fit decided that a reader should know (dropped curves, nudged ties)."""
    def evaluate(
        self,
        segment: Segment,
        *,
        split: str | None = None,
        previous: _Previous | None = None,
    ) -> ActivationResult:
        """Corrects one activation with every model and measures the paper's metric; `split`
        ("validation" by default) labels the result for `summarise`. The history-keyed model
        ("by-history") starts from `previous`, what firmware kept of the previous activation (a
        (3, 2) array, per axis [ambient °C, switch-off °C], as `Corrector.power_on_after` takes
        and `Corrector.keep` returns); without it, with nothing kept (a cold start, flagged
        HISTORY_UNKNOWN). The GIL is released. Raises `InputError` for a bad `previous`."""
    def evaluate_series(
        self, segments: Sequence[Segment], *, split: str | None = None
    ) -> list[ActivationResult]:
        """Corrects a recording's activations (one unit's) with every model, as `gyrodrift report`
        does: the history-keyed model starts each from what firmware kept of the one before in
        switch-on order, knowing a full cool-down from the recorded off-time; results in the order
        given. The GIL is released, and Ctrl-C stops it between activations. Raises `InputError`
        for an item that is not a Segment."""
    def diagnose(
        self,
        segments: _Source,
        *,
        calibration: Sequence[float] | str | None = None,
        extend: bool = False,
        diagnose_on: Sequence[float] = ...,
        half: int = 0,
        bench_channels: Sequence[str] = ...,
        progress: _Progress | None = None,
    ) -> Diagnosis:
        """Diagnoses what the paper's model leaves in the residual of this unit's activations among
        `segments` (recordings, segments or files; other units' activations are skipped), as
        `gyrodrift diagnose` does: candidates ranked on the field-like activations at the
        calibration set points inside the calibrated ambient range (else on every activation the
        fit did not see); with `extend`, the guarded extended model and its error before and after
        on the held-out activations. `diagnose_on` names set points whose series (field and
        protocol) are the diagnosis data, cross-fitted by series: `half` (0 or 1) is the half this
        loop ranks and fits on, the other half is held out and judges (run both halves, as
        `gyrodrift diagnose --diagnose-on` does). `bench_channels` describe the bench and are never
        ranked (the chamber's set point and air always are). Like the command line, the loop
        works on the activations' 0.1-s block means and refits this unit's paper tables on its
        calibration protocol among them. The GIL is released; Ctrl-C stops it within a second while
        it reads or ranks and between its steps, and `progress` is told the steps. Raises
        `InputError` (no activation of this unit to diagnose, `half` not 0 or 1) or `FitError`."""
    def save(self, folder: _Path) -> Path:
        """Writes <folder>/<unit_id>/{modified,by_history,standard,third_order}.{json,bin} through
        the command line's own writer (the same bytes as `gyrodrift fit`); returns the unit's
        folder. Raises `FileError`."""

def fit(
    source: _Source,
    *,
    calibration: Sequence[float] | None = None,
    settings: FitSettings | None = None,
    progress: _Progress | None = None,
) -> list[FittedUnit]:
    """Fits the tables and both baselines for every unit in `source`, on the protocol activations
    at the `calibration` set points (default 30, 40 °C), as `gyrodrift fit` does. `source` is a
    campaign folder, a folder of .mcap files, one file, a list of files, or recordings/segments in
    memory. One `FittedUnit` per unit, sorted by unit id. The GIL is released; Ctrl-C stops it
    within a second (`KeyboardInterrupt`), and `progress` is told how far it got. Raises
    `FitError`, `RecordingError`, `FileError` or `InputError`."""

@final
class Evaluation:
    """What `evaluate` found: fitted units, analysed calibration activations, evaluated activations."""

    @property
    def fitted(self) -> list[FittedUnit]:
        """Tables fitted on all calibration activations, one per unit."""
    @property
    def calibration(self) -> list[AnalysedActivation]:
        """The calibration activations, analysed (for the paper's figures)."""
    @property
    def results(self) -> list[ActivationResult]:
        """Every evaluated activation with its split."""
    @property
    def records(self) -> list[_Record]:
        """The report's table as data, the records of `report.json`: one dict per unit × set point ×
        split × model × axis with keys unit, set_point_celsius, split, model, axis, drift_dps,
        residual_rms_dps, activations."""
    def to_dataframe(self) -> Any:
        """The records as a pandas DataFrame. Raises ImportError without pandas."""
    @property
    def noise_floor_units(self) -> list[str]:
        """Unit ids of the noise-floor units ("noise:<id>"), if `noise_floor` was given."""
    @property
    def timings(self) -> list[tuple[str, float]]:
        """Measured durations of the pipeline's steps: (step, seconds)."""

def evaluate(
    source: _Path | Sequence[_Path],
    *,
    calibration: Sequence[float] | None = None,
    validation: Sequence[float] | None = None,
    settings: FitSettings | None = None,
    held_out_repeats: bool = True,
    noise_floor: _Path | Sequence[_Path] | None = None,
    progress: _Progress | None = None,
) -> Evaluation:
    """Fits at the `calibration` set points (default 30, 40 °C) and evaluates every activation no
    fit saw, as `gyrodrift report` does: the `validation` set points (default 33 °C), field
    sessions, and (with `held_out_repeats`) each repeat at the calibration set points against
    tables refitted without it. `source` is recording files (a campaign folder, a folder of .mcap
    files, a list of files); `noise_floor` a campaign of zero-drift units, measured at the
    validation set points. The GIL is released; Ctrl-C stops it within a second
    (`KeyboardInterrupt`), and `progress` is called with (step, done, total): "reading
    recordings" and "correcting and evaluating" count files. Raises `FitError`, `RecordingError`,
    `FileError` or `InputError`."""

def report(
    source: _Path | Sequence[_Path],
    out: _Path,
    *,
    calibration: Sequence[float] | None = None,
    validation: Sequence[float] | None = None,
    settings: FitSettings | None = None,
    noise_floor: _Path | Sequence[_Path] | None = None,
    progress: _Progress | None = None,
) -> Path:
    """Writes the report of `gyrodrift report` into `out`: `report.md` with its SVG figures,
    `report.json` (the table as data), `timings.json` and the fitted tables folder `tables/`, through
    the same function as the command line, so the same recordings and options give the same bytes.
    Returns the path of `report.md`. Arguments as `evaluate`'s. The GIL is released; Ctrl-C stops
    it within a second, before anything is written. Raises `FitError`, `RecordingError`,
    `FileError` or `InputError`."""

def summarise(results: Sequence[ActivationResult]) -> list[_Record]:
    """Averages activation results into the report's records (as `Evaluation.records`)."""

def excess_cut(before: _Floats, after: _Floats, floor: _Floats) -> tuple[float, float, float]:
    """How many times a model cuts the metric's excess over the noise floor, with its 95 %
    interval: `(ratio, low, high)`, ratio = (mean(before) − mean(floor)) / (mean(after) −
    mean(floor)), as the closed-loop experiment and `gyrodrift diagnose --extend` report it.
    `before[i]` and `after[i]` are activation i's metric (e.g. its drift, °/s) under the two
    models, resampled together; `floor` the zero-drift twin's activations, resampled apart (a
    seeded bootstrap of 2000 draws, so the same data give the same interval). Raises `InputError`
    for an array that is empty, not finite (naming the index), or `after` not as long as
    `before`."""

def _restore(kind: str, version: str, state: bytes) -> Any:
    """Rebuilds a pickled object (what `__reduce__` names)."""

def _read_csv_text(
    data: bytes,
    name: str,
    *,
    time: str,
    rate: Sequence[str],
    temperature: Sequence[str],
    activation: str | None,
    rate_unit: str,
    unit_id: str,
    sample_rate_hz: int,
    max_gap_s: float | None,
    set_point_celsius: float | None,
    series_kind: str,
    temperature_dropouts: bool,
) -> Recording:
    """CSV text through the command line's validating reader (`Recording.from_dataframe`)."""
