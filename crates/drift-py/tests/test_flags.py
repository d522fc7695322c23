"""The flags as named constants and as an IntFlag."""

from __future__ import annotations

import gyrodrift
from gyrodrift import Flags, _gyrodrift


def test_every_native_flag_is_a_flag_member() -> None:
    """`_gyrodrift.FLAGS` is drift_core::Flags::ALL: a flag added there fails here until `Flags`
    (python/gyrodrift/__init__.py) and the stubs name it."""
    assert [(m.name, m.value) for m in Flags] == list(_gyrodrift.FLAGS)
    for name, value in _gyrodrift.FLAGS:
        assert getattr(_gyrodrift, name) == value


def test_flag_names_and_bits() -> None:
    names = [
        "AMBIENT_OUT_OF_RANGE",
        "RISE_OUT_OF_SPAN",
        "PAST_LAST_REFERENCE",
        "TEMPERATURE_OUT_OF_RANGE",
        "TEMPERATURE_INVALID",
        "TEMPERATURE_STUCK",
        "RATE_INVALID",
        "NOT_POWERED_ON",
        "MODEL_INVALID",
        "EXTENSION_INPUT_INVALID",
        "HISTORY_UNKNOWN",
        "HISTORY_OUT_OF_SPAN",
    ]
    assert [m.name for m in Flags] == names
    for name in names:
        assert Flags[name].value == getattr(_gyrodrift, name)
    values = [f.value for f in Flags]
    assert values == [1 << i for i in range(len(names))]  # distinct single bits, as in drift-core
    assert Flags.EXTENSION_INPUT_INVALID.value == 1 << 9
    assert len(names) == 12
    assert (Flags.HISTORY_UNKNOWN.value, Flags.HISTORY_OUT_OF_SPAN.value) == (1 << 10, 1 << 11)


def test_faults_mask() -> None:
    assert Flags.faults() == (
        Flags.TEMPERATURE_INVALID
        | Flags.TEMPERATURE_STUCK
        | Flags.RATE_INVALID
        | Flags.NOT_POWERED_ON
        | Flags.MODEL_INVALID
        | Flags.EXTENSION_INPUT_INVALID
    )
    assert Flags.faults().value == _gyrodrift.FAULTS


def test_flags_decode_an_output_value() -> None:
    decoded = Flags(6)
    assert Flags.RISE_OUT_OF_SPAN in decoded and Flags.PAST_LAST_REFERENCE in decoded
    assert Flags.RATE_INVALID not in decoded
    assert Flags.EXTENSION_INPUT_INVALID in Flags(1 << 9 | 1)
    assert gyrodrift.Flags is Flags
