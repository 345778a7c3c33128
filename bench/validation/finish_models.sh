#!/usr/bin/env bash
# Issue 15 "done when": every mesh of ../shared/models/ocl and ../shared/models/mech finished
# with the default strategy (steep-and-shallow on meshes), with a ball and a bull-nose cutter
# sized for the part, at sh 0.01 mm and 0.05 mm. Runs the job files of examples/jobs/finish
# (one per case), writes each run's output into OUT, and a table (markdown) of part, cutter, sh, exit code, passes, levels, predicted time, planning
# time, simulated scallop, unreachable area.
# Usage: bench/validation/finish_models.sh [OUT] [--reduced]   (reduced: sphere_on_plate and cone_on_side)
# Env: SCALLOP (binary, default target/release/scallop, built when missing), TIMEOUT (s, 600),
# PARTS (comma-separated part names without extension, e.g. mount_rush,demo: only those; default all).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT="${1:-target/finish-models}"
REDUCED="${2:-}"
SCALLOP="${SCALLOP:-target/release/scallop}"
TIMEOUT="${TIMEOUT:-600}"
MODELS=../shared/models
if [ ! -d "$MODELS" ]; then
    echo "finish_models.sh: ../shared/models is absent; nothing to run."
    exit 0
fi
[ -x "$SCALLOP" ] || cargo build --release -q -p scallop-cli
mkdir -p "$OUT"
# The jobs are examples/jobs/finish/<part>-<ball|bull>-<sh>.toml (the cutter sizes a
# machinist would pick for each part are in them); their part paths are relative to the
# job file, so they are run from where they are.
JOBS=examples/jobs/finish
CASES="$(ls "$JOBS" | sed -n 's/-\(ball\|bull\)-0\.0[15]\.toml$//p' | sort -u)"
if [ "$REDUCED" = "--reduced" ]; then
    CASES="$(printf '%s\n' "$CASES" | grep -E '^(sphere_on_plate|cone_on_side)$')"
fi
if [ -n "${PARTS:-}" ]; then
    CASES="$(printf '%s\n' "$CASES" | grep -E "^($(printf '%s' "$PARTS" | tr ',' '|'))$")"
fi
TABLE="$OUT/table.md"
echo "| part | cutter | sh mm | exit | passes | levels | predicted time | planning s | simulated scallop mm | unreachable mm2 |" > "$TABLE"
echo "|---|---|---|---|---|---|---|---|---|---|" >> "$TABLE"
while read -r base; do
    for sh in 0.01 0.05; do
        for tool in ball bull; do
            name="$base-$tool-$sh"
            job="$JOBS/$name.toml"
            part="$(sed -n 's|^file = "\.\./\.\./\.\./\.\./shared/models/\(.*\)"$|\1|p' "$job")"
            start=$(python3 -c "import time; print(time.time())")
            set +e
            timeout "$TIMEOUT" "$SCALLOP" run "$job" -o "$OUT/$name" --json > "$OUT/$name.json" 2> "$OUT/$name.err"
            code=$?
            set -e
            secs=$(python3 -c "import time; print(time.time() - $start)")
            python3 - "$OUT/$name.json" "$part" "$tool" "$sh" "$code" "$secs" "$OUT/$name.err" >> "$TABLE" <<'PY'
import json, sys
path, part, tool, sh, code, secs, err = sys.argv[1:]
cutter = tool
try:
    r = json.load(open(path))
    p = r["plan"]
    t = p["total_time_s"]
    hms = f"{t:.0f} s" if t < 60 else f"{int(t)//3600}:{int(t)//60%60:02d}:{int(t)%60:02d}"
    print(f"| {part} | {r['cutter']} | {sh} | {code} | {p['passes']} | {p['planes']} | {hms} | {float(secs):.1f} | "
          f"{r['sim_max_scallop_mm']:.4f} | {r['rest']['area_mm2']:.0f} |")
except Exception:
    msg = open(err).read().strip().replace("|", "/").replace("\n", " ")[:160]
    print(f"| {part} | {cutter} | {sh} | {code} | | | | {float(secs):.1f} | {msg} | |")
PY
        done
    done
done <<< "$CASES"
cat "$TABLE"
