"""The pockets of the FreeCAD Adaptive comparison, written as pocket JSON files.

    python3 bench/freecad/pockets.py OUT_DIR [--reduced]

Format (shared with `scallop pocket --region` and `scallop engagement --pocket`):
{"units": "mm", "rings": [[[x, y], ...], ...]}, the outer boundary (the pocket wall) first,
then islands; rings are not closed (the last point is not the first) and the outer ring is
counter-clockwise, islands clockwise.
"""

import json
import math
import os
import sys


def circle(cx, cy, r, n=128, clockwise=False):
    pts = [[cx + r * math.cos(2 * math.pi * k / n), cy + r * math.sin(2 * math.pi * k / n)] for k in range(n)]
    return pts[::-1] if clockwise else pts


def rectangle(x0, y0, x1, y1, clockwise=False):
    pts = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    return pts[::-1] if clockwise else pts


def gear(cx, cy, teeth=16, tip=40.0, root=33.0, per_tooth=24):
    """A spur-gear outline: each tooth a rounded trapezoid between the root and tip circles."""
    pts = []
    n = teeth * per_tooth
    for k in range(n):
        a = 2 * math.pi * k / n
        phase = (k % per_tooth) / per_tooth  # 0..1 within a tooth pitch
        # Tooth profile: flank up over 0.15, tip over 0.25, flank down over 0.15, root 0.45.
        if phase < 0.15:
            r = root + (tip - root) * (0.5 - 0.5 * math.cos(math.pi * phase / 0.15))
        elif phase < 0.40:
            r = tip
        elif phase < 0.55:
            r = tip - (tip - root) * (0.5 - 0.5 * math.cos(math.pi * (phase - 0.40) / 0.15))
        else:
            r = root
        pts.append([cx + r * math.cos(a), cy + r * math.sin(a)])
    return pts


def branching():
    """A narrow branching pocket: a 10 mm channel with fingers 7 to 9 mm wide, one slanted."""
    pts = [[0, 0], [100, 0], [100, 10]]
    # Fingers going up from the channel, right to left: (x_left, width, height).
    fingers = [(84, 8.0, 40.0), (62, 7.0, 35.0), (40, 9.0, 45.0)]
    for x, w, h in fingers:
        pts += [[x + w, 10], [x + w, 10 + h], [x, 10 + h], [x, 10]]
    # A slanted branch at 45 degrees, 7.5 mm wide, from x = 12..22.6 on the channel.
    w = 7.5 / math.cos(math.pi / 4)
    pts += [[12 + w, 10], [12 + w - 30, 40], [12 - 30, 40], [12, 10]]
    pts += [[0, 10]]
    return pts


def hash_glyph():
    """A "#": four bars 12 mm wide over 80 x 80 mm; the central square is an island."""
    outer = [[20, 0], [32, 0], [32, 20], [48, 20], [48, 0], [60, 0], [60, 20], [80, 20], [80, 32], [60, 32],
             [60, 48], [80, 48], [80, 60], [60, 60], [60, 80], [48, 80], [48, 60], [32, 60], [32, 80], [20, 80],
             [20, 60], [0, 60], [0, 48], [20, 48], [20, 32], [0, 32], [0, 20], [20, 20]]
    return [outer, rectangle(32, 32, 48, 48, clockwise=True)]


def pockets():
    return {
        "rectangle": [rectangle(0, 0, 100, 60)],
        "rectangle_island": [rectangle(0, 0, 100, 60), circle(50, 30, 12, clockwise=True)],
        "l_shape": [[[0, 0], [100, 0], [100, 30], [40, 30], [40, 80], [0, 80]]],
        "disc": [circle(40, 40, 40, n=256)],
        "gear": [gear(45, 45)],
        "branching": [branching()],
        "hash": hash_glyph(),
    }


REDUCED = ["rectangle", "hash"]


def main():
    out = sys.argv[1]
    reduced = "--reduced" in sys.argv[2:]
    os.makedirs(out, exist_ok=True)
    for name, rings in pockets().items():
        if reduced and name not in REDUCED:
            continue
        rounded = [[[round(x, 6), round(y, 6)] for x, y in ring] for ring in rings]
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump({"units": "mm", "rings": rounded}, f)
        print(name)


if __name__ == "__main__":
    main()
