#!/usr/bin/env python3
"""The deviation view of a mesh part with large facets, checked in a screenshot.

Usage:
  large_facets.py part OUT.stl     writes the part (binary STL, mm)
  large_facets.py check DOM.html SCREENSHOT.png
                                   checks report.html#colour=deviation&hide=path,stock
                                   as headless Chromium drew it (bench/report/deviation_check.sh)

The part is the kind a CAD exporter writes: a plate 80 x 60 x 8 mm with a
frustum on it (base 40 x 30, top 20 x 14, 10 mm high), 28 triangles. The
plate's top is a ring of eight triangles whose corners lie on the outline and
on the frustum's foot, so a colouring taken at the vertices has almost nothing
to go on (docs/report.md, "The deviation view").

`check` rebuilds the viewer's camera (bench/report/check.sh's window, the
fitted view of viewer.js) from the scene block of the dumped page, projects
faces of the part into the screenshot and counts, inside each face (shrunk
by a quarter towards its centre, away from edges and antialiasing), the pixels
that are the expected colour once the face's Lambert shading is divided out:
a colour of the deviation ramp on the plate's top and the frustum's top, the
wall colour on the plate's front wall. Fails unless 90 % of the pixels of
every face are.
"""
import json
import math
import re
import struct
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from page_check import CANVAS_BACKGROUND, read_png  # noqa: E402

PLATE = (80.0, 60.0, 8.0)  # x, y, height; centred on the origin in x and y
FOOT = (40.0, 30.0)  # the frustum's base on the plate
TOP = (20.0, 14.0, 18.0)  # the frustum's top and its height above z = 0

# viewer.js: the ramp's stops, the wall colour, the camera at the start.
STOPS = [(40, 60, 200), (0, 190, 220), (40, 190, 60), (240, 220, 30), (220, 50, 40)]
WALL = (205, 205, 190)
FOV = math.radians(35.0)
YAW, PITCH = -math.pi / 4, 0.6
TOLERANCE = 24.0  # RGB distance (0..255) to the expected colour after unshading
MIN_SHARE = 0.9


def rect(x, y, z):
    return [(-x / 2, -y / 2, z), (x / 2, -y / 2, z), (x / 2, y / 2, z), (-x / 2, y / 2, z)]


def triangles():
    """The part's triangles, counter-clockwise seen from outside."""
    px, py, pz = PLATE
    base, top_plate, foot = rect(px, py, 0.0), rect(px, py, pz), rect(*FOOT, pz)
    top = rect(TOP[0], TOP[1], TOP[2])
    tris = [(base[0], base[2], base[1]), (base[0], base[3], base[2])]
    for k in range(4):
        a, b = k, (k + 1) % 4
        tris += [(base[a], base[b], top_plate[b]), (base[a], top_plate[b], top_plate[a])]  # plate walls
        tris += [(top_plate[a], top_plate[b], foot[b]), (top_plate[a], foot[b], foot[a])]  # the ring
        tris += [(foot[a], foot[b], top[b]), (foot[a], top[b], top[a])]  # frustum sides
    tris += [(top[0], top[1], top[2]), (top[0], top[2], top[3])]
    return tris


def write_stl(path):
    out = bytearray(80) + struct.pack("<I", len(triangles()))
    for t in triangles():
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for p in t:
            out += struct.pack("<3f", *p)
        out += b"\0\0"
    Path(path).write_bytes(bytes(out))


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def unit(a):
    n = math.sqrt(dot(a, a)) or 1.0
    return [v / n for v in a]


def camera(scene, width, height):
    """Projects a part point (mm) to screenshot pixels inside the canvas, as viewer.js does."""
    dist = 1.02 * scene["radius"] / math.sin(FOV / 2)
    cp = math.cos(PITCH)
    eye = [dist * cp * math.cos(YAW), dist * cp * math.sin(YAW), dist * math.sin(PITCH)]
    z = unit(eye)
    x = unit(cross([0, 0, 1], z))
    y = cross(z, x)
    f = 1 / math.tan(FOV / 2)
    centre = scene["centre"]

    def project(p):
        q = sub(sub(p, centre), eye)
        vx, vy, vz = dot(x, q), dot(y, q), dot(z, q)
        ndc = (f * height / width * vx / -vz, f * vy / -vz)
        return ((ndc[0] + 1) / 2 * width, (1 - ndc[1]) / 2 * height)

    return project, z


