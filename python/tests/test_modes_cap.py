"""fastcal.modes_cap: the modes over the cap as `fastcal modes --cap` writes them (issue
59: the command had no Python equivalent), the same numbers as the CLI's CSV; bad options
named."""
import io
import os
import subprocess

import pandas
import pytest

import fastcal

GRID = dict(max_off_axis_deg=10, off_axis_step_deg=10, azimuth_step_deg=180)


def test_the_cap_is_the_commands_csv(tmp_path) -> None:
    frame = fastcal.modes_cap(segments=12, count=6, **GRID)
    assert len(frame) == 3  # the axis, and the 10 deg ring at azimuths 0 and 180
    assert list(frame.columns[:3]) == ["off_axis_deg", "azimuth_deg", "x_m"]
    assert (frame.status == "ok").all()
    assert frame.lowest_hz.between(0.1, 0.3).all()
    binary = os.environ.get("FASTCAL_BIN")
    if not binary:
        pytest.skip("FASTCAL_BIN unset: the comparison with the command line needs it")
    out = tmp_path / "cap.csv"
    subprocess.run([binary, "modes", "--cap", "--max-off-axis-deg=10", "--off-axis-step-deg=10",
                    "--azimuth-step-deg=180", "--segments=12", "--modes=6",
                    "--output=" + str(out)], check=True, capture_output=True)
    cli = pandas.read_csv(out, keep_default_na=False, na_values=[""])
    pandas.testing.assert_frame_equal(frame, cli)


def test_bad_options_are_named() -> None:
    with pytest.raises(fastcal.InputError, match="azimuth"):
        fastcal.modes_cap(max_off_axis_deg=10, off_axis_step_deg=10, azimuth_step_deg=0,
                          segments=12, count=6)
    with pytest.raises(fastcal.InputError, match="segments"):
        fastcal.modes_cap(segments=1, **GRID)
