#!/usr/bin/env python3
"""Coordination-number drift against hold length (issue 40, item 3): is the loss of contacts in a hold a settling
transient (the drift over the second half shrinks as the hold grows) or creep (it grows with the hold)?

For every completed hold directory `T*/` of one or more `rubblepile spinup critical` searches, reads `spinup.csv`,
keeps the samples of the hold (from the first sample where the path has reached T_final), and for hold lengths L = 2000, 4000, 8000, 12000
and 16000 s computes the drift of the quantities the creep criteria judge over the *second half* of [start,
start + L], exactly as `src/analysis/creep.rs::second_half_drift` does (the change of the least-squares line
over that half): the raw coordination number (every touching pair), the force-floored one (`coordination_loaded`,
contacts carrying >= 1 % of the mean normal force), theta_max and eta_B.

Usage: python3 analysis/zhang2017/criterion/drift.py --search LABEL=DIR [--search ...] --out drift.csv
"""
import argparse
import csv
import json
import os


def second_half_drift(t, y):
    n = min(len(t), len(y))
    t, y = t[n // 2 : n], y[n // 2 : n]
    if len(t) < 3:
        return 0.0
    tm, ym = sum(t) / len(t), sum(y) / len(y)
    sty = sum((a - tm) * (b - ym) for a, b in zip(t, y))
    stt = sum((a - tm) ** 2 for a in t)
    return 0.0 if stt == 0 else sty / stt * (t[-1] - t[0])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--search", action="append", required=True, help="LABEL=DIR of a spinup critical search")
    ap.add_argument("--out", required=True)
    ap.add_argument("--lengths", default="2000,4000,8000,12000,16000")
    args = ap.parse_args()
    lengths = [float(x) for x in args.lengths.split(",")]
    rows = []
    for spec in args.search:
        label, d = spec.split("=", 1)
        for name in sorted(os.listdir(d)):
            hold_dir = os.path.join(d, name)
            summary = os.path.join(hold_dir, "summary.json")
            if not (name.startswith("T") and os.path.isfile(summary)):
                continue
            if json.load(open(summary)).get("status") != "completed":
                continue
            samples = list(csv.DictReader(open(os.path.join(hold_dir, "spinup.csv"))))
            released = any(s["forcing"] == "0" for s in samples)
            # the hold starts where the path reaches T_final: the first sample with the path at its final period
            tf = float(name[1:])
            start = next(float(s["t"]) for s in samples if abs(float(s["path_period_h"]) - tf) < 1e-9)
            hold = [s for s in samples if float(s["t"]) >= start]
            for length in lengths:
                part = [s for s in hold if float(s["t"]) <= start + length + 1e-6]
                t = [float(s["t"]) for s in part]
                col = lambda k: [float(s[k]) for s in part]
                loaded = col("coordination_loaded") if "coordination_loaded" in part[0] else None
                rows.append(
                    dict(
                        search=label,
                        t_final_h=tf,
                        released=int(released),
                        hold_s=length,
                        samples=len(part),
                        coordination_drift=round(second_half_drift(t, col("coordination_number")), 4),
                        coordination_loaded_drift=(
                            round(second_half_drift(t, loaded), 4) if loaded is not None else ""
                        ),
                        coordination_end=round(col("coordination_number")[-1], 3),
                        coordination_loaded_end=round(loaded[-1], 3) if loaded is not None else "",
                        theta_max_drift_deg=round(second_half_drift(t, col("theta_max_deg")), 3),
                        eta_drift=round(second_half_drift(t, col("packing_fraction")), 6),
                    )
                )
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"{len(rows)} rows -> {args.out}")


if __name__ == "__main__":
    main()
