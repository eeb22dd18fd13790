#!/usr/bin/env bash
# The main job: set up, build, and calibrate the bundled paper-like circle dataset;
# writes the report to out/demo/ (replaced on each run).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/build.sh" fastcal_cli
cd "$root"
rm -rf out/demo
build/bin/fastcal calibrate \
  --spec=calibration_data/spec_mass_centre_density.yaml \
  --data=calibration_data/circle_paper.csv \
  --out=out/demo
echo
echo "Report: $root/out/demo/report.html (also report.md, summary.json, model_calibrated.yaml)"
