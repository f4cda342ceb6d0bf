"""Collects the runs of tidal_grid.sh (runs/tidal_grid/*) into tidal_grid.csv and the table tidal_grid.md.

Every change is the tide's effect as `rubblepile flyby` reports it: the run minus its control (same settled pile,
same duration, no planet). Usage (repository root): python3 analysis/apophis2029/summarize_grid.py
"""
import csv
import json
import os

RUNS = "runs/tidal_grid"
HERE = os.path.dirname(os.path.abspath(__file__))
RE = 6.371e6

rows = []
for name in sorted(os.listdir(RUNS)):
    d = os.path.join(RUNS, name)
    fa = os.path.join(d, "analysis", "flyby.json")
    if not os.path.isfile(fa):
        continue
    a = json.load(open(fa))
    setup = json.load(open(os.path.join(d, "flyby.json")))
    s = json.load(open(os.path.join(d, "summary.json")))
    t = a["tide"]
    wall = float(open(os.path.join(RUNS, name + ".time")).read().split()[-1])
    rows.append({
        "q_RE": round(setup["q"] / RE, 3),
        "v_inf_km_s": setup["v_inf"] / 1e3,
        "class": a["class"],
        "rbl98": a["rbl98_class"],
        "mass_lost": round(t["mass_lost"], 4),
        "fragments_lost": t["fragments_lost"],
        "dP_invariant_h": round(t["delta_invariant_period_hours"], 3),
        "dP_h": round(t["delta_period_hours"], 3),
        "d_b_a": round(t["delta_b_over_a"], 4),
        "d_c_a": round(t["delta_c_over_a"], 4),
        "P_before_h": round(a["before"]["spin"]["invariant_period_hours"], 3),
        "spin_before": a["before"]["spin"]["mode"],
        "spin_after": a["after"]["spin"]["mode"],
        "settle_h": round(a["settling"]["time"] / 3600, 2) if a.get("settling") else None,
        "settle_capped": a["settling"]["capped"] if a.get("settling") else None,
        "energy_error": s["energy_error"],
        "angular_momentum_residual": s["angular_momentum_error"],
        "tidal_torque_impulse": s.get("tidal_torque_impulse"),
        "wall_s": wall,
    })
rows.sort(key=lambda r: (r["v_inf_km_s"], r["q_RE"]))
with open(os.path.join(HERE, "tidal_grid.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)

qs = sorted({r["q_RE"] for r in rows})
vs = sorted({r["v_inf_km_s"] for r in rows})
cell = {(r["q_RE"], r["v_inf_km_s"]): r for r in rows}
lines = ["| v∞ (km/s) \\ q (R_E) | " + " | ".join(f"{q:g}" for q in qs) + " |",
         "|---|" + "---|" * len(qs)]
for v in vs:
    out = []
    for q in qs:
        r = cell.get((q, v))
        if r is None:
            out.append("")
            continue
        out.append(f"{r['class']} ({r['rbl98']}): lost {100 * r['mass_lost']:.0f} %, "
                   f"ΔP {r['dP_invariant_h']:+.2f} h, Δ(b/a) {r['d_b_a']:+.3f}")
    lines.append(f"| {v:g} | " + " | ".join(out) + " |")
open(os.path.join(HERE, "tidal_grid.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
