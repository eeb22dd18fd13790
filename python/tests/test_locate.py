"""fastcal.locate: the forward statics on numpy arrays, round trips through solve, fits."""

from __future__ import annotations

import numpy as np
import pytest

import fastcal

ROUND_TRIP_M = 1e-9  # locate gives back solve's pose (docs/model.md, "Forward statics")
K1_LENGTH_M = 319.4245427  # every cable at K1 = (0, 0, 140), R = I (solve, 10 digits)


def test_locate_inverts_solve_along_an_arc() -> None:
    p = fastcal.arc(centre_m=(0, 0, 150), radius_m=50, nodes=21)
    q = fastcal.focal_attitude(p)
    solved = fastcal.solve(p, quat=q)
    located = fastcal.locate(solved.s0_m)
    assert located.position_m.shape == (21, 3) and located.quat.shape == (21, 4)
    assert located.ok.all() and (located.stability == "stable").all()
    assert np.abs(located.position_m - p).max() < ROUND_TRIP_M
    # q and -q are one attitude: compare |q . q'|.
    assert np.abs(np.abs(np.sum(located.quat * q, axis=1)) - 1).max() < 1e-12
    np.testing.assert_allclose(located.lower_tension_kN, solved.lower_tension_kN, rtol=1e-9)
    np.testing.assert_array_equal(located.s0_m, solved.s0_m)
    assert (located.readings == 6).all() and (located.chi2 == 0).all()
    assert located.covariance.shape == (21, 6, 6)
    assert located.pose_per_length.shape == (21, 6, 6)
    # Warm (the default) and cold give the same poses.
    cold = fastcal.locate(solved.s0_m, warm_start=False, search_radius_m=0)
    np.testing.assert_allclose(cold.position_m, located.position_m, atol=ROUND_TRIP_M)


def test_one_row_has_scalars_and_sigmas_follow_the_length_sigma() -> None:
    one = fastcal.locate([K1_LENGTH_M] * 6)
    assert one.position_m.shape == (3,)
    assert one.status == "ok" and one.ok and one.stability == "stable"
    assert abs(one.position_m[2] - 140.0) < 1e-6
    assert one.other_equilibria == 0 and np.isnan(one.nearest_other_m)
    assert one.min_stiffness_kN_per_m > 0
    # Lengths alone: the covariance is sigma_L^2 P P^T, so sigmas scale with sigma_L.
    finer = fastcal.locate([K1_LENGTH_M] * 6, length_sigma_m=0.001)
    np.testing.assert_allclose(finer.sigma_position_m, one.sigma_position_m / 10, rtol=1e-9)
    np.testing.assert_allclose(finer.sigma_rpy_deg, one.sigma_rpy_deg / 10, rtol=1e-9)


def test_measured_attitude_and_tensions_are_fitted() -> None:
    p = fastcal.arc(centre_m=(0, 0, 150), radius_m=50, nodes=5)
    q = fastcal.focal_attitude(p)
    solved = fastcal.solve(p, quat=q)
    fitted = fastcal.locate(solved.s0_m, quat=q, tensions_kN=solved.lower_tension_kN)
    assert (fitted.readings == 15).all()
    assert fitted.chi2.max() < 1e-10
    assert np.abs(fitted.position_m - p).max() < 1e-7
    # The attitude as roll/pitch/yaw is the same measurement.
    by_rpy = fastcal.locate(solved.s0_m, rpy_deg=fastcal.rpy_deg_from_quat(q))
    assert (by_rpy.readings == 9).all()
    # More measurements, smaller sigmas than the lengths' alone.
    alone = fastcal.locate(solved.s0_m)
    assert (fitted.sigma_position_m < alone.sigma_position_m).all()


def test_lengths_no_equilibrium_holds_are_marked_not_raised() -> None:
    r = fastcal.locate(np.array([[250.0] * 6, [K1_LENGTH_M] * 6]))
    assert list(r.status) == ["overstretched_cable", "ok"]
    assert list(r.stability) == ["unknown", "stable"]
    assert np.isnan(r.position_m[0]).all() and np.isnan(r.lower_tension_kN[0]).all()
    assert "stretched beyond" in r.messages[0]
    assert 1 not in r.messages


