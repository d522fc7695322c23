"""Model names, spelled two ways for the same models: the report's (`records`, frames,
`ActivationResult.drift_dps`: "3rd-order", "by-history") and the identifiers of `FittedUnit`'s
attributes and the files `save` writes ("third_order", "by_history"). Whatever takes a model name
takes either."""

from __future__ import annotations

from . import _gyrodrift

MODEL_NAMES: dict[str, str] = {
    "uncorrected": "uncorrected",
    "standard": "standard",
    "3rd-order": "third_order",
    "relative": "relative",
    "relative-cubic": "relative_cubic",
    "modified": "modified",
    "by-history": "by_history",
    "recommended": "recommended",
    "modified-at-ambient": "modified_at_ambient",
}
"""Each model's report name → its identifier (the `FittedUnit` attribute, where a unit holds one)."""

_BY_IDENTIFIER = {identifier: name for name, identifier in MODEL_NAMES.items()}


def model_name(name: str) -> str:
    """The report's spelling of a model given either way (`"third_order"` → `"3rd-order"`): the key
    of `records`, frame columns and `ActivationResult.drift_dps`. Raises `InputError`, listing the
    valid names, for any other name."""
    if isinstance(name, str):
        if name in MODEL_NAMES:
            return name
        if name in _BY_IDENTIFIER:
            return _BY_IDENTIFIER[name]
    valid = ", ".join(n if n == i else f"{n} ({i})" for n, i in MODEL_NAMES.items())
    raise _gyrodrift.InputError(f"unknown model name {name!r}: the models are {valid}")


def model_attribute(name: str) -> str:
    """The identifier spelling of a model given either way (`"3rd-order"` → `"third_order"`): the
    `FittedUnit` attribute, `getattr(unit, model_attribute(name))`. Raises `InputError`, listing
    the valid names, for any other name."""
    return MODEL_NAMES[model_name(name)]
