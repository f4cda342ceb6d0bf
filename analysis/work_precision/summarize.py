#!/usr/bin/env python3
"""Equal-error table from the work-precision CSVs of `rubblepile bench work-precision`.

For every problem and every error level 10^-k inside both curves, the wall time (median) each method needs is
interpolated log-log on its (wall_seconds, error) curve (sorted by time, first crossing), and the ratio to
Bulirsch-Stoer's is printed: ratio > 1 means the method is slower than BS at that error. The same for the
energy residual. Standard library only.

Usage: python3 analysis/work_precision/summarize.py [DIR]   (default: this script's directory)
"""

import csv
import math
import os
import sys

PROBLEMS = ["top", "pair", "pair_dissipative", "n30", "n200"]
METHODS = ["bulirsch-stoer", "dop853", "dopri5", "rk4"]


def time_at(points, level):
    pts = sorted((t, e) for t, e in points if t > 0 and e > 0 and math.isfinite(e))
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if (e0 - level) * (e1 - level) <= 0 and e0 != e1:
            s = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + s * (math.log(t1) - math.log(t0)))
    return None


def table(rows, column, title, work="wall_seconds", unit="s"):
    curves = {m: [(float(r[work]), float(r[column])) for r in rows if r["method"] == m] for m in METHODS}
    out = [f"\n{title}\n\n| error | " + " | ".join(f"{m} ({unit})" for m in METHODS)
           + " | dop853/BS | dopri5/BS | rk4/BS |\n|---" + "|---" * (len(METHODS) + 3) + "|\n"]
    for k in range(1, 15):
        level = 10.0 ** -k
        t = {m: time_at(curves[m], level) for m in METHODS}
        if t["bulirsch-stoer"] is None and t["dop853"] is None:
            continue
        cells = ["–" if t[m] is None else (f"{t[m]:.3e}" if unit == "s" else f"{t[m]:.0f}") for m in METHODS]
        ratios = []
        for m in METHODS[1:]:
            if t[m] and t["bulirsch-stoer"]:
                ratios.append(f"{t[m] / t['bulirsch-stoer']:.2f}")
            else:
                ratios.append("–")
        out.append(f"| 1e-{k} | " + " | ".join(cells) + " | " + " | ".join(ratios) + " |\n")
    return "".join(out)


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for p in PROBLEMS:
        path = os.path.join(d, f"work_precision_{p}.csv")
        if not os.path.exists(path):
            continue
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        print(f"## {p}")
        print(table(rows, "error", "Final-state error: wall time at equal error"))
        print(table(rows, "energy_error", "Energy residual: wall time at equal residual"))
        print(table(rows, "error", "Final-state error: RHS evaluations at equal error (load-independent work)",
                    work="rhs_evaluations", unit="RHS"))


if __name__ == "__main__":
    main()
