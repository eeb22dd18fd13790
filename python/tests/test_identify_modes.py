"""fastcal.identify_modes: modes identified from a record and compared with the
prediction, as `fastcal modes --data` writes them (issue 59: the command had no Python
equivalent): the same CSV as the command line's, its verdict in attrs; bad input named."""
import os
import subprocess

import pandas
import pytest

import fastcal


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    binary = os.environ.get("FASTCAL_BIN")
    if not binary:
        pytest.skip("FASTCAL_BIN unset: the record is made by fastcal simulate --vibration")
    path = tmp_path_factory.mktemp("vibration") / "decay.csv"
    subprocess.run([binary, "simulate", "--vibration", "--position=102.846,0,177.433",
                    "--attitude-law=focal", "--excite=2,7,18", "--out=" + str(path)],
                   check=True, capture_output=True)
    return path


def test_the_modes_are_the_commands_csv(record, tmp_path) -> None:
    frame = fastcal.identify_modes(record, segments=24)
    assert len(frame) == 3
    assert frame.attrs["method"] == "era"  # a free decay
    assert frame.attrs["agrees"]  # made with the nominal model
    assert set(frame.attrs["fits"]) == {"linear_density", "cabin_mass", "cabin_inertia"}
    out = tmp_path / "identified.csv"
    subprocess.run([os.environ["FASTCAL_BIN"], "modes", "--data=" + str(record),
                    "--segments=24", "--output=" + str(out)], check=True, capture_output=True)
    pandas.testing.assert_frame_equal(frame, pandas.read_csv(out))


def test_bad_input_is_named(record, tmp_path) -> None:
    with pytest.raises(fastcal.InputError, match="identification"):
        fastcal.identify_modes(record, identification="fft")
    with pytest.raises(FileNotFoundError):
        fastcal.identify_modes(tmp_path / "missing.csv")
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,x_m\n0,1\n")
    with pytest.raises(fastcal.InputError, match="bad.csv"):
        fastcal.identify_modes(bad)
