"""The control cycle: at planned poses, the winch lengths to command and the expected
tensions, with the model's checks and the installation's limits (fastcal/control_cycle.h;
the same call as the C interface's fastcal_control_cycle, docs/embedding.md)."""

from __future__ import annotations

import math
from typing import Any, Dict, List, Optional

import numpy as np

from . import _fastcal
from ._fastcal import InputError, Model

from ._common import ArrayLike, _STATUS_NAMES_ARRAY, _attitude, _number, _rows

CONTROL_STATUS_NAMES: List[str] = _fastcal.control_status_names()
"""A cycle's outcome by code: 'ok', 'statics_failed', 'below_min_tension',
'above_max_tension', 'inside_reflector_margin'."""
_CONTROL_NAMES_ARRAY = np.array(CONTROL_STATUS_NAMES, dtype=object)


class ControlCycleResult:
    """What the winches and sensors should show at one planned pose or n (fastcal.control_cycle).

    For n poses each array has a leading axis of n; for one pose none, and `status`, `ok`
    and `cable` are scalars. Cable i is at index i-1.

    Attributes:
        winch_length_m: the winch encoders' readings to command, s0 + the model's
            length_offset_m, (n, 6).
        s0_m: the model's unstretched lengths, (n, 6).
        tension_kN: the true lower-end (cabin) tensions, (n, 6); sensor_reading_kN what the
            tension sensors should read (the model's gains and biases), upper_tension_kN
            at the tower tops.
        error_estimate_pct: the statics' relative tension error estimate, percent.
        reflector_clearance_m: the smallest cable clearance from the reflector (inf: none
            could reach it).
        min_tension_margin_kN: min over cables of tension - min_tension_kN;
            max_tension_margin_kN: min over cables of max_tension_kN - max(lower, upper).
        status: 'ok', a limit ('below_min_tension', 'above_max_tension',
            'inside_reflector_margin': the numbers are there, the controller decides), or
            the statics' failure ('no_equilibrium', 'sagging_cable', ...: the numbers NaN).
        ok: status == 'ok'. cable: the 1-based cable concerned, 0 when none.
    """

    def __init__(self, raw: Dict[str, Any], single: bool) -> None:
        control = raw["control_status_code"]
        statics = _STATUS_NAMES_ARRAY[raw["statics_status_code"]]
        status = np.where(control == 1, statics, _CONTROL_NAMES_ARRAY[control])
        pick = (lambda a: a[0]) if single else (lambda a: a)
        self._single = single
        self.winch_length_m: np.ndarray = pick(raw["winch_length_m"])
        self.s0_m: np.ndarray = pick(raw["s0_m"])
        self.tension_kN: np.ndarray = pick(raw["tension_kN"])
        self.sensor_reading_kN: np.ndarray = pick(raw["sensor_reading_kN"])
        self.upper_tension_kN: np.ndarray = pick(raw["upper_tension_kN"])
        self.error_estimate_pct = pick(100.0 * raw["error_estimate"])
        self.reflector_clearance_m = pick(raw["reflector_clearance_m"])
        self.min_tension_margin_kN = pick(raw["min_tension_margin_kN"])
        self.max_tension_margin_kN = pick(raw["max_tension_margin_kN"])
        self.status = pick(status.astype(object))
        self.ok = pick(control == 0)
        self.cable = pick(raw["cable"] + 1)

    def __len__(self) -> int:
        return 1 if self._single else len(self.ok)

    def __repr__(self) -> str:
        n = len(self)
        bad = n - int(np.sum(self.ok))
        return f"<fastcal.ControlCycleResult: {n} pose{'s' if n != 1 else ''}, {bad} not ok>"


def control_cycle(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    joints: Optional[ArrayLike] = None,
    model: Optional[Model] = None,
    *,
    min_tension_kN: float = 50.0,
    max_tension_kN: float = math.inf,
    min_reflector_clearance_m: float = 5.0,
) -> ControlCycleResult:
    """The winch lengths to command and the tensions to expect at planned poses.

    Each pose is solved by the exact statics warm from the one before (a trajectory in
    order), then checked against the model's range (strain, sag, reflector contact) and
    the limits below. The same computation as the C interface's fastcal_control_cycle.

    Args:
        position_m: the planned cabin position(s), global frame: (3,) or (n, 3); with
            the attitude, the model's measured frame's pose where it declares one
            (Model.measured_frame), the cabin's following from the joints.
        rpy_deg, quat: the planned attitude(s), as fastcal.solve takes them.
        joints: the moving parts' values (Model.joint_columns order and units: deg, m):
            (J,) for every pose or (n, J); None for all at zero. Each within the range
            the model states for its joint, as the C interface and the command line check.
        model: the model (e.g. a calibration's); None for Model.nominal().
        min_tension_kN: every lower-end tension at least this (default 50 kN: the survey
            design's margin; below it a sagging cable's length is uncertain by metres).
        max_tension_kN: every tension at most this: the cables' rated load (default inf:
            the model states none, only its max_strain applies).
        min_reflector_clearance_m: every cable at least this far from the reflector
            (default 5 m).

    Returns:
        A ControlCycleResult. Poses that break a limit or the statics are marked in
        `status`, not raised.

    Raises:
        InputError: a wrong shape, limits out of range (named), joints for a model
            without moving parts, a joint beyond one turn (or 100 m) or outside the range
            the model states for it (named with its row and column).
    """
    positions, single = _rows(position_m, 3, "position_m")
    n = positions.shape[0]
    kind, attitude = _attitude(n, rpy_deg, quat)
    model = model if model is not None else Model.nominal()
    joint_array = np.zeros((0,)) if joints is None else np.asarray(joints, dtype=np.float64)
    raw = _fastcal.control_cycle(
        model,
        positions,
        kind,
        attitude,
        np.ascontiguousarray(joint_array),
        _number(min_tension_kN, "min_tension_kN"),
        _number(max_tension_kN, "max_tension_kN"),
        _number(min_reflector_clearance_m, "min_reflector_clearance_m"),
    )
    return ControlCycleResult(raw, single)
