#!/usr/bin/env python3
"""Tumbler of Richardson11 §3.2, scaled down: a horizontal cylinder (axis y) of radius 30 mm and length 5 mm between
two frictionless end planes, lined with particles stuck to the cylinder wall (they turn with it: the rough lining),
about half full of free rough spheres, uniform gravity -9.81 z. Writes tumbler_particles.csv (stuck_to = 0 marks the
lining, attached to wall 0, the cylinder) and one scene per Froude number, tumbler_fr<Fr>.toml, whose cylinder spins
at omega = sqrt(Fr g / R). Particle radius 1 mm (R/d = 15; the paper used R/d ~ 57 with 6513 particles) to keep the
event count tractable. Deterministic: the small initial jitter comes from a fixed-seed generator.

--fill f sets the fraction of the disc inside the lining (radius R - 2r) that the free particles fill at the start:
the grid's centres are cut at the height where the circular segment below it holds that fraction of the disc (0.5:
the axis, the default, half full; the report measures the fill from the top of the bed, 0.52 for the default). A fill other than 0.5 writes tumbler_particles_fill<f>.csv and tumbler_fill<f>_fr<Fr>.toml.
--revolutions n sets each scene's duration to n drum turns (2 pi n / omega, rounded up to 0.01 s) instead of --t-end
and adds _<n>rev to the scene name; --snapshots k writes k + 1 evenly spaced snapshots (on whole steps).

--scale paper builds Richardson11 §3.2's own size: particle radius 0.53 mm and the cylinder wall at 31.06 mm, so the
lining's inner edge lies at R = 30 mm (the paper's footnote: the cylinder was made 31.06 mm "to allow for the finite
diameter of the stuck particles", 31.06 - 30 = 1.06 mm = one diameter; the radius itself was lost in extraction and is
inferred from that), Fr = omega^2 R / g with R = 30 mm, and the 5945 free particles of the paper (6513 in all, 568
stuck) as the lowest 5945 sites of the grid (--n-free). It writes tumbler_paper_particles.csv and
tumbler_paper_fr<Fr>.toml. --eps-n / --eps-t set the restitution coefficients (default 0.8 / 0.8) and, when not the
default, add _en<e>_et<e> to the scene name.

Usage: python3 make_tumbler.py [--radius 1e-3] [--fr 0.001,0.01,...] [--t-end 0.6] [--dt 5e-4] [--fill 0.5]
                               [--revolutions n] [--snapshots 20] [--scale paper] [--n-free N]
                               [--eps-n 0.8] [--eps-t 0.8]"""
import argparse, math, random

R_CYL, LENGTH, G = 0.030, 0.005, 9.81
ap = argparse.ArgumentParser()
ap.add_argument("--scale", choices=["small", "paper"], default="small",
                help="small: r = 1 mm, wall at 30 mm (the defaults); paper: r = 0.53 mm, wall at 31.06 mm, 5945 free")
ap.add_argument("--radius", type=float, default=None, help="particle radius (m); default 1e-3, paper scale 0.53e-3")
ap.add_argument("--n-free", type=int, default=None,
                help="keep the lowest N grid sites as free particles instead of cutting at --fill (paper scale: 5945)")
ap.add_argument("--eps-n", type=float, default=0.8, help="normal coefficient of restitution")
ap.add_argument("--eps-t", type=float, default=0.8, help="tangential coefficient of restitution")
ap.add_argument("--fr", default="0.001,0.01,0.1,0.3,0.5,1.0,1.5", help="Froude numbers omega^2 R / g")
ap.add_argument("--t-end", type=float, default=0.6, help="simulated time (s)")
ap.add_argument("--dt", type=float, default=5e-4, help="step (s)")
ap.add_argument("--fill", type=float, default=0.5, help="fraction (0..1) of the disc inside the lining filled at the start")
ap.add_argument("--revolutions", type=float, default=None, help="run each scene for this many drum turns")
ap.add_argument("--snapshots", type=int, default=20, help="number of snapshot intervals")
args = ap.parse_args()
if not 0.0 < args.fill < 1.0:
    ap.error(f"--fill must lie in (0, 1) (a fraction of the disc), got {args.fill}")
if args.snapshots < 1:
    ap.error(f"--snapshots must be >= 1, got {args.snapshots}")
if args.revolutions is not None and args.revolutions <= 0:
    ap.error(f"--revolutions must be > 0, got {args.revolutions}")
paper = args.scale == "paper"
# R_FR: the drum radius in Fr = omega^2 R / g (the lining's inner edge at the paper's scale, the wall otherwise).
R_FR = R_CYL
if paper:
    R_FR, R_CYL = 0.030, 0.03106
r = args.radius if args.radius is not None else (0.53e-3 if paper else 1.0e-3)
n_free = args.n_free if args.n_free is not None else (5945 if paper else None)
if n_free is not None and n_free < 1:
    ap.error(f"--n-free must be >= 1, got {n_free}")
if not (0.0 <= args.eps_n <= 1.0 and -1.0 <= args.eps_t <= 1.0):
    ap.error(f"--eps-n must lie in [0, 1] and --eps-t in [-1, 1], got {args.eps_n}, {args.eps_t}")
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


def segment_fraction(h, a):
    """Fraction of a disc of radius a lying below the chord at height h (-a <= h <= a)."""
    return (a * a * math.acos(-h / a) + h * math.sqrt(a * a - h * h)) / (math.pi * a * a)


