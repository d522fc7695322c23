"""The native module (pyo3). Use it through `gyrodrift`, which re-exports everything here.

Units are in the names: `_dps` is °/s, `_ms` milliseconds since switch-on, `_raw` raw
temperature-sensor units (see `Settings`), `_celsius` °C. All arithmetic is f32, as on the firmware.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Final, final

import numpy as np
from numpy.typing import NDArray
from typing_extensions import TypeAlias

__version__: Final[str]
__all__ = [
    "AMBIENT_OUT_OF_RANGE",
    "FAULTS",
    "MODEL_INVALID",
    "NOT_POWERED_ON",
    "PAST_LAST_REFERENCE",
    "RATE_INVALID",
    "RISE_OUT_OF_SPAN",
    "TEMPERATURE_INVALID",
    "TEMPERATURE_OUT_OF_RANGE",
    "TEMPERATURE_STUCK",
    "Corrector",
    "FileError",
    "GyrodriftError",
    "ImageError",
    "InputError",
    "ModifiedTables",
    "Output",
    "PolynomialTables",
    "Settings",
    "TableError",
    "__version__",
]

_Path: TypeAlias = str | os.PathLike[str]
_Floats3: TypeAlias = Sequence[float] | NDArray[np.floating]
_Model: TypeAlias = ModifiedTables | PolynomialTables

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
FAULTS: Final[int]

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
    def celsius(self, raw: float) -> float:
        """A raw temperature reading in °C, computed in f32 as the corrector does."""

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
    def power_on(self, switch_on_raw: _Floats3) -> tuple[int, int, int]:
        """Starts an activation from the raw temperatures at switch-on (X, Y, Z).

        Returns the flags that hold for the whole activation, per axis. A NaN or infinite reading
        raises `InputError` naming the axis, and the state is unchanged.
        """
    def power_off(self) -> None:
        """Ends the activation: samples pass through, flagged NOT_POWERED_ON, until `power_on`."""
    def correct(self, since_power_on_ms: int, rate_dps: _Floats3, temperature_raw: _Floats3) -> Output:
        """Corrects one sample. NaN/inf inputs are flagged, not raised."""
    def correct_batch(
        self,
        since_power_on_ms: NDArray[np.uint32],
        rate_dps: NDArray[np.float32] | NDArray[np.float64],
        temperature_raw: NDArray[np.float32] | NDArray[np.float64],
        *,
        out: tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.uint16]] | None = None,
    ) -> tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.uint16]]:
        """Corrects n samples in order, continuing the current activation.

        Arguments: `since_power_on_ms` uint32 (n,); `rate_dps` and `temperature_raw` float32 or
        float64 (n, 3), any strides (read in place, not copied; float64 is rounded to f32 per
        value). Returns `(corrected_dps, bias_dps, flags)`: float32, float32 and uint16 arrays of
        shape (n, 3) — new arrays, or the arrays given as `out` (C-contiguous, writeable, none of
        them an input), filled in place, which saves allocating for every block. The GIL is
        released while correcting. Raises `InputError` for a wrong dtype or shape, an empty
        array, or lengths that differ.
        """
