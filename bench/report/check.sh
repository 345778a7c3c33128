#!/usr/bin/env bash
# Issue 7: open the HTML reports in headless Chromium and check that they work.
# Builds the demo's finishing report (`scallop demo`), the simulation report of its
# program (`scallop simulate`) and the report of a small optimisation study
# (`scallop optimize`), the report of a job of three operations (`scallop run
# examples/jobs/pocket-rest.toml`) and the deviation view of a generated mesh part with large
# facets (`scallop run`, bench/report/large_facets.py), then for each:
#   chromium --headless ... --screenshot   (1200 x 800)
#   chromium --headless ... --dump-dom
# and checks with bench/report/page_check.py that the viewer set its drawn
# marker, that the page's error element is empty (window.onerror, console.error
# and the draw try/catch write there), and that the canvas is not blank (pixel
# statistics of the screenshot); on the large facets, large_facets.py checks that
# the faces take the deviation colours (pixel statistics inside each face).
# Installs Debian's `chromium` when missing; if apt cannot, says so and exits 0.
# Usage: bench/report/check.sh [OUTDIR]   (default target/report-check)
# Env: SCALLOP (binary, default target/release/scallop, built when missing).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT="${1:-target/report-check}"
SCALLOP="${SCALLOP:-target/release/scallop}"

find_chromium() {
    for c in chromium chromium-browser; do
        command -v "$c" 2>/dev/null && return 0
    done
    return 1
}
CHROMIUM="$(find_chromium || true)"
if [ -z "$CHROMIUM" ]; then
    SUDO=""
    [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -qq >/dev/null 2>&1 || true
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null 2>&1 || true
    CHROMIUM="$(find_chromium || true)"
    if [ -z "$CHROMIUM" ]; then
        echo "check.sh: apt could not install the Debian package chromium; the browser check of the reports is skipped."
        exit 0
    fi
fi
[ -x "$SCALLOP" ] || cargo build --release -q -p scallop-cli

mkdir -p "$OUT"
"$SCALLOP" demo -o "$OUT/demo" >/dev/null
"$SCALLOP" simulate --part choi --program "$OUT/demo/program.nc" --cutter bull --diameter 10 --corner-radius 2 \
    --flute-length 30 --resolution 0.2 --gouge-tolerance 0.0125 -o "$OUT/sim" >/dev/null
# A small optimisation study (K = 2..3, 30 evaluations per K) for the optimisation report.
sed -e 's/^k_max = .*/k_max = 3/' -e 's/^budget = .*/budget = 30/' \
    examples/jobs/optimize-choi-3axis.toml > "$OUT/optimize-small.toml"
"$SCALLOP" optimize "$OUT/optimize-small.toml" -o "$OUT/optimize" >/dev/null
# A job of three operations on one stock (rough, rest, finish): one colour per operation.
"$SCALLOP" run examples/jobs/pocket-rest.toml -o "$OUT/job" >/dev/null

# Chromium stalls on connection attempts without these flags (no network here).
# WebGL runs on SwiftShader (software): --disable-gpu plus --enable-unsafe-swiftshader.
browse() {
    local profile
    profile="$(mktemp -d)"
    "$CHROMIUM" --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader \
        --disable-background-networking --disable-component-update --disable-sync --no-first-run \
        --disable-quic --user-data-dir="$profile" --window-size=1200,800 --virtual-time-budget=15000 \
        "$@" 2>/dev/null
    rm -rf "$profile"
}

# Screenshot and DOM of PAGE (opened with the URL fragment FRAGMENT, may be empty), then
# page_check.py: the drawn marker, no errors, the canvas not blank.
shoot() {
    local page="$1" fragment="$2" url shot dom
    url="file://$(cd "$(dirname "$page")" && pwd)/$(basename "$page")$fragment"
    shot="${page%.html}.png"
    dom="${page%.html}.dom.html"
    rm -f "$shot"
    (cd "$(dirname "$page")" && browse --screenshot="$(basename "$shot")" "$url") >/dev/null
    browse --dump-dom "$url" > "$dom"
    python3 bench/report/page_check.py "$dom" "$shot"
}

status=0
for page in "$OUT/demo/report.html" "$OUT/sim/report.html" "$OUT/optimize/report.html" "$OUT/job/report.html"; do
    if shoot "$page" ""; then
        echo "ok: $page"
    else
        echo "FAILED: $page" >&2
        status=1
    fi
done

# The deviation view of a mesh part with large facets (issue 22): every pixel of a big
# facet takes its cell's colour, walls the wall colour (bench/report/large_facets.py).
mkdir -p "$OUT/facets"
python3 bench/report/large_facets.py part "$OUT/facets/plate.stl"
printf '%s\n' '[part]' 'file = "plate.stl"' '[cutter]' 'shape = "ball"' 'diameter = 6' \
    '[finishing]' 'scallop_height = 0.05' '[verify]' 'resolution = 0.2' '[output]' 'spindle = 10000' \
    > "$OUT/facets/job.toml"
"$SCALLOP" run "$OUT/facets/job.toml" -o "$OUT/facets" >/dev/null
page="$OUT/facets/report.html"
if shoot "$page" "#colour=deviation&hide=path,stock" &&
    python3 bench/report/large_facets.py check "${page%.html}.dom.html" "${page%.html}.png"; then
    echo "ok: $page (deviation view)"
else
    echo "FAILED: $page (deviation view)" >&2
    status=1
fi
exit $status
