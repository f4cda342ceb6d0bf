"""Figures of analysis/pile_projectiles/REPORT.md (issue 20): a rubble-pile projectile against the same-mass single
ellipsoid on N200_T4. Reads the run directories under runs/ (see REPORT.md for the commands) and writes
energy.png and ejection.png beside this file.

    python3 analysis/pile_projectiles/figures.py
"""
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

HERE = os.path.dirname(os.path.abspath(__file__))
RUNS = os.path.join(HERE, "..", "..", "runs")
CASES = [  # (run directory, label, colour, line style)
    ("demo_pile", "N30 pile, 5 km/s", "tab:red", "-"),
    ("demo_ellipsoid", "same-mass ellipsoid, 5 km/s", "tab:blue", "-"),
    ("demo_pile_v03_long", "N30 pile, 0.3 km/s", "tab:red", "--"),
    ("demo_ellipsoid_v03_long", "same-mass ellipsoid, 0.3 km/s", "tab:blue", "--"),
]


def rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def energy_figure():
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, label, colour, style in CASES:
        ts = rows(os.path.join(RUNS, name, "timeseries.csv"))
        t = [float(r["t"]) for r in ts]
        k0 = float(ts[0]["kinetic_translational"]) + float(ts[0]["kinetic_rotational"])
        kin = [(float(r["kinetic_translational"]) + float(r["kinetic_rotational"])) / k0 for r in ts]
        dis = [abs(float(r["dissipated"])) / k0 for r in ts]
        axes[0].plot(t, kin, color=colour, ls=style, label=label)
        axes[1].plot(t, dis, color=colour, ls=style, label=label)
    axes[0].set_ylabel("kinetic energy K(t) / K(0)")
    axes[1].set_ylabel("dissipated work |2∫F dt| / K(0)")
    for ax in axes:
        ax.set_xlabel("time t (s)")
        ax.set_xscale("symlog", linthresh=100)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Pile vs single-ellipsoid projectile on N200_T4 (ζ = 45°, contact at t = 90 s)")
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "energy.png"), dpi=110)


def ejection_figure():
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for name, label, colour, style in CASES:
        fr = rows(os.path.join(RUNS, name, "analysis", "fragments.csv"))
        v = sorted(float(r["ejection_speed"]) for r in fr if r["is_projectile"] == "false")
        frac = [(k + 1) / len(v) for k in range(len(v))]
        ax.step(v, frac, where="post", color=colour, ls=style, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("ejection speed |Δv| of the target fragments (m/s)")
    ax.set_ylabel("cumulative fraction of target fragments")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Ejection speeds at t = 10 000 s (N200_T4, ζ = 45°)")
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "ejection.png"), dpi=110)


if __name__ == "__main__":
    energy_figure()
    ejection_figure()
