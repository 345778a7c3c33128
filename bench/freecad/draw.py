#!/usr/bin/env python3
"""Draws a pocket program coloured by engagement, as SVG (no dependencies).

    python3 draw.py POCKET.json MOVES.csv OUT.svg [--target DEG] [--title TEXT]

POCKET.json is bench/freecad/pockets.py's pocket ({"units": "mm", "rings": [...]}), MOVES.csv
is `scallop engagement --moves`'s output (move,kind,x0,y0,x1,y1,z,phi_deg: each move's largest
engagement). Colours: grey, no cut (a tool-down link or air); blue, up to 1.1 x the target;
orange, up to 1.2 x; red, above; black and thick, a full slot (170 degrees or more). Rapids,
plunges and retracts are left out. A long move is coloured by its largest engagement all along.
"""

import argparse
import csv
import json
import sys


def colour(phi, target):
    if phi < 5.0:
        return "#b0b0b0", 0.25
    if phi <= 1.1 * target:
        return "#2b59c3", 0.3
    if phi <= 1.2 * target:
        return "#f39c12", 0.6
    if phi < 170.0:
        return "#d62728", 0.8
    return "#000000", 1.2


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pocket")
    ap.add_argument("moves")
    ap.add_argument("out")
    ap.add_argument("--target", type=float, default=53.13, help="target engagement (degrees)")
    ap.add_argument("--title", default="")
    args = ap.parse_args()
    try:
        with open(args.pocket) as f:
            rings = json.load(f)["rings"]
        with open(args.moves, newline="") as f:
            rows = list(csv.DictReader(f))
    except (OSError, ValueError, KeyError) as e:
        print(f"draw.py: {e}", file=sys.stderr)
        return 2
    xs = [p[0] for r in rings for p in r]
    ys = [p[1] for r in rings for p in r]
    if not xs:
        print(f"draw.py: {args.pocket}: no rings", file=sys.stderr)
        return 2
    pad = 5.0
    x0, y0, x1, y1 = min(xs) - pad, min(ys) - pad, max(xs) + pad, max(ys) + pad
    scale = 800.0 / max(x1 - x0, y1 - y0)
    w, h = (x1 - x0) * scale, (y1 - y0) * scale

    def pt(x, y):
        return f"{(x - x0) * scale:.2f},{(y1 - y) * scale:.2f}"

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0f}" height="{h + 30:.0f}">',
           '<rect width="100%" height="100%" fill="white"/>']
    for r in rings:
        out.append(f'<polygon points="{" ".join(pt(x, y) for x, y in r)}" fill="none" stroke="#444" stroke-width="1"/>')
    for row in rows:
        if row["kind"] not in ("Feed", "Link"):
            continue
        c, sw = colour(float(row["phi_deg"]), args.target)
        a = pt(float(row["x0"]), float(row["y0"]))
        b = pt(float(row["x1"]), float(row["y1"]))
        out.append(f'<polyline points="{a} {b}" stroke="{c}" stroke-width="{sw * scale / 4:.2f}" fill="none"/>')
    legend = (f"{args.title}  grey: no cut, blue: <= 1.1 x target ({args.target:.1f} deg), "
              "orange: <= 1.2 x, red: above, black: full slot")
    out.append(f'<text x="5" y="{h + 20:.0f}" font-family="sans-serif" font-size="12">{legend}</text>')
    out.append("</svg>")
    with open(args.out, "w") as f:
        f.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
