#!/usr/bin/env python3
"""Interleaved A/B of `rubblepile bench ssdem` between builds (issue 39, "a whole node").

For every repeat, every binary in turn runs `bench ssdem --particles N --threads T1,T2,...` for each gravity mode
(contacts only; tree gravity every K steps). The load average is read before every run. Writes every sample to
`samples.csv` and, per binary, mode and thread count, the median and quartiles of the particle-steps per second,
of the speed-up over one thread (paired within a run), and of the ratio new/old (paired by repeat), to
`summary.csv`; prints the summary.

    python3 analysis/ssdem_perf/scaling_ab.py --bin old=/tmp/rubblepile-old --bin new=target/release/rubblepile \\
        --particles 40000 --steps 100 --threads 1,2 --repeats 7 --out analysis/ssdem_perf/scaling
"""
import argparse
import csv
import os
import re
import statistics
import subprocess
import time


def quartiles(xs):
    xs = sorted(xs)
    if len(xs) < 2:
        return xs[0], xs[0], xs[0]
    q = statistics.quantiles(xs, n=4, method="inclusive")
    return q[0], statistics.median(xs), q[2]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", action="append", required=True, help="LABEL=PATH (repeatable; the first is the baseline)")
    ap.add_argument("--particles", type=int, default=40000)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--interval", type=int, default=10, help="tree gravity every K steps")
    ap.add_argument("--modes", default="off,tree")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    bins = [b.split("=", 1) for b in a.bin]
    os.makedirs(a.out, exist_ok=True)
    line = re.compile(r"(\d+) thread\(s\): ([0-9.e+]+) particle-steps/s")
    rows = []
    for rep in range(a.repeats):
        for mode in a.modes.split(","):
            for label, path in bins:
                cmd = [path, "bench", "ssdem", "--particles", str(a.particles), "--steps", str(a.steps),
                       "--threads", a.threads]
                if mode == "tree":
                    cmd += ["--gravity", "tree", "--gravity-interval", str(a.interval)]
                load = os.getloadavg()[0]
                out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
                for t, r in line.findall(out):
                    rows.append(dict(repeat=rep, mode=mode, binary=label, threads=int(t), rate=float(r), load1=load,
                                     time=time.strftime("%H:%M:%S")))
                    print(rows[-1], flush=True)
    with open(os.path.join(a.out, "samples.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    rate = {(r["repeat"], r["mode"], r["binary"], r["threads"]): r["rate"] for r in rows}
    threads = [int(t) for t in a.threads.split(",")]
    base = bins[0][0]
    summary = []
    for mode in a.modes.split(","):
        for label, _ in bins:
            for t in threads:
                xs = [rate[(k, mode, label, t)] for k in range(a.repeats)]
                sp = [rate[(k, mode, label, t)] / rate[(k, mode, label, threads[0])] for k in range(a.repeats)]
                ab = [rate[(k, mode, label, t)] / rate[(k, mode, base, t)] for k in range(a.repeats)]
                tree = ([rate[(k, "tree", label, t)] / rate[(k, "off", label, t)] for k in range(a.repeats)]
                        if mode == "tree" and "off" in a.modes.split(",") else None)
                row = dict(mode=mode, binary=label, threads=t)
                for name, v in [("rate", xs), ("speedup", sp), ("vs_" + base, ab)] + ([("tree_over_off", tree)] if tree else []):
                    lo, med, hi = quartiles(v)
                    row[name + "_q1"], row[name + "_median"], row[name + "_q3"] = lo, med, hi
                summary.append(row)
    keys = []
    for r in summary:
        for k in r:
            if k not in keys:
                keys.append(k)
    with open(os.path.join(a.out, "summary.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(summary)
    loads = [r["load1"] for r in rows]
    print(f"load average (1 min) over the run: min {min(loads):.2f}, median {statistics.median(loads):.2f}, max {max(loads):.2f}")
    for r in summary:
        print(", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in r.items()))


if __name__ == "__main__":
    main()
