#!/usr/bin/env bash
# A season of a cabin with moving parts tracked with the parts shared (docs/calibration.md,
# "Moving parts", issue 35): 16 observing days of 40 minutes from 20:00 UTC, 2 s apart,
# each day's feed splitting the tilt between cabin and rotator differently (the focal law's
# tilt fraction drawn per day from 0.32..0.42, the rotator completing the rest), the
# platform spread 5 cm, a 1 %, 120 s slow sensor error, the mass centre moved 3.6 cm in x
# before day 9. Tracked from a first moment of 0 with
# calibration_data/spec_track_moving_parts.yaml.
#
# Usage: scripts/moving_parts_season_study.sh FIRST_MOMENT_KG_M SEEDS [WORKDIR]
#   FIRST_MOMENT_KG_M: the rotator's first moment (its z, negative: below the axes),
#   SEEDS: comma-separated. One line per season: events reported (the move is 1), the
#   day-axes whose mass centre is within 2.5 sigma_total of the truth, converged, the
#   first moment's z with sigma_total, and whether the move was dated between days 8 and 9.
# Needs build/bin/fastcal (scripts/build.sh). Random cap poses a day's tilt split cannot
# hold are redrawn (another seed for that day).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin="$root/build/bin/fastcal"
moment=${1:?first moment (kg m)}
seeds=${2:?seeds}
work=${3:-$(mktemp -d)}
model="$root/calibration_data/moving_parts.yaml"
for seed in ${seeds//,/ }; do
  dir="$work/season_${moment}_$seed"
  rm -rf "$dir" && mkdir -p "$dir"
  sed "s/first_moment_kg_m: \[0, 0, -6000\]/first_moment_kg_m: [0, 0, -$moment]/" "$model" \
    > "$dir/truth.yaml"
  sed "s/first_moment_kg_m: \[0, 0, -6000\]/first_moment_kg_m: [0, 0, 0]/" "$model" \
    > "$dir/start.yaml"
  files=""
  for d in $(seq 1 16); do
    tilt=$(python3 -c "import random; random.seed($seed * 100 + $d); print(round(random.uniform(0.32, 0.42), 3))")
    x=0.22
    [ "$d" -ge 9 ] && x=0.256
    day=$(date -u -d "2024-05-01 +$((d - 1)) days" +%Y-%m-%d)
    for try in $(seq 0 10); do
      if "$bin" simulate --truth="$dir/truth.yaml" --trajectory=random --samples=1200 \
        --interval-s=2 --start="${day}T20:00:00Z" --mass-centre=$x,0.11,0.5 \
        --joint-law=focal --tilt-fraction="$tilt" --prismatic-spread-m=0.05 \
        --tension-drift-percent=1 --tension-drift-time-s=120 \
        --seed=$((seed * 1000 + d * 10 + try)) --out="$dir/d$d.csv" --force \
        > /dev/null 2>&1; then
        break
      fi
    done
    files="$files,$dir/d$d.csv"
  done
  "$bin" track --spec="$root/calibration_data/spec_track_moving_parts.yaml" \
    --model="$dir/start.yaml" --data="${files#,}" --out="$dir/track" > "$dir/track.log" 2>&1
  python3 - "$dir" "$moment" "$seed" <<'PY'
import csv, re, sys
directory, moment, seed = sys.argv[1], float(sys.argv[2]), sys.argv[3]
log = open(f"{directory}/track.log").read()
events = re.search(r"Events .*?: (\d+)", log)
rows = list(csv.DictReader(open(f"{directory}/track/track.csv")))
inside = total = 0
for day, row in enumerate(rows):
    truth = {"x": 0.22 if day < 8 else 0.256, "y": 0.11, "z": 0.5}
    for axis in "xyz":
        value = float(row[f"mass_centre_m.{axis}"])
        sigma = float(row[f"mass_centre_m.{axis}_sigma_total"])
        total += 1
        inside += abs(value - truth[axis]) < 2.5 * sigma
qz = re.search(r"first_moment_kg_m.z = (\S+) \+- (\S+)", log)
dated = "between 2024-05-08T20:39:58Z and 2024-05-09T20:00:00Z: mass_centre_m.x" in log
print(f"seed {seed}: events {events.group(1) if events else '?'}, within 2.5 sigma "
      f"{inside}/{total}, converged {'converged in' in ' '.join(log.split())}, Q_z {qz.group(1)} +- "
      f"{qz.group(2)} kg m (truth {-moment:g}), move dated {dated}")
PY
done
