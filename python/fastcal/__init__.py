"""fastcal: statics and calibration of the FAST cable robot, from Python.

The C++ library's statics (six sagging cables, elastic catenary) and its calibration
against measured cable tensions, on numpy arrays. Guide: docs/python.md.

    import fastcal
    p = fastcal.arc(centre_m=(0, 0, 156.73), radius_m=71.11, nodes=360)
    sol = fastcal.solve(p, quat=fastcal.focal_attitude(p))
    sol.lower_tension_kN          # (360, 6), cable i in column i-1

Units are in the names: SI inside (position_m, s0_m), kN for tensions and forces
(lower_tension_kN, force_kN), degrees for roll/pitch/yaw (rpy_deg). Quaternions are
(w, x, y, z). A sensor bias is in kN too (Model.sensor_bias_kN). A missing input file
raises FileNotFoundError (an OSError), as open() does; other bad input raises
fastcal.InputError (a ValueError) with the message the command line prints: it names the
file, line, column or parameter. A calibration the data cannot support raises
fastcal.CalibrationError (a RuntimeError).
"""

from __future__ import annotations

import difflib
import functools
import json
import os
import re
import warnings
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, TypeVar, Union

try:
    import numpy as np

    from . import _fastcal
except ImportError as _error:  # another interpreter than the build's: say which to use
    try:
        from ._build import PYTHON as _BUILT_FOR
    except ImportError:  # an installed package: no build tree
        raise _error from None
    raise ImportError(
        f"fastcal was built for {_BUILT_FOR}; this is another Python interpreter "
        f"({_error}). Run it with {_BUILT_FOR}, or build/python/python3 in the build tree "
        "(docs/python.md)"
    ) from _error
from ._fastcal import CalibrationError, Dataset, Error, InputError, Model

__version__: str = _fastcal.__version__

__all__ = [
    "CalibrationError",
    "CalibrationResult",
    "Dataset",
    "Error",
    "InputError",
    "LocateResult",
    "Model",
    "StaticsResult",
    "__version__",
    "arc",
    "calibrate",
    "design",
    "evaluate",
    "focal_attitude",
    "focal_grid",
    "line",
    "locate",
    "quat_from_rpy_deg",
    "random_workspace",
    "read_dataset",
    "rpy_deg_from_quat",
    "simulate",
    "solve",
    "track",
    "TrackResult",
]



def __dir__() -> List[str]:
    """What the package offers (__all__), not the modules it imports (np, os, re, json)."""
    return sorted(__all__ + ["STATUS_NAMES"])


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


class StaticsResult:
    """The statics of one pose or of n poses (fastcal.solve).

    For n poses (positions of shape (n, 3)) each array has a leading axis of n; for one
    pose (shape (3,)) it has none, and `status` and `ok` are scalars. Cable i is at index
    i-1 of the cable axis.

    Attributes:
        lower_tension_kN: tension at the cabin end, (n, 6). What the cabin-side sensor
            reads through its gain and bias (Model.sensor_gain, sensor_bias_kN).
        upper_tension_kN: tension at the tower end, (n, 6).
        s0_m: unstretched cable lengths, (n, 6).
        force_kN: force applied on each cable at its lower end by the cabin, global
            frame, (n, 6, 3); the cabin feels its opposite.
        chord_m: straight-line length from cabin anchor to tower top, (n, 6).
        status: per pose 'ok' or why it failed ('no_equilibrium', 'sagging_cable',
            'reflector_contact', 'not_converged', ...; STATUS_NAMES), an (n,) array of str.
        ok: per pose whether status is 'ok', (n,) bool.
        cable: per pose the 1-based cable a failure concerns, 0 when none, (n,) int.
        messages: per failed pose index, the full account (the CLI's words).
        end_residual_m: per pose, how far the returned state misses the catenaries' end
            conditions (largest over the cables), (n,); ~0 for 'exact'.
        error_estimate: per pose, the relative tension error those misses imply, (n,):
            the check behind every 'ok' (docs/model.md, "Checks and statuses").

    A failed pose has NaN tensions, forces and unstretched lengths (its chord is
    geometry and stays), with `status` saying why: np.nanmean skips it, a plain mean
    shows it.
    """

    def __init__(self, raw: Dict[str, Any], single: bool) -> None:
        codes = raw["status_code"]
        status = _STATUS_NAMES_ARRAY[codes]
        self.messages: Dict[int, str] = dict(raw["failures"])
        self._single = single
        pick = (lambda a: a[0]) if single else (lambda a: a)
        self.lower_tension_kN: np.ndarray = pick(raw["lower_tension_kN"])
        self.upper_tension_kN: np.ndarray = pick(raw["upper_tension_kN"])
        self.s0_m: np.ndarray = pick(raw["s0_m"])
        self.force_kN: np.ndarray = pick(raw["force_kN"])
        self.chord_m: np.ndarray = pick(raw["chord_m"])
        self.end_residual_m = pick(raw["end_residual_m"])
        self.error_estimate = pick(raw["error_estimate"])
        self.status = pick(status)
        self.ok = pick(codes == 0)
        self.cable = pick(raw["cable"] + 1)

    def __len__(self) -> int:
        return 1 if self._single else len(self.ok)

    def __repr__(self) -> str:
        n = len(self)
        failed = n - int(np.sum(self.ok))
        return f"<fastcal.StaticsResult: {n} pose{'s' if n != 1 else ''}, {failed} failed>"


@_renamed_keywords(
    {
        "refined_relative_tolerance": "refined_tolerance",
        "aas_max_relative_error": "aas_max_error",
        "exact_relative_tolerance": "exact_tolerance",
        "min_reflector_clearance_m": "reflector_clearance_m",
    }
)
def solve(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    method: str = "exact",
    model: Optional[Model] = None,
    *,
    warm_start: bool = False,
    max_refinement_steps: int = 8,
    refined_tolerance: float = 1e-6,
    aas_max_error: float = 1e-2,
    exact_tolerance: float = 1e-12,
    max_strain: float = 0.05,
    max_length_ratio: float = 1.5,
    reflector_clearance_m: float = 0.0,
) -> StaticsResult:
    """Cable forces, tensions and unstretched lengths at one pose or many.

    Args:
        position_m: position of the cabin-frame origin, global frame: (3,) or (n, 3).
        rpy_deg: attitude as roll, pitch, yaw in degrees, R = Rz(yaw) Ry(pitch) Rx(roll):
            (3,) or (n, 3); one (3,) attitude applies to every position. At most one of
            rpy_deg and quat; neither means R = I.
        quat: attitude as unit quaternions (w, x, y, z): (4,) or (n, 4), one for all as
            rpy_deg. E.g. the focal law's, fastcal.focal_attitude(position_m).
        method: 'exact' (Newton on all unknowns; where its start fails it follows the
            equilibrium from the home pose), 'aas-refined' (the paper's AAS refined by
            Newton steps on its tangent until its error estimate is below
            refined_tolerance) or 'aas' (the paper's; 'inaccurate' when its error
            estimate exceeds aas_max_error).
        model: the model; None for Model.nominal().
        warm_start: start each pose from the previous pose's solution (a trajectory);
            off, each pose is solved on its own and the order does not matter.
        max_refinement_steps: at most this many steps of 'aas-refined' (>= 1), then
            'not_converged'.
        refined_tolerance: where 'aas-refined' stops (relative tension error).
        aas_max_error: the largest relative error estimate 'aas' calls 'ok'.
        exact_tolerance: where 'exact' stops (relative).
        max_strain: tensions above max_strain * EA are refused ('overstretched_cable').
        max_length_ratio: unstretched lengths above this times the chord are refused
            ('sagging_cable').
        reflector_clearance_m: with a reflector in the model, a cable closer to its
            surface than this is refused ('reflector_contact').

    The keywords are the command line's flags (--aas-max-error: aas_max_error), with
    the unit where the flag leaves it implicit (--reflector-clearance:
    reflector_clearance_m). The former names (aas_max_relative_error, ...) still work,
    with a DeprecationWarning.

    Returns:
        A StaticsResult: arrays with a leading axis of n for (n, 3) positions, none for
        one (3,) position. Poses the cables cannot hold are marked in `status`/`ok`,
        not raised. Solved in C++, without holding the GIL.

    Raises:
        InputError: a wrong shape, an unknown method, a non-unit quaternion (named by row).
    """
    positions, single = _rows(position_m, 3, "position_m")
    kind, attitude = _attitude(positions.shape[0], rpy_deg, quat)
    raw = _call_with_names(
        _SOLVE_OPTION_FIELDS,
        _fastcal.solve,
        model if model is not None else Model.nominal(),
        positions,
        kind,
        attitude,
        method,
        {
            "warm_start": warm_start,
            "max_refinement_steps": _whole(max_refinement_steps, "max_refinement_steps", 1, 10**6),
            "refined_relative_tolerance": refined_tolerance,
            "aas_max_relative_error": aas_max_error,
            "exact_relative_tolerance": exact_tolerance,
            "max_strain": max_strain,
            "max_length_ratio": max_length_ratio,
            "min_reflector_clearance_m": reflector_clearance_m,
        },
    )
    return StaticsResult(raw, single)


