"""fastcal.calibrate and fastcal.evaluate: the bundled circle as the CLI calibrates it."""

from __future__ import annotations

import json
import pathlib
import subprocess
from typing import Optional

import numpy as np
import pytest

import fastcal

# calibration_data/circle_paper.truth.yaml
TRUTH_MASS_CENTRE_M = (0.22, 0.11, 0.5)
# Formal sigmas are ~2 mm on x, y for 360 samples at 3% noise; the truth within 4 sigma.
COVERAGE_SIGMAS = 4.0

SPEC_DICT = {
    "format": "fastcal-calibration-spec-1",
    "forward_model": "exact",
    "noise": {"tension_sigma_kN": 0, "tension_sigma_percent": 3},
    "parameters": {
        "mass_centre_m": {"x": {"free": True}, "y": {"free": True}, "z": {"free": True}},
        "linear_density_kg_per_m": {"mode": "common", "free": True},
    },
}


@pytest.fixture(scope="module")
def circle(data_dir: pathlib.Path) -> fastcal.Dataset:
    return fastcal.read_dataset(data_dir / "circle_paper.csv")


@pytest.fixture(scope="module")
def result(data_dir: pathlib.Path, circle: fastcal.Dataset) -> fastcal.CalibrationResult:
    return fastcal.calibrate(data_dir / "spec_mass_centre_density.yaml", circle)


def test_estimates_sigmas_and_tables(result: fastcal.CalibrationResult) -> None:
    assert result.verdict == "ok" and result.converged
    assert result.free_names == [
        "mass_centre_m.x",
        "mass_centre_m.y",
        "mass_centre_m.z",
        "linear_density_kg_per_m",
    ]
    for axis, truth in zip("xy", TRUTH_MASS_CENTRE_M):
        name = f"mass_centre_m.{axis}"
        assert abs(result.estimates[name] - truth) < COVERAGE_SIGMAS * result.sigma_total[name]
        assert result.sigma_total[name] >= result.sigma[name] > 0
    assert result.correlation.shape == (4, 4)
    np.testing.assert_allclose(np.diag(result.correlation), 1.0)
    table = {p["name"]: p for p in result.parameters}
    assert table["mass_centre_m.x"]["unit"] == "m"
    assert set(table["mass_centre_m.x"]) >= {"sigma_statistical", "sigma_systematic", "widening"}
    assert result.outliers == []
    assert result.misfit_ranking and "expected_chi_square_decrease" in result.misfit_ranking[0]
    assert set(result.rms_kN) == {
        "initial model, planned attitude",
        "initial model, measured attitude",
        "calibrated model, measured attitude",
    }
    before = result.rms_kN["initial model, measured attitude"]
    after = result.rms_kN["calibrated model, measured attitude"]
    assert after.shape == (6,) and (after < before).all()
    np.testing.assert_array_equal(result.model.mass_centre_m[:2], [
        result.estimates["mass_centre_m.x"], result.estimates["mass_centre_m.y"]])


def test_same_as_the_command_line(
    result: fastcal.CalibrationResult,
    data_dir: pathlib.Path,
    tmp_path: pathlib.Path,
    cli: Optional[str],
) -> None:
    if cli is None:
        pytest.skip("the fastcal command line was not built")
    out = tmp_path / "out"
    subprocess.run(
        [
            cli,
            "calibrate",
            "--quiet",
            f"--spec={data_dir / 'spec_mass_centre_density.yaml'}",
            f"--data={data_dir / 'circle_paper.csv'}",
            f"--out={out}",
        ],
        check=True,
        capture_output=True,
    )
    summary = json.loads((out / "summary.json").read_text())
    for p in summary["parameters"]:
        # summary.json keeps 12 significant digits.
        assert result.estimates[p["name"]] == pytest.approx(p["estimate"], rel=1e-11)
        assert result.sigma_total[p["name"]] == pytest.approx(p["sigma_total"], rel=1e-11)
    for row in summary["evaluation"]:
        np.testing.assert_allclose(result.rms_kN[row["name"]], row["fit"]["rms_kN"], rtol=1e-11)


def test_spec_as_a_dict_is_the_same_spec(
    result: fastcal.CalibrationResult, circle: fastcal.Dataset
) -> None:
    from_dict = fastcal.calibrate(SPEC_DICT, circle)
    assert from_dict.estimates == result.estimates


def test_evaluate_agrees_with_the_calibration(
    result: fastcal.CalibrationResult, circle: fastcal.Dataset
) -> None:
    table = fastcal.evaluate(circle, model=result.model)
    assert set(table) == {"model, planned attitude", "model, measured attitude"}
    np.testing.assert_allclose(
        table["model, measured attitude"]["fit"]["rms_kN"],
        result.rms_kN["calibrated model, measured attitude"],
        rtol=1e-12,
    )
    assert table["model, measured attitude"]["predicted_kN"].shape == (360, 6)


def test_undetermined_free_set_is_refused_with_the_combination(circle: fastcal.Dataset) -> None:
    spec = {
        "format": "fastcal-calibration-spec-1",
        "parameters": {
            "cabin_mass_kg": {"free": True},
            "linear_density_kg_per_m": {"free": True},
            "ea_n": {"free": True},
            "sensor_gain": {"free": True},
        },
    }
    with pytest.raises(fastcal.CalibrationError) as raised:
        fastcal.calibrate(spec, circle)
    assert raised.value.status == "undetermined"
    assert "cannot determine" in str(raised.value) and "sensor_gain" in str(raised.value)
    assert isinstance(raised.value, RuntimeError)


def test_spec_with_a_stray_comma_is_a_syntax_error_not_a_hang(
    tmp_path: pathlib.Path, circle: fastcal.Dataset
) -> None:
    # yaml-cpp 0.7's LoadAll looped without end on this (docs/hardening.md).
    path = tmp_path / "spec.yaml"
    path.write_text("{format: fastcal-calibration-spec-1},")
    with pytest.raises(fastcal.InputError, match=r"spec\.yaml:1: YAML syntax error: unexpected ','"):
        fastcal.calibrate(path, circle)


def test_bad_spec_names_file_line_and_key_as_the_cli_does(
    tmp_path: pathlib.Path, data_dir: pathlib.Path, circle: fastcal.Dataset, cli: Optional[str]
) -> None:
    path = tmp_path / "spec.yaml"
    path.write_text(
        "format: fastcal-calibration-spec-1\n"
        "parameters:\n  mass_centre_m:\n    x: {free: yes, sigma: 1}\n"
    )
    with pytest.raises(fastcal.InputError) as raised:
        fastcal.calibrate(path, circle)
    message = str(raised.value)
    assert message.startswith(f"{path}:4")
    assert "sigma" in message
    if cli is not None:
        run = subprocess.run(
            [cli, "calibrate", f"--spec={path}", f"--data={data_dir / 'circle_paper.csv'}",
             f"--out={tmp_path / 'out'}"],
            capture_output=True, text=True, check=False,
        )
        assert run.returncode == 2
        assert run.stderr.strip() == f"fastcal calibrate: {message}"
    with pytest.raises(fastcal.InputError, match=r"^spec \(dict\): parameters\.mass: unknown"):
        fastcal.calibrate(
            {"format": "fastcal-calibration-spec-1", "parameters": {"mass": 1}}, circle
        )
