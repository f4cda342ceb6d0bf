#!/usr/bin/env python3
"""Tumbler of Richardson11 §3.2, scaled down: a horizontal cylinder (axis y) of radius 30 mm and length 5 mm between
two frictionless end planes, lined with particles stuck to the cylinder wall (they turn with it: the rough lining),
about half full of free rough spheres, uniform gravity -9.81 z. Writes tumbler_particles.csv (stuck_to = 0 marks the
lining, attached to wall 0, the cylinder) and one scene per Froude number, tumbler_fr<Fr>.toml, whose cylinder spins
at omega = sqrt(Fr g / R). Particle radius 1 mm (R/d = 15; the paper used R/d ~ 57 with 6513 particles) to keep the
event count tractable. Deterministic: the small initial jitter comes from a fixed-seed generator.

Usage: python3 make_tumbler.py [--radius 1e-3] [--fr 0.001,0.01,...] [--t-end 0.6] [--dt 5e-4]"""
import argparse, math, random

R_CYL, LENGTH, G = 0.030, 0.005, 9.81
ap = argparse.ArgumentParser()
ap.add_argument("--radius", type=float, default=1.0e-3, help="particle radius (m)")
ap.add_argument("--fr", default="0.001,0.01,0.1,0.3,0.5,1.0,1.5", help="Froude numbers omega^2 R / g")
ap.add_argument("--t-end", type=float, default=0.6, help="simulated time (s)")
ap.add_argument("--dt", type=float, default=5e-4, help="step (s)")
args = ap.parse_args()
r = args.radius
rows = []
# Lining: rows along y touching the end planes' interior, centres at R - r, touching neighbours in a row, alternate
# rows offset by half a spacing.
ring = R_CYL - r
n_row = int(2 * math.pi * ring / (2 * r))
ys = []
y = -LENGTH / 2 + r
while y <= LENGTH / 2 - r + 1e-12:
    ys.append(y)
    y += 3 * r
for k, y in enumerate(ys):
    for j in range(n_row):
        a = 2 * math.pi * (j + 0.5 * (k % 2)) / n_row
        rows.append((ring * math.sin(a), y, -ring * math.cos(a), 0))
n_stuck = len(rows)
# Free particles: a square grid (spacing 2.04 r) in x-z in the lower half inside the lining, layers in y.
rng = random.Random(2011)
s = 2.04 * r
free_ys = []
y = -LENGTH / 2 + 1.02 * r
while y <= LENGTH / 2 - 1.02 * r + 1e-12:
    free_ys.append(y)
    y += s
inner = R_CYL - 2 * r - 1.05 * r
for y in free_ys:
    nz = int(inner / s)
    for iz in range(-nz, 1):
        for ix in range(-nz, nz + 1):
            x, z = ix * s, iz * s
            if x * x + z * z < inner * inner:
                rows.append((x + rng.uniform(-0.01, 0.01) * r, y, z, -1))
with open("tumbler_particles.csv", "w") as f:
    f.write("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n")
    m = 2500.0 * 4.0 / 3.0 * math.pi * r**3  # glass beads, 2500 kg/m^3
    for n, (x, y, z, w) in enumerate(rows):
        f.write(f"0,{n},{m!r},{r!r},{x!r},{y!r},{z!r},0,0,0,0,0,0,{w}\n")
print(f"{n_stuck} stuck, {len(rows) - n_stuck} free, radius {r} m, R/d = {R_CYL / (2 * r):.1f}")
for fr in [float(x) for x in args.fr.split(",")]:
    omega = math.sqrt(fr * G / R_CYL)
    with open(f"tumbler_fr{fr:g}.toml", "w") as f:
        f.write(f"""# Richardson11 §3.2 tumbler, Fr = omega^2 R / g = {fr:g} (written by make_tumbler.py).
[scene]
kind = "hard-spheres"
t_end = {args.t_end}                # s
seed = 0
particles_file = "tumbler_particles.csv"

[stepping]
dt = {args.dt}                  # s
collapse_speed = {2 * G * args.dt:.6g}      # m/s: twice g dt, so resting contacts bounce elastically (inelastic-collapse guard)

[gravity]
g = [0.0, 0.0, -{G}]         # m/s^2

[material]
eps_n = 0.8                  # glass-like normal restitution (our choice; the paper's value was lost in extraction)
eps_t = 0.8                  # rough spheres (our choice)

[output]
every = 0.01                 # s
times = [{", ".join(f"{t:.2f}" for t in [args.t_end * k / 20 for k in range(21)])}]

[[wall]]                     # 0: the drum, spinning about +y at omega = sqrt(Fr g / R)
type = "cylinder"
origin = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
radius = {R_CYL}
spin = {omega!r}           # rad/s

[[wall]]                     # end planes, frictionless
type = "plane"
origin = [0.0, {-LENGTH / 2}, 0.0]
axis = [0.0, 1.0, 0.0]
eps_t = 1.0

[[wall]]
type = "plane"
origin = [0.0, {LENGTH / 2}, 0.0]
axis = [0.0, -1.0, 0.0]
eps_t = 1.0
""")
