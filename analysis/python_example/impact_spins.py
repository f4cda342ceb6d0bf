"""From Python: build a rubble-pile target, throw a projectile at it, and fit the spin distribution of the
fragments (Roig03 Sec. 4.3, Eq. 44: f(w) = a w^n exp(-w^2/b^2)) with SciPy; the histogram and the fits go to a PNG.

    pip install ./src/python scipy matplotlib
    python analysis/python_example/impact_spins.py [--fragments 30] [--out runs/python_example]

Everything it writes goes under --out (default runs/python_example): the target (target.csv, target.json), the
impact's run directory (impact/, with impact/analysis/ from the analysis) and spins.png. SI units throughout.
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy import optimize, stats  # noqa: E402

import rubblepile  # noqa: E402


def eq44(w, a, n, b):
    """Roig03 Eq. 44: the number of fragments per spin-rate bin, a w^n exp(-w^2/b^2) (w in rad/s)."""
    return a * w**n * np.exp(-((w / b) ** 2))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fragments", type=int, default=30, help="fragments of the target (30, 100 or 200)")
    p.add_argument("--period-hours", type=float, default=4.0, help="spin period of the target (h)")
    p.add_argument("--speed", type=float, default=5000.0, help="impact speed (m/s)")
    p.add_argument("--angle", type=float, default=45.0, help="impact angle to the spin axis (degrees)")
    p.add_argument("--t-end", type=float, default=1000.0, help="end of the impact run (s)")
    p.add_argument("--out", default="runs/python_example")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)

    target = os.path.join(args.out, "target.csv")
    report = rubblepile.build_target(args.fragments, args.period_hours, target, force=True)
    print(f"target: {report['fragments']} fragments, {report['total_mass_kg']:.3e} kg, "
          f"porosity {report['porosity']:.2f}")

    run = os.path.join(args.out, "impact")
    sim = rubblepile.impact(target, run, speed=args.speed, angle=args.angle, t_end=args.t_end, force=True)
    print(f"impact: t = {sim.t} s, energy error {sim.energy_error:.2e}, wall {sim.wall_seconds:.1f} s")
    a = rubblepile.analyze(run, at=args.t_end, force=True)
    for line in a["lines"]:
        print(line)

    f = a["fragments"]
    spins = f["spin_rate_corrected"][~f["is_projectile"] & (f["spin_rate_corrected"] > 0)]
    counts, edges = np.histogram(spins, bins=max(5, int(np.sqrt(len(spins)))))
    centres = 0.5 * (edges[1:] + edges[:-1])
    # Eq. 44 with its exponent free, least squares on the histogram; and the Maxwellian (n = 2) by maximum
    # likelihood on the spins themselves.
    guess = (counts.max() / centres[np.argmax(counts)] ** 2, 2.0, np.median(spins) * 1.5)
    (a44, n44, b44), cov = optimize.curve_fit(eq44, centres, counts, p0=guess, bounds=([0, 0, 0], np.inf),
                                              maxfev=20000)
    loc, scale = stats.maxwell.fit(spins, floc=0.0)
    print(f"spins of {len(spins)} target fragments: Eq. 44 fit n = {n44:.2f} +- {np.sqrt(cov[1, 1]):.2f}, "
          f"b = {b44:.3e} rad/s; Maxwellian scale {scale:.3e} rad/s")

    w = np.linspace(0.0, edges[-1], 200)
    width = edges[1] - edges[0]
    plt.figure(figsize=(6, 4))
    plt.bar(centres, counts, width=width, alpha=0.5, label=f"{len(spins)} target fragments")
    plt.plot(w, eq44(w, a44, n44, b44), label=f"Eq. 44, n = {n44:.2f}")
    plt.plot(w, len(spins) * width * stats.maxwell.pdf(w, loc, scale), "--", label="Maxwellian (n = 2)")
    plt.xlabel("corrected spin rate (rad/s)")
    plt.ylabel("fragments per bin")
    plt.title(f"N{args.fragments} target, {args.speed / 1e3:g} km/s at {args.angle:g} deg, t = {args.t_end:g} s")
    plt.legend()
    plt.tight_layout()
    png = os.path.join(args.out, "spins.png")
    plt.savefig(png, dpi=120)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
