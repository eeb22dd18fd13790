#!/usr/bin/env python3
"""Coverage study of a season's answers (issue 53; docs/calibration.md, "Tracking over a
season", "Events: intervals, sizes and false alarms on independent seasons"): events at
moments drawn at random over a season's observing time and nights, on telemetry with
errors the track does not model.

Each season: DAYS observing days of HOURS h from 20:00 UTC (sources tracked at the
sidereal rate, `simulate --trajectory=tracks`, 2 s apart), each day simulated on its own
(its own seed; a cabin with moving parts splits the feed's tilt between the cabin and the
rotator by a fraction drawn per day from 0.25-0.55), with
  3 % white tension noise, a 1.5 % slow sensor error of ~70 s, gain and bias spreads of
  1 % and 1.5 kN, an attitude-control error of 0.3 deg AR(1) with a 60 s memory, 1 cm of
  position noise, and the mass centre wandering inside each day by WANDER mm per axis (a
  Gauss-Markov process of time constant TAU, made of zero mean over each day or not),
the conditions drawn per season from CONDITIONS below. EVENTS events per season, at least
two days apart: a move of the mass centre of 1-4 cm in a random horizontal direction, or a sensor
re-zeroed by 2-5 kN (either sign, a random cable), each at a moment drawn uniformly over
one of: a day's observing time (mid-track or between tracks), the first or last 15
minutes of a day, or a night. Tracked with calibration_data/spec_track.yaml (or
spec_track_moving_parts.yaml from a first moment of 0).

Per event: found (one event of its kind, and cable, within 1.5 days of the truth; truths
and reports paired closest first, a report whose interval holds the truth before one only
near it), the truth inside the stated interval [time_low, time_high], the shifts' pulls
(shift - truth) / sigma_total per component (the truth: the sum of the true moves of that
kind inside the interval, the change between the stretches either side), the interval's
width, dated to 15 minutes, and for a move the pulls against the true change between the
stretches either side of its interval too (the true daily means of the whole days up to
the neighbouring reported changes, from `simulate`'s truth files: what the shift
estimates when a move nearby went unreported); per season: the events reported that match
no truth. `null` seasons have no event: the fraction that
report any is the false-alarm rate.

Usage: scripts/season_answers_study.py events|null [--seasons=40] [--first-seed=1]
           [--days=15] [--hours=2] [--events=5] [--parts] [--work=DIR] [--jobs=2]
Prints one line per season, then the table (docs/calibration.md's). Needs build/bin/fastcal
(scripts/build.sh).
"""
import argparse
import datetime
import json
import math
import multiprocessing
import os
import random
import shutil
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("FASTCAL_BIN", os.path.join(ROOT, "build", "bin", "fastcal"))
START = datetime.datetime(2024, 5, 1, 20, 0, 0, tzinfo=datetime.timezone.utc)
DAY = 86400.0
INTERVAL = 2.0
MASS_CENTRE = (0.22, 0.11, 0.5)
# (wander per axis in m, its time constant in s, centred per day): drawn per season.
CONDITIONS = [(0.005, 600.0, True), (0.005, 1800.0, True), (0.003, 300.0, False),
              (0.008, 900.0, True), (0.005, 7200.0, True), (0.005, 600.0, False)]
COMMON = ["--trajectory=tracks", "--interval-s=%g" % INTERVAL, "--track-minutes=20,60",
          "--max-off-axis-deg=35", "--tension-noise-percent=3", "--tension-drift-percent=1.5",
          "--tension-drift-time-s=70", "--attitude-control-deg=0.3",
          "--attitude-control-time-s=60", "--position-noise-m=0.01",
          "--sensor-gain-spread-percent=1", "--sensor-bias-spread-kN=1.5"]
EDGE_S = 15 * 60.0   # the first or last minutes of a day
DATED_S = 15 * 60.0  # "pinned": the point within this of the truth


def iso(t):
    return datetime.datetime.fromtimestamp(t, datetime.timezone.utc).strftime(
        "%Y-%m-%dT%H:%M:%SZ")