STABILITY_NAMES: List[str] = _fastcal.stability_names()
"""The stability of a located pose, by code: 'unknown' (no answer), 'stable',
'unstable', 'marginal' (fastcal locate's stability column)."""
_STABILITY_NAMES_ARRAY = np.array(STABILITY_NAMES, dtype=object)


class LocateResult:
    """Where the cabin hangs for one row of lengths or n rows (fastcal.locate).

    For n rows (lengths of shape (n, 6)) each array has a leading axis of n; for one
    ((6,)) it has none, and `status`, `ok`, `stability` are scalars.

    Attributes:
        position_m: the cabin-frame origin, global frame, (n, 3).
        quat: the attitude as unit quaternions (w, x, y, z), (n, 4); rpy_deg the same as
            roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll), (n, 3).
        lower_tension_kN: the tensions at the cabin ends there, (n, 6).
        s0_m: the lengths of the answer's equilibrium, (n, 6): the given ones for lengths
            alone, the fitted pose's with a measured attitude or tensions.
        status: 'ok' or why not ('no_equilibrium', 'overstretched_cable', ...;
            STATUS_NAMES), ok: status == 'ok'.
        stability: 'stable', 'unstable', 'marginal' ('unknown' where not ok).
        min_stiffness_kN_per_m: smallest eigenvalue of the stiffness of the potential
            energy with the lengths held (rotations scaled by the cabin's size): < 0 unstable.
        other_equilibria: other equilibria of the same lengths found within
            search_radius_m; nearest_other_m their nearest's distance (NaN: none).
        covariance: of (position (m), rotation vector (rad, global axes)), (n, 6, 6);
            sigma_position_m (n, 3) and sigma_rpy_deg (n, 3) from it.
        pose_per_length: d(position, rotation vector)/d s0_j, (n, 6, 6).
        readings, chi2: readings the pose fits and their whitened residuals squared
            (lengths alone: 6 and 0).
        error_estimate_m: the next Newton step's size after the last.
        messages: row index -> the account of a row that failed, is not stable or has
            another equilibrium nearby (the CLI's words).

    A failed row has NaN numbers, with `status` saying why.
    """

    def __init__(self, raw: Dict[str, Any], single: bool) -> None:
        self._single = single
        pick = (lambda a: a[0]) if single else (lambda a: a)
        codes = raw["status_code"]
        self.position_m: np.ndarray = pick(raw["position_m"])
        self.quat: np.ndarray = pick(raw["quat"])
        rpy = np.full((len(codes), 3), np.nan)
        ok = codes == 0
        if ok.any():
            rpy[ok] = _fastcal.rpy_deg_from_quat(raw["quat"][ok])
        self.rpy_deg: np.ndarray = pick(rpy)
        self.lower_tension_kN: np.ndarray = pick(raw["lower_tension_kN"])
        self.s0_m: np.ndarray = pick(raw["s0_m"])
        self.status = pick(_STATUS_NAMES_ARRAY[codes])
        self.ok = pick(ok)
        self.stability = pick(_STABILITY_NAMES_ARRAY[raw["stability_code"]])
        self.min_stiffness_kN_per_m = pick(raw["min_stiffness_kN_per_m"])
        self.other_equilibria = pick(raw["other_equilibria"])
        self.nearest_other_m = pick(raw["nearest_other_m"])
        covariance = raw["covariance"]
        self.covariance: np.ndarray = pick(covariance)
        variances = np.diagonal(covariance, axis1=1, axis2=2)
        self.sigma_position_m: np.ndarray = pick(np.sqrt(np.maximum(variances[:, :3], 0.0)))
        sigma_rpy = np.full((len(codes), 3), np.nan)
        if ok.any():
            j = _fastcal.rpy_deg_per_rotation_vector(raw["quat"][ok])
            c = np.einsum("kab,kbc,kdc->kad", j, covariance[ok][:, 3:, 3:], j)
            sigma_rpy[ok] = np.sqrt(np.maximum(np.diagonal(c, axis1=1, axis2=2), 0.0))
        self.sigma_rpy_deg: np.ndarray = pick(sigma_rpy)
        self.pose_per_length: np.ndarray = pick(raw["pose_per_length"])
        self.readings = pick(raw["readings"])
        self.chi2 = pick(raw["chi2"])
        self.error_estimate_m = pick(raw["error_estimate_m"])
        self.messages: Dict[int, str] = dict(raw["messages"])

    def __len__(self) -> int:
        return 1 if self._single else len(self.ok)

    def __repr__(self) -> str:
        n = len(self)
        failed = n - int(np.sum(self.ok))
        unstable = int(np.sum(np.atleast_1d(self.stability) != "stable")) - failed
        return (
            f"<fastcal.LocateResult: {n} row{'s' if n != 1 else ''}, {failed} failed, "
            f"{unstable} not stable>"
        )


