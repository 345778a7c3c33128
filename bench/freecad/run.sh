#!/usr/bin/env bash
# Side by side: FreeCAD 0.20.2 Adaptive clearing vs `scallop pocket` (--pattern offset or adaptive),
# both evaluated by the same independent measure, `scallop engagement`.
#
#   bash bench/freecad/run.sh [--reduced] [--workdir DIR] [--scallop BIN] [--planner BIN] [--pattern NAME] [--both-ways] [--markdown FILE]
#
# Pockets (bench/freecad/pockets.py): rectangle 100 x 60, the same with a 24 mm round
# island, L 100 x 80 with a 60 x 50 notch, disc 80 mm, a 16-tooth gear, a narrow branching
# pocket, a "#" glyph; --reduced: the rectangle and the "#". Tool D 6 mm, stepover 0.2 D,
# accuracy 0.1 mm. FreeCAD (LGPL) runs as an external program (`freecadcmd`); when it is
# missing and apt has `freecad-python3`, it is installed (about 1.3 GB, 5 minutes).
# scallop's side runs when `scallop pocket` exists, else it is skipped with a message;
# --pattern gives its clearing pattern (default offset: adaptive is experimental, docs/roughing.md); --planner another scallop binary
# that plans (`scallop pocket`) while --scallop evaluates (`scallop engagement`); --both-ways
# plans the adaptive passes both ways (`scallop pocket --both-ways`), FreeCAD's climb only.
# Outputs (pockets, G-code, JSON figures, each program drawn coloured by engagement as SVG) go to
# the work directory, never to the repository.
# Exit status: 0 done, 2 setup or run error.
set -euo pipefail

caller_dir=$(pwd)
repo_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
here="$repo_root/bench/freecad"
workdir="$repo_root/target/freecad-bench"
scallop=""
reduced=()
markdown=""
pattern=offset
planner=""
both=()
while [ $# -gt 0 ]; do
    case "$1" in
        --reduced) reduced=(--reduced) ;;
        --both-ways) both=(--both-ways) ;;
        --workdir|--scallop|--planner|--markdown|--pattern)
            [ $# -ge 2 ] || { echo "run.sh: $1 needs a value" >&2; exit 2; }
            val=$2
            # Relative paths from the caller's directory; a bare --scallop name is looked up in PATH.
            if [ "$1" != --pattern ] && [[ "$val" != /* ]] && { [ "$1" != --scallop ] && [ "$1" != --planner ] || [[ "$val" == */* ]]; }; then
                val="$caller_dir/$val"
            fi
            case "$1" in
                --workdir) workdir=$val ;; --scallop) scallop=$val ;; --markdown) markdown=$val ;; --pattern) pattern=$val ;;
                --planner) planner=$val ;;
            esac
            shift ;;
        -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    esac
    shift
done

# FreeCAD: install when missing and apt has it.
if ! command -v freecadcmd > /dev/null; then
    if command -v apt-get > /dev/null && apt-cache show freecad-python3 > /dev/null 2>&1; then
        echo "run.sh: installing freecad-python3 (about 1.3 GB, 5 minutes)"
        DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends freecad-python3 > "$workdir.apt.log" 2>&1 \
            || { echo "run.sh: apt-get install freecad-python3 failed, see $workdir.apt.log" >&2; exit 2; }
    else
        echo "run.sh: freecadcmd not found and apt has no freecad-python3; install FreeCAD 0.20 (freecadcmd) first" >&2
        exit 2
    fi
fi

# scallop: the given binary, else a release or fast build of this repository, else built here.
if [ -z "$scallop" ]; then
    for candidate in "$repo_root/target/release/scallop" "$repo_root/target/fast/scallop"; do
        [ -x "$candidate" ] && { scallop=$candidate; break; }
    done
fi
if [ -z "$scallop" ]; then
    echo "run.sh: building scallop (cargo build -p scallop-cli --profile fast)"
    (cd "$repo_root" && cargo build -q -p scallop-cli --profile fast)
    scallop="$repo_root/target/fast/scallop"
