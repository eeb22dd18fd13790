#!/usr/bin/env bash
# The track's events on simulated seasons (docs/calibration.md, "Tracking over a season",
# "Events: false alarms and power"): the README's season (ten days of an hour's telemetry
# from 20:00 UTC, 2 s apart; 1% tension drift with a 2-minute memory; gain and bias
# spreads of 1% and 1.5 kN) tracked with calibration_data/spec_track.yaml.
#
# Usage: scripts/track_event_study.sh null SEEDS [WORKDIR]
#          seasons without any event: counts those that report one, per kind
#        scripts/track_event_study.sh power KIND SEEDS SIZES [WORKDIR]
#          KIND mass: a mass-centre step of d (m, along x); sensor: cable 3's bias steps
#          by d (kN); each size in SIZES (comma-separated) once inside day 5's telemetry
#          (20:30 UTC) and once overnight (12:00 UTC before it), SEEDS seasons each.
#          Found: an event of the kind (and cable) dated right (overnight: between the
#          two days' data; inside: within 15 min of the truth); also counts the seasons
#          with any other event.
# FIRST_SEED (default 1) is the first season's seed. One line per season (null) or per
# size and place (power). Needs build/bin/fastcal (scripts/build.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin="$root/build/bin/fastcal"
mode=${1:?null or power}
first=${FIRST_SEED:-1}  # the seasons' seeds: FIRST_SEED, FIRST_SEED + 1, ...
season=(--trajectory=random --samples=18000 --days=10 --interval-s=2
        --start=2024-05-01T20:00:00Z --mass-centre=0.22,0.11,0.5 --tension-drift-percent=1
        --tension-drift-time-s=120 --sensor-gain-spread-percent=1 --sensor-bias-spread-kN=1.5)
inside=2024-05-05T20:30:00Z
overnight=2024-05-05T12:00:00Z

# track SEED WORK [simulate flags...]: simulates and tracks one season into WORK/track.
track() {
  local seed=$1 work=$2
  shift 2
  "$bin" simulate "${season[@]}" "$@" --seed="$seed" --force --out="$work/season.csv" \
    >/dev/null 2>&1
  rm -rf "$work/track"
  "$bin" track --quiet --spec="$root/calibration_data/spec_track.yaml" \
    --data="$work/season.csv" --out="$work/track" >/dev/null 2>&1
}

# judge EVENTS KIND TRUTH_ISO: "detected dated others": an event of KIND (a sensor's of
# cable 3) reported, and dated right (1 or 0); the number of events of another kind or
# cable.
judge() {
  python3 - "$@" <<'EOF'
import json, sys
from datetime import datetime
events = json.load(open(sys.argv[1]))["events"]
kind, truth = sys.argv[2], sys.argv[3]
t = datetime.fromisoformat(truth.replace("Z", "+00:00")).timestamp() if truth else None
want = "sensor" if kind == "sensor" else "parameter"
detected, dated, others = 0, 0, 0
for e in events:
    if t is None or e["kind"] != want or (want == "sensor" and e.get("cables") != [3]):
        others += 1
        continue
    detected = 1
    if e["within_window"]:
        right = abs(e["time_s"] - t) <= 900.0
    else:
        right = e["after_s"] < t < e["time_s"]
    dated = max(dated, int(right))
print(detected, dated, others)
EOF
}

case $mode in
  null)
    seeds=${2:?number of seeds}
    work=${3:-$(mktemp -d)}
    mkdir -p "$work"
    parameter=0
    sensor=0
    for seed in $(seq "$first" $((first + seeds - 1))); do
      track "$seed" "$work"
      line=$(python3 -c "
import json, sys
e = json.load(open(sys.argv[1]))['events']
print(sum(x['kind'] == 'parameter' for x in e), sum(x['kind'] == 'sensor' for x in e))" \
        "$work/track/events.json")
      echo "$seed $line"
      [ "$(echo "$line" | cut -d' ' -f1)" != "0" ] && parameter=$((parameter + 1))
      [ "$(echo "$line" | cut -d' ' -f2)" != "0" ] && sensor=$((sensor + 1))
    done
    echo "null: $parameter of $seeds seasons reported a parameter event, $sensor a sensor event"
    ;;
  power)
    kind=${2:?mass or sensor}
    seeds=${3:?number of seeds}
    sizes=${4:?comma-separated sizes}
    work=${5:-$(mktemp -d)}
    mkdir -p "$work"
    for d in ${sizes//,/ }; do
      for where in inside overnight; do
        at=$inside
        [ "$where" = overnight ] && at=$overnight
        if [ "$kind" = mass ]; then step=(--mass-centre-step="$at:$d,0,0"); else
          step=(--sensor-step="$at:3:$d"); fi
        detected=0
        dated=0
        others=0
        for seed in $(seq "$first" $((first + seeds - 1))); do
          track "$seed" "$work" "${step[@]}"
          line=$(judge "$work/track/events.json" "$kind" "$at")
          detected=$((detected + $(echo "$line" | cut -d' ' -f1)))
          dated=$((dated + $(echo "$line" | cut -d' ' -f2)))
          [ "$(echo "$line" | cut -d' ' -f3)" != "0" ] && others=$((others + 1))
        done
        echo "$kind $d $where: found in $detected of $seeds, dated right in $dated," \
          "another event in $others"
      done
    done
    ;;
  *)
    echo "unknown mode $mode (null, power)" >&2
    exit 2
    ;;
esac
