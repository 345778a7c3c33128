#!/usr/bin/env bash
# Thread scaling of `scallop drop`: for each cutter on mount_rush.stl and sphere2.stl (from
# ../shared/models/ocl, D = XY extent / 20 as in bench/ocl), a grid of about 2 million points,
# the best of RUNS kernel times (`drop_seconds`) with 1 and with 2 threads, and their ratio.
# Best-of-N because a shared 2-vCPU VM adds noise in one direction only (slower).
# Usage: bash bench/scaling.sh [RUNS]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
runs=${1:-5}
if [ ! -d ../shared/models/ocl ]; then
    echo "scaling.sh: ../shared/models/ocl is absent; nothing measured."
    exit 0
fi
cargo build --release -q -p scallop-cli
bin=target/release/scallop
best() {
    local b=""
    for _ in $(seq "$runs"); do
        local s
        s=$("$bin" drop "$@" -o "$tmp/cl.csv" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["drop_seconds"])')
        b=$(python3 -c "print(min($s, ${b:-$s}))")
    done
    echo "$b"
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| mesh | cutter | points | best 1-thread s | best 2-thread s | speedup |"
echo "|---|---|---:|---:|---:|---:|"
for spec in "mount_rush -40.958:44.862:0.0429 -24.696:18.492:0.0429 4.291 -29.94" \
            "sphere2 -4.995:22.995:0.0132 -4.999:4.999:0.0132 1.3995 -6.40"; do
    read -r mesh xs ys d floor <<<"$spec"
    for cutter in ball flat bull cone; do
        extra=()
        [ "$cutter" = bull ] && extra=(--corner-radius "$(python3 -c "print($d / 4)")")
        args=(--mesh "../shared/models/ocl/$mesh.stl" --cutter "$cutter" --diameter "$d" "${extra[@]}"
              "--x=$xs" "--y=$ys" "--floor=$floor")
        n=$("$bin" drop "${args[@]}" --threads 1 -o "$tmp/cl.csv" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["points"])')
        t1=$(best "${args[@]}" --threads 1)
        t2=$(best "${args[@]}" --threads 2)
        echo "| $mesh.stl | $cutter | $n | $t1 | $t2 | $(python3 -c "print(f'{$t1 / $t2:.2f}')") |"
    done
done
echo
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) CPUs"