fi
planner=${planner:-$scallop}
has_pocket=0
if "$planner" pocket --help > /dev/null 2>&1; then
    has_pocket=1
else
    echo "run.sh: '$planner pocket' does not exist in this build: scallop's side is skipped (FreeCAD only)."
fi

mkdir -p "$workdir"
rm -rf "${workdir:?}/pockets"
python3 "$here/pockets.py" "$workdir/pockets" "${reduced[@]}" > "$workdir/pocket-names.txt"

# Each program is also drawn coloured by engagement (OUT.svg beside OUT.json, draw.py) when the
# evaluating scallop writes per-move engagement (`engagement --moves`).
moves=()
if "$scallop" engagement --help 2>/dev/null | grep -- '--moves' > /dev/null; then moves=(1); fi
evaluate() { # evaluate NAME PROGRAM OUT.json
    local extra=()
    [ ${#moves[@]} -gt 0 ] && extra=(--moves "${3%.json}-moves.csv")
    "$scallop" engagement --pocket "$workdir/pockets/$1.json" --program "$2" --tool-diameter 6 --stepover 0.2 \
        --gouge-tolerance 0.1 --json "${extra[@]}" > "$3" 2> "$3.err" || { echo "{\"error\": $(python3 -c 'import json,sys; print(json.dumps(open(sys.argv[1]).read().strip()))' "$3.err")}" > "$3"; }
    if [ ${#moves[@]} -gt 0 ] && [ -s "${3%.json}-moves.csv" ]; then
        python3 "$here/draw.py" "$workdir/pockets/$1.json" "${3%.json}-moves.csv" "${3%.json}.svg" --title "$1: $(basename "$2")" \
            || echo "run.sh: could not draw ${3%.json}.svg" >&2
    fi
}

while read -r name; do
    echo "== $name"
    out="$workdir/$name"
    mkdir -p "$out"
    POCKET="$workdir/pockets/$name.json" GCODE="$out/freecad.nc" TIMING="$out/freecad-timing.json" \
        OMP_NUM_THREADS=1 freecadcmd "$here/adaptive.py" > "$out/freecad.log" 2>&1 \
        || { echo "run.sh: FreeCAD failed on $name, see $out/freecad.log" >&2; echo '{"error": "FreeCAD failed"}' > "$out/freecad-timing.json"; }
    if [ -s "$out/freecad.nc" ]; then
        evaluate "$name" "$out/freecad.nc" "$out/freecad-eval.json"
    fi
    if [ "$has_pocket" = 1 ]; then
        rm -rf "$out/scallop"
        start=$(date +%s.%N)
        if RAYON_NUM_THREADS=1 "$planner" pocket --region "$workdir/pockets/$name.json" --tool-diameter 6 --stepover 0.2 \
            --pattern "$pattern" "${both[@]}" -o "$out/scallop" > "$out/scallop.log" 2>&1; then
            end=$(date +%s.%N)
            echo "{\"seconds\": $(python3 -c "print($end - $start)")}" > "$out/scallop-timing.json"
            program=$(find "$out/scallop" -maxdepth 1 \( -name '*.nc' -o -name '*.ngc' -o -name '*.gcode' \) | sort | head -1)
            [ -n "$program" ] || program=$(find "$out/scallop" -maxdepth 1 -name '*.csv' | sort | head -1)
            if [ -n "$program" ]; then
                evaluate "$name" "$program" "$out/scallop-eval.json"
            else
                echo '{"error": "scallop pocket wrote no program"}' > "$out/scallop-eval.json"
            fi
        else
            echo "{\"error\": \"scallop pocket failed, see $out/scallop.log\"}" > "$out/scallop-eval.json"
        fi
    fi
done < "$workdir/pocket-names.txt"

python3 "$here/compare.py" "$workdir" ${markdown:+--markdown "$markdown"}