@_renamed_keywords({"min_reflector_clearance_m": "reflector_clearance_m"})
def locate(
    lengths_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    tensions_kN: Optional[ArrayLike] = None,
    model: Optional[Model] = None,
    *,
    warm_start: bool = True,
    search_radius_m: float = 2.0,
    spec: Optional[Union[PathLike, Mapping[str, Any]]] = None,
    length_sigma_m: Optional[float] = None,
    tension_sigma_percent: Optional[float] = None,
    tension_sigma_kN: Optional[float] = None,
    attitude_sigma_deg: float = 0.05,
    max_strain: float = 0.05,
    max_length_ratio: float = 1.5,
    reflector_clearance_m: float = 0.0,
) -> LocateResult:
    """Where the cabin hangs, from the six unstretched cable lengths (forward statics).

    Args:
        lengths_m: unstretched lengths s0, cable 1 first: (6,) or (n, 6).
        rpy_deg, quat: a measured attitude per row ((3,)/(n, 3) or (4,)/(n, 4)), at most
            one: the pose is then fitted to the lengths and the attitude together.
        tensions_kN: measured tension readings per row, (6,) or (n, 6) (the model's
            sensor gain and bias apply): fitted too.
        model: the model; None for Model.nominal().
        warm_start: each row starts from the previous row's answer (a trajectory); the
            first, and any whose warm start fails, follows the equilibrium from the home
            pose as the lengths move from its lengths to the row's.
        search_radius_m: look for other equilibria of the same lengths this far from the
            answer (m, anchors' move); 0: none.
        spec: a calibration spec (file or dict) whose noise gives the sigmas below
            (its tension sigmas, and length_sigma_m when it has one), as `fastcal locate
            --spec`; a sigma given as a keyword overrides it.
        length_sigma_m, tension_sigma_percent, tension_sigma_kN, attitude_sigma_deg:
            the measurements' sigmas (the fit's weights, and `covariance`); without
            them and a spec 0.01 m, 3 %, 0 kN (attitude 0.05 deg).
        max_strain, max_length_ratio, reflector_clearance_m: the model's range, as in
            solve() (min_reflector_clearance_m, the former name, warns).

    Returns:
        A LocateResult (arrays with a leading axis of n for (n, 6) lengths). Rows that
        fail are marked in `status`/`ok`, not raised. Solved in C++ without the GIL.

    Raises:
        InputError: a wrong shape, a non-unit quaternion, a bad sigma or option.
    """
    lengths, single = _rows(lengths_m, 6, "lengths_m")
    n = lengths.shape[0]
    kind, attitude = _attitude(n, rpy_deg, quat, "rows of lengths_m")
    if tensions_kN is None:
        tensions = np.zeros((0, 6))
    else:
        tensions, _ = _rows(tensions_kN, 6, "tensions_kN")
    robot = model if model is not None else Model.nominal()
    noise: Dict[str, Any] = {
        "length_sigma_m": 0.01,
        "tension_sigma_percent": 3.0,
        "tension_sigma_kN": 0.0,
    }
    if spec is not None:
        given = _fastcal.spec_noise(robot, *_spec_argument(spec))
        noise.update({k: v for k, v in given.items() if v is not None})
    for name, value in (
        ("length_sigma_m", length_sigma_m),
        ("tension_sigma_percent", tension_sigma_percent),
        ("tension_sigma_kN", tension_sigma_kN),
    ):
        if value is not None:
            noise[name] = value
    raw = _fastcal.locate(
        robot,
        lengths,
        kind,
        attitude,
        tensions,
        {
            "warm_start": warm_start,
            "search_radius_m": search_radius_m,
            **noise,
            "attitude_sigma_deg": attitude_sigma_deg,
            "max_strain": max_strain,
            "max_length_ratio": max_length_ratio,
            "min_reflector_clearance_m": reflector_clearance_m,
        },
    )
    return LocateResult(raw, single)


def line(from_m: ArrayLike, to_m: ArrayLike, nodes: int = 101) -> np.ndarray:
    """`nodes` evenly spaced positions from `from_m` to `to_m`, both included: (nodes, 3).

    The paper's line G1 -> G2 is line((50, 0, 150), (-50, 0, 150)).
    """
    return _fastcal.line(
        _point(from_m, "from_m"), _point(to_m, "to_m"), _whole(nodes, "nodes", _INT32_MIN, _INT32_MAX)
    )


def arc(
    centre_m: ArrayLike = (0.0, 0.0, 150.0),
    radius_m: float = 50.0,
    start_deg: float = 0.0,
    end_deg: float = 360.0,
    nodes: int = 101,
) -> np.ndarray:
    """Positions on a horizontal circle or arc at the height of its centre: (nodes, 3).

    Angles from +x toward +y; a 360 deg span is a full circle without a repeated node.
    The paper's measured circle: arc(centre_m=(0, 0, 156.73), radius_m=71.11).
    """
    return _fastcal.arc(
        _point(centre_m, "centre_m"),
        _number(radius_m, "radius_m"),
        _number(start_deg, "start_deg"),
        _number(end_deg, "end_deg"),
        _whole(nodes, "nodes", _INT32_MIN, _INT32_MAX),
    )


def focal_grid(
    max_off_axis_deg: float = 40.0,
    off_axis_step_deg: float = 5.0,
    azimuth_step_deg: float = 15.0,
    focal_centre_m: ArrayLike = (0.0, 0.0, 300.0),
    focal_radius_m: float = 160.0,
) -> np.ndarray:
    """A regular grid on the lower cap of the focal sphere, axis point first: (n, 3)."""
    return _fastcal.focal_grid(
        _number(max_off_axis_deg, "max_off_axis_deg"),
        _number(off_axis_step_deg, "off_axis_step_deg"),
        _number(azimuth_step_deg, "azimuth_step_deg"),
        _point(focal_centre_m, "focal_centre_m"),
        _number(focal_radius_m, "focal_radius_m"),
    )


def random_workspace(
    samples: int = 100,
    max_off_axis_deg: float = 40.0,
    radial_spread_m: float = 0.0,
    seed: int = 0,
    focal_centre_m: ArrayLike = (0.0, 0.0, 300.0),
    focal_radius_m: float = 160.0,
) -> np.ndarray:
    """Positions spread uniformly over the focal sphere's lower cap: (samples, 3).

    Each is moved along the sphere's normal by a uniform offset in +-radial_spread_m.
    The same seed gives the same positions on every platform.
    """
    return _fastcal.random_workspace(
        _whole(samples, "samples", _INT32_MIN, _INT32_MAX),
        _number(max_off_axis_deg, "max_off_axis_deg"),
        _number(radial_spread_m, "radial_spread_m"),
        _whole(seed, "seed", 0, _UINT64_MAX),
        _point(focal_centre_m, "focal_centre_m"),
        _number(focal_radius_m, "focal_radius_m"),
    )


def focal_attitude(
    position_m: ArrayLike,
    tilt_fraction: float = 0.41,
    focal_centre_m: ArrayLike = (0.0, 0.0, 300.0),
) -> np.ndarray:
    """The attitude the focal law prescribes at each position, as quaternions (w, x, y, z).

    The cabin's z' axis is tilted toward the focal-sphere centre by tilt_fraction of the
    off-axis angle (docs/model.md); with the defaults it reproduces the paper's Tables
    3-5. Positions must lie below the focal centre. Shape (n, 4), or (4,) for one (3,)
    position.
    """
    positions, single = _rows(position_m, 3, "position_m")
    centre = _point(focal_centre_m, "focal_centre_m")
    quat = _fastcal.focal_attitude(positions, tilt_fraction, centre)
    return quat[0] if single else quat


def rpy_deg_from_quat(quat: ArrayLike) -> np.ndarray:
    """Roll, pitch, yaw in degrees (pitch in [-90, 90]) of unit quaternions (w, x, y, z)."""
    rows, single = _rows(quat, 4, "quat")
    rpy = _fastcal.rpy_deg_from_quat(rows)
    return rpy[0] if single else rpy


def quat_from_rpy_deg(rpy_deg: ArrayLike) -> np.ndarray:
    """Unit quaternions (w, x, y, z; w >= 0) of roll, pitch, yaw in degrees."""
    rows, single = _rows(rpy_deg, 3, "rpy_deg")
    quat = _fastcal.quat_from_rpy_deg(rows)
    return quat[0] if single else quat


