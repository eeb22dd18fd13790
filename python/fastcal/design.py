"""Survey design: which poses a survey should visit."""

from __future__ import annotations

import os
import re
from typing import Any, Dict, Mapping, Optional, Sequence, Union

from . import _fastcal
from ._fastcal import InputError, Model

from ._common import PathLike, _DICT_SPEC, _INT32_MAX, _UINT64_MAX, _number, _renamed_keywords, _spec_argument, _whole


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
    settle_fraction: float = 0.005,
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
        settle_fraction: with a speed, after each move wait until every tension is within
            this fraction of quasi-static (the time-domain model; docs/design.md); 0: no
            waits.
        min_tension_kN, max_tension_kN, reflector_clearance_m: the candidates' limits;
            None: the design's defaults (50 kN, none, 5 m).
        max_off_axis_deg, off_axis_step_deg, azimuth_step_deg: the grid; None: the
            workspace's (40, 1, 5 deg).

    Returns:
        A dict: 'poses', a (samples, 6) array of x_m, y_m, z_m, roll_deg, pitch_deg,
        yaw_deg in flight order (what poses.csv holds); 'stops' (dicts: samples,
        position_m, extra_tilt_deg, tilt_direction_deg, extra_yaw_deg); 'wanted';
        'settle_s' (the waits after moves, in duration_s; stops[]['settle_s'] each);
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
        "settle_fraction": _number(settle_fraction, "settle_fraction"),
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
