"""The dynamics layer: the natural frequencies and modes of the cabin on its six sagging
cables at one pose (the C++ library's modes.h; docs/model.md, "Vibrations"), and the
cabin and its cables moving in time beside the quasi-static answer (dynamics_run.h;
docs/model.md, "Dynamics"), and the cabin in its control loop (closed_loop.h;
docs/model.md, "The closed loop")."""

from __future__ import annotations

import os
from dataclasses import dataclass
import json
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _fastcal
from ._common import PathLike, _whole
from ._fastcal import InputError, Model

ArrayLike = Union[np.ndarray, Sequence[float]]

#: The cabin's motions, in the order of ModesResult.shares' first six columns.
CABIN_MOTIONS = ("x", "y", "z", "rx", "ry", "rz")


@dataclass(frozen=True)
class ModesResult:
    """The lowest modes of one pose, ascending in frequency.

    Attributes:
        frequency_hz: (m,) natural frequencies.
        shares: (m, 7) each mode's kinetic energy split into the cabin's translation of its
            mass centre along x, y, z, its rotation about the global x, y, z, and the six
            cables together; each row sums to 1.
        cable_share: (m, 6) each cable's share (their sum is shares[:, 6]).
        dominant_cable: (m,) the cable (1-6) with the largest share.
        cabin_shape: (m, 6) the cabin's part of each mode shape, (u (m), theta (rad)) in
            global axes, M-normalised over the whole system (sign arbitrary).
        degrees_of_freedom: of the eigenproblem solved.
    """

    frequency_hz: np.ndarray
    shares: np.ndarray
    cable_share: np.ndarray
    dominant_cable: np.ndarray
    cabin_shape: np.ndarray
    degrees_of_freedom: int

    @property
    def cabin_share(self) -> np.ndarray:
        """(m,) the cabin's share of each mode's kinetic energy."""
        return self.shares[:, :6].sum(axis=1)


def _pose_arrays(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike],
    quat: Optional[ArrayLike],
    attitude_law: Optional[str],
    tilt_fraction: float,
    focal_centre: ArrayLike,
) -> Tuple[np.ndarray, str, np.ndarray]:
    """One pose as the bindings take it: the (3,) position, the attitude's kind ("none",
    "rpy", "quat") and its (1, k) array; InputError for a wrong shape or two attitudes."""
    position = np.asarray(position_m, dtype=np.float64)
    if position.shape != (3,):
        raise InputError(f"position_m must have shape (3,), got {position.shape}")
    given = [a is not None for a in (rpy_deg, quat, attitude_law)]
    if sum(given) > 1:
        raise InputError("give at most one of rpy_deg, quat, attitude_law")
    kind, attitude = "none", np.zeros((1, 3))
    if attitude_law is not None:
        if attitude_law != "focal":
            raise InputError(f"attitude_law must be 'focal', got {attitude_law!r}")
        centre = np.asarray(focal_centre, dtype=np.float64)
        kind = "quat"
        attitude = _fastcal.focal_attitude(position.reshape(1, 3), float(tilt_fraction), centre)
    elif rpy_deg is not None:
        kind, attitude = "rpy", np.asarray(rpy_deg, dtype=np.float64).reshape(1, -1)
    elif quat is not None:
        kind, attitude = "quat", np.asarray(quat, dtype=np.float64).reshape(1, -1)
    return position, kind, np.ascontiguousarray(attitude)


