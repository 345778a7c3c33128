#!/usr/bin/env bash
# Side-by-side drop-cutter comparison: OpenCAMLib BatchDropCutter vs `scallop drop`.
#
#   bash bench/ocl/compare.sh [--reduced] [--ocl-only] [--markdown FILE] [--cutters LIST]
#                             [--keep-csv] [--adjudicate N] [--adjudicate-random N] [MESH.stl ...]
#   bash bench/ocl/compare.sh --waterline [--reduced] [--markdown FILE] [--cutters LIST] [MESH.stl ...]
#       (waterline mode: OpenCAMLib Waterline vs `scallop waterline`, bench/ocl/waterline.py)
#
# Without meshes it uses every ../shared/models/ocl/*.stl (relative to the repository
# root); if ../shared is absent it says so and exits 0 without comparing.
# OpenCAMLib (LGPL) is installed from PyPI into bench/ocl/.venv and run side by side;
# its wheel exists only for CPython 3.11. Exit status: 0 all cases within tolerance,
# 1 a case exceeds its tolerance, 2 setup or run error.
set -euo pipefail

caller_dir=$(pwd)
repo_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$repo_root"

venv=bench/ocl/.venv
py_args=()
meshes=()
ocl_only=0
script=bench/ocl/compare.py
while [ $# -gt 0 ]; do
    case "$1" in
        --reduced|--keep-csv) py_args+=("$1") ;;
        --ocl-only) py_args+=("$1"); ocl_only=1 ;;
        --waterline) script=bench/ocl/waterline.py ;;
        --markdown|--cutters|--workdir|--adjudicate|--adjudicate-random)
            [ $# -ge 2 ] || { echo "compare.sh: $1 needs a value" >&2; exit 2; }
            val=$2
            if [ "$1" = --markdown ] || [ "$1" = --workdir ]; then
                case "$val" in /*) ;; *) val="$caller_dir/$val" ;; esac
            fi
            py_args+=("$1" "$val"); shift ;;
        -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "compare.sh: unknown option $1" >&2; exit 2 ;;
        *) case "$1" in /*) meshes+=("$1") ;; *) meshes+=("$caller_dir/$1") ;; esac ;;
    esac
    shift
done

if [ ${#meshes[@]} -eq 0 ]; then
    if [ ! -d ../shared ]; then
        echo "compare.sh: ../shared is not present next to the repository; no shared meshes, nothing compared."
        exit 0
    fi
    shopt -s nullglob
    meshes=(../shared/models/ocl/*.stl)
    shopt -u nullglob
    if [ ${#meshes[@]} -eq 0 ]; then
        echo "compare.sh: no ../shared/models/ocl/*.stl found; nothing compared."
        exit 0
    fi
fi

# Python 3.11 virtualenv with the opencamlib wheel (created once, then reused).
if [ ! -f "$venv/.ready" ]; then
    py=""
    for cand in python3.11 python3; do
        if command -v "$cand" >/dev/null 2>&1 &&
            "$cand" -c 'import sys; sys.exit(0 if sys.version_info[:2] == (3, 11) else 1)' 2>/dev/null; then
            py=$cand
            break
        fi
    done
    if [ -z "$py" ]; then
        echo "compare.sh: CPython 3.11 is required (the opencamlib wheel exists only for 3.11); none found" >&2
        exit 2
    fi
    echo "compare.sh: creating $venv with $("$py" --version)"
    rm -rf "$venv"
    "$py" -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check opencamlib numpy
    "$venv/bin/python" -c 'from opencamlib import ocl; import numpy' # fails loudly if the wheel is unusable
    touch "$venv/.ready"
fi

if [ "$ocl_only" -eq 0 ]; then
    cargo build --release -p scallop-cli
fi

exec "$venv/bin/python" "$script" "${py_args[@]}" "${meshes[@]}"
