"""What a new user trips on in Python: keyword names that differ from the command line's,
model arrays edited in place to no effect, one attitude for many positions, a package
namespace full of its imports, design sigmas in another unit than their names say."""

from __future__ import annotations

import numpy as np
import pytest

import fastcal

CIRCLE = fastcal.arc(centre_m=(0, 0, 156.73), radius_m=71.11, nodes=12)
# Exact statics repeat bit for bit: results by old and new keywords are equal, not close.


def test_the_package_lists_what_it_offers_not_its_imports() -> None:
    names = set(dir(fastcal))
    assert not names & {"np", "os", "re", "json", "warnings", "functools", "difflib"}
    assert {"solve", "calibrate", "design", "Model", "STATUS_NAMES"} <= names


def test_model_arrays_cannot_be_edited_in_place_to_no_effect() -> None:
    model = fastcal.Model.nominal()
    for name in (
        "ea_n",
        "linear_density_kg_per_m",
        "sensor_gain",
        "sensor_bias_kN",
        "mass_centre_m",
        "anchor_points_cabin_m",
        "tower_top_m",
        "anchor_index",
    ):
        with pytest.raises(ValueError, match="read-only"):
            getattr(model, name)[0] = 1
    # A whole array assigned is what changes the model, a copy edited first included.
    ea = model.ea_n.copy()
    ea[0] *= 1.01
    model.ea_n = ea
    assert model.ea_n[0] == pytest.approx(2.4656e7 * 1.01)
    assert model.reflector is not None
    with pytest.raises(ValueError, match="read-only"):
        model.reflector["centre_m"][2] = 0.0


def test_one_attitude_applies_to_every_position() -> None:
    rpy = [1.0, -0.5, 2.0]
    together = fastcal.solve(CIRCLE, rpy_deg=rpy)
    one_by_one = fastcal.solve(CIRCLE, rpy_deg=np.tile(rpy, (len(CIRCLE), 1)))
    np.testing.assert_array_equal(together.lower_tension_kN, one_by_one.lower_tension_kN)
    quat = fastcal.quat_from_rpy_deg(rpy)
    by_quat = fastcal.solve(CIRCLE, quat=quat)
    np.testing.assert_allclose(by_quat.lower_tension_kN, together.lower_tension_kN, rtol=1e-9)
    with pytest.raises(fastcal.InputError, match="rpy_deg has 2 rows for 12 positions"):
        fastcal.solve(CIRCLE, rpy_deg=[rpy, rpy])


def test_solve_keywords_are_the_command_lines_and_the_old_ones_warn() -> None:
    new = fastcal.solve(CIRCLE, method="aas", aas_max_error=0.02, reflector_clearance_m=1.0)
    with pytest.warns(DeprecationWarning, match=r"aas_max_relative_error=.*aas_max_error="):
        old = fastcal.solve(
            CIRCLE, method="aas", aas_max_relative_error=0.02, min_reflector_clearance_m=1.0
        )
    np.testing.assert_array_equal(old.lower_tension_kN, new.lower_tension_kN)
    with pytest.raises(TypeError, match="both"):
        fastcal.solve(CIRCLE, exact_tolerance=1e-12, exact_relative_tolerance=1e-12)
    # A bad value is named by the keyword the user typed, not the library's field.
    with pytest.raises(fastcal.InputError, match=r"\baas_max_error\b"):
        fastcal.solve(CIRCLE, method="aas", aas_max_error=-1.0)


def test_simulate_options_are_the_command_lines_flags() -> None:
    quat = fastcal.focal_attitude(CIRCLE)
    options = dict(attitude_control_deg=0.1, attitude_noise_deg=0.02, position_noise_m=0.01)
    new, _, summary = fastcal.simulate(CIRCLE, quat=quat, seed=2, interval_s=2.0, **options)
    np.testing.assert_array_equal(new.time_s, 2.0 * np.arange(len(CIRCLE)))
    assert summary["attitude_control_rms_deg"] > 0.0
    with pytest.warns(DeprecationWarning, match="attitude_control_sigma_deg"):
        old, _, _ = fastcal.simulate(
            CIRCLE,
            quat=quat,
            seed=2,
            sample_interval_s=2.0,
            attitude_control_sigma_deg=0.1,
            attitude_measurement_sigma_deg=0.02,
            position_measurement_sigma_m=0.01,
        )
    np.testing.assert_array_equal(old.tension_kN, new.tension_kN)
    with pytest.raises(fastcal.InputError, match="did you mean tension_noise_percent"):
        fastcal.simulate(CIRCLE, quat=quat, tension_noise_pct=3.0)
    with pytest.raises(fastcal.InputError, match=r"\btension_noise_kN\b"):
        fastcal.simulate(CIRCLE, quat=quat, tension_noise_kN=-1.0)


def test_design_sigmas_are_in_the_units_their_names_carry() -> None:
    spec = {
        "parameters": {
            "mass_centre_m": {"x": {"free": True}, "y": {"free": True}, "z": {"free": True}},
            "sensor_bias_kN": {"free": True, "prior": {"mean": 0, "sigma": 2}},
        }
    }
    d = fastcal.design(spec, 30, off_axis_step_deg=5.0, azimuth_step_deg=30.0, interval_s=2.0)
    assert d["units"]["sensor_bias_kN"] == "kN"
    assert d["units"]["mass_centre_m.x"] == "m"
    # A prior of 2 kN bounds the bias's sigma: kN (below 2), never N (hundreds).
    assert 0.0 < d["design"]["sigma_total"]["sensor_bias_kN"] <= 2.0
    assert d["design"]["sigma_total"]["mass_centre_m.x"] < 0.1  # metres
    with pytest.warns(DeprecationWarning, match="sample_interval_s"):
        fastcal.design(spec, 30, off_axis_step_deg=5.0, azimuth_step_deg=30.0, sample_interval_s=2)


def test_one_name_per_quantity_and_the_old_ones_warn() -> None:
    # The model's mass centre as the model file and calibrate name it; the statics'
    # error estimate in percent as the command line's column.
    model = fastcal.Model.nominal()
    np.testing.assert_array_equal(model.mass_centre_m, [0.0, 0.0, 0.5])
    with pytest.warns(DeprecationWarning, match="mass_centre_m"):
        np.testing.assert_array_equal(model.mass_centre_cabin_m, model.mass_centre_m)
    with pytest.raises(ValueError, match=r"mass_centre_m\[2\]"):
        model.mass_centre_m = [0.0, 0.0, 500.0]
    result = fastcal.solve([0.0, 0.0, 150.0])
    with pytest.warns(DeprecationWarning, match="error_estimate_pct"):
        assert result.error_estimate * 100 == result.error_estimate_pct
