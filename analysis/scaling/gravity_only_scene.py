#!/usr/bin/env python3
"""A gravity-only scene through `rubblepile run` against the point-mass path (`bench nbody`) and REBOUND's BS
(issue 39, "a scene must not pay for what it does not use"): the outer Solar System of
`analysis/rebound_compare/outer_solar.toml`, rtol = atol = 1e-10, to t = 1000.

Five rounds; in each: REBOUND BS (median of 21), the scene run 7 times (median of its `summary.json` wall time,
which excludes start-up and parsing), `bench nbody` (median of 21). Prints the medians over the rounds, the
ratios, and each final state's error against REBOUND's IAS15. Needs `pip install rebound` and a release build.

    python3 analysis/scaling/gravity_only_scene.py
"""
os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
sys.path.insert(0, 'analysis/rebound_compare')
import compare as C
subprocess.run(['target/release/rubblepile', 'bench', 'nbody', '--problem', 'outer-solar', '--rtol', '1e-10', '--methods', 'bulirsch-stoer', '--repeats', '1', '--out', '/tmp/nb', '--force'], check=True, capture_output=True)
rows = C.read_csv('/tmp/nb/nbody_outer_solar_states.csv')
initial = C.state_of(rows, 'initial')
ref = C.run_rebound(initial, 1000.0, 'ias15', None, 1)[3]
res = {}
for rnd in range(5):
    w = C.run_rebound(initial, 1000.0, 'bs', 1e-10, 21)
    res.setdefault('rebound', []).append(w[0]); res['rebound_err'] = C.block_error(w[3], ref)
    walls = []
    for i in range(7):
        shutil.rmtree('/tmp/os', ignore_errors=True)
        subprocess.run(['target/release/rubblepile', 'run', 'analysis/rebound_compare/outer_solar.toml', '--out', '/tmp/os', '--no-progress'], check=True, capture_output=True)
        walls.append(json.load(open('/tmp/os/summary.json'))['wall_seconds'])
    res.setdefault('scene', []).append(statistics.median(walls))
    subprocess.run(['target/release/rubblepile', 'bench', 'nbody', '--problem', 'outer-solar', '--rtol', '1e-10', '--methods', 'bulirsch-stoer', '--repeats', '21', '--out', '/tmp/nb2', '--force'], check=True, capture_output=True)
    res.setdefault('nbody', []).append(float(C.read_csv('/tmp/nb2/nbody_outer_solar.csv')[0]['wall_seconds']))
# scene final state error vs IAS15
snaps = sorted(os.listdir('/tmp/os/snapshots'), key=lambda s: float(s.split('.')[0]) if s[0].isdigit() else 0)
last = C.read_csv('/tmp/os/snapshots/' + snaps[-1])
state = [(float(r['mass']), float(r['x']), float(r['y']), float(r['z']), float(r['vx']), float(r['vy']), float(r['vz'])) for r in last]
med = {k: statistics.median(v) for k, v in res.items() if k != 'rebound_err'}
print('medians (s):', med)
print('scene/rebound %.2f  scene/nbody %.2f  nbody/rebound %.2f' % (med['scene']/med['rebound'], med['scene']/med['nbody'], med['nbody']/med['rebound']))
print('error vs IAS15: rebound BS %.2e  scene %.2e' % (res['rebound_err'], C.block_error(state, ref)))
