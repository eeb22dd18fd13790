"""Sessions and the change scan from Python: two surveys as two files, a joint fit with
a mass centre per session, and a step found within one survey."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import fastcal

SPEC_SEPARATE = {
    "parameters": {
        "mass_centre_m": {"x": {"free": True}, "y": {"free": True}, "z": {"free": True}}
    },
    "sessions": {"separate": ["mass_centre_m"]},
}


def _circle(nodes: int) -> np.ndarray:
    angle = np.linspace(0.0, 2.0 * np.pi, nodes, endpoint=False)
    return np.column_stack([71.11 * np.cos(angle), 71.11 * np.sin(angle), np.full(nodes, 156.73)])


def _survey(mass_centre_m, seed: int, **options) -> fastcal.Dataset:
    positions = _circle(120)
    truth = fastcal.Model.nominal()
    truth.mass_centre_m = np.asarray(mass_centre_m, dtype=float)
    data, _, _ = fastcal.simulate(
        positions, quat=fastcal.focal_attitude(positions), model=truth, seed=seed, **options
    )
    return data


def test_two_files_are_two_sessions_and_the_joint_fit_finds_the_move(
    tmp_path: pathlib.Path,
) -> None:
    _survey([0.2, 0.0, 0.5], 1).save(str(tmp_path / "before.csv"))
    _survey([0.26, 0.0, 0.5], 2).save(str(tmp_path / "after.csv"))
    data = fastcal.read_dataset([tmp_path / "before.csv", tmp_path / "after.csv"])
    assert data.session_labels == ["before", "after"]
    assert list(np.bincount(data.session)) == [120, 120]
    result = fastcal.calibrate(SPEC_SEPARATE, data)
    assert result.sessions == ["before", "after"]
    assert set(result.session_models) == {"before", "after"}
    assert "mass_centre_m.x@after" in result.free_names
    x = [d for d in result.session_differences if d["name"] == "mass_centre_m.x"][0]
    assert (x["from"], x["to"]) == ("before", "after")
    assert abs(x["difference"] - 0.06) < 4.0 * x["sigma_total"]
    assert x["difference"] / x["sigma_total"] > 3.0
    after = result.session_models["after"].mass_centre_m
    assert after[0] == pytest.approx(result.estimates["mass_centre_m.x@after"])
    assert "moved mass_centre_m.x" in result.verdict_text
    assert result.change_scan is None and result.changes == []


def test_the_same_label_twice_is_refused(tmp_path: pathlib.Path) -> None:
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    _survey([0.2, 0.0, 0.5], 1).save(str(tmp_path / "a" / "day.csv"))
    _survey([0.2, 0.0, 0.5], 2).save(str(tmp_path / "b" / "day.csv"))
    with pytest.raises(fastcal.InputError, match="session 'day' is in both"):
        fastcal.read_dataset([tmp_path / "a" / "day.csv", tmp_path / "b" / "day.csv"])


def test_simulated_sessions_and_a_step_found_by_the_scan() -> None:
    data = _survey([0.2, 0.0, 0.5], 3, sessions=3)
    assert data.session_labels == ["1", "2", "3"]
    stepped = _survey([0.2, 0.0, 0.5], 4, mass_centre_steps=[(60.0, (0.08, 0.0, 0.0))])
    spec = {
        "parameters": SPEC_SEPARATE["parameters"],
        "change_scan": {"parameters": ["mass_centre_m"], "min_segment_samples": 20},
    }
    result = fastcal.calibrate(spec, stepped)
    assert result.change_scan is not None
    assert len(result.change_scan["time_s"]) == len(result.change_scan["statistic"])
    assert len(result.changes) == 1
    change = result.changes[0]
    assert abs(change["time_s"] - 60.0) <= 6.0
    shift = change["shifts"]["mass_centre_m.x"]
    assert abs(shift - 0.08) < 4.0 * change["shift_sigmas"]["mass_centre_m.x"]