def modes(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    model: Optional[Union[Model, PathLike]] = None,
    *,
    attitude_law: Optional[str] = None,
    tilt_fraction: float = 0.41,
    focal_centre: ArrayLike = (0.0, 0.0, 300.0),
    segments: int = 48,
    count: int = 20,
    cable_inertia: bool = True,
) -> ModesResult:
    """The lowest natural frequencies and modes at one pose, as `fastcal modes`.

    Args:
        position_m: (3,) the cabin frame's origin.
        rpy_deg, quat: its attitude (at most one, or attitude_law); R = I without one.
        model: the model (its cabin_inertia_kg_m2 among the rest), or its file's path;
            None for the nominal.
        attitude_law: "focal" for the focal law (tilt_fraction, focal_centre).
        segments: per cable, 2 to 1000 (the default puts the 20 lowest within 0.1% of
            converged; memory and time grow linearly with it).
        count: how many of the lowest modes, 1 to 200.
        cable_inertia: False ignores the cables' inertia (the cabin on their static
            stiffness; at most six modes): a check, not the physics.

    Raises:
        InputError: a wrong shape, several attitudes, bad segments, count, cable_inertia or
            model (a model file that does not load, named).
        RuntimeError: the pose has no equilibrium, or it is unstable.
    """
    position, kind, attitude = _pose_arrays(
        position_m, rpy_deg, quat, attitude_law, tilt_fraction, focal_centre
    )
    # Each argument checked with its name (issue 57: segments=2**31 and model='path.yaml'
    # raised pybind11's TypeError, cable_inertia='no' was taken as True).
    segments = _whole(segments, "segments", 2, 1000)
    count = _whole(count, "count", 1, 200)
    if not isinstance(cable_inertia, (bool, np.bool_)):
        raise InputError(f"cable_inertia must be True or False, got {cable_inertia!r}")
    model = _model(model)
    out = _fastcal.modes(
        model,
        position.reshape(1, 3),
        kind,
        attitude,
        segments,
        count,
        bool(cable_inertia),
    )
    return ModesResult(
        frequency_hz=out["frequency_hz"],
        shares=out["shares"],
        cable_share=out["cable_share"],
        dominant_cable=out["dominant_cable"],
        cabin_shape=out["cabin_shape"],
        degrees_of_freedom=int(out["degrees_of_freedom"]),
    )


#: The record's columns, as `fastcal dynamics` writes its CSV (docs/cli.md).
_POSE_COLUMNS = ("x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg")
_QS_POSE_COLUMNS = ("x_qs_m", "y_qs_m", "z_qs_m", "roll_qs_deg", "pitch_qs_deg", "yaw_qs_deg")


def _end_arrays(to, to_rpy_deg, attitude_law, tilt_fraction, focal_centre):
    """A move's or a slew's end as the binding takes it: its position, and "same" (the
    start's attitude), a turn to to_rpy_deg, or the focal law's."""
    if attitude_law is not None and to_rpy_deg is not None:
        raise InputError("to_rpy_deg: with attitude_law='focal' every pose flies the law")
    end, end_kind, end_attitude = _pose_arrays(
        to, to_rpy_deg, None, attitude_law, tilt_fraction, focal_centre
    )
    return end, ("same" if end_kind == "none" else end_kind), end_attitude


def _model(model: Any) -> Model:
    """None (the nominal), a Model, or a model file's path; InputError for anything else."""
    if model is None:
        return Model.nominal()
    if isinstance(model, Model):
        return model
    if not isinstance(model, (str, os.PathLike)):
        raise InputError(f"model must be a fastcal.Model or a model file's path, got {model!r}")
    return Model.load(os.fspath(model))


def _winch_table(lengths: Any) -> Tuple[np.ndarray, np.ndarray]:
    """A DataFrame (or a mapping of arrays) with time_s and s0_1_m .. s0_6_m as the
    binding's (n,) times and (n, 6) lengths."""
    names = ["s0_%d_m" % i for i in range(1, 7)]
    missing = [c for c in ["time_s"] + names if c not in lengths]
    if missing:
        raise InputError("lengths: missing columns " + ", ".join(missing))
    time = np.ascontiguousarray(np.asarray(lengths["time_s"], dtype=np.float64))
    s0 = np.ascontiguousarray(
        np.column_stack([np.asarray(lengths[c], dtype=np.float64) for c in names])
    )
    return time, s0


