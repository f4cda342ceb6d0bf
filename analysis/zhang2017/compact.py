#!/usr/bin/env python3
"""Copy the compact results of a spin-up run directory (issue 40: the tables regenerate from the repository):
spinup.csv, timeseries.csv, summary.json and scene.toml as they are, and particles.json in place of the snapshots
(n, radius_min_m, radius_max_m, mass_kg of the first snapshot: what `rubblepile report zhang2017` reads from
snapshots/0.csv when a run keeps its snapshots). Searches: critical.json and critical.csv of a `spinup critical`
directory, and holds.csv: every hold's samples from its start (the scene's `spinup.t_final`) to its end, the state
variables that Zhang17 Fig. 22 follows (θ_max, η_B, the coordination number) with the period and the bound mass.

A search's copy also keeps target.json, the report of the aggregate its scene loads (NAME.json beside the
particle file), which says the grain count and the lattice's orientation.

Usage: python3 analysis/zhang2017/compact.py RUN_DIR OUT_DIR          # a run
       python3 analysis/zhang2017/compact.py --base SEARCH_DIR/base OUT_DIR   # a search's base run (no summary.json)
       python3 analysis/zhang2017/compact.py --search SEARCH_DIR OUT_DIR   # a T_c3 search
       python3 analysis/zhang2017/compact.py --search --running SEARCH_DIR OUT_DIR   # one still running: holds.csv
           as far as each hold has got; then `rubblepile spinup judge SEARCH_DIR --csv OUT_DIR/critical.csv`
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


HOLD_COLUMNS = ["period_h", "body_mass_fraction", "packing_fraction", "coordination_number", "coordination_loaded",
                "theta_max_deg"]


def running_holds(search_dir):
    """The holds of a search still running (no critical.json yet): every T<period>/ with a spinup.csv, as far as
    each has got, in the shape of critical.json's `runs`."""
    runs = []
    for name in sorted(os.listdir(search_dir)):
        if name.startswith("T") and os.path.isfile(os.path.join(search_dir, name, "spinup.csv")):
            runs.append({"dir": name, "t_final_hours": float(name[1:])})
    return runs


def write_holds(search_dir, dst, force, running=False):
    """One row per sample of every hold in critical.json's `runs`, from the hold's start on: t_final_h (the hold's
    period), t_hold_s (seconds since the hold began), HOLD_COLUMNS (empty where a run lacks the column) and
    forcing (1 while the spin-up forcing acts, 0 once it was released)."""
    import tomllib
    if os.path.exists(dst) and not force:
        sys.exit(f"{dst} exists (use --force to overwrite it)")
    runs = running_holds(search_dir) if running else None
    if runs is None:
        with open(os.path.join(search_dir, "critical.json")) as f:
            runs = json.load(f)["runs"]
    rows = []
    for run in runs:
        hold = os.path.join(search_dir, os.path.basename(run["dir"]))
        with open(os.path.join(hold, "scene.toml"), "rb") as f:
            t0 = tomllib.load(f)["spinup"]["t_final"]
        with open(os.path.join(hold, "spinup.csv")) as f:
            for r in csv.DictReader(f):
                t = float(r["t"])
                if t + 1e-6 < t0:
                    continue
                forcing = r.get("forcing", "")
                forcing = {"true": "1", "false": "0"}.get(forcing, forcing)
                rows.append([f"{run['t_final_hours']:.2f}", f"{t - t0:.1f}"] + [r.get(c, "") for c in HOLD_COLUMNS]
                            + [forcing])
    with open(dst, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_final_h", "t_hold_s"] + HOLD_COLUMNS + ["forcing"])
        w.writerows(rows)


def copy_target(search_dir, dst, force):
    """target.json: the aggregate report beside the particle file of the search's scenes (if there is one)."""
    import glob
    import tomllib
    scenes = sorted(glob.glob(os.path.join(search_dir, "base", "scene.toml"))) + sorted(
        glob.glob(os.path.join(search_dir, "T*", "scene.toml")))
    for scene in scenes:
        with open(scene, "rb") as f:
            particles = tomllib.load(f)["scene"].get("particles_file")
        if not particles:
            continue
        if not os.path.isabs(particles):
            particles = os.path.join(os.path.dirname(scene), particles)
        report = os.path.splitext(particles)[0] + ".json"
        if os.path.isfile(report):
            copy(report, dst, force)
        return


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("src")
    ap.add_argument("out")
    ap.add_argument("--search", action="store_true", help="SRC is a spinup critical directory")
    ap.add_argument("--base", action="store_true", help="SRC is a search's base run (it has no summary.json)")
    ap.add_argument("--running", action="store_true",
                    help="with --search: a search still running (holds.csv only; write its critical.csv with "
                         "`rubblepile spinup judge SRC --csv OUT/critical.csv`)")
    ap.add_argument("--force", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    names = ([] if a.running else ["critical.json", "critical.csv"]) if a.search else ["spinup.csv", "timeseries.csv", "summary.json", "scene.toml"]
    for name in names:
        src = os.path.join(a.src, name)
        if not os.path.isfile(src):
            if a.base and name == "summary.json":
                continue
            sys.exit(f"{src}: missing (a run still going has no summary.json: wait for it)")
        copy(src, os.path.join(a.out, name), a.force)
    if a.search:
        write_holds(a.src, os.path.join(a.out, "holds.csv"), a.force, a.running)
        copy_target(a.src, os.path.join(a.out, "target.json"), a.force)
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
