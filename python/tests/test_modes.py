"""fastcal.modes: the vibrations of one pose, as `fastcal modes` computes them."""

from __future__ import annotations

import numpy as np
import pytest

import fastcal


def test_zenith_modes_ascend_with_shares_summing_to_one() -> None:
    result = fastcal.modes((0, 0, 140), segments=16)
    assert result.frequency_hz.shape == (20,)
    assert result.degrees_of_freedom == 6 + 18 * 15
    assert np.all(np.diff(result.frequency_hz) >= 0)
    np.testing.assert_allclose(result.shares.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(result.cable_share.sum(axis=1), result.shares[:, 6], atol=1e-12)
    # The sway pair at ~0.155 Hz: equal frequencies by the 3-fold symmetry.
    assert result.frequency_hz[0] == pytest.approx(0.155, abs=0.005)
    assert result.frequency_hz[1] == pytest.approx(result.frequency_hz[0], rel=1e-8)
    assert set(result.dominant_cable) <= set(range(1, 7))


def test_focal_law_and_inertia_change_the_modes() -> None:
    position = (102.846, 0.0, 177.433)
    focal = fastcal.modes(position, attitude_law="focal", segments=12, count=6)
    quat = fastcal.focal_attitude(np.array(position))
    same = fastcal.modes(position, quat=quat, segments=12, count=6)
    np.testing.assert_array_equal(focal.frequency_hz, same.frequency_hz)
    model = fastcal.Model.nominal()
    np.testing.assert_array_equal(np.diag(model.cabin_inertia_kg_m2), (3.5e5, 3.5e5, 5.0e5))
    model.cabin_inertia_kg_m2 = (7e5, 7e5, 1e6)
    heavier = fastcal.modes(position, attitude_law="focal", segments=12, count=6, model=model)
    assert not np.array_equal(heavier.frequency_hz, focal.frequency_hz)


def test_bad_input_is_named() -> None:
    with pytest.raises(fastcal.InputError, match="segments"):
        fastcal.modes((0, 0, 140), segments=1)
    with pytest.raises(fastcal.InputError, match="at most one"):
        fastcal.modes((0, 0, 140), rpy_deg=(0, 0, 0), attitude_law="focal")
    with pytest.raises(fastcal.InputError, match="position_m"):
        fastcal.modes((0, 0))
    with pytest.raises(fastcal.InputError, match="cabin_inertia_kg_m2"):
        fastcal.Model.nominal().cabin_inertia_kg_m2 = (1.0, -1.0, 1.0)
    with pytest.raises(RuntimeError, match="no equilibrium"):
        fastcal.modes((0, 0, 268))


def test_arguments_of_the_wrong_kind_are_named(tmp_path) -> None:
    # Issue 57: segments=2**31 and model='path.yaml' raised pybind11's TypeError, and
    # cable_inertia='no' was taken as True.
    with pytest.raises(fastcal.InputError, match="segments must be from 2 to 1000"):
        fastcal.modes((0, 0, 140), segments=2**31)
    with pytest.raises(fastcal.InputError, match="count must be from 1 to 200"):
        fastcal.modes((0, 0, 140), count=10**6)
    with pytest.raises(fastcal.InputError, match="cable_inertia must be True or False"):
        fastcal.modes((0, 0, 140), cable_inertia="no")
    with pytest.raises(fastcal.InputError, match="model must be a fastcal.Model"):
        fastcal.modes((0, 0, 140), model=42)
    path = tmp_path / "model.yaml"
    fastcal.Model.nominal().save(str(path))
    by_path = fastcal.modes((0, 0, 140), model=str(path), segments=8, count=3)
    assert by_path.frequency_hz.tolist() == fastcal.modes((0, 0, 140), segments=8, count=3).frequency_hz.tolist()
    path.write_text("cabin:\n  inertia_kg_m2: [1e300, 1e300, 1e300]\n")
    with pytest.raises(fastcal.InputError, match=r"cabin.inertia_kg_m2\[0\]: 1e\+300 kg m\^2"):
        fastcal.modes((0, 0, 140), model=path)
