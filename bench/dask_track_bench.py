#!/usr/bin/env python3
"""The same track locally and on a Dask LocalCluster of one-thread workers (issue 41).

Tracks DATA (a telemetry CSV with absolute times) with calibration_data/spec_track.yaml
twice, into a temporary directory: first locally (fastcal.track, 2 windows at once), then
on a LocalCluster of --workers one-thread workers on the loopback interface. Prints each
run's wall time and whether the two track.csv are the same bytes; fastcal.track's
progress lines on stderr mark the phases (the read, then each round of folds), which
docs/speed.md, "A year at 10 Hz on a Dask cluster", times with the shell:

    PYTHONPATH=build/python PYTHONUNBUFFERED=1 /usr/bin/python3 bench/dask_track_bench.py \
        DATA.csv 2>&1 | while IFS= read -r l; do echo "$(date +%M:%S.%N | cut -c1-8) $l"; done

Needs python3-dask and python3-distributed (scripts/setup.sh installs them).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile
import time

import fastcal

SPEC = pathlib.Path(__file__).resolve().parent.parent / "calibration_data" / "spec_track.yaml"


def run(data: str, out: pathlib.Path, client=None) -> float:
    start = time.perf_counter()
    fastcal.track(data, str(SPEC), out=str(out), client=client)
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", help="telemetry CSV with absolute times")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster workers (2)")
    args = parser.parse_args()
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("dask_track_bench: needs python3-dask and python3-distributed", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory() as tmp:
        local, dask = pathlib.Path(tmp) / "local", pathlib.Path(tmp) / "dask"
        print(f"local: {run(args.data, local):.2f} s")
        with LocalCluster(n_workers=args.workers, threads_per_worker=1, host="127.0.0.1",
                          dashboard_address=None) as cluster, Client(cluster) as client:
            print(f"LocalCluster of {args.workers}: {run(args.data, dask, client):.2f} s")
        same = (local / "track.csv").read_bytes() == (dask / "track.csv").read_bytes()
        print("track.csv the same bytes:", same)
    return 0


if __name__ == "__main__":
    sys.exit(main())