_DICT_COLUMNS = "columns (dict)"
_SPREADSHEET_SUFFIXES = (".xlsx", ".xlsm")
ColumnsLike = Union[PathLike, Mapping[str, Any]]


def _columns_argument(columns: Optional[ColumnsLike]) -> Tuple[str, str]:
    """A column map as (YAML text, name for messages): a file's text, or a dict as JSON
    (which is YAML); ("", "") for none."""
    if columns is None:
        return "", ""
    if isinstance(columns, Mapping):
        return json.dumps(columns, indent=1), _DICT_COLUMNS
    path = os.fspath(columns)
    with open(path, encoding="utf-8") as f:  # FileNotFoundError as open() gives it
        return f.read(), path


def _map_errors(call: Any) -> Any:
    """Runs call(); a dict column map's messages name its key path (a dict has no lines)."""
    try:
        return call()
    except InputError as error:
        message = re.sub(rf"{re.escape(_DICT_COLUMNS)}:\d+: ", f"{_DICT_COLUMNS}: ", str(error))
        raise InputError(message) from None


def _cell_text(value: Any, decimal: str) -> str:
    """A spreadsheet cell as the text a CSV export would hold."""
    import datetime

    if value is None:
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        text = repr(value)
        return text.replace(".", ",") if decimal == "," else text
    if isinstance(value, datetime.datetime):
        return value.isoformat(sep=" ")
    if isinstance(value, (datetime.date, datetime.time)):
        return value.isoformat()
    return str(value)


def _spreadsheet_text(path: str, sheet: Optional[Union[str, int]], decimal: str) -> Tuple[str, str]:
    """The rows of a sheet of an .xlsx workbook as CSV text, one line per sheet row (so
    messages name the sheet's row numbers), and the source name for messages."""
    import csv
    import io

    try:
        import openpyxl
    except ImportError:
        raise ImportError(
            f"{path}: reading an .xlsx workbook needs openpyxl, which is not installed: "
            "apt-get install python3-openpyxl (Debian), or convert the sheet to CSV with "
            f"xlsx2csv {path} export.csv (Debian package xlsx2csv) and read that"
        ) from None
    if not os.path.exists(path):
        raise FileNotFoundError(2, "No such file or directory", path)
    book = openpyxl.load_workbook(path, read_only=True, data_only=True)
    try:
        if sheet is None:
            ws = book.worksheets[0]
        elif isinstance(sheet, int):
            if not 0 <= sheet < len(book.worksheets):
                raise InputError(
                    f"{path}: no sheet {sheet} (the workbook has {len(book.worksheets)}: "
                    f"{', '.join(book.sheetnames)})"
                )
            ws = book.worksheets[sheet]
        else:
            if sheet not in book.sheetnames:
                raise InputError(
                    f"{path}: no sheet {sheet!r} (sheets: {', '.join(book.sheetnames)})"
                )
            ws = book[sheet]
        rows = [list(r) for r in ws.iter_rows(values_only=True)]
        name = ws.title
    finally:
        book.close()
    width = 0
    for r in rows:
        for k in range(len(r) - 1, -1, -1):
            if r[k] is not None:
                width = max(width, k + 1)
                break
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    for r in rows:
        if all(v is None for v in r):
            out.write("\n")  # a blank row stays a (blank) line: row numbers hold
            continue
        cells = [_cell_text(v, decimal) for v in r[:width]]
        cells += [""] * (width - len(cells))
        writer.writerow(cells)
    return out.getvalue(), f"{path}[{name}]"


def read_dataset(
    path: Union[PathLike, Sequence[PathLike]],
    skip_invalid_rows: bool = False,
    columns: Optional[ColumnsLike] = None,
    sheet: Optional[Union[str, int]] = None,
) -> Dataset:
    """Reads telemetry (docs/data-format.md): a canonical CSV, an export through a
    column map, or a sheet of an .xlsx workbook; or several files as one session each.

    Args:
        path: a file, or a list of files (merged, one session per file labelled by its
            name without directory and extension; a file with a `session` column keeps
            its labels; Dataset.session_labels and Dataset.session say which sample is
            whose).
        skip_invalid_rows: leave out a row with a bad value, listed in Dataset.skipped,
            instead of raising.
        columns: a column map (format fastcal-columns-1, docs/data-format.md, "Column
            maps"): its file, or the same content as a dict, e.g.
            {"format": "fastcal-columns-1", "time": {"column": "SysTime", "format":
            "iso8601", "zone": "+08:00"}, "columns": {"x_m": {"column": "X", "unit":
            "mm"}, ...}, "unmapped": "ignore"}. None: the canonical columns.
        sheet: for an .xlsx workbook (read with openpyxl, python3-openpyxl), the sheet's
            name or 0-based index; None: the first. Its rows are read as a CSV export's
            lines (row numbers in messages are the sheet's), with the map's header_line,
            skip_after_header, units and time stamps; date cells are read as dates and
            times in the map's zone.

    Raises InputError naming the file (the sheet), line (row) and column, e.g.
    "data.csv:12: column 'T3_kN': 'abc' is not a number" or, through a map,
    "export.csv:12: column 'CableForce3' (T3_kN, N): 'abc' is not a number"; the map's
    own errors name its key and line; ImportError for an .xlsx without openpyxl.
    """
    if isinstance(path, (str, bytes, os.PathLike)):
        paths = [os.fspath(path)]
    else:
        paths = [os.fspath(p) for p in path]
    map_text, map_source = _columns_argument(columns)
    for p in paths:
        if str(p).lower().endswith((".xls", ".ods")):
            raise InputError(
                f"{p}: an .xls or .ods workbook: save it as .xlsx (read here, with "
                "openpyxl) or export the sheet as CSV"
            )
    spreadsheets = [p for p in paths if str(p).lower().endswith(_SPREADSHEET_SUFFIXES)]
    if spreadsheets:
        if len(paths) > 1:
            raise InputError(
                "read_dataset: a workbook is read on its own; read each and merge as CSV "
                "(Dataset.save), or give CSV files"
            )
        decimal = "."
        if map_text:
            decimal = _map_errors(lambda: _fastcal.column_map_decimal(map_text, map_source))
        text, source = _spreadsheet_text(paths[0], sheet, decimal)
        return _map_errors(
            lambda: _fastcal.parse_dataset(
                text, source, skip_invalid_rows, map_text, map_source, False
            )
        )
    if sheet is not None:
        raise InputError(f"read_dataset: sheet= is for an .xlsx workbook, not {paths[0]}")
    return _map_errors(
        lambda: _fastcal.read_dataset(paths, skip_invalid_rows, map_text, map_source)
    )


