#!/usr/bin/env python3
"""Side-by-side waterline comparison: OpenCAMLib `Waterline` vs `scallop waterline`.

Run through `bash bench/ocl/compare.sh --waterline` (which provides a Python 3.11
virtualenv with the `opencamlib` wheel and builds scallop). OpenCAMLib (LGPL) is only
*run* here, as a separate installed package; none of its code is copied.

For every mesh, cutter (ball, flat, bull r = D/4, cone 90 deg included angle; D = 1/20 of
the mesh's larger XY extent, as in compare.py) and z level, both engines compute the
waterline loops at the same tip height, single-threaded:
- agreement: every OpenCAMLib loop point (a push-cutter contact on an X or Y fibre, on
  the true contour up to its root finder) is measured to scallop's loops (closed
  polylines); target 1e-5 mm. The other direction (scallop points to OpenCAMLib's
  polylines) is printed too: it includes OpenCAMLib's own chord error between fibre
  points, about sampling^2 / (8 radius of curvature), so it has no target;
- loop counts per level;
- speed: OpenCAMLib `Waterline.run()` summed over the levels vs scallop's command
  time for all levels (grid + contours, wall clock from `--json`), both on one thread;
  also as CPU time, which the load of a shared machine inflates far less than wall
  time, in two ratios:
  - kernel (like for like): OpenCAMLib's `run()` calls by `time.process_time` (its STL
    load and kd-tree build, `setSTL`, are outside them) vs scallop's
    `kernel_cpu_seconds` from `--json`: the process CPU clock around the part's
    preparation (mesh copy and XY index build, included to be conservative), the
    drop-cutter grid and all levels' loops; scallop's mesh file parse, output
    writing and process start are outside it, as OpenCAMLib's Python-side STL
    parse and loop read-back are outside `run()`;
  - whole process: the same `run()` calls vs scallop's whole process (the children's
    `getrusage`: process start, mesh parse, index, kernel, CSV writing), which
    favours OpenCAMLib;
  scallop runs twice, both with chord tolerance CHORD_TOLERANCE (--chord-tolerance):
  with its grid step equal to OpenCAMLib's fibre spacing (the same feature resolution;
  the same feature resolution), and with its default step R/4 (2.5 times coarser; gaps
  and islands between samples are looked for: the product's own setting, whose loops
  are as exact as at the finer step, since a contour between samples is found by the
  covers and gap walks of docs/waterline.md, not by the sampling). Both runs are judged
  alike (the exit status fails on either), and each has its wall and kernel CPU times
  and ratios.

Exit status: 0 all cases within tolerance, 1 some case exceeds it, 2 usage or run error.
"""

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare import load_stl, fmt, brute_drop, CONE_INCLUDED_ANGLE_DEG  # noqa: E402

try:
    from opencamlib import ocl
except ImportError:  # pragma: no cover - reported plainly below
    ocl = None

CUTTERS = ("ball", "flat", "bull", "cone")
TOLERANCE = 1e-5  # mm, OpenCAMLib point to scallop loop
# scallop's chord tolerance for the comparison (--chord-tolerance): its chords stay
# this close to the contour at their midpoints, and its long chords at their quarter
# points too (docs/waterline.md, step 6), inside TOLERANCE with a margin: a chord
# whose contour bends at a point off its middle deviates there by up to about twice
# what its midpoint does (on the eleven meshes: at most 9.9e-6 mm with 8e-6, and
# 4.5e-5 mm with 8e-6 before long chords were checked at their quarters;
# docs/benchmarks.md).
CHORD_TOLERANCE = 6e-6
FULL_LEVELS = 5
REDUCED_LEVELS = 1
# OpenCAMLib fibre spacing as a fraction of the cutter diameter.
SAMPLING_PER_DIAMETER = 0.05
REDUCED_MESHES = ("sphere_on_plate.stl", "cone_on_side.stl")
# Adjudication of an OpenCAMLib point away from scallop's loops: the independent numpy
# brute-force drop-cutter of compare.py on a circle of this radius around it. A point on
# the true contour has both sides on every small circle; a circle all on one side proves
# the point is not on the contour.
ADJUDICATE_RADIUS = 1e-4
ADJUDICATE_SAMPLES = 16
ADJUDICATE_POINTS = 5


