#!/usr/bin/env python3
"""Copy the compact results of a spin-up run directory (issue 40: the tables regenerate from the repository):
spinup.csv, timeseries.csv, summary.json and scene.toml as they are, and particles.json in place of the snapshots
(n, radius_min_m, radius_max_m, mass_kg of the first snapshot: what `rubblepile report zhang2017` reads from
snapshots/0.csv when a run keeps its snapshots). Searches: critical.json and critical.csv of a `spinup critical`
directory.

Usage: python3 analysis/zhang2017/compact.py RUN_DIR OUT_DIR          # a run
       python3 analysis/zhang2017/compact.py --search SEARCH_DIR OUT_DIR   # a T_c3 search
Refuses to overwrite OUT_DIR's files unless --force.
"""
import argparse
import csv
import json
import os
import shutil
import sys


def copy(src, dst, force):
    if os.path.exists(dst) and not force:
        sys.exit(f"{dst} exists (use --force to overwrite it)")
    shutil.copyfile(src, dst)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("src")
    ap.add_argument("out")
    ap.add_argument("--search", action="store_true", help="SRC is a spinup critical directory")
    ap.add_argument("--force", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    names = ["critical.json", "critical.csv"] if a.search else ["spinup.csv", "timeseries.csv", "summary.json", "scene.toml"]
    for name in names:
        src = os.path.join(a.src, name)
        if not os.path.isfile(src):
            sys.exit(f"{src}: missing (a run still going has no summary.json: wait for it)")
        copy(src, os.path.join(a.out, name), a.force)
    if a.search:
        return
    with open(os.path.join(a.src, "snapshots", "0.csv")) as f:
        rows = list(csv.DictReader(f))
    radii = [float(r["radius"]) for r in rows]
    summary = {
        "n": len(rows),
        "radius_min_m": min(radii),
        "radius_max_m": max(radii),
        "mass_kg": sum(float(r["mass"]) for r in rows),
    }
    dst = os.path.join(a.out, "particles.json")
    if os.path.exists(dst) and not a.force:
        sys.exit(f"{dst} exists (use --force to overwrite it)")
    with open(dst, "w") as f:
        json.dump(summary, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()