def _dataset_from_arrays(
    time_s: ArrayLike,
    position_m: ArrayLike,
    tension_kN: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    planned_rpy_deg: Optional[ArrayLike] = None,
    s0_m: Optional[ArrayLike] = None,
    session: Optional[Sequence[str]] = None,
    skip_invalid_rows: bool = False,
) -> Dataset:
    """A Dataset from numpy arrays, checked as a file is read (docs/data-format.md).

    Args:
        time_s: (n,) seconds (any epoch, or Unix seconds: times >= 1e8 s are shown as
            dates and times, UTC).
        position_m: (n, 3) measured position; tension_kN: (n, 6) measured tensions.
        rpy_deg: (n, 3) measured roll, pitch, yaw (deg), or quat: (n, 4) w, x, y, z;
            one of the two.
        planned_rpy_deg: (n, 3), optional; s0_m: (n, 6) unstretched lengths, optional.
        session: n labels (letters, digits, '-', '_'), optional.
        skip_invalid_rows: leave bad rows out (Dataset.skipped) instead of raising.

    The same checks as the file reader (finite values, plausible positions, angles and
    tensions, unit quaternions, attitudes in radians): a bad value raises InputError
    naming the row (1-based) and the column, "arrays, row 3: column 'T2_kN': -5 kN is
    negative: a tension reading is >= 0". Dataset.line is the 1-based row.
    """
    t = np.asarray(time_s, dtype=np.float64).reshape(-1)
    n = t.shape[0]
    parts: List[Tuple[List[str], np.ndarray]] = [(["time_s"], t.reshape(n, 1))]

    def add(names: List[str], value: Optional[ArrayLike], label: str) -> None:
        if value is None:
            return
        array = np.asarray(value, dtype=np.float64)
        if array.ndim == 1 and len(names) > 1 and array.shape[0] == len(names) and n != len(names):
            array = np.broadcast_to(array, (n, len(names)))
        if array.shape != (n, len(names)):
            raise InputError(
                f"from_arrays: {label} must have shape ({n}, {len(names)}), got {array.shape}"
            )
        parts.append((names, array))

    add(["x_m", "y_m", "z_m"], position_m, "position_m")
    if rpy_deg is not None and quat is not None:
        raise InputError("from_arrays: give rpy_deg or quat, not both")
    if rpy_deg is None and quat is None:
        raise InputError("from_arrays: the measured attitude is needed: rpy_deg or quat")
    add(["roll_deg", "pitch_deg", "yaw_deg"], rpy_deg, "rpy_deg")
    add(["qw", "qx", "qy", "qz"], quat, "quat")
    add(["planned_roll_deg", "planned_pitch_deg", "planned_yaw_deg"], planned_rpy_deg,
        "planned_rpy_deg")
    add([f"T{i}_kN" for i in range(1, 7)], tension_kN, "tension_kN")
    add([f"s0_{i}_m" for i in range(1, 7)], s0_m, "s0_m")
    names = [name for group, _ in parts for name in group]
    values = np.ascontiguousarray(np.hstack([a for _, a in parts]))
    labels = [] if session is None else [str(s) for s in session]
    text = _fastcal.canonical_text(names, values, labels)
    return _fastcal.parse_dataset(text, "arrays", skip_invalid_rows, "", "", True)


def _dataset_from_dataframe(
    df: Any, columns: Optional[ColumnsLike] = None, skip_invalid_rows: bool = False
) -> Dataset:
    """A Dataset from a pandas DataFrame, checked as a file is read.

    Without `columns` the DataFrame's columns are fastcal's (time_s, x_m, ..., T6_kN,
    optionally session, docs/data-format.md); with a column map (a file or a dict,
    read_dataset) they are the export's, named and converted by the map (its
    header_line, skip_after_header and decimal do not apply: a DataFrame has its names
    and its numbers). Datetime columns are read as dates and times (the map's zone when
    they have none). Messages name the row (1-based, in the DataFrame's order) and the
    column: "DataFrame, row 3: column 'CableForce2' (T2_kN, N): ...".
    """
    map_text, map_source = _columns_argument(columns)
    frame = df.reset_index(drop=True) if hasattr(df, "reset_index") else df
    try:
        text = frame.to_csv(index=False, lineterminator="\n")
    except TypeError:  # pandas before 1.5
        text = frame.to_csv(index=False, line_terminator="\n")
    return _map_errors(
        lambda: _fastcal.parse_dataset(
            text, "DataFrame", skip_invalid_rows, map_text, map_source, True
        )
    )


Dataset.from_arrays = staticmethod(_dataset_from_arrays)  # type: ignore[attr-defined]
Dataset.from_dataframe = staticmethod(_dataset_from_dataframe)  # type: ignore[attr-defined]


# simulate()'s keywords: the command line's flags (--attitude-control-deg:
# attitude_control_deg), each with the SimulationOptions field it sets where the two differ.
_SIMULATE_OPTION_FIELDS = {
    "attitude_control_deg": "attitude_control_sigma_deg",
    "attitude_noise_deg": "attitude_measurement_sigma_deg",
    "position_noise_m": "position_measurement_sigma_m",
    "tension_noise_kN": "tension_noise_kn",
    "sensor_bias_spread_kN": "sensor_bias_spread_kn",
    "interval_s": "sample_interval_s",
}
_SIMULATE_OPTIONS = sorted(
    list(_SIMULATE_OPTION_FIELDS)
    + [
        "attitude_control_time_s",
        "density_mismatch_percent",
        "length_noise_m",
        "length_offset_spread_m",
        "mass_centre_drift_m",
        "mass_centre_drift_time_s",
        "mass_centre_steps",
        "method",
        "outlier_fraction",
        "outlier_scale_percent",
        "seed",
        "sensor_bias_steps",
        "sensor_gain_spread_percent",
        "session_gap_s",
        "sessions",
        "start_time_s",
        "tension_drift_percent",
        "tension_drift_time_s",
        "tension_noise_percent",
    ]
)


def _simulation_fields(options: Mapping[str, Any]) -> Dict[str, Any]:
    """simulate()'s keywords as the library's fields; a former name (the field's) with a
    DeprecationWarning, an unknown one refused with the closest names."""
    old_names = {field: keyword for keyword, field in _SIMULATE_OPTION_FIELDS.items()}
    fields: Dict[str, Any] = {}
    for name, value in options.items():
        if name in old_names:
            warnings.warn(
                f"simulate({name}=...) is deprecated: use {old_names[name]}= (the command "
                f"line's --{old_names[name].replace('_', '-')})",
                DeprecationWarning,
                stacklevel=3,
            )
            name = old_names[name]
        if name not in _SIMULATE_OPTIONS:
            close = difflib.get_close_matches(name, _SIMULATE_OPTIONS, n=3)
            guess = f"; did you mean {' or '.join(close)}?" if close else ""
            raise InputError(f"simulate: unknown option '{name}'{guess} (accepted: " +
                             ", ".join(_SIMULATE_OPTIONS) + ")")
        fields[_SIMULATE_OPTION_FIELDS.get(name, name)] = value
    return fields


