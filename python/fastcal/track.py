"""Tracking over a season: the windows folded locally or on a Dask cluster."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _fastcal
from ._fastcal import CalibrationError, InputError, Model

from ._common import PathLike, _spec_argument, _whole
from .statics import ColumnsLike
from .dataset import _columns_argument, _map_errors


class TrackResult:
    """What fastcal.track found, as it wrote it in `out` (docs/calibration.md, "Tracking").

    Attributes:
        out: the track's directory (track.csv, events.json, track.html,
            model_calibrated@WINDOW.yaml, and the state an update reads).
        windows: one dict per window in time order: label, start_s, end_s (its bounds),
            first_time_s, last_time_s, samples, readings, gross_errors,
            reduced_chi_square, widening, folded (in this run), estimates (name ->
            {value, sigma_total, sigma_formal}, in the spec's units) and
            sensor_offset_kN (cable 1..6 -> the same, when the biases are shared).
        events: dicts of kind ('parameter' or 'sensor'), time_s (the first sample after
            the change: the later window's first, or its block's inside a window) and
            time (the same as events.json writes it, ISO 8601 for Unix times), after_s
            and after (the last before), time_low/time_high as text too, time_low_s and time_high_s (its likelihood
            interval), window, previous_window, within_window, new (not reported by the
            track's previous run; every event of a track built afresh), parts (a move
            inside a window: the window before and after it, each start_s, end_s,
            samples and estimates {name: {value, sigma_total}}, as track.csv's
            LABEL_before and LABEL_after rows; empty otherwise),
            parameters (name -> {shift, sigma_total, unit}), cables (for a sensor),
            statistic, degrees_of_freedom, threshold, p_value (family-wise).
        wander: per per-window group, its wander between windows beyond its errors
            (parameters, rms per component, unit; rms 0: none seen): the parameter
            events are steps beyond it.
        shared: the shared parameters (name, unit, estimate {value, sigma_total,
            sigma_formal}, from_window, to_window: a re-zeroed sensor's bias has one entry
            per stretch).
        window_parameters: the per-window parameters' names; files: the data files;
        models: the model files written; slow_error: what the slow error was found to be;
        samples, reduced_chi_square, iterations, converged, folds (computed in this
        run), updated (an existing track was updated), notes.
    """

    def __init__(self, raw: Dict[str, Any], out: str) -> None:
        self.out: str = out
        self.windows: List[Dict[str, Any]] = raw["windows"]
        self.events: List[Dict[str, Any]] = raw["events"]
        self._add_event_times()
        self.wander: List[Dict[str, Any]] = raw["wander"]
        self.shared: List[Dict[str, Any]] = raw["shared"]
        self.window_parameters: List[str] = raw["window_parameters"]
        self.files: List[str] = raw["files"]
        self.window: str = raw["window"]
        self.models: List[str] = raw["models"]
        self.slow_error: str = raw["slow_error"]
        self.samples: int = raw["samples"]
        self.reduced_chi_square: float = raw["reduced_chi_square"]
        self.iterations: int = raw["iterations"]
        self.converged: bool = raw["converged"]
        self.folds: int = raw["folds"]
        self.updated: bool = raw["updated"]
        self.notes: List[str] = raw["notes"]

    def _add_event_times(self) -> None:
        """The events' times as events.json writes them (ISO 8601 in the data's zone for
        Unix times): time, after, time_low, time_high beside their _s numbers."""
        import json

        try:
            with open(os.path.join(self.out, "events.json"), encoding="utf-8") as f:
                written = json.load(f).get("events", [])
        except (OSError, ValueError):
            return
        if len(written) != len(self.events):
            return
        for event, text in zip(self.events, written):
            for key in ("time", "after", "time_low", "time_high"):
                if key in text and key not in event:
                    event[key] = text[key]

    def to_dataframe(self) -> Any:
        """The windows as a pandas DataFrame, one row per window, every column of
        track.csv: window (its label), start_s, end_s, first_time_s, last_time_s,
        samples, readings, per per-window parameter its value and NAME_sigma_total, each
        shared sensor's offset sensor_offset_kN[i] and its _sigma_total, the window's
        reduced_chi_square, widening, gross_errors and folded. The index is the windows'
        start as a UTC DatetimeIndex (`window_start`) for Unix times, else the labels
        (issue 59: label strings beside float seconds would not line up with dates)."""
        import pandas

        rows = []
        for w in self.windows:
            row = {"window": w["label"]}
            for k in ("start_s", "end_s", "first_time_s", "last_time_s", "samples", "readings"):
                row[k] = w[k]
            for name, e in w["estimates"].items():
                row[name] = e["value"]
                row[f"{name}_sigma_total"] = e["sigma_total"]
            for cable, e in sorted(w.get("sensor_offset_kN", {}).items(), key=lambda x: int(x[0])):
                row[f"sensor_offset_kN[{cable}]"] = e["value"]
                row[f"sensor_offset_kN[{cable}]_sigma_total"] = e["sigma_total"]
            for k in ("reduced_chi_square", "widening", "gross_errors", "folded"):
                row[k] = w[k]
            rows.append(row)
        frame = pandas.DataFrame(rows)
        starts = np.array([w["start_s"] for w in self.windows], dtype=np.float64)
        if len(starts) > 0 and np.all(starts >= 1e8):  # Unix seconds
            frame.index = pandas.DatetimeIndex(
                pandas.to_datetime(starts, unit="s", utc=True), name="window_start"
            )
        else:
            frame.index = pandas.Index([w["label"] for w in self.windows], name="window")
        return frame

    def estimates(self, name: str) -> Tuple[np.ndarray, np.ndarray]:
        """A per-window parameter's estimates and sigma_total over the windows, (n,) each."""
        if name not in self.window_parameters:
            raise InputError(f"{name} is not a per-window parameter ({self.window_parameters})")
        values = np.array([w["estimates"][name]["value"] for w in self.windows])
        sigmas = np.array([w["estimates"][name]["sigma_total"] for w in self.windows])
        return values, sigmas

    def __repr__(self) -> str:
        return (
            f"<fastcal.TrackResult: {len(self.windows)} windows of {self.window}, "
            f"{len(self.events)} events, in {self.out}>"
        )


