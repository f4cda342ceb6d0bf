#!/usr/bin/env python3
"""Side-by-side speed of `rubblepile bench ssdem` and LAMMPS on the same packing (issue 6, "Speed").

What it does (standard library only):

1. `rubblepile bench ssdem --particles N --steps 1 --threads 1 --dump-particles work/particles_N.csv`
   exports the benchmark's FCC ball (spheres of radius 1 m, 2000 kg/m^3, 0.5 % overlaps, uniform spin
   1e-3 rad/s about z) in the snapshot columns `t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`.
2. Writes a LAMMPS data file (`atom_style sphere`) and input deck (`work/in.N`) with `pair_style granular`
   set to the same contact law as far as LAMMPS allows (see `lammps_coeffs` and REPORT.md), no gravity,
   `fix nve/sphere`, the benchmark's dt, skin 0.1 m checked every step, `newton on`.
3. Times, interleaved and `--repeats` times: LAMMPS on 1 MPI rank (and 2 ranks with `--mpi`), and
   `rubblepile bench ssdem --gravity off` on 1 and 2 threads, same N and steps; medians go to
   `results.csv` (code,N,threads,particle_steps_per_s,contacts).
   Also the median of the per-repeat ratios ours/LAMMPS (1 core each) to `paired_ratios.csv`
   (N,median_ratio,min_ratio,max_ratio,repeats): neighbouring samples see about the same machine load.
4. With `--gravity-table`, also times `bench ssdem --gravity off` and `--gravity tree` at each N (1 and 2
   threads) into `gravity.csv` (gravity,N,threads,steps,particle_steps_per_s).

The Debian `lammps` package (29 Sep 2021) has no OPENMP package, so `-sf omp` is not available: the
2-core LAMMPS figure uses 2 MPI ranks instead.

Usage: python3 analysis/ssdem_perf/compare.py --particles 10000,40000 --steps 100,50 --repeats 3 --mpi
"""

import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# Material::nominal(1e7) of src/cli/ssdem.rs::bench_system (Zhang17 nominal set).
K_N = 1e7
EPS_N = 0.55
EPS_T = 0.55
MU_S = 1.0
MU_T = 1.3
MU_R = 1.05
BETA = 0.5


def damping(eps, k, mu):
    """C = -2 ln(eps) sqrt(k mu / (pi^2 + ln^2 eps)) (src/granular/soft/contact.rs::damping)."""
    lg = math.log(eps)
    return -2.0 * lg * math.sqrt(k * mu / (math.pi**2 + lg * lg))


