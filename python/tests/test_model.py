"""fastcal.Model: the nominal model, its file, and its fields as numbers."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import fastcal


def test_version_is_the_projects() -> None:
    top = (pathlib.Path(__file__).parents[2] / "CMakeLists.txt").read_text()
    assert f"project(fastcal VERSION {fastcal.__version__} " in top


def test_nominal_fields_are_numbers_and_arrays() -> None:
    model = fastcal.Model.nominal()
    assert model.cabin_mass_kg == 30000.0
    assert model.gravity_m_per_s2 == -9.8
    np.testing.assert_array_equal(model.mass_centre_cabin_m, [0.0, 0.0, 0.5])
    assert model.anchor_points_cabin_m.shape == (3, 3)
    assert model.tower_top_m.shape == (6, 3)
    np.testing.assert_array_equal(model.tower_top_m[:, 2], np.full(6, 270.0))
    np.testing.assert_array_equal(model.anchor_index, [0, 0, 1, 1, 2, 2])
    np.testing.assert_array_equal(model.ea_n, np.full(6, 2.4656e7))
    np.testing.assert_array_equal(model.linear_density_kg_per_m, np.full(6, 11.718))
    np.testing.assert_array_equal(model.sensor_gain, np.ones(6))
    np.testing.assert_array_equal(model.sensor_bias_n, np.zeros(6))


def test_fields_are_set_by_whole_arrays(tmp_path: pathlib.Path) -> None:
    model = fastcal.Model.nominal()
    model.mass_centre_cabin_m = [0.22, 0.11, 0.5]
    model.linear_density_kg_per_m = np.linspace(11.0, 12.0, 6)
    model.cabin_mass_kg = 30500.0
    path = tmp_path / "model.yaml"
    model.save(str(path), "edited in Python")
    again = fastcal.Model.load(str(path))
    np.testing.assert_array_equal(again.mass_centre_cabin_m, [0.22, 0.11, 0.5])
    np.testing.assert_array_equal(again.linear_density_kg_per_m, np.linspace(11.0, 12.0, 6))
    assert again.cabin_mass_kg == 30500.0
    assert path.read_text().startswith("# edited in Python")


def test_wrong_shape_is_an_input_error_naming_the_field() -> None:
    model = fastcal.Model.nominal()
    with pytest.raises(fastcal.InputError, match="ea_n must have shape \\(6,\\)"):
        model.ea_n = [1.0, 2.0]
    with pytest.raises(ValueError, match="mass_centre_cabin_m"):
        model.mass_centre_cabin_m = [0.0, 0.0]


def test_bad_model_file_names_file_and_key(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("cabin:\n  mass_kg: -5\n")
    with pytest.raises(fastcal.InputError, match="bad.yaml") as raised:
        fastcal.Model.load(str(path))
    assert "mass_kg" in str(raised.value)
    assert isinstance(raised.value, fastcal.Error)
    with pytest.raises(fastcal.InputError, match="absent.yaml"):
        fastcal.Model.load(str(tmp_path / "absent.yaml"))


def test_stray_comma_is_a_syntax_error_not_a_hang(tmp_path: pathlib.Path) -> None:
    # yaml-cpp 0.7's LoadAll looped without end on this (docs/hardening.md); the module
    # reads through the same guarded reader as the command line.
    path = tmp_path / "comma.yaml"
    path.write_text("{format: fastcal-model-1, gravity_m_per_s2: -9.8},")
    with pytest.raises(fastcal.InputError, match=r"comma\.yaml:1: YAML syntax error: unexpected ','"):
        fastcal.Model.load(str(path))


def test_validate_names_the_key() -> None:
    model = fastcal.Model.nominal()
    model.ea_n = [2.4656e7, 2.4656e7, -1.0, 2.4656e7, 2.4656e7, 2.4656e7]
    with pytest.raises(fastcal.InputError, match=r"cables\[2\]\.ea_n"):
        model.validate()


def test_attachments_round_trip_and_change_the_tensions(tmp_path: pathlib.Path) -> None:
    model = fastcal.Model.nominal()
    assert model.attachments == [[], [], [], [], [], []]
    built = [[{"at_m": 4.0, "mass_kg": 450.0},
              {"from_m": 0.0, "to_m": 160.0, "added_density_kg_per_m": 1.0}]] + [[]] * 5
    model.attachments = built
    assert model.attachments == built
    path = tmp_path / "built.yaml"
    model.save(str(path))
    assert fastcal.Model.load(str(path)).attachments == built
    with pytest.raises(fastcal.InputError, match=r"attachments\[0\]\[0\]\.mass_kg"):
        model.attachments = [[{"at_m": 1.0, "mass_kg": -5.0}]] + [[]] * 5
    with pytest.raises(fastcal.InputError, match="exactly the keys"):
        model.attachments = [[{"at_m": 1.0}]] + [[]] * 5
    assert model.attachments == built  # a refused assignment changes nothing
