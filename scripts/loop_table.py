#!/usr/bin/env python3
"""What a calibration is worth in the control loop (issue 56; docs/model.md, "The closed
loop"): `fastcal loop` with the truth of the bundled realistic survey as the plant, and as
the controller's model the nominal model, the model calibrated from that survey, or the
truth itself; the feed-forward alone and with the default PID (measured by a total
station: 0.4 mm per axis, 0.24 s late); no wind, 4 and 8 m/s. Two tasks: a source
tracked for an hour (40 deg of azimuth on the focal sphere's 20 deg ring at the sidereal
rate, the focal law), and a slew of 20 m in 120 s from 20 deg off axis, then held; each
summarised from 120 s on (after the PID's start, after the slew).

Usage: scripts/loop_table.py [--work=DIR] [--hold-s=480]
Prints the table (Markdown). Needs build/bin/fastcal (scripts/build.sh).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("FASTCAL_BIN", os.path.join(ROOT, "build", "bin", "fastcal"))
DATA = os.path.join(ROOT, "calibration_data")
# 20 deg off axis toward +x on the 160 m focal sphere centred at (0, 0, 300).
START = "54.72,0,149.65"
# A source tracked for an hour: 40 deg of azimuth on the 20 deg ring of the focal sphere
# at the sidereal rate on the sphere (loop's default --path-speed, 0.0116 m/s: 38 m in 55
# minutes), eased in and out over a minute.
TRACK = ["--trajectory=arc", "--centre=0,0,149.65", "--radius=54.72", "--start-deg=-20",
         "--end-deg=20", "--nodes=81"]
SLEW_TO = "34.72,0,149.65"


def run(args, summary):
    r = subprocess.run([BIN, "loop"] + args + ["--summary=" + summary,
                                               "--output=" + summary[:-5] + ".csv", "--force"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(" ".join(args) + ": " + r.stderr.strip())
    with open(summary) as f:
        return json.load(f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--work", default=None)
    parser.add_argument("--hold-s", type=float, default=480.0)
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="fastcal_loop_")
    os.makedirs(work, exist_ok=True)
    truth = os.path.join(DATA, "realistic_survey.truth.yaml")
    calibrated_dir = os.path.join(work, "calibrated")
    if not os.path.exists(os.path.join(calibrated_dir, "model_calibrated.yaml")):
        subprocess.run([BIN, "calibrate", "--quiet", "--spec=" + os.path.join(DATA, "spec_realistic.yaml"),
                        "--data=" + os.path.join(DATA, "realistic_survey.csv"),
                        "--out=" + calibrated_dir], check=True, capture_output=True)
    models = [("nominal", os.path.join(DATA, "nominal_fast.yaml")),
              ("calibrated", os.path.join(calibrated_dir, "model_calibrated.yaml")),
              ("truth", truth)]
    # Both summarised from 120 s on: tracking once the PID has taken the start's static
    # error away; the slew over the hold after it (the time a source is observed).
    tasks = [("tracking a source for an hour", TRACK + ["--hold-s=0", "--summary-from-s=120"]),
             ("after a slew of 20 m in 120 s", ["--to=" + SLEW_TO, "--move-s=120",
                                                "--hold-s=%g" % args.hold_s,
                                                "--summary-from-s=120"])]
    loops = [("feed-forward", ["--pid=0,0,0"]),
             ("+ PID", ["--measurement-noise-mm=0.4", "--measurement-delay-s=0.24"])]
    print("| task | controller's model | loop | wind 0: RMS / peak (lateral RMS) mm | "
          "wind 4 m/s | wind 8 m/s | efficiency lost at 3 GHz (wind 0) |")
    print("|---|---|---|---:|---:|---:|---:|")
    for task, task_args in tasks:
        for name, model in models:
            for loop, loop_args in loops:
                cells = []
                loss = None
                for wind in (0, 4, 8):
                    tag = "%s_%s_%s_%d" % (task.split()[0], name, loop.strip("+ ").replace("-", ""),
                                           wind)
                    flags = ["--truth=" + truth, "--controller-model=" + model, "--seed=1"]
                    if "--trajectory=arc" not in task_args:
                        flags += ["--position=" + START, "--attitude-law=focal"]
                    flags += task_args + loop_args
                    if wind:
                        flags.append("--wind=%d,0" % wind)
                    s = run(flags, os.path.join(work, tag + ".json"))
                    cells.append("%.1f / %.1f (%.1f)" % (s["error_rms_mm"], s["error_peak_mm"],
                                                         s["lateral_rms_mm"]))
                    if wind == 0:
                        loss = s["efficiency"]["loss"]
                print("| %s | %s | %s | %s | %s | %s | %.2f%% |" % (
                    task, name, loop, cells[0], cells[1], cells[2], 100.0 * loss))
                sys.stdout.flush()


if __name__ == "__main__":
    main()
