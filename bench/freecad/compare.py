"""The side-by-side table of bench/freecad/run.sh from the JSON files in its work directory.

    python3 bench/freecad/compare.py WORKDIR [--markdown FILE]
"""

import json
import os
import sys

COLUMNS = [
    ("compute s", lambda t, e: t.get("seconds")),
    ("phi p50", lambda t, e: e.get("phi_p50_deg")),
    ("p95", lambda t, e: e.get("phi_p95_deg")),
    ("p99", lambda t, e: e.get("phi_p99_deg")),
    ("max", lambda t, e: e.get("phi_max_deg")),
    ("> 1.2 target %", lambda t, e: e.get("over_percent")),
    ("slot mm", lambda t, e: e.get("slot_mm")),
    ("air %", lambda t, e: e.get("air_percent")),
    ("links %", lambda t, e: e.get("link_percent")),
    ("retracts", lambda t, e: e.get("retracts")),
    ("uncut mm2", lambda t, e: e.get("uncut_mm2")),
    ("wall reach mm", lambda t, e: e.get("max_penetration_mm")),
    ("time s", lambda t, e: e.get("time_jerk_limited_s")),
]
RATIOS = {"compute s", "max", "links %", "time s"}


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def cell(v):
    if v is None:
        return "-"
    if isinstance(v, int):
        return str(v)
    return "%.2f" % v if abs(v) < 10 else "%.1f" % v


def main():
    work = sys.argv[1]
    markdown = sys.argv[sys.argv.index("--markdown") + 1] if "--markdown" in sys.argv else None
    with open(os.path.join(work, "pocket-names.txt")) as f:
        names = [line.strip() for line in f if line.strip()]
    head = ["pocket", "program"] + [c for c, _ in COLUMNS]
    rows = [head, ["---"] * len(head)]
    notes = []
    for name in names:
        sides = {}
        for side in ("freecad", "scallop"):
            timing = load(os.path.join(work, name, side + "-timing.json")) or {}
            ev = load(os.path.join(work, name, side + "-eval.json"))
            if ev is None and not timing:
                continue
            ev = ev or {"error": "no program"}
            if "error" in ev:
                notes.append("%s, %s: %s" % (name, side, ev["error"]))
            sides[side] = [get(timing, ev) for _, get in COLUMNS]
            rows.append([name, side] + [cell(v) for v in sides[side]])
        if "freecad" in sides and "scallop" in sides:
            ratio = []
            for (col, _), f, s in zip(COLUMNS, sides["freecad"], sides["scallop"]):
                ok = col in RATIOS and isinstance(f, (int, float)) and isinstance(s, (int, float)) and f
                ratio.append("%.2f" % (s / f) if ok else "")
            rows.append([name, "scallop / FreeCAD"] + ratio)
    text = "\n".join("| " + " | ".join(r) + " |" for r in rows)
    if notes:
        text += "\n\n" + "\n".join("- " + n for n in notes)
    print(text)
    if markdown:
        with open(markdown, "w") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
