#!/usr/bin/env python3
"""Two builds side by side on this machine, interleaved (issue 39: the 2-core figures of REPORT.md).

For every round, each binary in turn runs, at 1 and 2 threads:
  `bench rhs` on N2000_T4 and N10000_T4 (exact gravity, and the tree with the step's lists on N10000),
  `bench ssdem --particles 40000` (contacts only) and with the tree every 10 steps,
  `bench impact` of the N200 impact (P2, 45 deg, Bulirsch-Stoer at rtol 1e-6, 10 000 s).
The machine is shared; interleaving the builds round by round and quoting medians (and the medians of per-round
ratios) keeps a slow minute from favouring one build. Writes `samples.csv` (round, build, case, threads, value,
unit) and `summary.csv` (build, case, threads, median, speed-up median over the rounds' 1-thread/2-thread pairs)
into --out, and prints the summary.

    python3 analysis/scaling/local_ab.py --bin before=target/base-rubblepile --bin after=target/release/rubblepile \\
        --rounds 5 --out analysis/scaling/local_2026-11-27/ab
"""
import argparse
import csv
import os
import statistics
import subprocess
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def run(cmd):
    subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def cases(binary, tmp):
    """Yields (case, threads, value, unit) for one build: seconds per RHS, particle-steps/s, wall seconds."""
    for target, gravity in [("N2000_T4", "direct"), ("N10000_T4", "direct"), ("N10000_T4", "tree-step")]:
        out = os.path.join(tmp, "rhs")
        run([binary, "bench", "rhs", "--targets", f"targets/{target}.csv", "--gravity", gravity, "--threads", "2",
             "--repeats", "10", "--out", out, "--force"])
        for r in read_csv(os.path.join(out, "bench_rhs.csv")):
            yield f"rhs-{target}-{gravity}", int(r["threads"]), float(r["median_us"]) * 1e-6, "s per RHS"
    for name, extra in [("ssdem-40k", []), ("ssdem-40k-tree10", ["--gravity", "tree", "--gravity-interval", "10"])]:
        out = os.path.join(tmp, "ssdem")
        run([binary, "bench", "ssdem", "--particles", "40000", "--threads", "1,2", "--steps", "30", *extra,
             "--out", out, "--force"])
        for r in read_csv(os.path.join(out, "bench_ssdem.csv")):
            yield name, int(r["threads"]), float(r["particle_steps_per_second"]), "particle-steps/s"
    out = os.path.join(tmp, "impact")
    run([binary, "bench", "impact", "--target", "targets/N200_T4.csv", "--threads", "1,2", "--out", out, "--force"])
    for r in read_csv(os.path.join(out, "bench_impact.csv")):
        yield "impact-n200", int(r["threads"]), float(r["median_s"]), "s"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", action="append", required=True, help="NAME=PATH, once per build")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    builds = [b.split("=", 1) for b in args.bin]
    os.makedirs(args.out, exist_ok=True)
    samples = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.rounds):
            for name, path in builds:
                for case, threads, value, unit in cases(path, tmp):
                    samples.append((k, name, case, threads, value, unit))
                print(f"round {k + 1}/{args.rounds}: {name} done", flush=True)
    with open(os.path.join(args.out, "samples.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["round", "build", "case", "threads", "value", "unit"])
        w.writerows(samples)
    by = {}
    for k, name, case, threads, value, unit in samples:
        by.setdefault((name, case, unit), {}).setdefault(threads, {})[k] = value
    rows = []
    for (name, case, unit), per in by.items():
        one, two = per.get(1, {}), per.get(2, {})
        rate = unit == "particle-steps/s"
        ratios = [(two[k] / one[k]) if rate else (one[k] / two[k]) for k in one if k in two]
        for threads in sorted(per):
            rows.append([name, case, unit, threads, statistics.median(per[threads].values()),
                         statistics.median(ratios) if threads == 2 and ratios else ""])
    with open(os.path.join(args.out, "summary.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["build", "case", "unit", "threads", "median", "speedup_median"])
        w.writerows(rows)
    for r in sorted(rows, key=lambda r: (r[1], r[3], r[0])):
        print(f"{r[1]:<28} {r[3]} thread(s) {r[0]:<8} median {r[4]:.4g} {r[2]}" +
              (f"   speed-up {r[5]:.2f}x" if r[5] != "" else ""))


if __name__ == "__main__":
    main()
