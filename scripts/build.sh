#!/usr/bin/env bash
# Configures and builds fastcal (Release) into build/. Usage: scripts/build.sh [target...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ $# -gt 0 ]; then
  for t in "$@"; do cmake --build "$root/build" -j "$jobs" --target "$t"; done
else
  cmake --build "$root/build" -j "$jobs"
fi
