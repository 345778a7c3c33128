#!/usr/bin/env bash
# Issue 16: roughing a box 5 mm around ../shared/models/ocl/mount_rush.stl (15,592 triangles)
# with a 6 mm flat end mill, 2 mm stepdown, 20 % stepover, 0.3 mm stock to leave: prints the
# planning time of the operation (`plan.planning_time_s` of report.json, the wall time from the
# start of its planning to the start of its cut), its passes and levels, and the whole run's
# wall time (planning, simulation, proof), over RUNS runs (default 3).
# Usage: bench/rough/mount_rush.sh [OUT]   Env: SCALLOP (binary, default target/release/scallop,
# built when missing), RUNS.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT="${1:-target/rough-mount-rush}"
SCALLOP="${SCALLOP:-target/release/scallop}"
RUNS="${RUNS:-3}"
PART=../shared/models/ocl/mount_rush.stl
if [ ! -f "$PART" ]; then
    echo "mount_rush.sh: $PART is absent; nothing to run."
    exit 0
fi
[ -x "$SCALLOP" ] || cargo build --release -q -p scallop-cli
mkdir -p "$OUT"
PART_ABS="$(cd "$(dirname "$PART")" && pwd)/$(basename "$PART")"
printf '%s\n' '[part]' "file = \"$PART_ABS\"" '[stock]' 'margin = 5' 'top = 5' 'bottom = 0' \
    '[[operation]]' 'kind = "rough"' '[operation.cutter]' 'shape = "flat"' 'diameter = 6' 'flute_length = 40' \
    '[operation.roughing]' 'stepdown = 2' 'stepover = 0.2' 'stock_to_leave = 0.3' > "$OUT/job.toml"
echo "| run | planning (s) | passes | levels | whole run, wall (s) |"
echo "|---|---|---|---|---|"
for run in $(seq 1 "$RUNS"); do
    start=$(date +%s.%N)
    "$SCALLOP" run "$OUT/job.toml" -o "$OUT/out" --json > "$OUT/report.json"
    end=$(date +%s.%N)
    python3 - "$OUT/report.json" "$run" "$start" "$end" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["operations"][0]["plan"]
wall = float(sys.argv[4]) - float(sys.argv[3])
print(f"| {sys.argv[2]} | {r['planning_time_s']:.2f} | {r['passes']} | {r['planes']} | {wall:.1f} |")
PY
done
