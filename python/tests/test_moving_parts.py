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


def _survey(cli: str, truth: pathlib.Path, out: pathlib.Path, seed: int, samples: int) -> None:
    subprocess.run(
        [cli, "simulate", f"--truth={truth}", "--trajectory=random", f"--samples={samples}",
         f"--seed={seed}", "--joint-law=grid", f"--out={out}"],
        check=True, capture_output=True)


def test_dataframes_and_arrays_carry_the_joints(
    model: fastcal.Model, data_dir: pathlib.Path, tmp_path: pathlib.Path
) -> None:
    # The same samples from a file, from a DataFrame and from arrays: the same joints.
    pandas = pytest.importorskip("pandas")
    cli = os.environ.get("FASTCAL_BIN")
    if not cli:
        pytest.skip("the fastcal executable (FASTCAL_BIN) is not set")
    csv = tmp_path / "survey.csv"
    _survey(cli, data_dir / "moving_parts.yaml", csv, seed=5, samples=12)
    from_file = fastcal.read_dataset(csv, model=model)
    frame = pandas.read_csv(csv, comment="#")
    from_frame = fastcal.Dataset.from_dataframe(frame, model=model)
    np.testing.assert_array_equal(from_frame.joints, from_file.joints)
    with pytest.raises(fastcal.InputError, match="rotator_a_deg"):
        fastcal.Dataset.from_dataframe(frame)  # a joint column without a model to name it
    from_arrays = fastcal.Dataset.from_arrays(
        frame["time_s"], frame[["x_m", "y_m", "z_m"]],
        frame[[f"T{i}_kN" for i in range(1, 7)]],
        rpy_deg=frame[["roll_deg", "pitch_deg", "yaw_deg"]],
        joints=frame[model.joint_columns], model=model)
    np.testing.assert_array_equal(from_arrays.joints, from_file.joints)
    with pytest.raises(fastcal.InputError, match="needs model="):
        fastcal.Dataset.from_arrays([0], [[0, 0, 150]], [[170] * 6], rpy_deg=[[0, 0, 0]],
                                    joints=[[0] * 5])
    with pytest.raises(fastcal.InputError, match=r"joints= of shape \(1, 5\)"):
        fastcal.Dataset.from_arrays([0], [[0, 0, 150]], [[170] * 6], rpy_deg=[[0, 0, 0]],
                                    model=model)


def test_track_with_moving_parts_follows_the_joints(
    model: fastcal.Model, data_dir: pathlib.Path, tmp_path: pathlib.Path
) -> None:
    # Two days, the rotator through its grid: the track reads the joints with the model,
    # and each day's fixed mass centre is the truth's (0, 0, 0.5) within 3 sigma_total.
    # The joints ignored, the rotator's 6000 kg m turned 15 deg would move the centre 5 cm
    # sideways between samples, against a tension noise the fit expects: a reduced
    # chi-square far above 1.
    kSigmas = 3.0
    kMaxReducedChiSquare = 1.5
    cli = os.environ.get("FASTCAL_BIN")
    if not cli:
        pytest.skip("the fastcal executable (FASTCAL_BIN) is not set")
    days = []
    for seed in (1, 2):
        days.append(tmp_path / f"day{seed}.csv")
        _survey(cli, data_dir / "moving_parts.yaml", days[-1], seed=seed, samples=200)
    result = fastcal.track(days, data_dir / "spec_track.yaml", tmp_path / "track",
                           model=model, window="file")
    assert len(result.windows) == 2
    for w in result.windows:
        z = w["estimates"]["mass_centre_m.z"]
        assert abs(z["value"] - 0.5) < kSigmas * z["sigma_total"], w
        assert w["reduced_chi_square"] < kMaxReducedChiSquare, w
