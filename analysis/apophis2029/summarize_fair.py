"""Collects the runs of run_fair.sh (runs/apophis2029_fair/*) into fair_runs.csv: the tide's effect (run minus
control) on the Apophis pass and the spin state before and after.

Usage (repository root): python3 analysis/apophis2029/summarize_fair.py
"""
import csv
import json
import os

RUNS = "runs/apophis2029_fair"
HERE = os.path.dirname(os.path.abspath(__file__))

def a_setup_orientation(name):
    """The orbit's argument of perigee (deg) from the run's scene."""
    for line in open(os.path.join(RUNS, name, "scene.toml")):
        if line.startswith("orientation_deg"):
            return float(line.split("[")[1].split("]")[0].split(",")[2])
    return 0.0


def control_changes():
    """The control of `settled` (same pile, same duration): its changes of 2π/|ω|, π|L|/E and b/a."""
    c = json.load(open(os.path.join(RUNS, "settled", "analysis", "flyby.json")))["control"]
    inv = c["after"]["spin"]["invariant_period_hours"] - c["before"]["spin"]["invariant_period_hours"]
    return c["delta_period_hours"], inv, c["after"]["b_over_a"] - c["before"]["b_over_a"]


rows = []
for name in sorted(os.listdir(RUNS)):
    fa = os.path.join(RUNS, name, "analysis", "flyby.json")
    if not os.path.isfile(fa):
        continue
    a = json.load(open(fa))
    s = json.load(open(os.path.join(RUNS, name, "summary.json")))
    t, st = dict(a["tide"]), a["settling"]
    if not t["from_control"]:
        # Turned orbits (--no-control) share the control of `settled`: subtract it here.
        dp, dinv, dba = control_changes()
        t["delta_period_hours"] -= dp
        t["delta_invariant_period_hours"] -= dinv
        t["delta_b_over_a"] -= dba
    row = {"run": name, "orientation_deg": a_setup_orientation(name),
           "class": a["class"] if a["tide"]["from_control"] else "", "rbl98": a["rbl98_class"],
           "settle_h": round(st["time"] / 3600, 2), "settle_capped": st["capped"],
           "settle_K_rel_over_K": st["non_rigid_fraction"],
           "dP_tide_h": round(t["delta_period_hours"], 3),
           "dP_invariant_tide_h": round(t["delta_invariant_period_hours"], 3),
           "d_b_a_tide": round(t["delta_b_over_a"], 4), "mass_lost_tide": t["mass_lost"]}
    for when in ("before", "after"):
        sp = a[when]["spin"]
        row[f"{when}_mode"] = sp["mode"]
        row[f"{when}_angle_L_w_deg"] = round(sp["angle_l_omega_deg"], 2)
        row[f"{when}_angle_w_Imax_deg"] = round(sp["angle_omega_largest_axis_deg"], 1)
        row[f"{when}_D_over_I2"] = round(sp["l2_over_2e"] / sp["moments"][1], 4)
        row[f"{when}_P_h"] = round(sp["spin_period_hours"], 3)
        row[f"{when}_P_invariant_h"] = round(sp["invariant_period_hours"], 3)
        rng = sp.get("spin_period_range_hours")
        row[f"{when}_P_range_h"] = f"{rng[0]:.2f}-{rng[1]:.2f}" if rng else ""
        row[f"{when}_P_psi_h"] = round(sp["rotation_period_hours"], 2) if sp.get("rotation_period_hours") else ""
        row[f"{when}_P_phi_h"] = round(sp["precession_period_hours"], 2) if sp.get("precession_period_hours") else ""
    row["energy_error"] = s["energy_error"]
    row["angular_momentum_residual"] = s["angular_momentum_error"]
    row["tidal_torque_impulse"] = s.get("tidal_torque_impulse")
    rows.append(row)
with open(os.path.join(HERE, "fair_runs.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
for r in rows:
    print(r)
