"""The model's names in Python as on the command line and in the files (issue 39): one
name per quantity. `Model.mass_centre_m` is the cabin's mass centre (cabin frame, m), as
the model file's `mass_centre_m` and calibrate's `mass_centre_m.x`; the binding's older
`mass_centre_cabin_m` still works, with a DeprecationWarning."""

from __future__ import annotations

import warnings
from typing import Any

from ._fastcal import InputError, Model

_BOUND = Model.mass_centre_cabin_m  # the binding's property (validated setter)
_OLD, _NEW = "mass_centre_cabin_m", "mass_centre_m"


def _get(model: Model) -> Any:
    return _BOUND.fget(model)


def _set(model: Model, value: Any) -> None:
    try:
        _BOUND.fset(model, value)
    except (ValueError, InputError) as error:  # the message in the name the user wrote
        raise type(error)(str(error).replace(_OLD, _NEW)) from None


def _warn() -> None:
    warnings.warn(f"Model.{_OLD} is now Model.{_NEW} (the model file's and calibrate's name)",
                  DeprecationWarning, stacklevel=3)


def _old_get(model: Model) -> Any:
    _warn()
    return _BOUND.fget(model)


def _old_set(model: Model, value: Any) -> None:
    _warn()
    _BOUND.fset(model, value)


Model.mass_centre_m = property(  # type: ignore[attr-defined]
    _get, _set, doc="Mass centre of the cabin in the cabin frame (m), shape (3,), read-only "
                    "array; assign a whole one. With moving parts: at every joint zero.")
Model.mass_centre_cabin_m = property(  # type: ignore[attr-defined]
    _old_get, _old_set, doc=f"Deprecated: Model.{_NEW}.")
