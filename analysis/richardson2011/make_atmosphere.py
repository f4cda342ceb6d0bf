#!/usr/bin/env python3
"""Initial condition and scenes of the Richardson11 §3.1 model atmosphere: 991 spheres of radius 0.022 on an fcc
lattice (touching spacing times 1.000001) filling a ball centred at height 1.0, masses 1, 3, 10 in turn, at rest,
dropped into an infinite vertical cylinder standing on an infinite plane (g = 1, elastic).

Writes particles.csv (the ball's radius is 0.24), atmosphere.toml (cylinder radius 1.0) and atmosphere_half.toml
(radius 0.5, the same ball). Deterministic (no random numbers).

Usage: python3 make_atmosphere.py [--t-end 300] [--every 1.0]"""
import argparse, itertools, math

ap = argparse.ArgumentParser()
ap.add_argument("--t-end", type=float, default=300.0, help="run length (system units)")
ap.add_argument("--every", type=float, default=1.0, help="snapshot and time-series cadence")
args = ap.parse_args()
R, N, CENTRE = 0.022, 991, (0.0, 0.0, 1.0)
a = 2.0 * R * 1.000001 * math.sqrt(2.0)  # fcc cube edge for nearest-neighbour distance 2R(1+1e-6)
basis = [(0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5)]
pts = []
for i, j, k in itertools.product(range(-8, 9), repeat=3):
    for b in basis:
        p = ((i + b[0]) * a, (j + b[1]) * a, (k + b[2]) * a)
        pts.append((p[0] ** 2 + p[1] ** 2 + p[2] ** 2, p))
pts.sort()


def write(name, chosen):
    with open(name, "w") as f:
        f.write("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n")
        for n, (_, p) in enumerate(chosen[:N]):
            m = (1.0, 3.0, 10.0)[n % 3]
            x, y, z = (p[c] + CENTRE[c] for c in range(3))
            f.write(f"0,{n},{m},{R},{x!r},{y!r},{z!r},0,0,0,0,0,0\n")


def scene(name, particles, radius):
    times = ", ".join(f"{args.every * k:g}" for k in range(int(round(args.t_end / args.every)) + 1))
    with open(name, "w") as f:
        f.write(f"""# Richardson11 §3.1 model atmosphere (written by make_atmosphere.py): 991 elastic spheres (radius 0.022, masses
# 1/3/10) dropped as a blob centred at height 1.0 into an infinite vertical cylinder of radius {radius} standing on an
# infinite plane, uniform gravity g = 1. Expected scale heights kT/(m g) with kT = (2/5) E/N: 1.88, 0.626, 0.188.
[scene]
kind = "hard-spheres"
t_end = {args.t_end}                # system units
seed = 0
particles_file = "{particles}"

[stepping]
dt = 1e-3
collapse_speed = 0.0         # elastic anyway
skin_steps = 32              # neighbour-list skin: the fastest setting measured on this dilute gas (NOTES.md)

[gravity]
uniform = [0.0, 0.0, -1.0]

[material]
eps_n = 1.0
eps_t = 1.0

[output]
every = {args.every}
times = [{times}]

[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[wall]]
kind = "cylinder"
centre = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
radius = {radius}
""")


write("particles.csv", pts)
scene("atmosphere.toml", "particles.csv", 1.0)
scene("atmosphere_half.toml", "particles.csv", 0.5)
