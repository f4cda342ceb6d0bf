#!/usr/bin/env python3
"""An independent check of the SSDEM contact law (issue 40, item 2): a poured heap of spheres in rubblepile
and in LAMMPS, same grains, same law, same floor, and the angle of the heap it leaves.

Why this test: the slope of a heap of spheres is set by sliding, rolling and twisting resistance together
(without rolling resistance, spheres on a flat floor spread into a nearly flat layer), so a difference in
any of Zhang17 Eqs. 1-12 between the two codes shows up as a different angle.

What it does (standard library only):

1. Places equal spheres (radius R = 0.01 m, 2500 kg/m^3) at random, none touching, in a cylinder of radius 10 R
   and height 60 R standing on a plane floor z = 0, at a packing fraction of 0.3 (seeded), at rest, under
   g = 9.81 m/s^2. There is no cylinder wall: the cloud falls and pours into a heap on the floor. (A column on
   a lattice does not do: a simple cubic stack of frictional spheres stands.)
2. rubblepile: writes `work/<case>/scene.toml` (soft-spheres, floor plane wall) and runs it to `--t-end`.
3. LAMMPS (Debian `lmp`, 29 Sep 2021): the same grains in a data file, `pair_style granular` with
   `hooke` + `linear_history` + `rolling sds` + `twisting sds`, `fix wall/gran granular` with the same
   coefficients as the floor, `fix gravity`, `fix nve/sphere`, the same dt; final positions dumped.
4. Measures the heap on each code's final state with one function (`heap`): the surface height h(rho) is the
   highest grain top (z + R) in radial bins of width 2R about the heap's vertical axis (the centre of mass);
   the angle is the least-squares slope of h against rho over the flank, the bins whose h lies between 20 % and
   80 % of the highest; also the run-out (the largest rho of a grain touching a neighbour or the floor) and the
   final height. Writes `results.csv` and prints a table.

The contact law's coefficients in LAMMPS (`lammps_coeffs`): this LAMMPS has no `damping coeff_restitution`,
so the normal dashpot uses `damping tsuji` (eta = alpha(e) sqrt(m_eff k_n)) with the e that makes Tsuji's
polynomial alpha equal to ours, alpha = -2 ln(eps)/sqrt(pi^2 + ln^2 eps): that matches C_N for grain pairs and for
the floor alike. Tangential: k_t = 2/7 k_N, eta_t/eta_n = sqrt(2/7) (ours: C_S = damping(eps_t, k_S, mu)).
Rolling sds: LAMMPS' torque is R_eff^2 k_roll theta, capped at mu_roll R_eff |F_n| with R_eff = r_i r_j/(r_i + r_j)
(r_i at the floor), so k_roll = k_N beta^2 and mu_roll = mu_R beta reproduce Zhang17 Eqs. 11-12 at every contact;
gamma_roll is a fixed coefficient in LAMMPS, set to the grain pair's C_N beta^2 (our floor contacts have
sqrt(2) more rolling damping). Twisting sds: stiffness, damping and cap are fixed numbers in LAMMPS, set to the
grain pair's 2 k_S (beta R_eff)^2, 2 C_S (beta R_eff)^2 and mu_T beta R_eff mu_S; at the floor ours are 4x (stiffness,
damping) and 2x (cap) these. Both differences act only at the floor.

Cases (`--cases`): `nominal` (Zhang17's set: mu_S 1.0, beta 0.5, mu_T 1.3, mu_R 1.05, eps 0.55), `no_rolling`
(beta = 0: no twisting or rolling resistance, to show how much the angle owes to them) and `caps_x2` (mu_R and
mu_T doubled: the twisting and rolling limits of an implementation that reads Zhang17's R in Eq. 12 as the
grains' radius, 2 R_eff for equal spheres, instead of the reduced radius -- the audit's one difference).

Usage:
    cargo build --release
    python3 analysis/zhang2017/contact_check/repose.py --out runs/repose            # both codes, all cases
    python3 analysis/zhang2017/contact_check/repose.py --out runs/repose --codes ours --cases nominal
Results: analysis/zhang2017/contact_check/results.csv and README.md.
"""