def dynamics(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    model: Optional[Model] = None,
    *,
    attitude_law: Optional[str] = None,
    tilt_fraction: float = 0.41,
    focal_centre: ArrayLike = (0.0, 0.0, 300.0),
    to: Optional[ArrayLike] = None,
    to_rpy_deg: Optional[ArrayLike] = None,
    move_s: float = 60.0,
    lengths: Any = None,
    initial_offset: Optional[ArrayLike] = None,
    hold_s: float = 120.0,
    rate_hz: float = 10.0,
    settle_fraction: float = 0.005,
    segments: int = 40,
    damping_ratio: float = 0.004,
    step_s: float = 0.02,
    wind: Optional[Tuple[float, float]] = None,
    gust_spectrum: str = "kaimal",
    turbulence_intensity: float = 0.15,
    seed: int = 1,
):
    """The cabin and its six cables in time beside the quasi-static answer, as
    `fastcal dynamics` (docs/cli.md; docs/model.md, "Dynamics").

    Args:
        position_m, rpy_deg, quat, attitude_law, tilt_fraction, focal_centre: the start
            pose, as `modes` takes it.
        model: None for the nominal.
        to: (3,) a move's end (with move_s, s; the attitude flies the focal law with
            attitude_law="focal", else turns to to_rpy_deg, or stays); or
        lengths: a winch table, a DataFrame (or mapping) with time_s and s0_1_m .. s0_6_m
            (from 0 s, increasing; linear between rows, held after); or
        initial_offset: (3,) or (6,) a free decay: dx, dy, dz (m) [, rx, ry, rz (deg)];
            none of the three: the winches hold (a record in the wind).
        hold_s: after the winches stop; rate_hz: samples a second; settle_fraction: the
            settle time's band.
        segments, damping_ratio, step_s: the model and its integration step.
        wind: (speed m/s, direction deg toward, from +x toward +y), with gust_spectrum
            ("kaimal" | "davenport"), turbulence_intensity and seed.

    Returns:
        A pandas DataFrame, one row per sample, with the CSV's columns: time_s, x_m .. yaw_deg,
        T1_kN .. T6_kN, x_qs_m .. yaw_qs_deg, T1_qs_kN .. T6_qs_kN, s0_1_m .. s0_6_m,
        wind_m_per_s; frame.attrs["summary"] holds the summary JSON as a dict ("run",
        "start" with the lowest modes, "departure", "residual", "settle" with settle_s,
        "integrator").

    Raises:
        InputError: a wrong shape, two of to/lengths/initial_offset, bad options.
        RuntimeError: a pose the statics cannot hold, or a step that does not converge.
    """
    import pandas

    start, kind, attitude = _pose_arrays(
        position_m, rpy_deg, quat, attitude_law, tilt_fraction, focal_centre
    )
    if sum(x is not None for x in (to, lengths, initial_offset)) > 1:
        raise InputError("give one of to (a move), lengths (a winch table), initial_offset")
    run = "decay"
    end, end_kind, end_attitude = np.zeros(3), "same", np.zeros((1, 3))
    table_time, table_s0 = np.zeros(0), np.zeros((0, 6))
    offset = np.zeros(6)
    if to is not None:
        run = "move"
        end, end_kind, end_attitude = _end_arrays(
            to, to_rpy_deg, attitude_law, tilt_fraction, focal_centre
        )
    elif to_rpy_deg is not None:
        raise InputError("to_rpy_deg applies to a move (to)")
    elif lengths is not None:
        run = "lengths"
        table_time, table_s0 = _winch_table(lengths)
    elif initial_offset is not None:
        given = np.asarray(initial_offset, dtype=np.float64).ravel()
        if given.shape not in ((3,), (6,)):
            raise InputError(
                f"initial_offset must have 3 or 6 values (m, deg), got {given.shape}"
            )
        offset[: given.size] = given
    speed, direction = (0.0, 0.0) if wind is None else wind
    out = _fastcal.dynamics(
        _model(model),
        start.reshape(1, 3),
        kind,
        attitude,
        run,
        end.reshape(1, 3),
        end_kind,
        end_attitude,
        attitude_law is not None,
        np.asarray(focal_centre, dtype=np.float64).reshape(1, 3),
        float(tilt_fraction),
        float(move_s),
        table_time,
        table_s0,
        offset.reshape(1, 6),
        float(hold_s),
        float(rate_hz),
        float(settle_fraction),
        _whole(segments, "segments", 2, 1000),
        float(damping_ratio),
        float(step_s),
        float(speed),
        float(direction),
        str(gust_spectrum),
        float(turbulence_intensity),
        _whole(seed, "seed", 0, 2**63 - 1),
    )
    columns = {"time_s": out["time_s"]}
    tensions = ["T%d_kN" % i for i in range(1, 7)]
    qs_tensions = ["T%d_qs_kN" % i for i in range(1, 7)]
    for block, names in (
        ("pose", _POSE_COLUMNS),
        ("tension_kN", tensions),
        ("quasi_static_pose", _QS_POSE_COLUMNS),
        ("quasi_static_tension_kN", qs_tensions),
        ("s0_m", ["s0_%d_m" % i for i in range(1, 7)]),
    ):
        for j, name in enumerate(names):
            columns[name] = out[block][:, j]
    columns["wind_m_per_s"] = out["wind_m_per_s"]
    frame = pandas.DataFrame(columns)
    frame.attrs["summary"] = json.loads(out["summary_json"])
    return frame


