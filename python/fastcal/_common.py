"""Shared helpers of the package's modules: argument checks, array shapes, renamed keywords."""

from __future__ import annotations

import functools
import json
import os
import re
import warnings
from typing import Any, Callable, List, Mapping, Optional, Sequence, Tuple, TypeVar, Union

import numpy as np

from . import _fastcal
from ._fastcal import InputError


ArrayLike = Union[np.ndarray, Sequence[float], Sequence[Sequence[float]]]
_Function = TypeVar("_Function", bound=Callable[..., Any])


def _renamed_keywords(renamed: Mapping[str, str]) -> Callable[[_Function], _Function]:
    """Accepts each keyword's old name (a key of `renamed`) as its new one, with a
    DeprecationWarning: the keywords now have the command line's names (docs/python.md,
    "Names")."""

    def wrap(function: _Function) -> _Function:
        @functools.wraps(function)
        def call(*args: Any, **kwargs: Any) -> Any:
            for old, new in renamed.items():
                if old not in kwargs:
                    continue
                if new in kwargs:
                    raise TypeError(f"{function.__name__}() got both {old}= and {new}=")
                warnings.warn(
                    f"{function.__name__}({old}=...) is deprecated: use {new}= (the command "
                    f"line's --{new.replace('_', '-')})",
                    DeprecationWarning,
                    stacklevel=2,
                )
                kwargs[new] = kwargs.pop(old)
            return function(*args, **kwargs)

        return call  # type: ignore[return-value]

    return wrap

PathLike = Union[str, "os.PathLike[str]"]

STATUS_NAMES: List[str] = _fastcal.statics_status_names()
"""The statics status of a pose, by code: 'ok', 'invalid_input', 'vertical_cable',
'no_equilibrium', 'sagging_cable', 'overstretched_cable', 'reflector_contact', ... (the
short codes of `fastcal solve`'s status column)."""
_STATUS_NAMES_ARRAY = np.array(STATUS_NAMES, dtype=object)


def _rows(value: ArrayLike, columns: int, name: str) -> Tuple[np.ndarray, bool]:
    """`value` as an (n, columns) float array, and whether it was one row of shape (columns,)."""
    array = np.asarray(value, dtype=np.float64)
    if array.ndim == 1 and array.shape[0] == columns:
        return array.reshape(1, columns), True
    if array.ndim == 2 and array.shape[1] == columns:
        return np.ascontiguousarray(array), False
    raise InputError(f"{name} must have shape ({columns},) or (n, {columns}), got {array.shape}")


def _attitude(
    n: int, rpy_deg: Optional[ArrayLike], quat: Optional[ArrayLike], rows_of: str = "positions"
) -> Tuple[str, np.ndarray]:
    """The attitude arguments as the core takes them: a kind and an (n, k) array."""
    if rpy_deg is not None and quat is not None:
        raise InputError("give rpy_deg or quat, not both")
    if rpy_deg is None and quat is None:
        return "none", np.zeros((0, 3))
    kind, value, columns = ("rpy", rpy_deg, 3) if rpy_deg is not None else ("quat", quat, 4)
    name = "rpy_deg" if kind == "rpy" else "quat"
    array, _ = _rows(value, columns, name)
    if array.shape[0] == 1 and n > 1:  # one attitude for every position, as numpy broadcasts
        array = np.ascontiguousarray(np.repeat(array, n, axis=0))
    if array.shape[0] != n:
        raise InputError(f"{name} has {array.shape[0]} rows for {n} {rows_of}")
    return kind, array


_INT32_MIN = -(2**31)
_INT32_MAX = 2**31 - 1
_UINT64_MAX = 2**64 - 1


def _whole(value: Any, name: str, low: int, high: int) -> int:
    """`value` as a Python int in [low, high]; InputError naming `name` otherwise (a float,
    a str, a bool, a number out of range), never a raw TypeError of the core."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InputError(f"{name} must be a whole number, got {value!r}")
    if not low <= int(value) <= high:
        raise InputError(f"{name} must be from {low} to {high}, got {int(value)}")
    return int(value)


def _number(value: Any, name: str) -> float:
    """`value` as a float; InputError naming `name` for what is not a real number."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        raise InputError(f"{name} must be a number, got {value!r}")
    return float(value)


def _point(value: ArrayLike, name: str) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (3,):
        raise InputError(f"{name} must have shape (3,), got {array.shape}")
    return array


# The library's option fields behind keywords named as the command line's flags.
_SOLVE_OPTION_FIELDS = {
    "refined_tolerance": "refined_relative_tolerance",
    "aas_max_error": "aas_max_relative_error",
    "exact_tolerance": "exact_relative_tolerance",
    "reflector_clearance_m": "min_reflector_clearance_m",
}


def _call_with_names(fields: Mapping[str, str], function: Callable[..., Any], *args: Any) -> Any:
    """function(*args), an InputError's message naming the keywords instead of the
    library's fields (keyword -> field in `fields`)."""
    try:
        return function(*args)
    except InputError as error:
        message = str(error)
        for keyword, field in fields.items():
            message = re.sub(rf"\b{re.escape(field)}\b", keyword, message)
        raise InputError(message) from None


_DICT_SPEC = "spec (dict)"


def _spec_argument(spec: Union[PathLike, Mapping[str, Any]]) -> Tuple[str, bool, str]:
    """A spec file's path, or a dict as YAML text (JSON is YAML) with a name for messages."""
    if isinstance(spec, Mapping):
        return json.dumps(spec), True, _DICT_SPEC
    return os.fspath(spec), False, os.fspath(spec)
