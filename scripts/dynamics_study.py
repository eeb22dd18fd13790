#!/usr/bin/env python3
"""Where the quasi-static answer holds (docs/model.md, "Dynamics", issue 55 item 4).

Runs `fastcal dynamics` for sidereal tracking, minimum-jerk moves of 1-20 m in 20-120 s
and the cabin held in winds of 2-8 m/s, at the zenith and 40 deg off axis (focal law),
and prints the table of docs/model.md: the peak and RMS departure of the lower-end
tensions from the quasi-static ones at the same winch lengths (kN and % of the reading,
beside the sensors' 3%), the cabin's position departure, and after a move the time until
every tension stays within 0.5% and 0.1% of its quasi-static value.

    scripts/dynamics_study.py [--fastcal=build/bin/fastcal] [--out=out/dynamics_study]
        [--quick]

--quick: 16 segments and the short cases only (a smoke test). Each run's CSV and
summary JSON stay in --out.
"""

import argparse
import csv
import json
import math
import os
import subprocess
import sys

POSES = {
    "zenith": ("0,0,140", ["--attitude-law=focal"]),
    "40 deg": ("102.846,0,177.433", ["--attitude-law=focal"]),
}


def settle_times(path, motion_end_s, fractions):
    """Seconds after motion_end_s until every tension stays within each fraction."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    out = []
    for fraction in fractions:
        settle = 0.0
        settled = True
        for row in reversed(rows):
            t = float(row["time_s"])
            if t < motion_end_s:
                break
            outside = any(
                abs(float(row[f"T{i}_kN"]) / float(row[f"T{i}_qs_kN"]) - 1.0) > fraction
                for i in range(1, 7))
            if outside:
                if row is rows[-1]:
                    settled = False
                settle = t - motion_end_s
                break
        out.append(settle if settled else math.nan)
    return out


def run(fastcal, out_dir, name, args):
    csv_path = os.path.join(out_dir, name + ".csv")
    json_path = os.path.join(out_dir, name + ".json")
    command = [fastcal, "dynamics"] + args + [
        f"--output={csv_path}", f"--summary={json_path}", "--force"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)}\n{done.stderr}")
    with open(json_path) as f:
        return json.load(f), csv_path


def tracking_table(fastcal, out_dir, name, start, speed_m_per_s, duration_s, ramp_s):
    """A winch table for tracking along +y at speed_m_per_s from `start` for duration_s,
    the speed reached and left by minimum-jerk ramps of ramp_s: the exact statics'
    lengths each second (fastcal solve --poses, the focal law)."""
    x0, y0, z0 = (float(v) for v in start.split(","))

    def ramp(t):  # the distance covered t into a minimum-jerk ramp of the speed
        u = min(max(t / ramp_s, 0.0), 1.0)
        return speed_m_per_s * ramp_s * (2.5 * u**4 - 3.0 * u**5 + u**6)

    full = ramp(ramp_s)
    total = 2.0 * ramp_s + duration_s
    poses = os.path.join(out_dir, name + "_poses.csv")
    times = []
    with open(poses, "w") as f:
        f.write("x_m,y_m,z_m\n")
        for k in range(int(total) + 1):
            t = float(k)
            if t < ramp_s:
                y = ramp(t)
            elif t <= ramp_s + duration_s:
                y = full + speed_m_per_s * (t - ramp_s)
            else:  # the ramp down mirrors the ramp up
                y = 2.0 * full + speed_m_per_s * duration_s - ramp(total - t)
            f.write(f"{x0:.6f},{y0 + y:.6f},{z0:.6f}\n")
            times.append(t)
    solved = os.path.join(out_dir, name + "_statics.csv")
    done = subprocess.run([fastcal, "solve", f"--poses={poses}", "--attitude-law=focal",
                           f"--output={solved}", "--force"], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(done.stderr)
    table = os.path.join(out_dir, name + "_lengths.csv")
    with open(solved) as f, open(table, "w") as g:
        g.write("time_s," + ",".join(f"s0_{i}_m" for i in range(1, 7)) + "\n")
        for t, row in zip(times, csv.DictReader(f)):
            g.write(f"{t:g}," + ",".join(row[f"s0_{i}_m"] for i in range(1, 7)) + "\n")
    return table


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--fastcal", default="build/bin/fastcal")
    parser.add_argument("--out", default="out/dynamics_study")
    parser.add_argument("--quick", action="store_true")
    a = parser.parse_args()
    os.makedirs(a.out, exist_ok=True)
    common = ["--segments=16"] if a.quick else []
    rows = []

    def add(kind, pose_name, label, summary, csv_path, motion_end):
        d = summary["departure"]
        settle = settle_times(csv_path, motion_end, [0.005, 0.001]) if motion_end is not None else None
        rows.append((kind, pose_name, label, d, summary["residual"], settle))

    moves = [(1, 20), (5, 20), (10, 20), (20, 20), (10, 60), (20, 60), (10, 120), (20, 120)]
    winds = [2, 4, 6, 8]
    if a.quick:
        moves, winds = [(5, 20)], [4]
    for pose_name, (position, attitude) in POSES.items():
        x, y, z = (float(v) for v in position.split(","))
        # Tracking: 12 mm/s for 10 minutes between 30 s ramps.
        table = tracking_table(a.fastcal, a.out, f"track_{pose_name[:2]}", position, 0.012,
                               60 if a.quick else 600, 30)
        summary, path = run(a.fastcal, a.out, f"track_{pose_name[:2]}",
                            [f"--position={position}", *attitude, f"--lengths={table}",
                             "--hold-s=60", *common])
        add("tracking", pose_name, "12 mm/s", summary, path, None)
        for distance, duration in moves:
            name = f"move_{pose_name[:2]}_{distance}m_{duration}s"
            to = f"{x - distance:g},{y:g},{z:g}"  # toward (and across) the axis
            summary, path = run(a.fastcal, a.out, name,
                                [f"--position={position}", *attitude, f"--to={to}",
                                 f"--move-s={duration}", "--hold-s=600", *common])
            add("move", pose_name, f"{distance} m in {duration} s", summary, path, duration)
        for speed in winds:
            name = f"wind_{pose_name[:2]}_{speed}"
            summary, path = run(a.fastcal, a.out, name,
                                [f"--position={position}", *attitude, f"--wind={speed},30",
                                 "--hold-s=1200", "--seed=1", *common])
            add("wind", pose_name, f"{speed} m/s", summary, path, None)

    print("| case | pose | | peak dT, kN (% of reading) | RMS dT, kN (%) | peak dp, mm |"
          " residual after, kN (%) | settle to 0.5% / 0.1%, s |")
    print("|---|---|---|---|---|---|---|---|")
    for kind, pose_name, label, d, residual, settle in rows:
        settle_text = ""
        if settle is not None:
            settle_text = " / ".join("not in 600 s" if math.isnan(s) else f"{s:.0f}"
                                     for s in settle)
        residual_text = (f"{residual['peak_kN']:.3f} ({residual['peak_percent']:.3f}%)"
                         if kind == "move" else "")
        print(f"| {kind} | {pose_name} | {label} | {d['peak_kN']:.3f} ({d['peak_percent']:.3f}%)"
              f" | {d['rms_kN']:.3f} ({d['rms_percent']:.3f}%) | {d['peak_position_mm']:.1f} |"
              f" {residual_text} | {settle_text} |")


if __name__ == "__main__":
    main()
