#!/usr/bin/env python3
"""Modes from ordinary operation (docs/model.md, "Modes from ordinary operation", issue 55
item 6).

Flies the cabin held at the zenith for an hour at 10 Hz in a 4 m/s wind toward 30 deg
(`fastcal simulate --dynamics`, Kaimal gusts of intensity 0.15, the default sensor noise:
3% on the tensions), one record per seed, and identifies each by covariance-driven SSI
(`fastcal modes --data`, which takes SSI for an ambient record). The references in the
same mean wind: the frequencies `fastcal modes` predicts (still air, 40 segments) and
the damping of free decays in the steady wind (no gusts: the drag's damping included),
identified by ERA: along the wind (the sway the gusts drive) and vertical (the bounce).

    scripts/ambient_modes_study.py [--fastcal=build/bin/fastcal] [--out=out/ambient_modes]
        [--seeds=1,2,3,4]

Prints one row per identified mode: its frequency and damping with their jackknife
sigmas, the nearest predicted mode, the frequency's difference, and the damping against
the reference where there is one. Each record and result stays in --out.
"""

import argparse
import csv
import os
import subprocess
import sys

DATASET_COLUMNS = ["time_s", "x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"] + [
    f"T{i}_kN" for i in range(1, 7)]
WIND = "4,30"
# Free decays in the steady wind: along the wind (toward 30 deg) and vertical, each with
# the predicted modes (1-based, zenith, 40 segments) it stands for: the sway pair, the
# bounce.
REFERENCES = {"sway along the wind": ("0.0866,0.05,0", (1, 2)), "bounce": ("0,0,0.1", (4,))}
REFERENCE_OF_MODE = {m: name for name, (_, modes) in REFERENCES.items() for m in modes}


def run(args):
    result = subprocess.run(args, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"{' '.join(args)} failed:\n{result.stderr}{result.stdout}")
    return result


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def reference_damping(fastcal, out):
    """ERA on a free decay in the steady wind: {name: (frequency_hz, damping_ratio)}."""
    found = {}
    for name, (offset, modes) in REFERENCES.items():
        tag = name.split()[0]
        decay = os.path.join(out, f"decay_{tag}.csv")
        run([fastcal, "dynamics", "--position=0,0,140", f"--initial-offset={offset}",
             f"--wind={WIND}", "--turbulence-intensity=0", "--hold-s=1200",
             f"--output={decay}", "--force"])
        dataset = os.path.join(out, f"decay_{tag}_dataset.csv")
        with open(dataset, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(DATASET_COLUMNS)
            for row in rows(decay):
                writer.writerow([row[c] for c in DATASET_COLUMNS])
        identified = os.path.join(out, f"decay_{tag}_era.csv")
        run([fastcal, "modes", f"--data={dataset}", "--identification=era", "--segments=40",
             "--identified-modes=2", f"--output={identified}", "--force"])
        mode = next(m for m in rows(identified) if int(m["predicted_mode"]) in modes)
        found[name] = (float(mode["frequency_hz"]), float(mode["damping_ratio"]))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fastcal", default="build/bin/fastcal")
    parser.add_argument("--out", default="out/ambient_modes")
    parser.add_argument("--seeds", default="1,2,3,4")
    a = parser.parse_args()
    os.makedirs(a.out, exist_ok=True)
    references = reference_damping(a.fastcal, a.out)
    for name, (hz, zeta) in references.items():
        print(f"reference, {name}: {hz:.5f} Hz, damping {100 * zeta:.2f}% (ERA, steady wind)")
    print("| seed | identified, Hz | damping, % | predicted mode, Hz | difference, % "
          "| reference damping, % | damping / reference |")
    print("|---|---|---|---|---|---|---|")
    for seed in a.seeds.split(","):
        record = os.path.join(a.out, f"ambient_s{seed}.csv")
        run([a.fastcal, "simulate", "--dynamics", "--trajectory=line", "--from=0,0,140",
             "--to=0,0,140", "--nodes=36000", "--interval-s=0.1", f"--wind={WIND}",
             f"--seed={seed}", f"--out={record}", "--force"])
        identified = os.path.join(a.out, f"ssi_s{seed}.csv")
        run([a.fastcal, "modes", f"--data={record}", "--segments=40",
             f"--output={identified}", "--force"])
        for mode in rows(identified):
            predicted = int(mode["predicted_mode"])
            reference = references.get(REFERENCE_OF_MODE.get(predicted, ""))
            zeta = float(mode["damping_ratio"])
            ref_text = f"{100 * reference[1]:.2f}" if reference else "-"
            ratio = f"{zeta / reference[1]:.2f}" if reference else "-"
            print(f"| {seed} | {float(mode['frequency_hz']):.5f} +- "
                  f"{float(mode['frequency_sigma_hz']):.5f} | {100 * zeta:.2f} +- "
                  f"{100 * float(mode['damping_sigma']):.2f} | {predicted}: "
                  f"{float(mode['predicted_hz']):.5f} | {float(mode['difference_percent']):+.2f} "
                  f"| {ref_text} | {ratio} |")


if __name__ == "__main__":
    main()
