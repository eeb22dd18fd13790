#!/usr/bin/env python3
"""Time per pose of fastcal.solve on an array of poses, against the same loop in C++.

The poses: 10000 positions spread over the workspace cap (fastcal.random_workspace,
seed 1) with the focal attitude law, as bench/statics_bench.cc's BM_WorkspaceArray
builds them. Python times the whole call (arguments in, arrays out); C++ times the
SolveStatics loop over poses built beforehand. Both count the CPU time of the thread
that solves (Google Benchmark's items_per_second does; time.thread_time here), not the
wall clock: on a machine shared with other work the wall clock also counts the time
the thread waited for a core. Best of --repeat runs each.

Run from the build tree's configuration (the module and the benchmark built):

    PYTHONPATH=build/python /usr/bin/python3 bench/python_statics_bench.py \\
        --cpp build/bench/statics_bench
"""

from __future__ import annotations

import argparse
import json
import subprocess
import time
from typing import Dict, Optional

import fastcal

POSES = 10000
METHODS = ("aas", "aas-refined", "exact")


def python_us_per_pose(method: str, repeat: int) -> float:
    positions = fastcal.random_workspace(samples=POSES, seed=1)
    quat = fastcal.focal_attitude(positions)
    best = float("inf")
    for _ in range(repeat):
        start = time.thread_time()
        result = fastcal.solve(positions, quat=quat, method=method)
        best = min(best, time.thread_time() - start)
        assert result.ok.all()
    return best / POSES * 1e6


def cpp_us_per_pose(binary: str, repeat: int) -> Dict[str, float]:
    run = subprocess.run(
        [
            binary,
            "--benchmark_filter=BM_WorkspaceArray",
            f"--benchmark_repetitions={repeat}",
            "--benchmark_format=json",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    best: Dict[str, float] = {}
    for b in json.loads(run.stdout)["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        method = b["label"].split(" ")[0]
        per_pose_us = 1e6 / b["items_per_second"]
        best[method] = min(best.get(method, float("inf")), per_pose_us)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cpp", help="build/bench/statics_bench, for the C++ side")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    cpp: Optional[Dict[str, float]] = cpp_us_per_pose(args.cpp, args.repeat) if args.cpp else None
    print(f"{'method':<12} {'python us/pose':>15} {'c++ us/pose':>12} {'overhead':>9}")
    for method in METHODS:
        py = python_us_per_pose(method, args.repeat)
        if cpp is None:
            print(f"{method:<12} {py:>15.3f}")
            continue
        c = cpp[method]
        print(f"{method:<12} {py:>15.3f} {c:>12.3f} {100 * (py / c - 1):>8.1f}%")


if __name__ == "__main__":
    main()
