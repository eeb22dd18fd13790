#!/usr/bin/env bash
# The change scan's false-alarm rate (docs/calibration.md, "Change scan"): simulates
# surveys without a step of the mass centre and counts those in which
# calibration_data/spec_change_scan.yaml reports a change.
#
# Usage: scripts/change_scan_false_alarms.sh CASE SEEDS [WORKDIR]
#   CASE  white    3% white tension noise, per-cable density/gain/bias spreads, white
#                  attitude-control error, attitude and position noise
#         sensor   the same with slow errors: 2% tension drift (120 s correlation),
#                  attitude-control error correlated over 60 s
#         mcdrift  sensor, and the mass centre drifting (AR(1), 2 cm, 30 min), as
#                  calibration_data/realistic_survey.csv
# Each survey: 600 random poses of the cap up to 40 deg off axis, 2 s apart. Prints one
# line per seed (seed, changes, largest statistic, threshold, widening, change times)
# and the count. Needs build/bin/fastcal (scripts/build.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
case_=${1:?CASE (white, sensor or mcdrift)}
seeds=${2:?number of seeds}
work=${3:-$(mktemp -d)}
mkdir -p "$work"
bin="$root/build/bin/fastcal"
common=(--trajectory=random --samples=600 --max-off-axis-deg=40 --interval-s=2
        --mass-centre=0.22,0.11,0.5 --tension-noise-percent=3 --density-mismatch-percent=1.5
        --sensor-gain-spread-percent=1 --sensor-bias-spread-kN=2 --attitude-noise-deg=0.02
        --position-noise-m=0.01 --attitude-control-deg=0.2)
slow=(--attitude-control-time-s=60 --tension-drift-percent=2 --tension-drift-time-s=120)
case $case_ in
  white) extra=() ;;
  sensor) extra=("${slow[@]}") ;;
  mcdrift) extra=("${slow[@]}" --mass-centre-drift-m=0.02 --mass-centre-drift-time-s=1800) ;;
  *) echo "unknown case $case_ (white, sensor, mcdrift)" >&2; exit 2 ;;
esac
alarms=0
for seed in $(seq 1 "$seeds"); do
  "$bin" simulate "${common[@]}" "${extra[@]}" --seed="$seed" --force \
    --out="$work/survey.csv" >/dev/null 2>&1
  rm -rf "$work/out"
  "$bin" calibrate --quiet --spec="$root/calibration_data/spec_change_scan.yaml" \
    --data="$work/survey.csv" --out="$work/out" >/dev/null 2>&1
  line=$(python3 -c "
import json, sys
d = json.load(open(sys.argv[1])); s = d['change_scan']
print(sys.argv[2], len(d['changes']), round(max(s['statistic']), 2), round(s['threshold'], 2),
      round(s['widening'], 3), [round(c['time_s']) for c in d['changes']])" \
    "$work/out/summary.json" "$seed")
  echo "$line"
  [ "$(echo "$line" | cut -d' ' -f2)" != "0" ] && alarms=$((alarms + 1))
done
echo "$case_: $alarms of $seeds surveys raised an alarm"
