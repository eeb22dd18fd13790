#!/usr/bin/env python3
"""Monte Carlo study of the recommended specs on telemetry with slow sensor errors
(docs/calibration.md, "Slow sensor errors": the tables there come from this script).

Telemetry as a new user's (issue "sensors that drift"): random poses of the cap, 1 s apart,
per-cable density (1.5%), gain (1%) and bias (1.5 kN) spreads, 3% white tension noise, and
a slow per-cable tension error of a given amplitude (% of the reading) and time constant.
Each case simulates SEEDS surveys with `fastcal simulate`, calibrates each with a bundled
spec, and counts from summary.json:

  scan-*      spec_change_scan.yaml on one survey of 800 samples: surveys reporting a
              change (false alarms where nothing stepped), and for a 5 cm step the pulls
              (shift - truth) / sigma of the step found
  sessions-*  spec_sessions.yaml on two surveys of 400 samples three days apart: pairs whose
              verdict says the mass centre moved, sensors accused of a re-zeroing, and the
              pulls (difference - truth) / sigma_total of the mass centre's difference
  single-*    spec_realistic.yaml on one survey of 800 samples: how often the mass centre's
              truth lies within 2 sigma_total (per axis)

Rates are printed with their binomial standard error sqrt(p (1 - p) / n).

Usage: scripts/slow_error_study.py [--seeds=30] [--cases=all|NAME,...] [--work=DIR]
Needs build/bin/fastcal (scripts/build.sh). A run of all cases at 30 seeds takes about
2 minutes on 2 cores (20 before issue 28's second round).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("FASTCAL_BIN", os.path.join(ROOT, "build", "bin", "fastcal"))
TRUTH_MC = (0.22, 0.11, 0.5)
COMMON = ["--trajectory=random", "--max-off-axis-deg=40", "--interval-s=1",
          "--mass-centre=%g,%g,%g" % TRUTH_MC, "--tension-noise-percent=3",
          "--density-mismatch-percent=1.5", "--sensor-gain-spread-percent=1",
          "--sensor-bias-spread-kN=1.5", "--attitude-noise-deg=0.02", "--position-noise-m=0.01"]
THREE_DAYS_S = 3 * 86400


def drift(pct, tau):
    return ["--tension-drift-percent=%g" % pct, "--tension-drift-time-s=%g" % tau]


# name: (spec, simulate flags, kind, truth of what changed)
CASES = {
    "scan-white": ("spec_change_scan.yaml", ["--samples=800"], "scan", None),
    "scan-1pct-20s": ("spec_change_scan.yaml", ["--samples=800"] + drift(1, 20), "scan", None),
    "scan-2pct-60s": ("spec_change_scan.yaml", ["--samples=800"] + drift(2, 60), "scan", None),
    "scan-2pct-120s": ("spec_change_scan.yaml", ["--samples=800"] + drift(2, 120), "scan", None),
    "scan-mc-wanders": ("spec_change_scan.yaml",
                        ["--samples=800", "--mass-centre-drift-m=0.01",
                         "--mass-centre-drift-time-s=600"] + drift(2, 60), "scan", None),
    "scan-step-5cm": ("spec_change_scan.yaml",
                      ["--samples=800", "--mass-centre-step=400:0.05,0,0"] + drift(2, 60),
                      "scan", (0.05, 0.0, 0.0)),
    "sessions-2pct-60s": ("spec_sessions.yaml",
                          ["--samples=800", "--sessions=2", "--session-gap-s=%d" % THREE_DAYS_S]
                          + drift(2, 60), "sessions", (0.0, 0.0, 0.0)),
    "sessions-1pct-20s": ("spec_sessions.yaml",
                          ["--samples=800", "--sessions=2", "--session-gap-s=%d" % THREE_DAYS_S]
                          + drift(1, 20), "sessions", (0.0, 0.0, 0.0)),
    "sessions-rezeroed": ("spec_sessions.yaml",
                          ["--samples=800", "--sessions=2", "--session-gap-s=%d" % THREE_DAYS_S,
                           "--sensor-rezero-kN=1"] + drift(2, 60), "sessions", (0.0, 0.0, 0.0)),
    "sessions-rezeroed-3kn": ("spec_sessions.yaml",
                              ["--samples=800", "--sessions=2",
                               "--session-gap-s=%d" % THREE_DAYS_S, "--sensor-rezero-kN=3"]
                              + drift(2, 60), "sessions", (0.0, 0.0, 0.0)),
    "sessions-moved-3cm": ("spec_sessions.yaml",
                           ["--samples=800", "--sessions=2", "--session-gap-s=%d" % THREE_DAYS_S,
                            "--session-shift-m=0.03,0,0"] + drift(2, 60), "sessions",
                           (0.03, 0.0, 0.0)),
    "single-2pct-60s": ("spec_realistic.yaml", ["--samples=800"] + drift(2, 60), "single", None),
    "single-white": ("spec_realistic.yaml", ["--samples=800"], "single", None),
}


def run(args):
    done = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(" ".join(args) + "\n" + done.stderr[-2000:])


def survey(case, seed, work):
    spec, flags, _, _ = CASES[case]
    csv = os.path.join(work, "survey.csv")
    out = os.path.join(work, "out")
    run([BIN, "simulate"] + COMMON + flags + ["--seed=%d" % seed, "--force", "--out=" + csv])
    run([BIN, "calibrate", "--quiet", "--force", "--spec=" + os.path.join(ROOT, "calibration_data", spec),
         "--data=" + csv, "--out=" + out])
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def estimate(summary, name):
    for p in summary["parameters"]:
        if p["name"] == name:
            return p
    raise KeyError(name)


def rate(k, n):
    p = k / n if n else 0.0
    return "%d/%d = %.1f%% +- %.1f%%" % (k, n, 100 * p, 100 * math.sqrt(p * (1 - p) / n) if n else 0)


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float("nan")


def study(case, seeds, work):
    kind, truth = CASES[case][2], CASES[case][3]
    alarms, accused, pulls, covered, axes, wanders = 0, 0, [], 0, 0, 0
    slow = []
    for seed in range(1, seeds + 1):
        s = survey(case, seed, work)
        if s.get("slow_error", {}).get("enabled"):
            slow.append((s["slow_error"]["sigma_percent"], s["slow_error"]["time_constant_s"]))
        if kind == "scan":
            changes = s["changes"]
            alarms += bool(changes)
            wanders += bool(changes) and s["change_scan"].get("wanders", False)
            if truth is not None and changes:
                c = max(changes, key=lambda c: c["statistic"])
                for k, axis in enumerate("xyz"):
                    name = "mass_centre_m." + axis
                    pulls.append((c["shifts"][name] - truth[k]) / c["shift_sigmas"][name])
        elif kind == "sessions":
            diffs = [d for d in s["session_differences"] if d["name"].startswith("mass_centre_m")]
            alarms += any(abs(d["difference"]) > 3 * d["sigma_total"] for d in diffs)
            accused += bool(s.get("sensor_steps", {}).get("separated"))
            for d in diffs:
                k = "xyz".index(d["name"][-1])
                pulls.append((d["difference"] - truth[k]) / d["sigma_total"])
        else:
            for k, axis in enumerate("xyz"):
                p = estimate(s, "mass_centre_m." + axis)
                axes += 1
                covered += abs(p["estimate"] - TRUTH_MC[k]) <= 2 * p["sigma_total"]
    line = case + ": "
    if kind == "scan":
        line += "change reported in " + rate(alarms, seeds)
        line += " (said to be a wandering, not a step, in %d)" % wanders
    elif kind == "sessions":
        line += "move claimed in " + rate(alarms, seeds) + "; a sensor accused in " + rate(accused, seeds)
    else:
        line += "truth within 2 sigma_total in " + rate(covered, axes) + " of the axes"
    if pulls:
        line += "; pull RMS %.2f over %d" % (rms(pulls), len(pulls))
    if slow:
        line += "; slow error estimated %.2f%% / %.0f s (median)" % (
            sorted(a for a, _ in slow)[len(slow) // 2], sorted(t for _, t in slow)[len(slow) // 2])
    print(line, flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=30)
    parser.add_argument("--cases", default="all")
    parser.add_argument("--work", default=None)
    a = parser.parse_args()
    cases = list(CASES) if a.cases == "all" else a.cases.split(",")
    for c in cases:
        if c not in CASES:
            sys.exit("unknown case %s (known: %s)" % (c, ", ".join(CASES)))
    work = a.work or tempfile.mkdtemp(prefix="fastcal-study-")
    os.makedirs(work, exist_ok=True)
    for c in cases:
        study(c, a.seeds, work)


if __name__ == "__main__":
    main()