def modes_cap(
    model: Optional[Union[Model, PathLike]] = None,
    *,
    max_off_axis_deg: float = 40.0,
    off_axis_step_deg: float = 5.0,
    azimuth_step_deg: float = 15.0,
    focal_radius: float = 160.0,
    focal_centre: ArrayLike = (0.0, 0.0, 300.0),
    tilt_fraction: float = 0.41,
    segments: int = 48,
    count: int = 20,
):
    """The modes over the focal-sphere cap, as `fastcal modes --cap` (docs/model.md,
    "Vibrations"): at every node of the grid, on the focal law, the lowest frequency, the
    first mode the cabin dominates, and for each of the cabin's six motions the mode that
    holds most of it.

    Args:
        model: the model or its file's path; None for the nominal.
        max_off_axis_deg, off_axis_step_deg, azimuth_step_deg, focal_radius, focal_centre:
            the grid (193 nodes by default); tilt_fraction: the focal law's.
        segments, count: as `modes` takes them, at every node.

    Returns:
        A pandas DataFrame, one row per node, with the CSV's columns: off_axis_deg,
        azimuth_deg, x_m .. yaw_deg, status ("ok" or "no_modes", with `message`),
        lowest_hz, lowest_cabin_share, first_cabin_mode, first_cabin_hz, x_hz, x_share, ..,
        rz_hz, rz_share.

    Raises:
        InputError: bad options or model (named).
    """
    import io

    import pandas

    csv = _fastcal.modes_cap(
        _model(model),
        float(max_off_axis_deg),
        float(off_axis_step_deg),
        float(azimuth_step_deg),
        float(focal_radius),
        np.asarray(focal_centre, dtype=np.float64).reshape(1, 3),
        float(tilt_fraction),
        _whole(segments, "segments", 2, 1000),
        _whole(count, "count", 1, 200),
    )
    return pandas.read_csv(io.StringIO(csv), keep_default_na=False, na_values=[""])


def identify_modes(
    data: PathLike,
    model: Optional[Union[Model, PathLike]] = None,
    *,
    identification: str = "auto",
    identified_modes: int = 3,
    segments: int = 48,
    count: int = 20,
):
    """Modes identified from a vibration record and compared with the model's prediction,
    as `fastcal modes --data` (docs/model.md, "Identified modes", "Modes from ordinary
    operation").

    Args:
        data: the record's CSV (the dataset's columns: time_s, the pose and T1_kN ..
            T6_kN at a steady rate, about one pose).
        model: the model predicted at the record's mean pose; None for the nominal.
        identification: "era" (a free decay), "ssi" (an ambient record) or "auto" (era
            when the envelope's mean square falls 4x from the first quarter to the last).
        identified_modes: how many dominant modes; segments, count: the prediction's.

    Returns:
        A pandas DataFrame, one row per identified mode, with the command's CSV columns
        (frequency_hz and its sigma, damping_ratio and its sigma, the predicted mode it
        matches, the difference in percent with its sigma, d ln f / d ln of each
        parameter); frame.attrs holds "method", "chi2_model", "agrees" (the record
        agrees with the model), "best" (the parameter whose change explains the
        differences best) and "fits" (per parameter: relative_change, sigma, chi2), and
        "mean_position_m".

    Raises:
        InputError: bad options, or a record that is not one (named with its file).
        RuntimeError: the identification or the prediction fails.
    """
    import io

    import pandas

    path = os.fspath(data)
    if not os.path.exists(path):  # as open() says it (the package's convention)
        raise FileNotFoundError(2, "No such file or directory", path)
    out = _fastcal.identify_modes(
        _model(model),
        path,
        str(identification),
        _whole(identified_modes, "identified_modes", 1, 20),
        _whole(segments, "segments", 2, 1000),
        _whole(count, "count", 1, 200),
    )
    frame = pandas.read_csv(io.StringIO(out["csv"]))
    for key in ("method", "chi2_model", "agrees", "best", "fits", "mean_position_m"):
        frame.attrs[key] = out[key]
    return frame