# Cut height: bisection for the chord whose segment holds the fill fraction of the disc inside the lining.
a_lin = R_CYL - 2 * r
lo, hi = -a_lin, a_lin
for _ in range(100):
    mid = 0.5 * (lo + hi)
    lo, hi = (mid, hi) if segment_fraction(mid, a_lin) < args.fill else (lo, mid)
z_cut = 0.5 * (lo + hi)
if n_free is None:
    for y in free_ys:
        nz = int(inner / s)
        for iz in range(-nz, nz + 1):
            for ix in range(-nz, nz + 1):
                x, z = ix * s, iz * s
                if x * x + z * z < inner * inner and z <= z_cut + 0.01 * s:
                    rows.append((x + rng.uniform(-0.01, 0.01) * r, y, z, -1))
else:
    # The lowest n_free sites of the whole grid inside the lining (ties in height broken by x, then y).
    nz = int(inner / s)
    sites = [(iz, ix, k) for k in range(len(free_ys)) for iz in range(-nz, nz + 1) for ix in range(-nz, nz + 1)
             if (ix * s) ** 2 + (iz * s) ** 2 < inner * inner]
    if n_free > len(sites):
        ap.error(f"--n-free {n_free} exceeds the {len(sites)} grid sites inside the lining")
    for iz, ix, k in sorted(sites)[:n_free]:
        rows.append((ix * s + rng.uniform(-0.01, 0.01) * r, free_ys[k], iz * s, -1))
    z_top = max(z for (_, _, z, w) in rows if w == -1)
    lo, hi = 0.0, 1.0  # fill = fraction of the disc inside the lining below the top of the grid
    args.fill = segment_fraction(min(z_top, a_lin), a_lin)
    z_cut = z_top
fill_tag = "_paper" if paper else ("" if args.fill == 0.5 else f"_fill{args.fill:g}")
eps_tag = "" if (args.eps_n, args.eps_t) == (0.8, 0.8) else f"_en{args.eps_n:g}_et{args.eps_t:g}"
particles_file = f"tumbler_particles{fill_tag}.csv"
with open(particles_file, "w") as f:
    f.write("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n")
    m = 2500.0 * 4.0 / 3.0 * math.pi * r**3  # glass beads, 2500 kg/m^3
    for n, (x, y, z, w) in enumerate(rows):
        f.write(f"0,{n},{m!r},{r!r},{x!r},{y!r},{z!r},0,0,0,0,0,0,{w}\n")
print(f"{n_stuck} stuck, {len(rows) - n_stuck} free, radius {r} m, R/d = {R_FR / (2 * r):.1f} (R/r = {R_FR / r:.1f}), fill {args.fill:g} "
      f"(cut at z = {z_cut:.3e} m): {particles_file}")
for fr in [float(x) for x in args.fr.split(",")]:
    omega = math.sqrt(fr * G / R_FR)
    t_end, rev_tag = args.t_end, ""
    if args.revolutions is not None:
        t_end = math.ceil(args.revolutions * 2 * math.pi / omega / 0.01 - 1e-9) * 0.01
        rev_tag = f"_{args.revolutions:g}rev"
    t_end = round(t_end, 6)
    times = [round(t_end * k / args.snapshots / args.dt) * args.dt for k in range(args.snapshots + 1)]
    # Two decimals suffice for the 20 snapshots of a default scene (and keep those files as they were).
    fmt = ".2f" if args.snapshots == 20 and args.revolutions is None else ".4f"
    scene = f"tumbler{fill_tag}_fr{fr:g}{rev_tag}{eps_tag}.toml"
    print(f"Fr {fr:g}: omega {omega:.4f} rad/s, t_end {t_end:g} s ({t_end * omega / (2 * math.pi):.2f} turns): {scene}")
    with open(scene, "w") as f:
        title = f", paper scale (Fr with R = {R_FR} m)" if paper else (", fill " + format(args.fill, "g") if fill_tag else "")
        f.write(f"""# Richardson11 §3.2 tumbler, Fr = omega^2 R / g = {fr:g}{title} (written by make_tumbler.py).
[scene]
kind = "hard-spheres"
t_end = {t_end}                # s
seed = 0
particles_file = "{particles_file}"

[stepping]
dt = {args.dt}                  # s
collapse_speed = {2 * G * args.dt:.6g}      # m/s: twice g dt, so resting contacts bounce elastically (inelastic-collapse guard)

[gravity]
uniform = [0.0, 0.0, -{G}]   # m/s^2

[material]
eps_n = {args.eps_n}                  # glass-like normal restitution (our choice; the paper's value was lost in extraction)
eps_t = {args.eps_t}                  # rough spheres (our choice)

[output]
every = 0.01                 # s
times = [{", ".join(format(t, fmt) for t in times)}]

[[wall]]                     # 0: the drum, spinning about +y at omega = sqrt(Fr g / R){", R = " + str(R_FR) + " m" if paper else ""}
kind = "cylinder"
centre = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
radius = {R_CYL}
spin = {omega!r}           # rad/s

[[wall]]                     # end planes, frictionless
kind = "plane"
point = [0.0, {-LENGTH / 2}, 0.0]
normal = [0.0, 1.0, 0.0]
eps_t = 1.0

[[wall]]
kind = "plane"
point = [0.0, {LENGTH / 2}, 0.0]
normal = [0.0, -1.0, 0.0]
eps_t = 1.0
""")