def test_top_heavy_cabin_is_refused_as_implausible() -> None:
    # The library reports a cabin whose mass centre sits 12 m above its anchors unstable
    # and not unique (tests/locate_test.cc); Python, like the model files, refuses such a
    # model before locating with it, naming the value and the plausible range.
    model = fastcal.Model.nominal()
    with pytest.raises(fastcal.InputError, match=r"mass_centre_m\[2\]: 12 m is beyond"):
        model.mass_centre_m = [0.0, 0.0, 12.0]
        fastcal.locate([K1_LENGTH_M] * 6, model=model)
    # 4.9 m up, within the range, it still hangs stable and alone at K1.
    model.mass_centre_m = [0.0, 0.0, 4.9]
    lengths = fastcal.solve([0.0, 0.0, 140.0], model=model).s0_m
    r = fastcal.locate(lengths, model=model)
    assert r.ok and r.stability == "stable" and r.other_equilibria == 0


def test_bad_arguments_raise_input_error() -> None:
    with pytest.raises(fastcal.InputError, match=r"lengths_m must have shape \(6,\)"):
        fastcal.locate([1.0, 2.0, 3.0])
    with pytest.raises(fastcal.InputError, match="tensions_kN must have shape"):
        fastcal.locate([K1_LENGTH_M] * 6, tensions_kN=[1.0, 2.0])
    with pytest.raises(fastcal.InputError, match="quat has 2 rows for 1 rows of lengths_m"):
        fastcal.locate([K1_LENGTH_M] * 6, quat=[[1, 0, 0, 0], [1, 0, 0, 0]])
    with pytest.raises(fastcal.InputError, match="length_sigma_m"):
        fastcal.locate([K1_LENGTH_M] * 6, length_sigma_m=0.0)
    with pytest.raises(fastcal.InputError, match="search_radius_m"):
        fastcal.locate([K1_LENGTH_M] * 6, search_radius_m=-1.0)


def test_encoder_offsets_of_a_simulation_are_removed_by_the_truth_model() -> None:
    p = fastcal.random_workspace(samples=8, seed=3)
    data, truth, summary = fastcal.simulate(
        p, quat=fastcal.focal_attitude(p), length_offset_spread_m=0.3, seed=2
    )
    np.testing.assert_array_equal(truth.length_offset_m, summary["length_offset_m"])
    assert np.abs(truth.length_offset_m).max() > 0.0
    with_truth = fastcal.locate(data.s0_m, model=truth)
    assert np.abs(with_truth.position_m - p).max() < 1e-6
    nominal = fastcal.locate(data.s0_m)
    assert np.abs(nominal.position_m - p).max() > 0.1


def test_a_calibration_with_lengths_reports_them(data_dir) -> None:
    p = fastcal.random_workspace(samples=150, seed=4, radial_spread_m=3.0)
    truth = fastcal.Model.nominal()
    truth.length_offset_m = [0.1, -0.2, 0.05, 0.3, -0.1, 0.0]
    data, _, _ = fastcal.simulate(p, quat=fastcal.focal_attitude(p), model=truth, seed=6,
                                  length_noise_m=0.005)
    result = fastcal.calibrate(str(data_dir / "spec_lengths.yaml"), data)
    assert result.lengths is not None and result.lengths["sigma_m"] == 0.005
    assert (result.lengths["calibrated_rms_m"] < 0.01).all()
    for i, offset in enumerate(truth.length_offset_m):
        name = f"length_offset_m[{i + 1}]"
        assert abs(result.estimates[name] - offset) < 3 * result.sigma_total[name]
    np.testing.assert_allclose(result.model.length_offset_m, [result.estimates[
        f"length_offset_m[{i + 1}]"] for i in range(6)])


def test_sigmas_from_a_spec_and_the_former_keyword(data_dir) -> None:
    alone = fastcal.locate([K1_LENGTH_M] * 6)
    spec = fastcal.locate([K1_LENGTH_M] * 6, spec=data_dir / "spec_lengths.yaml")  # 5 mm
    as_dict = fastcal.locate([K1_LENGTH_M] * 6, spec={"noise": {"length_sigma_m": 0.005}})
    overridden = fastcal.locate([K1_LENGTH_M] * 6, spec=data_dir / "spec_lengths.yaml",
                                length_sigma_m=0.01)
    np.testing.assert_allclose(spec.sigma_position_m, 0.5 * alone.sigma_position_m, rtol=1e-9)
    np.testing.assert_allclose(as_dict.sigma_position_m, spec.sigma_position_m, rtol=1e-12)
    np.testing.assert_allclose(overridden.sigma_position_m, alone.sigma_position_m, rtol=1e-12)
    with pytest.raises(fastcal.InputError, match="length_sigma_m"):
        fastcal.locate([K1_LENGTH_M] * 6, spec={"noise": {"length_sigma_m": -1}})
    with pytest.warns(DeprecationWarning, match="use reflector_clearance_m="):
        fastcal.locate([K1_LENGTH_M] * 6, min_reflector_clearance_m=0.0)
