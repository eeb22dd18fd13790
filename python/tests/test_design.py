"""fastcal.design: the survey design from Python, as `fastcal design` makes it."""

from __future__ import annotations

import numpy as np
import pytest

import fastcal

SPEC = {
    "parameters": {
        "mass_centre_m": {"x": {"free": True}, "y": {"free": True}, "z": {"free": True}},
        "sensor_gain": {"free": True, "prior": {"mean": 1, "sigma": 0.01}},
        "sensor_bias_kN": {"free": True, "prior": {"mean": 0, "sigma": 2}},
    }
}
# A coarse cap keeps the test fast: every 5 deg off axis, every 30 deg of azimuth.
GRID = {"off_axis_step_deg": 5.0, "azimuth_step_deg": 30.0}


def test_design_returns_poses_in_flight_order_and_predictions():
    d = fastcal.design(SPEC, 60, max_extra_tilt_deg=5.0, speed_m_per_s=0.5, **GRID)
    poses = d["poses"]
    assert poses.shape == (60, 6)
    assert np.all(np.isfinite(poses))
    assert sum(s["samples"] for s in d["stops"]) == 60
    assert d["wanted"] == ["mass_centre_m.x", "mass_centre_m.y", "mass_centre_m.z"]
    for name in d["wanted"]:
        assert d["design"]["sigma_total"][name] < d["circle"]["sigma_total"][name]
        assert d["design"]["sigma_total"][name] < d["random"]["sigma_total"][name]
    # Travel, dwell and the waits after the moves (issue 55), each stop's wait beside it.
    assert d["settle_s"] == pytest.approx(sum(s["settle_s"] for s in d["stops"]))
    assert d["duration_s"] == pytest.approx(d["path_length_m"] / 0.5 + 60.0 + d["settle_s"])
    without = fastcal.design(
        SPEC, 60, max_extra_tilt_deg=5.0, speed_m_per_s=0.5, settle_fraction=0.0, **GRID
    )
    assert without["settle_s"] == 0.0
    assert without["duration_s"] == pytest.approx(without["path_length_m"] / 0.5 + 60.0)
    # The poses are ones the statics can hold.
    sol = fastcal.solve(poses[:, :3], rpy_deg=poses[:, 3:])
    assert np.all(sol.lower_tension_kN >= 50.0)


def test_design_is_deterministic():
    a = fastcal.design(SPEC, 30, **GRID)
    b = fastcal.design(SPEC, 30, **GRID)
    np.testing.assert_array_equal(a["poses"], b["poses"])


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"samples": 3}, "cannot determine the spec's 5 free parameters"),
        ({"samples": 30, "minutes": 0.1, "speed_m_per_s": 1.0}, "infeasible time budget"),
        ({"samples": 30, "criterion": "E"}, "criterion must be 'A' or 'D'"),
        ({"samples": 30, "parameters": ["cabin_mass_kg"]}, "not a free parameter"),
    ],
)
def test_design_bad_input(kwargs, message):
    with pytest.raises(fastcal.InputError, match=message):
        fastcal.design(SPEC, **kwargs, **GRID)


def test_design_spec_with_nothing_free():
    with pytest.raises(fastcal.InputError, match="frees no parameter"):
        fastcal.design({"parameters": {"mass_centre_m": {"x": {"free": False}}}}, 30, **GRID)
