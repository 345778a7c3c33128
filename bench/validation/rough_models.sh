#!/usr/bin/env bash
# Issue 16 on real parts: every mesh of ../shared/models/ocl and ../shared/models/mech roughed
# from a box (5 mm around the part, 2 mm above it; 1 mm and 0.5 mm for the 10 mm `demo`) by a
# flat end mill, then rest-roughed by a smaller one, on one simulated stock, proven there. The
# tools are those a machinist would pick for the part's size and narrowest features (the table
# below). The jobs are written into OUT (they read the meshes by absolute path, so they are not
# committed) and run with `scallop run JOB -o OUT/NAME --json`; a markdown table of each
# operation's exit, machine time, planning time, engagement (p99 / max outside entries, target;
# the largest in entries),
# slot length, links, and the material left (reachable step height, unreachable volume) goes to
# OUT/table.md and stdout.
# Usage: bench/validation/rough_models.sh [OUT] [--reduced]   (reduced: sphere_on_plate, demo)
# Env: SCALLOP (binary, default target/release/scallop, built when missing), TIMEOUT (s, 600),
# PATTERNS (comma-separated, default "offset,adaptive"), PARTS (comma-separated part names).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT="${1:-target/rough-models}"
REDUCED="${2:-}"
SCALLOP="${SCALLOP:-target/release/scallop}"
TIMEOUT="${TIMEOUT:-600}"
PATTERNS="${PATTERNS:-offset,adaptive}"
MODELS=../shared/models
if [ ! -d "$MODELS" ]; then
    echo "rough_models.sh: ../shared/models is absent; nothing to run."
    exit 0
fi
MODELS="$(cd "$MODELS" && pwd)"
[ -x "$SCALLOP" ] || cargo build --release -q -p scallop-cli
mkdir -p "$OUT"
# part file | units | rough D, stepdown | rest D, stepdown | stepover (x D) | allowance | flute | margin, top
CASES="$(cat <<'EOF'
ocl/30sphere.stl|mm|10 3|4 1.5|0.2|0.3|70|5 2
ocl/carpet1.stl|mm|12 3|6 1.5|0.2|0.3|25|5 2
ocl/cone_on_side.stl|mm|4 1.5|2 0.75|0.2|0.2|30|5 2
ocl/demo.stl|mm|2 0.5|1 0.25|0.2|0.1|8|1 0.5
ocl/failedinpycam.stl|mm|6 1|3 0.5|0.2|0.2|12|5 2
ocl/mount_rush.stl|mm|6 2|3 1|0.2|0.3|40|5 2
ocl/pycam-textbox.stl|mm|4 1.5|2 0.75|0.2|0.2|20|5 2
ocl/sphere.stl|mm|16 4|8 2|0.2|0.5|115|5 2
ocl/sphere2.stl|mm|4 1.5|2 0.75|0.2|0.2|30|5 2
ocl/sphere_cutout.stl|mm|10 3|4 1.5|0.2|0.3|75|5 2
ocl/sphere_on_plate.stl|mm|10 2.5|4 1|0.25|0.5|45|5 2
mech/angle_block.STL|in|6 2|3 1|0.2|0.3|45|5 2
mech/idler_riser.STL|in|8 2|3 1|0.25|0.3|25|5 2
mech/octagonal_pocket.stl|m|12 3|6 1.5|0.25|0.5|30|5 2
EOF
)"
if [ "$REDUCED" = "--reduced" ]; then
    CASES="$(printf '%s\n' "$CASES" | grep -E '^ocl/(sphere_on_plate|demo)\.stl')"
fi
if [ -n "${PARTS:-}" ]; then
    CASES="$(printf '%s\n' "$CASES" | grep -E "/($(printf '%s' "$PARTS" | tr ',' '|'))\.(stl|STL)\|")"
fi
TABLE="$OUT/table.md"
echo "| part | pattern | operation | exit | machine time s | plan s | p99 / max deg (target) | entries: max deg | slot mm | links % | left: reached max mm, unreachable mm3 |" > "$TABLE"
echo "|---|---|---|---|---|---|---|---|---|---|---|" >> "$TABLE"
while IFS='|' read -r file units rough rest stepover allowance flute box; do
    part="$(basename "$file" | sed 's/\.[sS][tT][lL]$//')"
    read -r rd rs <<< "$rough"
    read -r sd ss <<< "$rest"
    read -r margin top <<< "$box"
    for pattern in $(printf '%s' "$PATTERNS" | tr ',' ' '); do
        name="$part-$pattern"
        job="$OUT/$name.toml"
        cat > "$job" <<EOF
[part]
file = "$MODELS/$file"
units = "$units"

[stock]
margin = $margin
top = $top
bottom = 0

[[operation]]
kind = "rough"
name = "rough, flat $rd"
tool = 1
spindle = 12000
[operation.cutter]
shape = "flat"
diameter = $rd
flute_length = $flute
[operation.roughing]
stepdown = $rs
stepover = $stepover
stock_to_leave = $allowance
pattern = "$pattern"

[[operation]]
kind = "rest"
name = "rest, flat $sd"
tool = 2
spindle = 18000
[operation.cutter]
shape = "flat"
diameter = $sd
flute_length = $flute
[operation.roughing]
stepdown = $ss
stepover = $stepover
stock_to_leave = $allowance
pattern = "$pattern"

[tolerances]
path = 0.01

[machine]
feed = 5.0
acceleration = 6.0
jerk = 40.0
rapid = 30.0
clearance = 5.0

[verify]
resolution = $(python3 -c "print(min(0.1, $rd / 40))")

[output]
dialect = "linuxcnc"
EOF
        set +e
        timeout "$TIMEOUT" "$SCALLOP" run "$job" -o "$OUT/$name" --json > "$OUT/$name.json" 2> "$OUT/$name.err"
        code=$?
        set -e
        python3 - "$OUT/$name/report.json" "$file" "$pattern" "$code" "$OUT/$name.err" >> "$TABLE" <<'PY'
import json, sys
path, part, pattern, code, err = sys.argv[1:]
try:
    r = json.load(open(path))
except Exception:
    msg = open(err).read().strip().replace("|", "/").replace("\n", " ")[:200]
    print(f"| {part} | {pattern} | | {code} | | | | | | | {msg} |")
    sys.exit(0)
for op in r["operations"]:
    e, left, plan = op.get("engagement"), op.get("left"), op["plan"]
    eng = f"{e['p99_deg']:.1f} / {e['max_deg']:.1f} ({e['target_deg']:.1f})" if e else ""
    entry = f"{e['entry_max_deg']:.1f}" if e else ""
    slot = f"{e['slot_length_mm']:.1f}" if e else ""
    links = f"{100 * e['link_share']:.1f}" if e else ""
    lf = f"{left['reached_max_mm']:.2f}, {left['unreachable_volume_mm3']:.0f}" if left else ""
    print(f"| {part} | {pattern} | {op['name']} | {code} | {plan['total_time_s']:.1f} | "
          f"{plan.get('planning_time_s', 0):.1f} | {eng} | {entry} | {slot} | {links} | {lf} |")
PY
    done
done <<< "$CASES"
cat "$TABLE"
