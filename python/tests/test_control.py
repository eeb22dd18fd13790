"""fastcal.control_cycle against fastcal.solve, its limits, and bad input."""

import math

import numpy as np
import pytest

import fastcal

# Equal up to rounding: the same solver, warm vs cold, both to 1e-12.
SAME_RELATIVE = 1e-9


def _cap_poses(n, seed):
    positions = fastcal.random_workspace(n, seed=seed)
    return positions, fastcal.focal_attitude(positions)


def test_matches_solve_with_the_model_offsets_and_gains():
    model = fastcal.Model.nominal()
    model.length_offset_m = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    model.sensor_gain = [1.0, 1.01, 1.02, 1.03, 1.04, 1.05]
    positions, quat = _cap_poses(20, seed=38)
    cycle = fastcal.control_cycle(positions, quat=quat, model=model, min_tension_kN=0.0)
    ref = fastcal.solve(positions, quat=quat, model=model)
    assert cycle.ok.all(), cycle.status
    np.testing.assert_allclose(cycle.tension_kN, ref.lower_tension_kN, rtol=SAME_RELATIVE)
    np.testing.assert_allclose(cycle.s0_m, ref.s0_m, rtol=SAME_RELATIVE)
    np.testing.assert_allclose(cycle.winch_length_m - cycle.s0_m,
                               np.tile(model.length_offset_m, (20, 1)), atol=1e-9)
    np.testing.assert_allclose(cycle.sensor_reading_kN,
                               ref.lower_tension_kN * np.array(model.sensor_gain),
                               rtol=SAME_RELATIVE)
    np.testing.assert_allclose(cycle.min_tension_margin_kN, ref.lower_tension_kN.min(axis=1),
                               rtol=SAME_RELATIVE)


def test_limits_mark_the_pose_and_keep_the_numbers():
    position = [10.0, -20.0, 145.0]
    one = fastcal.control_cycle(position)
    assert one.ok and one.status == "ok" and one.cable == 0
    lowest = float(one.tension_kN.min())
    low = fastcal.control_cycle(position, min_tension_kN=lowest + 1.0)
    assert low.status == "below_min_tension"
    assert low.cable == int(np.argmin(one.tension_kN)) + 1
    assert math.isclose(low.min_tension_margin_kN, -1.0, abs_tol=1e-9)
    assert np.all(np.isfinite(low.winch_length_m))
    high = fastcal.control_cycle(position, max_tension_kN=lowest)
    assert high.status == "above_max_tension"
    # On the cap no cable dips toward the reflector (clearance inf); 45 m lower they do.
    assert math.isinf(one.reflector_clearance_m)
    low = [0.0, 0.0, 100.0]
    clearance = fastcal.control_cycle(low).reflector_clearance_m
    assert math.isfinite(clearance)
    near = fastcal.control_cycle(low, min_reflector_clearance_m=clearance + 1.0)
    assert near.status == "inside_reflector_margin"
    assert np.all(np.isfinite(near.tension_kN))


def test_a_statics_failure_is_its_status_with_nan():
    result = fastcal.control_cycle([[0.0, 0.0, 145.0], [0.0, 0.0, 260.0]])
    assert result.status[0] == "ok"
    assert result.status[1] not in ("ok", "statics_failed")
    assert result.status[1] in fastcal.STATUS_NAMES
    assert np.isnan(result.winch_length_m[1]).all()


def test_joints_move_the_tensions(data_dir):
    model = fastcal.Model.load(str(data_dir / "moving_parts.yaml"))
    columns = list(model.joint_columns)
    joints = [10.0 if c.endswith("_deg") else 0.05 for c in columns]
    position = [5.0, 5.0, 145.0]
    at_zero = fastcal.control_cycle(position, model=model)
    moved = fastcal.control_cycle(position, joints=joints, model=model)
    assert at_zero.ok and moved.ok
    assert np.max(np.abs(moved.tension_kN - at_zero.tension_kN)) > 0.1  # kN
    with pytest.raises(fastcal.InputError, match="shape"):
        fastcal.control_cycle(position, joints=joints[:-1], model=model)
    with pytest.raises(fastcal.InputError, match="no moving parts"):
        fastcal.control_cycle(position, joints=[1.0])
    # Issue 57: a joint outside the range the model states for it (+-40 deg) came back
    # 'ok'; the C interface and the command line refused it, and so does Python now.
    for value, why in ((400.0, "beyond one turn"),
                       (40.0000001, r"40.0000001 is outside the range \[-40, 40\]")):
        beyond = list(joints)
        beyond[0] = value
        with pytest.raises(fastcal.InputError, match=why):
            fastcal.control_cycle(position, joints=beyond, model=model)


def test_bad_limits_are_named():
    with pytest.raises(fastcal.InputError, match="min_tension"):
        fastcal.control_cycle([0.0, 0.0, 145.0], min_tension_kN=float("nan"))
    with pytest.raises(fastcal.InputError, match="max_tension"):
        fastcal.control_cycle([0.0, 0.0, 145.0], min_tension_kN=100.0, max_tension_kN=10.0)
    with pytest.raises(fastcal.InputError, match="min_reflector_clearance_m"):
        fastcal.control_cycle([0.0, 0.0, 145.0], min_reflector_clearance_m=-1.0)