import argparse
import csv
import math
import os
import random
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
BIN = os.path.join(ROOT, "target", "release", "rubblepile")

RADIUS = 0.01  # m
DENSITY = 2500.0  # kg/m^3
G = 9.81  # m/s^2
K_N = 1.0e6  # N/m: static overlaps ~1e-4 R; the falling grains' first impacts reach a few % of R (see README)
EPS = 0.55
MATERIALS = {
    "nominal": dict(mu_s=1.0, beta=0.5, mu_t=1.3, mu_r=1.05),
    "no_rolling": dict(mu_s=1.0, beta=0.0, mu_t=1.3, mu_r=1.05),
    "caps_x2": dict(mu_s=1.0, beta=0.5, mu_t=2.6, mu_r=2.1),
}


def mass():
    return DENSITY * 4.0 / 3.0 * math.pi * RADIUS**3


def alpha_ours(eps):
    """C / sqrt(k mu) of src/granular/soft/contact.rs::damping."""
    lg = math.log(eps)
    return -2.0 * lg / math.sqrt(math.pi**2 + lg * lg)


def alpha_tsuji(e):
    """LAMMPS' `damping tsuji` coefficient: eta_n = alpha(e) sqrt(m_eff k_n)."""
    return (
        1.2728
        - 4.2783 * e
        + 11.087 * e**2
        - 22.348 * e**3
        + 27.467 * e**4
        - 18.022 * e**5
        + 4.8218 * e**6
    )


def tsuji_e_for(alpha):
    """The e in (0, 1) with alpha_tsuji(e) = alpha (bisection; alpha_tsuji falls monotonically there)."""
    lo, hi = 1e-6, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if alpha_tsuji(mid) > alpha:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def time_step():
    """dt = contact time / 50 for a grain pair, pi sqrt(m_eff / k_N) / 50 (as `ssdem advise` rounds it)."""
    return math.pi * math.sqrt(0.5 * mass() / K_N) / 50.0


def cloud(seed, ring=10.0, height=60.0, fraction=0.3):
    """Grains at random in a cylinder of radius `ring` R and height `height` R (standing on the floor), at a packing
    fraction `fraction`, none touching (random sequential placement on a cell grid), all at rest."""
    rng = random.Random(seed)
    vol = math.pi * (ring * RADIUS) ** 2 * height * RADIUS
    n = int(fraction * vol / (4.0 / 3.0 * math.pi * RADIUS**3))
    cell = 2.0 * RADIUS
    grid = {}
    out = []
    tries = 0
    while len(out) < n:
        tries += 1
        if tries > 1000 * n:
            raise SystemExit(f"cannot place {n} grains")
        rho = (ring - 1.0) * RADIUS * math.sqrt(rng.random())
        phi = 2.0 * math.pi * rng.random()
        p = (rho * math.cos(phi), rho * math.sin(phi), RADIUS * (1.001 + (height - 2.0) * rng.random()))
        key = tuple(int(math.floor(c / cell)) for c in p)
        near = (
            q
            for dx in (-1, 0, 1)
            for dy in (-1, 0, 1)
            for dz in (-1, 0, 1)
            for q in grid.get((key[0] + dx, key[1] + dy, key[2] + dz), ())
        )
        if any(math.dist(p, q) < 2.02 * RADIUS for q in near):
            continue
        grid.setdefault(key, []).append(p)
        out.append(p)
    return out


