#!/usr/bin/env python3
"""The table of bench/plan_only/check.sh: estimated against planned passes.

Usage: table.py OUTDIR

Reads OUTDIR/times.txt (name, job, estimate seconds, run seconds per line),
OUTDIR/NAME.plan.json (`scallop run --plan-only --json`) and
OUTDIR/NAME/report.json (the full run), prints a Markdown table, one row per
operation, and exits 1 when an estimate took 1 s or more or missed the planned
passes by more than 10 % (or a job failed).
"""
import json
import sys
from pathlib import Path

MAX_SECONDS = 1.0
MAX_ERROR = 0.10


def planned(report):
    """(passes, planes) per operation of a report.json."""
    if "operations" in report:
        return [(op["plan"]["passes"], op["plan"]["planes"]) for op in report["operations"]]
    return [(report["plan"]["passes"], report["plan"]["planes"])]


def main():
    out = Path(sys.argv[1])
    print("| job | operation | strategy | estimated passes (planes + levels) | planned passes (planes) "
          "| error | estimate (s) | full run (s) |")
    print("|---|---|---|---|---|---|---|---|")
    bad = 0
    for line in (out / "times.txt").read_text().splitlines():
        name, job, t_plan, t_run = line.split()
        t_plan, t_run = float(t_plan), float(t_run)
        try:
            estimates = json.loads((out / f"{name}.plan.json").read_text())
        except (OSError, ValueError):
            err = (out / f"{name}.plan.err").read_text().strip().splitlines()
            print(f"| {name} | | | estimate failed: {err[-1] if err else '?'} | | | {t_plan:.2f} | {t_run:.1f} |")
            bad += 1
            continue
        try:
            plans = planned(json.loads((out / name / "report.json").read_text()))
        except (OSError, ValueError, KeyError):
            err = (out / f"{name}.run.err").read_text().strip().splitlines()
            plans = [None] * len(estimates)
            print(f"| {name} | | | | full run failed: {err[-1] if err else '?'} | | | {t_run:.1f} |")
            bad += 1
        for item, plan in zip(estimates, plans):
            e = item["estimate"]
            parts = f"{e['planes']} + {e['levels']}" if e["levels"] else f"{e['planes']}"
            if e["strategy"] == "rough":
                parts = f"{e['levels']} levels"
            if plan is None:
                continue
            error = (e["passes"] - plan[0]) / max(1, plan[0])
            if abs(error) > MAX_ERROR or t_plan >= MAX_SECONDS:
                bad += 1
            print(f"| {name} | {item['name']} | {e['strategy']} | {e['passes']} ({parts}) | {plan[0]} ({plan[1]}) "
                  f"| {100 * error:+.1f} % | {t_plan:.2f} | {t_run:.1f} |")
    print(f"\n{bad} operation(s) or job(s) outside {100 * MAX_ERROR:.0f} % or {MAX_SECONDS} s, or failed.")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