def near_ramp(c):
    """RGB distance from c to the ramp's polyline."""
    best = math.inf
    for a, b in zip(STOPS, STOPS[1:]):
        d = sub(b, a)
        t = max(0.0, min(1.0, dot(sub(c, a), d) / dot(d, d)))
        best = min(best, math.dist(c, [a[k] + t * d[k] for k in range(3)]))
    return best


def inside(poly, x, y):
    """Point in a convex polygon (either orientation)."""
    signs = set()
    for (ax, ay), (bx, by) in zip(poly, poly[1:] + poly[:1]):
        s = (bx - ax) * (y - ay) - (by - ay) * (x - ax)
        if s != 0:
            signs.add(s > 0)
    return len(signs) <= 1


def faces():
    """(name, corners, expected) of the faces checked."""
    px, py, pz = PLATE
    fx, fy = FOOT
    # The front strip of the plate's top, between the outline and the frustum's foot.
    strip = [(-fx / 2, -py / 2, pz), (fx / 2, -py / 2, pz), (fx / 2, -fy / 2, pz), (-fx / 2, -fy / 2, pz)]
    front = [(-px / 2, -py / 2, 0.0), (px / 2, -py / 2, 0.0), (px / 2, -py / 2, pz), (-px / 2, -py / 2, pz)]
    return [
        ("plate top (front strip of the ring)", strip, "ramp"),
        ("frustum top", rect(TOP[0], TOP[1], TOP[2]), "ramp"),
        ("plate front wall", front, "wall"),
    ]


def check(dom_path, png_path):
    dom = Path(dom_path).read_text(encoding="utf-8", errors="replace")
    block = re.search(r'<script type="application/json" id="scene-data">(.*?)</script>', dom, re.S)
    scene = json.loads(block.group(1).replace("<\\/", "</"))
    width, height, channels, rows = read_png(png_path)
    bg = bytes(CANVAS_BACKGROUND)
    ys = [y for y, r in enumerate(rows) if r.count(bg) > width // 4]
    xs = [x for x in range(width) if rows[ys[len(ys) // 2]][x * channels:x * channels + 3] == bg]
    x0, y0, cw, ch = xs[0], ys[0], xs[-1] - xs[0] + 1, ys[-1] - ys[0] + 1
    project, view = camera(scene, cw, ch)
    light = view  # viewer.js lights along the view direction
    failures = 0
    for name, corners, expected in faces():
        c = [sum(p[k] for p in corners) / len(corners) for k in range(3)]
        shrunk = [[c[k] + 0.75 * (p[k] - c[k]) for k in range(3)] for p in corners]
        poly = [project(p) for p in shrunk]
        n = unit(cross(sub(corners[1], corners[0]), sub(corners[2], corners[0])))
        shade = 0.3 + 0.7 * abs(dot(n, light))
        good = total = 0
        for y in range(int(min(p[1] for p in poly)), int(max(p[1] for p in poly)) + 1):
            for x in range(int(min(p[0] for p in poly)), int(max(p[0] for p in poly)) + 1):
                if not inside(poly, x + 0.5, y + 0.5):
                    continue
                r = rows[y0 + y][(x0 + x) * channels:(x0 + x) * channels + 3]
                colour = [v / shade for v in r]
                d = near_ramp(colour) if expected == "ramp" else math.dist(colour, WALL)
                total += 1
                good += d <= TOLERANCE
        share = good / max(1, total)
        print(f"{png_path}: {name}: {good} of {total} pixels the {expected} colour ({100 * share:.1f} %)")
        if total < 200 or share < MIN_SHARE:
            print(f"{png_path}: {name}: fewer than {100 * MIN_SHARE:.0f} % of at least 200 pixels", file=sys.stderr)
            failures += 1
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "part":
        write_stl(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "check":
        check(sys.argv[2], sys.argv[3])
    else:
        raise SystemExit(__doc__)
