"""The cabin's moving parts from Python (issue 35): the model's joint columns, the mass
centre at the joints, a dataset's joints, and a calibration that finds the rotator's
first moment, with the same names as the command line."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import fastcal


@pytest.fixture
def model(data_dir: pathlib.Path) -> fastcal.Model:
    return fastcal.Model.load(str(data_dir / "moving_parts.yaml"))


def test_joint_columns_and_mass_centre(model: fastcal.Model) -> None:
    assert model.joint_columns == [
        "rotator_a_deg",
        "rotator_b_deg",
        "stewart_x_m",
        "stewart_y_m",
        "stewart_z_m",
    ]
    np.testing.assert_array_equal(model.mass_centre_at([0, 0, 0, 0, 0]), [0, 0, 0.5])
    # A 90 deg turn about x takes the first moment (0, 0, -6000) kg m to (0, 6000, 0).
    shift = model.mass_centre_at([90, 0, 0, 0, 0]) - np.array([0, 0, 0.5])
    np.testing.assert_allclose(shift, np.array([0, 6000, 6000]) / 30000, atol=1e-15)
    with pytest.raises(fastcal.InputError, match="5 joints"):
        model.mass_centre_at([1, 2])


def test_survey_calibrates_the_first_moment(
    model: fastcal.Model, data_dir: pathlib.Path, tmp_path: pathlib.Path
) -> None:
    # 432 poses, the rotator through the 9 pairs of -15, 0, 15 deg: its first moment's z
    # (-6000 kg m, across both axes) is found within 2.5 sigma_total.
    csv = tmp_path / "survey.csv"
    cli = os.environ.get("FASTCAL_BIN")
    if not cli:
        pytest.skip("the fastcal executable (FASTCAL_BIN) is not set")
    subprocess.run(
        [cli, "simulate", f"--truth={data_dir / 'moving_parts.yaml'}", "--trajectory=random",
         "--samples=432", "--seed=4", "--joint-law=grid", "--prismatic-spread-m=0.05",
         f"--out={csv}"],
        check=True, capture_output=True)
    data = fastcal.read_dataset(csv, model=model)
    assert data.joint_columns == model.joint_columns
    assert data.joints.shape == (432, 5)
    with pytest.raises(fastcal.InputError, match="unknown column 'rotator_a_deg'"):
        fastcal.read_dataset(csv)
    # The start: the first moment unknown (0), as the spec's prior.
    text = (data_dir / "moving_parts.yaml").read_text().replace("[0, 0, -6000]", "[0, 0, 0]")
    (tmp_path / "start.yaml").write_text(text)
    start = fastcal.Model.load(str(tmp_path / "start.yaml"))
    result = fastcal.calibrate(data_dir / "spec_moving_parts.yaml", csv, model=start)
    name = "moving_parts.rotator.first_moment_kg_m.z"
    assert abs(result.estimates[name] + 6000) < 2.5 * result.sigma_total[name]
    assert result.sigma_total[name] <= 500
    assert "moving_parts.stewart.mass_kg" in result.free_names
