#!/usr/bin/env python3
"""rubblepile vs REBOUND, side by side, on two point-mass problems (issue 5 part 4).

Problems (G = 1): the Pythagorean three-body problem to t = 10 and the outer Solar System (Sun + 4 giants on
circular coplanar orbits) to t = 1000. Both codes start from the *same* numbers: the initial state is the one
`rubblepile bench nbody` writes (method `initial` in `nbody_<problem>_states.csv`).

* rubblepile: `rubblepile bench nbody --problem P --rtol ... --methods bulirsch-stoer,dop853` times the
  integration inside the binary (no process start-up, no I/O), one thread, median of --repeats runs; it also
  times the same integrator on a bare point-mass right-hand side (`bare_wall_seconds`) and the time spent
  inside the model's RHS (`rhs_seconds`).
* REBOUND: `sim.integrator = "bs"` with eps_abs = eps_rel = tol (REBOUND >= 5 spells it
  `sim.integrator.eps_abs`; REBOUND 4 spelled it `sim.ri_bs.eps_abs`), timed with time.perf_counter around
  `sim.integrate(t_end)` only (exact finish time), median of the same number of runs.
* Reference: REBOUND's IAS15 (epsilon = 1e-9, its machine-precision default; smaller epsilon only adds
  round-off), checked against rubblepile's Dop853 at rtol = 1e-14 (printed and recorded as the reference's
  uncertainty).
* Error: the block norm of tests/ and `bench work-precision`, with velocities: for positions and velocities
  separately, max over bodies of |x_b - x_ref,b| / max over bodies of |x_ref,b|, then the larger of the two.
* Equal-error comparison: for each error level (one per decade inside both curves) the wall time of each code
  is interpolated log-log on its (time, error) curve; ratio = rubblepile / REBOUND.

Usage (from the repository root, after `cargo build --release`):
    python3 analysis/rebound_compare/compare.py --binary target/release/rubblepile --repeats 21 --rounds 9
Writes into analysis/rebound_compare/: compare_<problem>.csv, equal_error_<problem>.csv, compare_<problem>.svg,
RESULTS.md, and the rubblepile outputs under rubblepile_out/.
"""

import argparse
import csv
import math
import os
import statistics
import subprocess
import sys
import time

import rebound

HERE = os.path.dirname(os.path.abspath(__file__))
TOLERANCES = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
PROBLEMS = {"pythagorean": 10.0, "outer-solar": 1000.0}


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run_rubblepile(binary, problem, tolerances, methods, repeats, out):
    cmd = [binary, "bench", "nbody", "--problem", problem, "--rtol", ",".join(f"{t:g}" for t in tolerances),
           "--methods", ",".join(methods), "--repeats", str(repeats), "--out", out, "--force"]
    print("$", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    stem = "nbody_" + problem.replace("-", "_")
    timing = read_csv(os.path.join(out, stem + ".csv"))
    states = read_csv(os.path.join(out, stem + "_states.csv"))
    return timing, states


def state_of(rows, method, rtol=None):
    """[(m, x, y, z, vx, vy, vz)] of one method/tolerance in a states CSV."""
    out = []
    for r in rows:
        if r["method"] == method and (rtol is None or math.isclose(float(r["rtol"]), rtol, rel_tol=1e-12)):
            out.append(tuple(float(r[k]) for k in ("mass", "x", "y", "z", "vx", "vy", "vz")))
    return out


def make_sim(initial, integrator, tol=None):
    sim = rebound.Simulation()
    sim.G = 1.0
    for (m, x, y, z, vx, vy, vz) in initial:
        sim.add(m=m, x=x, y=y, z=z, vx=vx, vy=vy, vz=vz)
    sim.integrator = integrator
    if integrator == "bs":
        sim.integrator.eps_abs = tol
        sim.integrator.eps_rel = tol
    return sim


def final_state(sim):
    return [(p.m, p.x, p.y, p.z, p.vx, p.vy, p.vz) for p in sim.particles]


def run_rebound(initial, t_end, integrator, tol, repeats):
    walls, cpus, final, steps = [], [], None, 0
    for _ in range(repeats):
        sim = make_sim(initial, integrator, tol)
        c0 = time.thread_time()
        t0 = time.perf_counter()
        sim.integrate(t_end)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.thread_time() - c0)
        if final is None:
            final, steps = final_state(sim), sim.steps_done
    return statistics.median(walls), min(walls), statistics.median(cpus), final, steps


def block_error(state, ref):
    """max over {r, v} of max_b |x_b - x_ref,b| / max_b |x_ref,b|."""
    worst = 0.0
    for lo in (1, 4):
        err = max(math.dist(s[lo:lo + 3], r[lo:lo + 3]) for s, r in zip(state, ref))
        scale = max(math.hypot(*r[lo:lo + 3]) for r in ref)
        worst = max(worst, err / scale if scale > 0 else err)
    return worst


