#!/usr/bin/env bash
# Checks a survey design's predictions (docs/design.md, "Predictions that hold"): designs a
# survey with `fastcal design`, simulates telemetry at its poses at several seeds with the
# nuisance drawn from the spec's priors (per cable: density 1.5%, gain 1%, bias 2 kN: the
# tolerances of calibration_data/spec_realistic.yaml), calibrates each, and compares the
# predicted sigma_total of the mass centre with the calibrations' own and with the spread
# of their estimates about the truth.
# Usage: scripts/check-design.sh OUTDIR SEEDS [design flags...]
#   e.g. scripts/check-design.sh out/check-tilt 10 --max-extra-tilt-deg=5 --max-extra-yaw-deg=10
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin="$root/build/bin/fastcal"
out=$1
seeds=$2
shift 2
spec="$root/calibration_data/spec_realistic.yaml"
rm -rf "$out"
"$bin" design --spec="$spec" --samples=360 --out="$out/design" "$@"
for seed in $(seq 1 "$seeds"); do
  "$bin" simulate --poses="$out/design/poses.csv" --seed="$seed" --density-mismatch-percent=1.5 \
    --sensor-gain-spread-percent=1 --sensor-bias-spread-kN=2 --out="$out/sim$seed.csv" 2>/dev/null
  "$bin" calibrate --spec="$spec" --data="$out/sim$seed.csv" --out="$out/cal$seed" --quiet \
    >/dev/null 2>&1
done
python3 - "$out" "$seeds" <<'PY'
import json, sys, math
out, seeds = sys.argv[1], int(sys.argv[2])
design = json.load(open(f"{out}/design/design.json"))
pred = {p["name"]: p["sigma_total"] for p in design["parameters"]}
names = ["mass_centre_m.x", "mass_centre_m.y", "mass_centre_m.z"]
truth = [0.0, 0.0, 0.5]  # the nominal model's mass centre (simulate's default truth)
print("parameter         predicted  calibrate's (mean)  RMS error  RMS/predicted")
for i, n in enumerate(names):
    reported, errors = [], []
    for s in range(1, seeds + 1):
        summary = json.load(open(f"{out}/cal{s}/summary.json"))
        p = next(p for p in summary["parameters"] if p["name"] == n)
        reported.append(p["sigma_total"])
        errors.append(p["estimate"] - truth[i])
    rms = math.sqrt(sum(e * e for e in errors) / len(errors))
    print(f"{n:17s} {pred[n]*1e3:8.2f} mm {sum(reported)/len(reported)*1e3:10.2f} mm "
          f"{rms*1e3:11.2f} mm {rms/pred[n]:9.2f}")
PY
