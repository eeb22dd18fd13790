"""A season tracked from Python: on this machine's threads and on a two-worker Dask
LocalCluster on the loopback interface, with the same numbers; the step and the
re-zeroed sensor found; an update with a new day; dask's absence named."""

from __future__ import annotations

import builtins
import json
import pathlib
import sys

import numpy as np
import pytest

import fastcal

START_S = 1714593600.0  # 2024-05-01T20:00:00Z
DAY_S = 86400.0
DAYS = 6
PER_DAY = 240
INTERVAL_S = 20.0


def _season(path: pathlib.Path, days: int = DAYS) -> None:
    """`days` days of PER_DAY samples from 20:00 UTC, the mass centre moved before day 2
    and cable 5's sensor re-zeroed before day 4."""
    positions = fastcal.random_workspace(samples=days * PER_DAY, seed=5)
    truth = fastcal.Model.nominal()
    truth.mass_centre_m = np.array([0.22, 0.11, 0.5])
    data, _, _ = fastcal.simulate(
        positions,
        quat=fastcal.focal_attitude(positions),
        model=truth,
        seed=9,
        interval_s=INTERVAL_S,
        start_time_s=START_S,
        sessions=days,
        session_gap_s=DAY_S - PER_DAY * INTERVAL_S,
        tension_drift_percent=1.0,
        tension_drift_time_s=120.0,
        sensor_gain_spread_percent=1.0,
        sensor_bias_spread_kN=1.5,
        mass_centre_steps=[(START_S + 2 * DAY_S - 3600.0, (0.05, 0.0, 0.0))],
        sensor_bias_steps=[(START_S + 4 * DAY_S - 3600.0, 5, 5.0)],
    )
    data.save(str(path))


@pytest.fixture(scope="module")
def season(tmp_path_factory: pytest.TempPathFactory) -> pathlib.Path:
    path = tmp_path_factory.mktemp("season") / "season.csv"
    _season(path)
    return path


@pytest.fixture(scope="module")
def spec(data_dir: pathlib.Path) -> pathlib.Path:
    return data_dir / "spec_track.yaml"


@pytest.fixture(scope="module")
def local(season: pathlib.Path, spec: pathlib.Path, tmp_path_factory) -> fastcal.TrackResult:
    out = tmp_path_factory.mktemp("local") / "track"
    return fastcal.track(season, spec, out=out)


def test_the_step_and_the_re_zeroed_sensor_are_found(local: fastcal.TrackResult) -> None:
    assert len(local.windows) == DAYS
    assert [w["label"] for w in local.windows][:2] == ["2024-05-01", "2024-05-02"]
    kinds = [(e["kind"], e["window"]) for e in local.events]
    assert kinds == [("parameter", "2024-05-03"), ("sensor", "2024-05-05")]
    step = local.events[0]["parameters"]["mass_centre_m.x"]
    assert abs(step["shift"] - 0.05) < 3 * step["sigma_total"]
    assert local.events[1]["cables"] == [5]
    x, sigma = local.estimates("mass_centre_m.x")
    assert x.shape == (DAYS,) and np.all(sigma > 0)
    written = json.loads((pathlib.Path(local.out) / "events.json").read_text())
    assert [e["time_s"] for e in written["events"]] == [e["time_s"] for e in local.events]
    assert (pathlib.Path(local.out) / "track.csv").read_text().startswith(
        "window_start,window_end,samples,mass_centre_m.x,mass_centre_m.x_sigma_total"
    )


# Debian's tornado 6.2 under distributed 2022.12 warns of its own event loop use.
@pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")
def test_dask_local_cluster_gives_the_same_track(
    local: fastcal.TrackResult, season: pathlib.Path, spec: pathlib.Path, tmp_path: pathlib.Path
) -> None:
    distributed = pytest.importorskip(
        "dask.distributed", reason="python3-dask and python3-distributed (scripts/setup.sh)"
    )
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
        processes=True,
    )
    try:
        with distributed.Client(cluster) as client:
            result = fastcal.track(season, spec, out=tmp_path / "dask", client=client)
    finally:
        cluster.close()
    assert result.folds == local.folds
    for name in ("track.csv", "events.json"):
        assert (tmp_path / "dask" / name).read_bytes() == (
            pathlib.Path(local.out) / name
        ).read_bytes(), name


def test_a_new_day_updates_the_track(spec: pathlib.Path, tmp_path: pathlib.Path) -> None:
    first = tmp_path / "first.csv"
    _season(first, days=3)
    out = tmp_path / "track"
    before = fastcal.track(first, spec, out=out)
    assert len(before.windows) == 3
    again = fastcal.track([first], spec, out=out)
    assert again.updated and again.folds == 0


def test_a_scheduler_address_without_dask_names_the_packages(
    season: pathlib.Path, spec: pathlib.Path, tmp_path: pathlib.Path, monkeypatch
) -> None:
    real_import = builtins.__import__

    def no_dask(name, *args, **kwargs):
        if name.startswith("dask"):
            raise ImportError(f"No module named '{name}'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_dask)
    for module in [m for m in sys.modules if m.startswith("dask") or m.startswith("distributed")]:
        monkeypatch.delitem(sys.modules, module)
    with pytest.raises(ImportError, match="python3-dask and python3-distributed"):
        fastcal.track(season, spec, out=tmp_path / "t", client="tcp://127.0.0.1:8786")


def test_bad_window_is_an_input_error(season: pathlib.Path, spec: pathlib.Path, tmp_path) -> None:
    with pytest.raises(fastcal.InputError, match="window '2x'"):
        fastcal.track(season, spec, out=tmp_path / "t", window="2x")


def test_bad_threads_is_an_input_error(season: pathlib.Path, spec: pathlib.Path, tmp_path) -> None:
    # A review (issue 37): 2**40 raised pybind11's raw TypeError, True was taken as 1.
    for threads in (2**40, True, 0, 2.5):
        with pytest.raises(fastcal.InputError, match="threads"):
            fastcal.track(season, spec, out=tmp_path / "t", threads=threads)