def read_particles(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [{k: float(v) for k, v in r.items()} for r in rows]


def lammps_coeffs(mass, radius):
    """pair_coeff values reproducing our law for equal spheres (reduced mass m/2, R_eff = r/2)."""
    m_eff = 0.5 * mass
    r_eff = 0.5 * radius
    k_s = 2.0 / 7.0 * K_N
    c_n = damping(EPS_N, K_N, m_eff)
    c_s = damping(EPS_T, k_s, m_eff)
    br2 = (BETA * r_eff) ** 2
    # LAMMPS rolling sds: xi = int R_eff (w_i - w_j) x n dt (a length), torque = R_eff n x (-k xi - g v_roll):
    # torque = R_eff^2 k theta  ->  k_roll = k_N beta^2, gamma_roll = C_N beta^2, mu_roll = mu_R beta.
    # twisting sds: torque = -k xi_twist - g w_twist (angle), cap mu_twist |F_n| -> mu_twist = mu_T beta R mu_S
    # (a length: LAMMPS multiplies mu_twist by |F_n| directly).
    return {
        "kn": K_N,
        "damp_n": c_n,  # damping velocity: eta_n = damp_n (kg/s); all pairs have the same m_eff
        "kt": k_s,
        "xgammat": c_s / c_n,  # eta_t = xgammat * eta_n
        "mu_s": MU_S,
        "k_roll": K_N * BETA**2,
        "gamma_roll": c_n * BETA**2,
        "mu_roll": MU_R * BETA,
        "k_twist": 2.0 * k_s * br2,
        "gamma_twist": 2.0 * c_s * br2,
        "mu_twist": MU_T * BETA * r_eff * MU_S,
        "dt": math.pi * math.sqrt(0.5 * mass / K_N) / 50.0,  # time_steps() in src/cli/ssdem.rs
    }


def write_lammps(particles, work, n, steps):
    p0 = particles[0]
    mass, radius = p0["mass"], p0["radius"]
    c = lammps_coeffs(mass, radius)
    density = mass / (4.0 / 3.0 * math.pi * radius**3)
    lo = [min(p[k] for p in particles) - 5.0 * radius for k in "xyz"]
    hi = [max(p[k] for p in particles) + 5.0 * radius for k in "xyz"]
    data = os.path.join(work, f"data.{n}")
    with open(data, "w") as f:
        f.write(f"rubblepile bench ssdem packing, N = {n}\n\n{len(particles)} atoms\n1 atom types\n\n")
        for a, l, h in zip("xyz", lo, hi):
            f.write(f"{l!r} {h!r} {a}lo {a}hi\n")
        f.write("\nAtoms # sphere\n\n")
        for i, p in enumerate(particles):
            f.write(f"{i + 1} 1 {2.0 * p['radius']!r} {density!r} {p['x']!r} {p['y']!r} {p['z']!r}\n")
        f.write("\nVelocities\n\n")
        for i, p in enumerate(particles):
            f.write(f"{i + 1} {p['vx']!r} {p['vy']!r} {p['vz']!r} {p['wx']!r} {p['wy']!r} {p['wz']!r}\n")
    deck = os.path.join(work, f"in.{n}")
    with open(deck, "w") as f:
        f.write(
            f"""# rubblepile bench ssdem equivalent (analysis/ssdem_perf/compare.py), N = {n}
units si
dimension 3
atom_style sphere
atom_modify map array
boundary f f f
newton on
comm_modify vel yes
read_data data.{n}
pair_style granular
pair_coeff * * hooke {c['kn']!r} {c['damp_n']!r} &
  tangential linear_history {c['kt']!r} {c['xgammat']!r} {c['mu_s']!r} &
  rolling sds {c['k_roll']!r} {c['gamma_roll']!r} {c['mu_roll']!r} &
  twisting sds {c['k_twist']!r} {c['gamma_twist']!r} {c['mu_twist']!r} &
  damping velocity
neighbor {0.1 * radius!r} bin
neigh_modify every 1 delay 0 check yes
fix integrate all nve/sphere
timestep {c['dt']!r}
compute cnt all contact/atom
compute ncnt all reduce sum c_cnt
thermo_style custom step atoms c_ncnt
run 0
thermo_style custom step atoms
thermo {steps}
# one untimed step, as bench ssdem does
run 1
run {steps}
"""
        )
    return deck, c


def run_lammps(lmp, deck, work, ranks):
    cmd = [lmp, "-in", os.path.basename(deck), "-log", "none", "-nocite"]
    if ranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + cmd
    out = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"LAMMPS failed ({' '.join(cmd)}):\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}")
    loops = re.findall(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms", out.stdout)
    t, procs, steps, atoms = loops[-1]
    # contacts: the sum of contact/atom (each contact counted on both spheres) printed by `run 0`
    m = re.search(r"Step\s+Atoms\s+c_ncnt\s*\n\s*0\s+\d+\s+([0-9.eE+-]+)", out.stdout)
    contacts = int(round(float(m.group(1)) / 2)) if m else -1
    return int(atoms) * int(steps) / float(t), contacts


BENCH_LINE = re.compile(
    r"N = (\d+), gravity (\w+)(?: \(interval \d+\))?, (\d+) thread\(s\): ([0-9.eE+-]+) particle-steps/s \((\d+) contacts\)"
)


def run_bench(binary, n, gravity, steps, threads, extra=()):
    cmd = [binary, "bench", "ssdem", "--particles", str(n), "--gravity", gravity, "--steps", str(steps)]
    cmd += ["--threads", ",".join(str(t) for t in threads)] + list(extra)
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"bench failed ({' '.join(cmd)}): {out.stderr.strip()}")
    return {int(m.group(3)): (float(m.group(4)), int(m.group(5))) for m in BENCH_LINE.finditer(out.stdout)}


