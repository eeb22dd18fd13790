"""Datasets: reading the bundled telemetry, errors as the CLI words them, simulation."""

from __future__ import annotations

import pathlib
import subprocess
from typing import Optional

import numpy as np
import pytest

import fastcal


def test_reads_the_bundled_circle(data_dir: pathlib.Path) -> None:
    data = fastcal.read_dataset(data_dir / "circle_paper.csv")
    assert len(data) == 360
    assert data.position_m.shape == (360, 3)
    assert data.rpy_deg.shape == (360, 3)
    assert data.quat.shape == (360, 4)
    assert data.tension_kN.shape == (360, 6)
    assert data.planned_rpy_deg.shape == (360, 3)
    assert data.s0_m.shape == (360, 6)
    assert data.time_s.shape == (360,)
    assert data.line[0] == 5  # after three comment lines and the header
    # The first row as the file gives it.
    first = (data_dir / "circle_paper.csv").read_text().splitlines()[4].split(",")
    assert data.position_m[0, 0] == float(first[1])
    assert data.tension_kN[0, 0] == float(first[10])


def cli_error(cli: Optional[str], args: list) -> Optional[str]:
    """The CLI's message for the same input ("fastcal <command>: <message>")."""
    if cli is None:
        return None
    run = subprocess.run([cli, *args], capture_output=True, text=True, check=False)
    assert run.returncode == 2, run.stderr
    return run.stderr.strip().split(": ", 1)[1]


def test_bad_value_names_file_line_and_column_as_the_cli_does(
    tmp_path: pathlib.Path, data_dir: pathlib.Path, cli: Optional[str]
) -> None:
    rows = (data_dir / "circle_paper.csv").read_text().splitlines()[:8]
    fields = rows[6].split(",")
    fields[12] = "abc"
    rows[6] = ",".join(fields)
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(fastcal.InputError) as raised:
        fastcal.read_dataset(path)
    message = str(raised.value)
    assert message == f"{path}:7: column 'T3_kN': 'abc' is not a number"
    expected = cli_error(cli, ["evaluate", f"--data={path}"])
    if expected is not None:
        assert message == expected
    skipped = fastcal.read_dataset(path, skip_invalid_rows=True)
    assert len(skipped) == 3 and len(skipped.skipped) == 1


def test_attitudes_in_radians_are_refused_as_the_cli_does(
    tmp_path: pathlib.Path, data_dir: pathlib.Path, cli: Optional[str]
) -> None:
    rows = []
    for row in (data_dir / "circle_paper.csv").read_text().splitlines():
        fields = row.split(",")
        if not row.startswith(("#", "time_s")):  # radians under roll_deg, pitch_deg, yaw_deg
            fields[4:7] = [repr(float(np.radians(float(v)))) for v in fields[4:7]]
        rows.append(",".join(fields))
    path = tmp_path / "radians.csv"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(fastcal.InputError) as raised:
        fastcal.read_dataset(path)
    message = str(raised.value)
    assert message.startswith(f"{path}: roll_deg, pitch_deg, yaw_deg look like radians: ")
    assert message.endswith("write degrees (radians x 57.2958)")
    expected = cli_error(cli, ["evaluate", f"--data={path}"])
    if expected is not None:
        assert message == expected


def test_simulate_is_reproducible_and_round_trips(tmp_path: pathlib.Path) -> None:
    truth = fastcal.Model.nominal()
    truth.mass_centre_m = [0.22, 0.11, 0.5]
    p = fastcal.arc(centre_m=(0, 0, 156.73), radius_m=71.11, nodes=24)
    q = fastcal.focal_attitude(p)
    data, used, summary = fastcal.simulate(
        p, quat=q, model=truth, seed=3, tension_noise_percent=1.0
    )
    again, _, _ = fastcal.simulate(p, quat=q, model=truth, seed=3, tension_noise_percent=1.0)
    np.testing.assert_array_equal(data.tension_kN, again.tension_kN)
    assert summary["samples"] == 24 and summary["tension_noise_rms_kN"].shape == (6,)
    np.testing.assert_array_equal(used.mass_centre_m, [0.22, 0.11, 0.5])
    # Noise-free, the readings are the truth's tensions.
    clean, _, _ = fastcal.simulate(p, quat=q, model=truth, tension_noise_percent=0.0)
    exact = fastcal.solve(p, rpy_deg=clean.planned_rpy_deg, model=truth)
    np.testing.assert_allclose(clean.tension_kN, exact.lower_tension_kN, rtol=1e-12)
    path = tmp_path / "sim.csv"
    data.save(str(path), "simulated in a test")
    read = fastcal.read_dataset(path)
    np.testing.assert_array_equal(read.tension_kN, data.tension_kN)
    with pytest.raises(fastcal.InputError, match="unknown option 'noise'"):
        fastcal.simulate(p, quat=q, noise=3)
    with pytest.raises(fastcal.InputError, match="outlier_fraction"):
        fastcal.simulate(p, quat=q, outlier_fraction=2.0)