def draw_events(rng, days, hours, count):
    """Events at least two days apart: (kind, time_s, place, shift, cable)."""
    day_s = hours * 3600.0
    start = START.timestamp()
    slots = list(range(1, days - 1))
    rng.shuffle(slots)
    chosen = []
    for d in slots:
        if all(abs(d - c) >= 2 for c in chosen):
            chosen.append(d)
        if len(chosen) == count:
            break
    events = []
    for d in sorted(chosen):
        place = rng.choice(["day", "day", "edge", "night", "night"])
        day0 = start + d * DAY
        if place == "day":
            t = day0 + rng.uniform(EDGE_S, day_s - EDGE_S)
        elif place == "edge":
            t = day0 + (rng.uniform(0, EDGE_S) if rng.random() < 0.5
                        else rng.uniform(day_s - EDGE_S, day_s - INTERVAL))
        else:  # the night before day d
            t = day0 - DAY + day_s + rng.uniform(0, DAY - day_s)
        if rng.random() < 0.5:
            # Horizontal: a move along z shows only through the tilt, by a tenth as much.
            size = rng.uniform(0.01, 0.04)
            phi = rng.uniform(0, 2 * math.pi)
            shift = (size * math.cos(phi), size * math.sin(phi), 0.0)
            events.append(("parameter", t, place, shift, 0))
        else:
            size = rng.uniform(2.0, 5.0) * rng.choice([-1, 1])
            events.append(("sensor", t, place, (size,), rng.randint(1, 6)))
    return events


def simulate_season(work, seed, args, events, condition):
    rng = random.Random(seed * 7919)
    wander, tau, centred = condition
    truth = os.path.join(ROOT, "calibration_data", "moving_parts.yaml") if args.parts else None
    model = None
    if args.parts:
        moment = rng.choice([1500, 6000])
        text = open(truth).read()
        with open(os.path.join(work, "truth.yaml"), "w") as f:
            f.write(text.replace("first_moment_kg_m: [0, 0, -6000]",
                                 "first_moment_kg_m: [0, 0, -%d]" % moment))
        with open(os.path.join(work, "start.yaml"), "w") as f:
            f.write(text.replace("first_moment_kg_m: [0, 0, -6000]",
                                 "first_moment_kg_m: [0, 0, 0]"))
        truth = os.path.join(work, "truth.yaml")
        model = os.path.join(work, "start.yaml")
    steps = ";".join("%s:%.6f,%.6f,%.6f" % ((iso(e[1]),) + e[3])
                     for e in events if e[0] == "parameter")
    rezero = ";".join("%s:%d:%.4f" % (iso(e[1]), e[4], e[3][0])
                      for e in events if e[0] == "sensor")
    files = []
    samples = int(args.hours * 3600 / INTERVAL)
    for d in range(args.days):
        out = os.path.join(work, "d%02d.csv" % d)
        flags = COMMON + ["--samples=%d" % samples, "--start=%s" % iso(START.timestamp() + d * DAY),
                          "--mass-centre=%g,%g,%g" % MASS_CENTRE,
                          "--mass-centre-drift-m=%g" % wander,
                          "--mass-centre-drift-time-s=%g" % tau, "--force", "--out=" + out]
        if centred:
            flags.append("--mass-centre-drift-centred")
        if steps:
            flags.append("--mass-centre-step=" + steps)
        if rezero:
            flags.append("--sensor-step=" + rezero)
        if truth:
            flags += ["--truth=" + truth, "--joint-law=focal", "--prismatic-spread-m=0.05",
                      "--tilt-fraction=%.3f" % rng.uniform(0.25, 0.55)]
        # The truth's sensor spreads drawn once: the same seed's draws for every day would
        # repeat the day's noise, so each day has its own seed and the spreads come from
        # the first day's truth model.
        if d > 0:
            flags += ["--truth=" + first_truth]
            flags = [f for f in flags if not f.startswith("--sensor-gain-spread") and
                     not f.startswith("--sensor-bias-spread")]
            if truth:
                flags.remove("--truth=" + truth)
        ok = False
        for attempt in range(5):
            r = subprocess.run([BIN, "simulate"] + flags + ["--seed=%d" % (seed * 1000 + d * 10
                                                                         + attempt)],
                               capture_output=True, text=True)
            if r.returncode == 0:
                ok = True
                break
        if not ok:
            raise RuntimeError("simulate day %d: %s" % (d, r.stderr.strip()))
        if d == 0:
            first_truth = os.path.join(work, "first.truth.yaml")
            shutil.copy(out[:-4] + ".truth.yaml", first_truth)
        files.append(out)
    return files, model