def loop(
    position_m: ArrayLike,
    rpy_deg: Optional[ArrayLike] = None,
    quat: Optional[ArrayLike] = None,
    truth: Optional[Model] = None,
    controller: Optional[Model] = None,
    *,
    attitude_law: Optional[str] = None,
    tilt_fraction: float = 0.41,
    focal_centre: ArrayLike = (0.0, 0.0, 300.0),
    to: Optional[ArrayLike] = None,
    to_rpy_deg: Optional[ArrayLike] = None,
    move_s: float = 60.0,
    hold_s: float = 120.0,
    pid: Tuple[float, float, float] = (0.05, 0.02, 0.0),
    error_filter_hz: float = 0.02,
    control_period_s: float = 0.1,
    measurement_noise_mm: float = 0.0,
    measurement_delay_s: float = 0.0,
    max_winch_speed: float = 0.5,
    max_winch_acceleration: float = 0.2,
    summary_from_s: float = 0.0,
    frequency_ghz: float = 3.0,
    segments: int = 40,
    damping_ratio: float = 0.004,
    step_s: float = 0.02,
    wind: Optional[Tuple[float, float]] = None,
    gust_spectrum: str = "kaimal",
    turbulence_intensity: float = 0.15,
    seed: int = 1,
):
    """The cabin in its control loop, a truth model against the controller's model, as
    `fastcal loop` (docs/cli.md; docs/model.md, "The closed loop").

    Args:
        position_m, rpy_deg, quat, attitude_law, tilt_fraction, focal_centre: the start
            pose, as `dynamics` takes it; to, to_rpy_deg, move_s: a slew's end and its
            duration (s), then hold_s.
        truth: the plant; controller: the model the control cycle solves with (None: the
            nominal, for either).
        pid: (Kp, Ki 1/s, Kd s); (0, 0, 0) is the feed-forward alone; error_filter_hz:
            the error low-passed twice there before the PID (0: none).
        control_period_s, measurement_noise_mm (per axis), measurement_delay_s,
            max_winch_speed (m/s), max_winch_acceleration (m/s^2): the controller.
        summary_from_s: the summary from this time on; frequency_ghz: of the efficiency
            estimate.
        segments, damping_ratio, step_s, wind, gust_spectrum, turbulence_intensity, seed:
            the plant, as `dynamics` takes them (the seed also the measurement noise's).

    Returns:
        A pandas DataFrame, one row per control cycle, with the CSV's columns: time_s, x_m,
        y_m, z_m, x_cmd_m .. z_cmd_m, x_meas_m .. z_meas_m, error_mm, lateral_mm,
        axial_mm, T1_kN .. T6_kN, T1_plan_kN .. T6_plan_kN, s0_1_m .. s0_6_m;
        frame.attrs["summary"] holds the summary JSON as a dict (error_rms_mm,
        error_peak_mm, lateral_*, axial_*, tension_error_rms_kN, winch_travel_m,
        efficiency, controller).

    Raises:
        InputError: a wrong shape, bad options (named).
        RuntimeError: a pose the controller's statics cannot solve, or a failed step.
    """
    import io

    import pandas

    start, kind, attitude = _pose_arrays(
        position_m, rpy_deg, quat, attitude_law, tilt_fraction, focal_centre
    )
    end, end_kind, end_attitude = np.zeros(3), "same", np.zeros((1, 3))
    if to is not None:
        end, end_kind, end_attitude = _end_arrays(
            to, to_rpy_deg, attitude_law, tilt_fraction, focal_centre
        )
    elif to_rpy_deg is not None:
        raise InputError("to_rpy_deg applies to a slew (to)")
    gains = np.asarray(pid, dtype=np.float64).ravel()
    if gains.shape != (3,):
        raise InputError(f"pid must be (Kp, Ki, Kd), got shape {gains.shape}")
    speed, direction = (0.0, 0.0) if wind is None else wind
    out = _fastcal.loop(
        _model(truth),
        _model(controller),
        start.reshape(1, 3),
        kind,
        attitude,
        to is not None,
        end.reshape(1, 3),
        end_kind,
        end_attitude,
        attitude_law is not None,
        np.asarray(focal_centre, dtype=np.float64).reshape(1, 3),
        float(tilt_fraction),
        float(move_s),
        float(hold_s),
        float(gains[0]),
        float(gains[1]),
        float(gains[2]),
        float(error_filter_hz),
        float(control_period_s),
        float(measurement_noise_mm) * 1e-3,
        float(measurement_delay_s),
        float(max_winch_speed),
        float(max_winch_acceleration),
        float(summary_from_s),
        _whole(segments, "segments", 2, 1000),
        float(damping_ratio),
        float(step_s),
        float(speed),
        float(direction),
        str(gust_spectrum),
        float(turbulence_intensity),
        _whole(seed, "seed", 0, 2**63 - 1),
        float(frequency_ghz) * 1e9,
    )
    frame = pandas.read_csv(io.StringIO(out["csv"]))
    frame.attrs["summary"] = json.loads(out["summary_json"])
    return frame