def write_ours(case, grains, work, t_end, dt):
    m = MATERIALS[case]
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(work, "grains.csv"), "w") as f:
        f.write("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n")
        for i, (x, y, z) in enumerate(grains):
            f.write(f"0,{i},{mass()!r},{RADIUS!r},{x!r},{y!r},{z!r},0,0,0,0,0,0\n")
    scene = os.path.join(work, "scene.toml")
    with open(scene, "w") as f:
        f.write(
            f"""# Poured heap (analysis/zhang2017/contact_check/repose.py), case {case}
[scene]
kind = "soft-spheres"
t_end = {t_end!r}
seed = 1
particles_file = "{os.path.abspath(os.path.join(work, 'grains.csv'))}"

[stepping]
dt = {dt!r}

[material]
k_n = {K_N!r}
eps_n = {EPS!r}
eps_t = {EPS!r}
mu_s = {m['mu_s']!r}
mu_t = {m['mu_t']!r}
mu_r = {m['mu_r']!r}
beta = {m['beta']!r}

[gravity]
uniform = [0.0, 0.0, {-G!r}]

[output]
every = {t_end / 20.0!r}
times = [0.0, {t_end!r}]

[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""
        )
    return scene


def lammps_coeffs(case):
    m = MATERIALS[case]
    m_pair = 0.5 * mass()
    r_pair = 0.5 * RADIUS
    k_s = 2.0 / 7.0 * K_N
    c_n_pair = alpha_ours(EPS) * math.sqrt(K_N * m_pair)
    c_s_pair = alpha_ours(EPS) * math.sqrt(k_s * m_pair)
    br2 = (m["beta"] * r_pair) ** 2
    return {
        "kn": K_N,
        "e_tsuji": tsuji_e_for(alpha_ours(EPS)),
        "kt": k_s,
        "xgammat": math.sqrt(k_s / K_N),
        "mu_s": m["mu_s"],
        "k_roll": K_N * m["beta"] ** 2,
        "gamma_roll": c_n_pair * m["beta"] ** 2,
        "mu_roll": m["mu_r"] * m["beta"],
        "k_twist": 2.0 * k_s * br2,
        "gamma_twist": 2.0 * c_s_pair * br2,
        "mu_twist": m["mu_t"] * m["beta"] * r_pair * m["mu_s"],
    }


def write_lammps(case, grains, work, t_end, dt):
    os.makedirs(work, exist_ok=True)
    c = lammps_coeffs(case)
    span = 60.0 * RADIUS
    with open(os.path.join(work, "data.column"), "w") as f:
        f.write(f"poured heap, {len(grains)} grains\n\n{len(grains)} atoms\n1 atom types\n\n")
        f.write(f"{-span!r} {span!r} xlo xhi\n{-span!r} {span!r} ylo yhi\n0.0 {2.0 * span!r} zlo zhi\n")
        f.write("\nAtoms # sphere\n\n")
        for i, (x, y, z) in enumerate(grains):
            f.write(f"{i + 1} 1 {2.0 * RADIUS!r} {DENSITY!r} {x!r} {y!r} {z!r}\n")
    model = (
        f"hooke {c['kn']!r} {c['e_tsuji']!r} tangential linear_history {c['kt']!r} {c['xgammat']!r} {c['mu_s']!r}"
    )
    if MATERIALS[case]["beta"] > 0.0:
        model += (
            f" rolling sds {c['k_roll']!r} {c['gamma_roll']!r} {c['mu_roll']!r}"
            f" twisting sds {c['k_twist']!r} {c['gamma_twist']!r} {c['mu_twist']!r}"
        )
    model += " damping tsuji"
    steps = int(round(t_end / dt))
    with open(os.path.join(work, "in.column"), "w") as f:
        f.write(
            f"""# poured heap (analysis/zhang2017/contact_check/repose.py), case {case}
units si
dimension 3
atom_style sphere
atom_modify map array
boundary m m fm
newton on
comm_modify vel yes
read_data data.column
pair_style granular
pair_coeff * * {model}
fix floor all wall/gran granular {model} zplane 0.0 NULL
fix g all gravity {G!r} vector 0 0 -1
neighbor {0.2 * RADIUS!r} bin
neigh_modify every 1 delay 0 check yes
fix integrate all nve/sphere
timestep {dt!r}
thermo_style custom step time ke
thermo {max(1, steps // 20)}
run {steps}
write_dump all custom final.dump id radius x y z vx vy vz modify sort id format float %.17g
"""
        )


def read_ours(run_dir, t_end):
    snaps = os.path.join(run_dir, "snapshots")
    last = sorted(os.listdir(snaps))[-1]
    out = []
    with open(os.path.join(snaps, last)) as f:
        for row in csv.DictReader(f):
            out.append((float(row["x"]), float(row["y"]), float(row["z"])))
    return out


def read_lammps(work):
    out = []
    with open(os.path.join(work, "final.dump")) as f:
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("ITEM: ATOMS")) + 1
    for line in lines[start:]:
        p = line.split()
        out.append((float(p[2]), float(p[3]), float(p[4])))
    return out


def heap(grains):
    """Flank angle (deg), final height (m) and run-out radius (m) of a heap of grains of radius RADIUS."""
    n = len(grains)
    cx = sum(g[0] for g in grains) / n
    cy = sum(g[1] for g in grains) / n
    width = 2.0 * RADIUS
    tops = {}
    for x, y, z in grains:
        b = int(math.hypot(x - cx, y - cy) / width)
        tops[b] = max(tops.get(b, 0.0), z + RADIUS)
    h_max = max(tops.values())
    pts = [((b + 0.5) * width, h) for b, h in sorted(tops.items()) if 0.2 * h_max <= h <= 0.8 * h_max]
    # run-out: the outermost grain that still touches the floor or the heap (isolated rollers excluded)
    near = sorted(grains, key=lambda g: -math.hypot(g[0] - cx, g[1] - cy))
    runout = 0.0
    for g in near:
        if g[2] < 1.5 * RADIUS or any(
            o is not g and math.dist(g, o) < 2.05 * RADIUS for o in grains
        ):
            runout = math.hypot(g[0] - cx, g[1] - cy) + RADIUS
            break
    if len(pts) < 3:
        return float("nan"), h_max, runout, len(pts)
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts)
    slope = sxy / sxx
    return math.degrees(math.atan(-slope)), h_max, runout, len(pts)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="work directory (run directories and decks)")
    ap.add_argument("--cases", default="nominal,no_rolling,caps_x2")
    ap.add_argument("--codes", default="ours,lammps")
    ap.add_argument("--t-end", type=float, default=1.2, help="s of simulated time")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--results", default=os.path.join(HERE, "results.csv"))
    args = ap.parse_args()
    grains = cloud(args.seed)
    dt = time_step()
    print(f"{len(grains)} grains, dt {dt:.4g} s, {int(round(args.t_end / dt))} steps", flush=True)
    rows = []
    for case in args.cases.split(","):
        for code in args.codes.split(","):
            work = os.path.join(args.out, f"{case}_{code}")
            t0 = time.time()
            if code == "ours":
                scene = write_ours(case, grains, work + "_in", args.t_end, dt)
                env = dict(os.environ, RAYON_NUM_THREADS=str(args.threads))
                subprocess.run([BIN, "run", scene, "--out", work], check=True, env=env, stdout=subprocess.DEVNULL)
                final = read_ours(work, args.t_end)
            else:
                write_lammps(case, grains, work, args.t_end, dt)
                subprocess.run(["lmp", "-in", "in.column", "-log", "log.lammps"], cwd=work, check=True,
                               stdout=subprocess.DEVNULL)
                final = read_lammps(work)
            wall = time.time() - t0
            angle, height, runout, bins = heap(final)
            rows.append(dict(case=case, code=code, seed=args.seed, grains=len(grains), t_end_s=args.t_end, dt_s=dt,
                             angle_deg=round(angle, 2), height_m=round(height, 4), runout_m=round(runout, 4),
                             flank_bins=bins, wall_s=round(wall, 1)))
            print(rows[-1], flush=True)
    new = not os.path.exists(args.results)
    with open(args.results, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        if new:
            w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    sys.exit(main())
