#!/usr/bin/env python3
"""Rates of the creep diagnostics in successive quarters of every committed hold (issue 55's criterion study).

Reads `../decided/<group>/<name>/critical/holds.csv` and the base run's `path2/spinup.csv` (for the time at which
the hold branched off the path, i.e. how long after the build the pile was held), and writes `late_rates.csv`: per
hold that kept its forcing for at least 8000 s, the least-squares rate per 1000 s of the loaded coordination number
(contacts per grain), η_B and θ_max (degrees) over the hold's quarters 2, 3 and 4, and the coordination number's
ratio q4/q2 (below 1: the loss slows down, a relaxation; about 1 or more: a steady or growing loss, creep).

    python3 analysis/zhang2017/criterion/late_rates.py
"""
import csv
import os
import sys
from collections import defaultdict

HERE = os.path.dirname(os.path.abspath(__file__))
DECIDED = os.path.join(HERE, '..', 'decided')
COLUMNS = [('coordination_loaded', 'cn'), ('packing_fraction', 'eta'), ('theta_max_deg', 'theta')]


def slope_per_ks(t, y):
    n = len(t)
    tm, ym = sum(t) / n, sum(y) / n
    stt = sum((a - tm) ** 2 for a in t)
    return 1e3 * sum((a - tm) * (b - ym) for a, b in zip(t, y)) / stt if stt > 0 else float('nan')


def quarter_rates(t, y):
    span = t[-1]
    out = []
    for lo, hi in [(0.25, 0.5), (0.5, 0.75), (0.75, 1.0)]:
        sel = [(a, b) for a, b in zip(t, y) if lo * span <= a <= hi * span]
        out.append(slope_per_ks([a for a, _ in sel], [b for _, b in sel]) if len(sel) > 3 else float('nan'))
    return out


def branch_time(path2, t_final_h):
    try:
        rows = list(csv.DictReader(open(os.path.join(path2, 'spinup.csv'))))
    except OSError:
        return float('nan')
    for r in rows:
        if float(r['path_period_h']) <= t_final_h + 1e-9:
            return float(r['t'])
    # the base run stops at the last output before the slowest hold's branch point
    return float(rows[-1]['t']) if rows else float('nan')


def main():
    out_rows = []
    for group in sorted(os.listdir(DECIDED)):
        gdir = os.path.join(DECIDED, group)
        if not os.path.isdir(gdir):
            continue
        for name in sorted(os.listdir(gdir)):
            holds = os.path.join(gdir, name, 'critical', 'holds.csv')
            if not os.path.exists(holds):
                continue
            by_hold = defaultdict(list)
            for r in csv.DictReader(open(holds)):
                by_hold[r['t_final_h']].append(r)
            for t_final, rows in sorted(by_hold.items()):
                held = [r for r in rows if r.get('forcing', '1') == '1']  # older copies: no release column
                if len(held) < len(rows) or not held or float(held[-1]['t_hold_s']) < 8000:
                    continue  # released, or too short to have quarters
                t = [float(r['t_hold_s']) for r in held]
                row = {'group': group, 'name': name, 't_final_h': t_final, 'hold_s': round(t[-1]),
                       'branch_t_s': f"{branch_time(os.path.join(gdir, name, 'path2'), float(t_final)):.0f}"}
                for col, short in COLUMNS:
                    q = quarter_rates(t, [float(r[col]) for r in held])
                    for k, v in zip((2, 3, 4), q):
                        row[f'{short}_q{k}_per_ks'] = f'{v:.4g}'
                    if short == 'cn':
                        row['cn_q4_over_q2'] = f'{q[2] / q[0]:.3g}' if q[0] else 'nan'
                out_rows.append(row)
    path = os.path.join(HERE, 'late_rates.csv')
    with open(path, 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=list(out_rows[0].keys()), lineterminator='\n')
        w.writeheader()
        w.writerows(out_rows)
    print(f'wrote {path} ({len(out_rows)} holds)', file=sys.stderr)


if __name__ == '__main__':
    main()
