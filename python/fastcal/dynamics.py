"""The vibrations layer: the natural frequencies and modes of the cabin on its six sagging
cables at one pose (the C++ library's modes.h; docs/model.md, "Vibrations")."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional, Sequence, Union

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
    # Each argument checked with its name (issue 57: segments=2**31 and model='path.yaml'
    # raised pybind11's TypeError, cable_inertia='no' was taken as True).
    segments = _whole(segments, "segments", 2, 1000)
    count = _whole(count, "count", 1, 200)
    if not isinstance(cable_inertia, (bool, np.bool_)):
        raise InputError(f"cable_inertia must be True or False, got {cable_inertia!r}")
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        if not isinstance(model, (str, os.PathLike)):
            raise InputError(f"model must be a fastcal.Model or a model file's path, got {model!r}")
        model = Model.load(os.fspath(model))
    out = _fastcal.modes(
        model,
        position.reshape(1, 3),
        kind,
        np.ascontiguousarray(attitude),
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
