#!/usr/bin/env bash
# Regenerates the Apophis 2029 flyby study (issue 20): the Apophis run, a control run without tide, and the sweep of
# perigee distance q (1.2–6 Earth radii) at v_inf = 5.8 and 12 km/s. Outputs go to runs/apophis2029/ (git-ignored);
# then `python3 analysis/apophis2029/summarize.py` writes runs.csv and the figures here.
# Usage (from the repository root, release build present): nice bash analysis/apophis2029/run.sh
set -u
BIN=./target/release/rubblepile
OUT=runs/apophis2029
RE=6371000
mkdir -p "$OUT"
# 0. The pile: targets/N100_T12.csv (Roig03-scale, relaxed at P = 12 h) scaled to 4.0e10 kg (volume-equivalent radius
# 170 m at its bulk density 1959 kg/m^3; max extent 205 m), set into rigid rotation at P = 30.56 h and relaxed for
# 36 h without tide (a flyby with the planet's mass 0); its last snapshot is the pile of every run below.
if [ ! -f "$OUT/relax/analysis/flyby.json" ]; then
  $BIN flyby --target targets/N100_T12.csv --radius-m 205 --period-h 30.56 --q-m 3.8e7 --v-inf-km-s 5.8 \
    --planet-mass-kg 0 --out "$OUT/relax" --force > "$OUT/relax.log" 2>&1
fi
COMMON=(--target "$OUT/relax/snapshots/8.csv" --kappa 14.982288520067549 --force)
one() { # name, extra args...
  local name=$1; shift
  if [ -f "$OUT/$name/analysis/flyby.json" ]; then return; fi
  /usr/bin/time -f "%e" -o "$OUT/$name.time" $BIN flyby "${COMMON[@]}" "$@" --out "$OUT/$name" > "$OUT/$name.log" 2>&1
}
# Apophis on 13 April 2029: perigee 38 000 km from Earth's centre, v_inf 5.8 km/s.
one apophis --q-m 3.8e7 --v-inf-km-s 5.8
# Control: the same pile and duration scale with the planet's mass set to 0 (no tide): the drift of the pile alone.
one control --q-m 3.8e7 --v-inf-km-s 5.8 --planet-mass-kg 0
for v in 5.8 12; do
  for qr in 1.2 1.5 2 2.5 3 4 6; do
    q=$(python3 -c "print($qr*$RE)")
    one "sweep_v${v}_q${qr}" --q-m "$q" --v-inf-km-s "$v"
  done
done
# Earth's J2 (1.0826e-3 about the equatorial radius 6378.137 km) with two spin axes that bracket the real one:
# normal to the flyby plane (the pass stays over the equator) and along the perigee direction (over a pole at
# perigee). For Apophis and for the closest pass of the sweep (1.2 R_E, 5.8 km/s).
for pole in eq:0,0,1 polar:1,0,0; do
  name=${pole%%:*}; axis=${pole#*:}
  J2=(--planet-j2 1.0826e-3 --planet-radius-m 6378137 --planet-pole "$axis")
  one "j2${name}_apophis" --q-m 3.8e7 --v-inf-km-s 5.8 "${J2[@]}"
  one "j2${name}_q1.2" --q-m "$(python3 -c "print(1.2*$RE)")" --v-inf-km-s 5.8 "${J2[@]}"
done
# How far the 1.2 R_E outcome moves anyway: the point-mass pass with q changed by 1e-5 and 1e-4 (relative), an
# effect of the order of J2's there (J2 (R/q)^2 = 7.5e-4 of the pull, a smaller share of the tide's gradient).
for f in 1.00001 1.0001; do
  one "perturb_q1.2_$f" --q-m "$(python3 -c "print(1.2*$RE*$f)")" --v-inf-km-s 5.8
done