def make_ocl_cutter(name, d, length):
    """OpenCAMLib cutters as in compare.py, with a given length: a waterline from
    above needs the cutter (and its shank) to reach above the part, as scallop's
    drop-cutter does (its cutter continues upwards as a cylinder of radius R)."""
    if name == "ball":
        return ocl.BallCutter(d, length)
    if name == "flat":
        return ocl.CylCutter(d, length)
    if name == "bull":
        return ocl.BullCutter(d, d / 4.0, length)
    if name == "cone":  # OCL takes the half-angle in radians
        return ocl.ConeCutter(d, math.radians(CONE_INCLUDED_ANGLE_DEG / 2.0), length)
    raise ValueError(name)


def levels_of(zmin, zmax, count):
    """Heights spread over (zmin, zmax), off any round fraction of the range."""
    return [zmin + (k + 0.382) / count * (zmax - zmin) for k in range(count)]


def run_ocl(surf, cutter, z, sampling):
    w = ocl.Waterline()
    w.setThreads(1)
    w.setSTL(surf)
    w.setCutter(cutter)
    w.setZ(z)
    w.setSampling(sampling)
    t, c = time.perf_counter(), time.process_time()
    w.run()
    dt, dc = time.perf_counter() - t, time.process_time() - c
    loops = [np.array([(p.x, p.y) for p in lp], dtype=np.float64) for lp in w.getLoops()]
    return [lp for lp in loops if len(lp)], dt, dc


