#!/usr/bin/env python3
"""Initial condition of the Richardson11 §3 model atmosphere: 991 spheres of radius 0.022 on an fcc lattice
(touching spacing times 1.000001) filling a ball centred at height 1.0, masses 1, 3, 10 in turn, at rest.
Writes particles.csv in the particles-file columns. Deterministic (no random numbers)."""
import itertools, math

R, N, CENTRE = 0.022, 991, (0.0, 0.0, 1.0)
a = 2.0 * R * 1.000001 * math.sqrt(2.0)  # fcc cube edge for nearest-neighbour distance 2R(1+1e-6)
basis = [(0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5)]
pts = []
for i, j, k in itertools.product(range(-8, 9), repeat=3):
    for b in basis:
        p = ((i + b[0]) * a, (j + b[1]) * a, (k + b[2]) * a)
        pts.append((p[0] ** 2 + p[1] ** 2 + p[2] ** 2, p))
pts.sort()
with open("particles.csv", "w") as f:
    f.write("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n")
    for n, (_, p) in enumerate(pts[:N]):
        m = (1.0, 3.0, 10.0)[n % 3]
        x, y, z = (p[c] + CENTRE[c] for c in range(3))
        f.write(f"0,{n},{m},{R},{x!r},{y!r},{z!r},0,0,0,0,0,0\n")
