"""Statics: solve (the inverse statics), locate (the forward statics), trajectories and attitudes."""

from __future__ import annotations

import warnings
from typing import Any, Dict, List, Mapping, Optional, Union

import numpy as np

from . import _fastcal
from ._fastcal import Cable, InputError, Model  # noqa: F401  (Cable: one cable, cable.h)

from ._common import ArrayLike, PathLike, _INT32_MAX, _INT32_MIN, _SOLVE_OPTION_FIELDS, _STATUS_NAMES_ARRAY, _UINT64_MAX, _attitude, _call_with_names, _number, _point, _renamed_keywords, _rows, _spec_argument, _whole


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
        error_estimate_pct: per pose, the relative tension error those misses imply, in
            percent as the command line's error_estimate_pct, (n,): the check behind
            every 'ok' (docs/model.md, "Checks and statuses"). (error_estimate, the same
            as a fraction, is deprecated.)

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
        self.error_estimate_pct = pick(100.0 * raw["error_estimate"])
        self._error_fraction = pick(raw["error_estimate"])
        self.status = pick(status)
        self.ok = pick(codes == 0)
        self.cable = pick(raw["cable"] + 1)

    @property
    def error_estimate(self) -> Any:
        """Deprecated: error_estimate_pct / 100 (the command line's name and unit)."""
        warnings.warn("StaticsResult.error_estimate (a fraction) is now error_estimate_pct "
                      "(percent), as the command line's column", DeprecationWarning,
                      stacklevel=2)
        return self._error_fraction

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
    joints: Optional[ArrayLike] = None,
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
        position_m: position of the cabin-frame origin, global frame: (3,) or (n, 3); of
            the model's measured frame's point where it declares one (Model.measured_frame:
            the data's frame, e.g. the feed's phase centre), the cabin's pose then
            following from the joints.
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
        joints: the moving parts' values (Model.joint_columns order and units: deg, m):
            (J,) for every pose or (n, J); None: all at zero. They move the mass centre and,
            with a measured frame on a part, the cabin's pose under the given one.
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
        _joint_array(joints),
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
        position_m: the cabin-frame origin, global frame, (n, 3); the measured frame's
            point where the model declares one (Model.measured_frame), as the data give it.
        quat: the attitude as unit quaternions (w, x, y, z), (n, 4); rpy_deg the same as
            roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll), (n, 3). The measured frame's
            where the model declares one.
        cabin_position_m, cabin_quat: the cabin's own pose (equal to the above without a
            measured frame).
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
        covariance: of (position_m (m), rotation vector (rad, global axes)), (n, 6, 6);
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
        self.cabin_position_m: np.ndarray = pick(raw["cabin_position_m"])
        self.cabin_quat: np.ndarray = pick(raw["cabin_quat"])
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
    joints: Optional[ArrayLike] = None,
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
        joints: the moving parts' values per row ((J,) for all or (n, J); None: zero), as
            solve(): the mass centre there; a measured attitude and the answers are the
            model's measured frame's where it declares one.
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
        _joint_array(joints),
    )
    return LocateResult(raw, single)


def _joint_array(joints: Optional[ArrayLike]) -> np.ndarray:
    """The joints for the C++ side: an empty array for None (all at zero)."""
    array = np.zeros((0,)) if joints is None else np.asarray(joints, dtype=np.float64)
    return np.ascontiguousarray(array)


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