def run_scallop(exe, mesh, cname, d, zs, out_csv, chord, step):
    cmd = [exe, "waterline", "--mesh", mesh, "--cutter", cname, "--diameter", fmt(d)]
    if cname == "bull":
        cmd += ["--corner-radius", fmt(d / 4.0)]
    if cname == "cone":
        cmd += ["--angle", fmt(CONE_INCLUDED_ANGLE_DEG)]
    for z in zs:
        cmd += ["--z", fmt(z)]
    if chord is not None:
        cmd += ["--chord-tolerance", fmt(chord)]
    if step is not None:
        cmd += ["--step", fmt(step)]
    cmd += ["--threads", "1", "-o", out_csv, "--json"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise RuntimeError(f"scallop failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr.strip()}")
    info = json.loads(r.stdout)
    # CPU time of the whole process (reading the mesh and writing the loops included):
    # unlike the wall time, it does not grow with the load of the machine.
    info["cpu_seconds"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if info.get("kernel_cpu_seconds") is None:
        raise RuntimeError(f"scallop gave no kernel_cpu_seconds (not Linux, or an older build): {' '.join(cmd)}")
    data = np.loadtxt(out_csv, delimiter=",", skiprows=1, ndmin=2)
    loops = {}
    for k in np.unique(data[:, 0]).astype(int):
        rows = data[data[:, 0] == k]
        loops.setdefault(float(rows[0, 3]), []).append(rows[:, 1:3].copy())
    return loops, info, " ".join(cmd)


class Segments:
    """The chords of closed polylines, bucketed on a uniform grid for nearest queries."""

    def __init__(self, loops):
        a = [lp for lp in loops if len(lp) >= 2]
        self.a = np.concatenate(a) if a else np.zeros((0, 2))
        self.b = np.concatenate([np.roll(lp, -1, axis=0) for lp in a]) if a else np.zeros((0, 2))
        lengths = np.hypot(*(self.b - self.a).T)
        self.cell = max(float(lengths.max()) if len(lengths) else 1.0, 1e-6)
        mid = 0.5 * (self.a + self.b)
        keys = np.floor(mid / self.cell).astype(np.int64)
        self.buckets = {}
        for i, (kx, ky) in enumerate(keys.tolist()):
            self.buckets.setdefault((kx, ky), []).append(i)
        self.buckets = {k: np.array(v) for k, v in self.buckets.items()}

    def distance(self, p):
        """Distance from p to the nearest chord; inf if none within one cell."""
        kx, ky = (int(math.floor(p[0] / self.cell)), int(math.floor(p[1] / self.cell)))
        idx = [self.buckets[(kx + i, ky + j)] for i in (-1, 0, 1) for j in (-1, 0, 1) if (kx + i, ky + j) in self.buckets]
        if not idx:
            return math.inf
        idx = np.concatenate(idx)
        a, b = self.a[idx], self.b[idx]
        d = b - a
        t = np.clip(((p - a) * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0.0, 1.0)
        q = a + d * t[:, None]
        best = float(np.hypot(*(q - p).T).min())
        return best if best <= 0.5 * self.cell else math.inf


def distances(points, loops):
    seg = Segments(loops)
    return np.array([seg.distance(p) for p in points]) if len(points) else np.zeros(0)


def adjudicate(tris, cname, d, z, points):
    """For OCL points away from scallop's loops: (not on the contour, undecided) counts
    and a few lines, by the brute force on a small circle around each point."""
    wrong, lines = 0, []
    for x, y in points:
        ang = np.linspace(0.0, 2 * math.pi, ADJUDICATE_SAMPLES, endpoint=False)
        inside = [brute_drop(tris, cname, d, x + ADJUDICATE_RADIUS * math.cos(t), y + ADJUDICATE_RADIUS * math.sin(t)) > z
                  for t in ang]
        if all(inside) or not any(inside):
            wrong += 1
            side = "inside the material (the cutter at z cuts there)" if all(inside) else "outside, away from the part"
            lines.append(f"    OCL point ({x:.6f}, {y:.6f}) at z {z:.6f} is not on the contour: all {ADJUDICATE_SAMPLES} "
                         f"brute-force samples within {ADJUDICATE_RADIUS:g} mm are {side}")
        else:
            lines.append(f"    OCL point ({x:.6f}, {y:.6f}) at z {z:.6f}: the contour passes within "
                         f"{ADJUDICATE_RADIUS:g} mm (scallop misses it)")
    return wrong, lines


class Agreement:
    """One scallop run's loops against OpenCAMLib's, level by level: the distances both
    ways and the farthest points, then the verdict (with the brute-force adjudication)."""

    def __init__(self, loops, cmd):
        self.loops, self.cmd = loops, cmd
        self.n_ours = 0
        self.d_o2s, self.d_s2o, self.far_ocl, self.far_ours = [], [], [], []

    def add(self, z, pts, theirs):
        mine = self.loops.get(float(z), [])
        self.n_ours += len(mine)
        dz = distances(pts, mine)
        self.d_o2s.append(dz)
        worst = np.argsort(-dz)[:ADJUDICATE_POINTS]
        self.far_ocl += [(z, pts[i]) for i in worst if dz[i] > TOLERANCE]
        mpts = np.concatenate(mine) if mine else np.zeros((0, 2))
        ds = distances(mpts, theirs)
        self.d_s2o.append(ds)
        self.far_ours += [(z, mpts[i]) for i in np.where(~np.isfinite(ds))[0][:ADJUDICATE_POINTS]]

    def o2s(self):
        return np.concatenate(self.d_o2s) if self.d_o2s else np.zeros(0)

    def s2o(self):
        return np.concatenate(self.d_s2o) if self.d_s2o else np.zeros(0)

    def over(self):
        return int((self.o2s() > TOLERANCE).sum())

    def judge(self, tris, cname, d, n_ocl, known):
        """None when every point agrees, else (text, failed)."""
        over, far = self.over(), int((~np.isfinite(self.s2o())).sum())
        if not (over or far):
            return None
        line = (f"{over} OCL points farther than {TOLERANCE:g} mm from scallop's loops, "
                f"{far} scallop points with no OCL loop nearby, loops {n_ocl} (OCL) vs {self.n_ours} (scallop); "
                f"reproduce: {self.cmd}")
        checked = self.far_ocl[:ADJUDICATE_POINTS]
        wrong, lines = 0, []
        for z, (x, y) in checked:
            w, ls = adjudicate(tris, cname, d, z, [(x, y)])
            wrong += w
            lines += ls
        # scallop points with no OpenCAMLib loop nearby: is the contour really there?
        missed = 0
        for z, (x, y) in self.far_ours[:ADJUDICATE_POINTS]:
            w, ls = adjudicate(tris, cname, d, z, [(x, y)])
            if w == 0:
                missed += 1
                lines.append(f"    scallop point ({x:.6f}, {y:.6f}) at z {z:.6f} with no OCL loop nearby: the brute "
                             f"force confirms the contour passes within {ADJUDICATE_RADIUS:g} mm (OCL misses it)")
            else:
                lines += [ln.replace("OCL point", "scallop point") for ln in ls]
        checked_ours = min(len(self.far_ours), ADJUDICATE_POINTS)
        line += "\n" + "\n".join(lines)
        ocl_points_wrong = not checked or wrong == len(checked)
        failed = False
        if over == 0 and far and missed == checked_ours:
            line += (f"\n    => OpenCAMLib misses a loop that the brute force confirms at every checked point "
                     f"({missed} of {checked_ours}): accepted, not scallop's error")
        elif over and ocl_points_wrong and missed == checked_ours:
            line += (f"\n    => OpenCAMLib wrong at every checked point ({wrong} of {len(checked)}, worst first)"
                     + (f", and misses a loop the brute force confirms ({missed} of {checked_ours})" if far else "")
                     + ": accepted, not scallop's error")
        elif cname in known:
            line += "\n    => known OpenCAMLib defect: reported, not failed"
        else:
            failed = True
            line += "\n    => FAIL"
        return line, failed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes", nargs="+", help="STL files (binary or ASCII)")
    ap.add_argument("--reduced", action="store_true",
                    help=f"{REDUCED_LEVELS} levels on {', '.join(REDUCED_MESHES)} only (CI)")
    ap.add_argument("--scallop", default=os.path.join("target", "release", "scallop"), help="scallop binary")
    ap.add_argument("--cutters", default=",".join(CUTTERS), help="comma-separated subset of " + ",".join(CUTTERS))
    ap.add_argument("--workdir", default=os.path.join("bench", "ocl", "results"), help="where loop CSV files go")
    ap.add_argument("--markdown", help="also write the table as Markdown to this file")
    ap.add_argument("--keep-csv", action="store_true", help="keep scallop's loop CSV files in --workdir")
    ap.add_argument("--repeat", type=int, default=1,
                    help="run each engine this many times per case and keep the least time of each "
                         "kind (wall, CPU, kernel CPU): a shared or noisy machine's spikes dropped (default 1)")
    ap.add_argument("--chord-tolerance", type=float, default=CHORD_TOLERANCE,
                    help=f"scallop's chord tolerance in mm for both runs (default {CHORD_TOLERANCE:g})")
    ap.add_argument("--known-ocl-defect", default="",
                    help="comma-separated cutters whose OpenCAMLib waterline is known to be wrong: reported, not failed")
    a = ap.parse_args()
    if a.repeat < 1:
        print(f"error: --repeat must be at least 1, got {a.repeat}", file=sys.stderr)
        return 2
    if ocl is None:
        print("error: the opencamlib module is not importable (needs CPython 3.11 + `pip install opencamlib`)", file=sys.stderr)
        return 2
    cutters = [c for c in a.cutters.split(",") if c]
    for c in cutters:
        if c not in CUTTERS:
            ap.error(f"unknown cutter {c!r}")
    known = {c for c in a.known_ocl_defect.split(",") if c}
    os.makedirs(a.workdir, exist_ok=True)
    meshes = [m for m in a.meshes if not a.reduced or os.path.basename(m) in REDUCED_MESHES] or a.meshes[:1]
    nlev = REDUCED_LEVELS if a.reduced else FULL_LEVELS
    head = ["mesh", "triangles", "cutter", "levels", "loops OCL/scallop", "OCL points", "max OCL->scallop (mm)",
            "mean OCL->scallop (mm)", "over tol", "max scallop->OCL polyline (mm)", "OCL s 1 thr",
            f"scallop s 1 thr (step = OCL sampling, chord {a.chord_tolerance:g})", "OCL/scallop",
            "scallop s 1 thr (step R/4)", "OCL/scallop (step R/4)", "over tol (step R/4)",
            "OCL CPU s", "scallop kernel CPU s (step = OCL sampling)", "OCL/scallop kernel CPU",
            "scallop CPU s (step = OCL sampling, whole process)", "OCL/scallop CPU (whole process)",
            "scallop kernel CPU s (step R/4)", "OCL/scallop kernel CPU (step R/4)"]
    print(f"# OpenCAMLib {ocl.version()} Waterline; mode {'reduced' if a.reduced else 'full'}; tolerance {TOLERANCE:g} mm "
          f"(OCL point to scallop loop); scallop chord tolerance {a.chord_tolerance:g} mm; OCL sampling "
          f"{SAMPLING_PER_DIAMETER:g} D", flush=True)
    print(" | ".join(head), flush=True)
    rows, notes, failures = [], [], []
    status = 0
    load0 = os.getloadavg()
    ratios = []
    for mesh in meshes:
        base = os.path.basename(mesh)
        tris, kind = load_stl(mesh)
        v = tris.reshape(-1, 3)
        lo, hi = v.min(0), v.max(0)
        big = float(max(hi[0] - lo[0], hi[1] - lo[1]))
        d = big / 20.0
        sampling = SAMPLING_PER_DIAMETER * d
        zs = levels_of(float(lo[2]), float(hi[2]), nlev)
        notes.append(f"{base}: {kind} STL, {len(tris)} triangles, D = {d:.6g} mm, OCL sampling {sampling:.6g} mm, "
                     f"levels {', '.join(f'{z:.4f}' for z in zs)}")
        surf = ocl.STLSurf()
        for t in tris:
            surf.addTriangle(ocl.Triangle(*(ocl.Point(*map(float, p)) for p in t)))
        for cname in cutters:
            cutter = make_ocl_cutter(cname, d, float(hi[2] - lo[2]) + 4.0 * d)
            stem = os.path.join(a.workdir, f"{os.path.splitext(base)[0]}_{cname}_waterline.csv")
            try:
                ours, info, cmd = run_scallop(a.scallop, mesh, cname, d, zs, stem, a.chord_tolerance, sampling)
                # --repeat: the least time of each kind over the runs (the loops are the same each run).
                for _ in range(a.repeat - 1):
                    _, again, _ = run_scallop(a.scallop, mesh, cname, d, zs, stem, a.chord_tolerance, sampling)
                    for key in ("seconds", "cpu_seconds", "kernel_cpu_seconds"):
                        info[key] = min(info[key], again[key])
                coarse, info_default, cmd_default = run_scallop(a.scallop, mesh, cname, d, zs, stem, a.chord_tolerance,
                                                                 None)
                for _ in range(a.repeat - 1):
                    _, again, _ = run_scallop(a.scallop, mesh, cname, d, zs, stem, a.chord_tolerance, None)
                    for key in ("seconds", "cpu_seconds", "kernel_cpu_seconds"):
                        info_default[key] = min(info_default[key], again[key])
            except (RuntimeError, OSError, ValueError) as e:
                print(f"error: {e}", file=sys.stderr)
                return 2
            if not a.keep_csv:
                os.remove(stem)
            t_ocl, c_ocl, n_ocl, npts = 0.0, 0.0, 0, 0
            # Per scallop run (at OCL's sampling, at the default step): loops, distances both ways, far points.
            runs = {"fine": Agreement(ours, cmd), "default": Agreement(coarse, cmd_default)}
            for z in zs:
                theirs, dt, dc = run_ocl(surf, cutter, z, sampling)
                for _ in range(a.repeat - 1):
                    _, dt2, dc2 = run_ocl(surf, cutter, z, sampling)
                    dt, dc = min(dt, dt2), min(dc, dc2)
                t_ocl += dt
                c_ocl += dc
                n_ocl += len(theirs)
                pts = np.concatenate(theirs) if theirs else np.zeros((0, 2))
                npts += len(pts)
                for run in runs.values():
                    run.add(z, pts, theirs)
            fine, default = runs["fine"], runs["default"]
            d_o2s, d_s2o = fine.o2s(), fine.s2o()
            over, over_coarse = fine.over(), default.over()
            n_ours = fine.n_ours
            t_ours = info["seconds"]
            ratio = t_ocl / t_ours if t_ours > 0 else math.inf
            t_default = info_default["seconds"]
            ratio_default = t_ocl / t_default if t_default > 0 else math.inf
            c_ours = info["cpu_seconds"]
            ratio_cpu = c_ocl / c_ours if c_ours > 0 else math.inf
            k_ours = info["kernel_cpu_seconds"]
            ratio_kernel = c_ocl / k_ours if k_ours > 0 else math.inf
            k_default = info_default["kernel_cpu_seconds"]
            ratio_kernel_default = c_ocl / k_default if k_default > 0 else math.inf
            fin = d_s2o[np.isfinite(d_s2o)]
            row = [base, str(len(tris)), cname, str(len(zs)), f"{n_ocl}/{n_ours}", str(npts),
                   f"{d_o2s.max() if len(d_o2s) else 0:.2e}", f"{d_o2s.mean() if len(d_o2s) else 0:.2e}", str(over),
                   f"{fin.max() if len(fin) else 0:.2e}" + ("" if len(fin) == len(d_s2o) else f" ({len(d_s2o) - len(fin)} far)"),
                   f"{t_ocl:.3f}", f"{t_ours:.3f}", f"{ratio:.1f}", f"{t_default:.3f}", f"{ratio_default:.1f}",
                   str(over_coarse), f"{c_ocl:.3f}", f"{k_ours:.3f}", f"{ratio_kernel:.1f}", f"{c_ours:.3f}",
                   f"{ratio_cpu:.1f}", f"{k_default:.3f}", f"{ratio_kernel_default:.1f}"]
            rows.append(row)
            print(" | ".join(row), flush=True)
            if cname not in known:
                ratios.append((ratio, ratio_default, ratio_cpu, ratio_kernel, ratio_kernel_default, over, over_coarse))
            # OpenCAMLib sometimes splits one contour into several loops (or adds
            # one-point loops): the loop counts are informational. A failure is an
            # OpenCAMLib point away from scallop's loops, or a scallop point with no
            # OpenCAMLib polyline nearby (a loop OpenCAMLib does not have); both
            # scallop runs are judged alike.
            for label, run in (("", fine), (" (default step R/4)", default)):
                verdict = run.judge(tris, cname, d, n_ocl, known)
                if verdict is None:
                    continue
                line, failed = verdict
                line = f"  {base} {cname}{label}: " + line
                if failed:
                    status = 1
                failures.append(line)
                print(line, flush=True)
        del surf
    if ratios:
        r1, r2 = [r[0] for r in ratios], [r[1] for r in ratios]
        notes.append(f"speed ratio OCL/scallop, single thread, all levels of a case: scallop at OCL's sampling and "
                     f"chord tolerance {a.chord_tolerance:g} mm min {min(r1):.1f}, median {float(np.median(r1)):.1f}; "
                     f"scallop with step R/4 (same chord tolerance) min {min(r2):.1f}, median {float(np.median(r2)):.1f}")
        r4 = [r[3] for r in ratios]
        notes.append(f"CPU-time ratio OCL/scallop at OCL's sampling, kernel (OCL's run() calls vs scallop's "
                     f"kernel_cpu_seconds: index build, grid and loops): min {min(r4):.1f}, median "
                     f"{float(np.median(r4)):.1f}, at least 20 on {sum(r >= 20 for r in r4)} of {len(r4)} cases")
        r5 = [r[4] for r in ratios]
        same = sum(r[5] == r[6] for r in ratios)
        notes.append(f"CPU-time ratio OCL/scallop, kernel, scallop at its default step R/4 (same chord tolerance; "
                     f"its loops as close to OpenCAMLib's: OCL points over the tolerance the same as at OCL's "
                     f"sampling on {same} of {len(ratios)} cases): min {min(r5):.1f}, median "
                     f"{float(np.median(r5)):.1f}, at least 20 on {sum(r >= 20 for r in r5)} of {len(r5)} cases")
        r3 = [r[2] for r in ratios]
        notes.append(f"CPU-time ratio OCL/scallop at OCL's sampling, whole process (OCL's run() calls vs scallop's "
                     f"whole process: start, mesh parse, index, grid, loops, CSV writing): min {min(r3):.1f}, median "
                     f"{float(np.median(r3)):.1f}, at least 20 on {sum(r >= 20 for r in r3)} of {len(r3)} cases")
    notes.append(f"load average (1/5/15 min) at start {load0[0]:.2f}/{load0[1]:.2f}/{load0[2]:.2f}, at end "
                 "{:.2f}/{:.2f}/{:.2f} on {} CPUs".format(*os.getloadavg(), os.cpu_count()))
    print("\nNotes:")
    for n in notes:
        print("  " + n)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(f"OpenCAMLib {ocl.version()} Waterline, mode {'reduced' if a.reduced else 'full'}; tolerance "
                    f"{TOLERANCE:g} mm; scallop chord tolerance {a.chord_tolerance:g} mm.\n\n")
            f.write("| " + " | ".join(head) + " |\n")
            f.write("|" + "|".join("---" if i < 3 else "---:" for i in range(len(head))) + "|\n")
            for r in rows:
                f.write("| " + " | ".join(r) + " |\n")
            f.write("\n")
            for n in notes:
                f.write(f"- {n}\n")
            if failures:
                f.write("\n```\n" + "\n".join(failures) + "\n```\n")
    return status


if __name__ == "__main__":
    sys.exit(main())
