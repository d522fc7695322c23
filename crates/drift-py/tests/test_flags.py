"""The flags as named constants and as an IntFlag."""

from __future__ import annotations

import gyrodrift
from gyrodrift import Flags, _gyrodrift


def test_every_native_constant_is_a_flag_member() -> None:
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
    ]
    assert [m.name for m in Flags] == names
    for name in names:
        assert Flags[name].value == getattr(_gyrodrift, name)
    values = [f.value for f in Flags]
    assert values == [1 << i for i in range(len(names))]  # distinct single bits, as in drift-core


def test_faults_mask() -> None:
    assert Flags.faults() == (
        Flags.TEMPERATURE_INVALID
        | Flags.TEMPERATURE_STUCK
        | Flags.RATE_INVALID
        | Flags.NOT_POWERED_ON
        | Flags.MODEL_INVALID
    )
    assert Flags.faults().value == _gyrodrift.FAULTS


def test_flags_decode_an_output_value() -> None:
    decoded = Flags(6)
    assert Flags.RISE_OUT_OF_SPAN in decoded and Flags.PAST_LAST_REFERENCE in decoded
    assert Flags.RATE_INVALID not in decoded
    assert gyrodrift.Flags is Flags
