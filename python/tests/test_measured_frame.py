"""Where the telemetry measures, from Python (issue 58): the model's measured frame, the
cabin's pose derived by hand, solve and locate in the data's frame, and the bad input a
user meets."""

import pathlib

import numpy as np
import pytest

import fastcal

SIN10, COS10 = 0.17364817766693033, 0.984807753012208


@pytest.fixture
def feed(data_dir: pathlib.Path) -> fastcal.Model:
    return fastcal.Model.load(str(data_dir / "fast_feed.yaml"))


def test_the_frame_and_the_cabin_pose_derived_by_hand(feed: fastcal.Model) -> None:
    frame = feed.measured_frame
    assert frame["part"] == "stewart"
    np.testing.assert_array_equal(frame["offset_m"], [0, 0, -1.2])
    # The platform rolled 10 deg with the rotator at a = 10 deg: the cabin level, at
    # m + (0, 0, 0.8) + 1.2 (0, -sin 10, cos 10).
    position, rpy = feed.cabin_pose([0, 0, 140], [10, 0, 0], [10, 0, 0, 0, 0])
    np.testing.assert_allclose(position, [0, -1.2 * SIN10, 140.8 + 1.2 * COS10], atol=1e-12)
    np.testing.assert_allclose(rpy, [0, 0, 0], atol=1e-12)
    assert fastcal.Model.nominal().measured_frame is None


def test_solve_is_the_plain_models_at_the_cabin_pose(
    feed: fastcal.Model, data_dir: pathlib.Path
) -> None:
    joints = [10, 0, 0, 0, 0]
    framed = fastcal.solve([0, 0, 140], rpy_deg=[10, 0, 0], model=feed, joints=joints)
    plain = fastcal.Model.load(str(data_dir / "fast_feed.yaml"))
    plain.measured_frame = None
    cabin, _ = feed.cabin_pose([0, 0, 140], [10, 0, 0], joints)
    at_cabin = fastcal.solve(cabin, rpy_deg=[0, 0, 0], model=plain, joints=joints)
    np.testing.assert_allclose(framed.lower_tension_kN, at_cabin.lower_tension_kN, rtol=1e-10)
    # Taken as the cabin's, the data's pose is a kilonewton and more off.
    as_cabin = fastcal.solve([0, 0, 140], rpy_deg=[10, 0, 0], model=plain, joints=joints)
    assert np.max(np.abs(as_cabin.lower_tension_kN - at_cabin.lower_tension_kN)) > 1.0


def test_locate_returns_the_frames_pose_and_the_cabins(data_dir: pathlib.Path) -> None:
    feed = fastcal.Model.load(str(data_dir / "fast_feed.yaml"))
    joints = [10, 0, 0, 0, 0]
    solved = fastcal.solve([0, 0, 140], rpy_deg=[10, 0, 0], model=feed, joints=joints)
    located = fastcal.locate(solved.s0_m, model=feed, joints=joints)
    assert located.ok
    np.testing.assert_allclose(located.position_m, [0, 0, 140], atol=1e-6)
    np.testing.assert_allclose(located.rpy_deg, [10, 0, 0], atol=1e-6)
    np.testing.assert_allclose(located.cabin_position_m, [0, -1.2 * SIN10, 140.8 + 1.2 * COS10],
                               atol=1e-6)


def test_bad_frames_are_refused_by_name(feed: fastcal.Model) -> None:
    with pytest.raises(fastcal.InputError, match="'stewartt' is not a moving part"):
        feed.measured_frame = {"part": "stewartt"}
    with pytest.raises(fastcal.InputError, match="unknown key 'point'"):
        feed.measured_frame = {"point": [0, 0, 1]}
    with pytest.raises(fastcal.InputError, match="measured_frame.offset_m"):
        feed.measured_frame = {"part": "stewart", "offset_m": [0, float("nan"), 0]}
    # A refused assignment leaves the model as it was.
    assert feed.measured_frame["part"] == "stewart"
    feed.measured_frame = {"part": "cabin", "offset_m": [0, 0, -2]}
    assert feed.measured_frame["part"] == "cabin"