def ints(s):
    return [int(x) for x in s.split(",") if x]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--particles", type=ints, default=[10000], help="comma-separated N")
    ap.add_argument("--steps", type=ints, default=[100], help="timed steps per N (one value, or one per N)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "rubblepile"))
    ap.add_argument("--lmp", default="lmp")
    ap.add_argument("--mpi", action="store_true", help="also time LAMMPS on 2 MPI ranks")
    ap.add_argument("--gravity-table", action="store_true", help="also time bench ssdem off vs tree")
    ap.add_argument("--tree-steps", type=ints, default=[20], help="timed steps per N for --gravity-table tree")
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--threads", type=ints, default=[1, 2], help="rubblepile thread counts to time (default 1,2)")
    a = ap.parse_args()
    steps = a.steps * len(a.particles) if len(a.steps) == 1 else a.steps
    tree_steps = a.tree_steps * len(a.particles) if len(a.tree_steps) == 1 else a.tree_steps
    work = os.path.join(a.out, "work")
    os.makedirs(work, exist_ok=True)

    rows, grows, paired = [], [], []
    for n, s, ts in zip(a.particles, steps, tree_steps):
        dump = os.path.join(work, f"particles_{n}.csv")
        run_bench(a.bin, n, "off", 1, [1], ["--dump-particles", dump])
        particles = read_particles(dump)
        deck, coeffs = write_lammps(particles, work, n, s)
        print(f"N = {n}: {s} steps, dt = {coeffs['dt']:.6e} s, coefficients {coeffs}", flush=True)
        samples = {}
        contacts = {}
        for rep in range(a.repeats):
            for ranks in [1, 2] if a.mpi else [1]:
                rate, c = run_lammps(a.lmp, deck, work, ranks)
                samples.setdefault(("lammps", ranks), []).append(rate)
                contacts[("lammps", ranks)] = c
                print(f"  rep {rep}: LAMMPS {ranks} rank(s) {rate:.4e} particle-steps/s ({c} contacts)", flush=True)
            for t, (rate, c) in run_bench(a.bin, n, "off", s, a.threads).items():
                samples.setdefault(("rubblepile", t), []).append(rate)
                contacts[("rubblepile", t)] = c
                print(f"  rep {rep}: rubblepile {t} thread(s) {rate:.4e} particle-steps/s ({c} contacts)", flush=True)
            if a.gravity_table:
                for t, (rate, _) in run_bench(a.bin, n, "tree", ts, [1, 2]).items():
                    samples.setdefault(("tree", t), []).append(rate)
                    print(f"  rep {rep}: rubblepile tree {t} thread(s) {rate:.4e} particle-steps/s", flush=True)
        # Paired ratios (ours / LAMMPS, 1 core each, same repeat): on a shared machine the load drifts between
        # repeats, and a pair of neighbouring samples sees about the same load.
        if ("rubblepile", 1) in samples:
            ratios = sorted(r / l for r, l in zip(samples[("rubblepile", 1)], samples[("lammps", 1)]))
            paired.append((n, statistics.median(ratios), ratios[0], ratios[-1], len(ratios)))
            print(f"N = {n}: paired ratio ours/LAMMPS (1 core) median {paired[-1][1]:.3f}, "
                  f"range {ratios[0]:.3f}-{ratios[-1]:.3f} over {len(ratios)} repeats", flush=True)
        for (code, t), v in sorted(samples.items()):
            med = statistics.median(v)
            if code == "tree":
                grows.append(("tree", n, t, ts, med))
                continue
            rows.append((code, n, t, med, contacts[(code, t)]))
            if code == "rubblepile":
                grows.append(("off", n, t, s, med))

    with open(os.path.join(a.out, "results.csv"), "w") as f:
        f.write("code,N,threads,particle_steps_per_s,contacts\n")
        for code, n, t, r, c in rows:
            f.write(f"{code},{n},{t},{r:.6e},{c}\n")
    with open(os.path.join(a.out, "paired_ratios.csv"), "w") as f:
        f.write("N,median_ratio,min_ratio,max_ratio,repeats\n")
        for n, med, lo, hi, k in paired:
            f.write(f"{n},{med:.4f},{lo:.4f},{hi:.4f},{k}\n")
    if a.gravity_table:
        with open(os.path.join(a.out, "gravity.csv"), "w") as f:
            f.write("gravity,N,threads,steps,particle_steps_per_s\n")
            for g, n, t, s, r in sorted(grows):
                f.write(f"{g},{n},{t},{s},{r:.6e}\n")
    print("wrote", os.path.join(a.out, "results.csv"))


if __name__ == "__main__":
    main()
