"""Python in a notebook (issue 39): progress on stderr (quiet=True silences it), the
report as the command line writes it, DataFrames of datasets and results, and the
track's events with the ISO times events.json has."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import fastcal

SPEC = {
    "format": "fastcal-calibration-spec-1",
    "noise": {"tension_sigma_percent": 3},
    "parameters": {"mass_centre_m": {"x": {"free": True}, "y": {"free": True},
                                     "z": {"free": True}}},
}


@pytest.fixture(scope="module")
def survey() -> fastcal.Dataset:
    positions = fastcal.random_workspace(120, seed=4)
    data, _, _ = fastcal.simulate(positions, quat=fastcal.focal_attitude(positions), seed=4)
    return data


def test_progress_goes_to_stderr_unless_quiet(survey: fastcal.Dataset, capsys) -> None:
    fastcal.calibrate(SPEC, survey)
    assert "fastcal.calibrate: " in capsys.readouterr().err
    fastcal.calibrate(SPEC, survey, quiet=True)
    assert "fastcal.calibrate" not in capsys.readouterr().err


def test_report_and_dataframes(survey: fastcal.Dataset, tmp_path: pathlib.Path) -> None:
    pytest.importorskip("pandas", reason="python3-pandas is not installed")
    result = fastcal.calibrate(SPEC, survey, quiet=True)
    html = result.report_html(tmp_path / "report.html")
    assert html.startswith("<!DOCTYPE html>") and "<svg" in html
    assert (tmp_path / "report.html").read_text(encoding="utf-8") == html
    with pytest.raises(FileExistsError):
        result.report_html(tmp_path / "report.html")  # never over a file
    assert "mass_centre_m.z" in result.report_markdown()
    table = result.to_dataframe()
    assert table.loc["mass_centre_m.z", "estimate"] == result.estimates["mass_centre_m.z"]
    assert table.loc["mass_centre_m.z", "sigma_total"] == result.sigma_total["mass_centre_m.z"]
    frame = survey.to_dataframe()
    assert list(frame.columns[:4]) == ["time_s", "x_m", "y_m", "z_m"]
    np.testing.assert_array_equal(frame[[f"T{i}_kN" for i in range(1, 7)]].to_numpy(),
                                  survey.tension_kN)
    # Round trip: the DataFrame reads back as the same samples (through text in kN and
    # back to N: a rounding each way).
    kRoundTrip = 1e-15
    back = fastcal.Dataset.from_dataframe(frame.drop(columns=["line"]))
    np.testing.assert_allclose(back.tension_kN, survey.tension_kN, rtol=kRoundTrip, atol=0)


def test_track_events_carry_iso_times(tmp_path: pathlib.Path, cli) -> None:
    if not cli:
        pytest.skip("the fastcal executable (FASTCAL_BIN) is not set")
    import subprocess

    season = tmp_path / "season.csv"
    subprocess.run(
        [cli, "simulate", "--trajectory=random", "--samples=2400", "--days=4",
         "--interval-s=2", "--start=2024-05-01T20:00:00Z", "--mass-centre=0.22,0.11,0.5",
         "--mass-centre-step=2024-05-03T20:00:00Z:0.05,0,0", "--seed=3", f"--out={season}"],
        check=True, capture_output=True)
    spec = pathlib.Path(__file__).parents[2] / "calibration_data" / "spec_track.yaml"
    result = fastcal.track(season, spec, tmp_path / "track", quiet=True)
    assert result.events, "the 5 cm move is found"
    event = result.events[0]
    assert event["time"].startswith("2024-05-03T")
    assert event["after"].startswith("2024-05-02T")
    frame = result.to_dataframe()
    assert len(frame) == len(result.windows)
    assert "mass_centre_m.x_sigma_total" in frame.columns
    # Issue 59: every column of track.csv (its bounds as the index), and dates that line
    # up with the data's.
    header = (tmp_path / "track" / "track.csv").read_text().splitlines()
    header = [line for line in header if not line.startswith("#")][0].split(",")
    missing = set(header) - set(frame.columns) - {"window_start", "window_end"}
    assert not missing, missing
    assert str(frame.index.tz) == "UTC"
    assert frame.index[0].isoformat().startswith("2024-05-01T00:00:00")
    assert list(frame["window"]) == [w["label"] for w in result.windows]
    data = fastcal.read_dataset(season).to_dataframe()
    assert data.index.name == "time" and str(data.index.tz) == "UTC"
    assert data.index[0].isoformat().startswith("2024-05-01T20:00:00")
    assert data.index[0] >= frame.index[0]  # the same axis: plotting events on it works
