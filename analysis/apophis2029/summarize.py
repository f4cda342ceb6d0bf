"""Collects the flyby runs of run.sh (runs/apophis2029/*) into runs.csv and draws the figures of REPORT.md.

Usage (repository root): python3 analysis/apophis2029/summarize.py
"""
import csv
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

RUNS = "runs/apophis2029"
HERE = os.path.dirname(os.path.abspath(__file__))
RE = 6.371e6

rows = []
for name in sorted(os.listdir(RUNS)):
    d = os.path.join(RUNS, name)
    fa = os.path.join(d, "analysis", "flyby.json")
    if not os.path.isfile(fa):
        continue
    a = json.load(open(fa))
    s = json.load(open(os.path.join(d, "summary.json")))
    setup = json.load(open(os.path.join(d, "flyby.json")))
    massless = setup["gm"] == 0.0
    rows.append({
        "run": name,
        "q_RE": round(setup["q"] / RE, 3),
        "q_km": round(setup["q"] / 1e3, 1),
        "v_inf_km_s": setup["v_inf"] / 1e3,
        "planet": "none (control)" if massless else "Earth",
        "t_end_h": round(setup["t_end"] / 3600, 2),
        "mass_lost": a["mass_lost"],
        "fragments_after": a["after"]["fragments"],
        "P_before_h": a["before"]["period_hours"],
        "P_after_h": a["after"]["period_hours"],
        "dP_h": a["delta_period_hours"],
        "b_a_before": a["before"]["b_over_a"],
        "b_a_after": a["after"]["b_over_a"],
        "c_a_before": a["before"]["c_over_a"],
        "c_a_after": a["after"]["c_over_a"],
        "class": a["class"],
        "rbl98": a["rbl98_class"],
        "wall_s": s["wall_seconds"],
        "energy_error": s["energy_error"],
        "status": s["status"],
    })

with open(os.path.join(HERE, "runs.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    for r in rows:
        w.writerow(r)

sweep = [r for r in rows if r["run"].startswith("sweep")]
control = [r for r in rows if r["run"] == "control"]
apophis = [r for r in rows if r["run"] == "apophis"]

fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
for v, mk in [(5.8, "o-"), (12.0, "s--")]:
    sel = sorted([r for r in sweep if abs(r["v_inf_km_s"] - v) < 1e-9], key=lambda r: r["q_RE"])
    q = [r["q_RE"] for r in sel]
    axes[0].plot(q, [100 * r["mass_lost"] for r in sel], mk, label=f"v_inf = {v} km/s")
    axes[1].plot(q, [r["dP_h"] for r in sel], mk, label=f"v_inf = {v} km/s")
    axes[2].plot(q, [r["b_a_after"] - r["b_a_before"] for r in sel], mk, label=f"Δ(b/a), v_inf = {v} km/s")
    axes[2].plot(q, [r["c_a_after"] - r["c_a_before"] for r in sel], mk, alpha=0.4, label=f"Δ(c/a), v_inf = {v} km/s")
for r in apophis:
    axes[0].plot([r["q_RE"]], [100 * r["mass_lost"]], "r*", ms=14, label="Apophis 2029")
    axes[1].plot([r["q_RE"]], [r["dP_h"]], "r*", ms=14, label="Apophis 2029")
for r in control:
    axes[1].axhline(r["dP_h"], color="grey", lw=1, ls=":", label="control (no tide)")
    axes[2].axhline(r["b_a_after"] - r["b_a_before"], color="grey", lw=1, ls=":", label="control Δ(b/a)")
axes[0].set_ylabel("mass lost from the largest remnant (%)")
axes[1].set_ylabel("spin period change ΔP (h)")
axes[2].set_ylabel("axis-ratio change")
for ax in axes:
    ax.set_xlabel("perigee distance q (Earth radii)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
fig.suptitle("Tidal flybys of a 340 m, N = 100 rubble pile (P0 = 30.56 h, prograde) past Earth")
fig.tight_layout()
fig.savefig(os.path.join(HERE, "sweep.png"), dpi=110)

# Energy residual and spin of the Apophis run over time.
for r in apophis + control:
    ts = os.path.join(RUNS, r["run"], "timeseries.csv")
    t, res = [], []
    with open(ts) as f:
        for row in csv.DictReader(f):
            t.append(float(row["t"]) / 3600)
            res.append(float(row["energy_residual"]))
    plt.figure(figsize=(6, 4))
    plt.plot(t, res)
    plt.xlabel("time (h)")
    plt.ylabel("(H + E_tide − H0 − 2∫F dt) / energy scale")
    plt.title(f"Energy residual, run {r['run']}")
    plt.grid(alpha=0.3)
    plt.tight_layout()
    plt.savefig(os.path.join(HERE, f"energy_{r['run']}.png"), dpi=110)

for r in rows:
    print(",".join(str(r[k]) for k in ["run", "q_RE", "v_inf_km_s", "mass_lost", "dP_h", "b_a_before", "b_a_after",
                                        "c_a_before", "c_a_after", "class", "rbl98", "wall_s", "energy_error"]))

# The table of REPORT.md.
with open(os.path.join(HERE, "runs_table.md"), "w") as f:
    f.write("| run | q (R_E) | q (km) | v_inf (km/s) | t_end (h) | mass lost | P before (h) | P after (h) | ΔP (h) "
            "| b/a before→after | c/a before→after | class (RBL98) | wall (s) | energy error |\n")
    f.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        f.write(f"| {r['run']} | {r['q_RE']:.2f} | {r['q_km']:.0f} | {r['v_inf_km_s']:g} | {r['t_end_h']:.1f} "
                f"| {100 * r['mass_lost']:.1f} % | {r['P_before_h']:.2f} | {r['P_after_h']:.2f} | {r['dP_h']:+.2f} "
                f"| {r['b_a_before']:.3f}→{r['b_a_after']:.3f} | {r['c_a_before']:.3f}→{r['c_a_after']:.3f} "
                f"| {r['class']} ({r['rbl98']}) | {r['wall_s']:.0f} | {r['energy_error']:.1e} |\n")
