#!/usr/bin/env python3
"""Tree self-gravity against contact-only throughput (issue 6, "Speed"), side by side in one run.

Runs `rubblepile bench ssdem` interleaved, `--repeats` times, for every N and mode:
  off            --gravity off
  tree           --gravity tree (theta = 0.5, self-gravity every step)
  tree-K         --gravity tree --gravity-interval K (r-RESPA: self-gravity every K steps)
on 1 and 2 threads, and writes the medians to gravity.csv (binary, gravity, N, threads, steps,
gravity_interval, particle_steps_per_s), every sample to gravity_run.log, and the paired ratios of each gravity
mode to contact only (same binary, N, threads and repeat, so neighbouring samples that saw the same load) to
gravity_paired.csv (median and quartiles over the repeats). Standard library only.

    cargo build --release
    python3 analysis/ssdem_perf/gravity_bench.py --particles 10000,40000 --interval 10 --repeats 3

`--bin LABEL=PATH` (repeatable) times several builds side by side, interleaved run by run (e.g. a copy of the
binary from before a change against the current one); `--modes` picks a subset of off,tree,respa.
"""
import argparse
import itertools
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
BIN = os.path.join(ROOT, "target", "release", "rubblepile")
LINE = re.compile(r"(\d+) thread\(s\): ([0-9.eE+-]+) particle-steps/s")


def bench(binary, n, gravity, interval, steps, threads):
    cmd = [binary, "bench", "ssdem", "--particles", str(n), "--gravity", gravity, "--gravity-interval",
           str(interval), "--steps", str(steps), "--threads", threads]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return {int(t): float(r) for t, r in LINE.findall(out)}, " ".join(cmd)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--particles", default="10000,40000")
    ap.add_argument("--interval", type=int, default=10, help="K of the tree-K mode")
    ap.add_argument("--steps-off", default="60,30", help="timed steps per N, contact only")
    ap.add_argument("--steps-tree", default="20,10", help="timed steps per N, tree every step")
    ap.add_argument("--steps-respa", default="60,30", help="timed steps per N, tree every K steps")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--force", action="store_true", help="overwrite gravity.csv and gravity_run.log")
    ap.add_argument("--bin", action="append", default=[], metavar="LABEL=PATH",
                    help=f"binary to time (repeatable; default current={BIN})")
    ap.add_argument("--modes", default="off,tree,respa", help="subset of off,tree,respa")
    a = ap.parse_args()
    bins = []
    for b in a.bin or [f"current={BIN}"]:
        label, sep, path = b.partition("=")
        if not sep or not label or not os.path.isfile(path):
            sys.exit(f"--bin: expected LABEL=PATH of an existing binary, got {b!r}")
        bins.append((label, path))
    wanted = a.modes.split(",")
    if not wanted or any(m not in ("off", "tree", "respa") for m in wanted):
        sys.exit(f"--modes: expected a comma-separated subset of off,tree,respa, got {a.modes!r}")
    csv_path = os.path.join(a.out, "gravity.csv")
    log_path = os.path.join(a.out, "gravity_run.log")
    for p in (csv_path, log_path):
        if os.path.exists(p) and not a.force:
            sys.exit(f"{p} exists; use --force to overwrite it")
    ns = [int(x) for x in a.particles.split(",")]
    steps = {k: [int(x) for x in getattr(a, "steps_" + k).split(",")] for k in ("off", "tree", "respa")}
    modes = [("off", "off", 1, "off"), ("tree", "tree", 1, "tree"), (f"tree-{a.interval}", "tree", a.interval, "respa")]
    modes = [m for m in modes if m[3] in wanted]
    samples = {}
    per_rep = {}
    with open(log_path, "w") as log:
        log.write(f"load average at start: {os.getloadavg()}\n")
        for rep in range(a.repeats):
            for i, n in enumerate(ns):
                for (name, gravity, interval, key), (label, binary) in itertools.product(modes, bins):
                    s = steps[key][min(i, len(steps[key]) - 1)]
                    rates, cmd = bench(binary, n, gravity, interval, s, "1,2")
                    for t, r in rates.items():
                        samples.setdefault((label, name, n, t, s, interval), []).append(r)
                        per_rep[(label, name, n, t, rep)] = r
                    line = f"repeat {rep} load {os.getloadavg()[0]:.2f}: {cmd} -> {rates}"
                    print(line, flush=True)
                    log.write(line + "\n")
                    log.flush()
        log.write(f"load average at end: {os.getloadavg()}\n")
    with open(csv_path, "w") as f:
        f.write("binary,gravity,N,threads,steps,gravity_interval,particle_steps_per_s\n")
        for (label, name, n, t, s, k), rs in samples.items():
            f.write(f"{label},{name},{n},{t},{s},{k},{statistics.median(rs):.6e}\n")
    paired_path = os.path.join(a.out, "gravity_paired.csv")
    with open(paired_path, "w") as f:
        f.write("binary,gravity,N,threads,repeats,median_ratio_to_off,q1,q3\n")
        for (label, _), n, t, (name, _, _, _) in itertools.product(bins, ns, (1, 2), modes):
            if name == "off":
                continue
            rs = sorted(per_rep[(label, name, n, t, r)] / per_rep[(label, "off", n, t, r)]
                        for r in range(a.repeats)
                        if (label, name, n, t, r) in per_rep and (label, "off", n, t, r) in per_rep)
            if len(rs) >= 2:
                q = statistics.quantiles(rs, n=4)
                f.write(f"{label},{name},{n},{t},{len(rs)},{statistics.median(rs):.4f},{q[0]:.4f},{q[2]:.4f}\n")
    print(f"wrote {csv_path}, {paired_path} and {log_path}")


if __name__ == "__main__":
    main()