def simulate(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    model: Optional[Model] = None,
    **options: Any,
) -> Tuple[Dataset, Model, Dict[str, Any]]:
    """Synthetic telemetry from a known ("truth") model at planned poses.

    The planned poses are positions (n, 3) with an attitude as in solve(). Options are
    `fastcal simulate`'s flags (docs/cli.md), with underscores:
    tension_noise_percent (3), tension_noise_kN, outlier_fraction,
    outlier_scale_percent, attitude_control_deg, attitude_control_time_s,
    attitude_noise_deg, position_noise_m, tension_drift_percent, tension_drift_time_s,
    mass_centre_drift_m, mass_centre_drift_time_s, sensor_gain_spread_percent,
    sensor_bias_spread_kN, density_mismatch_percent, length_offset_spread_m and
    length_noise_m (the s0 columns: encoder offsets drawn once, written into the truth
    model, and reading noise), interval_s (1), seed (1),
    method ('exact'), sessions (1: the samples cut into that many consecutive sessions,
    labelled 1..N), mass_centre_steps ([(time_s, (dx, dy, dz)), ...]: the mass centre
    moves by the shift at that time and stays), start_time_s (0: the first sample's
    time, e.g. a Unix time), session_gap_s (0: time between sessions; 86400 - a day's
    span makes a session a day), sensor_bias_steps ([(time_s, cable 1..6, shift_kN),
    ...]: one sensor re-zeroed). The former names, SimulationOptions' fields
    (attitude_control_sigma_deg, tension_noise_kn, sample_interval_s, ...), still work
    with a DeprecationWarning.

    Returns:
        (dataset, truth_used, summary): the telemetry, the truth model after the drawn
        per-cable mismatches (the one the tensions come from), and what was added
        (noise RMS per cable in kN, outliers, ...).
    """
    positions, _ = _rows(position_m, 3, "position_m")
    kind, attitude = _attitude(positions.shape[0], rpy_deg, quat)
    truth = model if model is not None else Model.nominal()
    fields = _simulation_fields(options)
    if "seed" in fields:
        fields["seed"] = _whole(fields["seed"], "seed", 0, _UINT64_MAX)
    if "sessions" in fields:
        fields["sessions"] = _whole(fields["sessions"], "sessions", 1, _INT32_MAX)
    for key, value in fields.items():
        if key not in ("seed", "sessions", "method", "mass_centre_steps", "sensor_bias_steps"):
            fields[key] = _number(value, key)
    return _call_with_names(
        _SIMULATE_OPTION_FIELDS, _fastcal.simulate, truth, positions, kind, attitude, fields
    )


class CalibrationResult:
    """What fastcal.calibrate found (docs/calibration.md explains each part).

    Attributes:
        parameters: one dict per parameter the spec names, in spec order: name, unit,
            free, consider, initial, estimate, sigma (formal: stated noise, independent
            samples), sigma_total (the uncertainty to quote) with its parts
            sigma_statistical (the formal one widened by misfit and time-correlated
            residuals; widening = their ratio; tau) and sigma_systematic (from consider
            parameters; systematic_by_group), prior_mean, prior_sigma (None without a
            prior), note. Values in the spec's units (kN for sensor biases).
        estimates: name -> estimate, every parameter the spec names.
        sigma, sigma_total: name -> formal and total standard deviation, free ones.
        free_names: the free parameters, in the order of `correlation`'s rows.
        correlation: correlation matrix of the free estimates (total covariance), (k, k).
        outliers: the gross errors kept out of the fit, in file order: dicts of line,
            cable (1-6), reading ('tension', or 'length' with the lengths in the fit),
            measured_kN and predicted_kN (a length: measured_m, predicted_m),
            residual_sigma, held_out.
        lengths: with the lengths in the fit (spec noise.length_sigma_m), a dict of
            sigma_m and per cable (6,) initial_rms_m, calibrated_rms_m,
            calibrated_mean_m (model minus measured); None without.
        worst_readings: the fitted readings with the largest |residual| / sigma.
        misfit_ranking: fixed parameters by the chi-square decrease freeing each would
            bring (name, expected_chi_square_decrease, significant); misfit_threshold
            is what white noise alone reaches.
        rms_kN: variant -> RMS of model minus measured per cable, (6,), on the fitted
            samples: the initial model at each attitude the data has, and the
            calibrated one (the paper's Table 6). holdout_rms_kN: the same on the
            held-out samples (variants with some). cross_validation_rms_kN: the block
            cross-validation's, or None.
        evaluation: variant -> the full statistics (fit, holdout: samples, rms_kN,
            mean_kN, max_abs_kN, rms_percent, max_abs_percent) and predicted_kN (n, 6).
        verdict: 'ok', 'noise overstated', 'misfit' or 'failed'; verdict_text says why.
        reduced_chi_square, converged, iterations, termination, notes,
        strong_correlations, budget (dict), seconds.
        model: the calibrated Model.
        held_out: per sample, held out of the fit (list of bool).
        gross_error_mask: per sample and cable, a reading kept out, (n, 6) bool.
        sessions: a joint fit's session labels (spec sessions.separate), else empty;
            session_models: label -> the calibrated Model of that session;
            session_differences: each separate parameter's change between consecutive
            sessions, dicts of name, unit, from, to, difference, sigma_total.
        change_scan: the scan (spec change_scan) as a dict (parameters, time_s,
            statistic, threshold, significance, widening, min_segment_samples), or None;
            changes: the changes found, dicts of time_s, line, sample, statistic,
            p_value, shifts and shift_sigmas (name -> value, later minus earlier).
    """

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.parameters: List[Dict[str, Any]] = raw["parameters"]
        self.estimates: Dict[str, float] = {p["name"]: p["estimate"] for p in self.parameters}
        free = [p for p in self.parameters if p["free"]]
        self.sigma: Dict[str, float] = {p["name"]: p["sigma"] for p in free}
        self.sigma_total: Dict[str, float] = {p["name"]: p["sigma_total"] for p in free}
        self.free_names: List[str] = raw["free_names"]
        self.correlation: np.ndarray = raw["correlation"]
        self.outliers: List[Dict[str, Any]] = raw["outliers"]
        self.worst_readings: List[Dict[str, Any]] = raw["worst_readings"]
        self.misfit_ranking: List[Dict[str, Any]] = raw["misfit_ranking"]
        self.misfit_threshold: float = raw["misfit_threshold"]
        self.evaluation: Dict[str, Dict[str, Any]] = raw["evaluation"]
        self.rms_kN: Dict[str, np.ndarray] = {
            name: v["fit"]["rms_kN"] for name, v in self.evaluation.items()
        }
        self.holdout_rms_kN: Dict[str, np.ndarray] = {
            name: v["holdout"]["rms_kN"]
            for name, v in self.evaluation.items()
            if v["holdout"] is not None
        }
        self.cross_validation_rms_kN: Optional[np.ndarray] = raw["cross_validation_rms_kN"]
        self.lengths: Optional[Dict[str, Any]] = raw["lengths"]
        self.verdict: str = raw["verdict"]
        self.verdict_text: str = raw["verdict_text"]
        self.notes: List[str] = raw["notes"]
        self.strong_correlations: List[str] = raw["strong_correlations"]
        self.budget: Dict[str, Any] = raw["budget"]
        self.model: Model = raw["model"]
        self.held_out: List[bool] = raw["held_out"]
        self.gross_error_mask: np.ndarray = raw["gross_error_mask"]
        self.reduced_chi_square: float = raw["reduced_chi_square"]
        self.converged: bool = raw["converged"]
        self.iterations: int = raw["iterations"]
        self.termination: str = raw["termination"]
        self.num_residuals: int = raw["num_residuals"]
        self.num_fit_samples: int = raw["num_fit_samples"]
        self.seconds: float = raw["seconds"]
        self.ceres_report: str = raw["ceres_report"]
        self.sessions: List[str] = raw["sessions"]
        self.session_models: Dict[str, Model] = raw["session_models"]
        self.session_differences: List[Dict[str, Any]] = raw["session_differences"]
        self.change_scan: Optional[Dict[str, Any]] = raw["change_scan"]
        self.changes: List[Dict[str, Any]] = raw["changes"]

    def __repr__(self) -> str:
        shown = ", ".join(
            f"{name} = {self.estimates[name]:.6g} +- {self.sigma_total[name]:.2g}"
            for name in self.free_names
        )
        return f"<fastcal.CalibrationResult: {self.verdict}; {shown}>"


