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

from typing import List

try:
    import numpy as np

    from . import _fastcal
except ImportError as _error:  # another interpreter than the build's: say which to use
    import sys as _sys

    try:
        from ._build import PYTHON as _BUILT_FOR
    except ImportError:  # an installed package: no build tree
        _BUILT_FOR = None
    _where = f"; it was built for {_BUILT_FOR}" if _BUILT_FOR else ""
    if getattr(_error, "name", None) == "numpy" or "numpy" in str(_error):
        # Issue 59: an installed package under another interpreter said only "No module
        # named numpy".
        raise ImportError(
            f"fastcal needs numpy, which this Python interpreter ({_sys.executable}) does "
            f"not have{_where}: run fastcal with an interpreter that has numpy, or install "
            "it for this one (Debian: apt-get install python3-numpy; docs/python.md)"
        ) from _error
    if _BUILT_FOR is None:
        raise _error from None
    raise ImportError(
        f"fastcal was built for {_BUILT_FOR}; this is another Python interpreter "
        f"({_sys.executable}: {_error}). Run it with {_BUILT_FOR}, or build/python/python3 in "
        "the build tree (docs/python.md)"
    ) from _error
from ._fastcal import CalibrationError, Dataset, Error, InputError, Model

__version__: str = _fastcal.__version__

__all__ = [
    "Cable",
    "CalibrationError",
    "CalibrationResult",
    "ControlCycleResult",
    "Dataset",
    "Error",
    "InputError",
    "LocateResult",
    "Model",
    "ModesResult",
    "StaticsResult",
    "__version__",
    "arc",
    "calibrate",
    "control_cycle",
    "design",
    "dynamics",
    "evaluate",
    "focal_attitude",
    "focal_grid",
    "identify_modes",
    "line",
    "locate",
    "loop",
    "modes",
    "modes_cap",
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

# The modules mirror the library's layers; this file only gathers what they offer.
from ._common import STATUS_NAMES, ArrayLike, PathLike  # noqa: F401
from . import model as _model_names  # noqa: F401  (Model.mass_centre_m)
from .statics import (  # noqa: F401
    STABILITY_NAMES,
    Cable,
    ColumnsLike,
    LocateResult,
    StaticsResult,
    arc,
    focal_attitude,
    focal_grid,
    line,
    locate,
    quat_from_rpy_deg,
    random_workspace,
    rpy_deg_from_quat,
    solve,
)
from .control import ControlCycleResult, control_cycle  # noqa: F401
from .dataset import read_dataset, simulate  # noqa: F401
from .calibration import CalibrationResult, calibrate, evaluate  # noqa: F401
from .design import design  # noqa: F401
from .track import TrackResult, track  # noqa: F401
from .dynamics import ModesResult, dynamics, identify_modes, loop, modes, modes_cap  # noqa: F401
