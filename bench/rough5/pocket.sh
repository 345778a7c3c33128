#!/usr/bin/env bash
# Issue 18: planning time of the closed test pocket (scallop-parts, 100 x 100 x 35 mm) by
# `scallop rough5`, both variants (guide-curve tilt and zero tilt), RUNS runs each (default 3):
# the planning and proof wall times the command reports, V_r and the machine time. The issue's
# target: planning under 30 s on the 2-core machine.
# Usage: bench/rough5/pocket.sh [OUT]   Env: SCALLOP (binary, default target/release/scallop,
# built when missing), RUNS.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT="${1:-target/rough5-pocket}"
SCALLOP="${SCALLOP:-target/release/scallop}"
RUNS="${RUNS:-3}"
[ -x "$SCALLOP" ] || cargo build --release -q -p scallop-cli
mkdir -p "$OUT"
echo "| variant | run | planning (s) | proof (s) | V_r (%) | machine time (s) |"
echo "|---|---|---|---|---|---|"
for tilt in guides zero; do
    for run in $(seq 1 "$RUNS"); do
        "$SCALLOP" rough5 --part pocket --tilt "$tilt" -o "$OUT/$tilt" --json > "$OUT/$tilt.json"
        python3 - "$OUT/$tilt.json" "$tilt" "$run" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
m = r["metrics"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {r['plan_seconds']:.2f} | {r['proof_seconds']:.2f} | "
      f"{m['remaining_percent']:.2f} | {m['machining_time_s']:.1f} |")
PY
    done
done