_DICT_SPEC = "spec (dict)"


def _spec_argument(spec: Union[PathLike, Mapping[str, Any]]) -> Tuple[str, bool, str]:
    """A spec file's path, or a dict as YAML text (JSON is YAML) with a name for messages."""
    if isinstance(spec, Mapping):
        return json.dumps(spec), True, _DICT_SPEC
    return os.fspath(spec), False, os.fspath(spec)


def calibrate(
    spec: Union[PathLike, Mapping[str, Any]],
    data: Union[Dataset, PathLike],
    model: Optional[Union[Model, PathLike]] = None,
) -> CalibrationResult:
    """Estimates model parameters from measured poses and tensions (docs/calibration.md).

    What `fastcal calibrate` does, without writing files: the fit, its uncertainty
    budget, gross errors, the misfit ranking, and the RMS tables of the initial and the
    calibrated model (exact statics).

    Args:
        spec: a calibration spec file, or the same content as a dict, e.g.
            {"format": "fastcal-calibration-spec-1",
             "parameters": {"mass_centre_m": {"x": {"free": True}, "y": {"free": True}}}}.
        data: a Dataset, or the path of a telemetry CSV.
        model: the starting model (a Model or a model file); None for Model.nominal().

    Returns:
        A CalibrationResult. A fit whose verdict is 'failed' is returned, with a
        RuntimeWarning, as the command line writes it with a warning.

    Raises:
        InputError: a bad spec, dataset or model file (file, line, key named).
        CalibrationError: refused or failed; `status` is 'undetermined' (the data cannot
            determine the free set: the message names the combination), 'infeasible' (the
            model cannot hold a sample's pose: the line is named), 'solver failed' or
            'mostly gross errors'.
    """
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        model = Model.load(os.fspath(model))
    if not isinstance(data, Dataset):
        data = read_dataset(data)
    spec_text, is_text, source = _spec_argument(spec)
    try:
        raw = _fastcal.calibrate(model, spec_text, is_text, source, data)
    except InputError as error:
        # A dict has no lines: its messages name the key path alone.
        message = re.sub(rf"^{re.escape(_DICT_SPEC)}:\d+: ", f"{_DICT_SPEC}: ", str(error))
        raise InputError(message) from None
    result = CalibrationResult(raw)
    if result.verdict == "failed":
        warnings.warn(f"the fit failed: {result.verdict_text}", RuntimeWarning, stacklevel=2)
    return result


def evaluate(
    data: Union[Dataset, PathLike],
    model: Optional[Union[Model, PathLike]] = None,
    method: str = "exact",
) -> Dict[str, Dict[str, Any]]:
    """Model minus measured tension statistics per cable, as `fastcal evaluate` prints.

    Returns:
        variant -> statistics, for 'model, planned attitude' (when the data has it) and
        'model, measured attitude': {'fit': {'samples', 'rms_kN', 'mean_kN',
        'max_abs_kN', 'rms_percent', 'max_abs_percent', 'excluded'}, 'holdout': None,
        'predicted_kN': (n, 6)}. The model's sensor gains and biases are applied.

    Raises:
        InputError: a bad file or method. CalibrationError ('infeasible'): the model
        cannot hold a sample's pose (its line is named).
    """
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        model = Model.load(os.fspath(model))
    if not isinstance(data, Dataset):
        data = read_dataset(data)
    return _fastcal.evaluate(model, data, method)


@_renamed_keywords({"sample_interval_s": "interval_s"})
def design(
    spec: Union[PathLike, Mapping[str, Any]],
    samples: int,
    model: Optional[Union[Model, PathLike]] = None,
    *,
    max_extra_tilt_deg: float = 0.0,
    max_extra_yaw_deg: float = 0.0,
    criterion: str = "A",
    parameters: Sequence[str] = (),
    seed: int = 1,
    speed_m_per_s: float = 0.0,
    interval_s: float = 1.0,
    minutes: float = 0.0,
    min_tension_kN: Optional[float] = None,
    max_tension_kN: Optional[float] = None,
    reflector_clearance_m: Optional[float] = None,
    max_off_axis_deg: Optional[float] = None,
    off_axis_step_deg: Optional[float] = None,
    azimuth_step_deg: Optional[float] = None,
) -> Dict[str, Any]:
    """Designs a calibration survey, as `fastcal design` does without writing files.

    Chooses `samples` samples among the feasible poses of the focal-sphere cap (with
    attitudes up to max_extra_tilt_deg tilted and max_extra_yaw_deg turned off the focal
    law) so that a calibration with `spec` determines the wanted parameters best, and
    orders them into a short path (docs/design.md).

    Args:
        spec: a calibration spec file, or the same content as a dict (see calibrate).
        samples: the survey's samples (at least the spec's free parameters).
        model: the model (a Model or a model file); None for Model.nominal().
        criterion: 'A' (sum of the wanted variances) or 'D' (their log-determinant).
        parameters: the wanted parameters; empty: the free ones without a prior.
        seed: draws the random survey the design is compared with.
        speed_m_per_s, interval_s: the path's duration (cabin speed, time per sample);
            minutes: a time budget (needs a speed). (interval_s was sample_interval_s:
            the old name still works, with a DeprecationWarning.)
        min_tension_kN, max_tension_kN, reflector_clearance_m: the candidates' limits;
            None: the design's defaults (50 kN, none, 5 m).
        max_off_axis_deg, off_axis_step_deg, azimuth_step_deg: the grid; None: the
            workspace's (40, 1, 5 deg).

    Returns:
        A dict: 'poses', a (samples, 6) array of x_m, y_m, z_m, roll_deg, pitch_deg,
        yaw_deg in flight order (what poses.csv holds); 'stops' (dicts: samples,
        position_m, extra_tilt_deg, tilt_direction_deg, extra_yaw_deg); 'wanted';
        'design', 'circle', 'random': {'ok', 'note', 'criterion', 'sigma_total':
        {name: value}}; 'units' ({name: unit}); 'path_length_m', 'duration_s' (nan
        without a speed), 'candidates', 'rejected_candidates', 'limiting_part',
        'limiting_share', 'prior_halved' ({group: {wanted name: sigma_total with its
        sigma halved}}). Every sigma is in its parameter's unit, the one its name
        carries and the spec's (sensor_bias_kN[1] in kN), as calibrate() reports it.

    Raises:
        InputError: a bad spec or option, nothing free, fewer samples than free
            parameters, no feasible candidate, an infeasible time budget.
    """
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        model = Model.load(os.fspath(model))
    spec_text, is_text, source = _spec_argument(spec)
    options = {
        "samples": _whole(samples, "samples", 1, _INT32_MAX),
        "max_extra_tilt_deg": _number(max_extra_tilt_deg, "max_extra_tilt_deg"),
        "max_extra_yaw_deg": _number(max_extra_yaw_deg, "max_extra_yaw_deg"),
        "criterion": str(criterion).upper(),
        "parameters": [str(p) for p in parameters],
        "seed": _whole(seed, "seed", 0, _UINT64_MAX),
        "speed_m_per_s": _number(speed_m_per_s, "speed_m_per_s"),
        "sample_interval_s": _number(interval_s, "interval_s"),
        "time_budget_s": 60.0 * _number(minutes, "minutes"),
    }
    for key, value in (
        ("min_tension_kN", min_tension_kN),
        ("max_tension_kN", max_tension_kN),
        ("reflector_clearance_m", reflector_clearance_m),
        ("max_off_axis_deg", max_off_axis_deg),
        ("off_axis_step_deg", off_axis_step_deg),
        ("azimuth_step_deg", azimuth_step_deg),
    ):
        options[key] = None if value is None else _number(value, key)
    try:
        return _fastcal.design(model, spec_text, is_text, source, options)
    except InputError as error:
        message = re.sub(rf"^{re.escape(_DICT_SPEC)}:\d+: ", f"{_DICT_SPEC}: ", str(error))
        raise InputError(message) from None