def track(work, files, model, args):
    spec = "spec_track_moving_parts.yaml" if args.parts else "spec_track.yaml"
    # --skip-invalid-rows as on telemetry: near the cap's edge the attitude-control error
    # can put a sample where the model loops a cable (it is left out and counted).
    cmd = [BIN, "track", "--quiet", "--skip-invalid-rows",
           "--spec=" + os.path.join(ROOT, "calibration_data", spec),
           "--data=" + ",".join(files), "--out=" + os.path.join(work, "track")]
    if model:
        cmd.append("--model=" + model)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("track: " + r.stderr.strip()[-400:])
    with open(os.path.join(work, "track", "events.json")) as f:
        return json.load(f), r.stdout



def daily_means(work, days):
    """Each day's true mean of the mass centre over its samples (moves and wander included),
    as `simulate` states it in the day's truth file."""
    import re
    means = []
    for d in range(days):
        text = open(os.path.join(work, "d%02d.truth.yaml" % d)).read()
        m = re.search(r"its average over the samples was \(([^)]*)\)", text)
        means.append([float(x) for x in m.group(1).split(",")] if m else None)
    return means


def stretch_truth(e, reported, means, hours):
    """The true change between the stretches either side of reported parameter event `e`:
    the mean of the true daily means of the days after its interval up to the next reported
    change, less that of the days before it back to the previous one (days in equal weight;
    a day holding a change's interval left out). What the shift estimates when a change
    nearby went unreported; None without a whole day on either side."""
    others = sorted((x for x in reported["events"] if x["kind"] == "parameter" and x is not e),
                    key=lambda x: x["time_s"])
    low = max([x["time_high_s"] for x in others if x["time_high_s"] <= e["time_low_s"]],
              default=-math.inf)
    high = min([x["time_low_s"] for x in others if x["time_low_s"] >= e["time_high_s"]],
               default=math.inf)
    before, after = [], []
    for d, m in enumerate(means):
        first = START.timestamp() + d * DAY
        last = first + hours * 3600.0
        if m is None:
            continue
        if low < first and last < e["time_low_s"]:
            before.append(m)
        elif e["time_high_s"] < first and last < high:
            after.append(m)
    if not before or not after:
        return None
    return [sum(a[c] for a in after) / len(after) - sum(b[c] for b in before) / len(before)
            for c in range(3)]

def judge(events, reported, means=None, hours=2.0):
    """Per true event its verdict; the reported events no truth claims. Truths and reports
    are paired closest first (a report whose interval holds the truth before one that only
    lies within 1.5 days of it), so that a small move that is missed does not claim the
    report of a larger one the next night."""
    pairs = []
    for i, (kind, t, place, shift, cable) in enumerate(events):
        for k, e in enumerate(reported["events"]):
            if e["kind"] != kind or (kind == "sensor" and e.get("cables") != [cable]):
                continue
            if abs(e["time_s"] - t) > 1.5 * DAY and abs(e["after_s"] - t) > 1.5 * DAY:
                continue
            outside = max(0.0, e["time_low_s"] - t, t - e["time_high_s"])
            pairs.append((outside, abs(e["time_s"] - t), i, k))
    match, claimed = {}, set()
    for _, _, i, k in sorted(pairs):
        if i not in match and k not in claimed:
            match[i] = k
            claimed.add(k)
    verdicts = []
    for i, (kind, t, place, shift, cable) in enumerate(events):
        best = match.get(i)
        v = {"kind": kind, "place": place, "found": best is not None, "time": iso(t),
             "truth": list(shift), "cable": cable}
        if best is not None:
            e = reported["events"][best]
            v["covered"] = e["time_low_s"] <= t <= e["time_high_s"]
            v["width_s"] = e["time_high_s"] - e["time_low_s"]
            point = e["time_s"] if e["within_window"] else None
            v["dated"] = (point is not None and abs(point - t) <= DATED_S) or (
                not e["within_window"] and e["after_s"] <= t <= e["time_s"])
            # The shift is the change between the stretches either side of the interval:
            # every true move of this kind (and cable) inside it adds to it.
            total = list(shift)
            for j, (kind2, t2, _, shift2, cable2) in enumerate(events):
                if j != i and kind2 == kind and cable2 == cable and \
                        e["time_low_s"] <= t2 <= e["time_high_s"]:
                    total = [a + b for a, b in zip(total, shift2)]
                    v["merged"] = v.get("merged", 0) + 1
            names = list(e["parameters"].keys())
            v["pulls"] = [(e["parameters"][n]["shift"] - total[j]) / e["parameters"][n]["sigma_total"]
                          for j, n in enumerate(names)]
            v["size"] = math.sqrt(sum(x * x for x in shift))
            stretches = stretch_truth(e, reported, means, hours) if kind == "parameter" and \
                means else None
            if stretches is not None:
                v["pulls_stretch"] = [
                    (e["parameters"][n]["shift"] - stretches[j]) / e["parameters"][n]["sigma_total"]
                    for j, n in enumerate(names)]
        verdicts.append(v)
    # A truth not found whose moment is inside a found one's interval was reported within it.
    for i, v in enumerate(verdicts):
        if v["found"]:
            continue
        kind, t, _, _, cable = events[i]
        for k in claimed:
            e = reported["events"][k]
            if e["kind"] == kind and (kind != "sensor" or e.get("cables") == [cable]) and \
                    e["time_low_s"] <= t <= e["time_high_s"]:
                v["within_another"] = True
    false = [e for k, e in enumerate(reported["events"]) if k not in claimed]
    return verdicts, false