def time_at_error(points, error):
    """Log-log interpolation of the time at which a (time, error) curve, sorted by time, first reaches `error`."""
    pts = sorted((t, e) for t, e in points if t > 0 and e > 0 and math.isfinite(e))
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if (e0 - error) * (e1 - error) <= 0 and e0 != e1:
            s = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + s * (math.log(t1) - math.log(t0)))
    return None


def plot(problem, rows, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no plot", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    styles = {
        ("rubblepile", "bulirsch-stoer"): ("tab:red", "-", "o", "rubblepile BS"),
        ("rubblepile", "dop853"): ("tab:blue", "-", "s", "rubblepile Dop853"),
        ("rubblepile-bare-rhs", "bulirsch-stoer"): ("tab:red", "--", "o", "rubblepile BS, bare N-body RHS"),
        ("rubblepile-bare-rhs", "dop853"): ("tab:blue", "--", "s", "rubblepile Dop853, bare N-body RHS"),
        ("rebound", "bs"): ("black", "-", "^", "REBOUND BS"),
    }
    for key, (colour, ls, marker, label) in styles.items():
        pts = sorted((r["wall_seconds"], r["error"], r["tol"]) for r in rows if (r["code"], r["method"]) == key)
        pts = [p for p in pts if p[1] > 0]
        if not pts:
            continue
        pts.sort(key=lambda p: -p[2])
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], ls=ls, marker=marker, color=colour, label=label,
                  mfc="none" if ls == "--" else colour)
    ax.set_xlabel("integration wall time (s), median")
    ax.set_ylabel("final-state error (block norm vs IAS15)")
    ax.set_title(f"{problem}: rubblepile vs REBOUND (tol 1e-6 ... 1e-12)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(HERE, "..", "..", "target", "release", "rubblepile"))
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--rounds", type=int, default=1,
                    help="alternate the two codes' timing blocks this many times and report the median of the "
                         "rounds' medians (the machine's speed drifts between blocks)")
    ap.add_argument("--problems", default=",".join(PROBLEMS))
    args = ap.parse_args()
    print(f"REBOUND {rebound.__version__}, Python {sys.version.split()[0]}")
    summary = [f"# rubblepile vs REBOUND: measured tables\n",
               f"Generated by `analysis/rebound_compare/compare.py --repeats {args.repeats} --rounds {args.rounds}`; "
               f"REBOUND {rebound.__version__}, Python {sys.version.split()[0]}. Times are medians of {args.repeats} "
               f"runs (integration only), and with several rounds (rubblepile's block and REBOUND's alternating) the "
               f"median of the rounds' medians. Error: block norm (r, v) of the final state against REBOUND IAS15.\n"]
    for problem in args.problems.split(","):
        t_end = PROBLEMS[problem]
        out = os.path.join(HERE, "rubblepile_out")
        rounds = []  # (rubblepile timing rows, {tol: REBOUND run}) per round
        for _ in range(max(args.rounds, 1)):
            timing, states = run_rubblepile(args.binary, problem, TOLERANCES, ["bulirsch-stoer", "dop853"],
                                            args.repeats, out)
            initial = state_of(states, "initial")
            rounds.append((timing, {tol: run_rebound(initial, t_end, "bs", tol, args.repeats) for tol in TOLERANCES}))
        # the states do not depend on the round; the times are the medians over the rounds
        timing = [dict(r) for r in rounds[0][0]]
        for k, r in enumerate(timing):
            for key in ("wall_seconds", "cpu_seconds", "bare_wall_seconds", "bare_cpu_seconds"):
                r[key] = statistics.median(float(rr[0][k][key]) for rr in rounds)
        # Reference: IAS15; its uncertainty from rubblepile's Dop853 at 1e-14.
        ias = make_sim(initial, "ias15")
        ias.integrate(t_end)
        ref = final_state(ias)
        _, tight = run_rubblepile(args.binary, problem, [1e-14], ["dop853", "bulirsch-stoer"], 1,
                                  os.path.join(HERE, "rubblepile_out", "tight"))
        ref_check = {m: block_error(state_of(tight, m, 1e-14), ref) for m in ("dop853", "bulirsch-stoer")}
        print(f"{problem}: IAS15 reference vs rubblepile at 1e-14: {ref_check}")
        rows = []
        for r in timing:
            tol = float(r["rtol"])
            err = block_error(state_of(states, r["method"], tol), ref)
            rows.append(dict(code="rubblepile", method=r["method"], tol=tol, wall_seconds=float(r["wall_seconds"]),
                             cpu_seconds=float(r["cpu_seconds"]), error=err, steps=int(r["steps"]),
                             rhs_evaluations=int(r["rhs_evaluations"]),
                             rhs_share=float(r["rhs_seconds"]) / float(r["profiled_wall_seconds"])))
            rows.append(dict(code="rubblepile-bare-rhs", method=r["method"], tol=tol,
                             wall_seconds=float(r["bare_wall_seconds"]), cpu_seconds=float(r["bare_cpu_seconds"]),
                             error=err, steps=int(r["steps"]), rhs_evaluations=int(r["rhs_evaluations"]),
                             rhs_share=float("nan")))
        for tol in TOLERANCES:
            runs = [rr[1][tol] for rr in rounds]
            wall = statistics.median(run[0] for run in runs)
            wall_min = min(run[1] for run in runs)
            cpu = statistics.median(run[2] for run in runs)
            _, _, _, final, steps = runs[0]
            rows.append(dict(code="rebound", method="bs", tol=tol, wall_seconds=wall, cpu_seconds=cpu,
                             error=block_error(final, ref), steps=steps, rhs_evaluations=-1, rhs_share=float("nan")))
            print(f"  REBOUND bs {tol:g}: {wall:.4e} s (min {wall_min:.4e}), error {rows[-1]['error']:.3e}, "
                  f"{steps} steps", flush=True)
        stem = problem.replace("-", "_")
        with open(os.path.join(HERE, f"compare_{stem}.csv"), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        plot(problem, rows, os.path.join(HERE, f"compare_{stem}.svg"))

        def curve(code, method):
            return [(r["wall_seconds"], r["error"]) for r in rows if r["code"] == code and r["method"] == method]

        reb = curve("rebound", "bs")
        equal = []
        for k in range(2, 15):
            e = 10.0 ** -k
            t_reb = time_at_error(reb, e)
            entry = dict(error=e, rebound_bs=t_reb)
            for code, method, name in [("rubblepile", "bulirsch-stoer", "rubblepile_bs"),
                                       ("rubblepile", "dop853", "rubblepile_dop853"),
                                       ("rubblepile-bare-rhs", "bulirsch-stoer", "bare_rhs_bs")]:
                t = time_at_error(curve(code, method), e)
                entry[name] = t
                entry[name + "_ratio"] = t / t_reb if (t and t_reb) else None
            if t_reb is not None and any(entry[n] for n in ("rubblepile_bs", "rubblepile_dop853")):
                equal.append(entry)
        with open(os.path.join(HERE, f"equal_error_{stem}.csv"), "w", newline="") as f:
            fields = ["error", "rebound_bs", "rubblepile_bs", "rubblepile_bs_ratio", "rubblepile_dop853",
                      "rubblepile_dop853_ratio", "bare_rhs_bs", "bare_rhs_bs_ratio"]
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(equal)

        fmt = lambda v, spec=".3e": "–" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)
        summary.append(f"\n## {problem} (t = 0..{t_end:g})\n")
        summary.append(f"Reference: IAS15; rubblepile at rtol 1e-14 differs from it by "
                       f"{ref_check['dop853']:.2e} (Dop853) and {ref_check['bulirsch-stoer']:.2e} (BS).\n")
        summary.append("\n| tol | REBOUND BS time (s) | REBOUND BS error | rubblepile BS time (s) | rubblepile BS error "
                       "| ratio at equal tol | RHS share | bare-RHS BS time (s) | rubblepile Dop853 time (s) "
                       "| Dop853 error |\n|---|---|---|---|---|---|---|---|---|---|\n")
        for tol in TOLERANCES:
            get = lambda code, method: next(r for r in rows if r["code"] == code and r["method"] == method
                                            and r["tol"] == tol)
            rb, bs = get("rebound", "bs"), get("rubblepile", "bulirsch-stoer")
            bare, dop = get("rubblepile-bare-rhs", "bulirsch-stoer"), get("rubblepile", "dop853")
            summary.append(f"| {tol:g} | {rb['wall_seconds']:.3e} | {rb['error']:.2e} | {bs['wall_seconds']:.3e} | "
                           f"{bs['error']:.2e} | {bs['wall_seconds'] / rb['wall_seconds']:.2f} | "
                           f"{100 * bs['rhs_share']:.0f}% | {bare['wall_seconds']:.3e} | {dop['wall_seconds']:.3e} | "
                           f"{dop['error']:.2e} |\n")
        summary.append("\nAt equal error (log-log interpolation):\n\n| error | REBOUND BS (s) | rubblepile BS (s) "
                       "| ratio | rubblepile Dop853 (s) | ratio | bare-RHS BS (s) | ratio |\n"
                       "|---|---|---|---|---|---|---|---|\n")
        for e in equal:
            summary.append(f"| {e['error']:.0e} | {fmt(e['rebound_bs'])} | {fmt(e['rubblepile_bs'])} | "
                           f"{fmt(e['rubblepile_bs_ratio'], '.2f')} | {fmt(e['rubblepile_dop853'])} | "
                           f"{fmt(e['rubblepile_dop853_ratio'], '.2f')} | {fmt(e['bare_rhs_bs'])} | "
                           f"{fmt(e['bare_rhs_bs_ratio'], '.2f')} |\n")
    with open(os.path.join(HERE, "RESULTS.md"), "w") as f:
        f.writelines(summary)
    print("wrote", os.path.join(HERE, "RESULTS.md"))


if __name__ == "__main__":
    main()