class TrackResult:
    """What fastcal.track found, as it wrote it in `out` (docs/calibration.md, "Tracking").

    Attributes:
        out: the track's directory (track.csv, events.json, track.html,
            model_calibrated@WINDOW.yaml, and the state an update reads).
        windows: one dict per window in time order: label, start_s, end_s (its bounds),
            first_time_s, last_time_s, samples, readings, gross_errors,
            reduced_chi_square, widening, folded (in this run), estimates (name ->
            {value, sigma_total, sigma_formal}, in the spec's units) and
            sensor_offset_kN (cable 1..6 -> the same, when the biases are shared).
        events: dicts of kind ('parameter' or 'sensor'), time_s (the first sample after
            the change: the later window's first, or its block's inside a window),
            after_s (the last before), time_low_s and time_high_s (its likelihood
            interval), window, previous_window, within_window,
            parameters (name -> {shift, sigma_total, unit}), cables (for a sensor),
            statistic, degrees_of_freedom, threshold, p_value (family-wise).
        wander: per per-window group, its wander between windows beyond its errors
            (parameters, rms per component, unit; rms 0: none seen): the parameter
            events are steps beyond it.
        shared: the shared parameters (name, unit, estimate {value, sigma_total,
            sigma_formal}, from_window, to_window: a re-zeroed sensor's bias has one entry
            per stretch).
        window_parameters: the per-window parameters' names; files: the data files;
        models: the model files written; slow_error: what the slow error was found to be;
        samples, reduced_chi_square, iterations, converged, folds (computed in this
        run), updated (an existing track was updated), notes.
    """

    def __init__(self, raw: Dict[str, Any], out: str) -> None:
        self.out: str = out
        self.windows: List[Dict[str, Any]] = raw["windows"]
        self.events: List[Dict[str, Any]] = raw["events"]
        self.wander: List[Dict[str, Any]] = raw["wander"]
        self.shared: List[Dict[str, Any]] = raw["shared"]
        self.window_parameters: List[str] = raw["window_parameters"]
        self.files: List[str] = raw["files"]
        self.window: str = raw["window"]
        self.models: List[str] = raw["models"]
        self.slow_error: str = raw["slow_error"]
        self.samples: int = raw["samples"]
        self.reduced_chi_square: float = raw["reduced_chi_square"]
        self.iterations: int = raw["iterations"]
        self.converged: bool = raw["converged"]
        self.folds: int = raw["folds"]
        self.updated: bool = raw["updated"]
        self.notes: List[str] = raw["notes"]

    def estimates(self, name: str) -> Tuple[np.ndarray, np.ndarray]:
        """A per-window parameter's estimates and sigma_total over the windows, (n,) each."""
        if name not in self.window_parameters:
            raise InputError(f"{name} is not a per-window parameter ({self.window_parameters})")
        values = np.array([w["estimates"][name]["value"] for w in self.windows])
        sigmas = np.array([w["estimates"][name]["sigma_total"] for w in self.windows])
        return values, sigmas

    def __repr__(self) -> str:
        return (
            f"<fastcal.TrackResult: {len(self.windows)} windows of {self.window}, "
            f"{len(self.events)} events, in {self.out}>"
        )


def _fold_task(task: bytes) -> bytes:
    """One window's fold (track_fold.h): what a Dask worker runs, without the GIL."""
    return _fastcal.fold_task(task)


def _dask_client(client: Any) -> Any:
    """A dask.distributed.Client: the one given, or one connected to a scheduler address."""
    if not isinstance(client, str):
        return client
    try:
        from dask.distributed import Client
    except ImportError as error:
        raise ImportError(
            "fastcal.track(client=...) needs dask.distributed: install the Debian packages "
            "python3-dask and python3-distributed (scripts/setup.sh does)"
        ) from error
    return Client(client)


def track(
    data: Union[PathLike, Sequence[PathLike]],
    spec: Union[PathLike, Mapping[str, Any]],
    out: PathLike,
    window: str = "1d",
    client: Any = None,
    model: Optional[Union[Model, PathLike]] = None,
    threads: int = 2,
    refold: bool = False,
    force: bool = False,
    columns: Optional[ColumnsLike] = None,
) -> TrackResult:
    """The mass centre and the sensors through a season of telemetry (`fastcal track`).

    The data are cut into windows (calendar days in UTC by default), each window folded
    at a linearisation point into its information over its own parameters (the spec's
    sessions.separate groups) and the shared ones, and the joint fit solved by the Schur
    complement; the events between windows (a moved mass centre, a re-zeroed sensor) are
    tested at a 1% false-alarm rate over the whole track. Writes track.csv, events.json,
    track.html and the models in `out`, as the command line does, and returns them.

    Args:
        data: a telemetry file, a directory (its *.csv files), or a list of files; the
            times absolute (Unix seconds, or ISO 8601 through a column map).
        spec: a calibration spec file or dict (calibration_data/spec_track.yaml).
        out: the track's directory: new or empty, or a track built before, then updated
            with the files it does not hold yet (only the windows that gained samples are
            folded).
        window: "1d", "12h", "30m", "3600s", ... or "file" (one window per file).
        client: None to fold on this machine's threads, or a dask.distributed.Client (a
            LocalCluster's, or one connected to a scheduler) or a scheduler's address
            ("tcp://host:8786"): each window's fold is then a task on the workers, which
            must see `out` and the data at the same paths. The numbers are the same.
        model: the starting model (a Model or a model file); None for Model.nominal().
        threads: windows folded at once without a client.
        refold: on an update, refold every window (as a fresh track would).
        force: `out` holds a track of another model, spec or windowing: build it afresh.
        columns: a column map (a file or a dict, as read_dataset takes) through which
            every data file is read: an export as it comes, ISO 8601 times included.

    Raises:
        InputError: bad data, spec, window or directory. CalibrationError: a pose the
        model cannot solve ('infeasible'), parameters the windows cannot determine
        ('undetermined'), or a failed fold runner ('failed').
    """
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        model = Model.load(os.fspath(model))
    if isinstance(data, (str, os.PathLike)):
        paths = [os.fspath(data)]
    else:
        paths = [os.fspath(p) for p in data]
    spec_text, is_text, source = _spec_argument(spec)
    fold_many = None
    if client is not None:
        dask_client = _dask_client(client)

        def fold_many(tasks: List[bytes]) -> List[bytes]:
            futures = dask_client.map(_fold_task, tasks, pure=False)
            return dask_client.gather(futures)

    map_text, map_source = _columns_argument(columns)
    raw = _map_errors(
        lambda: _fastcal.track(
            model, spec_text, is_text, source, paths, os.fspath(out), window, threads, refold,
            force, map_text, map_source, fold_many,
        )
    )
    return TrackResult(raw, os.fspath(out))
