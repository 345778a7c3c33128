"""FreeCAD 0.20.2 Adaptive clearing (libarea `area.Adaptive2d`) of one pocket, written as G-code.

    POCKET=P.json GCODE=OUT.nc TIMING=OUT.json [DIAMETER=6 STEPOVER=0.2 ACCURACY=0.1] freecadcmd adaptive.py

Run by bench/freecad/run.sh (freecadcmd passes no arguments to a script, hence the
environment). FreeCAD is LGPL: this script only calls it as an external program.
The kernel returns tool-centre polylines with a motion type each: 0 cutting, 1 link in
cleared area (written as feed moves), 2 link that needs a retract, 3 link clear at the
previous pass (both written as a retract, a rapid and a plunge). The entry is a plunge at
the helix centre (helix diameter 0), then a feed move to the start point.
"""

import json
import os
import time

import area

CUT_Z = -1.0
SAFE_Z = 5.0
LIFT_Z = 1.0


def ring(points):
    pts = [list(p) for p in points]
    return pts + [pts[0]]


def run():
    with open(os.environ["POCKET"]) as f:
        pocket = json.load(f)
    rings = [ring(r) for r in pocket["rings"]]
    xs = [p[0] for r in rings for p in r]
    ys = [p[1] for r in rings for p in r]
    m = 50.0
    stock = [[[min(xs) - m, min(ys) - m], [max(xs) + m, min(ys) - m], [max(xs) + m, max(ys) + m],
              [min(xs) - m, max(ys) + m], [min(xs) - m, min(ys) - m]]]
    a = area.Adaptive2d()
    a.toolDiameter = float(os.environ.get("DIAMETER", "6"))
    a.stepOverFactor = float(os.environ.get("STEPOVER", "0.2"))
    a.tolerance = float(os.environ.get("ACCURACY", "0.1"))
    a.helixRampDiameter = 0
    a.keepToolDownDistRatio = 3.0
    a.stockToLeave = 0.0
    a.forceInsideOut = True
    a.finishingProfile = True
    a.opType = area.AdaptiveOperationType.ClearingInside
    t0 = time.perf_counter()
    out = a.Execute(stock, rings, lambda paths: False)
    seconds = time.perf_counter() - t0
    lines = ["(FreeCAD 0.20.2 Adaptive2d, written by bench/freecad/adaptive.py)", "G21 G90 G17",
             "G0 Z%.4f" % SAFE_Z]
    counts = {0: 0, 1: 0, 2: 0, 3: 0}

    def xy(p):
        return "X%.4f Y%.4f" % (p[0], p[1])

    for region in out:
        helix, start = region.HelixCenterPoint, region.StartPoint
        lines += ["G0 " + xy(helix), "G1 Z%.4f F1000" % CUT_Z, "G1 " + xy(start)]
        down = True
        for motion, pts in region.AdaptivePaths:
            if not pts:
                continue
            counts[motion] = counts.get(motion, 0) + 1
            if motion in (0, 1):
                if not down:
                    lines += ["G0 " + xy(pts[0]), "G1 Z%.4f" % CUT_Z]
                    down = True
                lines += ["G1 " + xy(p) for p in pts]
            else:
                lines += ["G0 Z%.4f" % (SAFE_Z if motion == 2 else LIFT_Z), "G0 " + xy(pts[-1])]
                down = False
        lines.append("G0 Z%.4f" % SAFE_Z)
    lines.append("M2")
    with open(os.environ["GCODE"], "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.environ["TIMING"], "w") as f:
        json.dump({"seconds": seconds, "regions": len(out), "paths_by_motion": counts}, f)


run()
