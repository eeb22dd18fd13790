#!/usr/bin/env python3
"""What dynamics do to a calibration (docs/calibration.md, "A survey flown in time";
issue 55 item 5).

A survey designed by `fastcal design` (spec_realistic.yaml, 120 samples, tilts of 5 deg
and turns of 10 deg off the focal law) is flown in time by `fastcal simulate --dynamics`
(minimum-jerk moves at 0.5 m/s, at least 10 s each, then a wait before each stop's first
sample), for several waits and seeds, with the sensors' errors of realistic_survey.csv
(3% white, per-cable gains, biases and densities off nominal); the same poses are also
simulated standing (the statics). Each is calibrated with spec_realistic.yaml from the
nominal model, and the mass centre's error against the truth is divided by its
sigma_total: the table gives, per wait, the largest |error| / sigma_total over the axes
and the seeds, and the rms of the ratios (1 for an honest sigma).

    /usr/bin/python3 scripts/dynamics_calibration_study.py [--fastcal=build/bin/fastcal]
        [--out=out/dynamics_calibration] [--seeds=5] [--waits=0,10,30,120]
"""

import argparse
import json
import math
import os
import subprocess
import sys

TRUTH_CENTRE = "0.22,0.11,0.5"
ERRORS = [
    "--tension-noise-percent=3",
    "--density-mismatch-percent=1.5",
    "--sensor-gain-spread-percent=1",
    "--sensor-bias-spread-kN=2",
    "--position-noise-m=0.01",
    "--attitude-noise-deg=0.02",
]


def run(cmd):
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        sys.exit("failed: " + " ".join(cmd) + "\n" + done.stdout[-2000:])
    return done.stdout


def mass_centre(summary_path, truth):
    """[(error / sigma_total)] per axis from a calibration's summary.json."""
    with open(summary_path) as f:
        s = json.load(f)
    out = []
    for p in s["parameters"]:
        name = p["name"]
        if name.startswith("mass_centre_m."):
            axis = "xyz".index(name[-1])
            out.append((p["estimate"] - truth[axis]) / p["sigma_total"])
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--fastcal", default="build/bin/fastcal")
    parser.add_argument("--out", default="out/dynamics_calibration")
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--waits", default="0,10,30,120")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    spec = "calibration_data/spec_realistic.yaml"
    design = os.path.join(args.out, "design")
    if not os.path.exists(os.path.join(design, "poses.csv")):
        run([args.fastcal, "design", "--spec=" + spec, "--samples=120",
             "--max-extra-tilt-deg=5", "--max-extra-yaw-deg=10", "--speed-m-per-s=0.5",
             "--out=" + design])
    truth = [float(v) for v in TRUTH_CENTRE.split(",")]
    cases = ["statics"] + ["wait %s s" % w for w in args.waits.split(",")]
    ratios = {c: [] for c in cases}
    for seed in range(1, args.seeds + 1):
        for case in cases:
            tag = case.replace(" ", "_") + "_seed%d" % seed
            data = os.path.join(args.out, tag + ".csv")
            cmd = [args.fastcal, "simulate", "--poses=" + os.path.join(design, "poses.csv"),
                   "--mass-centre=" + TRUTH_CENTRE, "--seed=%d" % seed, "--out=" + data] + ERRORS
            if case != "statics":
                cmd += ["--dynamics", "--speed-m-per-s=0.5", "--min-move-s=10",
                        "--wait-s=" + case.split()[1], "--interval-s=1"]
            if not os.path.exists(data):
                run(cmd)
            cal = os.path.join(args.out, tag + "_cal")
            if not os.path.exists(os.path.join(cal, "summary.json")):
                run([args.fastcal, "calibrate", "--spec=" + spec, "--data=" + data,
                     "--out=" + cal])
            ratios[case] += mass_centre(os.path.join(cal, "summary.json"), truth)
            print(case, seed, ["%.2f" % r for r in ratios[case][-3:]], flush=True)
    print("\n| case | samples of the mass centre | largest abs(error) / sigma_total | rms of error / sigma_total |")
    print("|---|---|---|---|")
    for case in cases:
        r = ratios[case]
        rms = math.sqrt(sum(x * x for x in r) / len(r))
        print("| %s | %d | %.2f | %.2f |" % (case, len(r), max(abs(x) for x in r), rms))


if __name__ == "__main__":
    main()