def judge_days(work, events, condition):
    """Per day-axis of the mass centre: within 2.5 sigma_total of the truth (the level the
    day's wander is about, plus the moves before the day; days with a move inside left
    out, and every day where the wander is not made of zero mean per day)."""
    if not condition[2]:
        return []
    import csv
    out = []
    with open(os.path.join(work, "track", "track.csv")) as f:
        for row in csv.DictReader(f):
            start = datetime.datetime.strptime(row["window_start"], "%Y-%m-%dT%H:%M:%SZ").replace(
                tzinfo=datetime.timezone.utc).timestamp()
            first, last = start + 20 * 3600.0, start + DAY
            moves = [e for e in events if e[0] == "parameter"]
            if any(first <= e[1] < last for e in moves):
                continue
            truth = list(MASS_CENTRE)
            for e in moves:
                if e[1] < first:
                    truth = [truth[a] + e[3][a] for a in range(3)]
            for a, axis in enumerate("xyz"):
                value = float(row["mass_centre_m.%s" % axis])
                sigma = float(row["mass_centre_m.%s_sigma_total" % axis])
                out.append(abs(value - truth[a]) / sigma)
    return out


def run_season(job):
    seed, args = job
    rng = random.Random(seed)
    condition = CONDITIONS[seed % len(CONDITIONS)]
    events = [] if args.mode == "null" else draw_events(rng, args.days, args.hours, args.events)
    work = os.path.join(args.work, "season_%d" % seed)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    try:
        files, model = simulate_season(work, seed, args, events, condition)
        reported, console = track(work, files, model, args)
    except RuntimeError as e:
        return {"seed": seed, "error": str(e)}
    verdicts, false = judge(events, reported, daily_means(work, args.days), args.hours)
    day_axes = judge_days(work, events, condition)
    converged = "did not converge" not in " ".join(console.split())
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return {"seed": seed, "condition": condition, "verdicts": verdicts,
            "false": [(e["kind"], e["time"]) for e in false], "converged": converged,
            "wander": reported["wander"], "day_axes": day_axes}


def rate(k, n):
    if n == 0:
        return "-"
    p = k / n
    return "%d/%d = %.3f +- %.3f" % (k, n, p, math.sqrt(max(p * (1 - p), 1e-12) / n))