def _fold_task(task: bytes) -> bytes:
    """One window's fold (track_fold.h): what a Dask worker runs, without the GIL."""
    return _fastcal.fold_task(task)


def _dask_client(client: Any) -> Any:
    """A dask.distributed.Client: the one given, or one connected to a scheduler address."""
    if not isinstance(client, str):
        return client
    try:
        from dask.distributed import Client
    except ImportError as error:
        raise ImportError(
            "fastcal.track(client=...) needs dask.distributed: install the Debian packages "
            "python3-dask and python3-distributed (scripts/setup.sh does)"
        ) from error
    return Client(client)


def track(
    data: Union[PathLike, Sequence[PathLike]],
    spec: Union[PathLike, Mapping[str, Any]],
    out: PathLike,
    window: str = "1d",
    client: Any = None,
    model: Optional[Union[Model, PathLike]] = None,
    threads: int = 2,
    refold: bool = False,
    force: bool = False,
    columns: Optional[ColumnsLike] = None,
    quiet: bool = False,
) -> TrackResult:
    """The mass centre and the sensors through a season of telemetry (`fastcal track`).

    The data are cut into windows (calendar days in UTC by default), each window folded
    at a linearisation point into its information over its own parameters (the spec's
    sessions.separate groups) and the shared ones, and the joint fit solved by the Schur
    complement; the events between windows (a moved mass centre, a re-zeroed sensor) are
    tested at a 1% false-alarm rate over the whole track. Writes track.csv, events.json,
    track.html and the models in `out`, as the command line does, and returns them.

    Args:
        data: a telemetry file, a directory (its *.csv files), or a list of files; the
            times absolute (Unix seconds, or ISO 8601 through a column map).
        spec: a calibration spec file or dict (calibration_data/spec_track.yaml).
        out: the track's directory: new or empty, or a track built before, then updated
            with the files it does not hold yet (only the windows that gained samples are
            folded).
        window: "1d", "12h", "30m", "3600s", ... or "file" (one window per file).
        client: None to fold on this machine's threads, or a dask.distributed.Client (a
            LocalCluster's, or one connected to a scheduler) or a scheduler's address
            ("tcp://host:8786"): each window's fold is then a task on the workers, which
            must see `out` and the data at the same paths. The numbers are the same.
        model: the starting model (a Model or a model file); None for Model.nominal().
        threads: windows folded at once without a client.
        refold: on an update, refold every window (as a fresh track would).
        force: build the track in `out` afresh from the data, whatever it holds (needed
            when it holds a track of another model, spec or windowing, of files that
            changed, or a damaged one).
        columns: a column map (a file or a dict, as read_dataset takes) through which
            every data file is read: an export as it comes, ISO 8601 times included.
        quiet: no progress lines ("fastcal.track: ..." on sys.stderr, as the command
            line prints them).

    Raises:
        InputError: bad data, spec, window or directory. CalibrationError: a pose the
        model cannot solve ('infeasible'), parameters the windows cannot determine
        ('undetermined'), or a failed fold runner ('failed').
    """
    if model is None:
        model = Model.nominal()
    elif not isinstance(model, Model):
        model = Model.load(os.fspath(model))
    if isinstance(data, (str, os.PathLike)):
        paths = [os.fspath(data)]
    else:
        paths = [os.fspath(p) for p in data]
    spec_text, is_text, source = _spec_argument(spec)
    threads = _whole(threads, "threads", 1, 256)  # not True, not 2**40 (a raw TypeError)
    fold_many = None
    if client is not None:
        dask_client = _dask_client(client)

        def fold_many(tasks: List[bytes]) -> List[bytes]:
            futures = dask_client.map(_fold_task, tasks, pure=False)
            return dask_client.gather(futures)

    map_text, map_source = _columns_argument(columns)
    raw = _map_errors(
        lambda: _fastcal.track(
            model, spec_text, is_text, source, paths, os.fspath(out), window, threads, refold,
            force, map_text, map_source, fold_many, quiet,
        )
    )
    return TrackResult(raw, os.fspath(out))
