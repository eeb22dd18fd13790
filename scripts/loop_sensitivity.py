#!/usr/bin/env python3
"""Which calibrated parameter matters most in the control loop (issue 56; docs/model.md,
"The closed loop"): each parameter of a calibration moved by its sigma_total in the
controller's model, the cabin's static error that leaves where the feed-forward alone
holds it (what the PID must take away after every slew, and all of it without a position
measurement).

For a parameter p with sigma_total s: the controller's model with p + s gives the winch
lengths s0 of the commanded pose (its exact statics); the plant (the calibrated model
itself) hangs at those lengths where the forward statics put it (fastcal.locate). The
displacement from the commanded position, in mm per sigma_total, split across and along
the feed's axis, at a few poses of the cap; then the root sum of squares over the
parameters (their correlations ignored: an upper bound where estimates trade against
each other, as the mass centre's z against the densities). Sensor gains and biases do not
move the lengths: they do not enter.

Usage: scripts/loop_sensitivity.py [--summary=DIR/summary.json] [--model=DIR/model_calibrated.yaml]
Without them it calibrates the bundled realistic survey first (build/bin/fastcal). Needs
the Python module (build/python on PYTHONPATH: scripts/build.sh builds it).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
import numpy as np  # noqa: E402

import fastcal  # noqa: E402

BIN = os.environ.get("FASTCAL_BIN", os.path.join(ROOT, "build", "bin", "fastcal"))
# Off-axis angles (deg, toward +x, azimuth 0 and 90) of the poses on the focal law.
POSES = [(0.0, 0.0), (20.0, 0.0), (20.0, 90.0), (40.0, 0.0)]


def focal_position(zenith_deg, azimuth_deg):
    z, a = math.radians(zenith_deg), math.radians(azimuth_deg)
    return np.array([160.0 * math.sin(z) * math.cos(a), 160.0 * math.sin(z) * math.sin(a),
                     300.0 - 160.0 * math.cos(z)])


def cable_index(name):
    """The 0-based cable of "name[i]..." (1-based in the name), or None for a common one."""
    return int(name[name.index("[") + 1:name.index("]")]) - 1 if "[" in name else None


def perturbed(model, name, step):
    """The model with parameter `name` moved by `step` (SI), or None when it does not move
    the lengths."""
    m = model.copy()
    # (the name's prefix, the model's attribute, the axis its last letter names)
    fields = [("mass_centre_m.", "mass_centre_m", True), ("linear_density_kg_per_m",
              "linear_density_kg_per_m", False), ("ea_n", "ea_n", False),
              ("tower_offset_m[", "tower_top_m", True), ("length_offset_m", "length_offset_m",
                                                          False)]
    for prefix, attribute, axis in fields:
        if not name.startswith(prefix):
            continue
        value = np.array(getattr(m, attribute), dtype=float)
        cable = cable_index(name)
        where = () if cable is None else (cable,)
        if axis:
            where = where + ("xyz".index(name[-1]),)
        if where:
            value[where] += step
        else:
            value += step
        setattr(m, attribute, value)
        return m
    return None


def displacement(plant, controller, position, quat):
    """Where the plant hangs at the controller's winch lengths, minus the command (m)."""
    s0 = fastcal.control_cycle(position, quat=quat, model=controller).winch_length_m - \
        np.array(plant.length_offset_m, dtype=float)
    located = fastcal.locate(s0, model=plant)
    if not located.ok:
        raise RuntimeError("locate: " + str(located.status))
    return np.asarray(located.position_m) - position


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--summary")
    parser.add_argument("--model")
    args = parser.parse_args()
    if not args.summary:
        out = os.path.join(tempfile.mkdtemp(prefix="fastcal_sens_"), "cal")
        subprocess.run([BIN, "calibrate", "--quiet",
                        "--spec=" + os.path.join(ROOT, "calibration_data", "spec_realistic.yaml"),
                        "--data=" + os.path.join(ROOT, "calibration_data", "realistic_survey.csv"),
                        "--out=" + out], check=True, capture_output=True)
        args.summary = os.path.join(out, "summary.json")
        args.model = os.path.join(out, "model_calibrated.yaml")
    with open(args.summary) as f:
        summary = json.load(f)
    model = fastcal.Model.load(args.model)
    rows = []
    for p in summary["parameters"]:
        if not (p["free"] or p["consider"]) or not p.get("sigma_total"):
            continue
        scale = 1e3 if p["unit"] == "kN" else 1.0
        step = p["sigma_total"] * scale
        controller = perturbed(model, p["name"], step)
        if controller is None:
            continue
        per_pose, vectors = [], []
        for zenith, azimuth in POSES:
            position = focal_position(zenith, azimuth)
            quat = fastcal.focal_attitude(position)
            d = displacement(model, controller, position, quat) - \
                displacement(model, model, position, quat)
            per_pose.append(np.linalg.norm(d) * 1e3)
            vectors.append(d * 1e3)
        rows.append((max(per_pose), p["name"], p["sigma_total"], p["unit"],
                     "consider" if p["consider"] else "free", per_pose, vectors))
    rows.sort(reverse=True)
    print("| parameter | sigma_total | kind | cabin moved (mm) at %s | largest |" %
          ", ".join("%g deg az %g" % z for z in POSES))
    print("|---|---:|---|---:|---:|")
    for largest, name, sigma, unit, kind, per_pose, _ in rows:
        print("| %s | %.3g %s | %s | %s | %.2f |" % (
            name, sigma, unit, kind, " / ".join("%.2f" % v for v in per_pose), largest))
    total = [math.sqrt(sum(r[5][k] ** 2 for r in rows)) for k in range(len(POSES))]
    print("| root sum of squares | | | %s | %.2f |" % (
        " / ".join("%.2f" % v for v in total), max(total)))
    # With the free parameters' correlations (summary.json's matrix; the consider ones
    # independent of everything): the RMS of the cabin's 3-d error, sqrt(tr(D C D^T)).
    names = summary["correlation"]["names"]
    matrix = np.array(summary["correlation"]["matrix"], dtype=float)
    index = {n: k for k, n in enumerate(names)}
    propagated = []
    for k in range(len(POSES)):
        d = np.array([r[6][k] for r in rows])  # rows x 3, mm per sigma
        c = np.eye(len(rows))
        for a, ra in enumerate(rows):
            for b, rb in enumerate(rows):
                if a != b and ra[1] in index and rb[1] in index:
                    c[a, b] = matrix[index[ra[1]], index[rb[1]]]
        propagated.append(math.sqrt(max(0.0, np.trace(d.T @ c @ d))))
    print("| with the free parameters' correlations | | | %s | %.2f |" % (
        " / ".join("%.2f" % v for v in propagated), max(propagated)))


if __name__ == "__main__":
    main()