def summarise(results, args):
    verdicts = [v for r in results if "verdicts" in r for v in r["verdicts"]]
    found = [v for v in verdicts if v["found"]]
    print("\nseasons %d (errors %d), events %d, found %s" % (
        len(results), sum("error" in r for r in results), len(verdicts),
        rate(len(found), len(verdicts))))
    print("seasons with a false event: %s; false events %d" % (
        rate(sum(bool(r.get("false")) for r in results if "verdicts" in r),
             sum("verdicts" in r for r in results)),
        sum(len(r.get("false", [])) for r in results)))
    print("not converged: %d" % sum(not r.get("converged", True) for r in results))
    days = [z for r in results for z in r.get("day_axes", [])]
    if days:
        print("day-axes of the mass centre within 2.5 sigma_total: %s (rms z %.2f)" % (
            rate(sum(z <= 2.5 for z in days), len(days)),
            math.sqrt(sum(z * z for z in days) / len(days))))
    for label, sel in [("all", lambda v: True), ("mass centre", lambda v: v["kind"] == "parameter"),
                       ("sensor", lambda v: v["kind"] == "sensor"),
                       ("inside a day", lambda v: v["place"] == "day"),
                       ("a day's edge", lambda v: v["place"] == "edge"),
                       ("overnight", lambda v: v["place"] == "night")]:
        group = [v for v in found if sel(v)]
        if not group:
            continue
        pulls = [p for v in group for p in v["pulls"]]
        spread = statistics.pstdev(pulls) if len(pulls) > 1 else float("nan")
        within = sum(abs(p) <= 2.5 for p in pulls)
        widths = sorted(v["width_s"] for v in group if v["place"] != "night")
        median_width = ("%.1f min" % (statistics.median(widths) / 60.0)) if widths else "-"
        print("  %-13s found %3d  interval holds the truth %s  pulls sd %.2f (|pull| <= 2.5: %s)"
              "  median width (in days) %s  dated %s" % (
                  label, len(group), rate(sum(v["covered"] for v in group), len(group)), spread,
                  rate(within, len(pulls)), median_width,
                  rate(sum(v["dated"] for v in group), len(group))))
    # The mass centre's shifts against the true change between their stretches (the day
    # means either side, stretch_truth): what the shift estimates when a move nearby went
    # unreported, where the pull against the move itself counts that move as error.
    against = [v for v in found if "pulls_stretch" in v]
    if against:
        pulls = [p for v in against for p in v["pulls_stretch"]]
        print("  mass centre's shifts against their stretches' true change (%d events): pulls sd "
              "%.2f (|pull| <= 2.5: %s)" % (len(against), statistics.pstdev(pulls),
                                             rate(sum(abs(p) <= 2.5 for p in pulls), len(pulls))))
    within = [v for v in verdicts if not v["found"] and v.get("within_another")]
    print("  not found alone but inside a found event's interval (its shift the sum): %d" %
          len(within))
    # Over every true move inside a day, found or not: a move missed is not pinned.
    moves = [v for v in verdicts if v["kind"] == "parameter" and v["place"] in ("day", "edge")]
    for lo, hi in [(0.01, 0.02), (0.02, 0.03), (0.03, 0.04)]:
        group = [v for v in moves if lo <= math.sqrt(sum(x * x for x in v["truth"])) < hi]
        print("  moves of %d-%d cm inside a day: pinned to 15 min %s (found %d)" % (
            lo * 100, hi * 100, rate(sum(v.get("dated", False) for v in group), len(group)),
            sum(v["found"] for v in group)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("mode", choices=["events", "null"])
    parser.add_argument("--seasons", type=int, default=40)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--days", type=int, default=15)
    parser.add_argument("--hours", type=float, default=2.0)
    parser.add_argument("--events", type=int, default=5)
    parser.add_argument("--parts", action="store_true", help="a cabin with moving parts")
    parser.add_argument("--work", default=None)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--keep", action="store_true", help="keep each season's files")
    args = parser.parse_args()
    if args.work is None:
        args.work = tempfile.mkdtemp(prefix="season_answers_")
    os.makedirs(args.work, exist_ok=True)
    jobs = [(s, args) for s in range(args.first_seed, args.first_seed + args.seasons)]
    results = []
    with multiprocessing.Pool(args.jobs) as pool:
        for r in pool.imap_unordered(run_season, jobs):
            results.append(r)
            if "error" in r:
                print("seed %d: %s" % (r["seed"], r["error"]), flush=True)
                continue
            v = r["verdicts"]
            print("seed %d %s: events %d found %d covered %d false %s%s" % (
                r["seed"], r["condition"], len(v), sum(x["found"] for x in v),
                sum(x.get("covered", False) for x in v), r["false"],
                "" if r["converged"] else " NOT CONVERGED"), flush=True)
            for x in v:
                if not x["found"] or not x["covered"]:
                    print("    %s %s %s at %s %s%s" % (
                        "missed" if not x["found"] else "not covered", x["kind"], x["place"],
                        x["time"], ["%.4g" % y for y in x["truth"]],
                        " cable %d" % x["cable"] if x["kind"] == "sensor" else ""), flush=True)
    with open(os.path.join(args.work, "results.json"), "w") as f:
        json.dump(results, f)
    summarise(results, args)


if __name__ == "__main__":
    main()
