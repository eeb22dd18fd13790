"""fastcal.Model: the nominal model, its file, and its fields as numbers."""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

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
    np.testing.assert_array_equal(model.mass_centre_m, [0.0, 0.0, 0.5])
    assert model.anchor_points_cabin_m.shape == (3, 3)
    assert model.tower_top_m.shape == (6, 3)
    np.testing.assert_array_equal(model.tower_top_m[:, 2], np.full(6, 270.0))
    np.testing.assert_array_equal(model.anchor_index, [0, 0, 1, 1, 2, 2])
    np.testing.assert_array_equal(model.ea_n, np.full(6, 2.4656e7))
    np.testing.assert_array_equal(model.linear_density_kg_per_m, np.full(6, 11.718))
    np.testing.assert_array_equal(model.sensor_gain, np.ones(6))
    np.testing.assert_array_equal(model.sensor_bias_kN, np.zeros(6))


def test_sensor_bias_is_in_kn_like_every_tension_and_the_old_name_says_so(
    tmp_path: pathlib.Path,
) -> None:
    model = fastcal.Model.nominal()
    model.sensor_bias_kN = [1.5, 0, 0, 0, 0, -2]
    path = tmp_path / "model.yaml"
    model.save(str(path), "biased")
    assert "sensor_bias_kN: 1.5\n" in path.read_text()  # the file's key and unit
    np.testing.assert_array_equal(fastcal.Model.load(str(path)).sensor_bias_kN, model.sensor_bias_kN)
    with pytest.raises(AttributeError, match="now Model.sensor_bias_kN"):
        model.sensor_bias_n
    with pytest.raises(AttributeError, match="now Model.sensor_bias_kN"):
        model.sensor_bias_n = np.zeros(6)


def test_the_build_names_its_interpreter_and_runs_it() -> None:
    """build/python/python3 runs the interpreter the module was built for (docs/python.md)."""
    from fastcal import _build  # the build tree's record; not installed

    assert os.path.samefile(_build.PYTHON, sys.executable)
    runner = pathlib.Path(fastcal.__file__).parents[1] / "python3"
    out = subprocess.run(
        [str(runner), "-c", "import fastcal; print(fastcal.Model.nominal().sensor_bias_kN.sum())"],
        env={"PATH": "/nonexistent"},  # whatever python3 is on PATH does not matter
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout == "0.0\n"


@pytest.mark.parametrize("installed", [False, True])
def test_an_interpreter_without_numpy_is_told_so(installed: bool) -> None:
    """Issue 59: under an interpreter without numpy, the installed package said only 'No
    module named numpy'. numpy is hidden from a child interpreter (and, for the installed
    package, the build tree's record too)."""
    hide = "import sys; sys.modules['numpy'] = None"
    if installed:
        hide += "; sys.modules['fastcal._build'] = None"
    package = pathlib.Path(fastcal.__file__).parents[1]
    out = subprocess.run(
        [sys.executable, "-c", hide + "; import fastcal"],
        env={"PYTHONPATH": str(package), "PATH": "/nonexistent"},
        capture_output=True,
        text=True,
    )
    assert out.returncode != 0
    assert "fastcal needs numpy" in out.stderr, out.stderr
    assert sys.executable in out.stderr, out.stderr
    assert "python3-numpy" in out.stderr, out.stderr
    assert ("it was built for" in out.stderr) != installed, out.stderr


def test_a_missing_file_is_file_not_found_as_open_raises(
    tmp_path: pathlib.Path, data_dir: pathlib.Path
) -> None:
    missing = tmp_path / "nowhere.yaml"
    with pytest.raises(FileNotFoundError) as raised:
        fastcal.Model.load(str(missing))
    assert isinstance(raised.value, OSError)
    assert raised.value.filename == str(missing)
    with pytest.raises(FileNotFoundError, match="no such dataset file"):
        fastcal.read_dataset(tmp_path / "nowhere.csv")
    with pytest.raises(FileNotFoundError, match="no such spec file"):
        fastcal.calibrate(missing, data_dir / "circle_paper.csv")
    # A file that exists but is wrong stays an InputError (a ValueError).
    bad = tmp_path / "bad.yaml"
    bad.write_text("cabin:\n  mass_kg: 30\n")
    with pytest.raises(fastcal.InputError, match="tonnes written as kg"):
        fastcal.Model.load(str(bad))


def test_fields_are_set_by_whole_arrays(tmp_path: pathlib.Path) -> None:
    model = fastcal.Model.nominal()
    model.mass_centre_m = [0.22, 0.11, 0.5]
    model.linear_density_kg_per_m = np.linspace(11.0, 12.0, 6)
    model.cabin_mass_kg = 30500.0
    path = tmp_path / "model.yaml"
    model.save(str(path), "edited in Python")
    again = fastcal.Model.load(str(path))
    np.testing.assert_array_equal(again.mass_centre_m, [0.22, 0.11, 0.5])
    np.testing.assert_array_equal(again.linear_density_kg_per_m, np.linspace(11.0, 12.0, 6))
    assert again.cabin_mass_kg == 30500.0
    assert path.read_text().startswith("# edited in Python")


def test_wrong_shape_is_an_input_error_naming_the_field() -> None:
    model = fastcal.Model.nominal()
    with pytest.raises(fastcal.InputError, match="ea_n must have shape \\(6,\\)"):
        model.ea_n = [1.0, 2.0]
    with pytest.raises(ValueError, match="mass_centre_m"):
        model.mass_centre_m = [0.0, 0.0]


def test_bad_model_file_names_file_and_key(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("cabin:\n  mass_kg: -5\n")
    with pytest.raises(fastcal.InputError, match="bad.yaml") as raised:
        fastcal.Model.load(str(path))
    assert "mass_kg" in str(raised.value)
    assert isinstance(raised.value, fastcal.Error)
    with pytest.raises(FileNotFoundError, match="absent.yaml"):  # as open() raises
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
    # The setter runs the reader's checks: the value is refused where it is assigned.
    with pytest.raises(fastcal.InputError, match=r"model: ea_n\[2\]: must be > 0"):
        model.ea_n = [2.4656e7, 2.4656e7, -1.0, 2.4656e7, 2.4656e7, 2.4656e7]
    model.validate()  # unchanged: still the nominal model


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
